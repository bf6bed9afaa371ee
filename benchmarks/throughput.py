"""Throughput of discsim's event-driven engine (PIC): collisions/s, events/s, queue size, memory.

Run ``python benchmarks/throughput.py`` (about 15 minutes in full, more on a loaded machine) or ``--quick`` (seconds).
For each N and packing fraction, a seeded periodic :func:`discsim.random_gas`
is built, equilibrated for a few collisions per disc (a dense start is a
crystal and must melt), then timed over a fixed number of collisions. Every
measurement is the median of several runs, each from its own seed and in its
own fresh Python process (:func:`measure_pic_fresh`: a run that follows a
larger one in the same process inherits the heap it left behind); the runs
of the main section are interleaved over the points
(every point once, then again), so that a slow spell of a shared machine does
not bias the ratios between sizes that the engine issue's targets are about.

The main PIC section and the queue section time the pure-Python backend (``backend="python"``: the one
with a choice of queues); the backends section (``benchmarks/backends.py``, ``backends.csv``) puts it side
by side with the compiled backend. The main PIC section times the engine's default event queue (the ``queue``
column names it: ``calendar`` when this was written). The queue section runs
``calendar``, ``sorted`` and ``heap`` side by side at packing fraction 0.3,
runs interleaved (seed by seed, queue by queue) so that drift in the machine's
load hits all three alike; the three give bit-identical simulations, so they
time the same collisions.

Definitions, as printed and written to CSV:

* ``collisions/s``: disc-disc collisions in the timed segment / its wall-clock
  seconds (median, with the smallest and largest of the runs); ``coll/CPU-s``
  divides by the process's CPU seconds instead, which other processes on a busy
  machine inflate less (the header prints the load average).
* ``events/s``: every event the engine pops in that segment (collisions, wall
  hits, cell crossings and stale events) per second.
* ``max queue``: ``sim.max_queue``, the largest number of pending (live)
  events seen over the whole run (construction included); the largest over the runs.
* ``storage`` (queue section): entries the queue holds at the end of the timed
  segment, dead ones included (the heap and the calendar keep replaced events
  until they are popped or compacted; ``sorted`` holds live ones only). A
  snapshot, the largest over the runs; ``storage/N`` divides it by N.
* ``vs sorted``: a queue's median collisions/s over that of ``sorted`` at the
  same N (``vs sorted (CPU)`` the same with CPU seconds).
* ``peak MB``: ``tracemalloc`` peak of Python and numpy allocations while building
  the gas and the engine and equilibrating it, in a separate untimed pass
  (tracemalloc slows Python down, so it never runs during timing).
* ``RSS MB``: peak resident size (:func:`benchutils.peak_resident_mb`) of a fresh Python
  process that imports discsim, builds the same gas and engine and equilibrates
  it: what the operating system sees, interpreter and numpy included (the CSV
  also has ``rss_import_mb``, the peak after the imports alone). This script's
  own peak resident size is printed at the end; it is larger, because memory
  freed by one run is not returned to the system before the next.

PIT (fixed-step) sections, on the same kind of equilibrated periodic gas:

* ``frames/s`` and ``tests/s``: :class:`discsim.FixedStep` frames and
  narrow-phase pair tests (``counts["pair_tests"]``) per wall-clock second,
  with the cell grid and with all pairs (all pairs only up to
  ``pit_all_pairs_max`` discs), at packing fraction 0.3 and the frame step that
  keeps PIT within 1% missed collisions there.
* ``PIC s/unit t`` and ``PIT s/unit t``: wall-clock seconds per unit of
  simulated time of the event-driven engine, and of the fixed-step engine
  (cell grid, policy ``resolve``) at that 1% frame step, timed side by side from
  the same gases. The step ``s = v dt / r`` (``v`` the rms speed) is read from
  ``accuracy_map_boundary.csv`` (column ``largest_step_missed_ok``), or measured
  with :func:`discsim.analysis.compare` when that file is missing; the output says
  which. ``crossover step``: the step at which PIT would cost as much as PIC.

Targets: the end of the PIC section prints the engine issue's targets
against the measured medians, each marked ``met``, ``not met`` or ``not
measured`` (the point was not run, e.g. in ``--quick`` mode), and writes them
to ``throughput_targets.csv`` (:data:`TARGETS`): collisions/s at N = 10^4,
packing 0.3, at least 40,000; collisions/s at N = 10^3 over those at N = 10^5
(packing 0.3 and 0.7) at most 2; fresh-process peak RSS at N = 10^5 (the
larger over the packing fractions) under 300 MB. Figures only: nothing here
asserts a time.

Sections are functions listed in :data:`SECTIONS`. Output: ``throughput.csv``,
``throughput_targets.csv``, ``throughput_queue.csv``, ``throughput_pit.csv``,
``throughput_crossover.csv``, ``throughput.png`` (collisions/s against N, the
default queue per packing fraction with error bars and the three queues at
0.3 dashed/dotted; pending events and queue storage against N) and
``throughput_pit.png`` in ``--results``.
"""

