"""discsim side by side with other event-driven codes, from the same initial configurations.

Run ``python benchmarks/peers.py`` (a few minutes) or ``--quick`` (seconds).

PIC section: discsim's :class:`~discsim.EventDriven` against

* the naive textbook baseline in ``benchmarks/baselines/naive_event_driven.py``
  (a heap of every pair event, O(N) predictions and O(N) moves per event), and
* the ``billiards`` package (PyPI; ``pip install -e .[bench]``), whose box is
  four ``InfiniteWall`` obstacles; when it is not installed the script says so
  and carries on.

Every engine starts from the same seeded walled :func:`discsim.random_gas` and
runs to the same horizon ``T`` (chosen for about ``collisions_per_disc``
collisions per disc from Enskog's collision rate). Reported per engine:
disc-disc collisions and wall hits over ``[0, T]``, set-up seconds, run seconds
(median of the repeats, engines interleaved), collisions/s over the run (by
wall-clock and by CPU time, which a busy machine inflates less), how many
times faster discsim is (``discsim x``: discsim's collisions/s over the
engine's), and how far each peer's collision count is from
discsim's. Hard-disc dynamics is chaotic, so once roundoff has grown (a few
dozen collisions) the peers' trajectories differ from discsim's in detail:
counts then agree statistically, not exactly.

A peer that has not finished within the budget (setup plus run: 60 s, 30 s
with ``--quick``) is stopped, the point is reported as such, and larger N are skipped for it.

Sections are functions listed in :data:`SECTIONS`; the PIT-against-pymunk
section of issue 4 joins that list when the fixed-step engine lands.
Output: ``peers.csv`` and ``peers.png`` in ``--results``.
"""

from __future__ import annotations

import abc
import argparse
import dataclasses
import gc
import math
import sys
import time
from pathlib import Path

from baselines.naive_event_driven import NaiveEventDriven
from benchutils import (
    Column,
    TimeLimitExceeded,
    announce,
    format_table,
    load_average,
    machine_summary,
    median,
    parse_args,
    time_limit,
    write_csv,
)

import discsim as ds


@dataclasses.dataclass(frozen=True)
class Config:
    """Sizes and run lengths of one mode.

    Attributes:
        sizes: numbers of discs N.
        packing_fraction: of the walled random gas.
        collisions_per_disc, min_collisions: the horizon aims at
            ``max(collisions_per_disc * N, min_collisions)`` disc-disc collisions.
        repeats: timed runs per engine and N (median reported).
        budget_s: wall-clock seconds one run of one peer may take.
        chunks: the run to ``T`` is done in this many equal steps of time
            (so that a stopped run still reports how far it got).
    """

    sizes: tuple[int, ...]
    packing_fraction: float
    collisions_per_disc: float
    min_collisions: int
    repeats: int
    budget_s: float
    chunks: int = 20

    def horizon(self, n: int) -> float:
        """Simulated time ``T`` for ``n`` discs."""
        target = max(self.collisions_per_disc * n, self.min_collisions)
        rate_per_disc = float(ds.enskog_collision_rate(self.packing_fraction))
        return target / (0.5 * n * rate_per_disc)  # each collision involves two discs


FULL = Config(
    sizes=(100, 1_000, 10_000),
    packing_fraction=0.3,
    collisions_per_disc=2.0,
    min_collisions=2_000,
    repeats=3,
    budget_s=60.0,
)

QUICK = Config(
    sizes=(30, 60),
    packing_fraction=0.3,
    collisions_per_disc=2.0,
    min_collisions=100,
    repeats=1,
    budget_s=30.0,
)


# --- the engines, behind one small interface -------------------------------------------
class Peer(abc.ABC):
    """An engine under test: ``build`` from discsim discs and box, then ``advance`` to a time."""

    name = ""
    missing = ""  # why the engine cannot run here ("" when it can)

    @abc.abstractmethod
    def build(self, discs: ds.Discs, box: ds.Box):
        """A simulation of ``discs`` in ``box`` at time 0."""

    @abc.abstractmethod
    def advance(self, sim, until: float) -> tuple[int, int]:
        """Run ``sim`` to time ``until``; return the cumulative ``(collisions, wall_hits)``."""


class DiscsimPeer(Peer):
    """discsim's event-driven engine, event log off."""

    name = "discsim"

    def build(self, discs, box):
        return ds.EventDriven(discs, box, record=False)

    def advance(self, sim, until):
        sim.run(until=until)
        return sim.counts["collisions"], sim.counts["wall_hits"]


class NaivePeer(Peer):
    """The textbook baseline of ``benchmarks/baselines``."""

    name = "naive"

    def build(self, discs, box):
        return NaiveEventDriven(discs, box)

    def advance(self, sim, until):
        sim.run(until=until)
        return sim.counts["collisions"], sim.counts["wall_hits"]


