"""The benchmark scripts run (in their ``--quick`` mode) and the naive baseline agrees with discsim.

No test here asserts a speed: timings belong to the scripts' output, not to pass/fail.
"""

import doctest
import importlib.util
import inspect
import math
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from benchscripts import read_csv, run_quick
from paths import BENCHMARKS

import discsim as ds


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


naive = _load("naive_event_driven", BENCHMARKS / "baselines" / "naive_event_driven.py")
benchutils = _load("benchutils", BENCHMARKS / "benchutils.py")


# --- the scripts run -------------------------------------------------------------------
@pytest.fixture(scope="module")
def throughput():
    """benchmarks/throughput.py as a module (it imports ``benchutils`` from its own folder)."""
    spec = importlib.util.spec_from_file_location("throughput", BENCHMARKS / "throughput.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.syspath_prepend(str(BENCHMARKS))
        patch.setitem(sys.modules, "throughput", module)  # its dataclasses look their module up there
        spec.loader.exec_module(module)
        yield module


_TARGET_KEYS = [
    "collisions_per_s_n1e4_phi0.3",
    "slowdown_n1e3_over_n1e5_phi0.3",
    "slowdown_n1e3_over_n1e5_phi0.7",
    "peak_rss_mb_n1e5",
]


@pytest.mark.slow
def test_throughput_quick_writes_its_csv_and_plot(tmp_path):
    done = run_quick("throughput.py", tmp_path)
    assert done.returncode == 0, done.stderr
    default_queue = inspect.signature(ds.EventDriven).parameters["queue"].default
    rows = read_csv(tmp_path / "throughput.csv")
    assert len(rows) == 4  # 2 sizes x 2 packing fractions
    for row in rows:
        assert row["queue"] == default_queue  # the main section times the engine's default queue
        assert float(row["collisions_per_s"]) > 0
        assert 0 < int(row["max_queue"]) <= int(row["n"])  # one pending event per disc at most
        assert float(row["peak_mb"]) > 0
    queues = read_csv(tmp_path / "throughput_queue.csv")
    assert [r["queue"] for r in queues] == ["calendar", "sorted", "heap"]  # N = 400 only
    for row in queues:
        n = int(row["n"])
        assert float(row["collisions_per_s"]) > 0
        assert 0 < int(row["max_queue"]) <= n
        assert 0 < int(row["storage"]) <= 3 * n + 64  # dead entries included; the calendar's bound
        assert float(row["speedup_vs_sorted"]) > 0
    by_queue = {r["queue"]: r for r in queues}
    assert float(by_queue["sorted"]["speedup_vs_sorted"]) == 1.0
    assert int(by_queue["sorted"]["storage"]) <= int(by_queue["sorted"]["n"])  # no dead entries
    assert len({r["timed_collisions"] for r in queues}) == 1
    # The targets need N = 10^3..10^5, which quick mode does not run: every row says so.
    targets = read_csv(tmp_path / "throughput_targets.csv")
    assert [r["target"] for r in targets] == _TARGET_KEYS
    assert [(r["comparison"], float(r["limit"])) for r in targets] == [
        (">=", 40_000.0),
        ("<=", 2.0),
        ("<=", 2.0),
        ("<", 300.0),
    ]
    assert all(r["status"] == "not measured" and math.isnan(float(r["measured"])) for r in targets)
    assert all(r["queue"] == default_queue for r in targets)
    assert (tmp_path / "throughput.png").stat().st_size > 0
    assert "coll/s" in done.stdout and "vs sorted" in done.stdout and "storage" in done.stdout
    assert "targets of the engine issue" in done.stdout and "not measured" in done.stdout
    pit = read_csv(tmp_path / "throughput_pit.csv")
    assert {r["broad_phase"] for r in pit} == {"grid", "all-pairs"}
    assert all(float(r["frames_per_s"]) > 0 and float(r["pair_tests_per_s"]) > 0 for r in pit)
    costs = read_csv(tmp_path / "throughput_crossover.csv")
    assert costs and all(float(r["pic_s_per_time"]) > 0 and float(r["pit_s_per_time"]) > 0 for r in costs)
    assert (tmp_path / "throughput_pit.png").stat().st_size > 0


@pytest.mark.slow
def test_peers_quick_writes_its_csv_and_plot(tmp_path):
    done = run_quick("peers.py", tmp_path)
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "peers.csv")
    engines = {r["engine"] for r in rows}
    assert {"discsim", "naive", "billiards"} <= engines  # billiards appears even when skipped
    ran = [r for r in rows if r["engine"] in ("discsim", "naive") and r["status"] == "ok"]
    assert len(ran) == 4  # 2 sizes x 2 engines
    assert (tmp_path / "peers.png").stat().st_size > 0
    pit = read_csv(tmp_path / "peers_pit.csv")
    fixed = [r for r in pit if r["engine"] == "fixed_step"]
    assert fixed and float(fixed[0]["seconds_per_frame"]) > 0
    assert int(fixed[0]["matched"]) + int(fixed[0]["missed"]) == int(fixed[0]["truth"])


