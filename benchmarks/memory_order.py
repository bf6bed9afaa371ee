"""How much of the compiled backend's slowdown at large N is memory order: an experiment (issue 32).

Run ``python benchmarks/memory_order.py`` (11 minutes on this project's 2 shared cores under a load of 4:
N = 10^6 and 10^4, two fresh processes each, four engines in each) or ``--quick`` (seconds).

The compiled backend numbers the discs tile by tile of cells at the start (``numbering.internal_order``), so
that a disc's neighbours lie near it in memory; as the gas mixes they drift apart. Hardware counters are not
readable on this project's machine (``perf stat`` answers "not supported" for cycles and cache misses in its
VM), so the question is answered by experiment: four engines on the same seeded gas (``ds.random_gas``,
packing 0.3 unless told), which process the same events, with the backend's per-disc records in four
memory orders:

* ``start``: the engine's own numbering, left to mix as the gas runs (what every run does today);
* ``shuffled``: the records in a random order from the start (a gas mixed for ever);
* ``morton``: numbered at the start along the Morton (Z) curve of the cells instead of tile by tile, then
  left to mix;
* ``resorted``: renumbered tile by tile of the discs' current cells before every chunk (the re-sort of issue
  32, done from outside the loop: export the state, renumber, load it back; ``resort s``, the seconds of
  one re-sort, is not in the rates).

What was measured (``memory_order.csv``, and a first run the same day): at N = 10^6 the shuffled records ran at
0.93-0.94 of the engine's own order per CPU second, the re-sorted ones at 1.03-1.05 (each re-sort, by export
and load, took 0.75-0.86 s: the time of about 400,000 collisions, so re-sorting every 10^6 collisions as here
loses more than it gains), the Morton numbering at 1.025 at first and no better after 12 collisions per disc;
at N = 10^4 all four within 0.5%. Memory order is thus a few percent of the 10^6 slowdown (the engine's own
order runs at 0.26-0.29 of its 10^4 rate there). The rest is not the records' order; not measured here, but
likely: successive events lie at random places in the box, so each one's records are cold in the caches
whatever their order, and the queue's heap is deeper.

After half a collision per disc to warm up, the four engines run ``chunks`` chunks of ``per_chunk``
collisions in turn, in one fresh process per repeat, so that the shared machine's load hits all four alike.
``coll/CPU s``: collisions per CPU second of the process (``time.process_time``; a wait for memory counts,
another process's turn on the core does not), median over chunks and then repeats; ``coll/wall s`` the same
per wall-clock second; ``first``, ``last``: the first and last chunk's CPU rate (how the rate drifts as the
gas mixes); ``/start``: the CPU rate over ``start``'s. Written to ``memory_order.csv``.

Where the numbering shows in the events (``memory_order_ties.csv``, also alone with ``--ties-only``): two
engines run the same gas of ``TIES["ties_n"]`` discs with logs, one of them renumbered at random five times;
the logs are compared row by row (``differ``), and the differing rows checked for the same collision with the
roles of its two discs swapped (``roles_swapped``); ``same_state``: whether both end with the same positions,
velocities, pressure and counters, bit for bit. The numbering decides the queue's order of events at exactly
the same time (``(time, internal number)``), and both discs of a pair often hold their collision at the same
time to the last bit: the lower internal number then owns it, and the log names it first.

This script reaches into the engine (``sim._backend``, its ``export`` and ``load``): an experiment on the
backend, not a use of the public API. Figures only: nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from benchutils import Column, announce, call_fresh, format_table, machine_summary, median, results_folder, write_csv

ORDERS = ("start", "shuffled", "resorted", "morton")
#: The comparison of logs (:func:`relabelled`): N and events between renumberings.
TIES = {"ties_n": 5_000, "ties_events": 20_000}
FULL = {"sizes": (1_000_000, 10_000), "chunks": 12, "per_chunk": 1_000_000, "repeats": 2, "packing": 0.3, **TIES}
QUICK = {
    "sizes": (5_000,),
    "chunks": 2,
    "per_chunk": 10_000,
    "repeats": 1,
    "packing": 0.3,
    "ties_n": 5_000,
    "ties_events": 2_000,
}


def renumber(sim, order) -> float:
    """Load ``sim``'s state back with the internal numbering ``order`` (``(N,)``; None: tile by tile of the
    discs' current cells, keeping the current numbering within a cell); the seconds it took."""
    import dataclasses

    from discsim.engines.event_driven.numbering import cell_order

    start = time.perf_counter()
    backend = sim._backend
    state = backend.export()
    if order is None:
        order = cell_order(backend.grid, state.cell, state.order)
    backend.load(dataclasses.replace(state, order=order))
    return time.perf_counter() - start


