"""ds.sweep: the same table from a plain loop, the local pool and dask; the cache, resuming, failures, bad input."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import sweep_tasks
from paths import ROOT

import discsim as ds
from discsim import _version
from discsim.run.cache import MANIFEST, SweepCache
from discsim.run.sweep import grid_points, seed_streams

pd = pytest.importorskip("pandas")

TESTS = Path(__file__).resolve().parents[1]
EOS_GRID = {"packing_fraction": [0.1, 0.4], "n": 80, "equilibrate": 2, "measure": 6, "backend": "python"}


def plain_loop(task, grid, seeds, **fixed):
    """The table a sweep must give, from a plain loop in this process."""
    rows = []
    for point in grid_points(grid):
        for seed in seed_streams(seeds):
            rows.append({**point, "seed": seed, **task(**point, seed=seed, **fixed), "error": None})
    return pd.DataFrame(rows)


# --- the same table everywhere ---------------------------------------------------------------------------


def test_local_pool_and_in_process_equal_a_plain_loop():
    grid = {"a": [1.0, 2.5, -3.0], "b": [0.0, 1.0]}
    expected = plain_loop(sweep_tasks.draw, grid, 3)
    for workers in (0, 2):
        table = ds.sweep(sweep_tasks.draw, grid, seeds=3, workers=workers)
        pd.testing.assert_frame_equal(table, expected)
        assert table.attrs["sweep"]["ran"] == 6 * 3
    assert list(expected.columns) == ["a", "b", "seed", "sum", "first", "label", "big", "error"]


@pytest.mark.slow
def test_dask_local_cluster_equals_local_pool_and_plain_loop():
    distributed = pytest.importorskip("distributed")
    expected = plain_loop(ds.tasks.equation_of_state, EOS_GRID, 2)
    local = ds.sweep(ds.tasks.equation_of_state, EOS_GRID, seeds=2, workers=2)
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster,
        distributed.Client(cluster) as client,
    ):
        remote = ds.sweep(ds.tasks.equation_of_state, EOS_GRID, seeds=2, client=client, progress=True)
        assert remote.attrs["sweep"]["where"].startswith("dask at tcp://")
    pd.testing.assert_frame_equal(local, expected)
    pd.testing.assert_frame_equal(remote, expected)
    assert (remote.z > 1.0).all() and remote.error.isna().all()


def test_list_of_points_keeps_their_order():
    points = [{"a": 2.0, "b": 1.0}, {"a": -1.0, "b": 0.5}]
    table = ds.sweep(sweep_tasks.draw, points, seeds=[4, 9], workers=0)
    assert table[["a", "b", "seed"]].values.tolist() == [[2.0, 1.0, 4], [2.0, 1.0, 9], [-1.0, 0.5, 4], [-1.0, 0.5, 9]]
    assert table["sum"].iloc[1] == sweep_tasks.draw(2.0, 1.0, seed=9)["sum"]


# --- seeds -------------------------------------------------------------------------------------------------


def test_seeds_are_spawned_streams_that_adding_points_or_seeds_does_not_change():
    children = np.random.SeedSequence(7).spawn(3)
    assert seed_streams(3, root_seed=7) == [int(c.generate_state(1, np.uint64)[0] >> np.uint64(1)) for c in children]
    assert seed_streams(5, root_seed=7)[:3] == seed_streams(3, root_seed=7)
    assert seed_streams(3, root_seed=8) != seed_streams(3, root_seed=7)
    assert len(set(seed_streams(64))) == 64 and all(0 <= s < 2**63 for s in seed_streams(64))
    small = ds.sweep(sweep_tasks.draw, {"a": [1.0]}, seeds=2, workers=0)
    more = ds.sweep(sweep_tasks.draw, {"a": [1.0, 5.0]}, seeds=3, workers=0)
    pd.testing.assert_frame_equal(more.iloc[:2].reset_index(drop=True), small)


# --- the cache ---------------------------------------------------------------------------------------------


def test_cache_runs_each_task_once_and_only_new_points(tmp_path):
    log = tmp_path / "log.txt"
    cache = tmp_path / "cache"
    first = ds.sweep(sweep_tasks.logged, {"a": [1, 2], "log": str(log)}, seeds=2, workers=2, cache=cache)
    assert len(log.read_text().splitlines()) == 4 and first.attrs["sweep"]["ran"] == 4
    again = ds.sweep(sweep_tasks.logged, {"a": [1, 2], "log": str(log)}, seeds=2, workers=2, cache=cache)
    pd.testing.assert_frame_equal(again, first)
    assert len(log.read_text().splitlines()) == 4
    assert again.attrs["sweep"]["cached"] == 4 and again.attrs["sweep"]["ran"] == 0
    grown = ds.sweep(sweep_tasks.logged, {"a": [1, 2, 3], "log": str(log)}, seeds=2, workers=0, cache=cache)
    assert len(log.read_text().splitlines()) == 6 and grown.attrs["sweep"]["ran"] == 2
    pd.testing.assert_frame_equal(grown.iloc[:4], first)
    manifest = json.loads((cache / MANIFEST).read_text())
    assert manifest["task"] == "sweep_tasks:logged"
    assert len(list(cache.glob("??/*.json"))) == 6


def test_cache_entry_that_cannot_be_read_is_computed_again(tmp_path):
    cache = tmp_path / "c"
    first = ds.sweep(sweep_tasks.draw, {"a": [1.0, 2.0]}, workers=0, cache=cache)
    entry = sorted(cache.glob("??/*.json"))[0]
    entry.write_text('{"key": "trunc')
    with pytest.warns(ds.CacheWarning, match=f"{entry.name}.*cannot be read"):
        again = ds.sweep(sweep_tasks.draw, {"a": [1.0, 2.0]}, workers=0, cache=cache)
    pd.testing.assert_frame_equal(again, first)
    assert again.attrs["sweep"]["ran"] == 1 and again.attrs["sweep"]["cached"] == 1


def test_a_cache_entry_changed_by_hand_is_reported_and_computed_again_never_served(tmp_path):
    cache = tmp_path / "c"
    first = ds.sweep(sweep_tasks.fails_at, {"a": [1, 3]}, workers=0, cache=cache)
    entries = sorted(cache.glob("??/*.json"))
    changed = next(e for e in entries if '"twice":2' in e.read_text())
    changed.write_text(changed.read_text().replace('"twice":2', '"twice":4'))  # "y": 1.0 to 2.0, by hand
    with pytest.warns(ds.CacheWarning, match=f"{changed.name}.*does not match its checksum"):
        again = ds.sweep(sweep_tasks.fails_at, {"a": [1, 3]}, workers=0, cache=cache)
    pd.testing.assert_frame_equal(again, first)
    assert again.twice.tolist() == [2, 6] and again.attrs["sweep"]["ran"] == 1
    assert '"twice":2' in changed.read_text()  # recomputed and stored again: served from now on, silently
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert ds.sweep(sweep_tasks.fails_at, {"a": [1, 3]}, workers=0, cache=cache).attrs["sweep"]["ran"] == 0


def test_a_cache_entry_with_another_tasks_identity_or_no_checksum_is_not_served(tmp_path):
    cache = tmp_path / "c"
    ds.sweep(sweep_tasks.fails_at, {"a": [1, 3]}, workers=0, cache=cache)
    one, three = sorted(cache.glob("??/*.json"), key=lambda e: '"twice":2' not in e.read_text())
    three.write_bytes(one.read_bytes())  # a whole, self-consistent entry, but another task's
    entry = json.loads(one.read_text())
    del entry["checksum"]
    one.write_text(json.dumps(entry))
    with pytest.warns(ds.CacheWarning) as caught:
        again = ds.sweep(sweep_tasks.fails_at, {"a": [1, 3]}, workers=0, cache=cache)
    assert again.twice.tolist() == [2, 6] and again.attrs["sweep"]["ran"] == 2
    messages = " ".join(str(w.message) for w in caught)
    assert one.name in messages and three.name in messages


def _entries(cache: Path) -> list[Path]:
    """The cache's entries (not the temporary file of one being written when the sweep was killed)."""
    return [e for e in cache.glob("??/*.json") if not e.name.startswith(".")]


