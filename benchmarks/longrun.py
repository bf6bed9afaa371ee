"""Long runs (issue 6): what a streamed event log costs, and whether a dense run stays healthy.

Run ``python benchmarks/longrun.py`` (several minutes) or ``--quick`` (seconds).

Section (a), storage: a seeded periodic gas (packing 0.5) runs a fixed number of
physical events three ways: no log (``record=False``), the log in memory
(``record=True``) and the log streamed to disk (``record=False,
record_to=path``). Reported:

* ``bytes/event``: size of the streamed file / events in it (header included).
* ``traced MB`` after each fifth of the run and ``peak MB``: ``tracemalloc``
  figures of Python and numpy allocations during the run, in a separate pass
  (tracemalloc slows Python down, so it never runs during timing). Flat for
  the streamed log, growing with the run for the in-memory one.
* ``coll/s`` and ``coll/CPU-s``: disc-disc collisions per wall-clock second and
  per CPU second of this process, in an untraced pass.

Section (b), the hardest density: N discs at packing fraction 0.72 (dense,
near the liquid-hexatic transition; the start is a crystal that melts) run
10^7 collisions (``--quick``: far fewer) as a real long run would, streaming
the log and checkpointing every segment into a temporary folder. For each
segment (a tenth of the run): collisions/s, the relative energy drift since
the start, the deepest overlap seen at a collision within the segment
(``sim.max_overlap``, reset at each segment's start, as a fraction of the
contact distance), the compressibility factor Z so far and the fraction of
stale events. None of them may degrade from segment to segment. Next to the
overlap, ``ulp(t) v/2r`` is the resolution lazy clocks would have if they ran
on the absolute time (one unit in the last place of ``t``, times the rms
speed, over the contact distance). The engine moves its clock origin every
``max(2^18, 16 N)`` physical events, so its deepest overlap stays flat while
this line climbs with ``t``.

Output in ``--results``: ``longrun_storage.csv``, ``longrun_memory.csv``,
``longrun_dense.csv`` and ``longrun.png``.
"""

from __future__ import annotations

import dataclasses
import gc
import math
import shutil
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
from benchutils import Column, announce, format_table, machine_summary, parse_args, write_csv

import discsim as ds


@dataclasses.dataclass(frozen=True)
class Config:
    """Sizes of one benchmark mode.

    Attributes:
        storage_n: discs in section (a). storage_events: physical events per run in (a).
        dense_n: discs in section (b). dense_collisions: collisions in (b).
        segments: segments of the dense run (and fifths of the storage runs).
    """

    storage_n: int
    storage_events: int
    dense_n: int
    dense_collisions: int
    segments: int


FULL = Config(storage_n=1000, storage_events=200_000, dense_n=10_000, dense_collisions=10_000_000, segments=10)
QUICK = Config(storage_n=200, storage_events=5_000, dense_n=400, dense_collisions=30_000, segments=3)
FIFTHS = 5


# --- (a) storage ---------------------------------------------------------------------------------
def _storage_sim(config: Config, mode: str):
    discs, box = ds.random_gas(config.storage_n, 0.5, periodic=True, seed=1)
    return ds.EventDriven(discs, box, record=(mode == "in memory"))


def _run_kwargs(mode: str, folder: Path, tag: str) -> dict:
    return {"record_to": folder / f"{tag}.dse"} if mode == "streamed" else {}


