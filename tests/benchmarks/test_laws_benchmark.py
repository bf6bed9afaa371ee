"""benchmarks/laws.py runs in its quick mode: a row per backend and law, the elastic one the reference (issue 27)."""

import csv
import importlib.util
import sys

import pytest
from paths import BENCHMARKS


@pytest.mark.slow
def test_quick_mode_writes_a_row_per_backend_and_law(tmp_path):
    spec = importlib.util.spec_from_file_location("laws_benchmark", BENCHMARKS / "laws.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(sys.modules, "laws_benchmark", module)
        patch.syspath_prepend(str(BENCHMARKS))
        spec.loader.exec_module(module)
        assert module.main(["--quick", "--results", str(tmp_path)]) == 0
    with open(tmp_path / "laws.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    laws = {"elastic", "gravity", "restitution", "gravity+restitution", "rough", "perfectly rough"}
    laws |= {"drag", "gravity+drag", "sensors", "moving segment", "piston"}
    assert {row["law"] for row in rows} == laws
    for row in rows:
        assert float(row["collisions_per_s"]) > 0
        if row["law"] == "elastic":
            assert float(row["ratio_to_elastic"]) == 1.0
