"""Measure one run against another: collisions matched, missed and late, paths apart.

:func:`compare` takes a reference run (the truth, normally the event-driven
engine) and a run to judge (normally the fixed-step engine) from the same
start, and reports what the second got wrong. It reads only the engine
protocol (``discs``, ``box``, ``start_time``, ``time``, ``events``,
``trajectory``, ``velocities``), plus optional attributes when an engine
has them: ``dt`` (frame interval, for the frame times and the matching
window), ``max_overlap`` (deepest overlap it saw), and the laws of motion
(``laws.gravity``, ``energy()``, ``dissipated``: the rebound heights and the
energy error).
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np

from discsim.cells import neighbour_pairs
from discsim.errors import InvalidArgumentError, WrongTypeError
from discsim.events import COLLISION, WALL
from discsim.model import frame_count, kinetic_energy, rotational_energy
from discsim.trajectory import check_times

__all__ = ["Comparison", "compare"]

#: Position samples used when neither engine has a frame interval.
_DEFAULT_SAMPLES = 201
#: Speeds below this fraction of the largest speed in a collision count as rest (no direction).
_REST = 1e-9


@dataclass
class Comparison:
    """What a run got wrong against a reference run (see :func:`compare`).

    Times are in the engines' time units, lengths in their length units.

    Attributes:
        truth_name, approx_name: the engines' class names.
        start, horizon: the common span compared.
        window: matching window (time units) for collisions of the same pair.
        truth_collisions, approx_collisions: disc-disc collisions in each log.
        truth_wall_hits, approx_wall_hits: wall hits in each log.
        matched, missed, spurious: collisions found in both, only in the
            truth, only in the approximation.
        matches: ``(i, j, t_truth, t_approx)`` per matched collision (``i < j``).
        missed_collisions, spurious_collisions: ``(i, j, t)`` each.
        delays: ``(M,)`` ``t_approx - t_truth`` of the matched collisions.
        direction_errors: ``(M, 2)`` angle in degrees between the outgoing
            velocities of disc ``i`` (column 0) and ``j`` (column 1) in the two
            runs; NaN where a disc leaves at rest in either run (no direction).
        times: ``(T,)`` sample times of the position error (the frame times).
        position_errors: ``(T,)`` largest distance between a disc's positions
            in the two runs at each sample time (minimum image if periodic).
        position_error_max, position_error_rms: over all discs and sample times.
        max_overlap: deepest disc-disc overlap of the approximation, as a
            fraction of the contact distance. truth_max_overlap: the same for
            the truth (0 for an exact engine).
        truth_energy_change, approx_energy_change: relative change of the
            kinetic energy from the start to the end of each run.
        wall_matches: ``(i, t_truth, t_approx)`` per wall or segment hit of disc
            ``i`` found in both runs (matched per disc, nearest times first,
            within ``window``, as collisions are); missed_wall_hits,
            spurious_wall_hits: ``(i, -1, t)`` each.
        wall_delays: ``(W,)`` ``t_approx - t_truth`` of the matched wall hits.
        rebound_errors: ``(W,)`` under gravity, how much higher (length) the
            disc rises after the matched hit in the approximation than in the
            truth: each run's height at the hit plus ``v_up^2 / (2 g)`` from the
            velocity it logged there (a bouncing ball's next apex); NaN without
            gravity.
        truth_energy_error, approx_energy_error: relative change from the start
            to the end of each run of its energy (kinetic plus potential, for an
            engine with ``energy()``) plus what its collision law dissipated
            (``dissipated``): what the run lost or gained beyond its laws (0 for an
            exact run; for elastic discs without gravity, the kinetic energy change).
    """

    truth_name: str
    approx_name: str
    start: float
    horizon: float
    window: float
    truth_collisions: int
    approx_collisions: int
    truth_wall_hits: int
    approx_wall_hits: int
    matches: list = field(default_factory=list)
    missed_collisions: list = field(default_factory=list)
    spurious_collisions: list = field(default_factory=list)
    delays: np.ndarray = field(default_factory=lambda: np.zeros(0))
    direction_errors: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    position_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    position_error_max: float = 0.0
    position_error_rms: float = 0.0
    max_overlap: float = 0.0
    truth_max_overlap: float = 0.0
    truth_energy_change: float = 0.0
    approx_energy_change: float = 0.0
    wall_matches: list = field(default_factory=list)
    missed_wall_hits: list = field(default_factory=list)
    spurious_wall_hits: list = field(default_factory=list)
    wall_delays: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rebound_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    truth_energy_error: float = 0.0
    approx_energy_error: float = 0.0

    @property
    def matched(self) -> int:
        """Collisions found in both runs."""
        return len(self.matches)

    @property
    def missed(self) -> int:
        """Collisions of the truth that the approximation lacks."""
        return len(self.missed_collisions)

    @property
    def spurious(self) -> int:
        """Collisions of the approximation that the truth lacks."""
        return len(self.spurious_collisions)

    @property
    def missed_fraction(self) -> float:
        """``missed / truth_collisions`` (0 when the truth has none)."""
        return self.missed / self.truth_collisions if self.truth_collisions else 0.0

    @property
    def max_delay(self) -> float:
        """Largest ``|t_approx - t_truth|`` of a matched collision, signed (0 if none)."""
        if not len(self.delays):
            return 0.0
        return float(self.delays[np.argmax(np.abs(self.delays))])

    @property
    def mean_delay(self) -> float:
        """Mean ``t_approx - t_truth`` over matched collisions (0 if none)."""
        return float(self.delays.mean()) if len(self.delays) else 0.0

    @property
    def max_direction_error(self) -> float:
        """Largest outgoing direction error in degrees (0 if none is defined)."""
        finite = self.direction_errors[np.isfinite(self.direction_errors)]
        return float(finite.max()) if finite.size else 0.0

    @property
    def mean_direction_error(self) -> float:
        """Mean outgoing direction error in degrees over discs where it is defined (0 if none)."""
        finite = self.direction_errors[np.isfinite(self.direction_errors)]
        return float(finite.mean()) if finite.size else 0.0

    @property
    def max_wall_delay(self) -> float:
        """Largest ``|t_approx - t_truth|`` of a matched wall hit, signed (0 if none)."""
        if not len(self.wall_delays):
            return 0.0
        return float(self.wall_delays[np.argmax(np.abs(self.wall_delays))])

    @property
    def max_rebound_error(self) -> float:
        """Largest ``|rebound_errors|`` (length), signed; NaN without gravity, 0 without matched wall hits."""
        if not len(self.rebound_errors):
            return 0.0
        if np.isnan(self.rebound_errors).all():
            return math.nan
        return float(self.rebound_errors[np.nanargmax(np.abs(self.rebound_errors))])

    @property
    def position_error_final(self) -> float:
        """Largest position error at the last sample time (the horizon)."""
        return float(self.position_errors[-1]) if len(self.position_errors) else 0.0

    def summary(self) -> dict:
        """The scalar figures only, as a flat ``dict`` of Python numbers."""
        return {
            "truth": self.truth_name,
            "approx": self.approx_name,
            "start": self.start,
            "horizon": self.horizon,
            "window": self.window,
            "truth_collisions": self.truth_collisions,
            "approx_collisions": self.approx_collisions,
            "truth_wall_hits": self.truth_wall_hits,
            "approx_wall_hits": self.approx_wall_hits,
            "matched": self.matched,
            "missed": self.missed,
            "spurious": self.spurious,
            "missed_fraction": self.missed_fraction,
            "max_delay": self.max_delay,
            "mean_delay": self.mean_delay,
            "max_direction_error_deg": self.max_direction_error,
            "mean_direction_error_deg": self.mean_direction_error,
            "position_error_max": self.position_error_max,
            "position_error_rms": self.position_error_rms,
            "position_error_final": self.position_error_final,
            "max_overlap": self.max_overlap,
            "truth_max_overlap": self.truth_max_overlap,
            "truth_energy_change": self.truth_energy_change,
            "approx_energy_change": self.approx_energy_change,
            "wall_matched": len(self.wall_matches),
            "wall_missed": len(self.missed_wall_hits),
            "wall_spurious": len(self.spurious_wall_hits),
            "max_wall_delay": self.max_wall_delay,
            "max_rebound_error": self.max_rebound_error,
            "truth_energy_error": self.truth_energy_error,
            "approx_energy_error": self.approx_energy_error,
        }

    def to_dict(self) -> dict:
        """Everything as plain Python types (JSON-ready; NaN becomes None).

        The scalars of :meth:`summary` plus the lists ``matches``,
        ``missed_collisions``, ``spurious_collisions``, ``delays``,
        ``direction_errors``, ``times`` and ``position_errors``.
        """

        def clean(value):
            if isinstance(value, float) and math.isnan(value):
                return None
            if isinstance(value, (list, tuple)):
                return [clean(v) for v in value]
            return value

        out = self.summary()
        out["matches"] = [list(m) for m in self.matches]
        out["missed_collisions"] = [list(m) for m in self.missed_collisions]
        out["spurious_collisions"] = [list(m) for m in self.spurious_collisions]
        out["wall_matches"] = [list(m) for m in self.wall_matches]
        out["missed_wall_hits"] = [list(m) for m in self.missed_wall_hits]
        out["spurious_wall_hits"] = [list(m) for m in self.spurious_wall_hits]
        out["wall_delays"] = self.wall_delays.tolist()
        out["rebound_errors"] = clean(self.rebound_errors.tolist())
        out["delays"] = self.delays.tolist()
        out["direction_errors"] = clean(self.direction_errors.tolist())
        out["times"] = self.times.tolist()
        out["position_errors"] = self.position_errors.tolist()
        return out

    def __str__(self) -> str:
        def pairs(items):
            shown = ", ".join(f"{i}-{j} at t={t:.4g}" for i, j, t in items[:3])
            return shown + (f", ... ({len(items)} in all)" if len(items) > 3 else "")

        lines = [
            f"{self.approx_name} against {self.truth_name} (truth), t in [{self.start:g}, {self.horizon:g}]",
            f"  collisions       truth {self.truth_collisions}, approx {self.approx_collisions}"
            f"   (wall hits: truth {self.truth_wall_hits}, approx {self.approx_wall_hits})",
            f"  matched {self.matched}, missed {self.missed}, spurious {self.spurious}"
            f"   (same pair within {self.window:.3g} time units)",
        ]
        if self.missed:
            lines.append(f"  missed           {pairs(self.missed_collisions)}")
        if self.spurious:
            lines.append(f"  spurious         {pairs(self.spurious_collisions)}")
        if self.matched:
            lines.append(f"  delay            max {self.max_delay:.4g}, mean {self.mean_delay:.4g}")
            lines.append(
                f"  direction error  max {self.max_direction_error:.3g} deg, mean {self.mean_direction_error:.3g} deg"
            )
        lines.append(
            f"  position error   max {self.position_error_max:.4g}, rms {self.position_error_rms:.4g},"
            f" at the end {self.position_error_final:.4g}   ({len(self.times)} sample times)"
        )
        lines.append(f"  deepest overlap  {self.max_overlap:.3g} of the contact distance")
        lines.append(
            f"  kinetic energy   relative change: truth {self.truth_energy_change:+.2e},"
            f" approx {self.approx_energy_change:+.2e}"
        )
        if self.wall_matches or self.missed_wall_hits or self.spurious_wall_hits:
            line = (
                f"  wall hits        matched {len(self.wall_matches)}, missed {len(self.missed_wall_hits)},"
                f" spurious {len(self.spurious_wall_hits)}; delay max {self.max_wall_delay:.4g}"
            )
            if not math.isnan(self.max_rebound_error):
                line += f"; rebound height error max {self.max_rebound_error:.4g}"
            lines.append(line)
        if self.truth_energy_error != self.truth_energy_change or self.approx_energy_error != self.approx_energy_change:
            lines.append(
                f"  energy error     (kinetic + potential + dissipated) relative change: truth"
                f" {self.truth_energy_error:+.2e}, approx {self.approx_energy_error:+.2e}"
            )
        return "\n".join(lines)


def _collisions(events: np.ndarray):
    """Disc-disc records as ``(pair -> [(time, row)])`` with ``pair = (min, max)``."""
    by_pair = defaultdict(list)
    rows = np.flatnonzero(events["kind"] == COLLISION)
    times, first, second = events["time"][rows].tolist(), events["i"][rows].tolist(), events["j"][rows].tolist()
    for r, t, i, j in zip(rows.tolist(), times, first, second, strict=True):
        by_pair[(min(i, j), max(i, j))].append((t, r))
    return by_pair


def _match(truth_by_pair, approx_by_pair, window: float):
    """Greedy nearest-time matching within each pair; returns matches, missed, spurious."""
    matches: list[tuple[tuple[int, int], tuple[float, int], tuple[float, int]]] = []  # pair, (time, row) twice
    missed: list[tuple[int, int, float]] = []  # i, j, time
    spurious: list[tuple[int, int, float]] = []
    for pair in sorted(set(truth_by_pair) | set(approx_by_pair)):
        tt = truth_by_pair.get(pair, [])
        ta = approx_by_pair.get(pair, [])
        candidates = sorted(
            (abs(a[0] - t[0]), k, m) for k, t in enumerate(tt) for m, a in enumerate(ta) if abs(a[0] - t[0]) <= window
        )
        used_t, used_a = set(), set()
        for _, k, m in candidates:
            if k in used_t or m in used_a:
                continue
            used_t.add(k)
            used_a.add(m)
            matches.append((pair, tt[k], ta[m]))
        missed.extend((*pair, tt[k][0]) for k in range(len(tt)) if k not in used_t)
        spurious.extend((*pair, ta[m][0]) for m in range(len(ta)) if m not in used_a)
    matches.sort(key=lambda item: item[1][0])
    missed.sort(key=lambda item: item[2])
    spurious.sort(key=lambda item: item[2])
    return matches, missed, spurious


def _outgoing(record, disc: int) -> tuple[float, float]:
    if int(record["i"]) == disc:
        return float(record["vxi"]), float(record["vyi"])
    return float(record["vxj"]), float(record["vyj"])


def _angle(u, v, scale: float) -> float:
    """Angle in degrees between 2-vectors ``u`` and ``v``; NaN if either is at rest (below ``scale``)."""
    if math.hypot(*u) <= scale or math.hypot(*v) <= scale:
        return math.nan
    cross = u[0] * v[1] - u[1] * v[0]
    dot = u[0] * v[0] + u[1] * v[1]
    return math.degrees(math.atan2(abs(cross), dot))


def _max_overlap(positions: np.ndarray, radii: np.ndarray, box) -> float:
    """Deepest overlap fraction (>= 0) over ``positions`` ``(T, N, 2)``."""
    n = positions.shape[1]
    if n < 2 or not len(positions):
        return 0.0
    deepest = 0.0
    if n > 200:  # a cell grid per sample time
        cell = 2.0 * float(radii.max())
        for frame in positions:
            i, j, d = neighbour_pairs(frame, cell, box)
            if len(i):
                depth = 1.0 - np.hypot(d[:, 0], d[:, 1]) / (radii[i] + radii[j])
                deepest = max(deepest, float(depth.max()))
        return deepest
    ii, jj = np.triu_indices(n, 1)
    contact = radii[ii] + radii[jj]
    block = max(1, 2_000_000 // len(ii))
    for start in range(0, len(positions), block):
        d = box.minimum_image(positions[start : start + block, jj] - positions[start : start + block, ii])
        depth = 1.0 - np.hypot(d[..., 0], d[..., 1]) / contact
        deepest = max(deepest, float(depth.max()))
    return deepest


def _deepest_overlap(engine, positions: np.ndarray, radii: np.ndarray) -> float:
    """The engine's own ``max_overlap`` if it tracks one (seen before its responses), else measured."""
    tracked = getattr(engine, "max_overlap", None)
    if tracked is not None:
        return max(float(tracked), 0.0)
    return _max_overlap(positions, radii, engine.box)


def _gravity(engine) -> tuple[float, float]:
    laws = getattr(engine, "laws", None)
    return tuple(laws.gravity) if laws is not None else (0.0, 0.0)


def _energy_error(engine) -> float:
    """Relative change of ``energy() + dissipated`` from the start (kinetic plus potential there)."""
    discs = engine.discs
    gx, gy = _gravity(engine)
    finite = np.isfinite(discs.masses)
    e0 = kinetic_energy(discs.velocities, discs.masses) + rotational_energy(discs.spins, discs.inertia)
    e0 -= float(np.sum(discs.masses[finite] * (discs.positions[finite] @ np.array([gx, gy]))))
    energy = getattr(engine, "energy", engine.kinetic_energy)
    e1 = float(energy()) + float(getattr(engine, "dissipated", 0.0))
    return (e1 - e0) / abs(e0) if e0 != 0 else 0.0


def _wall_hits(events: np.ndarray):
    """Wall and segment records as ``((disc, -1) -> [(time, row)])``."""
    by_disc = defaultdict(list)
    rows = np.flatnonzero(events["kind"] == WALL)
    for r, t, i in zip(rows.tolist(), events["time"][rows].tolist(), events["i"][rows].tolist(), strict=True):
        by_disc[(i, -1)].append((t, r))
    return by_disc


def _rebound(record, gravity: tuple[float, float]) -> float:
    """How high (along ``-g``) a disc rises after a logged wall hit: its height there plus ``v_up^2 / (2 g)``."""
    g = math.hypot(*gravity)
    ux, uy = -gravity[0] / g, -gravity[1] / g
    up = float(record["vxi"]) * ux + float(record["vyi"]) * uy
    return float(record["xi"]) * ux + float(record["yi"]) * uy + max(up, 0.0) ** 2 / (2.0 * g)


def _energy_change(engine) -> float:
    """Relative change of ``kinetic_energy()`` from the start (the rotational energy of spinning discs included)."""
    discs = engine.discs
    e0 = kinetic_energy(discs.velocities, discs.masses) + rotational_energy(discs.spins, discs.inertia)
    e1 = engine.kinetic_energy()
    return (e1 - e0) / e0 if e0 > 0 else 0.0


def _default_window(discs, dt: float) -> float:
    """``max(2 dt, sigma_min / v)``: see :func:`compare`."""
    finite = np.isfinite(discs.masses)
    energy = kinetic_energy(discs.velocities, discs.masses)
    if len(discs) < 2 or energy <= 0 or not finite.any():
        return 2.0 * dt
    v_typical = math.sqrt(2.0 * energy / float(discs.masses[finite].sum()))
    sigma_min = 2.0 * float(np.sort(discs.radii)[:2].mean())
    return max(2.0 * dt, sigma_min / v_typical)


def compare(truth, approx, *, window: float | None = None, times=None, until: float | None = None) -> Comparison:
    """Compare a run against a reference run from the same start.

    Collisions (disc-disc records of the event logs) are matched by unordered
    pair, nearest times first, within ``window``. The default window is
    ``max(2 dt, sigma_min / v)``: ``dt`` the larger frame interval of the two
    engines (0 for an exact one), ``sigma_min`` the smallest contact distance
    and ``v = sqrt(2 E / M)`` the root-mean-square speed from the kinetic
    energy ``E`` and total mass ``M`` of the moving discs at the start. Why:
    a fixed-step engine responds at the first frame after a contact, so it
    sees a collision up to a frame late, and earlier errors drift it further
    (a position error ``delta`` shifts a contact by about ``delta / v_rel``,
    large for slow, grazing approaches); while a pair that has just collided
    moves apart and needs a third disc or a wall to turn it back, which at
    typical speeds takes longer than the time to cover one contact distance,
    except in packed chains (Newton's cradle, a billiard rack). The closest
    times are matched first, so a wide window does not blur exact runs: two
    exact runs match with delays at the roundoff level. Pass ``window`` to
    choose another trade-off.

    Args:
        truth: the reference run (e.g. :class:`~discsim.engines.event_driven.EventDriven`).
        approx: the run to judge (e.g. :class:`~discsim.engines.fixed_step.FixedStep`).
            Both need ``record=True``, the same discs at the same start time
            and the same box.
        window: matching window in time units (>= 0), overriding the default.
        until: count the collisions of the truth up to this time only, while
            the approximation's detections up to ``until + window`` may still
            match them (a fixed-step run sees a contact just before ``until``
            only at its next frame: run it a few frames past ``until``).
            Default: the end of the shorter run.
        times: sample times ``(T,)`` for the position error; default the
            frame times of the engine with the larger ``dt`` over the common
            span, or 201 evenly spaced times when neither has one.

    Returns:
        A :class:`Comparison`.

    Raises:
        ValueError: if the runs do not start from the same state (naming the
            first differing disc and its two positions, velocities, spins ...), have different boxes
            or numbers of discs, or ``window`` is negative.

    Example:
        >>> import discsim as ds
        >>> case = ds.scenarios.wrong_direction()
        >>> pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
        >>> pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
        >>> report = compare(pic, pit)
        >>> report.matched, report.missed, round(report.max_delay, 4), round(report.max_direction_error, 2)
        (1, 0, 0.1667, 26.57)
    """
    for name, engine in (("truth", truth), ("approx", approx)):
        if not all(hasattr(engine, a) for a in ("discs", "box", "events", "trajectory", "time", "start_time")):
            shown = repr(engine) if len(repr(engine)) <= 60 else repr(engine)[:57] + "..."
            msg = f"compare() needs two runs (EventDriven, FixedStep or alike): {name} is {type(engine).__name__} "
            msg += shown
            raise WrongTypeError(msg)
        if not getattr(engine, "record", True):
            msg = f"compare() needs the event log of {name}; build the engine with record=True"
            raise InvalidArgumentError(msg)
    for run in (truth, approx):
        context = getattr(run, "run_context", None)
        if context is not None and context.origin is not None:
            msg = (
                f"compare() follows the same discs in both runs, and this {type(run).__name__} added or removed "
                "discs (add_discs / remove_discs); compare runs started from the same discs instead"
            )
            raise InvalidArgumentError(msg)
    n = len(truth.discs)
    if len(approx.discs) != n:
        msg = f"the runs have different numbers of discs: truth {n}, approx {len(approx.discs)}"
        raise InvalidArgumentError(msg)
    if truth.box != approx.box:
        msg = f"the runs have different boxes: truth {truth.box}, approx {approx.box}"
        raise InvalidArgumentError(msg)
    for what in ("positions", "velocities", "radii", "masses", "spins", "inertia"):
        a, b = getattr(truth.discs, what), getattr(approx.discs, what)
        differs = ~((a == b) | np.isclose(a, b, rtol=1e-12, atol=0.0))
        if differs.any():
            i = int(np.flatnonzero(differs.reshape(n, -1).any(axis=1))[0])
            msg = (
                f"the runs do not start from the same discs: disc {i} has {what} "
                f"{np.asarray(a[i]).tolist()} in truth but {np.asarray(b[i]).tolist()} in approx"
            )
            raise InvalidArgumentError(msg)
    start = max(float(truth.start_time), float(approx.start_time))
    common = min(float(truth.time), float(approx.time))
    horizon = common if until is None else float(until)
    if not (start <= horizon <= common):
        msg = f"until={until!r} must lie within the span both runs cover, [{start!r}, {common!r}]"
        raise InvalidArgumentError(msg)
    dts = [float(getattr(e, "dt", 0.0) or 0.0) for e in (truth, approx)]
    if window is None:
        window = _default_window(truth.discs, max(dts))
    elif isinstance(window, (bool, str, bytes)) or not isinstance(window, (int, float, np.integer, np.floating)):
        msg = f"window must be a non-negative number of time units, got {window!r}"
        raise InvalidArgumentError(msg)
    elif not (window >= 0):
        msg = f"window must be a non-negative number of time units, got {window!r}"
        raise InvalidArgumentError(msg)
    window = float(window)

    # Collisions within the common span (the approximation's up to a window past an explicit until).
    ev_t, ev_a = truth.events, approx.events
    reach = horizon if until is None else min(common, horizon + window)
    ev_t = ev_t[(ev_t["time"] >= start) & (ev_t["time"] <= horizon)]
    ev_a = ev_a[(ev_a["time"] >= start) & (ev_a["time"] <= reach)]
    matched, missed, spurious = _match(_collisions(ev_t), _collisions(ev_a), window)
    spurious = [(i, j, t) for i, j, t in spurious if t <= horizon]
    wall_matched, wall_missed, wall_spurious = _match(_wall_hits(ev_t), _wall_hits(ev_a), window)
    wall_spurious = [(i, j, t) for i, j, t in wall_spurious if t <= horizon]
    gravity = _gravity(truth)
    rebounds = np.full(len(wall_matched), np.nan)
    if gravity != (0.0, 0.0):
        for k, (_, (_, rt), (_, ra)) in enumerate(wall_matched):
            rebounds[k] = _rebound(ev_a[ra], gravity) - _rebound(ev_t[rt], gravity)
    delays = np.array([ta - tt for _, (tt, _), (ta, _) in matched])
    directions = np.full((len(matched), 2), np.nan)
    for k, ((i, j), (_, rt), (_, ra)) in enumerate(matched):
        rec_t, rec_a = ev_t[rt], ev_a[ra]
        outs = [(_outgoing(rec_t, d), _outgoing(rec_a, d)) for d in (i, j)]
        scale = _REST * max(math.hypot(*v) for pair in outs for v in pair)
        for col, (u, v) in enumerate(outs):
            directions[k, col] = _angle(u, v, scale)

    # Positions at the frame times.
    if times is None:
        frame = max(dts)
        if frame > 0:
            count = frame_count(start, horizon, frame)
            times = np.minimum(start + frame * np.arange(count + 1), horizon)  # k * dt may overshoot by roundoff
        else:
            times = np.linspace(start, horizon, _DEFAULT_SAMPLES)
    else:
        asked = check_times(times, start, horizon, "span both runs cover")  # was: dropped silently
        times = np.minimum(np.maximum(asked, start), horizon)  # within the roundoff check_times allows
    times = np.atleast_1d(np.asarray(times, dtype=float))
    pos_t = truth.trajectory(times)
    pos_a = approx.trajectory(times)
    d = truth.box.minimum_image(pos_a - pos_t)
    dist = np.hypot(d[..., 0], d[..., 1]) if n else np.zeros((len(times), 0))
    per_time = dist.max(axis=1) if n else np.zeros(len(times))
    radii = truth.discs.radii
    overlap_a = _deepest_overlap(approx, pos_a, radii)
    overlap_t = _deepest_overlap(truth, pos_t, radii)

    return Comparison(
        truth_name=type(truth).__name__,
        approx_name=type(approx).__name__,
        start=start,
        horizon=horizon,
        window=window,
        truth_collisions=int((ev_t["kind"] == COLLISION).sum()),
        approx_collisions=int(((ev_a["kind"] == COLLISION) & (ev_a["time"] <= horizon)).sum()),
        truth_wall_hits=int((ev_t["kind"] == WALL).sum()),
        approx_wall_hits=int(((ev_a["kind"] == WALL) & (ev_a["time"] <= horizon)).sum()),
        matches=[(i, j, tt, ta) for (i, j), (tt, _), (ta, _) in matched],
        missed_collisions=missed,
        spurious_collisions=spurious,
        delays=delays,
        direction_errors=directions,
        times=times,
        position_errors=per_time,
        position_error_max=float(dist.max()) if dist.size else 0.0,
        position_error_rms=float(np.sqrt(np.mean(dist**2))) if dist.size else 0.0,
        max_overlap=overlap_a,
        truth_max_overlap=overlap_t,
        truth_energy_change=_energy_change(truth),
        approx_energy_change=_energy_change(approx),
        wall_matches=[(i, tt, ta) for (i, _), (tt, _), (ta, _) in wall_matched],
        missed_wall_hits=wall_missed,
        spurious_wall_hits=wall_spurious,
        wall_delays=np.array([ta - tt for _, (tt, _), (ta, _) in wall_matched]),
        rebound_errors=rebounds,
        truth_energy_error=_energy_error(truth),
        approx_energy_error=_energy_error(approx),
    )
