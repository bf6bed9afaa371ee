"""benchmarks/equilibration.py runs in its quick mode and writes one row per analysis (issue 29, item 2)."""

import csv
import importlib.util
import sys

import pytest
from paths import BENCHMARKS


@pytest.mark.slow
def test_quick_mode_writes_its_rows(tmp_path):
    spec = importlib.util.spec_from_file_location("equilibration_benchmark", BENCHMARKS / "equilibration.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(sys.modules, "equilibration_benchmark", module)
        spec.loader.exec_module(module)
        assert module.main(["--quick", "--results", str(tmp_path)]) == 0
    with open(tmp_path / "equilibration_quick.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [row["since_asked"] for row in rows][1::2] == ["auto"] * 3  # lattice short, lattice long, random short
    assert rows[0]["warned"] == "True"  # 20 collisions per disc from the lattice at 0.70: psi6 still falls
    assert all(float(row["z_err"]) > 0 for row in rows)
