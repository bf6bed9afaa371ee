"""Throughput of discsim's event-driven engine (PIC): collisions/s, events/s, queue size, memory.

Run ``python benchmarks/throughput.py`` (a few minutes) or ``--quick`` (seconds).
For each N and packing fraction, a seeded periodic :func:`discsim.random_gas`
is built, equilibrated for a few collisions per disc (a dense start is a
crystal and must melt), then timed over a fixed number of collisions. Every
measurement is the median of several runs, each from its own seed.

Definitions, as printed and written to CSV:

* ``collisions/s``: disc-disc collisions in the timed segment / its wall-clock
  seconds (median, with the smallest and largest of the runs); ``coll/CPU-s``
  divides by the process's CPU seconds instead, which other processes on a busy
  machine inflate less (the header prints the load average).
* ``events/s``: every event the engine pops in that segment (collisions, wall
  hits, cell crossings and stale events) per second.
* ``max queue``: ``sim.max_queue``, the largest number of pending events seen
  over the whole run (construction included).
* ``peak MB``: ``tracemalloc`` peak of Python and numpy allocations while building
  the gas and the engine and equilibrating it, in a separate untimed pass
  (tracemalloc slows Python down, so it never runs during timing).
* ``RSS MB``: peak resident size (:func:`benchutils.peak_resident_mb`) of a fresh Python
  process that imports discsim, builds the same gas and engine and equilibrates
  it: what the operating system sees, interpreter and numpy included (the CSV
  also has ``rss_import_mb``, the peak after the imports alone). This script's
  own peak resident size is printed at the end; it is larger, because memory
  freed by one run is not returned to the system before the next.

Sections are functions listed in :data:`SECTIONS`; the fixed-step (PIT)
sections of issue 4 join that list when the PIT engine lands. Output:
``throughput.csv``, ``throughput_queue.csv`` and ``throughput.png`` in ``--results``.
"""

from __future__ import annotations

import dataclasses
import gc
import math
import subprocess
import sys
import tracemalloc
from pathlib import Path

from benchutils import (
    Column,
    announce,
    format_table,
    load_average,
    machine_summary,
    median,
    parse_args,
    peak_resident_mb,
    timed,
    write_csv,
)

import discsim as ds


@dataclasses.dataclass(frozen=True)
class Config:
    """Sizes and run lengths of one benchmark mode.

    Attributes:
        sizes: numbers of discs N.
        fractions: packing fractions.
        repeats: timed runs per point (the median is reported).
        equilibrate_per_disc: untimed collisions per disc before timing.
        timed_per_disc, timed_min: the timed segment has
            ``max(timed_per_disc * N, timed_min)`` collisions.
        queue_sizes, queue_fraction: where ``sorted`` and ``heap`` queues run side by side.
        memory: run the tracemalloc pass.
    """

    sizes: tuple[int, ...]
    fractions: tuple[float, ...]
    repeats: int
    equilibrate_per_disc: float
    timed_per_disc: float
    timed_min: int
    queue_sizes: tuple[int, ...]
    queue_fraction: float
    memory: bool = True

    def timed_collisions(self, n: int) -> int:
        """Collisions in the timed segment for ``n`` discs."""
        return max(int(self.timed_per_disc * n), self.timed_min)


FULL = Config(
    sizes=(1_000, 10_000, 100_000),
    fractions=(0.3, 0.7),
    repeats=3,
    equilibrate_per_disc=2.0,
    timed_per_disc=5.0,
    timed_min=50_000,
    queue_sizes=(1_000, 10_000, 100_000),
    queue_fraction=0.3,
)

QUICK = Config(
    sizes=(100, 400),
    fractions=(0.3, 0.7),
    repeats=1,
    equilibrate_per_disc=1.0,
    timed_per_disc=5.0,
    timed_min=1_000,
    queue_sizes=(400,),
    queue_fraction=0.3,
)

_EVENT_KINDS = ("collisions", "wall_hits", "cell_crossings", "stale")


