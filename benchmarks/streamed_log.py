"""Reading a long streamed event log: time and peak memory of the readers that replay a late span.

Run ``python benchmarks/streamed_log.py --log RUN/events.dse`` on a log written by ``discsim run`` (the
README's ``discsim run --n 10000 --packing 0.5 --until 400 --seed 1 --out RUN`` writes 7 million events,
625 MB), or without ``--log`` to write one first (``--quick``: a small one, seconds).

Each task runs in a fresh Python process (:func:`benchutils.call_fresh`), which reports its wall-clock
seconds and its peak resident memory (``VmHWM``: the whole process, the interpreter and numpy included).
The tasks replay a short span near the end of the log, where a reader that loads the log whole pays for
all of it:

- ``view``: ``ds.view(LOG, None, start=S, until=S + 0.5)``, the page of half a time unit (``discsim view``);
- ``trajectory``: ``ds.trajectory_from_events(LOG, [S])``;
- ``frames``: ``ds.frames(LOG, [S, S + 0.25, S + 0.5])``;
- ``read whole``: ``ds.read_events(LOG)``, the log in memory (what the others did before they read chunks).

To compare two versions of discsim, run the script under each (``PYTHONPATH=OTHER/checkout python
benchmarks/streamed_log.py --log ...``): the tasks use only names both have. Writes ``streamed_log.csv``.

Measured (``benchmarks/results/streamed_log.csv``, and ``streamed_log_before.csv`` for the commit before the
chunked readers, 7bdeb11), 7,010,478 events, 2 shared cores: ``view`` 34.7 s and 2,863 MB before, 2.1 s and
51 MB after; ``trajectory`` 36.6 s and 3,271 MB before, 1.1 s and 52 MB after; ``frames`` 41.9 s and 3,907 MB
before, 3.2 s and 53 MB after (the whole log in memory takes 1,231 MB).
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

from benchutils import Column, announce, call_fresh, format_table, machine_summary, parse_args, write_csv

COLUMNS = [
    Column("task", "task"),
    Column("events", "events in log", ",d"),
    Column("span", "span"),
    Column("seconds", "seconds", ".2f"),
    Column("peak_mb", "peak MB", ",.0f"),
    Column("result", "result"),
]


def run_task(task: str, log: str, start: float) -> dict:
    """One task in this (fresh) process: ``{"seconds", "peak_mb", "result"}``."""
    import time

    from benchutils import peak_resident_mb

    import discsim as ds

    begin = time.perf_counter()
    if task == "view":
        page = ds.view(log, None, start=start, until=start + 0.5, max_events=10**9)
        result = f"{page.events:,} events, {len(page.html):,} bytes"
    elif task == "trajectory":
        result = f"shape {ds.trajectory_from_events(log, [start]).shape}"
    elif task == "frames":
        result = f"{len(ds.frames(log, [start, start + 0.25, start + 0.5]))} frames"
    else:
        result = f"{len(ds.read_events(log).events):,} events"
    return {"seconds": time.perf_counter() - begin, "peak_mb": peak_resident_mb(), "result": result}


def write_log(folder: Path, n: int, until: float) -> Path:
    """A streamed log of a dense gas (``discsim run``'s scene) in ``folder``."""
    import discsim as ds

    path = folder / "events.dse"
    ds.EventDriven(*ds.random_gas(n, 0.5, seed=1), record=False).run(until=until, record_to=path)
    return path


def main(argv=None) -> list[dict]:
    import argparse

    extra = argparse.ArgumentParser(add_help=False)
    extra.add_argument("--log", type=Path, default=None, help="a streamed event log (default: write one)")
    known, rest = extra.parse_known_args(argv)
    args = parse_args(__doc__.splitlines()[0], rest)
    print(machine_summary())
    log = known.log
    if log is None:
        n, until = (400, 6.0) if args.quick else (10_000, 60.0)
        announce(f"writing a log: {n} discs to t = {until}")
        log = write_log(Path(tempfile.mkdtemp(prefix="discsim-log-")), n, until)
    import discsim as ds

    if hasattr(ds, "iter_events"):  # the header alone
        chunked = ds.iter_events(log)
        end, events = chunked.end_time, chunked.records
    else:  # a discsim from before iter_events
        whole = ds.read_events(log)
        end, events = whole.end_time, len(whole.events)
    start = math.floor(0.75 * end * 2) / 2  # three quarters in, on a half unit
    rows = []
    for task in ("view", "trajectory", "frames", "read whole"):
        announce(f"{task} ...")
        got = call_fresh("streamed_log", "run_task", task=task, log=str(log), start=start)
        span = f"[{start:g}, {start + 0.5:g}]" if task != "read whole" else "all"
        rows.append({"task": task, "events": events, "span": span, **got})
    print(format_table(rows, COLUMNS))
    write_csv(args.results / "streamed_log.csv", rows, [c.key for c in COLUMNS])
    return rows


if __name__ == "__main__":
    main()
