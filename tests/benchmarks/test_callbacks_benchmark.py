"""benchmarks/callbacks.py runs in its quick mode: a row per backend and way of calling back (issue 28, item 5)."""

import csv
import importlib.util
import sys

import pytest
from paths import BENCHMARKS


@pytest.mark.slow
def test_quick_mode_writes_a_row_per_backend_and_way(tmp_path):
    spec = importlib.util.spec_from_file_location("callbacks_benchmark", BENCHMARKS / "callbacks.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(sys.modules, "callbacks_benchmark", module)
        patch.syspath_prepend(str(BENCHMARKS))
        spec.loader.exec_module(module)
        assert module.main(["--quick", "--results", str(tmp_path)]) == 0
    with open(tmp_path / "callbacks.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert {row["way"] for row in rows} == {"none", "look", "exact", "exact+set"}
    by = {(r["backend"], r["way"]): float(r["us_per_event"]) for r in rows}
    for backend in {r["backend"] for r in rows}:
        assert by[(backend, "look")] < by[(backend, "exact")]  # looking costs less than stopping at every event