def storage(config: Config, folder: Path) -> tuple[list[dict], list[dict]]:
    """Section (a): rows per mode, and traced memory after each fifth of the run."""
    rows, memory = [], []
    step = config.storage_events // FIFTHS
    for mode in ("no log", "in memory", "streamed"):
        announce(f"(a) {mode}: {config.storage_events:,} events, N={config.storage_n}")
        sim = _storage_sim(config, mode)
        gc.collect()
        wall, cpu = time.perf_counter(), time.process_time()
        sim.run(events=config.storage_events, **_run_kwargs(mode, folder, "timed"))
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        collisions = sim.counts["collisions"]

        sim = _storage_sim(config, mode)
        gc.collect()
        tracemalloc.start()
        base = tracemalloc.get_traced_memory()[0]
        for fifth in range(1, FIFTHS + 1):
            sim.run(events=step, **_run_kwargs(mode, folder, "traced"))
            current, peak = tracemalloc.get_traced_memory()
            memory.append(
                {
                    "mode": mode,
                    "events": fifth * step,
                    "traced_mb": (current - base) / 1e6,
                    "peak_mb": (peak - base) / 1e6,
                }
            )
        tracemalloc.stop()
        row = {
            "mode": mode,
            "n": config.storage_n,
            "events": config.storage_events,
            "collisions_per_s": collisions / wall,
            "collisions_per_cpu_s": collisions / cpu,
            "peak_mb": memory[-1]["peak_mb"],
            "first_fifth_mb": memory[-FIFTHS]["traced_mb"],
            "last_fifth_mb": memory[-1]["traced_mb"],
            "bytes_per_event": float("nan"),
            "memory_bytes_per_event": (memory[-1]["traced_mb"] - memory[-FIFTHS]["traced_mb"])
            * 1e6
            / (config.storage_events - step),
        }
        if mode == "streamed":
            path = folder / "timed.dse"
            records = len(ds.read_events(path).events)
            row["bytes_per_event"] = path.stat().st_size / records
        rows.append(row)
        del sim
    return rows, memory


STORAGE_COLUMNS = [
    Column("mode", "log"),
    Column("n", "N"),
    Column("events", "events", ","),
    Column("collisions_per_s", "coll/s", ",.0f"),
    Column("collisions_per_cpu_s", "coll/CPU-s", ",.0f"),
    Column("first_fifth_mb", "MB at 1/5", ".2f"),
    Column("last_fifth_mb", "MB at 5/5", ".2f"),
    Column("peak_mb", "peak MB", ".2f"),
    Column("memory_bytes_per_event", "RAM bytes/event", ".1f"),
    Column("bytes_per_event", "disk bytes/event", ".2f"),
]


# --- (b) the hardest density ------------------------------------------------------------------------
def v_rms(sim) -> float:
    """Root-mean-square speed of the discs (unit masses)."""
    return math.sqrt(2.0 * sim.kinetic_energy() / len(sim.discs))


def dense(config: Config, folder: Path) -> list[dict]:
    """Section (b): one row per segment of the 0.72 run."""
    discs, box = ds.random_gas(config.dense_n, 0.72, periodic=True, seed=1)
    sim = ds.EventDriven(discs, box, record=False)
    e0 = discs.kinetic_energy()
    segment = config.dense_collisions // config.segments
    log, state = folder / "dense.dse", folder / "dense.dsc"
    rows, worst = [], 0.0
    previous = sim.counts
    announce(
        f"(b) packing 0.72, N={config.dense_n}: {config.dense_collisions:,} collisions in {config.segments} segments"
    )
    for k in range(1, config.segments + 1):
        sim.max_overlap = 0.0  # the deepest overlap within this segment
        wall, cpu = time.perf_counter(), time.process_time()
        sim.run(events=segment, record_to=log, checkpoint=state, checkpoint_every=segment)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        counts = sim.counts
        collisions = counts["collisions"] - previous["collisions"]
        popped = sum(counts[key] - previous[key] for key in ("collisions", "wall_hits", "cell_crossings", "stale"))
        worst = max(worst, sim.max_overlap)
        rows.append(
            {
                "segment": k,
                "collisions": counts["collisions"],
                "time": sim.time,
                "collisions_per_s": collisions / wall,
                "collisions_per_cpu_s": collisions / cpu,
                "energy_drift": (sim.kinetic_energy() - e0) / e0,
                "max_overlap": sim.max_overlap,
                "max_overlap_so_far": worst,
                # What an absolute clock would resolve: one ulp of t times the rms speed, over the
                # contact distance 2 r (r = 1 here). The engine's clock origin moves, so it does better.
                "clock_resolution": float(np.spacing(sim.time)) * v_rms(sim) / 2.0,
                "Z": ds.compressibility_factor(sim),
                "stale_fraction": (counts["stale"] - previous["stale"]) / popped,
                "log_gb": log.stat().st_size / 1e9,
            }
        )
        previous = counts
        announce(
            f"  segment {k}: {rows[-1]['collisions_per_s']:,.0f} coll/s, drift {rows[-1]['energy_drift']:.1e}, "
            f"overlap {rows[-1]['max_overlap']:.1e}"
        )
    stream = ds.checkpoint_info(state)["stream"]
    assert stream["records"] == sim.counts["collisions"] + sim.counts["wall_hits"]
    return rows


