"""Compression speed of ``ds.compress`` (Lubachevsky-Stillinger): packing reached per second, collisions per disc.

Four cases at N = 10^4 (``--quick``: N = 400): monodisperse discs to 0.85 and a 50:50 binary mixture with
radius ratio 1.4 to 0.80, each in a periodic and a walled box, from ``random_gas`` at packing 0.3 (the
mixture at 0.5), growth rate 0.01 thermal speeds, seed 1. Prints a table and writes
``results/compression.csv``: packing reached, whether it jammed, collisions per disc to 0.80 and 0.85,
packing gained per second of wall clock, collisions per second, seconds and the backend (numba when it
imports; the first process also compiles, a few seconds, so a warm-up compression runs first).
"""

from __future__ import annotations

import math
import time

from benchutils import Column, announce, format_table, machine_summary, parse_args, write_csv

import discsim as ds

KEYS = [
    "case", "n", "periodic", "target", "reached_packing", "jammed", "coll_per_disc_080", "coll_per_disc_085",
    "packing_per_s", "collisions_per_s", "collisions", "seconds", "backend",
]  # fmt: skip
COLUMNS = [
    Column("case", "case"),
    Column("n", "N"),
    Column("periodic", "periodic"),
    Column("reached_packing", "packing", ".4f"),
    Column("jammed", "jammed"),
    Column("coll_per_disc_080", "coll/disc to 0.80", ",.0f"),
    Column("coll_per_disc_085", "coll/disc to 0.85", ",.0f"),
    Column("packing_per_s", "packing/s", ".4f"),
    Column("collisions_per_s", "coll/s", ",.0f"),
    Column("seconds", "s", ".1f"),
    Column("backend", "backend"),
]


def main(argv=None) -> None:
    args = parse_args(__doc__.splitlines()[0], argv)
    n = 400 if args.quick else 10_000
    print(machine_summary())
    gas, box = ds.random_gas(100, 0.3, seed=1)
    ds.compress(gas, box, 0.5)  # warm-up: numba compiles (or loads its cache) here, not in a timed run
    rows = []
    for case, radii, start, target in (("monodisperse", None, 0.3, 0.85), ("binary 1:1.4", [1.0, 1.4], 0.5, 0.80)):
        for periodic in (True, False):
            announce(f"{case}, N = {n}, {'periodic' if periodic else 'walled'} box, to {target}")
            gas, box = ds.random_gas(n, start, periodic=periodic, seed=1, radii=radii)
            begin = time.perf_counter()
            _, report = ds.compress(gas, box, packing_fraction=target, growth_rate=0.01, seed=1)
            seconds = time.perf_counter() - begin
            rows.append(
                {
                    "case": case,
                    "n": n,
                    "periodic": periodic,
                    "target": target,
                    "reached_packing": report.packing_fraction,
                    "jammed": report.jammed,
                    "coll_per_disc_080": report.collisions_to(0.80, n),
                    "coll_per_disc_085": report.collisions_to(0.85, n) if target >= 0.85 else math.nan,
                    "packing_per_s": (report.packing_fraction - start) / seconds,
                    "collisions_per_s": report.collisions / seconds,
                    "collisions": report.collisions,
                    "seconds": seconds,
                    "backend": report.backend,
                }
            )
    print(format_table(rows, COLUMNS))
    path = write_csv(args.results / ("compression_quick.csv" if args.quick else "compression.csv"), rows, KEYS)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
