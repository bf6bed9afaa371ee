"""Write ``docs/performance.md`` from the benchmark results: one section per benchmark, one table per CSV file.

Run ``python benchmarks/performance_doc.py`` from the repository root after a benchmark script has rewritten
its CSV files under ``benchmarks/results/`` (``--out PATH`` writes the page elsewhere). Standard library only;
nothing here imports discsim or the benchmark scripts.

Each benchmark script (``benchmarks/NAME.py``) gets a section that opens with a paragraph of its own module
docstring: the summary line and the first paragraph after the run instructions (with the list that follows
it, when that paragraph introduces one). Each CSV file is listed under the script whose name is the longest
prefix of its stem (``throughput_queue.csv`` under ``throughput.py``) and rendered as a Markdown table: floats
to 4 significant digits, numbers from 1,000 up as whole numbers with thousands separators; then a link to the
PNG of the same stem, if there is one.
"""

from __future__ import annotations

import argparse
import ast
import csv
import math
import os
import re
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent
RESULTS = BENCHMARKS / "results"
DEFAULT_OUT = BENCHMARKS.parent / "docs" / "performance.md"

#: Scripts in ``benchmarks/`` that are not benchmarks.
NOT_BENCHMARKS = frozenset({"benchutils", "performance_doc"})

#: Section order (the README's); scripts not named here follow in alphabetical order.
SCRIPT_ORDER = ("throughput", "event_counts", "accuracy_map", "peers", "longrun", "pit_variants")

#: Significant digits of a float below 1,000.
SIGNIFICANT_DIGITS = 4

#: Tables with more rows than this are folded into a ``<details>`` block.
MAX_OPEN_ROWS = 30

#: The docstring sentence that says how to run a script; the description skips it.
RUN_SENTENCE = re.compile(r"Run ``python benchmarks/[^`]+``.*?\.(?=\s|$)", re.DOTALL)

#: A Sphinx cross-reference such as :func:`discsim.random_gas` or :class:`~discsim.EventDriven`.
SPHINX_ROLE = re.compile(r":[a-z]+:`(~?)([^`]+)`")


def format_cell(text: str) -> str:
    """One CSV cell as shown in a table: numbers rounded, text as written.

    Args:
        text: the cell as read from the CSV file.

    Returns:
        Integers and floats from 1,000 up as whole numbers with thousands separators, other floats to
        ``SIGNIFICANT_DIGITS`` significant digits, ``nan`` and ``inf`` as such; anything else unchanged,
        with ``|`` escaped.

    >>> [format_cell(t) for t in ["69809.48386885984", "0.0030513392207031772", "1.0", "500000", "calendar"]]
    ['69,809', '0.003051', '1', '500,000', 'calendar']
    """
    text = text.strip()
    try:
        integer = int(text)
    except ValueError:
        pass
    else:
        return f"{integer:,}"
    try:
        value = float(text)
    except ValueError:
        return text.replace("|", "\\|").replace("\n", " ")
    if not math.isfinite(value):
        return str(value)
    rounded = float(f"{value:.{SIGNIFICANT_DIGITS}g}")
    if abs(rounded) >= 1000:
        return f"{round(value):,}"
    if rounded == 0:
        return "0"
    return f"{value:.{SIGNIFICANT_DIGITS}g}"


def is_number(text: str) -> bool:
    """Whether a CSV cell parses as a number (``nan`` included)."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def markdown_table(header: list[str], rows: list[list[str]]) -> list[str]:
    """A CSV file's header and rows as the lines of a Markdown table; numeric columns align right."""
    columns = range(len(header))
    cells = [[format_cell(row[i]) if i < len(row) else "" for i in columns] for row in rows]
    numeric = [
        any(i < len(row) and row[i].strip() for row in rows)
        and all(is_number(row[i]) for row in rows if i < len(row) and row[i].strip())
        for i in columns
    ]
    lines = [
        "| " + " | ".join(name.replace("|", "\\|") for name in header) + " |",
        "|" + "|".join("---:" if right else "---" for right in numeric) + "|",
    ]
    lines += ["| " + " | ".join(row) + " |" for row in cells]
    return lines


def rst_to_markdown(text: str) -> str:
    """Docstring markup as Markdown: ````code```` to ```code```, Sphinx roles to their target in code."""
    text = SPHINX_ROLE.sub(lambda m: "`" + (m[2].rsplit(".", 1)[-1] if m[1] else m[2]) + "`", text)
    return text.replace("``", "`")


def unwrap(paragraph: str) -> str:
    """A paragraph's lines joined into one line."""
    return " ".join(line.strip() for line in paragraph.splitlines() if line.strip())


def bullet_items(paragraph: str) -> list[str]:
    """The items of a ``* ``-bulleted docstring list, each unwrapped to one line."""
    items: list[str] = []
    for line in paragraph.splitlines():
        if line.lstrip().startswith("* "):
            items.append(line.lstrip()[2:].strip())
        elif items and line.strip():
            items[-1] += " " + line.strip()
    return items


