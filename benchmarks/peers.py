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

PIT section: discsim's :class:`~discsim.FixedStep` (cell grid, policy
``resolve``) against ``pymunk`` (PyPI, optional; circles of elasticity 1 and
friction 0, four static segments for the walls, no gravity, pymunk's default
space otherwise: 10 iterations, ``collision_slop`` 0.1, bounding-box tree).
Both start from the same walled gas (the seeded random gas above, melted by
PIC for one collision per disc so that discs touch while timed) and step at the
same ``dt``: the frame step at which FixedStep misses at most 1% of collisions
(``accuracy_map_boundary.csv``, or measured; see ``throughput.py``). Reported:

* ``s/frame``: median of ``repeats`` timings of ``pit_frames`` frames (no
  callbacks installed), and each engine's ratio to pymunk;
* over ``T`` (a couple of mean free times), against PIC from the same start:
  FixedStep through :func:`discsim.analysis.compare`; pymunk through a collision handler
  whose ``begin`` callback records each disc pair that starts touching, with
  the step's time, matched to PIC's collisions by pair, nearest times first,
  within the window ``compare`` used (a pair in lasting contact counts once);
* ``dE/E``: relative change of the kinetic energy over ``T``; ``overlap``:
  deepest disc-disc overlap as a fraction of the contact distance (pymunk's
  from ``pre_solve``, before it solves the contact).

