"""Equation of state of hard discs: Z(eta) from 0.05 to 0.70 against Henderson's equation and the virial series.

Run ``python benchmarks/equation_of_state.py`` (about four minutes on two cores the first time, seconds once
cached) or ``--quick`` (seconds).

One sweep (:func:`discsim.sweep` of :func:`discsim.tasks.equation_of_state`) over 12 packing fractions
(0.05 to 0.70, closer together above 0.5) and 4 seeds (spawned from root 0): each task is a periodic gas of
N = 2000 discs from a jittered triangular lattice, run 500 collisions per disc to melt it and then measured
over 2000 collisions per disc (batch means, 10 blocks); about 2.5 million collisions and a few seconds with
the compiled backend. The results go to a cache folder, ``results/cache/equation_of_state/`` (one JSON file
per finished task, keyed by the task, its parameters, its seed and discsim's version): a rerun reads them
back instantly, and a run that was killed resumes with the tasks it had not finished. Delete the folder to
measure again (after a change to the engine, for instance: the key holds discsim's version, not the commit).

Per packing fraction, the seeds are pooled: ``z`` is their mean; ``z_err_batch`` propagates each seed's
batch-means error (``sqrt(sum err^2) / k``), ``z_err_seeds`` is the standard error of the mean over the
seeds (their scatter, ``std / sqrt(k)``), and the error bar ``z_err`` is the larger of the two, since batch
means inside one run underestimate fluctuations slower than a block. ``residual_henderson`` and
``residual_virial`` are ``Z`` minus :func:`discsim.henderson_z` and :func:`discsim.virial_z` (summed to
``B_10``) in units of ``z_err``.

Equilibration is checked at the dense end: 0.65, 0.68 and 0.70 are run again with four times the melting
(2000 collisions per disc) and the two ``Z`` compared (``check_*`` columns, the difference in combined error
bars). At 0.70 the hard-disc system is at the liquid end of its liquid-hexatic coexistence (Bernard and
Krauth, PRL 107, 155704 (2011): liquid up to 0.700, hexatic from 0.716, at ``beta P sigma^2 = 9.185``, that
is ``Z = 10.3`` at 0.700). There a lattice start takes about 500 collisions per disc to lose its memory
(``Z`` climbs from 10.0 to about 10.3 meanwhile), and afterwards the global ``psi6`` of N = 2000 discs
wanders between about 0.5 and 0.1 over thousands of collisions per disc, with ``Z`` moving against it (10.0
to 10.7 in windows of 50 collisions per disc): so each seed measures over 2000 collisions per disc, and the
error bar at 0.70 is several times those around it. Measured (2026-11-24): 10.34 +- 0.03 with 500
collisions per disc of melting, 10.28 +- 0.04 with 2000, both at Bernard and Krauth's 10.3. Henderson's
equation, fitted to lower densities, is 12% above there (0.4% at 0.5, 1.2% at 0.6, 2.1% at 0.65); the
virial series to ``B_10`` falls below from 0.4 on (0.6% at 0.5, 3% at 0.6, 6% at 0.65 and 0.68; 1% at
0.70, where the measured ``Z`` bends over towards the coexistence plateau).

Output: ``equation_of_state.csv`` (one row per packing fraction) and ``equation_of_state.png`` (``Z`` with
error bars against both references, and the residuals in units of the error bar) in ``--results``.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
from benchutils import Column, announce, format_table, load_average, machine_summary, parse_args, timed, write_csv

import discsim as ds


@dataclasses.dataclass(frozen=True)
class Config:
    """One mode's sweep.

    Attributes:
        fractions: packing fractions. seeds: seeds per packing fraction (spawned from root 0).
        n: discs. equilibrate, measure: collisions per disc to melt the lattice, and to average over.
        check_fractions: the dense points run again with ``check_factor`` times the melting.
        backend: the event-driven backend (the quick mode's small gases need no compiled loop).
    """

    fractions: tuple[float, ...]
    seeds: int
    n: int
    equilibrate: float
    measure: float
    check_fractions: tuple[float, ...]
    check_factor: float = 4.0
    backend: str = "auto"


FULL = Config(
    fractions=(0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.55, 0.6, 0.65, 0.68, 0.7),
    seeds=4,
    n=2000,
    equilibrate=500.0,
    measure=2000.0,
    check_fractions=(0.65, 0.68, 0.7),
)
QUICK = Config(
    fractions=(0.1, 0.4, 0.7),
    seeds=2,
    n=100,
    equilibrate=10.0,
    measure=40.0,
    check_fractions=(0.7,),
    backend="python",
)

KEYS = [
    "packing_fraction", "seeds", "n", "equilibrate", "measure", "z", "z_err", "z_err_batch", "z_err_seeds",
    "henderson_z", "virial_z", "residual_henderson", "residual_virial", "relative_to_henderson",
    "collision_rate", "collisions", "check_equilibrate", "check_z", "check_z_err", "check_difference_sigma",
]  # fmt: skip
COLUMNS = [
    Column("packing_fraction", "eta", ".2f"),
    Column("z", "Z", ".4f"),
    Column("z_err", "err", ".4f"),
    Column("z_err_batch", "batch err", ".4f"),
    Column("z_err_seeds", "seed err", ".4f"),
    Column("henderson_z", "Henderson", ".4f"),
    Column("virial_z", "virial B10", ".4f"),
    Column("residual_henderson", "(Z-H)/err", ".1f"),
    Column("relative_to_henderson", "Z/H-1 %", ".2f"),
    Column("check_z", "Z, 4x melt", ".4f"),
    Column("check_difference_sigma", "diff/err", ".1f"),
]


def grid(config: Config, fractions, equilibrate: float) -> dict:
    """The sweep's grid: the packing fractions, the other parameters fixed."""
    return {
        "packing_fraction": list(fractions),
        "n": config.n,
        "equilibrate": equilibrate,
        "measure": config.measure,
        "backend": config.backend,
    }


def pooled(table) -> list[dict]:
    """One row per packing fraction: the seeds' ``Z`` pooled (see the module docstring)."""
    failed = table[table["error"].notna()]
    if len(failed):
        msg = f"{len(failed)} task(s) failed, e.g. {failed.iloc[0].to_dict()}"
        raise RuntimeError(msg)
    rows = []
    for eta, part in table.groupby("packing_fraction", sort=True):
        k = len(part)
        z = float(part["z"].mean())
        batch = float(np.sqrt((part["z_err"] ** 2).sum()) / k)
        seeds = float(part["z"].std(ddof=1) / math.sqrt(k)) if k > 1 else math.nan
        err = max(batch, seeds) if math.isfinite(seeds) else batch
        henderson, virial = float(ds.henderson_z(eta)), float(ds.virial_z(eta))
        rows.append(
            {
                "packing_fraction": float(eta),
                "seeds": k,
                "n": int(part["n"].iloc[0]),
                "equilibrate": float(part["equilibrate"].iloc[0]),
                "measure": float(part["measure"].iloc[0]),
                "z": z,
                "z_err": err,
                "z_err_batch": batch,
                "z_err_seeds": seeds,
                "henderson_z": henderson,
                "virial_z": virial,
                "residual_henderson": (z - henderson) / err,
                "residual_virial": (z - virial) / err,
                "relative_to_henderson": 100.0 * (z / henderson - 1.0),
                "collision_rate": float(part["collision_rate"].mean()),
                "collisions": int(part["collisions"].sum()),
            }
        )
    return rows


def add_check(rows: list[dict], check: list[dict]) -> None:
    """Put the longer-melted runs beside the main ones, with their difference in combined error bars."""
    by_eta = {row["packing_fraction"]: row for row in check}
    for row in rows:
        other = by_eta.get(row["packing_fraction"])
        if other is None:
            continue
        row.update(
            check_equilibrate=other["equilibrate"],
            check_z=other["z"],
            check_z_err=other["z_err"],
            check_difference_sigma=(other["z"] - row["z"]) / math.hypot(other["z_err"], row["z_err"]),
        )


def plot(rows: list[dict], config: Config, path: Path) -> Path:
    """Z with error bars against Henderson's equation and the virial series, and the residuals below."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    eta = np.array([r["packing_fraction"] for r in rows])
    z = np.array([r["z"] for r in rows])
    err = np.array([r["z_err"] for r in rows])
    curve = np.linspace(0.0, max(0.72, eta.max() + 0.02), 300)
    fig, (top, bottom) = plt.subplots(
        2, 1, figsize=(7.0, 7.0), sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]}, constrained_layout=True
    )
    top.plot(curve, ds.henderson_z(curve), color="C0", lw=1.5, label="Henderson (1975)")
    top.plot(curve, ds.virial_z(curve), color="C2", lw=1.5, ls="--", label="virial series to $B_{10}$")
    top.errorbar(
        eta, z, yerr=err, fmt="o", color="k", ms=4, capsize=3,
        label=f"discsim: N = {config.n}, {config.seeds} seeds, {config.measure:g} coll./disc each",
    )  # fmt: skip
    top.set_ylabel("Z = PA / (N kT)")
    top.set_yscale("log")
    top.set_yticks([1, 2, 3, 5, 10], ["1", "2", "3", "5", "10"])
    top.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    top.legend(loc="upper left", fontsize=9)
    top.set_title("Hard discs: equation of state from ds.sweep(ds.tasks.equation_of_state)", fontsize=10)
    bottom.axhspan(-1.0, 1.0, color="0.85")
    bottom.axhline(0.0, color="0.4", lw=0.8)
    bottom.plot(eta, [r["residual_henderson"] for r in rows], "o", color="C0", ms=5, label="Z - Henderson")
    bottom.plot(eta, [r["residual_virial"] for r in rows], "^", color="C2", ms=5, label="Z - virial $B_{10}$")
    residuals = np.abs([r[key] for r in rows for key in ("residual_henderson", "residual_virial")])
    limit = max(5.0, 1.5 * float(np.nanmax(residuals, initial=0.0)))
    bottom.set_yscale("symlog", linthresh=3.0)
    bottom.set_ylim(-limit, limit)
    ticks = [t for t in (1, 3, 10, 30, 100, 300, 1000) if t <= limit]
    ticks = [-t for t in ticks[::-1]] + [0] + ticks
    bottom.set_yticks(ticks, [f"{t:g}" for t in ticks])
    bottom.yaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    bottom.set_ylabel("residual / error bar")
    bottom.set_xlabel("packing fraction eta")
    bottom.legend(loc="lower left", fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv=None) -> int:
    """Run (or read back) the sweep, print the table, write the CSV and the figure; return the exit code."""
    args = parse_args(__doc__.splitlines()[0], argv)
    config = QUICK if args.quick else FULL
    cache = args.results / "cache" / ("equation_of_state_quick" if args.quick else "equation_of_state")
    print(f"discsim {ds.__version__} equation of state; {machine_summary()}")
    print(
        f"mode: {'quick' if args.quick else 'full'}; N={config.n} periodic, kT=1, {len(config.fractions)} packing "
        f"fractions x {config.seeds} seeds; {config.equilibrate:g} collisions per disc to melt, {config.measure:g} "
        f"measured; cache {cache}"
    )
    run = timed(
        lambda: ds.sweep(
            ds.tasks.equation_of_state,
            grid(config, config.fractions, config.equilibrate),
            seeds=config.seeds,
            cache=cache,
            progress=True,
        )
    )
    announce(f"sweep: {_counts(run.result)} in {run.wall:.1f} s")
    melt = config.check_factor * config.equilibrate
    check = timed(
        lambda: ds.sweep(
            ds.tasks.equation_of_state,
            grid(config, config.check_fractions, melt),
            seeds=config.seeds,
            cache=cache,
            progress=True,
        )
    )
    announce(f"check ({melt:g} collisions per disc to melt): {_counts(check.result)} in {check.wall:.1f} s")
    rows = pooled(run.result)
    add_check(rows, pooled(check.result))
    print(format_table(rows, COLUMNS))
    spent = run.result.attrs["sweep"]["task_seconds"] + check.result.attrs["sweep"]["task_seconds"]
    print(
        f"\nerr: the larger of the batch-means error (propagated over the seeds) and the seeds' standard error; "
        f"(Z-H)/err: Z against Henderson's equation in error bars.\n"
        f"sweeps: {_counts(run.result)}, then {_counts(check.result)}; {run.wall + check.wall:.1f} s wall "
        f"({spent:.0f} s in the tasks that ran); load average at the end {load_average():.2f}"
    )
    csv_path = write_csv(args.results / "equation_of_state.csv", rows, KEYS)
    png = plot(rows, config, args.results / "equation_of_state.png")
    print(f"wrote {csv_path}, {png}")
    return 0


def _counts(table) -> str:
    info = table.attrs["sweep"]
    return f"{info['tasks']} tasks ({info['ran']} ran, {info['cached']} from the cache, {info['failed']} failed)"


if __name__ == "__main__":
    sys.exit(main())