def describe(script: Path) -> list[str]:
    """The Markdown lines describing a benchmark, taken from its module docstring.

    Args:
        script: a benchmark script, ``benchmarks/NAME.py``.

    Returns:
        One paragraph (the docstring's summary line in bold and its first paragraph after the run
        instructions) and, when that paragraph introduces a list (it does not end a sentence), the list.
    """
    docstring = ast.get_docstring(ast.parse(script.read_text(encoding="utf-8")))
    if not docstring:
        return [f"`{script.name}` has no module docstring."]
    paragraphs = [p for p in re.split(r"\n\s*\n", docstring.strip()) if p.strip()]
    summary, text = unwrap(paragraphs[0]), ""
    items: list[str] = []
    for index, paragraph in enumerate(paragraphs[1:], start=1):
        body = RUN_SENTENCE.sub("", paragraph, count=1).strip()
        if not body:
            continue
        text = unwrap(body)
        following = paragraphs[index + 1] if index + 1 < len(paragraphs) else ""
        if not text.endswith((".", ")")) and following.lstrip().startswith("* "):
            items = bullet_items(following)
        break
    paragraph = f"**{rst_to_markdown(summary)}** {rst_to_markdown(text)}".rstrip()
    return [paragraph, *([""] if items else []), *(f"- {rst_to_markdown(item)}" for item in items)]


def script_for(stem: str, scripts: list[str]) -> str | None:
    """The benchmark whose name is the longest prefix of a CSV file's stem (``throughput`` for ``throughput_pit``)."""
    matches = [name for name in scripts if stem == name or stem.startswith(name + "_")]
    return max(matches, key=len, default=None)


def anchor(heading: str) -> str:
    """The fragment GitHub gives a Markdown heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-")


def relative_link(target: Path, page: Path) -> str:
    """A link from the page to a file, relative to the page's folder when both share a root."""
    try:
        return Path(os.path.relpath(target, page.resolve().parent)).as_posix()
    except ValueError:  # another drive on Windows
        return target.as_posix()


def csv_section(path: Path, page: Path) -> list[str]:
    """The Markdown lines of one CSV file: heading, table (folded when long) and the figure of the same stem."""
    with path.open(newline="", encoding="utf-8") as file:
        records = [row for row in csv.reader(file) if row]
    lines = [f"### {path.name}", ""]
    if not records:
        return [*lines, "The file is empty.", ""]
    header, rows = records[0], records[1:]
    table = markdown_table(header, rows)
    if len(rows) > MAX_OPEN_ROWS:
        summary = f"{len(rows)} rows, {len(header)} columns"
        table = ["<details>", f"<summary>{summary}</summary>", "", *table, "", "</details>"]
    lines += [*table, ""]
    figure = path.with_suffix(".png")
    if figure.exists():
        lines += [f"Figure: [{figure.name}]({relative_link(figure, page)})", ""]
    return lines


def build_page(results: Path, page: Path) -> str:
    """The whole Markdown page for the CSV files in ``results``, with links relative to ``page``."""
    scripts = sorted(p.stem for p in BENCHMARKS.glob("*.py") if p.stem not in NOT_BENCHMARKS)
    scripts.sort(key=lambda name: SCRIPT_ORDER.index(name) if name in SCRIPT_ORDER else len(SCRIPT_ORDER))
    groups: dict[str | None, list[Path]] = {name: [] for name in scripts}
    groups[None] = []
    for path in sorted(results.glob("*.csv")):
        groups[script_for(path.stem, scripts)].append(path)
    for name, paths in groups.items():  # the file named after its script first
        paths.sort(key=lambda path, name=name: (path.stem != name, path.name))

    lines = [
        "<!-- Generated by `python benchmarks/performance_doc.py` from benchmarks/results/*.csv:"
        " do not edit by hand. -->",
        "# Benchmark results",
        "",
        "Each table is a CSV file under `benchmarks/results/` as its benchmark script last wrote it; the text"
        " above the tables comes from the script's module docstring, which defines every column. README.md's"
        " Performance section summarises these figures and says when and on which machine they were measured.",
        "Numbers are rounded for reading: floats to 4 significant digits, numbers from 1,000 up to whole numbers"
        " with thousands separators; the CSV files keep every digit.",
        "",
    ]
    contents = []
    for name, paths in groups.items():
        if paths:
            heading = f"{name}.py" if name else "Other results"
            files = ", ".join(f"[{p.name}](#{anchor(p.name)})" for p in paths)
            contents.append(f"- [{heading}](#{anchor(heading)}): {files}")
    lines += [*contents, ""]

    for name, paths in groups.items():
        if not paths:
            continue
        if name is None:
            lines += ["## Other results", "", "No benchmark script is named after these files.", ""]
        else:
            script = BENCHMARKS / f"{name}.py"
            lines += [f"## {script.name}", "", *describe(script), ""]
            lines += [f"Full description: [benchmarks/{script.name}]({relative_link(script, page)}).", ""]
            figure = results / f"{name}.png"
            if figure.exists() and not (results / f"{name}.csv").exists():
                lines += [f"Figure: [{figure.name}]({relative_link(figure, page)})", ""]
        for path in paths:
            lines += csv_section(path, page)
    return "\n".join(lines).rstrip("\n") + "\n"


def main(argv: list[str] | None = None) -> int:
    """Write the page; ``argv`` as on the command line (default ``sys.argv[1:]``). Returns the exit status, 0."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="Markdown file to write (docs/performance.md)")
    args = parser.parse_args(argv)
    page = build_page(RESULTS, args.out)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(page, encoding="utf-8", newline="\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
