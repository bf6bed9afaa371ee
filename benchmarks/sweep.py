"""Sweeps on one and two workers: ``ds.sweep`` on the local process pool and on a dask ``LocalCluster``.

Run ``python benchmarks/sweep.py`` (about ten minutes on two cores) or ``--quick`` (under a minute: tiny
tasks, one repeat; proves the script runs, says nothing about speed).

Two measurements, each configuration in a fresh Python process (:func:`benchutils.call_fresh`), the
configurations taken in turn within each repeat (so a slow spell of the shared machine hits them alike), the
median of ``--repeats`` (default 3) reported, with the load average before each run:

* **Speed-up.** The equation of state of ``equation_of_state.py`` (its 12 packing fractions x 4 seeds: 48
  tasks of :func:`discsim.tasks.equation_of_state`), made shorter so that the 48 tasks take about a minute on
  one core: N = 1000, 100 collisions per disc to melt and 1900 measured, about 1.3 s a task with the compiled
  backend. No cache: every task runs. On the local pool (``workers=1`` and ``2``) the time is that of the
  whole ``ds.sweep`` call, the pool's start included; on dask, a ``LocalCluster(n_workers=k,
  threads_per_worker=1, processes=True)`` is started first (its start-up is reported apart) and the time is
  that of ``ds.sweep(..., client=client)``. Either way each worker process loads discsim's compiled loop from
  numba's cache before its first task (about a second). The speed-up is the 1-worker time over the 2-worker
  time, per path; every configuration must give the same table (checked by a digest of its ``z`` column).
* **Overhead per task.** Sweeps of 50 and of 450 tasks that do nothing (``nothing(x, seed) -> {"echo":
  x}``) on 2 workers, local pool and dask, and with ``workers=0`` (in this process), after a warm-up sweep of
  10 (which imports pandas, and discsim in the workers): the seconds per task are the slope between the two
  (so the fixed costs, such as starting the pool, drop out; they are reported as ``fixed_s``), and the
  overhead per task is that slope less the in-process one: what the pool or the scheduler adds to each task.

Read the speed-up with the load beside it. On a shared Linux machine the kernel divides the CPU fairly
between sessions (autogroup scheduling): while another session keeps a core busy, this benchmark's two
workers share the other one, and two workers take as long as one (measured 2026-11-24: 62.05 s against
62.06 s at load 2-3, 30.8 s against 62.1 s, 2.01x, at load 1.1). The ``s/task`` column tells which: each
task's own wall time doubles when the two workers have one core between them.

Output: ``sweep.csv`` (one row per path and worker count) and ``sweep_overhead.csv`` in ``--results``.
"""

from __future__ import annotations

import hashlib
import logging
import os
import sys
import time
from pathlib import Path

from benchutils import (
    Column,
    announce,
    call_fresh,
    format_table,
    load_average,
    machine_summary,
    median,
    parse_args,
    write_csv,
)
from equation_of_state import FULL as EOS

import discsim as ds

HERE = Path(__file__).resolve().parent

#: The timed sweep: the equation of state's grid and seeds, each task about a second long.
EOS_TASK = {"n": 1000, "equilibrate": 100.0, "measure": 1900.0}
QUICK_TASK = {"n": 60, "equilibrate": 5.0, "measure": 20.0, "backend": "python"}
QUICK_FRACTIONS = (0.1, 0.4, 0.7)
#: Configurations of the speed-up: (path, workers).
CONFIGS = (("local", 1), ("local", 2), ("dask", 1), ("dask", 2))
#: Trivial tasks for the overhead, and where they run: (path, workers).
OVERHEAD_TASKS, QUICK_OVERHEAD_TASKS = (50, 450), (5, 20)
OVERHEAD_CONFIGS = (("in-process", 0), ("local", 2), ("dask", 2))


def nothing(x: int, seed: int) -> dict:
    """A task that does nothing: what a sweep costs besides its tasks."""
    return {"echo": x}


def _client(workers: int):
    """A dask ``LocalCluster`` of ``workers`` single-threaded processes and its client."""
    from distributed import Client, LocalCluster

    # The workers are new interpreters: they import this module (for ``nothing``) from here.
    paths = [str(HERE), *os.environ.get("PYTHONPATH", "").split(os.pathsep)]
    os.environ["PYTHONPATH"] = os.pathsep.join(p for p in paths if p)
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,
    )
    return cluster, Client(cluster)