from __future__ import annotations

import csv
import dataclasses
import gc
import inspect
import json
import math
import operator
import subprocess
import sys
import tracemalloc
from pathlib import Path

from benchutils import (
    DEFAULT_RESULTS,
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
        queue_sizes, queue_fraction: where the three event queues (:data:`QUEUES`) run side by side.
        pit_sizes: N of the fixed-step frames/s section (packing fraction 0.3).
        pit_all_pairs_max: largest N at which the all-pairs broad phase runs.
        pit_frames, pit_all_pairs_frames: timed frames per run in that section
            (cell grid, all pairs: an all-pairs frame at N = 10^4 takes seconds).
        cost_sizes, cost_fractions: where PIC and PIT cost per unit of simulated time are compared.
        cost_frames: timed PIT frames per run in that comparison.
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
    pit_sizes: tuple[int, ...] = ()
    pit_all_pairs_max: int = 0
    pit_frames: int = 20
    pit_all_pairs_frames: int = 3
    cost_sizes: tuple[int, ...] = ()
    cost_fractions: tuple[float, ...] = ()
    cost_frames: int = 50
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
    # Every timed segment lasts several seconds: N = 10^3 and 10^4 run as many collisions as
    # N = 10^5. With 50,000 (under a second at N = 10^3), one slow spell of this shared machine
    # (seen to last 1-3 s, at 60% of the rate) could fill a whole run of the small sizes.
    timed_min=500_000,
    queue_sizes=(1_000, 10_000, 100_000),
    queue_fraction=0.3,
    pit_sizes=(1_000, 10_000, 100_000),
    pit_all_pairs_max=10_000,
    pit_frames=20,
    cost_sizes=(1_000, 10_000),
    cost_fractions=(0.3, 0.6),
    cost_frames=100,
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
    pit_sizes=(100, 400),
    pit_all_pairs_max=400,
    pit_frames=5,
    cost_sizes=(100,),
    cost_fractions=(0.3,),
    cost_frames=20,
)

_EVENT_KINDS = ("collisions", "wall_hits", "cell_crossings", "stale")

#: The event queues of :class:`discsim.EventDriven`, compared side by side by :func:`queue_section`.
QUEUES = ("calendar", "sorted", "heap")
#: The queue the engine uses when none is given (what the main PIC section times).
DEFAULT_QUEUE = inspect.signature(ds.EventDriven).parameters["queue"].default


# --- one measurement -------------------------------------------------------------------
def measure_pic(n: int, packing_fraction: float, queue: str | None, seed: int, config: Config) -> dict:
    """Build, equilibrate and time one event-driven run.

    Args:
        n: number of discs.
        packing_fraction: of the periodic random gas.
        queue: one of :data:`QUEUES`, or None for the engine's default.
        seed: seed of :func:`discsim.random_gas`.
        config: run lengths.

    Returns:
        A dict with ``queue`` (the queue used), ``setup_s`` (gas and engine
        construction), ``seconds`` and ``cpu_seconds`` (the timed segment,
        wall-clock and CPU), ``collisions`` and ``events`` in it, ``max_queue``,
        ``queue_size`` and ``storage`` at its end, and ``simulated_time`` of the segment.
    """
    gc.collect()
    setup = timed(lambda: _build(n, packing_fraction, seed, queue))
    sim = setup.result
    sim.run(events=max(1, round(config.equilibrate_per_disc * n)))
    before, t_before = dict(sim.counts), sim.time
    run = timed(lambda: sim.run(events=config.timed_collisions(n)))
    delta = {k: sim.counts[k] - before[k] for k in _EVENT_KINDS}
    return {
        "queue": sim.queue_kind,
        "setup_s": setup.wall,
        "seconds": run.wall,
        "cpu_seconds": run.cpu,
        "collisions": delta["collisions"],
        "events": sum(delta.values()),
        "max_queue": sim.max_queue,
        "queue_size": sim.queue_size,
        "storage": sim.queue_storage,  # entries held, dead ones included (queue_size: live only)
        "simulated_time": sim.time - t_before,
    }