# --- one measurement -------------------------------------------------------------------
def measure_pic(n: int, packing_fraction: float, queue: str, seed: int, config: Config) -> dict:
    """Build, equilibrate and time one event-driven run.

    Args:
        n: number of discs.
        packing_fraction: of the periodic random gas.
        queue: ``"sorted"`` or ``"heap"``.
        seed: seed of :func:`discsim.random_gas`.
        config: run lengths.

    Returns:
        A dict with ``setup_s`` (gas and engine construction), ``seconds`` and
        ``cpu_seconds`` (the timed segment, wall-clock and CPU), ``collisions`` and ``events`` in it, ``max_queue``,
        ``queue_size`` and ``simulated_time`` of the segment.
    """
    gc.collect()
    setup = timed(lambda: _build(n, packing_fraction, seed, queue))
    sim = setup.result
    sim.run(events=max(1, round(config.equilibrate_per_disc * n)))
    before, t_before = dict(sim.counts), sim.time
    run = timed(lambda: sim.run(events=config.timed_collisions(n)))
    delta = {k: sim.counts[k] - before[k] for k in _EVENT_KINDS}
    return {
        "setup_s": setup.wall,
        "seconds": run.wall,
        "cpu_seconds": run.cpu,
        "collisions": delta["collisions"],
        "events": sum(delta.values()),
        "max_queue": sim.max_queue,
        "queue_size": sim.queue_size,
        "simulated_time": sim.time - t_before,
    }


def _build(n: int, packing_fraction: float, seed: int, queue: str) -> ds.EventDriven:
    discs, box = ds.random_gas(n, packing_fraction, periodic=True, seed=seed)
    return ds.EventDriven(discs, box, record=False, queue=queue)


def summarise(runs: list[dict], n: int, packing_fraction: float, queue: str) -> dict:
    """One table row from repeated runs of the same point (medians, and the spread of rates)."""
    rates = [r["collisions"] / r["seconds"] for r in runs]
    return {
        "n": n,
        "packing_fraction": packing_fraction,
        "queue": queue,
        "repeats": len(runs),
        "timed_collisions": runs[0]["collisions"],
        "collisions_per_s": median(rates),
        "collisions_per_s_min": min(rates),
        "collisions_per_s_max": max(rates),
        "collisions_per_cpu_s": median([r["collisions"] / r["cpu_seconds"] for r in runs]),
        "events_per_s": median([r["events"] / r["seconds"] for r in runs]),
        "seconds": median([r["seconds"] for r in runs]),
        "setup_s": median([r["setup_s"] for r in runs]),
        "max_queue": max(r["max_queue"] for r in runs),
        "max_queue_per_n": max(r["max_queue"] for r in runs) / n,
    }


def peak_memory_mb(n: int, packing_fraction: float, config: Config) -> float:
    """Tracemalloc peak (MB) of building an ``n``-disc gas and engine and equilibrating it."""
    gc.collect()
    tracemalloc.start()
    try:
        sim = _build(n, packing_fraction, 0, "sorted")
        sim.run(events=max(1, round(config.equilibrate_per_disc * n)))
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return peak / 2**20


#: Run in a fresh interpreter by :func:`peak_rss_mb`: prints the peak resident
#: MB after the imports and after building and equilibrating.
_RSS_PROBE = """
import sys
sys.path.insert(0, sys.argv[4])
from benchutils import peak_resident_mb
import discsim as ds
n, phi, events = int(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
after_import = peak_resident_mb()
discs, box = ds.random_gas(n, phi, periodic=True, seed=0)
ds.EventDriven(discs, box, record=False).run(events=events)
print(after_import, peak_resident_mb())
"""


def peak_rss_mb(n: int, packing_fraction: float, config: Config) -> tuple[float, float]:
    """Peak resident MB of a fresh process after importing discsim, and after building and equilibrating.

    Returns NaNs where the probe fails.
    """
    events = max(1, round(config.equilibrate_per_disc * n))
    here = str(Path(__file__).resolve().parent)
    args = [sys.executable, "-c", _RSS_PROBE, str(n), str(packing_fraction), str(events), here]
    try:
        done = subprocess.run(args, capture_output=True, text=True, check=True, timeout=600)
        after_import, peak = (float(v) for v in done.stdout.split())
    except (subprocess.SubprocessError, ValueError, OSError):
        return math.nan, math.nan
    return after_import, peak