Sections are functions listed in :data:`SECTIONS`. Output: ``peers.csv``,
``peers_pit.csv`` and ``peers.png`` in ``--results``.
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
        pit_sizes: N at which FixedStep and pymunk frames are timed.
        pit_frames: frames per timing (median of ``repeats`` timings).
        pit_accuracy_sizes: N at which both are judged against PIC.
        pit_horizon_free_times: the accuracy horizon, in mean free times.
    """

    sizes: tuple[int, ...]
    packing_fraction: float
    collisions_per_disc: float
    min_collisions: int
    repeats: int
    budget_s: float
    chunks: int = 20
    pit_sizes: tuple[int, ...] = ()
    pit_frames: int = 20
    pit_accuracy_sizes: tuple[int, ...] = ()
    pit_horizon_free_times: float = 2.0

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
    pit_sizes=(1_000, 10_000),
    pit_frames=100,  # several rebuilds of FixedStep's Verlet list per timing, as in a long run
    pit_accuracy_sizes=(1_000, 10_000),
)

QUICK = Config(
    sizes=(30, 60),
    packing_fraction=0.3,
    collisions_per_disc=2.0,
    min_collisions=100,
    repeats=1,
    budget_s=30.0,
    pit_sizes=(60,),
    pit_frames=5,
    pit_accuracy_sizes=(60,),
    pit_horizon_free_times=1.0,
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


# --- PIT against pymunk ----------------------------------------------------------------
#: FixedStep's response policy in this section.
PIT_POLICY = "resolve"


def _pymunk():
    """The ``pymunk`` module, or None when it is not installed."""
    try:
        import pymunk
    except ImportError:
        return None
    return pymunk


@dataclasses.dataclass
class PymunkRun:
    """A pymunk space holding the discs, and what its collision handler saw.

    Attributes:
        space: the ``pymunk.Space``.
        bodies: the discs' bodies, in disc order.
        index: shape -> disc index (walls absent).
        contacts: ``(i, j, t)`` for each disc pair that began touching (``i < j``),
            ``t`` the time at the end of that step.
        wall_contacts: disc-wall contacts begun.
        deepest: deepest disc-disc overlap seen before a solve, as a fraction of the contact distance.
        time: simulated time.
    """

    space: object
    bodies: list
    index: dict
    contacts: list = dataclasses.field(default_factory=list)
    wall_contacts: int = 0
    deepest: float = 0.0
    time: float = 0.0

    def step(self, dt: float, frames: int) -> None:
        """Advance ``frames`` steps of ``dt``."""
        space = self.space
        for _ in range(frames):
            self.time += dt  # before the step: the callbacks read it as the frame's time
            space.step(dt)

    def kinetic_energy(self) -> float:
        """Translational kinetic energy of the discs (friction 0: no rotation is excited)."""
        return sum(0.5 * b.mass * (b.velocity.x**2 + b.velocity.y**2) for b in self.bodies)


def build_pymunk(pymunk, discs: ds.Discs, box: ds.Box, *, watch: bool = False) -> PymunkRun:
    """The discs as pymunk circles (elasticity 1, friction 0) in four static wall segments, no gravity.

    Args:
        pymunk: the module.
        discs, box: a walled discsim configuration.
        watch: install collision callbacks that record contacts and overlaps
            (they cost Python calls, so timings run without them).
    """
    space = pymunk.Space()
    space.gravity = (0.0, 0.0)
    bodies, index = [], {}
    rows = zip(
        discs.positions.tolist(), discs.velocities.tolist(), discs.radii.tolist(), discs.masses.tolist(), strict=True
    )
    for k, (position, velocity, radius, mass) in enumerate(rows):
        body = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0.0, radius))
        body.position, body.velocity = position, velocity
        shape = pymunk.Circle(body, radius)
        shape.elasticity, shape.friction = 1.0, 0.0
        space.add(body, shape)
        bodies.append(body)
        index[shape] = k
    corners = [(0.0, 0.0), (box.width, 0.0), (box.width, box.height), (0.0, box.height)]
    for k in range(4):
        wall = pymunk.Segment(space.static_body, corners[k], corners[(k + 1) % 4], 0.0)
        wall.elasticity, wall.friction = 1.0, 0.0
        space.add(wall)
    run = PymunkRun(space, bodies, index)
    if watch:
        space.on_collision(begin=_begin, pre_solve=_pre_solve, data=run)
    return run


def _begin(arbiter, space, run: PymunkRun) -> None:
    first, second = (run.index.get(shape) for shape in arbiter.shapes)
    if first is None or second is None:
        run.wall_contacts += 1
    else:
        run.contacts.append((min(first, second), max(first, second), run.time))


def _pre_solve(arbiter, space, run: PymunkRun) -> None:
    a, b = arbiter.shapes
    if a in run.index and b in run.index:
        depth = max((-p.distance for p in arbiter.contact_point_set.points), default=0.0)
        run.deepest = max(run.deepest, depth / (a.radius + b.radius))


def match_contacts(truth: list, contacts: list, window: float) -> tuple[int, int, int]:
    """Match contacts to true collisions by pair, nearest times first, within ``window``.

    Args:
        truth, contacts: ``(i, j, t)`` with ``i < j``.

    Returns:
        ``(matched, missed, spurious)`` counts.
    """
    by_pair: dict = {}
    for k, (i, j, t) in enumerate(truth):
        by_pair.setdefault((i, j), ([], []))[0].append((t, k))
    for k, (i, j, t) in enumerate(contacts):
        by_pair.setdefault((i, j), ([], []))[1].append((t, k))
    matched = 0
    for true_times, found_times in by_pair.values():
        candidates = sorted((abs(a - b), k, m) for a, k in true_times for b, m in found_times if abs(a - b) <= window)
        used_true, used_found = set(), set()
        for _, k, m in candidates:
            if k not in used_true and m not in used_found:
                used_true.add(k)
                used_found.add(m)
        matched += len(used_true)
    return matched, len(truth) - matched, len(contacts) - matched


def _walled_gas(n: int, config: Config, seed: int = 0) -> tuple[ds.Discs, ds.Box]:
    """The walled random gas of :func:`compare_engines`, run under PIC for one collision per disc (melted)."""
    discs, box = ds.random_gas(n, config.packing_fraction, periodic=False, seed=seed)
    sim = ds.EventDriven(discs, box, record=False)
    sim.run(events=n)
    return ds.Discs(sim.positions, sim.velocities, discs.radii, discs.masses), box


def frame_step(discs: ds.Discs, config: Config) -> tuple[float, str]:
    """``dt`` of both engines: the step at which FixedStep misses at most 1% (from the throughput script)."""
    from benchutils import DEFAULT_RESULTS
    from throughput import one_percent_step

    step, source = one_percent_step(config.packing_fraction, DEFAULT_RESULTS)
    speed = math.sqrt(float((discs.velocities**2).sum(axis=1).mean()))
    return step * float(discs.radii.mean()) / speed, f"v dt / r = {step:.3g}, {source}"


def time_frames(pymunk, discs: ds.Discs, box: ds.Box, dt: float, config: Config) -> dict:
    """Seconds per frame of FixedStep (cell grid) and pymunk: median of ``repeats`` timings, interleaved."""
    fixed, other = [], []
    for _ in range(config.repeats):
        gc.collect()
        sim = ds.FixedStep(discs, box, dt=dt, policy=PIT_POLICY, record=False)
        sim.run(frames=1)
        start = time.perf_counter()
        sim.run(frames=config.pit_frames)
        fixed.append((time.perf_counter() - start) / config.pit_frames)
        if pymunk is not None:
            gc.collect()
            run = build_pymunk(pymunk, discs, box)
            run.step(dt, 1)
            start = time.perf_counter()
            run.step(dt, config.pit_frames)
            other.append((time.perf_counter() - start) / config.pit_frames)
    return {"fixed_step": median(fixed), "pymunk": median(other)}


def judge(pymunk, discs: ds.Discs, box: ds.Box, dt: float, horizon: float) -> dict:
    """FixedStep and pymunk against PIC over ``[0, horizon]``: missed, spurious, energy drift, deepest overlap."""
    truth = ds.EventDriven(discs, box).run(until=horizon + 4 * dt)
    frames = math.ceil(horizon / dt) + 1
    fixed = ds.FixedStep(discs, box, dt=dt, policy=PIT_POLICY).run(frames=frames)
    report = ds.compare(truth, fixed, until=horizon)
    out = {
        "fixed_step": {
            "truth": report.truth_collisions,
            "found": report.approx_collisions,
            "matched": report.matched,
            "missed": report.missed,
            "spurious": report.spurious,
            "energy_drift": report.approx_energy_change,
            "overlap": report.max_overlap,
        }
    }
    if pymunk is None:
        return out
    events = truth.events
    rows = (events["j"] >= 0) & (events["time"] <= horizon)
    true_pairs = [
        (min(i, j), max(i, j), t)
        for i, j, t in zip(events["i"][rows].tolist(), events["j"][rows].tolist(), events["time"][rows].tolist())
    ]
    run = build_pymunk(pymunk, discs, box, watch=True)
    energy = run.kinetic_energy()
    run.step(dt, frames)
    found = [c for c in run.contacts if c[2] <= horizon + dt]
    matched, missed, spurious = match_contacts(true_pairs, found, report.window)
    out["pymunk"] = {
        "truth": len(true_pairs),
        "found": len(found),
        "matched": matched,
        "missed": missed,
        "spurious": spurious,
        "energy_drift": (run.kinetic_energy() - energy) / energy,
        "overlap": run.deepest,
    }
    return out


PIT_COLUMNS = [
    Column("n", "N", ","),
    Column("engine", "engine"),
    Column("dt", "dt", ".3g"),
    Column("seconds_per_frame", "s/frame", ".3g"),
    Column("pymunk_ratio", "/ pymunk", ".2f"),
    Column("horizon", "T", ".3g"),
    Column("truth", "PIC coll", ","),
    Column("found", "found", ","),
    Column("matched", "matched", ","),
    Column("missed", "missed", ","),
    Column("missed_pct", "missed %", ".2f"),
    Column("spurious", "spurious", ","),
    Column("energy_drift", "dE/E", ".2e"),
    Column("overlap", "overlap", ".3g"),
]


def pit_peers_section(config: Config, results: Path) -> list[dict]:
    """discsim FixedStep against pymunk at the same dt: seconds per frame, and accuracy against PIC."""
    pymunk = _pymunk()
    if pymunk is None:
        print("note: pymunk is not installed (pip install -e .[bench]); FixedStep alone")
    else:
        print(f"pymunk {pymunk.version}: default space (iterations 10, collision_slop 0.1, BB tree)")
    rows = []
    for n in sorted(set(config.pit_sizes) | set(config.pit_accuracy_sizes)):
        discs, box = _walled_gas(n, config)
        dt, source = frame_step(discs, config)
        print(f"N={n:,}: walled gas phi={config.packing_fraction}, melted by PIC; dt={dt:.3g} ({source})")
        engines = ["fixed_step"] + (["pymunk"] if pymunk is not None else [])
        point = {e: {"n": n, "engine": e, "dt": dt} for e in engines}
        if n in config.pit_sizes:
            announce(f"  PIT N={n:,}: timing {config.repeats} x {config.pit_frames} frames")
            seconds = time_frames(pymunk, discs, box, dt, config)
            for e in engines:
                point[e]["seconds_per_frame"] = seconds[e]
                point[e]["pymunk_ratio"] = seconds[e] / seconds["pymunk"] if pymunk is not None else math.nan
        if n in config.pit_accuracy_sizes:
            horizon = config.pit_horizon_free_times / float(ds.enskog_collision_rate(config.packing_fraction))
            announce(f"  PIT N={n:,}: accuracy against PIC over T={horizon:.3g}")
            for e, found in judge(pymunk, discs, box, dt, horizon).items():
                point[e].update(found, horizon=horizon)
                point[e]["missed_pct"] = 100.0 * found["missed"] / found["truth"] if found["truth"] else math.nan
        rows += point.values()
    print(format_table(rows, PIT_COLUMNS))
    write_csv(results / "peers_pit.csv", rows, [c.key for c in PIT_COLUMNS])
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


#: The sections in run order: (title, function(config, results) -> rows).
SECTIONS = [
    ("PIC against peers (walled box)", pic_peers_section),
    ("PIT against pymunk (walled box, same dt)", pit_peers_section),
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
