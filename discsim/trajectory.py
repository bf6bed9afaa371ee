"""Exact positions from an event log: between events discs fly in straight lines.

:func:`reconstruct` gives every disc's position at any time the log covers, with no re-simulation: wrapped
into a periodic box (by :meth:`~discsim.model.Box.wrap`, the one wrap rule), or unwrapped, following each disc
across the periodic edges as it really moved (what a mean-squared displacement needs).
"""

from __future__ import annotations

import numpy as np

from discsim.errors import TimeError
from discsim.events import added_discs
from discsim.model import image_steps
from discsim.physics.dynamics import advance

__all__ = ["check_times", "log_start", "positions_from_log", "reconstruct"]


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
    time0: float,
    times,
    box=None,
    *,
    unwrapped: bool = False,
) -> np.ndarray:
    """Exact positions of every disc at ``times`` from an initial state and a log.

    Args:
        events: structured array of :data:`EVENT_DTYPE`, in time order.
        positions0, velocities0: ``(N, 2)`` state at ``time0``.
        time0: start time of the log.
        times: ``(T,)`` times (any order) at or after ``time0``.
        box: if given and periodic, positions are wrapped into it
            (:meth:`~discsim.model.Box.wrap`), unless ``unwrapped``.
        unwrapped: follow each disc across the periodic edges: where a
            logged position differs from the straight flight since the disc's
            previous record by whole box lengths (the engine wrapped it in
            between), those lengths are added back, exactly.

    Returns:
        ``(T, N, 2)`` positions. An event exactly at a requested time counts as
        having happened (positions are continuous there anyway). A disc whose
        state is NaN (not yet added at ``time0``, or after its ``REMOVE`` record)
        is NaN there (see :func:`log_start`).
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    n = len(positions0)
    # One state record per disc per change: initial state, then each event's i and j.
    # Each record also keeps the index of its event (-1 for the initial state), so
    # that a disc changing twice at one time (a chain of contacts) keeps the later state.
    discs: list[np.ndarray] = [np.arange(n)]
    t_recs: list[np.ndarray] = [np.full(n, float(time0))]
    seqs: list[np.ndarray] = [np.full(n, -1)]
    states: list[np.ndarray] = [np.hstack([positions0, velocities0])]
    if len(events):
        discs.append(events["i"])
        t_recs.append(events["time"])
        seqs.append(np.arange(len(events)))
        states.append(np.column_stack([events["xi"], events["yi"], events["vxi"], events["vyi"]]))
        pair = np.flatnonzero(events["j"] >= 0)
        ev = events[pair]
        discs.append(ev["j"])
        t_recs.append(ev["time"])
        seqs.append(pair)
        states.append(np.column_stack([ev["xj"], ev["yj"], ev["vxj"], ev["vyj"]]))
    disc = np.concatenate(discs)
    t_rec = np.concatenate(t_recs)
    seq = np.concatenate(seqs)
    state = np.vstack(states)
    order = np.lexsort((seq, t_rec, disc))  # by disc, then time, then log order
    disc, t_rec, state = disc[order], t_rec[order], state[order]
    starts = np.searchsorted(disc, np.arange(n + 1))
    periodic = box is not None and box.periodic
    if unwrapped and periodic and len(state) > n:
        state[:, :2] += _image_shifts(disc, t_rec, state, starts, box.size)
    out = np.empty((len(times), n, 2))
    for d in range(n):
        lo, hi = starts[d], starts[d + 1]
        k = lo + np.searchsorted(t_rec[lo:hi], times, side="right") - 1
        k = np.maximum(k, lo)
        dt = (times - t_rec[k])[:, None]
        x, y, _, _ = advance(state[k, 0], state[k, 1], state[k, 2], state[k, 3], dt[:, 0])
        out[:, d, 0], out[:, d, 1] = x, y
    if periodic and not unwrapped:
        out = box.wrap(out)
    return out


def _image_shifts(disc, t_rec, state, starts, size) -> np.ndarray:
    """``(R, 2)`` whole box lengths to add to each record so that every disc's path is continuous.

    Records are sorted by disc, then time. Between two records of a disc it flies straight, so the
    later logged position differs from the earlier one's flight by whole box lengths plus roundoff.
    """
    x, y, _, _ = advance(state[:-1, 0], state[:-1, 1], state[:-1, 2], state[:-1, 3], t_rec[1:] - t_rec[:-1])
    flown = np.column_stack([x, y])
    jump = np.nan_to_num(image_steps(flown, state[1:, :2], size) * size)  # NaN: not there yet, or gone
    jump[np.isin(np.arange(1, len(state)), starts)] = 0.0  # the first record of the next disc
    shifts = np.zeros_like(state[:, :2])
    shifts[1:] = np.cumsum(jump, axis=0)
    first = np.repeat(shifts[starts[:-1]], np.diff(starts), axis=0)  # each disc starts from zero
    return shifts - first


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
    events, discs, box, start_time: float, end_time: float, times, *, span: str, unwrapped: bool, ids=None
):
    """:func:`reconstruct` for a log covering ``[start_time, end_time]`` from ``discs`` (ids ``ids``) at ``start_time``.

    Checks ``times`` first (:func:`check_times`, naming the ``span``). Returns positions ``(T, M, 2)``: one
    column per disc id (:func:`log_start`), NaN where that disc was not in the simulation.
    """
    times = check_times(times, start_time, end_time, span)
    positions, velocities = log_start(events, discs, ids)[:2]
    return reconstruct(events, positions, velocities, start_time, times, box, unwrapped=unwrapped)
