"""Equilibration at packing 0.70: what thermo() says about a short run from the lattice, and a long one.

Run ``python benchmarks/equilibration.py`` (a few minutes on two cores: N = 10,000, 2,000 collisions per disc)
or ``--quick`` (seconds: N = 400, 20 and 200 collisions per disc); ``--n`` sets N.

The README's pattern (issue 29): a periodic gas of ``N`` discs at packing 0.70 starts from a jittered
triangular lattice, runs about 100 collisions per disc, and is averaged from ``since = T / 4``. Its global
``psi6`` is still falling from the lattice's, and ``Z`` is still climbing. :func:`discsim.thermo` must say so:
this script records, for that short run, ``thermo(since=T/4)`` (``Z``, its error bar from the statistical
inefficiency, Geweke's score, whether it warned, and the start that Chodera's detection finds) and
``thermo(since="auto")``; then the same run continued to 2,000 collisions per disc and averaged from
``since="auto"``; and, beside the lattice, the same short run from a disordered start
(``random_gas(..., start="random")``). The short runs keep their log in memory, so thermo also checks the
global ``psi6`` over the span; the long run is read from a :class:`discsim.Sampler` that keeps 128 frames.

Output: ``equilibration.csv`` (one row per analysis) in ``--results``.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import discsim as ds


def analyse(label: str, source, since, sim, box, seconds: float, psi6_start: float) -> dict:
    """One row: ``thermo(source, since=since)`` and whether it warned."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ds.EquilibrationWarning)
        t = ds.thermo(source, since=since)
    warned = [str(w.message) for w in caught if issubclass(w.category, ds.EquilibrationWarning)]
    n = len(sim.discs)
    return {
        "run": label,
        "since_asked": since if isinstance(since, str) else f"{since:.4g}",
        "collisions_per_disc": 2 * sim.counts["collisions"] / n,
        "time": sim.time,
        "since": t.since,
        "z": t.z,
        "z_err": t.z_err,
        "inefficiency": t.inefficiency,
        "independent": t.independent,
        "geweke": t.geweke,
        "equilibrium_start": t.equilibrium_start,
        "psi6_start": psi6_start,
        "psi6_since": float(t.order[0]) if len(t.order) else float("nan"),
        "psi6_end": float(ds.psi6(sim.positions, box).order),
        "warned": bool(warned),
        "warning": warned[0].split(": ", 1)[1].split(". Automated")[0].replace(",", ";") if warned else "",
        "seconds": seconds,
    }


def run(n: int, packing: float, short: float, long: float, start: str, seed: int = 0) -> list[dict]:
    """The short run (``short`` collisions per disc, its log in memory, so thermo checks psi6 from it) and, when
    ``long > short``, a run of ``long`` collisions per disc from the same start seen by a Sampler."""
    begin = time.perf_counter()
    discs, box = ds.random_gas(n, packing, seed=seed, start=start)
    prepared = time.perf_counter() - begin
    psi6_start = float(ds.psi6(discs.positions, box).order)
    sim = ds.EventDriven(discs, box)
    begin = time.perf_counter()
    sim.run(events=int(short * n / 2))
    seconds = time.perf_counter() - begin
    label = f"{start} {short:g}/disc"
    rows = [
        analyse(label, sim, sim.time / 4, sim, box, seconds, psi6_start),
        analyse(label, sim, "auto", sim, box, seconds, psi6_start),
    ]
    rows[0]["start_seconds"] = rows[1]["start_seconds"] = prepared
    if long > short:
        rate = float(ds.enskog_collision_rate(packing))  # collisions per disc per unit time, roughly
        sampler = ds.Sampler(long / rate / 128)  # 128 frames kept (psi6), virial blocks of dt / 8
        sim = ds.EventDriven(discs, box, record=False)
        begin = time.perf_counter()
        sim.run(events=int(long * n / 2), observers=[sampler])
        seconds = time.perf_counter() - begin
        label = f"{start} {long:g}/disc"
        rows.append(analyse(label, sampler, sim.time / 4, sim, box, seconds, psi6_start))
        rows.append(analyse(label, sampler, "auto", sim, box, seconds, psi6_start))
        rows[-1]["start_seconds"] = rows[-2]["start_seconds"] = prepared
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a small run that only shows the script works")
    parser.add_argument("--results", type=Path, default=Path(__file__).parent / "results")
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--long", type=float, default=2000, help="collisions per disc of the long run (0: none)")
    args = parser.parse_args(argv)
    n, short, long = (400, 20, 200) if args.quick else (args.n, 100, args.long)
    rows = run(n, 0.70, short, long, "lattice") + run(n, 0.70, short, 0, "random")
    keys = list(dict.fromkeys(k for row in rows for k in row))
    for row in rows:
        print(
            f"{row['run']:<18} since={row['since_asked']:<7} {row['collisions_per_disc']:7.0f} coll/disc: "
            f"Z = {row['z']:.4f} +- {row['z_err']:.4f} from t = {row['since']:.4g} (g = {row['inefficiency']:.3g}, "
            f"{row['independent']:.1f} independent, Geweke {row['geweke']:+.1f}, Chodera start "
            f"{row['equilibrium_start']:.4g}); psi6 {row['psi6_start']:.3f} at t = 0, {row['psi6_since']:.3f} at "
            f"since, {row['psi6_end']:.3f} at the end; {row['seconds']:.0f} s"
            + (f"\n    WARNED: {row['warning']}" if row["warned"] else ""),
            flush=True,
        )
    args.results.mkdir(parents=True, exist_ok=True)
    path = args.results / ("equilibration_quick.csv" if args.quick else "equilibration.csv")
    with open(path, "w") as handle:
        handle.write(",".join(keys) + "\n")
        for row in rows:
            handle.write(
                ",".join(
                    f"{row[k]:.6g}" if isinstance(row.get(k), (float, np.floating)) else str(row.get(k, ""))
                    for k in keys
                )
                + "\n"
            )
    print(f"written to {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
