"""The cost of one FixedStep frame: numpy (python) against compiled (numba) against pymunk, same discs and dt.

Run ``python benchmarks/fixed_step_frames.py`` (about 5 minutes) or ``--quick`` (a minute, most of it the
cold compile).

For each N, a walled gas at packing 0.3 is melted by the exact engine (one collision per disc, as in
``peers.py``), and FixedStep (policy ``resolve``, the ``grid`` broad phase, no log) and pymunk (circles of
elasticity 1 and friction 0 in four static walls, ``peers.build_pymunk``) step it at the same ``dt``, the
step at which PIT misses 1% of the collisions (``throughput.one_percent_step``). Every timing runs in a fresh
Python process; one frame is done first (numba loads its compiled code then), then ``frames`` frames are
timed; the engines alternate run by run (python, numba, pymunk, python, ...) so that a slow spell of a
shared machine hits all alike. Figures, as printed and written to ``fixed_step_frames.csv``:

* ``us/frame``: wall-clock microseconds per frame, median over the runs (``min`` and ``max`` beside it;
  ``cpu us``, the median of the process's CPU time, which other processes inflate less);
* ``/ pymunk``: the median over pymunk's (the issue's target for numba: at most 1 at N = 10^2 and 10^3);
* ``vs python``: python's median over this engine's (the target for numba: at least 5 at N = 10^4).

A second table, ``fixed_step_sub_frames.csv``: the same, for the sub-frame policies ``bisect`` and ``swept``
(python against numba, same scenes and dt; ``vs python`` within each policy).

A third table, ``fixed_step_frames_compile.csv``: seconds to import discsim, build a compiled FixedStep
and do its first frame in a fresh process, with an empty numba cache (``NUMBA_CACHE_DIR`` a new folder: what
the first run in a fresh environment costs) and then with that cache warm; ``first frame`` is the part the
first frame takes (compiling, or loading the compiled code), ``process cpu`` the child's CPU seconds.
"""

from __future__ import annotations

import math
import os
import resource
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from benchutils import Column, call_fresh, format_table, machine_summary, median, parse_args, timed, write_csv

import discsim as ds

PACKING_FRACTION = 0.3
ENGINES = ("python", "numba", "pymunk")
SUB_FRAME_POLICIES = ("bisect", "swept")


@dataclass(frozen=True)
class Config:
    """Sizes and run lengths of one mode: ``frames`` timed per run at each N."""

    frames: dict
    repeats: int
    compile_repeats: int
    sub_frames: dict  # frames timed per run of a sub-frame policy at each N


# Every timing lasts 0.1 s or more for the fastest engine: a shorter one may hold a whole time slice of
# another process on a shared machine.
FULL = Config(
    frames={100: 50_000, 1_000: 10_000, 10_000: 1_000},
    repeats=5,
    compile_repeats=3,
    sub_frames={100: 20_000, 1_000: 4_000, 10_000: 400},
)
QUICK = Config(frames={60: 200}, repeats=1, compile_repeats=1, sub_frames={60: 100})


def scene(n: int, seed: int = 0) -> tuple[ds.Discs, ds.Box, float]:
    """The walled gas melted by one collision per disc under PIC, and the frame interval ``dt``."""
    from throughput import one_percent_step

    discs, box = ds.random_gas(n, PACKING_FRACTION, periodic=False, seed=seed)
    sim = ds.EventDriven(discs, box, record=False).run(events=n)
    discs = ds.Discs(sim.positions, sim.velocities, discs.radii, discs.masses)
    step, _ = one_percent_step(PACKING_FRACTION, Path(__file__).resolve().parent / "results")
    speed = math.sqrt(float((discs.velocities**2).sum(axis=1).mean()))
    return discs, box, step * float(discs.radii.mean()) / speed


def measure(n: int, engine: str, frames: int, policy: str = "resolve") -> dict:
    """Seconds per frame of ``engine`` over ``frames`` frames, after one frame not timed (in this process)."""
    discs, box, dt = scene(n)
    row = {"n": n, "engine": engine, "policy": policy, "frames": frames, "dt": dt}
    if engine == "pymunk":
        import pymunk
        from peers import build_pymunk

        run = build_pymunk(pymunk, discs, box)
        run.step(dt, 1)
        timing = timed(lambda: run.step(dt, frames))
        row["seconds"], row["cpu_seconds"] = timing.wall / frames, timing.cpu / frames
        return row
    sim = ds.FixedStep(discs, box, dt=dt, policy=policy, record=False, backend=engine)
    sim.run(frames=1)
    timing = timed(lambda: sim.run(frames=frames))
    row["seconds"], row["cpu_seconds"] = timing.wall / frames, timing.cpu / frames
    row["list_builds"] = sim.counts["list_builds"]
    row["detections_per_frame"] = sim.counts["detections"] / (frames + 1)
    row["backend"] = sim.backend
    return row


