"""The documentation site (mkdocs.yml, docs/): every public name has an API page, every page is in the nav.

``mkdocs build --strict`` (run by ``.ci/run``) checks links, snippets and mkdocstrings references; these
checks need no MkDocs and say which name or page is missing.
"""

from __future__ import annotations

import importlib
import os
import re
import shutil
import subprocess
import sys
import types
import urllib.request
from pathlib import Path
from urllib.parse import urlparse

import pytest
from paths import ROOT

import discsim as ds

API = ROOT / "docs" / "api"


def _documented_modules() -> list[str]:
    return [m for page in sorted(API.glob("*.md")) for m in re.findall(r"^::: (\S+)", page.read_text(), re.M)]


def test_every_public_name_is_in_the_api_reference():
    modules = _documented_modules()
    assert modules, "docs/api/*.md render no module"
    covered = set(modules)
    for name in modules:
        covered.update(getattr(importlib.import_module(name), "__all__", ()))
    missing = []
    for name in ds.__all__:
        obj = getattr(ds, name)
        if isinstance(obj, types.ModuleType):
            if obj.__name__ not in covered:
                missing.append(name)
        elif name not in covered:
            missing.append(name)
    assert not missing, f"public names with no API page (add their module to a page in docs/api/): {missing}"


def test_every_page_is_in_the_nav():
    yaml = pytest.importorskip("yaml")
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())

    def pages(nav):
        for item in nav:
            for value in item.values() if isinstance(item, dict) else [item]:
                yield from pages(value) if isinstance(value, list) else [value]

    in_nav = set(pages(config["nav"]))
    docs = ROOT / "docs"
    own = {"index.md", "getting-started.md", "study.md", "algorithm.md", "architecture.md"}
    own |= {p.relative_to(docs).as_posix() for p in (docs / "users").glob("*.md")}
    own |= {p.relative_to(docs).as_posix() for p in API.glob("*.md")}
    assert own <= in_nav, f"pages missing from the nav of mkdocs.yml: {sorted(own - in_nav)}"
    notebooks = {f"notebooks/{p.name}" for p in (ROOT / "notebooks").glob("*.ipynb")}
    assert notebooks <= in_nav, f"notebooks missing from the nav: {sorted(notebooks - in_nav)}"
    assert "benchmarks/index.md" in in_nav  # docs/performance.md, served beside the benchmarks


# --- the notebooks' maths on the site -----------------------------------------------------------------
#: A formula of each notebook with maths, as its page must carry it for MathJax to typeset (``$...$`` text).
MATHS = {
    "02_trajectories": "$kT = 1$",
    "03_when_is_pit_good_enough": r"\frac{v\,\Delta t}{r}",
    "04_physics": "$kT$",
    "05_dense_discs": r"$\psi_6$",
}


def _jupyter_options() -> dict:
    """The options of the mkdocs-jupyter plugin in mkdocs.yml."""
    yaml = pytest.importorskip("yaml")
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
    found = [
        entry["mkdocs-jupyter"] for entry in config["plugins"] if isinstance(entry, dict) and "mkdocs-jupyter" in entry
    ]
    assert found, "mkdocs.yml has no mkdocs-jupyter plugin"
    return found[0]


def _mathjax_scripts(html: str) -> list[str]:
    return [src for src in re.findall(r'<script[^>]*\bsrc="([^"]*)"', html) if "mathjax" in src.lower() or not src]


def check_maths(html: str, name: str, site=None) -> None:
    """The page of notebook ``name`` loads MathJax from a real address (or a file of the site), configures it
    for ``$...$`` and carries its formulas as TeX text."""
    scripts = _mathjax_scripts(html)
    assert scripts, f"{name}: no MathJax script in the page"
    for src in scripts:
        address = urlparse(src)
        if address.scheme:
            assert address.scheme == "https" and address.netloc and address.path.endswith(".js"), (name, src)
        else:
            assert src and site is not None and (site / "notebooks" / name / src).resolve().is_file(), (name, src)
    assert "inlineMath: [ ['$','$']" in html, f"{name}: MathJax is not told to typeset $...$"
    assert MATHS[name] in html, f"{name}: {MATHS[name]} is not in the page as TeX"


