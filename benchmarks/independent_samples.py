"""Which algorithm to run: EDMD against ECMC, in wall-clock seconds per independent sample of the structure.

Run ``python benchmarks/independent_samples.py`` (about eight minutes on two cores) or ``--quick`` (under a minute:
proves the script runs). For each packing fraction (0.65 and 0.70; N = 32^2 = 1,024 in a square periodic box,
``--quick``: 12^2 at 0.65), each algorithm starts from the same disordered gas (``random_gas(..., start="random")``),
runs a fixed budget to forget it, then samples the global orientational order ``|psi6|`` (the slowest observable of
dense hard discs) at regular intervals of its own work: EDMD every ``dt`` (one collision per disc), ECMC every
``k`` chains (a fifth of a chain per disc, chains of half the box). The series' statistical inefficiency ``g`` (in
samples; :func:`discsim.analysis.equilibration.statistical_inefficiency`) times the wall-clock seconds per sample is the
time to an independent sample. The ratio EDMD/ECMC of those times says how much faster ECMC decorrelates the
structure (above 1: ECMC is faster). Both compiled (numba when it imports).

Read ``g`` against the samples: a series only a few ``g`` long gives ``g`` itself to no better than a factor of
two, so at 0.70, where the structure relaxes slowly, take the ratio as an order of magnitude (one seed, N = 1,024,
the default chain length), and run longer (``samples``) before quoting it.

Figures, as printed and written to ``independent_samples.csv``: per algorithm and packing, the work rate
(collisions or lifts per second), the samples, ``g``, seconds per sample, seconds per independent sample, and
``Z`` with its error bar from the same run (EDMD: ``ds.compressibility_factor``; ECMC: its lifts).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass

import numpy as np
from benchutils import Column, format_table, machine_summary, parse_args, write_csv

import discsim as ds
from discsim.analysis.equilibration import statistical_inefficiency


@dataclass(frozen=True)
class Config:
    side: int
    packings: tuple[float, ...]
    warm_seconds: float  # wall seconds each algorithm runs before sampling
    samples: int


FULL = Config(side=32, packings=(0.65, 0.70), warm_seconds=30.0, samples=1500)
QUICK = Config(side=12, packings=(0.65,), warm_seconds=1.0, samples=120)

KEYS = ["algorithm", "packing_fraction", "n", "rate", "samples", "g", "s_per_sample", "s_per_independent", "z",
        "edmd_over_ecmc"]  # fmt: skip
COLUMNS = [
    Column("algorithm", "algorithm", "s"),
    Column("packing_fraction", "phi", ".2f"),
    Column("rate", "work/s", ",.0f"),
    Column("g", "g (samples)", ".1f"),
    Column("s_per_sample", "s/sample", ".4f"),
    Column("s_per_independent", "s/independent", ".3f"),
    Column("z", "Z", ".3f"),
    Column("edmd_over_ecmc", "EDMD/ECMC", ".2f"),
]


def series(step, positions, box, samples: int) -> tuple[np.ndarray, float]:
    """``|psi6|`` after each of ``samples`` calls of ``step``, and the seconds those calls took (psi6 not counted)."""
    order = np.empty(samples)
    spent = 0.0
    for k in range(samples):
        began = time.perf_counter()
        step()
        spent += time.perf_counter() - began
        order[k] = ds.psi6(positions(), box).order
    return order, spent


def measure(config: Config, phi: float) -> list[dict]:
    n = config.side**2
    discs, box = ds.random_gas(n, phi, seed=1, start="random")
    rows = []
    # EDMD: dt = one collision per disc, from Enskog's rate
    md = ds.EventDriven(discs, box, record=False)
    dt = 1.0 / float(ds.enskog_collision_rate(phi))
    began = time.perf_counter()
    while time.perf_counter() - began < config.warm_seconds:
        md.run(until=md.time + 2 * dt)
    md_run = ds.EventDriven(md.snapshot(), box, record=False)
    order, spent = series(lambda: md_run.run(until=md_run.time + dt), lambda: md_run.positions, box, config.samples)
    rows.append(_row("edmd", phi, n, md_run.counts["collisions"] / spent, order, spent,
                     ds.compressibility_factor(md_run)))  # fmt: skip
    # ECMC: a fifth of a chain per disc between samples
    mc = ds.EventChain(discs, box, seed=1)
    chains = max(1, n // 5)
    began = time.perf_counter()
    while time.perf_counter() - began < config.warm_seconds:
        mc.run(chains=2 * chains)
    before = mc.state()
    order, spent = series(lambda: mc.run(chains=chains), lambda: mc.positions, box, config.samples)
    after = mc.state()
    z = 1.0 + (after.separation - before.separation) / ((after.chains - before.chains) * mc.chain_length)
    rows.append(_row("ecmc", phi, n, (after.lifts - before.lifts) / spent, order, spent, z))
    ratio = rows[0]["s_per_independent"] / rows[1]["s_per_independent"]
    for row in rows:
        row["edmd_over_ecmc"] = ratio
    return rows


def _row(algorithm, phi, n, rate, order, spent, z) -> dict:
    g = statistical_inefficiency(order)
    per_sample = spent / len(order)
    return {"algorithm": algorithm, "packing_fraction": phi, "n": n, "rate": rate, "samples": len(order), "g": g,
            "s_per_sample": per_sample, "s_per_independent": g * per_sample, "z": z}  # fmt: skip


def main(argv=None) -> int:
    args = parse_args(__doc__.splitlines()[0], argv)
    config = QUICK if args.quick else FULL
    print(f"discsim {ds.__version__} time to an independent sample; {machine_summary()}")
    print(f"N = {config.side}^2, packings {config.packings}, {config.warm_seconds:g} s to forget the start, "
          f"{config.samples} samples of |psi6| each")  # fmt: skip
    rows = [row for phi in config.packings for row in measure(config, phi)]
    print(format_table(rows, COLUMNS))
    path = write_csv(args.results / "independent_samples.csv", rows, KEYS)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
