"""The event log: one record per processed event, enough to rebuild every path.

Each record holds the time, the kind (disc-disc collision or wall hit), the
discs involved, and their positions and velocities just after the event.
Between events discs fly in straight lines, so :func:`reconstruct` gives the
exact position of every disc at any time covered by the log, with no
re-simulation. Both engines write the same records.
"""

from __future__ import annotations

import numpy as np

__all__ = ["COLLISION", "EVENT_DTYPE", "KIND_NAMES", "WALL", "EventLog", "reconstruct"]

COLLISION = 0
WALL = 1
KIND_NAMES = {COLLISION: "collision", WALL: "wall"}

#: One event: time, kind (0 disc-disc, 1 wall), discs ``i`` and ``j`` (``j`` is
#: -1 for a wall hit), and each disc's position and velocity after the event
#: (NaN for the absent ``j``).
EVENT_DTYPE = np.dtype(
    [
        ("time", "f8"),
        ("kind", "i1"),
        ("i", "i8"),
        ("j", "i8"),
        ("xi", "f8"),
        ("yi", "f8"),
        ("vxi", "f8"),
        ("vyi", "f8"),
        ("xj", "f8"),
        ("yj", "f8"),
        ("vxj", "f8"),
        ("vyj", "f8"),
    ]
)

_NAN = float("nan")


class EventLog:
    """An append-only in-memory list of event records.

    Engines call :meth:`collision` and :meth:`wall` in their hot loop; users
    read :meth:`to_array`, a structured array of :data:`EVENT_DTYPE`.
    """

    def __init__(self):
        self._rows: list[tuple] = []

    def collision(self, t, i, j, xi, yi, vxi, vyi, xj, yj, vxj, vyj) -> None:
        """Record a disc-disc event at time ``t`` with the discs' state after it."""
        self._rows.append((t, COLLISION, i, j, xi, yi, vxi, vyi, xj, yj, vxj, vyj))

    def wall(self, t, i, xi, yi, vxi, vyi) -> None:
        """Record a wall hit of disc ``i`` at time ``t`` with its state after it."""
        self._rows.append((t, WALL, i, -1, xi, yi, vxi, vyi, _NAN, _NAN, _NAN, _NAN))

    def extend(self, records: np.ndarray) -> None:
        """Append records given as a structured array of :data:`EVENT_DTYPE`."""
        self._rows.extend(tuple(r) for r in records.tolist())

    def __len__(self) -> int:
        return len(self._rows)

    def to_array(self) -> np.ndarray:
        """All records as a structured array ``(E,)`` of :data:`EVENT_DTYPE`."""
        return np.array(self._rows, dtype=EVENT_DTYPE)


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
