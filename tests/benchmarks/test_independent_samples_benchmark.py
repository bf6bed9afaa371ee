"""benchmarks/independent_samples.py runs in its quick mode: both algorithms, g and the time per independent sample."""

import csv
import importlib.util
import sys

import pytest
from paths import BENCHMARKS


@pytest.mark.slow
def test_quick_mode_writes_a_row_per_algorithm(tmp_path):
    script = BENCHMARKS / "independent_samples.py"
    spec = importlib.util.spec_from_file_location("independent_samples_benchmark", script)
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(sys.modules, "independent_samples_benchmark", module)
        patch.syspath_prepend(str(BENCHMARKS))
        spec.loader.exec_module(module)
        assert module.main(["--quick", "--results", str(tmp_path)]) == 0
    with open(tmp_path / "independent_samples.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [r["algorithm"] for r in rows] == ["edmd", "ecmc"]
    assert all(float(r["g"]) >= 1.0 and float(r["s_per_independent"]) > 0 and 6.0 < float(r["z"]) < 11.0 for r in rows)
    assert rows[0]["edmd_over_ecmc"] == rows[1]["edmd_over_ecmc"]