def _point(n: int, phi: float, rate: float, rss: float = math.nan) -> dict:
    return {
        "n": n,
        "packing_fraction": phi,
        "queue": "calendar",
        "collisions_per_s": rate,
        "rss_mb": rss,
        "rss_import_mb": 60.0,
        "peak_mb": 150.0,
    }


def test_targets_from_the_medians(throughput):
    rows = [
        _point(1_000, 0.3, 70_000.0),
        _point(10_000, 0.3, 40_000.0),  # exactly the target: met
        _point(100_000, 0.3, 20_000.0, rss=250.0),  # 3.5x slower: not met
        _point(1_000, 0.7, 30_000.0),
        _point(100_000, 0.7, 20_000.0, rss=320.0),  # 1.5x slower: met; the larger RSS counts
    ]
    targets = {t["target"]: t for t in throughput.target_rows(rows)}
    assert list(targets) == _TARGET_KEYS
    assert targets["collisions_per_s_n1e4_phi0.3"]["measured"] == 40_000.0
    assert targets["slowdown_n1e3_over_n1e5_phi0.3"]["measured"] == pytest.approx(3.5)
    assert targets["slowdown_n1e3_over_n1e5_phi0.7"]["measured"] == pytest.approx(1.5)
    assert targets["peak_rss_mb_n1e5"]["measured"] == 320.0
    assert "phi=0.7" in targets["peak_rss_mb_n1e5"]["note"]
    assert [t["status"] for t in targets.values()] == ["met", "not met", "met", "not met"]
    text = throughput.format_targets(list(targets.values()))
    assert "40,000" in text and "3.50" in text and "320" in text and text.count("not met") == 2


def test_slowdown_targets_note_each_repeat(throughput):
    """The slowdown notes pair the runs of both sizes by seed: one ratio per repeat."""
    rows = [_point(1_000, 0.3, 70_000.0), _point(100_000, 0.3, 35_000.0)]
    rows[0]["rates"], rows[1]["rates"] = (60_000.0, 70_000.0, 80_000.0), (40_000.0, 35_000.0, 32_000.0)
    targets = {t["target"]: t for t in throughput.target_rows(rows)}
    assert targets["slowdown_n1e3_over_n1e5_phi0.3"]["measured"] == pytest.approx(2.0)
    assert targets["slowdown_n1e3_over_n1e5_phi0.3"]["note"] == "per repeat (paired by seed): 1.50, 2.00, 2.50"
    assert targets["slowdown_n1e3_over_n1e5_phi0.7"]["note"] == ""  # not measured
    assert "1.50, 2.00, 2.50" in throughput.format_targets(list(targets.values()))


def test_targets_missing_points_are_not_measured(throughput):
    rows = [_point(1_000, 0.3, 70_000.0), _point(100_000, 0.3, 20_000.0)]  # no RSS, no 10^4, no phi 0.7
    statuses = [t["status"] for t in throughput.target_rows(rows)]
    assert statuses == ["not measured", "not met", "not measured", "not measured"]


# --- the naive baseline agrees with discsim event by event ------------------------------
def _events(sim, count: int) -> list:
    return [sim.step() for _ in range(count)]


