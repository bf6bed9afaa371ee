"""benchmarks/ab_throughput.py runs in its quick mode and times the tree it is told to.

No test here asserts a speed: timings belong to the script's output, not to pass/fail.
"""

import csv
import importlib.util
import shutil
import sys

import pytest
from paths import ROOT

from discsim._numba import available as numba_available

REPO = ROOT
BENCHMARKS = REPO / "benchmarks"


@pytest.fixture(scope="module")
def ab_throughput():
    """benchmarks/ab_throughput.py as a module (it imports ``benchutils`` from its own folder)."""
    spec = importlib.util.spec_from_file_location("ab_throughput", BENCHMARKS / "ab_throughput.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.syspath_prepend(str(BENCHMARKS))
        patch.setitem(sys.modules, "ab_throughput", module)
        spec.loader.exec_module(module)
        yield module


@pytest.mark.slow
def test_quick_run_against_itself_writes_one_row(ab_throughput, tmp_path):
    assert ab_throughput.main(["--quick", "--base", str(REPO), "--out", str(tmp_path)]) == 0
    with open(tmp_path / "ab_throughput.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 1  # N = 500, phi = 0.3
    row = rows[0]
    assert (int(row["n"]), float(row["packing"]), int(row["repeats"])) == (500, 0.3, 1)
    assert float(row["ratio_median"]) > 0
    assert row["base_label"] == row["new_label"]  # one tree on both sides
    assert (tmp_path / "ab_throughput.png").stat().st_size > 0


def test_a_tree_without_discsim_fails_loudly(ab_throughput, tmp_path):
    # PYTHONPATH points at an empty folder: the probe must not time an installed discsim instead.
    with pytest.raises(RuntimeError, match="failed"):
        ab_throughput.measure(tmp_path, 10, 0.3, 0, 10, tmp_path)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("valgrind") is None, reason="counting instructions needs valgrind")
def test_instruction_counts_run_and_write_their_table(tmp_path):
    spec = importlib.util.spec_from_file_location("ab_instructions", BENCHMARKS / "ab_instructions.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.syspath_prepend(str(BENCHMARKS))
        spec.loader.exec_module(module)
        assert module.main(["--quick", "--base", str(REPO), "--out", str(tmp_path)]) == 0
    with open(tmp_path / "ab_instructions.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 1 and float(rows[0]["base_per_collision"]) > 0
    # The same tree on both sides; a tiny run's ratio still moves by a few percent (garbage collections,
    # address-dependent hashing), which the full run's 40,000 counted collisions average out.
    assert 0.5 < float(rows[0]["ratio"]) < 2.0


@pytest.mark.slow  # two first compiles of the event loop
@pytest.mark.skipif(not numba_available(), reason="the compiled backend needs numba")
def test_compile_mode_times_cold_and_warm_starts(ab_throughput, tmp_path):
    assert ab_throughput.main(["--compile", "--repeats", "1", "--base", str(REPO), "--out", str(tmp_path)]) == 0
    with open(tmp_path / "ab_throughput_compile.csv", newline="") as handle:
        rows = {row["start"]: row for row in csv.DictReader(handle)}
    assert set(rows) == {"cold", "warm"}
    for side in ("base", "new"):  # a cold start compiles: it takes longer than a warm one, which loads
        assert float(rows["cold"][f"{side}_seconds"]) > float(rows["warm"][f"{side}_seconds"]) > 0


@pytest.mark.slow
@pytest.mark.skipif(not numba_available(), reason="the compiled backend needs numba")
def test_quick_run_of_the_compiled_loop(ab_throughput, tmp_path):
    assert ab_throughput.main(["--quick", "--backend", "numba", "--base", str(REPO), "--out", str(tmp_path)]) == 0
    with open(tmp_path / "ab_throughput_numba.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 1 and rows[0]["backend"] == "numba" and float(rows[0]["new_median"]) > 0


@pytest.mark.slow
def test_fixed_step_mode_times_frames(ab_throughput, tmp_path):
    argv = ["--quick", "--engine", "fixed-step", "--collisions", "20", "--base", str(REPO), "--out", str(tmp_path)]
    assert ab_throughput.main(argv) == 0
    with open(tmp_path / "ab_throughput_frames.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 1 and float(rows[0]["new_median"]) > 0 and rows[0]["backend"] == "python"
