"""The PIT benchmark scripts of issue 4 (event counts, accuracy map) run in their ``--quick`` mode.

Each script runs once in a subprocess into a temporary folder; the tests read
its CSV files. No test asserts a speed: timings belong to the scripts' output.
"""

import math
import sys

import pytest
from benchscripts import read_csv, run_quick
from paths import BENCHMARKS


def _number(text: str) -> float:
    return float(text) if text not in ("", None) else math.nan


# --- event_counts.py -------------------------------------------------------------------
@pytest.fixture(scope="module")
def event_counts(tmp_path_factory):
    results = tmp_path_factory.mktemp("event_counts")
    done = run_quick("event_counts.py", results)
    return done, results


@pytest.mark.slow
def test_event_counts_quick_runs_and_writes_its_files(event_counts):
    done, results = event_counts
    assert done.returncode == 0, done.stderr
    assert (results / "event_counts.png").stat().st_size > 0
    assert "missed %" in done.stdout and "work units" in done.stdout
    rows = read_csv(results / "event_counts.csv")
    expected = {
        "scenario",
        "method",
        "policy",
        "fps",
        "step",
        "frames",
        "pair_tests",
        "detections",
        "collisions",
        "wall_hits",
        "cell_crossings",
        "stale",
        "predictions",
        "work_units",
        "seconds",
        "missed_pct",
        "spurious_pct",
        "mean_delay",
        "max_delay",
        "mean_direction_error_deg",
        "max_direction_error_deg",
        "position_error_max",
        "max_overlap",
        "energy_change",
    }
    assert expected <= set(rows[0])
    scenarios = {r["scenario"] for r in rows}
    assert {"missed_collision", "wrong_direction", "multiple_collisions", "delay"} <= scenarios
    assert sum(s.startswith("gas") for s in scenarios) == 2


@pytest.mark.slow
def test_event_counts_pic_is_the_reference(event_counts):
    done, results = event_counts
    assert done.returncode == 0, done.stderr
    rows = read_csv(results / "event_counts.csv")
    pic = [r for r in rows if r["method"] == "PIC"]
    assert len(pic) == len({r["scenario"] for r in rows})
    for row in pic:
        # PIC against a second PIC run (the other event queue): nothing missed, nothing late.
        assert _number(row["missed_pct"]) == 0.0
        assert _number(row["spurious_pct"]) == 0.0
        assert _number(row["max_delay"]) < 1e-9
        assert _number(row["max_overlap"]) < 1e-9
        assert int(row["predictions"]) >= int(row["collisions"]) > 0
        assert abs(_number(row["energy_change"])) < 1e-12


@pytest.mark.slow
def test_event_counts_pit_work_grows_with_the_frame_rate_and_buys_accuracy(event_counts):
    done, results = event_counts
    assert done.returncode == 0, done.stderr
    rows = read_csv(results / "event_counts.csv")
    for scenario in {r["scenario"] for r in rows}:
        pit = [r for r in rows if r["scenario"] == scenario and r["policy"] == "resolve"]
        pit.sort(key=lambda r: _number(r["fps"]))
        slow, fast = pit[0], pit[-1]
        horizon = _number(slow["horizon"])
        assert int(slow["frames"]) == round(_number(slow["fps"]) * horizon)
        assert int(fast["frames"]) == round(_number(fast["fps"]) * horizon)
        assert int(fast["work_units"]) > int(slow["work_units"])
        assert _number(fast["missed_pct"]) <= _number(slow["missed_pct"])
        # resolve conserves kinetic energy
        assert abs(_number(fast["energy_change"])) < 1e-12
    missed = next(r for r in rows if r["scenario"] == "missed_collision" and r["policy"] == "resolve")
    assert _number(missed["missed_pct"]) == 100.0  # the study's case 1 at its own frame rate


# --- accuracy_map.py -------------------------------------------------------------------
@pytest.fixture(scope="module")
def accuracy_map(tmp_path_factory):
    results = tmp_path_factory.mktemp("accuracy_map")
    done = run_quick("accuracy_map.py", results)
    return done, results


@pytest.mark.slow
def test_accuracy_map_quick_runs_and_writes_its_files(accuracy_map):
    done, results = accuracy_map
    assert done.returncode == 0, done.stderr
    assert (results / "accuracy_map.png").stat().st_size > 0
    assert "boundary" in done.stdout
    rows = read_csv(results / "accuracy_map.csv")
    expected = {
        "policy",
        "packing_fraction",
        "step",
        "status",
        "truth_collisions",
        "missed_fraction",
        "mean_direction_error_deg",
        "mean_abs_delay_free_times",
        "good",
    }
    assert expected <= set(rows[0])
    policies = {r["policy"] for r in rows}
    assert {"resolve", "revert", "separate"} <= policies
    steps = {r["step"] for r in rows}
    fractions = {r["packing_fraction"] for r in rows}
    assert len(rows) == len(policies) * len(steps) * len(fractions)  # a full grid
    boundary = read_csv(results / "accuracy_map_boundary.csv")
    assert len(boundary) == len(policies) * len(fractions)