def test_the_cache_counts_entries_not_the_temporary_file_a_kill_left(tmp_path):
    cache = tmp_path / "c"
    ds.sweep(sweep_tasks.draw, {"a": [1.0, 2.0]}, workers=0, cache=cache)
    entry = sorted(cache.glob("??/*.json"))[0]
    (entry.parent / ".tmp-k1ll3d.json").write_text('{"key": "half')  # killed between writing and os.replace
    assert len(SweepCache(cache, "sweep_tasks:draw", ds.__version__)) == 2


def test_a_cache_of_the_layout_without_checksums_is_reported_once_and_computed_again(tmp_path):
    cache = tmp_path / "c"
    first = ds.sweep(sweep_tasks.fails_at, {"a": [1, 3, 4]}, workers=0, cache=cache)
    manifest = json.loads((cache / MANIFEST).read_text())
    (cache / MANIFEST).write_text(json.dumps({**manifest, "layout": 1}))  # as discsim 0.1.0 wrote it
    for entry in _entries(cache):
        old = json.loads(entry.read_text())
        del old["checksum"]
        entry.write_text(json.dumps(old))
    with pytest.warns(ds.CacheWarning) as caught:
        again = ds.sweep(sweep_tasks.fails_at, {"a": [1, 3, 4]}, workers=0, cache=cache)
    assert len(caught) == 1 and "written by an older discsim, without checksums" in str(caught[0].message)
    pd.testing.assert_frame_equal(again, first)
    assert again.attrs["sweep"]["ran"] == 3 and json.loads((cache / MANIFEST).read_text())["layout"] == 2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert ds.sweep(sweep_tasks.fails_at, {"a": [1, 3, 4]}, workers=0, cache=cache).attrs["sweep"]["cached"] == 3


