"""benchmarks/hexatic.py runs in its quick mode: both algorithms, the pooled rows, the verdict and the figure (issue
29, item 4)."""

import csv
import importlib.util
import sys

import pytest
from paths import BENCHMARKS


@pytest.mark.slow
def test_quick_mode_writes_a_row_per_algorithm_and_packing(tmp_path, capsys):
    spec = importlib.util.spec_from_file_location("hexatic_benchmark", BENCHMARKS / "hexatic.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(sys.modules, "hexatic_benchmark", module)
        patch.syspath_prepend(str(BENCHMARKS))
        spec.loader.exec_module(module)
        assert module.main(["--quick", "--workers", "0", "--results", str(tmp_path)]) == 0
    with open(tmp_path / "hexatic.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [(r["algorithm"], float(r["packing_fraction"])) for r in rows] == [
        (a, p) for a in ("edmd", "ecmc") for p in (0.698, 0.704, 0.708, 0.712, 0.716)
    ]
    assert all(8.0 < float(r["beta_p_d2"]) < 12.5 and float(r["err"]) > 0 for r in rows)
    assert (tmp_path / "hexatic.png").stat().st_size > 10_000
    out = capsys.readouterr().out
    assert out.count("sigma from the published") == 2
    # run again: every task comes from the cache, the same table
    with pytest.MonkeyPatch.context() as patch:
        patch.syspath_prepend(str(BENCHMARKS))
        assert module.main(["--quick", "--workers", "0", "--results", str(tmp_path)]) == 0
    again = capsys.readouterr()
    assert (again.out + again.err).count("(0 ran, 10 cached)") == 2
    with open(tmp_path / "hexatic.csv", newline="") as handle:
        assert list(csv.DictReader(handle)) == rows
