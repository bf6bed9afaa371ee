"""Speed at scale: collisions per second of the compiled backend against N, for four gases (issue 32).

Run ``python benchmarks/scale.py`` (4 to 5 minutes on this project's 2 shared cores: 3 runs per point, 1 at
N = 10^6), ``--huge`` to add N = 10^7 (measured here for ``mono 0.3`` alone, ``--huge --sizes 10000000
--gases "mono 0.3" --repeats 1 --stem scale_huge``: 3 minutes, most of it building the engine, and 4.3 GB of
peak memory before the start state stopped copying the discs: ``memory.py``; the mixture's construction at
10^6 already peaks at 1.8 GB, so the four gases at 10^7 were not tried on this 23 GB machine), ``--sizes 1000
10000`` for some sizes only, or ``--quick`` (seconds: proves the script runs).

For each gas and N, a seeded periodic gas is built through the public API (``import discsim as ds``), run
for ``WARMUP_PER_DISC`` collisions per disc (at most ``WARMUP_MAX``) untimed, then timed over ``TIMED``
collisions with ``time.perf_counter``, in a fresh Python process per run (``call_fresh``). Repeat by repeat,
every point runs once before any runs again, so that a slow spell of the shared machine spreads over all
points. Where the peak memory goes, stage by stage: ``benchmarks/memory.py``. The gases (``GASES``):

* ``mono 0.3``, ``mono 0.7``: equal discs at packing 0.3 and 0.7 (``ds.random_gas``, lattice start: the
  0.7 gas is still a crystal melting during the timed run; its rate is the engine's all the same);
* ``1:10 mix 0.3``: 10% of the discs (by number) of radius 10, the rest of radius 1, packing 0.3 (the
  mixture of ``benchmarks/backends.py``);
* ``uniform 0.3``: radii uniform in [0.5, 1.5], packing 0.3 (``ds.random_gas(radii=...)``).

Figures, as printed and written to ``scale.csv`` (and ``scale.png``: rate against N, one line per gas):

* ``coll/s``: median over the repeats of the timed collisions per wall-clock second (``rate_min``,
  ``rate_max`` in the CSV: the machine's noise); ``coll/CPU s``: the same per CPU second of the run's process
  (``time.process_time``: a wait for memory counts, another process's turn on the core does not), steadier
  than wall-clock time on a shared machine, and the rate the ratios and the figure use;
* ``/mono 1e4``: that CPU rate over the CPU rate of ``mono 0.3`` at N = 10^4 (issue 32's targets: at least 0.7
  for the monodisperse gases at 10^6, 0.5 at 10^7); ``/mono same N``: over ``mono 0.3`` at the same N (the
  targets: at least 0.8 for the mixtures at 10^4 and 10^5); the CSV has both from wall-clock rates too
  (``*_wall``);
* ``B/disc``: bytes of the compiled backend's state arrays per disc (its ``nbytes()``, as
  ``benchmarks/backends.py`` reports them: the one read past the public API); ``RSS B/disc``: growth of the
  process's resident memory from before building the ``EventDriven`` to its first event, per disc (every array
  the engine holds, the scene's copy of the discs included; coarse: memory the gas's construction freed is
  used again, so small N and the mixture read low); ``peak MB``: the process's peak resident memory
  (the interpreter, numba and the gas's construction included).

Figures only: nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from benchutils import Column, announce, call_fresh, format_table, machine_summary, median, results_folder, write_csv

#: The gases: name -> (packing fraction, kind of discs).
GASES = {
    "mono 0.3": (0.3, "mono"),
    "mono 0.7": (0.7, "mono"),
    "1:10 mix 0.3": (0.3, "mixture"),
    "uniform 0.3": (0.3, "uniform"),
}
SIZES = (1_000, 10_000, 100_000, 1_000_000)
HUGE = 10_000_000
#: Timed collisions per run, the same at every N.
TIMED = 1_000_000
#: Untimed collisions per disc before the timed segment (at most ``WARMUP_MAX`` in all).
WARMUP_PER_DISC = 1
WARMUP_MAX = 2_000_000
REPEATS = 3
#: Runs per point at N >= ``LARGE`` unless ``--repeats`` is given (building a gas of 10^6 discs takes 10-30 s).
LARGE, LARGE_REPEATS = 1_000_000, 1
QUICK = {"sizes": (1_000,), "gases": ("mono 0.3", "uniform 0.3"), "timed": 20_000, "repeats": 1}
REFERENCE = ("mono 0.3", 10_000)


def build(gas: str, n: int, seed: int):
    """The discs and box of ``gas`` with ``n`` discs (seeded)."""
    import discsim as ds

    packing, kind = GASES[gas]
    if kind == "mono":
        return ds.random_gas(n, packing, periodic=True, seed=seed)
    if kind == "uniform":
        return ds.random_gas(n, packing, periodic=True, seed=seed, radii=lambda rng, k: rng.uniform(0.5, 1.5, k))
    from backends import mixture

    return mixture(n, packing, seed)


def resident_bytes() -> int:
    """This process's resident memory now, in bytes (0 where ``/proc`` is missing)."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024  # kB
    except OSError:
        pass
    return 0