class BilliardsPeer(Peer):
    """The ``billiards`` package: balls in a box of four ``InfiniteWall`` obstacles."""

    name = "billiards"

    def __init__(self):
        try:
            import billiards
        except ImportError:
            self.missing = "billiards is not installed (pip install -e .[bench]); skipped"
            self._billiards = None
        else:
            self._billiards = billiards

    def build(self, discs, box):
        if box.periodic:
            msg = "billiards has no periodic boundaries"
            raise ValueError(msg)
        bl = self._billiards
        w, h = box.width, box.height
        # The inside of the table is on the left of each wall, going round the box anticlockwise.
        corners = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)]
        walls = [bl.InfiniteWall(corners[k], corners[(k + 1) % 4], inside="left") for k in range(4)]
        sim = _BilliardsRun(bl.Billiard(walls))
        for pos, vel, radius, mass in zip(
            discs.positions.tolist(),
            discs.velocities.tolist(),
            discs.radii.tolist(),
            discs.masses.tolist(),
            strict=True,
        ):
            sim.table.add_ball(pos, vel, radius, mass)
        return sim

    def advance(self, sim, until):
        for _, _, other in sim.table.evolve(until):
            if isinstance(other, self._billiards.obstacles.Obstacle):
                sim.wall_hits += 1
            else:
                sim.collisions += 1
        return sim.collisions, sim.wall_hits


@dataclasses.dataclass
class _BilliardsRun:
    """A ``billiards.Billiard`` and the events it has reported so far."""

    table: object
    collisions: int = 0
    wall_hits: int = 0


# --- one measurement -------------------------------------------------------------------
def measure(peer: Peer, discs: ds.Discs, box: ds.Box, horizon: float, config: Config) -> dict:
    """Build ``peer`` and run it to ``horizon`` within the time budget.

    Returns:
        ``status`` ("ok" or "stopped"), ``setup_s``, ``run_s`` and ``run_cpu_s``
        (wall-clock and CPU seconds of the run), ``collisions``,
        ``wall_hits`` and ``reached`` (simulated time reached).
    """
    gc.collect()
    out = {"status": "stopped", "setup_s": math.nan, "run_s": math.nan, "collisions": 0, "wall_hits": 0, "reached": 0.0}
    start = time.perf_counter()
    try:
        with time_limit(config.budget_s):
            sim = peer.build(discs, box)
            out["setup_s"] = time.perf_counter() - start
            run_start, cpu_start = time.perf_counter(), time.process_time()
            for k in range(1, config.chunks + 1):
                t = horizon * k / config.chunks
                out["collisions"], out["wall_hits"] = peer.advance(sim, t)
                out["reached"] = t
            out["run_s"] = time.perf_counter() - run_start
            out["run_cpu_s"] = time.process_time() - cpu_start
            out["status"] = "ok"
    except TimeLimitExceeded:
        pass
    return out


def compare_engines(peers: list[Peer], n: int, config: Config, dropped: dict[str, str]) -> list[dict]:
    """All runnable peers at one N from one initial configuration, repeats interleaved.

    ``dropped`` maps a peer's name to why it is skipped; peers stopped by the
    budget here are added to it, so larger N skip them.
    """
    discs, box = ds.random_gas(n, config.packing_fraction, periodic=False, seed=0)
    horizon = config.horizon(n)
    active = [p for p in peers if p.name not in dropped]
    runs: dict[str, list[dict]] = {p.name: [] for p in active}
    for repeat in range(config.repeats):
        for peer in active:
            if runs[peer.name] and runs[peer.name][-1]["status"] != "ok":
                continue  # stopped once: not worth another minute
            announce(f"  N={n:,} T={horizon:.3g}: {peer.name} run {repeat + 1}/{config.repeats}")
            runs[peer.name].append(measure(peer, discs, box, horizon, config))
    rows = [_row(peer, n, horizon, runs[peer.name], config) for peer in active]
    for peer, row in zip(active, rows, strict=True):
        if row["status"] != "ok":
            dropped[peer.name] = f"not run: did not finish N={n:,} within {config.budget_s:g} s"
    _relate_to_discsim(rows)
    rows += [_skipped_row(name, n, horizon, why) for name, why in dropped.items() if name not in runs]
    return rows


def _row(peer: Peer, n: int, horizon: float, runs: list[dict], config: Config) -> dict:
    ok = [r for r in runs if r["status"] == "ok"]
    row = {"n": n, "engine": peer.name, "horizon": horizon, "repeats": len(ok), "status": "ok" if ok else "stopped"}
    if not ok:
        last = runs[-1]
        stage = (
            "in setup"
            if math.isnan(last["setup_s"])
            else f"after setup {last['setup_s']:.1f} s, at t={last['reached']:.3g} of {horizon:.3g} "
            f"({last['collisions']:,} collisions)"
        )
        row["note"] = f"stopped by the {config.budget_s:g} s budget {stage}"
        row["setup_s"] = last["setup_s"]
        return row
    row["collisions"], row["wall_hits"] = ok[0]["collisions"], ok[0]["wall_hits"]
    row["setup_s"] = median([r["setup_s"] for r in ok])
    row["run_s"] = median([r["run_s"] for r in ok])
    row["collisions_per_s"] = median([r["collisions"] / r["run_s"] for r in ok])
    row["collisions_per_cpu_s"] = median([r["collisions"] / r["run_cpu_s"] for r in ok])
    row["collisions_per_disc"] = row["collisions"] / n
    if any((r["collisions"], r["wall_hits"]) != (row["collisions"], row["wall_hits"]) for r in ok):
        row["note"] = "counts differ between repeats"
    return row


