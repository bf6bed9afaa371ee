"""Exact positions from an event log: between events discs fly in straight lines.

:func:`reconstruct` gives every disc's position at any time the log covers, with no re-simulation: wrapped
into a periodic box (by :meth:`~discsim.model.Box.wrap`, the one wrap rule), or unwrapped, following each disc
across the periodic edges as it really moved (what a mean-squared displacement needs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from discsim.errors import InvalidArgumentError, TimeError
from discsim.events import SENSED, EventKind, added_discs
from discsim.model import image_steps
from discsim.physics.dynamics import advance, advance_many

__all__ = [
    "LastRecords",
    "check_times",
    "falling",
    "flight",
    "log_start",
    "positions_from_log",
    "reconstruct",
    "replay",
    "turning_at",
    "turning_history",
]

#: The event kinds after which a disc with velocity exactly zero has come to rest (under gravity).
_PHYSICAL = (int(EventKind.COLLISION), int(EventKind.WALL))


def _second_disc(events: np.ndarray) -> np.ndarray:
    """``(E,)`` bool: the records whose ``j`` is a disc (a sensor's record names the sensor there)."""
    return (events["j"] >= 0) & ~np.isin(events["kind"], SENSED)


def check_times(times, start: float, end: float, span: str) -> np.ndarray:
    """``times`` as a float array ``(T,)``, checked to be finite and within ``[start, end]``.

    The span is widened by ``1e-12 * max(1, |end|)`` for roundoff.

    Raises:
        TimeError: naming the first bad time and the ``span`` ("simulated span", "logged span").
    """
    try:
        raw = np.asarray(times, dtype=object if isinstance(times, (str, bytes)) else None)
    except (TypeError, ValueError):  # ragged
        raw = np.asarray([None], dtype=object)
    if raw.dtype.kind not in "iuf" or raw.ndim > 1:
        shown = repr(times) if len(repr(times)) <= 60 else repr(times)[:57] + "..."
        msg = f"trajectory times must be a number or a 1-D array of numbers, got {shown}"
        raise TimeError(msg)
    times = np.atleast_1d(raw.astype(float))
    if times.size and not np.isfinite(times).all():
        msg = f"trajectory times must be finite, got {times[~np.isfinite(times)][0]!r}"
        raise TimeError(msg)
    tol = 1e-12 * max(1.0, abs(end))
    if times.size and (times.min() < start - tol or times.max() > end + tol):
        bad = float(times.min() if times.min() < start - tol else times.max())
        msg = f"trajectory time {bad!r} is outside the {span} [{start!r}, {end!r}]"
        raise TimeError(msg)
    return times


def reconstruct(
    events: np.ndarray,
    positions0: np.ndarray,
    velocities0: np.ndarray,
    time0,
    times,
    box=None,
    *,
    unwrapped: bool = False,
    images0=None,
    gravity=None,
    masses=None,
    still0=None,
    drag: float = 0.0,
) -> np.ndarray:
    """Exact positions of every disc at ``times`` from an initial state and a log.

    Args:
        events: structured array of :data:`EVENT_DTYPE`, in time order.
        positions0, velocities0: ``(N, 2)`` state at ``time0``.
        time0: start time of the log; or ``(N,)``, each disc's own reference time (the time of its last
            record before ``events``, as a :class:`LastRecords` holds them).
        times: ``(T,)`` times (any order) at or after ``time0``.
        box: if given and periodic, positions are wrapped into it
            (:meth:`~discsim.model.Box.wrap`), unless ``unwrapped``.
        unwrapped: follow each disc across the periodic edges: where a
            logged position differs from the straight flight since the disc's
            previous record by whole box lengths (the engine wrapped it in
            between), those lengths are added back, exactly.
        images0: ``(N, 2)`` whole box lengths each disc had crossed by ``time0`` (``unwrapped`` only;
            :attr:`LastRecords.images`), default none.
        gravity: the run's ``(gx, gy)`` (None: free flight). Between records a disc of finite mass (``masses``
            ``(N,)``, default all finite) falls, except after a record that left it at rest: a record of an
            event with velocity exactly zero (the initial state and an edit always fall). A disc that an event
            stops dead while it still falls (possible only in contrived, exactly symmetric collisions) is taken at
            rest.
        still0: ``(N,)`` bool, the discs at rest at ``time0`` (:attr:`LastRecords.still`; gravity only), default none.
        drag: the run's drag ``gamma`` (1 / time; 0: none): exponential flight between records
            (:func:`discsim.physics.dynamics.advance_many`).

    Returns:
        ``(T, N, 2)`` positions. An event exactly at a requested time counts as
        having happened (positions are continuous there anyway). A disc whose
        state is NaN (not yet added at ``time0``, or after its ``REMOVE`` record)
        is NaN there (see :func:`log_start`).
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    n = len(positions0)
    under_gravity = gravity is not None and tuple(gravity) != (0.0, 0.0)
    disc, t_rec, state, starts, *kind = _sorted_records(events, positions0, velocities0, time0, kinds=under_gravity)
    periodic = box is not None and box.periodic
    falls = falling(disc, state, kind[0], gravity, masses, still0) if under_gravity else None
    if unwrapped and periodic and (len(state) > n or images0 is not None):
        state[:, :2] += _image_counts(disc, t_rec, state, starts, box.size, images0, gravity, falls, drag) * box.size
    out = np.empty((len(times), n, 2))
    for d in range(n):
        lo, hi = starts[d], starts[d + 1]
        k = lo + np.searchsorted(t_rec[lo:hi], times, side="right") - 1
        k = np.maximum(k, lo)
        dt = (times - t_rec[k])[:, None]
        x, y = _flight(state[k], dt[:, 0], gravity, None if falls is None else falls[k], drag)
        out[:, d, 0], out[:, d, 1] = x, y
    if periodic and not unwrapped:
        out = box.wrap(out)
    return out


def falling(disc, state, kind, gravity, masses, still0=None) -> np.ndarray:
    """``(R,)`` bool: the records after which the disc falls (see :func:`reconstruct`): all but those of a
    collision or wall hit that left the disc with velocity exactly zero (at rest), the first records of the discs
    ``still0`` (at rest where the records start), and the discs of infinite mass (NaN: a disc added later, which
    falls)."""
    moving = ~_rests(state, kind)
    if still0 is not None:
        moving &= ~((kind == -1) & np.asarray(still0, dtype=bool)[disc])
    if masses is not None:
        moving &= ~np.isinf(np.asarray(masses, dtype=float))[disc]
    return moving


def _rests(state, kind) -> np.ndarray:
    """``(R,)`` bool: the records of a collision or wall hit that left the disc with velocity exactly zero."""
    return (state[:, 2] == 0.0) & (state[:, 3] == 0.0) & np.isin(kind, _PHYSICAL)


def _flight(state, dt, gravity, falls, drag: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Centres ``dt`` after records ``state`` ``(K, 4)``: free flight, or under ``gravity`` where ``falls``, under
    ``drag``."""
    if drag:
        x, y, _, _ = advance_many(state[:, 0], state[:, 1], state[:, 2], state[:, 3], dt, 0.0, 0.0, drag)
    else:
        x, y, _, _ = advance(state[:, 0], state[:, 1], state[:, 2], state[:, 3], dt)
    if falls is not None:
        gx, gy = float(gravity[0]), float(gravity[1])
        fx, fy, _, _ = (
            advance_many(state[:, 0], state[:, 1], state[:, 2], state[:, 3], dt, gx, gy, drag)
            if drag
            else advance(state[:, 0], state[:, 1], state[:, 2], state[:, 3], dt, gx, gy)
        )
        x, y = np.where(falls, fx, x), np.where(falls, fy, y)
    return x, y


def _sorted_records(events, positions0, velocities0, time0, kinds: bool = False) -> tuple:
    """Every state record of every disc, sorted by disc, then time, then log order.

    Returns ``(disc (R,), time (R,), state (R, 4), starts (N + 1,))``: disc ``d`` owns rows
    ``starts[d]:starts[d + 1]``, the first of which is its state at ``time0``. With ``kinds``, also each record's
    event kind ``(R,)`` (-1 for the state at ``time0``).
    """
    n = len(positions0)
    # One state record per disc per change: initial state, then each event's i and j.
    # Each record also keeps the index of its event (-1 for the initial state), so
    # that a disc changing twice at one time (a chain of contacts) keeps the later state.
    discs: list[np.ndarray] = [np.arange(n)]
    t_recs: list[np.ndarray] = [np.broadcast_to(np.asarray(time0, dtype=float), (n,))]
    seqs: list[np.ndarray] = [np.full(n, -1)]
    states: list[np.ndarray] = [np.hstack([positions0, velocities0])]
    in_order = True
    if len(events):
        times = events["time"]
        discs.append(events["i"])
        t_recs.append(times)
        seqs.append(np.arange(len(events)))
        states.append(np.column_stack([events["xi"], events["yi"], events["vxi"], events["vyi"]]))
        pair = np.flatnonzero(_second_disc(events))
        discs.append(events["j"][pair])  # field by field: gathering whole 89-byte rows is slower
        t_recs.append(times[pair])
        seqs.append(pair)
        states.append(np.column_stack([events[name][pair] for name in ("xj", "yj", "vxj", "vyj")]))
        in_order = bool(times[0] >= np.max(t_recs[0], initial=-np.inf) and (np.diff(times) >= 0).all())
    disc = np.concatenate(discs)
    t_rec = np.concatenate(t_recs)
    seq = np.concatenate(seqs)
    state = np.vstack(states)
    if in_order:  # log order is time order: sort by disc, then log order, on one integer key (3x faster)
        order = np.argsort(disc * (len(events) + 1) + (seq + 1))
    else:
        order = np.lexsort((seq, t_rec, disc))  # by disc, then time, then log order
    disc, t_rec, state = disc[order], t_rec[order], state[order]
    starts = np.searchsorted(disc, np.arange(n + 1))
    if kinds:
        seq = seq[order]
        kind = np.where(seq >= 0, events["kind"][np.maximum(seq, 0)] if len(events) else -1, -1)
        return disc, t_rec, state, starts, kind
    return disc, t_rec, state, starts


@dataclass(frozen=True)
class LastRecords:
    """Where a log stands at some point: each disc's last state record up to there, by disc id.

    Between its records a disc flies straight, so its position at a later time ``t`` (before its next
    record) is ``positions + velocities * (t - times)``, the same arithmetic as :func:`reconstruct`.
    This is all a reader needs to go on from the middle of a log (:func:`discsim.iter_events`).

    Attributes:
        times: ``(M,)`` time of each disc's last record (the log's start for a disc not recorded since).
        positions, velocities: ``(M, 2)`` its state just after that record; NaN for a disc not there
            (not yet added, or removed); wrapped into a periodic box, as logged.
        radii, masses: ``(M,)`` float; groups: ``(M,)`` int64 (NaN radius and mass for an id never there yet).
        images: ``(M, 2)`` whole box lengths each disc has crossed since the log's start (integers as
            floats; kept when records are folded with ``unwrapped=True``, else zero): its unwrapped position
            is ``positions + images * box.size``.
        still: ``(M,)`` bool, the discs whose last record is a collision or wall hit that left them with velocity
            exactly zero: under gravity, at rest (they do not fall until their next record; see
            :func:`reconstruct`). False where the log starts.
    """

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    radii: np.ndarray
    masses: np.ndarray
    groups: np.ndarray
    images: np.ndarray
    still: np.ndarray = None  # type: ignore[assignment]  # None: none at rest (filled in by __post_init__)

    def __post_init__(self) -> None:
        if self.still is None:
            object.__setattr__(self, "still", np.zeros(len(self.times), dtype=bool))

    @classmethod
    def at_start(cls, discs, start_time: float, ids=None, still=None) -> LastRecords:
        """The discs ``discs`` (ids ``ids``, default their indices) where a log starts, at ``start_time``; ``still``
        ``(N,)`` bool: those at rest then (a log streamed from the middle of a run under gravity; default none)."""
        ids = np.arange(len(discs)) if ids is None else np.asarray(ids, dtype=np.int64)
        m = int(ids.max()) + 1 if len(ids) else 0
        out = cls._empty(m, float(start_time))
        out.positions[ids], out.velocities[ids] = discs.positions, discs.velocities
        out.radii[ids], out.masses[ids], out.groups[ids] = discs.radii, discs.masses, discs.groups
        if still is not None:
            out.still[ids] = np.asarray(still, dtype=bool)
        return out

    @classmethod
    def _empty(cls, m: int, time: float) -> LastRecords:
        return cls(
            np.full(m, time),
            np.full((m, 2), np.nan),
            np.full((m, 2), np.nan),
            np.full(m, np.nan),
            np.full(m, np.nan),
            np.zeros(m, dtype=np.int64),
            np.zeros((m, 2)),
            np.zeros(m, dtype=bool),
        )

    def __len__(self) -> int:
        return len(self.times)

    def grown(self, m: int) -> LastRecords:
        """The same records for ``m >= len(self)`` ids (the new ones not there: NaN)."""
        k = len(self)
        if m <= k:
            return self
        more = LastRecords._empty(m - k, float(self.times[0]) if k else 0.0)
        return LastRecords(
            *(np.concatenate([a, b]) for a, b in zip(self._arrays(), more._arrays(), strict=True))  # type: ignore[arg-type]
        )

    def _arrays(self) -> tuple[np.ndarray, ...]:
        return (
            self.times,
            self.positions,
            self.velocities,
            self.radii,
            self.masses,
            self.groups,
            self.images,
            self.still,
        )

    def _after_in_order(self, records: np.ndarray) -> LastRecords:
        """:meth:`after` for records in time order, none before these records' times: a disc's last record
        is the last row naming it (no sort: O(R + M), five times faster on a long log)."""
        m, rows = len(self), np.arange(len(records))
        as_i, as_j = np.full(m, -1), np.full(m, -1)
        np.maximum.at(as_i, records["i"], rows)
        pair = _second_disc(records)
        np.maximum.at(as_j, records["j"][pair], rows[pair])
        times, positions, velocities = self.times.copy(), self.positions.copy(), self.velocities.copy()
        still = self.still.copy()
        physical = np.isin(records["kind"], _PHYSICAL)
        for last, chosen, names in (
            (as_i, as_i > as_j, ("xi", "yi", "vxi", "vyi")),
            (as_j, as_j > as_i, ("xj", "yj", "vxj", "vyj")),
        ):
            k = last[chosen]
            times[chosen] = records["time"][k]
            positions[chosen] = np.column_stack([records[names[0]][k], records[names[1]][k]])
            velocities[chosen] = np.column_stack([records[names[2]][k], records[names[3]][k]])
            still[chosen] = physical[k] & (velocities[chosen] == 0.0).all(axis=1)
        radii, masses, groups = self.radii.copy(), self.masses.copy(), self.groups.copy()
        return LastRecords(times, positions, velocities, radii, masses, groups, self.images, still)

    def after(self, records: np.ndarray, box=None, *, unwrapped: bool = False, gravity=None) -> LastRecords:
        """These records followed by ``records`` (:data:`EVENT_DTYPE`, later in the log): a new object.

        A disc's last record is its latest in time (then in log order), as :func:`reconstruct` takes it;
        ``ADD`` records bring new ids (their radius, mass and group), ``REMOVE`` records make a disc NaN.
        ``unwrapped`` (with a periodic ``box``) keeps the positions continuous across the edges, along the
        parabolas of the run's ``gravity`` ``(gx, gy)`` (None: straight lines).
        """
        if not len(records):
            return self
        added, _, _, _, radii, masses, groups = added_discs(records)
        top = int(max(records["i"].max(), records["j"].max())) + 1
        base = self.grown(top)
        m = len(base)
        shifts = unwrapped and box is not None and box.periodic
        times = records["time"]
        if not shifts and times[0] >= np.max(base.times, initial=-np.inf) and (np.diff(times) >= 0).all():
            out = base._after_in_order(records)
        else:  # out of time order (or the box lengths crossed wanted): sort every disc's records
            disc, t_rec, state, starts, kind = _sorted_records(
                records, base.positions, base.velocities, base.times, kinds=True
            )
            last = starts[1:] - 1
            images = base.images
            if shifts:
                falls = (
                    falling(disc, state, kind, gravity, base.masses, base.still)
                    if gravity is not None and tuple(gravity) != (0.0, 0.0)
                    else None
                )
                images = _image_counts(disc, t_rec, state, starts, box.size, base.images, gravity, falls)[last]
            still = np.where(kind[last] == -1, base.still, _rests(state[last], kind[last]))
            out = LastRecords(
                t_rec[last].copy(),
                state[last, :2].copy(),
                state[last, 2:].copy(),
                base.radii.copy(),
                base.masses.copy(),
                base.groups.copy(),
                images,
                still,
            )
        if len(added):
            out.radii[added], out.masses[added], out.groups[added] = radii, masses, groups
        assert len(out) == m
        return out


def _image_counts(disc, t_rec, state, starts, size, images0=None, gravity=None, falls=None, drag=0.0) -> np.ndarray:
    """``(R, 2)`` whole box lengths (counts, integers as floats) to add to each record so that every disc's
    path is continuous; the shift of a record is ``counts * size``.

    Records are sorted by disc, then time. Between two records of a disc it flies straight, so the
    later logged position differs from the earlier one's flight by whole box lengths plus roundoff.
    Each disc starts from ``images0`` ``(N, 2)`` (default zero). The counts are summed as integers, so a
    log read in pieces (:meth:`LastRecords.after`) gives the same shifts, bit for bit, as read whole.
    """
    x, y = _flight(state[:-1], t_rec[1:] - t_rec[:-1], gravity, None if falls is None else falls[:-1], drag)
    flown = np.column_stack([x, y])
    steps = np.nan_to_num(image_steps(flown, state[1:, :2], size))  # NaN: not there yet, or gone
    first = np.zeros(len(state) + 1, dtype=bool)
    first[starts] = True
    steps[first[1:-1]] = 0.0  # the first record of the next disc
    counts = np.zeros_like(state[:, :2])
    counts[1:] = np.cumsum(steps, axis=0)
    counts -= np.repeat(counts[starts[:-1]], np.diff(starts), axis=0)  # each disc starts from zero
    if images0 is not None:
        counts += np.repeat(images0, np.diff(starts), axis=0)
    return counts


def log_start(events, discs, ids=None) -> tuple[np.ndarray, ...]:
    """Every disc a log names, by id: ``(positions, velocities, radii, masses, groups)`` of ``M`` rows.

    A log names its discs by id (:attr:`discsim.engines.base.Engine.ids`); ``M`` is one more than the
    largest id in ``ids`` or in the log's ``ADD`` records. Row ``k`` is disc id ``k``: its state at the
    log's start (``discs``, whose ids are ``ids``; default ``0 .. len(discs) - 1``) or NaN if it was not
    there then (added later: its ``ADD`` record gives its state, radius, mass and group; or removed before
    the log starts: NaN radius and mass). Without ``ADD`` records and ids these are the arrays of ``discs``.

    Returns:
        positions, velocities ``(M, 2)``; radii, masses ``(M,)`` float; groups ``(M,)`` int64.
    """
    added, _, _, _, radii_added, masses_added, groups_added = added_discs(events) if len(events) else ((),) * 7
    if ids is None and not len(added):
        return discs.positions, discs.velocities, discs.radii, discs.masses, discs.groups
    ids = np.arange(len(discs)) if ids is None else np.asarray(ids, dtype=np.int64)
    m = max(int(ids.max()) + 1 if len(ids) else 0, int(np.max(added)) + 1 if len(added) else 0)
    positions, velocities = np.full((m, 2), np.nan), np.full((m, 2), np.nan)
    radii, masses, groups = np.full(m, np.nan), np.full(m, np.nan), np.zeros(m, dtype=np.int64)
    positions[ids], velocities[ids] = discs.positions, discs.velocities
    radii[ids], masses[ids], groups[ids] = discs.radii, discs.masses, discs.groups
    if len(added):
        radii[added], masses[added], groups[added] = radii_added, masses_added, groups_added
    return positions, velocities, radii, masses, groups


def positions_from_log(
    events,
    discs,
    box,
    start_time: float,
    end_time: float,
    times,
    *,
    span: str,
    unwrapped: bool,
    ids=None,
    gravity=None,
    still=None,
    drag: float = 0.0,
):
    """:func:`reconstruct` for a log covering ``[start_time, end_time]`` from ``discs`` (ids ``ids``) at ``start_time``
    (``still`` ``(N,)``: those of ``discs`` at rest then, under ``gravity``; default none; ``drag``: the run's).

    Checks ``times`` first (:func:`check_times`, naming the ``span``). Returns positions ``(T, M, 2)``: one
    column per disc id (:func:`log_start`), NaN where that disc was not in the simulation.
    """
    times = check_times(times, start_time, end_time, span)
    positions, velocities, _, masses, _ = log_start(events, discs, ids)
    still0 = None if still is None else LastRecords.at_start(discs, start_time, ids, still).grown(len(masses)).still
    return reconstruct(
        events,
        positions,
        velocities,
        start_time,
        times,
        box,
        unwrapped=unwrapped,
        gravity=gravity,
        masses=masses,
        still0=still0,
        drag=drag,
    )


def replay(chunks, start: LastRecords, times, box, *, unwrapped: bool = False, velocities: bool = False, gravity=None):
    """Exact positions (and velocities) at ``times`` from where a log stands and the records that follow it.

    Reads ``chunks`` (an iterable of :data:`EVENT_DTYPE` arrays in time order, e.g. a streamed log read chunk
    by chunk) one at a time, holding two at most, and stops once every time is done: memory stays flat in the
    log's length. Positions and velocities are those of :func:`reconstruct` and
    :func:`discsim.analysis.frames.states_at` over the whole log, bit for bit.

    Args:
        chunks: the records after ``start``, in time order.
        start: each disc's last record before them (:meth:`LastRecords.at_start` where a log starts).
        times: ``(T,)`` times, any order, at or after ``start``.
        box: the box; positions are wrapped into a periodic one unless ``unwrapped``.
        unwrapped: follow each disc across the periodic edges (from ``start.images``).
        velocities: also return the velocities.
        gravity: the run's ``(gx, gy)`` (None: free flight): between records a disc falls along a parabola
            unless at rest (see :func:`reconstruct`), and its velocity changes by ``g`` times the time since.

    Returns:
        positions ``(T, M, 2)`` (and velocities ``(T, M, 2)``): ``M`` disc ids, those known up to the last
        chunk read (NaN where a disc was not there).
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    order = np.argsort(times, kind="stable")
    wanted = times[order]
    parts: list[tuple[np.ndarray, np.ndarray | None]] = []
    nonempty = (c for c in chunks if len(c))
    carry, current, done = start, next(nonempty, None), 0
    while done < len(wanted):
        following = next(nonempty, None) if current is not None else None
        # Records of later chunks come at or after the first time of the next one.
        k = len(wanted) if following is None else int(np.searchsorted(wanted, following["time"].min(), side="left"))
        if k > done:
            records = current if current is not None else np.zeros(0, dtype=carry.times.dtype)
            parts.append(_evaluate(records, carry, wanted[done:k], box, unwrapped, velocities, gravity))
            done = k
        if current is None or done == len(wanted):
            break
        carry = carry.after(current, box, unwrapped=unwrapped, gravity=gravity)
        current = following
    m = max((p.shape[1] for p, _ in parts), default=len(start))
    positions = np.full((len(times), m, 2), np.nan)
    speeds = np.full((len(times), m, 2), np.nan) if velocities else None
    at = 0
    for p, v in parts:
        positions[order[at : at + len(p)], : p.shape[1]] = p
        if speeds is not None and v is not None:
            speeds[order[at : at + len(p)], : v.shape[1]] = v
        at += len(p)
    return (positions, speeds) if velocities else positions


def _evaluate(records, carry: LastRecords, times, box, unwrapped: bool, velocities: bool, gravity=None):
    """Positions (and velocities) ``(T, M, 2)`` at sorted ``times`` from ``carry`` and one chunk of ``records``."""
    if len(records):
        carry = carry.grown(int(max(records["i"].max(), records["j"].max())) + 1)
    positions = reconstruct(
        records,
        carry.positions,
        carry.velocities,
        carry.times,
        times,
        box,
        unwrapped=unwrapped,
        images0=carry.images,
        gravity=gravity,
        masses=carry.masses,
        still0=carry.still,
    )
    if not velocities:
        return positions, None
    disc, t_rec, state, starts, kind = _sorted_records(
        records, carry.positions, carry.velocities, carry.times, kinds=True
    )
    under_gravity = gravity is not None and tuple(gravity) != (0.0, 0.0)
    falls = falling(disc, state, kind, gravity, carry.masses, carry.still) if under_gravity else None
    first = starts[:-1]
    speeds = np.empty_like(positions)
    for k, t in enumerate(times.tolist()):
        # Each disc's records are in time order, so those at or before t are a prefix of its own.
        done = np.add.reduceat((t_rec <= t).astype(np.int64), first) if len(first) else first
        last = first + np.maximum(done, 1) - 1
        speeds[k] = state[last, 2:]
        if falls is not None:  # v + g dt while falling (advance's arithmetic)
            dt = np.where(falls[last], t - t_rec[last], 0.0)
            speeds[k] = np.column_stack([speeds[k, :, 0] + gravity[0] * dt, speeds[k, :, 1] + gravity[1] * dt])
    return positions, speeds


def flight(gravity=None, drag=0.0, *, what: str):
    """The gravity ``(gx, gy)`` (or None) a replay of a run's log takes, refusing the laws it cannot replay.

    Between records a disc flies straight, or falls along a parabola under ``gravity`` (:func:`reconstruct`);
    a run with linear drag (``drag`` nonzero: exponential flight) is not replayed yet.

    Raises:
        InvalidArgumentError: for a nonzero ``drag``, naming ``what`` and the value.
    """
    if drag is not None and float(drag) != 0.0:
        msg = (
            f"{what} replays free flight and parabolas between events, and this run has drag {float(drag)!r} "
            "(exponential flight), which it does not replay yet: use sim.trajectory(times), or sample the run "
            "with ds.Sampler(dt) while it runs"
        )
        raise InvalidArgumentError(msg)
    if gravity is None or tuple(float(g) for g in gravity) == (0.0, 0.0):
        return None
    return (float(gravity[0]), float(gravity[1]))


def turning_history(events, spin_events, spins0, time0: float, angles0=None) -> tuple[np.ndarray, ...]:
    """Every disc's spin changes from a log and its spins: each disc's spin and angle after each change.

    Args:
        events: :data:`EVENT_DTYPE` records in time order, naming discs ``0 .. N - 1`` (and no later ones).
        spin_events: :data:`~discsim.events.SPIN_DTYPE` rows, the spins after each collision and wall hit of
            ``events``, in order (``sim.spin_events`` of a rough run); None: spins never change (smooth discs).
        spins0: ``(N,)`` the spins at ``time0``, where the log starts. angles0: ``(N,)`` the angles then
            (default zero: angles count from the run's start).

    Returns:
        ``(starts (N + 1,), times (H,), spins (H,), angles (H,))``: disc ``d`` owns rows ``starts[d]:starts[d + 1]``
        (the first at ``time0``), in time then log order; ``angles`` each row's angle at its time, summed in
        order as the engine turns a disc (``angle += spin * (now - then)`` at each of its collisions).

    Raises:
        ValueError: if ``spin_events`` does not hold one row per collision and wall hit of ``events``.
    """
    spins0 = np.asarray(spins0, dtype=float)
    n = len(spins0)
    discs, t_recs, seqs, spins = [np.arange(n)], [np.full(n, float(time0))], [np.full(n, -1)], [spins0]
    if spin_events is not None and len(events):
        rows = np.flatnonzero(np.isin(events["kind"], _PHYSICAL))
        if len(rows) != len(spin_events) or not np.array_equal(events["time"][rows], spin_events["time"]):
            msg = f"{len(spin_events)} spin rows for {len(rows)} collisions and wall hits in the log"
            raise ValueError(msg)
        pair = events["j"][rows] >= 0
        discs += [events["i"][rows], events["j"][rows][pair]]
        t_recs += [events["time"][rows], events["time"][rows][pair]]
        seqs += [rows, rows[pair]]
        spins += [spin_events["wi"], spin_events["wj"][pair]]
    disc, t_rec, seq, spin = (np.concatenate(a) for a in (discs, t_recs, seqs, spins))
    order = np.lexsort((seq, t_rec, disc))
    disc, t_rec, spin = disc[order], t_rec[order], spin[order]
    starts = np.searchsorted(disc, np.arange(n + 1))
    angles = np.empty(len(t_rec))
    first = np.zeros(n) if angles0 is None else np.asarray(angles0, dtype=float)
    for d in range(n):
        lo, hi = starts[d], starts[d + 1]
        steps = spin[lo : hi - 1] * (t_rec[lo + 1 : hi] - t_rec[lo : hi - 1])
        angles[lo:hi] = np.cumsum(np.concatenate([[first[d]], steps]))  # (a0 + s1) + s2 ...: the engine's order
    return starts, t_rec, spin, angles


def turning_at(history, times) -> tuple[np.ndarray, np.ndarray]:
    """Spins and angles ``(T, N)`` each at ``times`` ``(T,)`` from a :func:`turning_history` (a change exactly at a
    time counts as done): the last change's spin, and its angle plus the spin times the time since."""
    starts, t_rec, spin, angle = history
    times = np.atleast_1d(np.asarray(times, dtype=float))
    n = len(starts) - 1
    spins, angles = np.empty((len(times), n)), np.empty((len(times), n))
    for d in range(n):
        lo, hi = starts[d], starts[d + 1]
        k = np.maximum(lo + np.searchsorted(t_rec[lo:hi], times, side="right") - 1, lo)
        spins[:, d] = spin[k]
        angles[:, d] = angle[k] + spin[k] * (times - t_rec[k])
    return spins, angles