# --- sections --------------------------------------------------------------------------
THROUGHPUT_COLUMNS = [
    Column("n", "N", ","),
    Column("packing_fraction", "phi", ".2f"),
    Column("collisions_per_s", "coll/s", ",.0f"),
    Column("collisions_per_s_min", "min", ",.0f"),
    Column("collisions_per_s_max", "max", ",.0f"),
    Column("collisions_per_cpu_s", "coll/CPU-s", ",.0f"),
    Column("events_per_s", "events/s", ",.0f"),
    Column("timed_collisions", "timed coll", ","),
    Column("seconds", "run s", ".2f"),
    Column("setup_s", "setup s", ".2f"),
    Column("max_queue", "max queue", ","),
    Column("max_queue_per_n", "queue/N", ".3f"),
    Column("peak_mb", "peak MB", ".1f"),
    Column("rss_mb", "RSS MB", ".0f"),
]


def pic_throughput_section(config: Config, results: Path) -> list[dict]:
    """Collisions/s, events/s, max queue and peak memory against N and packing fraction (sorted queue)."""
    rows = []
    for n in config.sizes:
        for phi in config.fractions:
            announce(f"  PIC N={n:,} phi={phi}: {config.repeats} run(s) of {config.timed_collisions(n):,} collisions")
            runs = [measure_pic(n, phi, "sorted", seed, config) for seed in range(config.repeats)]
            row = summarise(runs, n, phi, "sorted")
            if config.memory:
                row["peak_mb"] = peak_memory_mb(n, phi, config)
                row["rss_import_mb"], row["rss_mb"] = peak_rss_mb(n, phi, config)
            rows.append(row)
    print(format_table(rows, THROUGHPUT_COLUMNS))
    print(_targets(rows))
    keys = [c.key for c in THROUGHPUT_COLUMNS] + ["rss_import_mb", "queue", "repeats"]
    write_csv(results / "throughput.csv", rows, keys)
    return rows


def _targets(rows: list[dict]) -> str:
    """Lines comparing the rows with issue 2's speed targets (printed, never asserted)."""
    by_point = {(r["n"], r["packing_fraction"]): r for r in rows}
    lines = []
    if (10_000, 0.3) in by_point:
        rate = by_point[10_000, 0.3]["collisions_per_s"]
        lines.append(f"target >= 40,000 coll/s at N=10^4, phi=0.3: measured {rate:,.0f}")
    for phi in sorted({p for _, p in by_point}):
        if (1_000, phi) in by_point and (100_000, phi) in by_point:
            slowdown = by_point[1_000, phi]["collisions_per_s"] / by_point[100_000, phi]["collisions_per_s"]
            lines.append(f"target N=10^5 at most 2x slower than N=10^3 (phi={phi}): {slowdown:.2f}x slower")
        if (100_000, phi) in by_point and "peak_mb" in by_point[100_000, phi]:
            row = by_point[100_000, phi]
            lines.append(
                f"target peak < 300 MB at N=10^5 (phi={phi}): tracemalloc {row['peak_mb']:.1f} MB, "
                f"fresh-process RSS {row['rss_mb']:.0f} MB ({row['rss_import_mb']:.0f} MB of it after imports)"
            )
    return "\n".join(lines)


QUEUE_COLUMNS = [
    Column("n", "N", ","),
    Column("packing_fraction", "phi", ".2f"),
    Column("queue", "queue"),
    Column("collisions_per_s", "coll/s", ",.0f"),
    Column("collisions_per_s_min", "min", ",.0f"),
    Column("collisions_per_s_max", "max", ",.0f"),
    Column("collisions_per_cpu_s", "coll/CPU-s", ",.0f"),
    Column("events_per_s", "events/s", ",.0f"),
    Column("seconds", "run s", ".2f"),
    Column("max_queue", "max queue", ","),
    Column("speedup_vs_sorted", "vs sorted", ".2f"),
    Column("cpu_speedup_vs_sorted", "vs sorted (CPU)", ".2f"),
]