DENSE_COLUMNS = [
    Column("segment", "segment"),
    Column("collisions", "collisions", ","),
    Column("time", "t", ".4g"),
    Column("collisions_per_s", "coll/s", ",.0f"),
    Column("collisions_per_cpu_s", "coll/CPU-s", ",.0f"),
    Column("energy_drift", "energy drift", ".2e"),
    Column("max_overlap", "deepest overlap", ".2e"),
    Column("clock_resolution", "ulp(t) v/2r", ".1e"),
    Column("Z", "Z so far", ".4f"),
    Column("stale_fraction", "stale", ".3f"),
    Column("log_gb", "log GB", ".3f"),
]


def verdict(rows: list[dict]) -> str:
    """One line comparing the last segment with the first ones (rate, drift, overlap)."""
    first, last = rows[0], rows[-1]
    settled = rows[1] if len(rows) > 1 else first  # the first segment includes the crystal melting
    return (
        f"last segment vs second: coll/CPU-s x{last['collisions_per_cpu_s'] / settled['collisions_per_cpu_s']:.2f}; "
        f"|energy drift| {abs(first['energy_drift']):.1e} -> {abs(last['energy_drift']):.1e}; "
        f"deepest overlap {max(r['max_overlap'] for r in rows[: len(rows) // 2]):.1e} (first half) vs "
        f"{max(r['max_overlap'] for r in rows[len(rows) // 2 :]):.1e} (second half)"
    )


def plot(memory: list[dict], rows: list[dict], path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    for mode in ("in memory", "streamed", "no log"):
        points = [m for m in memory if m["mode"] == mode]
        axes[0].plot([m["events"] for m in points], [m["traced_mb"] for m in points], "o-", label=mode)
    axes[0].set(xlabel="physical events", ylabel="traced memory (MB)", title="(a) memory while recording")
    axes[0].ticklabel_format(axis="x", style="sci", scilimits=(0, 0))
    axes[0].legend()
    x = [r["collisions"] for r in rows]
    axes[1].plot(x, [r["collisions_per_s"] for r in rows], "o-", label="per wall-clock s")
    axes[1].plot(x, [r["collisions_per_cpu_s"] for r in rows], "s--", label="per CPU s")
    axes[1].set(xlabel="collisions", ylabel="collisions/s", title="(b) packing 0.72: speed per segment", ylim=(0, None))
    axes[1].legend()
    axes[2].semilogy(x, [max(abs(r["energy_drift"]), 1e-18) for r in rows], "o-", label="|energy drift|")
    axes[2].semilogy(x, [max(r["max_overlap"], 1e-18) for r in rows], "s-", label="deepest overlap")
    axes[2].semilogy(x, [r["clock_resolution"] for r in rows], "k:", label="ulp(t) v / 2r (absolute clock)")
    axes[2].set(xlabel="collisions", title="(b) packing 0.72: roundoff per segment")
    axes[2].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv=None) -> int:
    args = parse_args(__doc__.splitlines()[0], argv)
    config = QUICK if args.quick else FULL
    print(f"discsim long runs ({'quick' if args.quick else 'full'}): {machine_summary()}")
    folder = Path(tempfile.mkdtemp(prefix="discsim-longrun-"))
    try:
        rows, memory = storage(config, folder)
        print("\n(a) the event log: in memory or streamed to disk (packing 0.5, periodic)")
        print(format_table(rows, STORAGE_COLUMNS))
        dense_rows = dense(config, folder)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    print(f"\n(b) {config.dense_collisions:,} collisions at packing fraction 0.72, N={config.dense_n}, periodic")
    print(format_table(dense_rows, DENSE_COLUMNS))
    print(verdict(dense_rows))
    results = args.results
    write_csv(results / "longrun_storage.csv", rows, [*rows[0]])
    write_csv(results / "longrun_memory.csv", memory, [*memory[0]])
    write_csv(results / "longrun_dense.csv", dense_rows, [*dense_rows[0]])
    png = plot(memory, dense_rows, results / "longrun.png")
    print(f"\nwritten: longrun_storage.csv, longrun_memory.csv, longrun_dense.csv, {png.name} in {results}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
