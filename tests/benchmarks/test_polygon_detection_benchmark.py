"""benchmarks/polygon_detection.py runs in its quick mode: a row per shape and turn, swept volumes missing nothing,
and the figure."""

import csv
import importlib.util
import sys

import pytest
from paths import BENCHMARKS


@pytest.mark.slow
def test_quick_mode_writes_the_detectors_rows_and_the_figure(tmp_path):
    spec = importlib.util.spec_from_file_location("polygon_detection_benchmark", BENCHMARKS / "polygon_detection.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(sys.modules, "polygon_detection_benchmark", module)
        patch.syspath_prepend(str(BENCHMARKS))
        spec.loader.exec_module(module)
        assert module.main(["--quick", "--results", str(tmp_path)]) == 0
    with open(tmp_path / "polygon_detection_quick.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [(row["sides"], row["turn"]) for row in rows] == [("4", "0.3"), ("4", "2.4"), ("12", "0.3"), ("12", "2.4")]
    assert all(int(row["contacts"]) > 0 for row in rows)
    slow, fast = float(rows[0]["pit_missed"]), float(rows[1]["pit_missed"])
    assert fast > slow  # PIT misses more as the squares turn faster per frame
    assert all(float(row["pic_agrees"]) == 1.0 for row in rows)  # the certified time is the brute-force one
    assert (tmp_path / "polygon_detection_quick.png").stat().st_size > 10_000