def test_version_is_part_of_the_key(tmp_path, monkeypatch):
    cache = tmp_path / "c"
    ds.sweep(sweep_tasks.draw, {"a": [1.0]}, workers=0, cache=cache)
    monkeypatch.setattr(_version, "__version__", "99.0")  # what ds.__version__ re-exports
    assert ds.sweep(sweep_tasks.draw, {"a": [1.0]}, workers=0, cache=cache).attrs["sweep"]["ran"] == 1


# --- failures ----------------------------------------------------------------------------------------------


def test_a_failing_point_is_reported_with_its_traceback_and_the_others_finish():
    with pytest.warns(RuntimeWarning, match="1 of 4 tasks failed after 3 attempt"):
        table = ds.sweep(sweep_tasks.fails_at, {"a": [1, 2, 3, 4]}, retries=2, workers=2)
    assert table.twice.tolist()[:1] == [2] and np.isnan(table.twice[1]) and table.twice.tolist()[2:] == [6, 8]
    assert table.error.isna().tolist() == [True, False, True, True]
    assert table.error[1] == "ValueError: no result at a=2"
    (failure,) = table.attrs["failures"]
    assert failure["params"] == {"a": 2} and failure["attempts"] == 3
    assert "raise ValueError(msg)" in failure["traceback"] and "fails_at" in failure["traceback"]
    assert table.attrs["sweep"]["retries"] == 2 and table.attrs["sweep"]["failed"] == 1
    assert len(table.attrs["seconds"]) == 4 and all(s >= 0.0 for s in table.attrs["seconds"])


def test_retries_rescue_a_flaky_task_and_are_counted(tmp_path):
    table = ds.sweep(sweep_tasks.flaky, {"a": [1, 2, 3], "marks": str(tmp_path)}, retries=1, workers=2)
    assert table.error.isna().all() and table.twice.tolist() == [2, 4, 6]
    assert table.attrs["sweep"]["retries"] == 3 and table.attrs["failures"] == []
    with pytest.warns(RuntimeWarning):
        none_left = ds.sweep(sweep_tasks.flaky, {"a": [7], "marks": str(tmp_path)}, retries=0, workers=0)
    assert none_left.error.tolist() == ["RuntimeError: first attempt at a=7"]