def time_sweep(path: str, workers: int, what: str, quick: bool) -> dict:
    """Timed sweeps in a fresh process: ``what`` is ``"eos"`` (one sweep) or ``"nothing"`` (a warm-up, then
    a small and a large sweep of trivial tasks); wall times, and a digest of the (last) table.
    """
    load = load_average()
    cluster = client = None
    start_seconds = float("nan")
    if path == "dask":
        begin = time.perf_counter()
        cluster, client = _client(workers)
        client.wait_for_workers(workers)
        start_seconds = time.perf_counter() - begin
    where = {"client": client} if client is not None else {"workers": workers}
    out = {"cluster_start": start_seconds, "load": load}
    try:
        if what == "eos":
            fractions = QUICK_FRACTIONS if quick else EOS.fractions
            grid = {"packing_fraction": list(fractions), **(QUICK_TASK if quick else EOS_TASK)}
            begin = time.perf_counter()
            table = ds.sweep(ds.tasks.equation_of_state, grid, seeds=2 if quick else EOS.seeds, **where)
            out["wall"] = time.perf_counter() - begin
            column = "z"
        else:
            ds.sweep(nothing, {"x": list(range(10))}, **where)  # imports pandas here, discsim in the workers
            for size, count in zip(("small", "large"), QUICK_OVERHEAD_TASKS if quick else OVERHEAD_TASKS):
                begin = time.perf_counter()
                table = ds.sweep(nothing, {"x": list(range(count))}, **where)
                out[f"wall_{size}"] = time.perf_counter() - begin
                out[f"tasks_{size}"] = count
            column = "echo"
    finally:
        if client is not None:
            client.close()
            cluster.close()
    info = table.attrs["sweep"]
    out.update(
        tasks=info["tasks"],
        failed=info["failed"],
        task_seconds=info["task_seconds"],
        where=info["where"],
        digest=hashlib.sha256(table[column].to_numpy().tobytes()).hexdigest()[:16],
    )
    return out


def measure(what: str, configs, repeats: int, quick: bool) -> dict:
    """Every configuration ``repeats`` times, in turn, each in a fresh process: ``{config: [runs]}``."""
    runs = {config: [] for config in configs}
    for r in range(repeats):
        for path, workers in configs:
            run = call_fresh("sweep", "time_sweep", path=path, workers=workers, what=what, quick=quick)
            if run["failed"]:
                msg = f"{what} on {path} x {workers}: {run['failed']} task(s) failed"
                raise RuntimeError(msg)
            wall = f"{run['wall']:.2f} s" if "wall" in run else f"{run['wall_small']:.2f} s, {run['wall_large']:.2f} s"
            announce(f"  repeat {r + 1}/{repeats}: {what} on {run['where']}: {wall} (load {run['load']:.2f})")
            runs[(path, workers)].append(run)
    digests = {run["digest"] for group in runs.values() for run in group}
    if len(digests) != 1:
        msg = f"the {what} sweeps gave different tables: digests {sorted(digests)}"
        raise RuntimeError(msg)
    return runs


def speedup_rows(runs: dict) -> list[dict]:
    """One row per configuration: median wall time, and the speed-up over one worker on the same path."""
    rows = []
    for (path, workers), group in runs.items():
        walls = [run["wall"] for run in group]
        one = runs.get((path, 1))
        rows.append(
            {
                "path": path,
                "workers": workers,
                "tasks": group[0]["tasks"],
                "repeats": len(group),
                "wall_s": median(walls),
                "wall_min_s": min(walls),
                "wall_max_s": max(walls),
                "walls_s": " ".join(f"{w:.2f}" for w in walls),
                "task_s": median([run["task_seconds"] for run in group]) / group[0]["tasks"],
                "cluster_start_s": median([run["cluster_start"] for run in group]),
                "speedup": median([r["wall"] for r in one]) / median(walls) if one else float("nan"),
                "speedup_per_repeat": " ".join(f"{a['wall'] / b['wall']:.2f}" for a, b in zip(one, group, strict=False))
                if one
                else "",
                "load": median([run["load"] for run in group]),
            }
        )
    return rows