#: Run in a fresh interpreter by :func:`measure_pic_fresh`: prints :func:`measure_pic`'s dict as JSON.
_RUN_PROBE = """
import json, sys
sys.path.insert(0, sys.argv[1])
import throughput
args = json.loads(sys.argv[2])
args["config"] = throughput.Config(**args["config"])
print(json.dumps(throughput.measure_pic(**args)))
"""


def measure_pic_fresh(n: int, packing_fraction: float, queue: str | None, seed: int, config: Config) -> dict:
    """:func:`measure_pic` in a fresh Python process; the same arguments and result.

    Every timed PIC run of the sections gets its own interpreter, as a user's
    run would. In one process, a run inherits the heap the runs before it
    left behind: N = 10^3 runs measured about 4% slower after an N = 10^5
    run than before it (same process, same seeds), which flatters the ratio
    between sizes that the targets are about.
    """
    here = str(Path(__file__).resolve().parent)
    args = {"n": n, "packing_fraction": packing_fraction, "queue": queue, "seed": seed}
    args["config"] = dataclasses.asdict(config)
    command = [sys.executable, "-c", _RUN_PROBE, here, json.dumps(args)]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode:
        msg = f"the timed run N={n} phi={packing_fraction} queue={queue} seed={seed} failed:\n{done.stderr}"
        raise RuntimeError(msg)
    return json.loads(done.stdout.splitlines()[-1])


def _build(n: int, packing_fraction: float, seed: int, queue: str | None = None) -> ds.EventDriven:
    """A periodic random gas and its engine under the Python backend (the one with a choice of queue);
    ``queue=None`` leaves the engine's default. The compiled backend is timed by :func:`backends_section`."""
    discs, box = ds.random_gas(n, packing_fraction, periodic=True, seed=seed)
    options = {} if queue is None else {"queue": queue}
    return ds.EventDriven(discs, box, record=False, backend="python", **options)


def backends_section(config: Config, results: Path) -> list[dict]:
    """The two backends side by side (``benchmarks/backends.py``): writes ``backends.csv``."""
    import backends

    quick = config.repeats == 1 and max(config.sizes) < 1000
    return backends.backends_section(backends.QUICK if quick else backends.FULL, config.repeats, results)


def summarise(runs: list[dict], n: int, packing_fraction: float) -> dict:
    """One table row from repeated runs of the same point and queue (medians, and the spread of rates)."""
    rates = [r["collisions"] / r["seconds"] for r in runs]
    return {
        "rates": tuple(rates),  # per run, in seed order (not written to CSV; the targets pair them)
        "n": n,
        "packing_fraction": packing_fraction,
        "queue": runs[0]["queue"],
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
        "storage": max(r["storage"] for r in runs),
        "storage_per_n": max(r["storage"] for r in runs) / n,
    }


def peak_memory_mb(n: int, packing_fraction: float, config: Config) -> float:
    """Tracemalloc peak (MB) of building an ``n``-disc gas and engine (default queue) and equilibrating it."""
    gc.collect()
    tracemalloc.start()
    try:
        sim = _build(n, packing_fraction, 0)
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

    The engine uses its default queue.

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
    Column("queue", "queue"),
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
    """Collisions/s, events/s, max queue and peak memory against N and packing fraction (default queue).

    Ends with the engine issue's targets (:func:`target_rows`), printed and
    written to ``throughput_targets.csv``.
    """
    # Repeats are interleaved over the points (every point once, then again), so that a slow spell
    # of this shared machine falls on all sizes alike and the ratios between sizes stay fair.
    points = [(n, phi) for n in config.sizes for phi in config.fractions]
    runs: dict[tuple[int, float], list[dict]] = {point: [] for point in points}
    for seed in range(config.repeats):
        for n, phi in points:
            timed = config.timed_collisions(n)
            announce(f"  PIC N={n:,} phi={phi}: run {seed + 1}/{config.repeats}, {timed:,} collisions")
            runs[n, phi].append(measure_pic_fresh(n, phi, None, seed, config))
    rows = []
    for n, phi in points:
        row = summarise(runs[n, phi], n, phi)
        if config.memory:
            row["peak_mb"] = peak_memory_mb(n, phi, config)
            row["rss_import_mb"], row["rss_mb"] = peak_rss_mb(n, phi, config)
        rows.append(row)
    print(format_table(rows, THROUGHPUT_COLUMNS))
    keys = [c.key for c in THROUGHPUT_COLUMNS] + ["rss_import_mb", "repeats"]
    write_csv(results / "throughput.csv", rows, keys)
    targets = target_rows(rows)
    print(format_targets(targets))
    write_csv(results / "throughput_targets.csv", targets, TARGET_KEYS)
    return rows