def measure_fresh(**args) -> dict:
    """:func:`measure` in a fresh Python process."""
    return call_fresh("fixed_step_frames", "measure", **args)


def _pymunk_missing() -> str:
    try:
        import pymunk  # noqa: F401
    except ImportError:
        return "pymunk is not installed (pip install -e .[bench])"
    return ""


#: The columns every timing table shares (after the labels of its configuration).
_TIMING_COLUMNS = [
    Column("dt", "dt", ".3g"),
    Column("frames", "frames", ","),
    Column("runs", "runs"),
    Column("us_per_frame", "us/frame", ".1f"),
    Column("us_min", "min", ".1f"),
    Column("us_max", "max", ".1f"),
    Column("cpu_us_per_frame", "cpu us", ".1f"),
]


def _timing_row(got: list[dict], **labels) -> dict:
    """A table row from the runs ``got`` of one configuration: its ``labels``, then microseconds per frame
    (median, min, max, CPU median) and the frame's ``dt``."""
    seconds = [r["seconds"] for r in got]
    return {
        **labels,
        "dt": got[0]["dt"],
        "runs": len(seconds),
        "us_per_frame": 1e6 * median(seconds),
        "us_min": 1e6 * min(seconds),
        "us_max": 1e6 * max(seconds),
        "cpu_us_per_frame": 1e6 * median([r["cpu_seconds"] for r in got]),
    }


def frames_section(config: Config, results: Path) -> list[dict]:
    """Time every engine at every N (alternating, fresh processes); print and write the table."""
    missing = _pymunk_missing()
    if missing:
        print(f"note: {missing}; python and numba alone")
    engines = [e for e in ENGINES if not (e == "pymunk" and missing)]
    if not ds.FixedStep(*ds.random_gas(4, 0.1, periodic=False, seed=0)).backend == "numba":
        print("note: numba is not installed or is hidden (the fast extra); the python frame alone")
        engines.remove("numba")
    rows = []
    for n, frames in config.frames.items():
        runs = {e: [] for e in engines}
        for attempt in range(config.repeats):
            for engine in engines:
                print(f"  N={n:,} {engine} run {attempt + 1}/{config.repeats}", file=sys.stderr, flush=True)
                runs[engine].append(measure_fresh(n=n, engine=engine, frames=frames))
        for engine in engines:
            got = runs[engine]
            rows.append(_timing_row(got, n=n, engine=engine, frames=frames))
            rows[-1]["list_builds"] = got[0].get("list_builds", math.nan)
        by = {r["engine"]: r["us_per_frame"] for r in rows if r["n"] == n}
        for row in rows:
            if row["n"] == n:
                row["pymunk_ratio"] = row["us_per_frame"] / by["pymunk"] if "pymunk" in by else math.nan
                row["speedup_vs_python"] = by["python"] / row["us_per_frame"]
    columns = [
        Column("n", "N", ","),
        Column("engine", "engine"),
        *_TIMING_COLUMNS,
        Column("pymunk_ratio", "/ pymunk", ".2f"),
        Column("speedup_vs_python", "vs python", ".1f"),
        Column("list_builds", "list builds", ".0f"),
    ]
    print(format_table(rows, columns))
    write_csv(results / "fixed_step_frames.csv", rows, [c.key for c in columns])
    return rows