def overhead_rows(runs: dict) -> list[dict]:
    """One row per path: seconds per trivial task (the slope between the small and the large sweep, so fixed
    costs such as starting the pool drop out), what that adds over ``workers=0``, and the fixed cost.
    """

    def slope(run):
        return (run["wall_large"] - run["wall_small"]) / (run["tasks_large"] - run["tasks_small"])

    base = median([slope(run) for run in runs[("in-process", 0)]])
    rows = []
    for (path, workers), group in runs.items():
        per_task = median([slope(run) for run in group])
        small, large = group[0]["tasks_small"], group[0]["tasks_large"]
        rows.append(
            {
                "path": path,
                "workers": workers,
                "tasks_small": small,
                "tasks_large": large,
                "repeats": len(group),
                "wall_small_s": median([run["wall_small"] for run in group]),
                "wall_large_s": median([run["wall_large"] for run in group]),
                "per_task_ms": 1e3 * per_task,
                "overhead_per_task_ms": 1e3 * (per_task - base),
                "fixed_s": median([run["wall_small"] - small * slope(run) for run in group]),
                "cluster_start_s": median([run["cluster_start"] for run in group]),
                "load": median([run["load"] for run in group]),
            }
        )
    return rows


SPEEDUP_KEYS = [
    "path", "workers", "tasks", "repeats", "wall_s", "wall_min_s", "wall_max_s", "walls_s", "task_s",
    "cluster_start_s", "speedup", "speedup_per_repeat", "load",
]  # fmt: skip
SPEEDUP_COLUMNS = [
    Column("path", "path"),
    Column("workers", "workers"),
    Column("tasks", "tasks"),
    Column("wall_s", "median s", ".2f"),
    Column("walls_s", "each run (s)"),
    Column("task_s", "s/task", ".3f"),
    Column("cluster_start_s", "cluster start s", ".2f"),
    Column("speedup", "speed-up", ".2f"),
    Column("speedup_per_repeat", "per repeat"),
    Column("load", "load", ".2f"),
]
OVERHEAD_KEYS = [
    "path", "workers", "tasks_small", "tasks_large", "repeats", "wall_small_s", "wall_large_s", "per_task_ms",
    "overhead_per_task_ms", "fixed_s", "cluster_start_s", "load",
]  # fmt: skip
OVERHEAD_COLUMNS = [
    Column("path", "path"),
    Column("workers", "workers"),
    Column("wall_small_s", "s, small", ".3f"),
    Column("wall_large_s", "s, large", ".3f"),
    Column("per_task_ms", "ms/task", ".3f"),
    Column("overhead_per_task_ms", "overhead ms/task", ".3f"),
    Column("fixed_s", "fixed s", ".3f"),
    Column("cluster_start_s", "cluster start s", ".2f"),
    Column("load", "load", ".2f"),
]


def main(argv=None) -> int:
    """Time the sweeps, print the tables, write the CSV files; return the exit code."""
    args = parse_args(__doc__.splitlines()[0], argv)
    repeats = args.repeats or (1 if args.quick else 3)
    task = QUICK_TASK if args.quick else EOS_TASK
    print(f"discsim {ds.__version__} sweeps; {machine_summary()}")
    print(
        f"mode: {'quick' if args.quick else 'full'}; equation of state {task} over "
        f"{len(QUICK_FRACTIONS if args.quick else EOS.fractions)} packing fractions x "
        f"{2 if args.quick else EOS.seeds} seeds, no cache; {repeats} repeat(s), each run in a fresh process",
        flush=True,
    )
    announce("speed-up: the equation of state on 1 and 2 workers")
    speed = speedup_rows(measure("eos", CONFIGS, repeats, args.quick))
    announce("overhead: trivial tasks")
    overhead = overhead_rows(measure("nothing", OVERHEAD_CONFIGS, repeats, args.quick))
    print("\n== speed-up: the equation of state's sweep (wall seconds of ds.sweep, medians) ==")
    print(format_table(speed, SPEEDUP_COLUMNS))
    print("\n== overhead: trivial tasks (seconds per task: slope between the small and the large sweep) ==")
    print(format_table(overhead, OVERHEAD_COLUMNS))
    print(
        "\nEvery configuration gave the same table. Local-pool times include starting the pool; dask times "
        f"exclude starting the cluster (its own column). Load average at the end: {load_average():.2f}"
    )
    speed_path = write_csv(args.results / "sweep.csv", speed, SPEEDUP_KEYS)
    overhead_path = write_csv(args.results / "sweep_overhead.csv", overhead, OVERHEAD_KEYS)
    print(f"wrote {speed_path}, {overhead_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