# --- the engine issue's targets ----------------------------------------------------------
#: ``(target, description, comparison, limit, unit)`` of each target, in print order.
TARGETS = (
    ("collisions_per_s_n1e4_phi0.3", "collisions/s at N=10^4, phi=0.3", ">=", 40_000.0, "coll/s"),
    ("slowdown_n1e3_over_n1e5_phi0.3", "coll/s at N=10^3 over coll/s at N=10^5, phi=0.3", "<=", 2.0, "x"),
    ("slowdown_n1e3_over_n1e5_phi0.7", "coll/s at N=10^3 over coll/s at N=10^5, phi=0.7", "<=", 2.0, "x"),
    ("peak_rss_mb_n1e5", "peak RSS of a fresh process at N=10^5 (largest over phi)", "<", 300.0, "MB"),
)
#: Columns of ``throughput_targets.csv``.
TARGET_KEYS = ["target", "description", "measured", "comparison", "limit", "unit", "status", "queue", "note"]
_FORMATS = {"coll/s": ",.0f", "x": ".2f", "MB": ".0f"}
_COMPARE = {">=": operator.ge, "<=": operator.le, "<": operator.lt}


def target_rows(rows: list[dict]) -> list[dict]:
    """The engine issue's targets against the medians of :func:`pic_throughput_section` rows.

    One row per entry of :data:`TARGETS`, always; ``measured`` is NaN and
    ``status`` ``"not measured"`` where a point needed was not run (as in
    ``--quick`` mode), else ``status`` is ``"met"`` or ``"not met"``.
    Figures only: the caller prints them, nothing asserts them.
    """
    by_point = {(r["n"], r["packing_fraction"]): r for r in rows}

    def rate(n: int, phi: float) -> float:
        return by_point[n, phi]["collisions_per_s"] if (n, phi) in by_point else math.nan

    def slowdown(phi: float) -> float:
        large = rate(100_000, phi)
        return rate(1_000, phi) / large if large > 0 else math.nan

    large = [r for (n, _), r in sorted(by_point.items()) if n == 100_000 and not math.isnan(r.get("rss_mb", math.nan))]
    worst = max(large, key=lambda r: r["rss_mb"], default=None)
    measured = [rate(10_000, 0.3), slowdown(0.3), slowdown(0.7), worst["rss_mb"] if worst else math.nan]
    notes = ["", _paired_note(by_point, 0.3), _paired_note(by_point, 0.7), ""]
    if worst:
        notes[3] = (
            f"phi={worst['packing_fraction']:g}; {worst['rss_import_mb']:.0f} MB of it after imports; "
            f"tracemalloc peak {worst.get('peak_mb', math.nan):.1f} MB"
        )
    queues = sorted({r["queue"] for r in rows})
    out = []
    for (key, description, comparison, limit, unit), value, note in zip(TARGETS, measured, notes, strict=True):
        if math.isnan(value):
            status = "not measured"
        else:
            status = "met" if _COMPARE[comparison](value, limit) else "not met"
        out.append(
            {
                "target": key,
                "description": description,
                "measured": value,
                "comparison": comparison,
                "limit": limit,
                "unit": unit,
                "status": status,
                "queue": "/".join(queues),
                "note": note,
            }
        )
    return out


def _paired_note(by_point: dict, phi: float) -> str:
    """The slowdown of each repeat on its own (N = 10^3 over 10^5, runs paired by seed), or ``""``.

    The main section interleaves its repeats over the points, so run k of both
    sizes ran in the same stretch of the machine's time; their spread shows
    how far one median-of-3 figure can be trusted near its limit.
    """
    small, large = by_point.get((1_000, phi), {}), by_point.get((100_000, phi), {})
    pairs = list(zip(small.get("rates", ()), large.get("rates", ())))
    if len(pairs) < 2:
        return ""
    ratios = ", ".join(f"{a / b:.2f}" for a, b in pairs)
    return f"per repeat (paired by seed): {ratios}"


def format_targets(targets: list[dict]) -> str:
    """The printed targets block: one line per target, measured against the limit, met or not."""
    queue = targets[0]["queue"] if targets else ""
    lines = [f"targets of the engine issue (medians above, queue {queue}; figures, not assertions):"]
    width = max((len(t["description"]) for t in targets), default=0)
    for t in targets:
        fmt = _FORMATS.get(t["unit"], ".3g")
        value = "-" if math.isnan(t["measured"]) else format(t["measured"], fmt)
        text = f"  {t['description']:<{width}}  {value:>8} {t['unit']:<6} (target {t['comparison']} "
        text += f"{format(t['limit'], fmt)}): {t['status']}"
        lines.append(text + (f"  [{t['note']}]" if t["note"] else ""))
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
    Column("storage", "storage", ","),
    Column("storage_per_n", "storage/N", ".3f"),
    Column("speedup_vs_sorted", "vs sorted", ".2f"),
    Column("cpu_speedup_vs_sorted", "vs sorted (CPU)", ".2f"),
]


