"""The layers of docs/architecture.md hold: module-level imports point down (or sideways), never up."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from paths import PACKAGE

#: Floor of each module or package, lowest first (docs/architecture.md).
FLOORS = {
    "ground": ["model", "queue", "errors", "_validate", "_interrupt", "_numba", "_compiled"],
    "model": ["scene", "scenarios", "events", "cells", "repair"],
    "physics": ["physics", "kernels", "trajectory"],
    "engines": ["engines"],
    "top": ["run", "io", "analysis", "cli", "plot", "view", "__init__", "__main__"],
}
LEVEL = {name: level for level, names in enumerate(FLOORS.values()) for name in names}


def _floor(module: str) -> int:
    """The floor of ``discsim.a.b`` (by its first part)."""
    return LEVEL[module.split(".")[1] if "." in module else "__init__"]


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        yield ".".join(parts[:-1] if parts[-1] == "__init__" else parts), path


def _top_level_imports(path: Path) -> list[str]:
    """discsim modules imported at module level (not inside functions: those are the documented late calls)."""
    tree = ast.parse(path.read_text())
    found = []
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("discsim"):
            found.append(node.module)
        elif isinstance(node, ast.Import):
            found += [alias.name for alias in node.names if alias.name.startswith("discsim")]
    return found


@pytest.mark.parametrize(("module", "path"), list(_modules()), ids=[m for m, _ in _modules()])
def test_imports_point_down(module, path):
    if module == "discsim":
        return  # the package's front door re-exports every floor
    for imported in _top_level_imports(path):
        if imported == "discsim":
            continue
        assert _floor(imported) <= _floor(module), f"{module} (floor {_floor(module)}) imports {imported} from above"


def test_the_container_format_knows_no_engine():
    assert not [m for m in _top_level_imports(PACKAGE / "io" / "container.py") if m != "discsim.errors"]


def test_backends_know_no_front_class():
    for path in (PACKAGE / "engines" / "event_driven" / "python").glob("*.py"):
        assert "discsim.engines.event_driven.engine" not in _top_level_imports(path)