def sub_frames_section(config: Config, results: Path) -> list[dict]:
    """Time ``bisect`` and ``swept`` under each backend at every N (alternating, fresh processes)."""
    engines = ["python", "numba"]
    if ds.FixedStep(*ds.random_gas(4, 0.1, periodic=False, seed=0), policy="swept").backend != "numba":
        print("note: numba is not installed or is hidden (the fast extra); the python frame alone")
        engines.remove("numba")
    rows = []
    for n, frames in config.sub_frames.items():
        runs = {(p, e): [] for p in SUB_FRAME_POLICIES for e in engines}
        for attempt in range(config.repeats):
            for policy in SUB_FRAME_POLICIES:
                for engine in engines:
                    print(
                        f"  N={n:,} {policy} {engine} run {attempt + 1}/{config.repeats}", file=sys.stderr, flush=True
                    )
                    runs[policy, engine].append(measure_fresh(n=n, engine=engine, frames=frames, policy=policy))
        for policy in SUB_FRAME_POLICIES:
            for engine in engines:
                got = runs[policy, engine]
                rows.append(_timing_row(got, n=n, policy=policy, engine=engine, frames=frames))
                rows[-1]["detections_per_frame"] = got[0]["detections_per_frame"]
            python = next(
                r["us_per_frame"] for r in rows if r["n"] == n and r["policy"] == policy and r["engine"] == "python"
            )
            for row in rows:
                if row["n"] == n and row["policy"] == policy:
                    row["speedup_vs_python"] = python / row["us_per_frame"]
    columns = [
        Column("n", "N", ","),
        Column("policy", "policy"),
        Column("engine", "engine"),
        *_TIMING_COLUMNS,
        Column("speedup_vs_python", "vs python", ".1f"),
        Column("detections_per_frame", "detections/frame", ".2f"),
    ]
    print(format_table(rows, columns))
    write_csv(results / "fixed_step_sub_frames.csv", rows, [c.key for c in columns])
    return rows


_COMPILE_PROBE = """
import time
start = time.perf_counter()
import discsim as ds
discs, box = ds.random_gas(200, 0.3, periodic=False, seed=0)
sim = ds.FixedStep(discs, box, dt=0.01, backend="numba")
built = time.perf_counter()
sim.run(frames=1)
end = time.perf_counter()
print(end - start, end - built)
"""


def compile_section(config: Config, results: Path) -> list[dict]:
    """Seconds to import discsim, build a compiled FixedStep and do one frame: cold numba cache, then warm."""
    if ds.FixedStep(*ds.random_gas(4, 0.1, periodic=False, seed=0)).backend != "numba":
        print("note: numba is not installed or is hidden: nothing to compile")
        return []
    rows = []
    for attempt in range(config.compile_repeats):
        with tempfile.TemporaryDirectory() as cache:
            env = {**os.environ, "NUMBA_CACHE_DIR": cache}
            for state in ("cold", "warm"):
                print(f"  compile: {state} cache, attempt {attempt + 1}", file=sys.stderr, flush=True)
                before = resource.getrusage(resource.RUSAGE_CHILDREN)
                done = subprocess.run(
                    [sys.executable, "-c", _COMPILE_PROBE], capture_output=True, text=True, env=env, check=True
                )
                after = resource.getrusage(resource.RUSAGE_CHILDREN)
                cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
                total, first = (float(x) for x in done.stdout.split()[-2:])
                row = {"cache": state, "attempt": attempt, "seconds": total, "first_frame_seconds": first}
                rows.append({**row, "cpu_seconds": cpu})
    summary = [
        {
            "cache": state,
            "seconds": median([r["seconds"] for r in rows if r["cache"] == state]),
            "first_frame_seconds": median([r["first_frame_seconds"] for r in rows if r["cache"] == state]),
            "cpu_seconds": median([r["cpu_seconds"] for r in rows if r["cache"] == state]),
        }
        for state in ("cold", "warm")
    ]
    print(
        format_table(
            summary,
            [
                Column("cache", "numba cache"),
                Column("seconds", "import+build+1 frame s", ".2f"),
                Column("first_frame_seconds", "first frame s", ".2f"),
                Column("cpu_seconds", "process cpu s", ".2f"),
            ],
        )
    )
    keys = ["cache", "attempt", "seconds", "first_frame_seconds", "cpu_seconds"]
    write_csv(results / "fixed_step_frames_compile.csv", rows, keys)
    return rows


def main(argv=None) -> int:
    args = parse_args(__doc__.splitlines()[0], argv)
    config = QUICK if args.quick else FULL
    if args.repeats is not None:
        config = Config(config.frames, args.repeats, config.compile_repeats, config.sub_frames)
    print(f"discsim {ds.__version__} FixedStep frames; {machine_summary()}")
    print(f"\n== One frame, walled gas at packing {PACKING_FRACTION}, policy resolve, same dt ==")
    frames_section(config, args.results)
    print("\n== One frame of the sub-frame policies, the same gas and dt, python against numba ==")
    sub_frames_section(config, args.results)
    print("\n== Compile time of the compiled frame ==")
    compile_section(config, args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
