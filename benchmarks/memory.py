"""Peak memory of a large run, stage by stage: where the bytes per disc go (issue 32: N = 10^7 in under 2 GB).

Run ``python benchmarks/memory.py`` (about a minute: N = 10^6), ``--huge`` to add N = 10^7 (3 to 5 minutes and
a few GB), ``--sizes 100000`` for some sizes only, or ``--quick`` (seconds: proves the script runs).

Each N runs in a fresh Python process (``call_fresh``) the user's whole path with the compiled backend, through the
public API: a tiny run first (1,000 discs, 10 events: numba loads or compiles the loop, the share of memory that
does not grow with N), then ``discs, box = ds.random_gas(N, 0.3, seed=0)``, ``sim = ds.EventDriven(discs, box,
backend="numba")`` (the default ``record=True``), ``sim.run(events=...)`` (``EVENTS``, a few million) and
``sim.snapshot()``. After each stage it reads the process's resident memory (``VmRSS``) and its peak so far
(``VmHWM``, from ``/proc/self/status``). ``memory_before.csv`` holds the same stages measured by hand before the
start state stopped copying the discs (its last stage reads ``sim.positions``, not a snapshot; 500,000 events at
10^6): at N = 10^7 the constructor's peak fell from 4,337 to 3,295 MB (and its CPU time at 10^4 from 77 to 10 ms:
the grid no longer builds the pure-Python predictor's table of shifts). What is left at 10^7 after the constructor,
271 bytes a disc over numba and the interpreter (170 MB): the discs 57, the backend's arrays about 154
(``nbytes()``), the scene's group of each disc 8, the rest (about 50) not broken down further; the peak adds the
start state (order, cells and members, about 45 bytes a disc) and the load's temporaries. A snapshot is a new
``Discs`` (about 73 bytes a disc) and, with its temporaries, sets the whole path's peak (4,038 MB). Figures, as
printed and written to ``memory.csv``:

* ``RSS MB``, ``peak MB``: the process's resident memory after the stage and its peak so far (the interpreter,
  numpy and numba included: what the operating system must give the run);
* ``RSS B/disc``, ``peak B/disc``: the same less the resident memory after the tiny run, per disc (what grows
  with N).

Figures only: nothing here asserts a size.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from benchutils import Column, announce, call_fresh, format_table, machine_summary, results_folder, write_csv

SIZES = (1_000_000,)
HUGE = 10_000_000
#: Events of the run after construction.
EVENTS = 2_000_000
PACKING = 0.3
QUICK = {"sizes": (20_000,), "events": 20_000}
STAGES = ("tiny run", "random_gas", "EventDriven", "run", "snapshot")


def memory_now() -> tuple[int, int]:
    """``(resident, peak)`` bytes of this process (``VmRSS``, ``VmHWM``; zeros where ``/proc`` is missing)."""
    found = {"VmRSS": 0, "VmHWM": 0}
    try:
        with open("/proc/self/status") as status:
            for line in status:
                key = line.split(":", 1)[0]
                if key in found:
                    found[key] = int(line.split()[1]) * 1024  # kB
    except OSError:
        pass
    return found["VmRSS"], found["VmHWM"]


def measure(n: int, events: int, seed: int = 0) -> dict:
    """The stages of one run (call it in a fresh process): ``{"rows": [...]}``, a row per stage."""
    import discsim as ds

    rows = []

    def stage(name: str) -> None:
        resident, peak = memory_now()
        rows.append({"n": n, "events": events, "stage": name, "rss": resident, "peak": peak})

    tiny = ds.EventDriven(*ds.random_gas(1_000, PACKING, seed=seed), backend="numba")
    tiny.run(events=10)
    del tiny
    stage("tiny run")
    discs, box = ds.random_gas(n, PACKING, seed=seed)
    stage("random_gas")
    sim = ds.EventDriven(discs, box, backend="numba")
    stage("EventDriven")
    sim.run(events=events)
    stage("run")
    snapshot = sim.snapshot()
    stage("snapshot")
    del snapshot
    base = rows[0]["rss"]
    for row in rows:
        row["rss_mb"], row["peak_mb"] = row["rss"] / 2**20, row["peak"] / 2**20
        row["rss_per_disc"], row["peak_per_disc"] = (row["rss"] - base) / n, (row["peak"] - base) / n
    return {"rows": rows}


COLUMNS = [
    Column("n", "N", ","),
    Column("stage", "after"),
    Column("rss_mb", "RSS MB", ",.0f"),
    Column("peak_mb", "peak MB", ",.0f"),
    Column("rss_per_disc", "RSS B/disc", ".0f"),
    Column("peak_per_disc", "peak B/disc", ".0f"),
]
CSV_KEYS = ["n", "events", "stage", "rss_mb", "peak_mb", "rss_per_disc", "peak_per_disc"]


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="N = 20,000 and 20,000 events: proves it runs")
    parser.add_argument("--huge", action="store_true", help=f"add N = {HUGE:,} (minutes and GB)")
    parser.add_argument("--sizes", type=int, nargs="+", help=f"numbers of discs (default {SIZES})")
    parser.add_argument("--events", type=int, help=f"events of the run (default {EVENTS:,})")
    parser.add_argument("--results", type=Path, help="CSV folder (default results/; --quick: a temporary one)")
    parser.add_argument("--stem", default="memory", help="name of the CSV file (default memory)")
    args = parser.parse_args(argv)
    quick = QUICK if args.quick else {}
    args.sizes = args.sizes or quick.get("sizes") or (*SIZES, *((HUGE,) if args.huge else ()))
    args.events = args.events or quick.get("events") or EVENTS
    if args.events < 1 or min(args.sizes) < 1:
        parser.error("--events and --sizes must be at least 1")
    args.results = results_folder(args.results, args.quick)
    return args


def main(argv: Sequence[str] | None = None) -> int:
    """Measure, print the table, write ``<stem>.csv``."""
    args = parse_args(argv)
    import discsim as ds

    print(f"discsim {ds.__version__} memory by stage (numba backend); {machine_summary()}")
    print(f"random_gas(N, {PACKING}, seed=0), {args.events:,} events, one fresh process per N")
    rows = []
    for n in args.sizes:
        announce(f"N = {n:,}")
        rows += call_fresh("memory", "measure", n=n, events=args.events)["rows"]
    print(format_table(rows, COLUMNS))
    csv_path = write_csv(args.results / f"{args.stem}.csv", rows, CSV_KEYS)
    print(f"wrote {csv_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