def measure(gas: str, n: int, seed: int, timed: int) -> dict:
    """One run (call it in a fresh process): build, start, warm up, time ``timed`` collisions."""
    from benchutils import peak_resident_mb

    import discsim as ds

    # Load (or compile) the loop first, on a small gas of the same kind, so that the memory measured is the run's.
    ds.EventDriven(*build(gas, 1_000, seed), record=False, backend="numba").run(events=1)
    discs, box = build(gas, n, seed)
    before = resident_bytes()
    sim = ds.EventDriven(discs, box, record=False, backend="numba")
    sim.run(events=1)  # the backend is built and every disc predicted
    resident = resident_bytes() - before
    # The one read past the public API (as benchmarks/backends.py): the bytes of the backend's state arrays.
    arrays = sim._backend.nbytes()
    sim.run(events=min(WARMUP_MAX, WARMUP_PER_DISC * n))
    start_count = sim.counts["collisions"]
    start, cpu = time.perf_counter(), time.process_time()
    sim.run(events=timed)
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    collisions = sim.counts["collisions"] - start_count
    return {
        "collisions": collisions,
        "seconds": seconds,
        "rate": collisions / seconds,
        "cpu_rate": collisions / cpu,
        "bytes_per_disc": arrays / n,
        "resident_per_disc": resident / n,
        "peak_mb": peak_resident_mb(),
    }


def run_points(
    gases: Sequence[str], sizes: Sequence[int], repeats: int, timed: int, large_repeats: int | None = None
) -> list[dict]:
    """Every (gas, N) point ``repeats`` times (``large_repeats`` at N >= ``LARGE``), each run in a fresh process;
    one row per point."""
    runs: dict[tuple[str, int], list[dict]] = {(g, n): [] for n in sizes for g in gases}
    large_repeats = repeats if large_repeats is None else large_repeats
    for seed in range(repeats):
        for n in sizes:
            if n >= LARGE and seed >= large_repeats:
                continue
            for gas in gases:
                announce(f"repeat {seed + 1}/{repeats}: {gas}, N = {n:,}")
                runs[gas, n].append(call_fresh("scale", "measure", gas=gas, n=n, seed=seed, timed=timed))
    rows = []
    for (gas, n), done in runs.items():
        rates = [r["rate"] for r in done]
        rows.append(
            {
                "gas": gas,
                "n": n,
                "packing": GASES[gas][0],
                "rate": median(rates),
                "rate_min": min(rates),
                "rate_max": max(rates),
                "cpu_rate": median([r["cpu_rate"] for r in done]),
                "cpu_rate_min": min(r["cpu_rate"] for r in done),
                "cpu_rate_max": max(r["cpu_rate"] for r in done),
                "bytes_per_disc": median([r["bytes_per_disc"] for r in done]),
                "resident_per_disc": median([r["resident_per_disc"] for r in done]),
                "peak_mb": max(r["peak_mb"] for r in done),
                "collisions": timed,
                "runs": len(done),
            }
        )
    for key, suffix in (("cpu_rate", ""), ("rate", "_wall")):
        by_point = {(r["gas"], r["n"]): r[key] for r in rows}
        reference = by_point.get(REFERENCE, float("nan"))
        for row in rows:
            row[f"over_reference{suffix}"] = row[key] / reference
            row[f"over_mono_same_n{suffix}"] = row[key] / by_point.get(("mono 0.3", row["n"]), float("nan"))
    return rows


