"""What a ``sim.on("collision", fn)`` callback costs per event, on top of the event loop, under both backends.

Run ``python benchmarks/callbacks.py`` (about two minutes) or ``--quick`` (seconds). For each backend, a periodic
gas of N = 10^3 at packing 0.3 (seed 1), warmed by 2,000 events, is timed over a fixed number of physical events
(10^5 without a callback, 2 x 10^4 with one; ``--quick``: 10^4 and 2,000) in a fresh Python process per run,
three ways in turn (so a slow spell hits them alike), ``--repeats`` times (default 3), medians reported:

* ``none``: no callback: the loop's own cost per event.
* ``look``: ``sim.on("collision", fn, changes=False)``: a callback that only looks (a game's sound, a counter);
  the run goes on in chunks and the callbacks of a chunk's events are called after it (issue 28, item 5: at
  most 20 us per event on top of the loop).
* ``exact``: ``sim.on("collision", fn)``: a callback that may change the simulation; the run stops after every
  event (one event per chunk of the driver).
* ``exact+set``: the same callback changing one disc's velocity at every tenth collision (the run goes on
  exactly from there).

``fn`` appends nothing costly: it counts. Output: ``callbacks.csv`` (one row per backend and way: microseconds per
event, and on top of ``none``).
"""

from __future__ import annotations

import sys
import time

from benchutils import Column, call_fresh, format_table, machine_summary, median, parse_args, write_csv

import discsim as ds

WAYS = ("none", "look", "exact", "exact+set")
KEYS = ["backend", "way", "events", "us_per_event", "us_on_top", "repeats"]
COLUMNS = [
    Column("backend", "backend", "s"),
    Column("way", "callback", "s"),
    Column("events", "events", "d"),
    Column("us_per_event", "us/event", ".2f"),
    Column("us_on_top", "on top of the loop", ".2f"),
]


def measure(backend: str, way: str, events: int) -> dict:
    """One timed run in this process (call it in a fresh one): seconds for ``events`` physical events."""
    discs, box = ds.random_gas(1000, 0.3, seed=1)
    sim = ds.EventDriven(discs, box, backend=backend, record=False)
    sim.run(events=2000)
    count = [0]

    def counter(sim, contact):
        count[0] += 1

    def setter(sim, contact):
        count[0] += 1
        if count[0] % 10 == 0:
            sim.set_velocities([contact.i], [[0.5, -0.25]])

    if way == "look":
        sim.on("collision", counter, changes=False)
    elif way == "exact":
        sim.on("collision", counter)
    elif way == "exact+set":
        sim.on("collision", setter)
    began = time.perf_counter()
    sim.run(events=events)
    return {"seconds": time.perf_counter() - began, "calls": count[0]}


def main(argv=None) -> int:
    args = parse_args(__doc__.splitlines()[0], argv)
    repeats = args.repeats or (1 if args.quick else 3)
    plain, watched = (10_000, 2_000) if args.quick else (100_000, 20_000)
    backends = ["python"] + (["numba"] if ds._numba.available() else [])
    print(f"discsim {ds.__version__} callback cost; {machine_summary()}; {repeats} repeats, fresh processes")
    times: dict[tuple[str, str], list[float]] = {}
    for _ in range(repeats):
        for backend in backends:
            for way in WAYS:
                events = plain if way == "none" else watched
                out = call_fresh("callbacks", "measure", backend=backend, way=way, events=events)
                if way != "none" and out["calls"] != events:
                    msg = f"{backend} {way}: {out['calls']} calls for {events} events"
                    raise RuntimeError(msg)
                times.setdefault((backend, way), []).append(out["seconds"] / events * 1e6)
    rows = []
    for backend in backends:
        base = median(times[(backend, "none")])
        for way in WAYS:
            us = median(times[(backend, way)])
            events = plain if way == "none" else watched
            rows.append({"backend": backend, "way": way, "events": events, "us_per_event": us,
                         "us_on_top": us - base, "repeats": repeats})  # fmt: skip
    print(format_table(rows, COLUMNS))
    path = write_csv(args.results / "callbacks.csv", rows, KEYS)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
