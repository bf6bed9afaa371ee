"""The event log: one record per processed event, enough to rebuild every path.

Each record holds the time, the kind (disc-disc collision or wall hit), the
discs involved, and their positions and velocities just after the event.
Between events discs fly in straight lines, so :func:`discsim.trajectory.reconstruct` gives the
exact position of every disc at any time covered by the log, with no
re-simulation. Both engines write the same records.
"""

from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

import numpy as np

__all__ = [
    "COLLISION",
    "EVENT_DTYPE",
    "KIND_NAMES",
    "SET",
    "WALL",
    "Event",
    "EventKind",
    "EventLog",
    "event_from_record",
]


class EventKind(IntEnum):
    """The one numbering of event kinds, in the log (``kind`` field) and in the engines' queues.

    The log holds ``COLLISION`` (disc-disc), ``WALL`` (a wall or a segment
    hit) and ``SET`` (a disc changed by the user: ``set_velocities``, ``apply_impulse``,
    ``set_positions``; ``j`` is -1) only; ``CROSSING`` (a disc enters another cell) and ``SEGMENT`` (a
    segment hit, logged as ``WALL``) live in the engines' queues.
    """

    COLLISION = 0
    WALL = 1
    CROSSING = 2
    SEGMENT = 3
    SET = 4


COLLISION = int(EventKind.COLLISION)
WALL = int(EventKind.WALL)
SET = int(EventKind.SET)
KIND_NAMES = {COLLISION: "collision", WALL: "wall", SET: "set"}


class Event(NamedTuple):
    """One processed event, as returned by ``step()``.

    Attributes:
        time: when it happened.
        kind: ``"collision"`` (disc-disc), ``"wall"``, or ``"set"`` (a change made by the user).
        i: the first disc. j: the second disc, or -1 for a wall hit.
    """

    time: float
    kind: str
    i: int
    j: int


def event_from_record(record) -> Event:
    """The :class:`Event` of one row of an :data:`EVENT_DTYPE` array."""
    return Event(float(record["time"]), KIND_NAMES[int(record["kind"])], int(record["i"]), int(record["j"]))


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

    def set(self, t, i, xi, yi, vxi, vyi) -> None:
        """Record that the user changed disc ``i`` at time ``t``, with its state after the change (rare: one copy)."""
        self.extend(np.array([(t, SET, i, -1, xi, yi, vxi, vyi, _NAN, _NAN, _NAN, _NAN)], dtype=EVENT_DTYPE))

    def extend(self, records: np.ndarray) -> None:
        """Append records given as a structured array of :data:`EVENT_DTYPE`."""
        self._rows.extend(tuple(r) for r in records.tolist())

    def since(self, start: int) -> np.ndarray:
        """The records from index ``start`` on, as a structured array (the log is unchanged).

        The driver hands such slices to the observers of a run.

        Example:
            >>> log = EventLog()
            >>> log.wall(0.5, 3, 1.0, 2.0, -1.0, 0.0)
            >>> log.since(0)["i"].tolist(), log.since(1).shape
            ([3], (0,))
        """
        return np.array(self._rows[start:], dtype=EVENT_DTYPE)

    def clear(self) -> None:
        """Drop every record (in place: a caller may hold the list's bound methods)."""
        del self._rows[:]

    def __len__(self) -> int:
        return len(self._rows)

    def to_array(self) -> np.ndarray:
        """All records as a structured array ``(E,)`` of :data:`EVENT_DTYPE`."""
        return np.array(self._rows, dtype=EVENT_DTYPE)
