"""The documentation site (mkdocs.yml, docs/): every public name has an API page, every page is in the nav.

``mkdocs build --strict`` (run by ``.ci/run``) checks links, snippets and mkdocstrings references; these
checks need no MkDocs and say which name or page is missing.
"""

from __future__ import annotations

import importlib
import re
import types

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