def queue_section(config: Config, results: Path) -> list[dict]:
    """The three event queues (:data:`QUEUES`) side by side, runs interleaved so that drift hits all alike.

    For each seed every queue runs once, the order rotated from seed to seed
    (with three repeats each queue goes first once). The queues give
    bit-identical simulations; a line is printed if a seed's simulated time
    differs between them (it should not).
    """
    rows = []
    phi = config.queue_fraction
    for n in config.queue_sizes:
        announce(f"  queues N={n:,} phi={phi}: {', '.join(QUEUES)}, {config.repeats} run(s) each, interleaved")
        runs = {q: [] for q in QUEUES}
        for seed in range(config.repeats):
            shift = seed % len(QUEUES)
            for queue in QUEUES[shift:] + QUEUES[:shift]:
                runs[queue].append(measure_pic_fresh(n, phi, queue, seed, config))
            times = {q: runs[q][-1]["simulated_time"] for q in QUEUES}
            if len(set(times.values())) > 1:
                print(f"warning: N={n:,} seed {seed}: the queues simulated different times {times}")
        group = [summarise(runs[q], n, phi) for q in QUEUES]
        sorted_row = group[QUEUES.index("sorted")]
        for row in group:
            row["speedup_vs_sorted"] = row["collisions_per_s"] / sorted_row["collisions_per_s"]
            row["cpu_speedup_vs_sorted"] = row["collisions_per_cpu_s"] / sorted_row["collisions_per_cpu_s"]
        rows += group
    print(format_table(rows, QUEUE_COLUMNS))
    write_csv(results / "throughput_queue.csv", rows, [c.key for c in QUEUE_COLUMNS] + ["repeats", "timed_collisions"])
    return rows


# --- fixed step (PIT) ------------------------------------------------------------------
#: Packing fraction of the PIT frames/s section (issue 3's speed target is set there).
PIT_FRACTION = 0.3
#: PIT response policy whose 1%-missed frame step is used for the cost comparison.
COST_POLICY = "resolve"
#: Steps ``s = v dt / r`` tried when the accuracy map's boundary file is missing.
_FALLBACK_STEPS = (0.001, 0.00215, 0.00464, 0.01, 0.0215, 0.0464, 0.1)


def _equilibrated(n: int, packing_fraction: float, seed: int, per_disc: float) -> tuple[ds.Discs, ds.Box]:
    """A periodic random gas run under PIC for ``per_disc`` collisions per disc, as new discs and its box."""
    discs, box = ds.random_gas(n, packing_fraction, periodic=True, seed=seed)
    sim = ds.EventDriven(discs, box, record=False)
    sim.run(events=max(1, round(per_disc * n)))
    return ds.Discs(sim.positions, sim.velocities, discs.radii, discs.masses), box


def _rms_speed(discs: ds.Discs) -> float:
    return math.sqrt(float((discs.velocities**2).sum(axis=1).mean()))


def measure_pit(discs: ds.Discs, box: ds.Box, dt: float, broad_phase: str, frames: int) -> dict:
    """Time ``frames`` frames of :class:`discsim.FixedStep` (policy ``resolve``) after one untimed frame.

    Returns:
        ``seconds`` and ``cpu_seconds`` of the timed frames, and the ``frames``,
        ``pair_tests`` and ``detections`` counted in them.
    """
    gc.collect()
    sim = ds.FixedStep(discs, box, dt=dt, policy=COST_POLICY, broad_phase=broad_phase, record=False)
    sim.run(frames=1)  # first frame builds the grid: not what a long run pays per frame
    before = dict(sim.counts)
    run = timed(lambda: sim.run(frames=frames))
    delta = {k: sim.counts[k] - before[k] for k in ("frames", "pair_tests", "detections")}
    return {"seconds": run.wall, "cpu_seconds": run.cpu, **delta}


def _pit_row(runs: list[dict], n: int, packing_fraction: float, broad_phase: str, dt: float) -> dict:
    """One table row from repeated PIT runs (medians)."""
    return {
        "n": n,
        "packing_fraction": packing_fraction,
        "broad_phase": broad_phase,
        "repeats": len(runs),
        "dt": dt,
        "timed_frames": runs[0]["frames"],
        "frames_per_s": median([r["frames"] / r["seconds"] for r in runs]),
        "frames_per_cpu_s": median([r["frames"] / r["cpu_seconds"] for r in runs]),
        "seconds_per_frame": median([r["seconds"] / r["frames"] for r in runs]),
        "pair_tests_per_frame": median([r["pair_tests"] / r["frames"] for r in runs]),
        "pair_tests_per_s": median([r["pair_tests"] / r["seconds"] for r in runs]),
        "detections_per_frame": median([r["detections"] / r["frames"] for r in runs]),
    }