def _relate_to_discsim(rows: list[dict]) -> None:
    """Add discsim's speed-up over each engine and each engine's count difference from discsim."""
    ref = next((r for r in rows if r["engine"] == "discsim" and r["status"] == "ok"), None)
    if ref is None:
        return
    for row in rows:
        if row["status"] != "ok":
            continue
        row["discsim_speedup"] = ref["collisions_per_s"] / row["collisions_per_s"]
        row["discsim_speedup_cpu"] = ref["collisions_per_cpu_s"] / row["collisions_per_cpu_s"]
        row["collision_diff"] = row["collisions"] - ref["collisions"]
        row["collision_diff_pct"] = 100.0 * row["collision_diff"] / ref["collisions"] if ref["collisions"] else math.nan
        row["wall_hit_diff"] = row["wall_hits"] - ref["wall_hits"]


def _skipped_row(name: str, n: int, horizon: float, why: str) -> dict:
    return {"n": n, "engine": name, "horizon": horizon, "status": "skipped", "repeats": 0, "note": why}


# --- sections --------------------------------------------------------------------------
PIC_COLUMNS = [
    Column("n", "N", ","),
    Column("engine", "engine"),
    Column("status", "status"),
    Column("horizon", "T", ".3g"),
    Column("collisions", "collisions", ","),
    Column("collisions_per_disc", "coll/disc", ".1f"),
    Column("wall_hits", "wall hits", ","),
    Column("setup_s", "setup s", ".3f"),
    Column("run_s", "run s", ".3f"),
    Column("collisions_per_s", "coll/s", ",.0f"),
    Column("collisions_per_cpu_s", "coll/CPU-s", ",.0f"),
    Column("discsim_speedup", "discsim x", ".1f"),
    Column("discsim_speedup_cpu", "x (CPU)", ".1f"),
    Column("collision_diff", "d coll", "+,d"),
    Column("collision_diff_pct", "d coll %", "+.2f"),
    Column("wall_hit_diff", "d walls", "+,d"),
]


def pic_peers_section(config: Config, results: Path) -> list[dict]:
    """discsim PIC against the naive baseline and billiards: speed and collision-count agreement."""
    peers = [DiscsimPeer(), NaivePeer(), BilliardsPeer()]
    dropped = {}
    for peer in peers:
        if peer.missing:
            print(f"note: {peer.missing}")
            dropped[peer.name] = peer.missing
    print(
        f"walled random gas, phi={config.packing_fraction}, seed 0; horizon T for about "
        f"max({config.collisions_per_disc:g} N, {config.min_collisions:,}) collisions; "
        f"median of {config.repeats} run(s); budget {config.budget_s:g} s per run"
    )
    rows = []
    for n in config.sizes:
        rows += compare_engines(peers, n, config, dropped)
    print(format_table(rows, PIC_COLUMNS))
    for row in rows:
        if row.get("note"):
            print(f"note: N={row['n']:,} {row['engine']}: {row['note']}")
    keys = [c.key for c in PIC_COLUMNS] + ["repeats", "note"]
    write_csv(results / "peers.csv", rows, keys)
    return rows


def plot(rows: list[dict], path: Path) -> Path:
    """Collisions/s against N for each engine that ran (log-log)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4), constrained_layout=True)
    for engine in dict.fromkeys(r["engine"] for r in rows):
        done = [r for r in rows if r["engine"] == engine and r["status"] == "ok"]
        if done:
            ax.plot([r["n"] for r in done], [r["collisions_per_s"] for r in done], marker="o", label=engine)
    ax.set(xscale="log", yscale="log", xlabel="N discs (walled box)", ylabel="collisions / s (median)")
    ax.set_title("event-driven hard discs: discsim and peers")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


#: The sections in run order: (title, function(config, results) -> rows). The
#: PIT-against-pymunk section of issue 4 (seconds per frame, missed collisions
#: against PIC, energy drift, deepest overlap) is added here by the fixed-step work.
SECTIONS = [
    ("PIC against peers (walled box)", pic_peers_section),
]


def main(argv=None) -> int:
    """Run every section, print its table, write CSV and PNG; return the exit code."""
    args: argparse.Namespace = parse_args(__doc__.splitlines()[0], argv)
    config = QUICK if args.quick else FULL
    if args.repeats is not None:
        config = dataclasses.replace(config, repeats=args.repeats)
    print(f"discsim {ds.__version__} against peers; {machine_summary()}")
    outputs = {}
    for title, section in SECTIONS:
        print(f"\n== {title} ==")
        outputs[section.__name__] = section(config, args.results)
    png = plot(outputs["pic_peers_section"], args.results / "peers.png")
    print(f"\nload average at the end: {load_average():.2f}")
    print(f"wrote {args.results / 'peers.csv'}, {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
