"""Exact positions from an event log: between events discs fly in straight lines.

:func:`reconstruct` gives every disc's position at any time the log covers, with no re-simulation: wrapped
into a periodic box (by :meth:`~discsim.model.Box.wrap`, the one wrap rule), or unwrapped, following each disc
across the periodic edges as it really moved (what a mean-squared displacement needs).
"""

from __future__ import annotations

import numpy as np

__all__ = ["reconstruct"]


def reconstruct(
    events: np.ndarray,
    positions0: np.ndarray,
    velocities0: np.ndarray,
    time0: float,
    times,
    box=None,
) -> np.ndarray:
    """Exact positions of every disc at ``times`` from an initial state and a log.

    Args:
        events: structured array of :data:`EVENT_DTYPE`, in time order.
        positions0, velocities0: ``(N, 2)`` state at ``time0``.
        time0: start time of the log.
        times: ``(T,)`` times (any order) at or after ``time0``.
        box: if given and periodic, positions are wrapped into it.

    Returns:
        ``(T, N, 2)`` positions. An event exactly at a requested time counts as
        having happened (positions are continuous there anyway).
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    n = len(positions0)
    # One state record per disc per change: initial state, then each event's i and j.
    # Each record also keeps the index of its event (-1 for the initial state), so
    # that a disc changing twice at one time (a chain of contacts) keeps the later state.
    disc = [np.arange(n)]
    t_rec = [np.full(n, float(time0))]
    seq = [np.full(n, -1)]
    state = [np.hstack([positions0, velocities0])]
    if len(events):
        disc.append(events["i"])
        t_rec.append(events["time"])
        seq.append(np.arange(len(events)))
        state.append(np.column_stack([events["xi"], events["yi"], events["vxi"], events["vyi"]]))
        pair = np.flatnonzero(events["j"] >= 0)
        ev = events[pair]
        disc.append(ev["j"])
        t_rec.append(ev["time"])
        seq.append(pair)
        state.append(np.column_stack([ev["xj"], ev["yj"], ev["vxj"], ev["vyj"]]))
    disc = np.concatenate(disc)
    t_rec = np.concatenate(t_rec)
    seq = np.concatenate(seq)
    state = np.vstack(state)
    order = np.lexsort((seq, t_rec, disc))  # by disc, then time, then log order
    disc, t_rec, state = disc[order], t_rec[order], state[order]
    starts = np.searchsorted(disc, np.arange(n + 1))
    out = np.empty((len(times), n, 2))
    for d in range(n):
        lo, hi = starts[d], starts[d + 1]
        k = lo + np.searchsorted(t_rec[lo:hi], times, side="right") - 1
        k = np.maximum(k, lo)
        dt = (times - t_rec[k])[:, None]
        out[:, d, :] = state[k, :2] + state[k, 2:] * dt
    if box is not None and box.periodic:
        out = np.mod(out, box.size)
    return out