@pytest.mark.slow
def test_accuracy_map_errors_grow_with_the_step(accuracy_map):
    done, results = accuracy_map
    assert done.returncode == 0, done.stderr
    rows = [r for r in read_csv(results / "accuracy_map.csv") if r["status"] == "ok"]
    for row in rows:
        assert int(row["truth_collisions"]) > 0
        assert 0.0 <= _number(row["missed_fraction"]) <= 1.0
        good = _number(row["missed_fraction"]) <= 0.01 and _number(row["mean_direction_error_deg"]) <= 1.0
        assert (row["good"] == "True") == good
    for policy in ("resolve", "revert", "separate"):
        for eta in {r["packing_fraction"] for r in rows}:
            cells = sorted(
                (r for r in rows if r["policy"] == policy and r["packing_fraction"] == eta),
                key=lambda r: _number(r["step"]),
            )
            small, large = cells[0], cells[-1]
            assert _number(small["missed_fraction"]) <= _number(large["missed_fraction"])
            assert _number(small["mean_direction_error_deg"]) <= _number(large["mean_direction_error_deg"])
            assert _number(large["missed_fraction"]) > 0.5  # ten radii per frame: most collisions missed


@pytest.mark.slow
def test_accuracy_map_boundary_is_consistent_with_the_cells(accuracy_map):
    done, results = accuracy_map
    assert done.returncode == 0, done.stderr
    rows = read_csv(results / "accuracy_map.csv")
    for limit in read_csv(results / "accuracy_map_boundary.csv"):
        cells = [
            r for r in rows if r["policy"] == limit["policy"] and r["packing_fraction"] == limit["packing_fraction"]
        ]
        largest = _number(limit["largest_good_step"])
        for cell in cells:
            if _number(cell["step"]) <= largest:
                assert cell["good"] == "True"
        first_bad = _number(limit["first_bad_step"])
        if not math.isnan(first_bad):
            bad = next(c for c in cells if _number(c["step"]) == first_bad)
            assert bad["good"] != "True"


@pytest.mark.slow
def test_accuracy_map_rerun_reads_its_cache(accuracy_map):
    """The map is a cached sweep: a second run computes nothing and writes the same files."""
    done, results = accuracy_map
    assert done.returncode == 0, done.stderr
    assert "sweep of 40 tasks" in done.stdout and "40 ran" in done.stdout
    before = {name: (results / name).read_text() for name in ("accuracy_map.csv", "accuracy_map_boundary.csv")}
    again = run_quick("accuracy_map.py", results)
    assert again.returncode == 0, again.stderr
    assert "0 ran (0 s in them), 40 from the cache, 0 failed" in again.stdout
    for name, text in before.items():
        assert (results / name).read_text() == text


def test_accuracy_map_pools_the_seeds(monkeypatch):
    """pool() adds the counts and sums of the seeds; a seed not measured leaves the cell without numbers."""
    import importlib.util

    import pandas as pd

    monkeypatch.syspath_prepend(str(BENCHMARKS))
    spec = importlib.util.spec_from_file_location("accuracy_map", BENCHMARKS / "accuracy_map.py")
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "accuracy_map", module)
    spec.loader.exec_module(module)

    def cell(seed, missed, angle_sum, status="ok", error=None):
        return {
            "packing_fraction": 0.3, "policy": "resolve", "step": 0.5, "seed": seed, "status": status,
            "horizon": 4.0, "free_time": 2.0, "frames": 9, "pair_tests": 100, "truth_collisions": 50,
            "matched": 50 - missed, "missed": missed, "spurious": 1, "angle_count": 50 - missed,
            "angle_sum": angle_sum, "angle_max": angle_sum / 10, "delay_count": 50 - missed,
            "abs_delay_sum": 0.5, "delay_sum_frames": 2.0, "max_overlap": 0.01 * seed, "error": error,
        }  # fmt: skip

    config = module.QUICK
    rows = module.pool(pd.DataFrame([cell(1, 0, 10.0), cell(2, 2, 38.0)]), config)
    assert len(rows) == 1
    row = rows[0]
    assert row["status"] == "ok" and row["seeds"] == 2
    assert row["truth_collisions"] == 100 and row["missed"] == 2 and row["missed_fraction"] == 0.02
    assert row["mean_direction_error_deg"] == pytest.approx(48.0 / 98)
    assert row["max_direction_error_deg"] == pytest.approx(3.8) and row["max_overlap"] == pytest.approx(0.02)
    assert row["frames"] == 9 and row["collisions_per_disc"] == 2.0 * 100 / (2 * config.n)
    assert row["good"] is False  # 2% missed
    assert type(row["missed_fraction"]) is float  # plain floats: the CSV writes repr()
    failed = module.pool(pd.DataFrame([cell(1, 0, 1.0), cell(2, 0, 1.0, status=None, error="ValueError: x")]), config)
    assert failed[0]["status"] == "failed: ValueError: x" and "missed_fraction" not in failed[0]
    over = module.pool(pd.DataFrame([cell(1, 0, 1.0, status="over budget"), cell(2, 0, 1.0)]), config)
    assert over[0]["status"] == "over budget"


def test_accuracy_map_docstring_examples(monkeypatch):
    import doctest
    import importlib.util

    monkeypatch.syspath_prepend(str(BENCHMARKS))  # the script imports benchutils from its own folder
    spec = importlib.util.spec_from_file_location("accuracy_map", BENCHMARKS / "accuracy_map.py")
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "accuracy_map", module)  # its dataclasses look themselves up there
    spec.loader.exec_module(module)
    assert doctest.testmod(module, raise_on_error=False).failed == 0