def queue_section(config: Config, results: Path) -> list[dict]:
    """The ``sorted`` and ``heap`` event queues side by side, runs interleaved so that drift hits both."""
    rows = []
    for n in config.queue_sizes:
        phi = config.queue_fraction
        announce(f"  queues N={n:,} phi={phi}: sorted and heap, {config.repeats} run(s) each, interleaved")
        runs = {"sorted": [], "heap": []}
        for seed in range(config.repeats):
            for queue in runs:
                runs[queue].append(measure_pic(n, phi, queue, seed, config))
        pair = [summarise(runs[q], n, phi, q) for q in runs]
        for row in pair:
            row["speedup_vs_sorted"] = row["collisions_per_s"] / pair[0]["collisions_per_s"]
            row["cpu_speedup_vs_sorted"] = row["collisions_per_cpu_s"] / pair[0]["collisions_per_cpu_s"]
        rows += pair
    print(format_table(rows, QUEUE_COLUMNS))
    write_csv(results / "throughput_queue.csv", rows, [c.key for c in QUEUE_COLUMNS] + ["repeats", "timed_collisions"])
    return rows


def plot(throughput_rows: list[dict], queue_rows: list[dict], path: Path) -> Path:
    """Two panels: collisions/s against N (each phi; heap queue dashed), and max queue size against N."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_rate, ax_queue) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for phi in sorted({r["packing_fraction"] for r in throughput_rows}):
        rows = [r for r in throughput_rows if r["packing_fraction"] == phi]
        ns = [r["n"] for r in rows]
        ax_rate.errorbar(
            ns,
            [r["collisions_per_s"] for r in rows],
            yerr=[
                [r["collisions_per_s"] - r["collisions_per_s_min"] for r in rows],
                [r["collisions_per_s_max"] - r["collisions_per_s"] for r in rows],
            ],
            marker="o",
            capsize=3,
            label=f"phi={phi:g}, sorted queue",
        )
        ax_queue.plot(ns, [r["max_queue"] for r in rows], marker="o", label=f"max queue, phi={phi:g}")
    heap = [r for r in queue_rows if r["queue"] == "heap"]
    if heap:
        phi = heap[0]["packing_fraction"]
        ax_rate.plot(
            [r["n"] for r in heap], [r["collisions_per_s"] for r in heap], "k--", marker="s", label=f"phi={phi:g}, heap"
        )
    ns = sorted({r["n"] for r in throughput_rows})
    ax_queue.plot(ns, ns, "k:", label="N")
    ax_rate.set(xscale="log", yscale="log", xlabel="N discs", ylabel="collisions / s (median)")
    ax_rate.set_title("discsim EventDriven throughput")
    ax_queue.set(xscale="log", yscale="log", xlabel="N discs", ylabel="events pending")
    ax_queue.set_title("largest event queue")
    for ax in (ax_rate, ax_queue):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


#: The sections in run order: (title, function(config, results) -> rows).
#: The PIT sections of issue 4 (frames/s and pair tests/s against N, cell grid
#: against all pairs, PIC against PIT cost per unit of simulated time) are added
#: to this list by the fixed-step work.
SECTIONS = [
    ("PIC throughput (periodic random gas, sorted queue)", pic_throughput_section),
    ("PIC event queue: sorted against heap", queue_section),
]


def main(argv=None) -> int:
    """Run every section, print its table, write CSV files and the PNG; return the exit code."""
    args = parse_args(__doc__.splitlines()[0], argv)
    config = QUICK if args.quick else FULL
    if args.repeats is not None:
        config = dataclasses.replace(config, repeats=args.repeats)
    print(f"discsim {ds.__version__} throughput; {machine_summary()}")
    print(f"mode: {'quick' if args.quick else 'full'}, median of {config.repeats} run(s) per point")
    outputs = {}
    for title, section in SECTIONS:
        print(f"\n== {title} ==")
        outputs[section.__name__] = section(config, args.results)
    png = plot(outputs["pic_throughput_section"], outputs["queue_section"], args.results / "throughput.png")
    print(f"\nthis script's peak resident memory: {peak_resident_mb():.0f} MB")
    print(f"load average at the end: {load_average():.2f}")
    print(f"wrote {args.results / 'throughput.csv'}, {args.results / 'throughput_queue.csv'}, {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