def _groups(events, rel: float = 1e-9) -> list[list]:
    """Split a time-ordered event list into runs of events at the same time (within ``rel``)."""
    groups = []
    for event in events:
        if groups and math.isclose(event.time, groups[-1][0].time, rel_tol=rel, abs_tol=1e-12):
            groups[-1].append(event)
        else:
            groups.append([event])
    return groups


def _assert_same_events(expected, got):
    """Same times (1e-9 relative) and the same discs, event by event; simultaneous events in any order."""
    assert None not in expected and None not in got
    assert len(expected) == len(got)
    for a, b in zip(expected, got, strict=True):
        assert b.time == pytest.approx(a.time, rel=1e-9, abs=1e-12), (a, b)
    for group_a, group_b in zip(_groups(expected), _groups(got), strict=True):
        assert sorted(map(_who, group_a)) == sorted(map(_who, group_b)), (group_a, group_b)


def _who(event) -> tuple:
    return event.kind, min(event.i, event.j), max(event.i, event.j)


@pytest.mark.parametrize(
    ("n", "periodic"),
    [(20, False), (30, True)],
)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_naive_baseline_follows_event_driven(n, periodic, seed):
    discs, box = ds.random_gas(n, 0.3, periodic=periodic, seed=seed)
    expected = _events(ds.EventDriven(discs, box), 50)
    baseline = naive.NaiveEventDriven(discs, box)
    got = _events(baseline, 50)
    _assert_same_events(expected, got)
    assert baseline.counts["collisions"] + baseline.counts["wall_hits"] == 50


def test_naive_baseline_with_mixed_discs_and_an_obstacle():
    rng = np.random.default_rng(3)
    positions = [[3.0, 3.0], [9.0, 3.5], [5.0, 8.0], [12.0, 10.0], [8.0, 12.5], [15.0, 5.0]]
    radii = [1.0, 0.5, 1.5, 0.7, 1.0, 1.2]
    masses = [1.0, 0.3, 4.0, 1.0, np.inf, 2.0]
    velocities = rng.normal(size=(6, 2))
    velocities[4] = 0.0  # the obstacle rests
    discs = ds.Discs(positions, velocities, radii, masses)
    box = ds.Box(18.0, 15.0)
    # Roundoff grows about tenfold every few collisions here: by event 47 it passes 1e-9.
    expected = _events(ds.EventDriven(discs, box), 40)
    _assert_same_events(expected, _events(naive.NaiveEventDriven(discs, box), 40))


def test_naive_baseline_runs_to_a_time_and_conserves_energy():
    discs, box = ds.random_gas(25, 0.4, periodic=True, seed=5)
    reference = ds.EventDriven(discs, box).run(until=3.0)
    baseline = naive.NaiveEventDriven(discs, box).run(until=3.0)
    assert baseline.time == 3.0
    assert baseline.counts["collisions"] == reference.counts["collisions"]
    assert baseline.counts["refreshes"] >= 1  # the periodic box re-predicts everything now and then
    energy = 0.5 * float(np.sum(baseline.velocities**2))
    assert energy == pytest.approx(discs.kinetic_energy(), rel=1e-12)
    shift = box.displacement(reference.positions, baseline.positions)
    assert np.abs(shift).max() < 1e-8


def test_naive_baseline_docstring_example():
    assert doctest.testmod(naive, raise_on_error=False).failed == 0


# --- helpers ---------------------------------------------------------------------------
def test_time_limit_interrupts_a_long_block():
    if not hasattr(__import__("signal"), "setitimer"):
        pytest.skip("no SIGALRM on this platform")
    start = time.perf_counter()
    with pytest.raises(benchutils.TimeLimitExceeded), benchutils.time_limit(0.05):
        while True:
            pass
    assert time.perf_counter() - start < 5.0