PIT_COLUMNS = [
    Column("n", "N", ","),
    Column("broad_phase", "broad phase"),
    Column("frames_per_s", "frames/s", ",.1f"),
    Column("frames_per_cpu_s", "frames/CPU-s", ",.1f"),
    Column("seconds_per_frame", "s/frame", ".3g"),
    Column("pair_tests_per_frame", "tests/frame", ",.0f"),
    Column("pair_tests_per_s", "tests/s", ",.3g"),
    Column("detections_per_frame", "det/frame", ".1f"),
    Column("timed_frames", "frames", ","),
]


def pit_throughput_section(config: Config, results: Path) -> list[dict]:
    """FixedStep frames/s and pair tests/s against N, cell grid against all pairs (periodic gas, phi 0.3).

    The frame step is the one that keeps PIT within 1% missed collisions at
    this packing fraction (see :func:`one_percent_step`).
    """
    phi = PIT_FRACTION
    step, source = one_percent_step(phi, results)
    print(f"periodic gas, phi={phi}, policy {COST_POLICY}; frame step v dt / r = {step:.3g} ({source})")
    rows = []
    for n in config.pit_sizes:
        phases = ["grid"] + (["all-pairs"] if n <= config.pit_all_pairs_max else [])
        runs = {bp: [] for bp in phases}
        for seed in range(config.repeats):
            discs, box = _equilibrated(n, phi, seed, config.equilibrate_per_disc)
            dt = step * float(discs.radii.mean()) / _rms_speed(discs)
            for bp in phases:  # interleaved, so that drift in the machine's load hits both
                frames = config.pit_frames if bp == "grid" else config.pit_all_pairs_frames
                announce(f"  PIT N={n:,} {bp}: run {seed + 1}/{config.repeats}, {frames} frames")
                runs[bp].append(measure_pit(discs, box, dt, bp, frames))
        rows += [_pit_row(runs[bp], n, phi, bp, dt) for bp in phases]
    print(format_table(rows, PIT_COLUMNS))
    keys = [c.key for c in PIT_COLUMNS] + ["packing_fraction", "dt", "repeats"]
    write_csv(results / "throughput_pit.csv", rows, keys)
    return rows


def one_percent_step(packing_fraction: float, results: Path) -> tuple[float, str]:
    """The largest frame step ``s = v dt / r`` at which PIT (policy ``resolve``) misses at most 1% of collisions.

    Read from ``accuracy_map_boundary.csv`` (``largest_step_missed_ok``, the
    nearest packing fraction on the map) in ``results`` or the default results
    folder; when neither has it, measured here with :func:`discsim.analysis.compare`
    (:func:`measure_one_percent_step`).

    Returns:
        The step and a few words saying where it came from.
    """
    for folder in dict.fromkeys((results, DEFAULT_RESULTS)):
        path = folder / "accuracy_map_boundary.csv"
        if not path.exists():
            continue
        with open(path, newline="") as handle:
            rows = [r for r in csv.DictReader(handle) if r["policy"] == COST_POLICY]
        rows = [r for r in rows if not math.isnan(float(r["largest_step_missed_ok"]))]
        if rows:
            row = min(rows, key=lambda r: abs(float(r["packing_fraction"]) - packing_fraction))
            phi = float(row["packing_fraction"])
            return float(row["largest_step_missed_ok"]), f"accuracy_map_boundary.csv at phi={phi:g}"
    return measure_one_percent_step(packing_fraction), "measured with ds.compare, N=200, 2 mean free times"


def measure_one_percent_step(packing_fraction: float, n: int = 200) -> float:
    """The largest of :data:`_FALLBACK_STEPS` at which PIT misses at most 1% of PIC's collisions.

    One equilibrated periodic gas, two mean free times, PIC and PIT from the
    same start, judged by :func:`discsim.analysis.compare`. Returns the smallest step
    tried if none is good.
    """
    discs, box = _equilibrated(n, packing_fraction, 0, 5.0)
    horizon = 2.0 / float(ds.enskog_collision_rate(packing_fraction))
    scale = float(discs.radii.mean()) / _rms_speed(discs)
    truth = ds.EventDriven(discs, box).run(until=2.0 * horizon)
    good = _FALLBACK_STEPS[0]
    for step in _FALLBACK_STEPS:
        approx = ds.FixedStep(discs, box, dt=step * scale, policy=COST_POLICY).run(until=horizon + step * scale)
        if ds.compare(truth, approx, until=horizon).missed_fraction > 0.01:
            break
        good = step
    return good