def morton_order(sim):
    """The discs of ``sim`` ordered along the Morton curve of their cells (bits of the column and row
    interleaved), the current numbering kept within a cell: ``(N,)`` for :func:`renumber`."""
    import numpy as np

    state = sim._backend.export()
    cx, cy = np.divmod(state.cell[state.order], sim._backend.grid.ny)
    key = np.zeros(len(cx), dtype=np.int64)
    for bit in range(21):
        key |= ((cx >> bit) & 1) << (2 * bit + 1) | ((cy >> bit) & 1) << (2 * bit)
    return state.order[np.argsort(key, kind="stable")].astype(np.int64)


def measure(n: int, packing: float, seed: int, chunks: int, per_chunk: int) -> dict:
    """One run (in a fresh process): four engines on the same gas, one per order, timed chunk by chunk in turn.

    Interleaving the four in one process puts them under the same load of the shared machine; each chunk's
    rate is per CPU second of this process (``time.process_time``: another process's turn on the core is not
    counted, a wait for memory is) and per wall-clock second.
    """
    import numpy as np

    import discsim as ds

    ds.EventDriven(*ds.random_gas(1_000, 0.3), record=False, backend="numba").run(events=1)  # load the loop
    sims = {}
    for order in ORDERS:
        sim = ds.EventDriven(*ds.random_gas(n, packing, seed=seed), record=False, backend="numba")
        sim.run(events=1)
        if order == "morton":
            renumber(sim, morton_order(sim))
        if order == "shuffled":
            renumber(sim, np.random.default_rng(seed).permutation(n).astype(np.int64))
        sim.run(events=n // 2)
        sims[order] = sim
    out: dict = {order: {"cpu": [], "wall": [], "resort": []} for order in ORDERS}
    for _ in range(chunks):
        for order, sim in sims.items():
            if order == "resorted":
                out[order]["resort"].append(renumber(sim, None))
            before = sim.counts["collisions"]
            wall, cpu = time.perf_counter(), time.process_time()
            sim.run(events=per_chunk)
            wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
            done = sim.counts["collisions"] - before
            out[order]["cpu"].append(done / cpu)
            out[order]["wall"].append(done / wall)
    return out


def relabelled(n: int, packing: float, seed: int, events: int, renumbers: int) -> dict:
    """Where the internal numbering shows in the events: two engines on the same gas (logs recorded), one of
    them renumbered (a random order) ``renumbers`` times, every ``events`` events; their logs compared.

    Returns the events compared, those that differ, how many of those are the same collision with its two
    discs' roles swapped (``i`` and ``j`` and their columns exchanged), and whether the two engines end in the
    same state (positions, velocities, pressure and counters bit for bit).
    """
    import numpy as np

    import discsim as ds

    kept = ds.EventDriven(*ds.random_gas(n, packing, seed=seed), backend="numba")
    moved = ds.EventDriven(*ds.random_gas(n, packing, seed=seed), backend="numba")
    rng = np.random.default_rng(seed)
    for _ in range(renumbers):
        kept.run(events=events)
        moved.run(events=events)
        renumber(moved, rng.permutation(n).astype(np.int64))
    kept.run(events=events)
    moved.run(events=events)
    a, b = np.asarray(kept.events), np.asarray(moved.events)
    columns = a.dtype.names
    same = np.ones(len(a), dtype=bool)
    for name in columns:
        same &= (a[name] == b[name]) | ((a[name] != a[name]) & (b[name] != b[name]))  # NaN matches NaN
    differ = np.flatnonzero(~same)
    pairs = [("i", "j"), ("xi", "xj"), ("yi", "yj"), ("vxi", "vxj"), ("vyi", "vyj")]
    mirror = np.ones(len(differ), dtype=bool)
    for p, q in pairs:
        mirror &= (a[p][differ] == b[q][differ]) & (a[q][differ] == b[p][differ])
    state = (
        np.array_equal(kept.positions, moved.positions)
        and np.array_equal(kept.velocities, moved.velocities)
        and kept.pressure() == moved.pressure()
        and kept.counts == moved.counts
    )
    return {
        "events": len(a),
        "after_first_renumber": len(a) - events,
        "differ": len(differ),
        "roles_swapped": int(mirror.sum()),
        "same_state": bool(state),
    }


def main(argv: Sequence[str] | None = None) -> int:
    """Run every (N, order) ``repeats`` times; print and write ``memory_order.csv``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a small gas, two chunks: proves the script runs")
    parser.add_argument("--ties-only", action="store_true", help="only the comparison of logs (seconds)")
    parser.add_argument("--sizes", type=int, nargs="+")
    parser.add_argument("--packing", type=float)
    parser.add_argument("--repeats", type=int)
    parser.add_argument("--results", type=Path, help="CSV folder (default results/; --quick: a temporary one)")
    args = parser.parse_args(argv)
    plan = dict(QUICK if args.quick else FULL)
    for key in ("sizes", "packing", "repeats"):
        if getattr(args, key) is not None:
            plan[key] = getattr(args, key)
    results = results_folder(args.results, args.quick)
    print(f"memory order of the compiled backend's records; {machine_summary()}")
    if not args.ties_only:
        orders_section(plan, results)
    ties_section(plan, results)
    return 0


def orders_section(plan: dict, results: Path) -> None:
    """The rates of the four orders: print and write ``memory_order.csv``."""
    runs: dict[int, list[dict]] = {n: [] for n in plan["sizes"]}
    for seed in range(plan["repeats"]):
        for n in plan["sizes"]:
            announce(f"repeat {seed + 1}: N = {n:,}")
            runs[n].append(
                call_fresh(
                    "memory_order",
                    "measure",
                    n=n,
                    packing=plan["packing"],
                    seed=seed,
                    chunks=plan["chunks"],
                    per_chunk=plan["per_chunk"],
                )
            )
    rows = []
    for n, done in runs.items():
        for order in ORDERS:
            mine = [r[order] for r in done]
            rows.append(
                {
                    "n": n,
                    "packing": plan["packing"],
                    "order": order,
                    "rate": median([median(r["cpu"]) for r in mine]),
                    "wall_rate": median([median(r["wall"]) for r in mine]),
                    "first": median([r["cpu"][0] for r in mine]),
                    "last": median([r["cpu"][-1] for r in mine]),
                    "resort_seconds": median([median(r["resort"]) for r in mine]),
                    "chunks": plan["chunks"],
                    "per_chunk": plan["per_chunk"],
                    "runs": len(done),
                }
            )
    start_rate = {r["n"]: r["rate"] for r in rows if r["order"] == "start"}
    for row in rows:
        row["over_start"] = row["rate"] / start_rate[row["n"]]
    columns = [
        Column("n", "N", ","),
        Column("order", "order"),
        Column("rate", "coll/CPU s", ",.0f"),
        Column("over_start", "/start", ".3f"),
        Column("wall_rate", "coll/wall s", ",.0f"),
        Column("first", "first", ",.0f"),
        Column("last", "last", ",.0f"),
        Column("resort_seconds", "resort s", ".3f"),
    ]
    print(format_table(rows, columns))
    keys = ["n", "packing", "order", "rate", "over_start", "wall_rate", "first", "last", "resort_seconds", "chunks"]
    print(f"wrote {write_csv(results / 'memory_order.csv', rows, [*keys, 'per_chunk', 'runs'])}")


def ties_section(plan: dict, results: Path) -> None:
    """The logs of a renumbered engine against those of one left alone: print and write ``memory_order_ties.csv``."""
    ties = relabelled(plan["ties_n"], plan["packing"], 3, plan["ties_events"], 5)
    ties.update(n=plan["ties_n"], packing=plan["packing"], renumbers=5)
    print(
        f"\nRenumbered 5 times (N = {ties['n']:,}): {ties['differ']:,} of {ties['after_first_renumber']:,} events "
        f"logged after the first renumbering differ, {ties['roles_swapped']:,} of them the same collision with "
        f"i and j swapped; same final state bit for bit: {ties['same_state']}"
    )
    keys = ["n", "packing", "renumbers", "events", "after_first_renumber", "differ", "roles_swapped", "same_state"]
    print(f"wrote {write_csv(results / 'memory_order_ties.csv', [ties], keys)}")


if __name__ == "__main__":
    sys.exit(main())
