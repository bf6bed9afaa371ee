"""The liquid-hexatic loop of hard discs: beta P d^2 at packing 0.698-0.716 by both algorithms, against the published.

Run ``python benchmarks/hexatic.py`` (the full study: N = 128^2, far beyond one session on two cores; it is a
cached ``ds.sweep``, so run it again, here or on a bigger machine with ``--workers``, and it goes on where it
stopped, each finished task kept in ``--cache``), or ``--quick`` (N = 12^2, a minute: proves the script runs,
says nothing about the loop).

Each task is :func:`discsim.tasks.hard_disc_pressure`: one seed of one algorithm at one packing fraction, from
a lattice (or ``--start random``), ``beta P d^2 = Z 4 phi / pi`` with an error bar from blocks of its measured
span. The seeds of a point pool into its mean and the standard error over seeds (the larger of that and the
tasks' own error bars propagated). The reference values are those of massively parallel Monte Carlo at N =
128^2 in a square periodic box (Engel, Anderson, Glotzer, Isobe, Bernard & Krauth, Phys. Rev. E 87, 042134
(2013), Table I; the loop is Bernard & Krauth, PRL 107, 155704 (2011)):

    phi    0.698        0.704        0.708        0.712        0.716
    bPd^2  9.17405(49)  9.18558(80)  9.17630(74)  9.16554(90)  9.1587(10)

Targets (issue 29, item 4): every point within 3 sigma of the published value, and the loop resolved: beta P at
0.704 above that at 0.712 by at least 5 sigma. The script says whether they are met, and for each algorithm
the core-hours a point needs for an error bar of 0.001 (the seconds per task times the tasks that error bar
takes, from the scatter of the seeds).

Output: ``hexatic.csv`` (one row per algorithm and packing fraction) and ``hexatic.png`` (the loop) in
``--results``.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from benchutils import Column, announce, format_table, load_average, machine_summary, results_folder, write_csv

import discsim as ds

HERE = Path(__file__).resolve().parent

#: beta P d^2 and its error at N = 128^2 (Engel et al. 2013), by packing fraction.
PUBLISHED = {
    0.698: (9.17405, 0.00049),
    0.704: (9.18558, 0.00080),
    0.708: (9.17630, 0.00074),
    0.712: (9.16554, 0.00090),
    0.716: (9.1587, 0.0010),
}
#: The error bar a point should reach, for the core-hours estimate.
TARGET_ERROR = 0.001


@dataclass(frozen=True)
class Config:
    """One study: the side of the square lattice (N = side^2), the budgets per task, the seeds per point.

    ``edmd``: (collisions per disc to melt, collisions per disc measured); ``ecmc``: (chains per disc to melt,
    chains per disc measured), sized so that a task of each takes about as long with the compiled backends
    (4.9 million lifts per second against 1.15 million collisions, N = 10^4 at packing 0.70, 2 cores).
    """

    side: int
    seeds: int
    edmd: tuple[float, float]
    ecmc: tuple[float, float]
    backend: str = "auto"


FULL = Config(side=128, seeds=8, edmd=(2000.0, 9000.0), ecmc=(15.0, 60.0))
QUICK = Config(side=12, seeds=2, edmd=(20.0, 60.0), ecmc=(2.0, 6.0), backend="python")

KEYS = [
    "algorithm", "packing_fraction", "n", "seeds", "beta_p_d2", "err", "err_seeds", "err_tasks", "published",
    "published_err", "sigma_from_published", "seconds_per_task", "work_per_task", "core_hours_to_0.001",
]  # fmt: skip
COLUMNS = [
    Column("algorithm", "algorithm", "s"),
    Column("packing_fraction", "phi", ".3f"),
    Column("seeds", "seeds", "d"),
    Column("beta_p_d2", "beta P d^2", ".5f"),
    Column("err", "err", ".5f"),
    Column("published", "published", ".5f"),
    Column("sigma_from_published", "diff/err", ".1f"),
    Column("seconds_per_task", "s/task", ".1f"),
    Column("core_hours_to_0.001", "core-h to 0.001", ".3g"),
]


def parse(argv) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="N = 12^2 and tiny budgets: proves the script runs")
    parser.add_argument("--results", type=Path, default=None, help="folder for the CSV and PNG (see benchutils)")
    parser.add_argument("--cache", type=Path, default=None, help="the sweep's cache (default: RESULTS/cache/...)")
    parser.add_argument("--workers", type=int, default=None, help="processes of the local pool (default: cores)")
    parser.add_argument("--seeds", type=int, default=None, help="seeds per point (default: the study's)")
    parser.add_argument("--algorithms", default="edmd,ecmc", help="comma-separated: edmd, ecmc")
    parser.add_argument("--start", choices=("lattice", "random"), default="lattice", help="the tasks' start")
    args = parser.parse_args(argv)
    args.results = results_folder(args.results, args.quick)
    return args


def grid(config: Config, algorithm: str, start: str) -> dict:
    equilibrate, measure = getattr(config, algorithm)
    return {
        "algorithm": algorithm,
        "packing_fraction": sorted(PUBLISHED),
        "n": config.side**2,
        "equilibrate": equilibrate,
        "measure": measure,
        "start": start,
        "backend": config.backend,
    }


def pooled(table, algorithm: str) -> list[dict]:
    """One row per packing fraction of ``algorithm``: the seeds pooled, against the published value."""
    failed = table[table["error"].notna()]
    if len(failed):
        msg = f"{len(failed)} task(s) failed, e.g. {failed.iloc[0].to_dict()}"
        raise RuntimeError(msg)
    rows = []
    for phi, part in table.groupby("packing_fraction", sort=True):
        k = len(part)
        value = float(part["beta_p_d2"].mean())
        tasks = float(np.sqrt((part["beta_p_d2_err"] ** 2).sum()) / k)
        spread = float(part["beta_p_d2"].std(ddof=1)) if k > 1 else math.nan
        seeds = spread / math.sqrt(k) if k > 1 else math.nan
        err = max(tasks, seeds) if math.isfinite(seeds) else tasks
        published, published_err = PUBLISHED[round(float(phi), 3)]
        per_task = float(part["seconds"].mean())
        # one task's scatter (sigma_1): k tasks give sigma_1 / sqrt(k), so 0.001 takes (sigma_1 / 0.001)^2 tasks
        one = spread if math.isfinite(spread) else tasks * math.sqrt(k)
        rows.append(
            {
                "algorithm": algorithm,
                "packing_fraction": float(phi),
                "n": int(part["n"].iloc[0]),
                "seeds": k,
                "beta_p_d2": value,
                "err": err,
                "err_seeds": seeds,
                "err_tasks": tasks,
                "published": published,
                "published_err": published_err,
                "sigma_from_published": (value - published) / math.hypot(err, published_err),
                "seconds_per_task": per_task,
                "work_per_task": float(part["work"].mean()),
                "core_hours_to_0.001": per_task * (one / TARGET_ERROR) ** 2 / 3600.0,
            }
        )
    return rows


def verdict(rows: list[dict]) -> list[str]:
    """The targets, per algorithm: each point within 3 sigma, the loop resolved by 5 sigma."""
    lines = []
    for algorithm in sorted({r["algorithm"] for r in rows}):
        mine = {round(r["packing_fraction"], 3): r for r in rows if r["algorithm"] == algorithm}
        worst = max(abs(r["sigma_from_published"]) for r in mine.values())
        a, b = mine.get(0.704), mine.get(0.712)
        loop = (a["beta_p_d2"] - b["beta_p_d2"]) / math.hypot(a["err"], b["err"]) if a and b else math.nan
        lines.append(
            f"{algorithm}: farthest point {worst:.1f} sigma from the published ({'met' if worst <= 3 else 'NOT met'}"
            f": target 3); beta P(0.704) - beta P(0.712) = {loop:.1f} sigma ({'met' if loop >= 5 else 'NOT met'}: "
            "target 5)"
        )
    return lines


def plot(rows: list[dict], config: Config, path: Path) -> Path:
    """beta P d^2 against the packing fraction: each algorithm's points and the published loop."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.8), constrained_layout=True)
    phi = np.array(sorted(PUBLISHED))
    ref = np.array([PUBLISHED[p] for p in phi])
    ax.errorbar(phi, ref[:, 0], yerr=ref[:, 1], fmt="s-", color="k", ms=4, capsize=3,
                label="Engel et al. 2013, N = 128$^2$ (massively parallel MC)")  # fmt: skip
    for k, algorithm in enumerate(sorted({r["algorithm"] for r in rows})):
        mine = sorted((r for r in rows if r["algorithm"] == algorithm), key=lambda r: r["packing_fraction"])
        x = np.array([r["packing_fraction"] for r in mine]) + (k - 0.5) * 0.0006
        label = f"discsim {algorithm.upper()}, N = {config.side}$^2$, {mine[0]['seeds']} seeds"
        ax.errorbar(x, [r["beta_p_d2"] for r in mine], yerr=[r["err"] for r in mine], fmt="o", ms=5, capsize=3,
                    color=f"C{k}", label=label)  # fmt: skip
    ax.set_xlabel("packing fraction phi")
    ax.set_ylabel("beta P d$^2$")
    ax.set_title("Hard discs: the liquid-hexatic loop (benchmarks/hexatic.py)", fontsize=10)
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv=None) -> int:
    args = parse(argv)
    config = QUICK if args.quick else FULL
    if args.seeds is not None:
        config = Config(config.side, args.seeds, config.edmd, config.ecmc, config.backend)
    algorithms = [a.strip() for a in args.algorithms.split(",") if a.strip()]
    cache = args.cache or args.results / "cache" / f"hexatic_{'quick' if args.quick else 'full'}_{args.start}"
    print(f"discsim {ds.__version__} liquid-hexatic loop; {machine_summary()}")
    print(f"mode: {'quick' if args.quick else 'full'}; N = {config.side}^2, {config.seeds} seeds, {args.start} start, "
          f"edmd {config.edmd} collisions per disc, ecmc {config.ecmc} chains per disc; cache {cache}")  # fmt: skip
    rows = []
    for algorithm in algorithms:
        table = ds.sweep(ds.tasks.hard_disc_pressure, grid(config, algorithm, args.start), seeds=config.seeds,
                         cache=cache, workers=args.workers, progress=True)  # fmt: skip
        info = table.attrs["sweep"]
        announce(f"{algorithm}: {info['tasks']} tasks ({info['ran']} ran, {info['cached']} cached)")
        rows += pooled(table, algorithm)
    print(format_table(rows, COLUMNS))
    print("\n".join(verdict(rows)))
    print(f"load average at the end {load_average():.2f}")
    csv_path = write_csv(args.results / "hexatic.csv", rows, KEYS)
    png = plot(rows, config, args.results / "hexatic.png")
    print(f"wrote {csv_path}, {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
