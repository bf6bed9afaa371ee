"""The sweep benchmarks of issue 17 (equation_of_state.py, sweep.py) run in their ``--quick`` mode.

Each script runs in a subprocess into a temporary folder; the tests read its CSV files and check what the
numbers must satisfy (never a speed): the pooled Z against Henderson's equation at low density, error bars
that combine the seeds, a rerun served from the cache, the same table from every sweep configuration.
"""

import math

import pytest
from benchscripts import read_csv, run_quick
from paths import BENCHMARKS

import discsim as ds


# --- equation_of_state.py -------------------------------------------------------------------
@pytest.fixture(scope="module")
def equation_of_state(tmp_path_factory):
    results = tmp_path_factory.mktemp("equation_of_state")
    first = run_quick("equation_of_state.py", results)
    csv_first = (results / "equation_of_state.csv").read_text() if first.returncode == 0 else ""
    second = run_quick("equation_of_state.py", results)
    return first, second, results, csv_first


@pytest.mark.slow  # the module's fixture runs the script twice: 5 s
def test_equation_of_state_quick_writes_its_csv_and_figure(equation_of_state):
    first, _, results, _ = equation_of_state
    assert first.returncode == 0, first.stderr
    assert (results / "equation_of_state.png").stat().st_size > 10_000
    rows = read_csv(results / "equation_of_state.csv")
    assert [float(r["packing_fraction"]) for r in rows] == [0.1, 0.4, 0.7]
    for row in rows:
        eta, z, err = float(row["packing_fraction"]), float(row["z"]), float(row["z_err"])
        assert int(row["seeds"]) == 2
        assert float(row["henderson_z"]) == pytest.approx(float(ds.henderson_z(eta)))
        assert float(row["virial_z"]) == pytest.approx(float(ds.virial_z(eta)))
        # the error bar is the larger of the two estimates, and the residual is in its units
        assert err == pytest.approx(max(float(row["z_err_batch"]), float(row["z_err_seeds"])))
        assert float(row["residual_henderson"]) == pytest.approx((z - float(row["henderson_z"])) / err)
        assert z > 1.0 and err > 0.0
    dilute = rows[0]
    assert abs(float(dilute["z"]) - float(dilute["henderson_z"])) < 6 * float(dilute["z_err"])
    # the dense point was run again with four times the melting, and compared
    dense = rows[-1]
    assert float(dense["check_equilibrate"]) == 4 * float(dense["equilibrate"])
    assert math.isfinite(float(dense["check_difference_sigma"]))
    assert rows[0]["check_z"] == ""


@pytest.mark.slow
def test_equation_of_state_rerun_reads_the_cache(equation_of_state):
    first, second, results, csv_first = equation_of_state
    assert first.returncode == 0, first.stderr
    assert second.returncode == 0, second.stderr
    assert "6 tasks (6 ran, 0 from the cache" in first.stdout
    assert "6 tasks (0 ran, 6 from the cache, 0 failed)" in second.stdout
    assert "2 tasks (0 ran, 2 from the cache, 0 failed)" in second.stdout
    assert (results / "equation_of_state.csv").read_text() == csv_first
    assert (results / "cache" / "equation_of_state_quick" / "discsim-sweep.json").is_file()


# --- sweep.py --------------------------------------------------------------------------------
@pytest.mark.slow
def test_sweep_quick_times_every_configuration(tmp_path):
    pytest.importorskip("distributed")
    done = run_quick("sweep.py", tmp_path)
    assert done.returncode == 0, done.stderr
    assert "Every configuration gave the same table" in done.stdout
    rows = read_csv(tmp_path / "sweep.csv")
    assert [(r["path"], int(r["workers"])) for r in rows] == [("local", 1), ("local", 2), ("dask", 1), ("dask", 2)]
    for row in rows:
        assert int(row["tasks"]) == 6  # 3 packing fractions x 2 seeds
        assert float(row["wall_s"]) > 0
        assert (row["path"] == "dask") == math.isfinite(float(row["cluster_start_s"]))
        if row["workers"] == "1":
            assert float(row["speedup"]) == 1.0
    overhead = read_csv(tmp_path / "sweep_overhead.csv")
    assert [(r["path"], int(r["workers"])) for r in overhead] == [("in-process", 0), ("local", 2), ("dask", 2)]
    assert float(overhead[0]["overhead_per_task_ms"]) == 0.0
    for row in overhead:
        assert (int(row["tasks_small"]), int(row["tasks_large"])) == (5, 20)
        assert float(row["wall_large_s"]) > 0


def test_sweep_overhead_is_the_slope_between_the_two_sweeps(monkeypatch):
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    import sweep as script

    def run(small, large):
        return {"wall_small": small, "wall_large": large, "tasks_small": 50, "tasks_large": 450, "cluster_start": 0}

    runs = {
        ("in-process", 0): [run(0.01, 0.05), run(0.01, 0.05), run(0.02, 0.06)],  # 0.1 ms a task
        ("dask", 2): [run(1.0, 3.0), run(1.1, 3.1), run(1.0, 5.0)],  # 5, 5 and 10 ms a task
    }
    for group in runs.values():
        for r in group:
            r["load"] = 1.0
    rows = {row["path"]: row for row in script.overhead_rows(runs)}
    assert rows["in-process"]["overhead_per_task_ms"] == 0.0
    assert rows["dask"]["per_task_ms"] == pytest.approx(5.0)  # the median slope
    assert rows["dask"]["overhead_per_task_ms"] == pytest.approx(4.9)
    assert rows["dask"]["fixed_s"] == pytest.approx(0.75)  # 1.0 - 50 x 5 ms
    assert script.nothing(3, seed=1) == {"echo": 3}
