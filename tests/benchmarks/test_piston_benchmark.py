"""benchmarks/piston.py runs in its quick mode: rows for both ensembles' Z and both compressions, and the figure."""

import csv
import importlib.util
import sys

import pytest
from paths import BENCHMARKS


@pytest.mark.slow
def test_quick_mode_writes_the_equation_of_state_and_the_compressions(tmp_path):
    spec = importlib.util.spec_from_file_location("piston_benchmark", BENCHMARKS / "piston.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(sys.modules, "piston_benchmark", module)
        patch.syspath_prepend(str(BENCHMARKS))
        spec.loader.exec_module(module)
        assert module.main(["--quick", "--results", str(tmp_path)]) == 0
    with open(tmp_path / "piston.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert {row["part"] for row in rows} == {"EOS", "slow compression", "sudden compression"}
    eos = [row for row in rows if row["part"] == "EOS"]
    assert len(eos) == 4 and all(float(row["z"]) > 1.0 for row in eos)
    assert (tmp_path / "piston.png").stat().st_size > 10_000