def test_failures_are_not_cached_and_run_again(tmp_path):
    cache = tmp_path / "c"
    with pytest.warns(RuntimeWarning):
        ds.sweep(sweep_tasks.flaky, {"a": [1], "marks": str(tmp_path)}, workers=0, cache=cache)
    table = ds.sweep(sweep_tasks.flaky, {"a": [1], "marks": str(tmp_path)}, workers=0, cache=cache)
    assert table.twice.tolist() == [2] and table.attrs["sweep"]["ran"] == 1


def test_a_worker_that_dies_fails_only_its_own_task_and_the_others_finish():
    with pytest.warns(RuntimeWarning, match="1 of 8 tasks failed after 2 attempt"):
        table = ds.sweep(sweep_tasks.dies, {"a": list(range(8))}, workers=1, retries=1)
    assert table.error.notna().tolist() == [a == 1 for a in range(8)]
    assert table.a2.drop(index=1).tolist() == [a * a for a in range(8) if a != 1]
    (failure,) = table.attrs["failures"]
    assert failure["params"] == {"a": 1} and failure["attempts"] == 2
    assert failure["error"].startswith("WorkerDied: the worker process died while running the task {'a': 1}, seed=")
    assert table.attrs["sweep"]["retries"] == 1


@pytest.mark.slow
def test_a_worker_that_dies_beside_busy_workers_fails_only_its_own_task():
    grid = {"a": list(range(8)), "pause": 0.3}  # a = 0 and a = 1 start together: both are running when 1 dies
    with pytest.warns(RuntimeWarning, match="1 of 8 tasks failed after 1 attempt"):
        table = ds.sweep(sweep_tasks.dies_beside_others, grid, workers=2)
    assert table.error.notna().tolist() == [a == 1 for a in range(8)]
    assert table.a2.drop(index=1).tolist() == [a * a for a in range(8) if a != 1]
    assert "'a': 1" in table.error[1] and table.attrs["failures"][0]["attempts"] == 1


def test_many_tasks_on_the_pool_each_reported_once():
    table = ds.sweep(sweep_tasks.draw, {"a": list(range(300))}, workers=2)
    assert table.a.tolist() == list(range(300)) and table.attrs["sweep"]["ran"] == 300
    assert table["sum"].tolist() == [sweep_tasks.draw(a, seed=table.seed[0])["sum"] for a in range(300)]


def test_a_task_that_returns_no_dict_fails_with_a_message():
    with pytest.warns(RuntimeWarning):
        table = ds.sweep(sweep_tasks.not_a_dict, {"a": [1]}, workers=0)
    assert table.error.iloc[0] == "TypeError: the task returned list, not a dict of results (the table's columns)"


def test_ctrl_c_stops_the_sweep_and_keeps_what_finished(tmp_path):
    cache = tmp_path / "c"
    with pytest.raises(ds.Interrupted, match="2 of 5 tasks unfinished; the 3 finished are in the cache"):
        ds.sweep(sweep_tasks.interrupts, {"a": [0, 1, 2, 3, 4]}, workers=0, cache=cache)
    assert len(list(cache.glob("??/*.json"))) == 3


def _alive(pid: int) -> bool:
    """Whether the process ``pid`` runs (a zombie, dead but not yet reaped, counts as gone)."""
    stat = Path(f"/proc/{pid}/stat")
    if stat.parent.parent.is_dir() and Path("/proc/self").exists():
        try:
            return stat.read_text().rsplit(")", 1)[1].split()[0] != "Z"
        except OSError:
            return False
    try:
        os.kill(pid, 0)
    except OSError:
        return False
    return True