COLUMNS = [
    Column("gas", "gas"),
    Column("n", "N", ","),
    Column("rate", "coll/s", ",.0f"),
    Column("cpu_rate", "coll/CPU s", ",.0f"),
    Column("over_reference", "/mono 1e4", ".2f"),
    Column("over_mono_same_n", "/mono same N", ".2f"),
    Column("bytes_per_disc", "B/disc", ".0f"),
    Column("resident_per_disc", "RSS B/disc", ".0f"),
    Column("peak_mb", "peak MB", ".0f"),
]
CSV_KEYS = [
    "gas",
    "n",
    "packing",
    "rate",
    "rate_min",
    "rate_max",
    "cpu_rate",
    "cpu_rate_min",
    "cpu_rate_max",
    "over_reference",
    "over_mono_same_n",
    "over_reference_wall",
    "over_mono_same_n_wall",
    "bytes_per_disc",
    "resident_per_disc",
    "peak_mb",
    "collisions",
    "runs",
]


def plot(rows: Sequence[dict], path: Path, title: str) -> Path:
    """Rate against N (log x), one line per gas: per CPU second (solid, with the min-max band of the repeats)
    and per wall-clock second (dashed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for gas in dict.fromkeys(r["gas"] for r in rows):
        mine = sorted((r for r in rows if r["gas"] == gas), key=lambda r: r["n"])
        ns = [r["n"] for r in mine]
        (line,) = ax.plot(ns, [r["cpu_rate"] for r in mine], marker="o", label=gas)
        ax.fill_between(ns, [r["cpu_rate_min"] for r in mine], [r["cpu_rate_max"] for r in mine], alpha=0.2)
        ax.plot(ns, [r["rate"] for r in mine], linestyle="--", color=line.get_color(), alpha=0.6)
    ax.set_xscale("log")
    ax.set_xlabel("N (discs)")
    ax.set_ylabel("collisions per CPU second (dashed: per wall s)")
    ax.set_ylim(bottom=0)
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="N = 1000, two gases, one short run: proves it runs")
    parser.add_argument("--huge", action="store_true", help=f"add N = {HUGE:,} (minutes and GB per run)")
    parser.add_argument("--sizes", type=int, nargs="+", help=f"numbers of discs (default {SIZES})")
    parser.add_argument("--gases", nargs="+", choices=list(GASES), help="gases (default all)")
    parser.add_argument(
        "--repeats", type=int, help=f"runs per point (default {REPEATS}, and {LARGE_REPEATS} at N >= {LARGE:,})"
    )
    parser.add_argument("--collisions", type=int, help=f"timed collisions per run (default {TIMED:,})")
    parser.add_argument("--results", type=Path, help="CSV and PNG folder (default results/; --quick: a temporary one)")
    parser.add_argument("--stem", default="scale", help="name of the CSV and PNG files (default scale)")
    args = parser.parse_args(argv)
    quick = QUICK if args.quick else {}
    args.sizes = args.sizes or quick.get("sizes") or (*SIZES, *((HUGE,) if args.huge else ()))
    args.gases = args.gases or quick.get("gases") or list(GASES)
    args.large_repeats = args.repeats or quick.get("repeats") or LARGE_REPEATS
    args.repeats = args.repeats or quick.get("repeats") or REPEATS
    args.collisions = args.collisions or quick.get("timed") or TIMED
    if args.repeats < 1 or args.collisions < 1 or min(args.sizes) < 1:
        parser.error("--repeats, --collisions and --sizes must be at least 1")
    args.results = results_folder(args.results, args.quick)
    return args


def main(argv: Sequence[str] | None = None) -> int:
    """Measure, print the table, write ``<stem>.csv`` and ``<stem>.png``."""
    args = parse_args(argv)
    import discsim as ds

    print(f"discsim {ds.__version__} scale (numba backend); {machine_summary()}")
    print(
        f"{args.collisions:,} timed collisions per run after min({WARMUP_MAX:,}, {WARMUP_PER_DISC} N) to warm up; "
        f"median of {args.repeats} run(s) per point ({args.large_repeats} at N >= {LARGE:,}), each in a fresh process"
    )
    rows = run_points(args.gases, args.sizes, args.repeats, args.collisions, args.large_repeats)
    print(format_table(rows, COLUMNS))
    csv_path = write_csv(args.results / f"{args.stem}.csv", rows, CSV_KEYS)
    png = plot(rows, args.results / f"{args.stem}.png", f"discsim {ds.__version__}, numba backend: rate against N")
    print(f"wrote {csv_path}, {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