def measure_pic_cost(discs: ds.Discs, box: ds.Box, collisions: int) -> dict:
    """Wall and CPU seconds of PIC per unit of simulated time over about ``collisions`` collisions."""
    gc.collect()
    sim = ds.EventDriven(discs, box, record=False)
    run = timed(lambda: sim.run(events=collisions))
    return {
        "seconds": run.wall / sim.time,
        "cpu_seconds": run.cpu / sim.time,
        "collisions_per_time": sim.counts["collisions"] / sim.time,
    }


COST_COLUMNS = [
    Column("n", "N", ","),
    Column("packing_fraction", "phi", ".2f"),
    Column("step", "step 1%", ".3g"),
    Column("frame_rate", "frames/unit t", ",.0f"),
    Column("pic_s_per_time", "PIC s/unit t", ".3g"),
    Column("pit_s_per_time", "PIT s/unit t", ".3g"),
    Column("pit_over_pic", "PIT/PIC", ".2f"),
    Column("pit_over_pic_cpu", "PIT/PIC (CPU)", ".2f"),
    Column("crossover_step", "crossover step", ".3g"),
    Column("pic_collisions_per_time", "PIC coll/unit t", ",.0f"),
]


def pic_against_pit_section(config: Config, results: Path) -> list[dict]:
    """Seconds of wall time per unit of simulated time: PIC, and PIT at the frame step for 1% missed.

    ``crossover step`` is the frame step ``s = v dt / r`` at which PIT would cost
    as much as PIC (its seconds per frame times ``v / (s r)`` frames per unit
    time); PIT at 1% missed is cheaper than PIC only where ``step 1%`` exceeds it.
    """
    rows = []
    for phi in config.cost_fractions:
        step, source = one_percent_step(phi, results)
        print(f"phi={phi}: frame step for 1% missed v dt / r = {step:.3g} ({source})")
        for n in config.cost_sizes:
            rows.append(_cost_point(n, phi, step, config))
    print(format_table(rows, COST_COLUMNS))
    print(_crossover_summary(rows))
    write_csv(results / "throughput_crossover.csv", rows, [c.key for c in COST_COLUMNS] + ["dt", "repeats"])
    return rows


def _cost_point(n: int, phi: float, step: float, config: Config) -> dict:
    """PIC and PIT, interleaved over the repeats, from the same equilibrated gases."""
    pic, pit = [], []
    for seed in range(config.repeats):
        announce(f"  cost N={n:,} phi={phi}: run {seed + 1}/{config.repeats}")
        discs, box = _equilibrated(n, phi, seed, config.equilibrate_per_disc)
        dt = step * float(discs.radii.mean()) / _rms_speed(discs)
        pic.append(measure_pic_cost(discs, box, config.timed_collisions(n)))
        pit.append(measure_pit(discs, box, dt, "grid", config.cost_frames))
    frame = median([r["seconds"] / r["frames"] for r in pit])
    frame_cpu = median([r["cpu_seconds"] / r["frames"] for r in pit])
    pic_s = median([r["seconds"] for r in pic])
    pic_cpu = median([r["cpu_seconds"] for r in pic])
    speed_over_radius = step / dt  # v / r
    return {
        "n": n,
        "packing_fraction": phi,
        "step": step,
        "dt": dt,
        "repeats": config.repeats,
        "frame_rate": 1.0 / dt,
        "pic_s_per_time": pic_s,
        "pit_s_per_time": frame / dt,
        "pit_over_pic": frame / dt / pic_s,
        "pit_over_pic_cpu": frame_cpu / dt / pic_cpu,
        "crossover_step": frame * speed_over_radius / pic_s,
        "pic_collisions_per_time": median([r["collisions_per_time"] for r in pic]),
    }


def _crossover_summary(rows: list[dict]) -> str:
    """One line per row: is PIT at 1% missed cheaper than PIC, and by how much the step would have to grow."""
    lines = []
    for r in rows:
        factor = r["crossover_step"] / r["step"]
        verdict = "PIT cheaper" if factor < 1 else f"PIC cheaper; PIT would need a {factor:.3g}x larger step"
        lines.append(f"N={r['n']:,} phi={r['packing_fraction']:g}: PIT/PIC = {r['pit_over_pic']:.3g} ({verdict})")
    return "\n".join(lines)