def test_a_quick_run_writes_to_a_temporary_folder_unless_told_where(tmp_path):
    """A smoke run never overwrites the measured results in benchmarks/results/."""
    assert benchutils.parse_args("x", []).results == benchutils.DEFAULT_RESULTS
    quick = benchutils.parse_args("x", ["--quick"]).results
    assert quick.is_dir() and quick != benchutils.DEFAULT_RESULTS and benchutils.DEFAULT_RESULTS not in quick.parents
    quick.rmdir()
    assert benchutils.parse_args("x", ["--quick", "--results", str(tmp_path / "r")]).results == tmp_path / "r"


def test_format_table_docstring_example():
    assert doctest.testmod(benchutils, raise_on_error=False).failed == 0


@pytest.mark.slow
@pytest.mark.skipif(not ds._numba.available(), reason="numba is not installed (the fast extra)")
def test_backends_script_writes_both_backends_side_by_side(tmp_path):
    done = run_quick("backends.py", tmp_path)
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "backends.csv")
    assert {row["discs"] for row in rows} == {"monodisperse", "1:10 mixture"}
    for row in rows:
        assert float(row["python_rate"]) > 0 and float(row["numba_rate"]) > 0
        assert float(row["speedup"]) == pytest.approx(float(row["numba_rate"]) / float(row["python_rate"]))
    compile_rows = read_csv(tmp_path / "backends_compile.csv")
    assert {(row["cache"], row["scipy"]) for row in compile_rows} == {
        ("cold", "visible"),
        ("warm", "visible"),
        ("warm", "hidden"),
    }


@pytest.mark.slow  # 3 s
@pytest.mark.skipif(not ds._numba.available(), reason="numba is not installed (the fast extra)")
def test_scale_script_writes_a_row_per_gas_and_size_and_its_plot(tmp_path):
    done = run_quick("scale.py", tmp_path)
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "scale.csv")
    assert [(row["gas"], int(row["n"])) for row in rows] == [("mono 0.3", 1000), ("uniform 0.3", 1000)]
    for row in rows:
        assert float(row["rate"]) > 0 and 0 < float(row["rate_min"]) <= float(row["rate_max"])
        assert float(row["cpu_rate_min"]) <= float(row["cpu_rate"]) <= float(row["cpu_rate_max"])
        assert float(row["over_mono_same_n"]) == pytest.approx(float(row["cpu_rate"]) / float(rows[0]["cpu_rate"]))
        assert float(row["over_mono_same_n_wall"]) == pytest.approx(float(row["rate"]) / float(rows[0]["rate"]))
        assert 64 < float(row["bytes_per_disc"]) < 10_000  # the engine's arrays, not numba's compiler
    assert (tmp_path / "scale.png").stat().st_size > 0


@pytest.mark.slow  # 4 s
@pytest.mark.skipif(not ds._numba.available(), reason="numba is not installed (the fast extra)")
def test_memory_script_writes_a_row_per_stage(tmp_path):
    done = run_quick("memory.py", tmp_path)
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "memory.csv")
    assert [row["stage"] for row in rows] == ["tiny run", "random_gas", "EventDriven", "run", "snapshot"]
    assert {int(row["n"]) for row in rows} == {20_000} and float(rows[0]["rss_per_disc"]) == 0.0
    for row in rows:  # the peak so far never falls, and bounds the memory now
        assert float(row["rss_mb"]) <= float(row["peak_mb"])
    peaks = [float(row["peak_mb"]) for row in rows]
    assert peaks == sorted(peaks) and float(rows[2]["rss_per_disc"]) > 64  # the engine's arrays, at least


@pytest.mark.slow  # 2 s
@pytest.mark.skipif(not ds._numba.available(), reason="numba is not installed (the fast extra)")
def test_memory_order_script_writes_each_order(tmp_path):
    done = run_quick("memory_order.py", tmp_path)
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "memory_order.csv")
    assert [row["order"] for row in rows] == ["start", "shuffled", "resorted", "morton"]
    assert all(float(row["rate"]) > 0 for row in rows)
    assert float(rows[0]["over_start"]) == 1.0
    (ties,) = read_csv(tmp_path / "memory_order_ties.csv")
    # a renumbered engine logs the same events, but for the roles of a pair's discs in exact ties
    assert int(ties["differ"]) == int(ties["roles_swapped"]) and ties["same_state"] == "True"