def test_the_notebook_pages_load_mathjax():
    """mkdocs-jupyter's own default for the MathJax address is "", which left every notebook page a
    ``<script src="">`` and its maths as typed; mkdocs.yml names the script. The page of notebook 05 as the
    plugin renders it with mkdocs.yml's options (the whole site: the slow test below)."""
    pytest.importorskip("mkdocs_jupyter")
    from mkdocs_jupyter.convert import nb2html
    from mkdocs_jupyter.plugin import Plugin

    plugin = Plugin()
    errors, _ = plugin.load_config(_jupyter_options())
    assert not errors, errors
    html = nb2html(
        str(ROOT / "notebooks" / "05_dense_discs.ipynb"),
        execute=False,
        theme=plugin.config["theme"],
        include_requirejs=plugin.config["include_requirejs"],
        custom_mathjax_url=plugin.config["custom_mathjax_url"],
    )
    check_maths(html, "05_dense_discs")


def _chromium() -> str | None:
    names = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome")
    return os.environ.get("DISCSIM_CHROMIUM") or next(filter(None, map(shutil.which, names)), None)


@pytest.fixture(scope="module")
def built_site(tmp_path_factory):
    """``mkdocs build --strict`` into a temporary folder, the notebooks not executed (``DISCSIM_DOCS_EXECUTE=0``)."""
    pytest.importorskip("mkdocs_jupyter")
    site = tmp_path_factory.mktemp("site")
    env = {**os.environ, "DISCSIM_DOCS_EXECUTE": "0", "NO_MKDOCS_2_WARNING": "1"}
    build = [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)]
    done = subprocess.run(build, cwd=ROOT, env=env, capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    return site


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(MATHS))
def test_the_built_notebook_pages_load_mathjax(built_site, name):
    """Each notebook page with maths: MathJax from a real address, configured for ``$...$``, the formulas as TeX."""
    check_maths((built_site / "notebooks" / name / "index.html").read_text(encoding="utf-8"), name, built_site)


#: Debian's MathJax 2.7 (libjs-mathjax), for the browser check where the page's own address cannot be fetched.
LOCAL_MATHJAX = Path("/usr/share/javascript/mathjax/MathJax.js")


@pytest.mark.slow
def test_a_browser_typesets_the_notebooks_maths(built_site):
    """The page of notebook 05 opened in headless Chromium has its maths typeset by MathJax (skips, saying why,
    where there is no Chromium, or MathJax can neither be fetched from its address nor found installed)."""
    browser = _chromium()
    if browser is None:
        pytest.skip("no Chromium binary found for the browser check: apt install chromium")
    page = built_site / "notebooks" / "05_dense_discs" / "index.html"
    html = page.read_text(encoding="utf-8")
    src = _mathjax_scripts(html)[0]
    if urlparse(src).scheme:
        try:
            urllib.request.urlopen(src, timeout=10).close()
        except OSError as exc:
            # No network (as on CI): the same MathJax 2.7 from Debian's libjs-mathjax, which .ci/run installs,
            # in place of the address, with the page's own configuration (the address's query).
            if not LOCAL_MATHJAX.is_file():
                pytest.skip(f"MathJax cannot be fetched from {src} here ({exc}), nor found at {LOCAL_MATHJAX}")
            query = urlparse(src).query
            local = LOCAL_MATHJAX.as_uri() + (f"?{query}" if query else "")
            page = page.with_name("index-local-mathjax.html")
            page.write_text(html.replace(src, local), encoding="utf-8")
    args = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--allow-file-access-from-files"]
    args += ["--virtual-time-budget=60000", "--dump-dom"]  # 20 s of virtual time sometimes ended before MathJax did
    dom = subprocess.run([*args, page.as_uri()], capture_output=True, text=True, timeout=300, check=False).stdout
    typeset = dom.count("MathJax_CHTML")  # each formula's output: class="mjx-chtml MathJax_CHTML"
    assert typeset >= 10, f"MathJax typeset {typeset} formulas in the page of notebook 05"