def plot_pit(pit_rows: list[dict], cost_rows: list[dict], path: Path) -> Path:
    """Two panels: PIT frames/s against N (grid, all pairs), and PIC and PIT seconds per unit simulated time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_frames, ax_cost) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for bp, marker in (("grid", "o"), ("all-pairs", "s")):
        rows = [r for r in pit_rows if r["broad_phase"] == bp]
        if rows:
            ax_frames.plot([r["n"] for r in rows], [r["frames_per_s"] for r in rows], marker=marker, label=bp)
    ax_frames.set(xscale="log", yscale="log", xlabel="N discs", ylabel="frames / s (median)")
    ax_frames.set_title(f"discsim FixedStep, phi={PIT_FRACTION:g}")
    for phi in sorted({r["packing_fraction"] for r in cost_rows}):
        rows = [r for r in cost_rows if r["packing_fraction"] == phi]
        ns = [r["n"] for r in rows]
        (line,) = ax_cost.plot(ns, [r["pic_s_per_time"] for r in rows], marker="o", label=f"PIC, phi={phi:g}")
        ax_cost.plot(
            ns,
            [r["pit_s_per_time"] for r in rows],
            "--",
            marker="s",
            color=line.get_color(),
            label=f"PIT 1%, phi={phi:g}",
        )
    ax_cost.set(xscale="log", yscale="log", xlabel="N discs", ylabel="wall s per unit simulated time")
    ax_cost.set_title("PIC against PIT at 1% missed")
    for ax in (ax_frames, ax_cost):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


#: Line style and marker of each queue in :func:`plot`.
QUEUE_STYLES = {"calendar": ("--", "^"), "sorted": (":", "s"), "heap": ("-.", "D")}


def plot(throughput_rows: list[dict], queue_rows: list[dict], path: Path) -> Path:
    """Two panels against N: collisions/s, and pending events and queue storage.

    Left: the default queue for each phi (solid, min-max error bars), and the
    three queues of :func:`queue_section` (black, dashed/dotted). Right: the
    largest number of pending events for each phi, and each queue's storage
    (dead entries included) in the same styles.
    """
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
            label=f"phi={phi:g}, {rows[0]['queue']} (default)",
        )
        ax_queue.plot(ns, [r["max_queue"] for r in rows], marker="o", label=f"max pending, phi={phi:g}")
    for queue, (style, marker) in QUEUE_STYLES.items():
        rows = [r for r in queue_rows if r["queue"] == queue]
        if not rows:
            continue
        ns, phi = [r["n"] for r in rows], rows[0]["packing_fraction"]
        common = {"color": "k", "marker": marker, "markerfacecolor": "none"}
        label = f"phi={phi:g}, {queue}, side by side"
        ax_rate.plot(ns, [r["collisions_per_s"] for r in rows], style, label=label, **common)
        ax_queue.plot(ns, [r["storage"] for r in rows], style, label=f"storage, {queue}, phi={phi:g}", **common)
    ns = sorted({r["n"] for r in throughput_rows} | {r["n"] for r in queue_rows})
    ax_queue.plot(ns, ns, color="0.6", linewidth=1, label="N")
    ax_rate.set(xscale="log", yscale="log", xlabel="N discs", ylabel="collisions / s (median)")
    ax_rate.set_title("discsim EventDriven throughput")
    ax_queue.set(xscale="log", yscale="log", xlabel="N discs", ylabel="queue entries")
    ax_queue.set_title("event queue: most pending, storage at the end")
    for ax in (ax_rate, ax_queue):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


#: The sections in run order: (title, function(config, results) -> rows).
SECTIONS = [
    (f"PIC throughput (periodic random gas, default queue: {DEFAULT_QUEUE})", pic_throughput_section),
    (f"PIC event queues side by side: {', '.join(QUEUES)}", queue_section),
    ("PIC backends side by side: python against numba (compiled)", backends_section),
    ("PIT throughput: frames/s and pair tests/s, cell grid against all pairs", pit_throughput_section),
    ("PIC against PIT: seconds per unit simulated time at 1% missed", pic_against_pit_section),
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
    pit_png = plot_pit(
        outputs["pit_throughput_section"], outputs["pic_against_pit_section"], args.results / "throughput_pit.png"
    )
    print(f"\nthis script's peak resident memory: {peak_resident_mb():.0f} MB")
    print(f"load average at the end: {load_average():.2f}")
    written = [
        "throughput.csv",
        "throughput_targets.csv",
        "throughput_queue.csv",
        "throughput_pit.csv",
        "throughput_crossover.csv",
        "backends.csv",
    ]
    print(f"wrote {', '.join(str(args.results / f) for f in written)}, {png}, {pit_png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