def _worker_pids(folder: Path, count: int, child, timeout: float = 60.0) -> list[int]:
    """The pids that ``count`` tasks of :func:`sweep_tasks.hangs` wrote into ``folder`` (waits for them)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and child.poll() is None:
        texts = [p.read_text() for p in folder.iterdir()]
        if len(texts) >= count and all(texts):
            return sorted({int(t) for t in texts})
        time.sleep(0.05)
    pytest.fail(f"the sweep's tasks did not start (exit code {child.poll()})")


def _stop(pids) -> None:
    """Kill what a failed test left running (the pids its own sweep's tasks reported)."""
    for pid in pids:
        if _alive(pid):
            os.kill(pid, signal.SIGKILL)


HANGS = """
import sys
import discsim as ds, sweep_tasks
try:
    ds.sweep(sweep_tasks.hangs, {{"a": [0, 1, 2], "pids": {pids!r}}}, workers=2)
except ds.Interrupted as exc:
    print("interrupted:", exc, flush=True)
    sys.exit(130)
"""


@pytest.mark.slow
def test_ctrl_c_with_a_task_hung_stops_the_workers_and_returns_promptly(tmp_path):
    pids = tmp_path / "pids"
    pids.mkdir()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), str(ROOT)])}
    child = subprocess.Popen(
        [sys.executable, "-c", HANGS.format(pids=str(pids))], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    workers = _worker_pids(pids, 2, child)
    try:
        time.sleep(0.3)
        os.kill(child.pid, signal.SIGINT)  # Ctrl-C to the sweep's process alone
        start = time.monotonic()
        out, err = child.communicate(timeout=10)
        assert time.monotonic() - start < 3.0, "Ctrl-C took more than 3 s to stop the sweep"
        assert child.returncode == 130, err
        assert b"interrupted: sweep interrupted with 2 of 3 tasks unfinished" in out
        deadline = time.monotonic() + 5.0
        while any(_alive(p) for p in workers) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(_alive(p) for p in workers), "the pool's workers outlived the sweep"
    finally:
        child.kill()
        _stop(workers)


# --- bad input: a clear error before any task runs ---------------------------------------------------------


def _bad_cases(tmp_path):
    log = str(tmp_path / "ran.txt")
    other = tmp_path / "other"
    ds.sweep(sweep_tasks.draw, {"a": [1.0]}, workers=0, cache=other)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    (tmp_path / "a_file").write_text("mine")
    task = sweep_tasks.logged
    return [
        ((task, {}), {}, "the grid is empty"),
        ((task, []), {}, "the grid is empty"),
        ((task, {"a": [], "log": log}), {}, r"grid\['a'\] is empty"),
        ((task, {"a": [1], "log": log, "speed": [2]}), {}, "takes no parameter 'speed'"),
        ((task, {"log": log}), {}, "needs the parameter 'a'"),
        ((task, {"a": [1], "log": log, "seed": [3]}), {}, "'seed' is reserved"),
        ((task, {"a": [1, 1], "log": log}), {}, "repeats point 0"),
        ((task, {"a": [[1, 2]], "log": log}), {}, "parameter values must be numbers"),
        ((task, [{"a": 1, "log": log}, {"a": 2}]), {}, "grid point 1 has the parameters"),
        ((task, "a=1"), {}, "dict of lists or a list of dicts"),
        ((task, {"a": [1], "log": log}), {"seeds": 0}, "seeds must be at least 1"),
        ((task, {"a": [1], "log": log}), {"seeds": [1, 1]}, "seeds repeat"),
        ((task, {"a": [1], "log": log}), {"retries": -1}, "retries must be an integer >= 0"),
        ((task, {"a": [1], "log": log}), {"workers": -2}, "workers must be an integer >= 0"),
        ((task, {"a": [1], "log": log}), {"client": object()}, "client must be a dask.distributed.Client"),
        ((task, {"a": [1], "log": log}), {"cache": other}, "another sweep's task, 'sweep_tasks:draw'"),
        ((task, {"a": [1], "log": log}), {"cache": foreign}, "holds files but is not a sweep cache"),
        ((task, {"a": [1], "log": log}), {"cache": tmp_path / "a_file" / "c"}, "cannot be created or written"),
        ((lambda a, seed: {"a": a}, {"a": [1]}), {"workers": 1}, "cannot be sent to worker processes"),
        ((lambda a, seed: {"a": a}, {"a": [1]}), {"workers": 0, "cache": tmp_path / "l"}, "stable name"),
        ((42, {"a": [1]}), {}, "task must be a function"),
    ]


def test_bad_input_is_refused_before_any_task_runs(tmp_path):
    for args, kwargs, match in _bad_cases(tmp_path):
        with pytest.raises(ds.DiscsimError, match=match):
            ds.sweep(*args, **kwargs)
    assert not (tmp_path / "ran.txt").exists() and not (tmp_path / "l").exists()
    assert [p.name for p in (tmp_path / "foreign").iterdir()] == ["notes.txt"]


def test_without_pandas_the_sweep_names_the_extra(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "pandas", None)  # as if it were not installed
    with pytest.raises(ds.InvalidArgumentError, match=r'pip install "discsim\[sweep\]"'):
        ds.sweep(sweep_tasks.logged, {"a": [1], "log": str(tmp_path / "ran.txt")}, workers=0)
    assert not (tmp_path / "ran.txt").exists()


@pytest.mark.slow
def test_a_closed_dask_client_is_refused(tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, processes=False, dashboard_address=":0") as cluster:
        client = distributed.Client(cluster)
        client.close()
        with pytest.raises(ds.InvalidArgumentError, match="the dask client is closed"):
            ds.sweep(sweep_tasks.logged, {"a": [1], "log": str(tmp_path / "ran.txt")}, client=client)
    assert not (tmp_path / "ran.txt").exists()


# --- the command line --------------------------------------------------------------------------------------

SPEC = """
task = "sweep_tasks:draw"
seeds = 2
retries = 1
[grid]
a = [1.0, 2.0, 3.0, 4.0]
pause = {pause}
"""


def _cli(args, start=subprocess.run, **kwargs):
    """``python -m discsim ARGS`` with the test tasks importable (``start``: run it, or Popen to kill it)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), str(ROOT)])}
    return start([sys.executable, "-m", "discsim", *map(str, args)], env=env, **kwargs)


def test_cli_sweep_writes_the_table_and_reads_ready_made_tasks(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.format(pause=0.0))
    done = _cli(
        ["sweep", spec, "--out", tmp_path / "out", "--workers", "2", "--no-progress"], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert "8 tasks (8 ran, 0 from the cache, 0 failed, 0 retries)" in done.stdout
    table = pd.read_csv(tmp_path / "out" / "sweep.csv")
    expected = plain_loop(sweep_tasks.draw, {"a": [1.0, 2.0, 3.0, 4.0], "pause": 0.0}, 2)
    assert table["sum"].tolist() == expected["sum"].tolist() and table.seed.tolist() == expected.seed.tolist()
    spec.write_text('task = "equation_of_state"\nseeds = [3]\n[[grid]]\npacking_fraction = 0.2\nn = 50\nmeasure = 3\n')
    done = _cli(["sweep", spec, "--out", tmp_path / "eos", "--workers", "0"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert pd.read_csv(tmp_path / "eos" / "sweep.csv").z.iloc[0] > 1.0


def test_cli_sweep_reports_failures_and_bad_specs(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text('task = "sweep_tasks:fails_at"\n[grid]\na = [1, 2]\n')
    done = _cli(["sweep", spec, "--out", tmp_path / "out", "--workers", "0"], capture_output=True, text=True)
    assert done.returncode == 1 and "1 failed" in done.stdout and "no result at a=2" in done.stderr
    assert "raise ValueError(msg)" in (tmp_path / "out" / "failures.txt").read_text()
    for text, match in [
        ('task = "draw_it"\n[grid]\na = 1\n', "not a ready-made task"),
        ('task = "sweep_tasks:nothing"\n[grid]\na = 1\n', "has no 'nothing'"),
        ('task = "sweep_tasks:draw"\n[grid]\na = 1\nflavour = 2\nspeed = [1\n', "not valid TOML"),
        ('task = "sweep_tasks:draw"\ngrid = {a = 1}\nseed = 3\n', r"unknown key\(s\) \['seed'\]"),
        ('task = "sweep_tasks:draw"\n', "has no 'grid'"),
    ]:
        spec.write_text(text)
        done = _cli(["sweep", spec, "--out", tmp_path / "bad"], capture_output=True, text=True)
        assert done.returncode == 1 and match.replace("\\", "") in done.stderr.replace("\\", ""), (text, done.stderr)
    assert not (tmp_path / "bad").exists()


@pytest.mark.slow
def test_cli_sweep_killed_half_way_resumes_running_only_the_missing_tasks(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.format(pause=0.4))
    out = tmp_path / "out"
    cache = out / "cache"
    child = _cli(
        ["sweep", spec, "--out", out, "--workers", "1", "--no-progress"],
        start=subprocess.Popen,
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 120.0
    while len(_entries(cache)) < 3 and time.monotonic() < deadline and child.poll() is None:
        time.sleep(0.05)
    os.killpg(child.pid, signal.SIGKILL)  # the sweep and its pool's worker
    child.wait()
    kept = len(_entries(cache))
    assert 3 <= kept < 8, "the kill did not land half-way"
    assert not (out / "sweep.csv").exists()
    done = _cli(["sweep", spec, "--out", out, "--workers", "2", "--no-progress"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert f"8 tasks ({8 - kept} ran, {kept} from the cache" in done.stdout
    whole = _cli(["sweep", spec, "--out", tmp_path / "whole", "--workers", "2", "--no-progress"], capture_output=True)
    assert whole.returncode == 0
    assert (out / "sweep.csv").read_text() == (tmp_path / "whole" / "sweep.csv").read_text()


def test_cli_sweep_with_an_output_folder_it_cannot_write_says_so_without_a_traceback(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.format(pause=0.0))
    a_file = tmp_path / "a_file"
    a_file.write_text("mine")
    for out in [a_file, a_file / "below"]:
        done = _cli(["sweep", spec, "--out", out, "--workers", "0"], capture_output=True, text=True)
        assert done.returncode == 1, done.stderr
        assert "Traceback" not in done.stderr and f"cannot create the output folder {str(out)!r}" in done.stderr
    assert a_file.read_text() == "mine"
    if os.name == "posix" and os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        done = _cli(["sweep", spec, "--out", locked, "--workers", "0"], capture_output=True, text=True)
        assert done.returncode == 1 and "Traceback" not in done.stderr and str(locked) in done.stderr


def test_cli_sweep_that_cannot_write_its_table_says_so_without_a_traceback(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.format(pause=0.0))
    out = tmp_path / "out"
    (out / "sweep.csv").mkdir(parents=True)  # a folder where the table goes
    done = _cli(["sweep", spec, "--out", out, "--workers", "0"], capture_output=True, text=True)
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    assert f"cannot write {str(out / 'sweep.csv')!r}" in done.stderr


def test_cli_sweep_reports_a_damaged_cache_entry_on_a_line_of_its_own_and_runs_its_task_again(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.format(pause=0.0))
    args = ["sweep", spec, "--out", tmp_path / "out", "--workers", "0", "--no-progress"]
    assert _cli(args, capture_output=True).returncode == 0
    entry = _entries(tmp_path / "out" / "cache")[0]
    entry.write_text(entry.read_text().replace('"first":0.', '"first":1.'))
    done = _cli(args, capture_output=True, text=True)
    assert done.returncode == 0 and "8 tasks (1 ran, 7 from the cache" in done.stdout, done.stderr
    assert done.stderr.startswith(f"discsim sweep: warning: sweep cache: the entry {str(entry)!r} does not match")
    assert len(done.stderr.splitlines()) == 1


@pytest.mark.slow
def test_cli_sweep_ctrl_c_with_a_task_hung_exits_at_once_without_the_workers_tracebacks(tmp_path):
    pids = tmp_path / "pids"
    pids.mkdir()
    spec = tmp_path / "s.toml"
    spec.write_text(f'task = "sweep_tasks:hangs"\n[grid]\na = [0, 1, 2]\npids = {str(pids)!r}\n')
    child = _cli(
        ["sweep", spec, "--out", tmp_path / "out", "--workers", "3", "--no-progress"],
        start=subprocess.Popen,
        start_new_session=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    workers = _worker_pids(pids, 3, child)  # a = 0 returned: its worker waits for more, a = 1 and 2 hang
    try:
        time.sleep(0.3)
        os.killpg(child.pid, signal.SIGINT)  # Ctrl-C in a terminal: the sweep and its workers
        _, err = child.communicate(timeout=10)
        assert child.returncode == 130, err
        assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
        assert "sweep interrupted with 2 of 3 tasks unfinished" in err
        deadline = time.monotonic() + 5.0
        while any(_alive(p) for p in workers) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(_alive(p) for p in workers), "the pool's workers outlived the sweep"
    finally:
        child.kill()
        _stop(workers)


@pytest.mark.slow
def test_cli_sweep_killed_with_sigkill_leaves_no_worker_behind(tmp_path):
    pids = tmp_path / "pids"
    pids.mkdir()
    spec = tmp_path / "s.toml"  # a = 0 returns (its worker then waits for more), a = 1 hangs
    spec.write_text(f'task = "sweep_tasks:hangs"\n[grid]\na = [0, 1]\npids = {str(pids)!r}\n')
    child = _cli(
        ["sweep", spec, "--out", tmp_path / "out", "--workers", "2", "--no-progress"],
        start=subprocess.Popen,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    workers = _worker_pids(pids, 2, child)
    try:
        time.sleep(0.3)
        os.kill(child.pid, signal.SIGKILL)  # the sweep alone: its workers are orphaned
        child.wait()
        deadline = time.monotonic() + 5.0
        while any(_alive(p) for p in workers) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not [p for p in workers if _alive(p)], "workers outlived their killed sweep by 5 s"
    finally:
        _stop(workers)


@pytest.mark.parametrize(
    "where",
    [
        ["--workers", "0"],
        ["--workers", "2"],
        pytest.param(["--scheduler", "local", "--workers", "2"], marks=pytest.mark.slow),
    ],
    ids=["in-process", "local-pool", "dask-local-cluster"],
)
def test_cli_sweep_imports_the_task_from_the_current_folder_in_the_workers_too(tmp_path, where):
    if "--scheduler" in where:
        pytest.importorskip("distributed")
    (tmp_path / "mytask.py").write_text("def free_path(a, *, seed):\n    return {'a2': a * a}\n")
    (tmp_path / "s.toml").write_text('task = "mytask:free_path"\n[grid]\na = [1, 2, 3]\n')
    bin_folder = tmp_path / "bin"  # as the installed `discsim` script: its own folder is sys.path[0], not "."
    bin_folder.mkdir()
    (bin_folder / "discsim").write_text(
        "import sys\nfrom discsim.cli import main\nif __name__ == '__main__':\n    sys.exit(main())\n"
    )
    done = subprocess.run(
        [sys.executable, bin_folder / "discsim", "sweep", "s.toml", "--out", "out", "--no-progress", *where],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    assert pd.read_csv(tmp_path / "out" / "sweep.csv").a2.tolist() == [1, 4, 9]


@pytest.mark.slow
def test_cli_sweep_on_a_dask_local_cluster(tmp_path):
    pytest.importorskip("distributed")
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.format(pause=0.0))
    done = _cli(
        ["sweep", spec, "--out", tmp_path / "d", "--scheduler", "local", "--workers", "2"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    assert "on dask at tcp://" in done.stdout
    local = _cli(["sweep", spec, "--out", tmp_path / "l", "--workers", "2"], capture_output=True)
    assert local.returncode == 0
    assert (tmp_path / "d" / "sweep.csv").read_text() == (tmp_path / "l" / "sweep.csv").read_text()
