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
    "ADD",
    "COLLISION",
    "ENTER",
    "EVENT_DTYPE",
    "KIND_NAMES",
    "LEAVE",
    "REMOVE",
    "SENSED",
    "SET",
    "SPIN_DTYPE",
    "WALL",
    "Crossing",
    "Event",
    "EventKind",
    "EventLog",
    "added_discs",
    "disc_count",
    "disc_partners",
    "event_from_record",
]


class EventKind(IntEnum):
    """The one numbering of event kinds, in the log (``kind`` field) and in the engines' queues.

    The log holds ``COLLISION`` (disc-disc), ``WALL`` (a wall or a segment
    hit), ``SET`` (a disc changed by the user: ``set_velocities``, ``apply_impulse``,
    ``set_positions``; or, under gravity, a disc at rest that falls again because what held it up went: where it
    is, velocity zero; ``j`` is -1), ``ADD`` and ``REMOVE`` (a disc added by ``add_discs`` or removed by
    ``remove_discs``; ``j`` is -1; see :class:`EventLog` for their fields), ``ENTER`` and ``LEAVE`` (a disc's
    centre enters or leaves a sensor, :class:`discsim.Sensor`: ``j`` is the sensor's index, the ``i`` fields the
    disc's centre and velocity then; the motion does not change) only; ``CROSSING`` (a disc enters another
    cell), ``SEGMENT`` (a segment hit, logged as ``WALL``), ``SENSOR`` (a centre changes sides of a sensor,
    logged as ``ENTER`` or ``LEAVE``, or not at all beyond a trip wire's ends) and ``PISTON`` (a disc meets the
    piston, :class:`discsim.Piston`: logged as ``WALL``, with the piston's height after in ``yj`` and its
    velocity in ``vyj``) live in the engines' queues.
    """

    COLLISION = 0
    WALL = 1
    CROSSING = 2
    SEGMENT = 3
    SET = 4
    ADD = 5
    REMOVE = 6
    SENSOR = 7
    ENTER = 8
    LEAVE = 9
    PISTON = 10


COLLISION = int(EventKind.COLLISION)
WALL = int(EventKind.WALL)
SET = int(EventKind.SET)
ADD = int(EventKind.ADD)
REMOVE = int(EventKind.REMOVE)
ENTER = int(EventKind.ENTER)
LEAVE = int(EventKind.LEAVE)
KIND_NAMES = {
    COLLISION: "collision", WALL: "wall", SET: "set", ADD: "add", REMOVE: "remove", ENTER: "enter", LEAVE: "leave"
}  # fmt: skip
#: The kinds of a sensor's records: ``j`` is a sensor, not a disc, and the motion does not change.
SENSED = (ENTER, LEAVE)


class Event(NamedTuple):
    """One processed event, as returned by ``step()``.

    Attributes:
        time: when it happened.
        kind: ``"collision"`` (disc-disc), ``"wall"``, ``"enter"`` or ``"leave"`` (a sensor), or a change made by
            the user: ``"set"``, ``"add"``, ``"remove"``.
        i: the first disc. j: the second disc, -1 for a wall hit, or the sensor's index.
    """

    time: float
    kind: str
    i: int
    j: int


class Crossing(NamedTuple):
    """A disc's centre entering or leaving a sensor, as a callback of ``sim.on("enter" | "leave", fn)`` receives it.

    Attributes:
        time: when. kind: ``"enter"`` or ``"leave"``. i: the disc (its index now). sensor: the sensor's index
            (``sim.sensors[sensor]``). position, velocity: ``(2,)`` the disc's centre and velocity then.
    """

    time: float
    kind: str
    i: int
    sensor: int
    position: np.ndarray
    velocity: np.ndarray


def disc_partners(events: np.ndarray) -> np.ndarray:
    """``(R,)`` bool: the records of ``events`` whose ``j`` names a disc (not a wall hit's -1, nor a sensor's index)."""
    return (events["j"] >= 0) & (events["kind"] != ENTER) & (events["kind"] != LEAVE)


def disc_count(events: np.ndarray) -> int:
    """One more than the largest disc id ``events`` name (0 for none)."""
    if not len(events):
        return 0
    j = events["j"][disc_partners(events)]
    return int(max(events["i"].max(), j.max(initial=-1))) + 1


def event_from_record(record) -> Event:
    """The :class:`Event` of one row of an :data:`EVENT_DTYPE` array."""
    return Event(float(record["time"]), KIND_NAMES[int(record["kind"])], int(record["i"]), int(record["j"]))


#: One event: time, kind (:class:`EventKind`), discs ``i`` and ``j`` (``j`` is
#: -1 for a wall hit), and each disc's position and velocity after the event
#: (NaN for the absent ``j``). Discs are named by their id (``sim.ids``: a disc's index until some disc
#: is removed). ``ADD`` and ``REMOVE`` records use the ``j`` fields for what the disc is or was (see
#: :class:`EventLog`).
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

#: A rough run's spins after each collision or wall hit (``EventDriven.spin_events``): the event's time and
#: discs (as in :data:`EVENT_DTYPE`) and the spins of ``i`` and ``j`` after it (``wj`` NaN for a wall hit).
SPIN_DTYPE = np.dtype([("time", "f8"), ("i", "i8"), ("j", "i8"), ("wi", "f8"), ("wj", "f8")])

_NAN = float("nan")
# Rows the hot loop's tuples wait in before they move into the log's arrays together (about 0.4 MB of tuples).
_FLUSH = 1024
# Rows per block of the log's arrays at most (5.8 MB): the log grows block by block, never copying what it holds.
_BLOCK = 1 << 16


def _copy_rows(dst: np.ndarray, src: np.ndarray) -> None:
    """``dst[:] = src`` for rows of :data:`EVENT_DTYPE`, as bytes: 10 ns a row instead of 80 field by field
    (the packed 89-byte rows are unaligned, so numpy would copy them field by field)."""
    if src.dtype == EVENT_DTYPE and src.ndim == 1:
        dst.view(np.uint8)[:] = np.ascontiguousarray(src).view(np.uint8)
    else:
        dst[:] = src


class EventLog:
    """An append-only in-memory log of event records, compact: one :data:`EVENT_DTYPE` row (89 bytes) per event.

    Engines call :meth:`collision` and :meth:`wall` in their hot loop; each appends a row tuple to a short
    list of pending rows, which moves into the log's arrays every thousand rows (amortised O(1) per event;
    the tuples and their floats are freed). A compiled backend appends whole chunks with :meth:`extend`
    (one copy, as bytes). The arrays are blocks of ``_BLOCK`` rows filled in turn, so the log never copies
    what it holds as it grows; :meth:`to_array` joins them into one array, once.

    Example:
        >>> log = EventLog()
        >>> log.collision(0.5, 0, 1, 1.0, 2.0, -1.0, 0.0, 2.0, 2.0, 1.0, 0.0)
        >>> log.wall(0.75, 1, 3.0, 2.0, -1.0, 0.0)
        >>> len(log), log.to_array()["j"].tolist()
        (2, [1, -1])
    """

    #: ``(N,)`` int64: the id of each disc the engine's loop names by its index, or None when they are the
    #: same (until a disc is removed). Records from the loop (:meth:`collision`, :meth:`wall`,
    #: :meth:`extend`) are renamed through it as they move into the arrays; :meth:`set`, :meth:`add` and
    #: :meth:`remove` take ids. Change it only after :meth:`flush`.
    ids: np.ndarray | None = None

    def __init__(self) -> None:
        self._reset()

    def _reset(self) -> None:
        """No records."""
        self._pending: list[tuple] = []  # rows not yet in the arrays, oldest first
        self._blocks: list[np.ndarray] = []  # full (or joined) arrays of rows, oldest first; never written again
        self._stored = 0  # rows in _blocks
        self._tail = np.zeros(0, dtype=EVENT_DTYPE)  # the block being filled: live rows are [_start, _fill)
        self._start = self._fill = 0

    def collision(self, t, i, j, xi, yi, vxi, vyi, xj, yj, vxj, vyj) -> None:
        """Record a disc-disc event at time ``t`` with the discs' state after it."""
        pending = self._pending
        pending.append((t, COLLISION, i, j, xi, yi, vxi, vyi, xj, yj, vxj, vyj))
        if len(pending) == _FLUSH:
            self._flush()

    def wall(self, t, i, xi, yi, vxi, vyi) -> None:
        """Record a wall hit of disc ``i`` at time ``t`` with its state after it."""
        pending = self._pending
        pending.append((t, WALL, i, -1, xi, yi, vxi, vyi, _NAN, _NAN, _NAN, _NAN))
        if len(pending) == _FLUSH:
            self._flush()

    def set(self, t, i, xi, yi, vxi, vyi) -> None:
        """Record that the user changed disc (id) ``i`` at time ``t``, with its state after the change (rare)."""
        self.flush()
        self._put(np.array([(t, SET, i, -1, xi, yi, vxi, vyi, _NAN, _NAN, _NAN, _NAN)], dtype=EVENT_DTYPE))

    def add(self, t, ids, positions, velocities, radii, masses, groups) -> None:
        """Record that discs ``ids`` ``(K,)`` were added at time ``t``: one ``ADD`` record each.

        ``xi, yi, vxi, vyi`` hold the disc's state; ``xj`` its radius, ``yj`` its mass, and ``vxj`` the 64
        bits of its integer group label (``np.int64(label).view(np.float64)``, exact for every label;
        :func:`added_discs` reads them back); ``j`` is -1 and ``vyj`` NaN.
        """
        k = len(ids)
        rows = np.empty(k, dtype=EVENT_DTYPE)
        rows["time"], rows["kind"], rows["i"], rows["j"] = t, ADD, ids, -1
        rows["xi"], rows["yi"] = positions[:, 0], positions[:, 1]
        rows["vxi"], rows["vyi"] = velocities[:, 0], velocities[:, 1]
        rows["xj"], rows["yj"] = radii, masses
        rows["vxj"] = np.asarray(groups).astype(np.int64).view(np.float64)
        rows["vyj"] = _NAN
        self.flush()
        self._put(rows)

    def remove(self, t, ids, positions, velocities) -> None:
        """Record that discs ``ids`` ``(K,)`` were removed at time ``t``: one ``REMOVE`` record each.

        The state after is NaN (``xi, yi, vxi, vyi``: the disc is gone, so a trajectory rebuilt from the log
        is NaN from then on); ``xj, yj, vxj, vyj`` hold where it was and its velocity then; ``j`` is -1.
        """
        k = len(ids)
        rows = np.empty(k, dtype=EVENT_DTYPE)
        rows["time"], rows["kind"], rows["i"], rows["j"] = t, REMOVE, ids, -1
        for name in ("xi", "yi", "vxi", "vyi"):
            rows[name] = _NAN
        rows["xj"], rows["yj"] = positions[:, 0], positions[:, 1]
        rows["vxj"], rows["vyj"] = velocities[:, 0], velocities[:, 1]
        self.flush()
        self._put(rows)

    def extend(self, records: np.ndarray) -> None:
        """Append records given as a structured array of :data:`EVENT_DTYPE` (one copy), renamed by :attr:`ids`."""
        self._flush()
        self._put(self._renamed(records))

    def restore(self, records: np.ndarray) -> None:
        """Append records already in ids (a log read back from a file), as they are."""
        self.flush()
        self._put(records)

    def _renamed(self, rows: np.ndarray) -> np.ndarray:
        """``rows`` with ``i`` and ``j`` turned from the loop's indices into ids (a copy; as is without ids)."""
        ids = self.ids
        if ids is None or not len(rows):
            return rows
        rows = np.array(rows)
        rows["i"] = ids[rows["i"]]
        j = rows["j"]
        pair = (j >= 0) & (rows["kind"] != ENTER) & (rows["kind"] != LEAVE)  # a sensor's j is the sensor's index
        rows["j"] = np.where(pair, ids[np.where(pair, j, 0)], j)
        return rows

    def flush(self) -> None:
        """Move the pending rows into the arrays (renamed by the :attr:`ids` of now)."""
        self._flush()

    def _flush(self) -> None:
        """Move the pending rows into the arrays."""
        pending = self._pending
        if pending:
            self._put(self._renamed(np.fromiter(pending, dtype=EVENT_DTYPE, count=len(pending))))
            pending.clear()

    def _put(self, rows: np.ndarray) -> None:
        """Copy ``rows`` into the tail block, starting new blocks as each fills."""
        k, done = len(rows), 0
        while done < k:
            room = len(self._tail) - self._fill
            if room == 0:
                self._seal()
                # Blocks as long as the log so far (1024 rows at least, _BLOCK at most): small logs stay small.
                size = min(_BLOCK, max(1024, self._stored))
                self._tail = np.empty(max(size, k - done), dtype=EVENT_DTYPE)
                self._start = self._fill = 0
                room = len(self._tail)
            m = min(room, k - done)
            _copy_rows(self._tail[self._fill : self._fill + m], rows[done : done + m])
            self._fill += m
            done += m

    def _seal(self) -> None:
        """File the tail's live rows (a full block) with the blocks."""
        if self._fill > self._start:
            self._blocks.append(self._tail[self._start : self._fill])
            self._stored += self._fill - self._start
        self._start = self._fill

    def _pieces(self) -> list[np.ndarray]:
        live = self._tail[self._start : self._fill]
        return [*self._blocks, live] if len(live) else list(self._blocks)

    def since(self, start: int) -> np.ndarray:
        """The records from index ``start`` on, as a new structured array (the log is unchanged); O(rows asked).

        The driver hands such slices to the observers of a run.

        Example:
            >>> log = EventLog()
            >>> log.wall(0.5, 3, 1.0, 2.0, -1.0, 0.0)
            >>> log.since(0)["i"].tolist(), log.since(1).shape
            ([3], (0,))
        """
        self._flush()
        total = len(self)
        start = min(max(int(start), 0), total)
        out = np.empty(total - start, dtype=EVENT_DTYPE)
        end = total
        for piece in reversed(self._pieces()):
            begin = end - len(piece)
            if end <= start:
                break
            skip = max(start - begin, 0)
            _copy_rows(out[begin + skip - start : end - start], piece[skip:])
            end = begin
        return out

    def clear(self) -> None:
        """Drop every record (arrays handed out by :meth:`to_array` keep theirs); :attr:`ids` stays."""
        self._reset()

    def __len__(self) -> int:
        return self._stored + self._fill - self._start + len(self._pending)

    @property
    def nbytes(self) -> int:
        """Bytes the log holds: its arrays (the tail block whole) and the pending row tuples (about 360 each)."""
        held = sum(block.base.nbytes if block.base is not None else block.nbytes for block in self._blocks)
        return (
            held
            + (self._tail.nbytes if not self._blocks or self._blocks[-1].base is not self._tail else 0)
            + (360 * len(self._pending))
        )

    def to_array(self) -> np.ndarray:
        """All records as a read-only structured array ``(E,)`` of :data:`EVENT_DTYPE`, without a copy when it can.

        Later events do not change it (they go past its end, or into a new block). When the log spans several
        blocks they are joined into one, which the log keeps in their place (so memory stays one row per event).
        """
        self._flush()
        pieces = self._pieces()
        if not pieces:
            out = np.zeros(0, dtype=EVENT_DTYPE)
        elif len(pieces) == 1:
            out = pieces[0][:]
        else:
            out = np.empty(len(self), dtype=EVENT_DTYPE)
            at = 0
            for piece in pieces:
                _copy_rows(out[at : at + len(piece)], piece)
                at += len(piece)
            self._blocks, self._stored = [out], len(out)
            self._tail = np.zeros(0, dtype=EVENT_DTYPE)  # its rows are in the joined array now
            self._start = self._fill = 0
            out = out[:]
        out.flags.writeable = False
        return out


def added_discs(events: np.ndarray) -> tuple[np.ndarray, ...]:
    """What the ``ADD`` records of a log say: ``(ids, times, positions, velocities, radii, masses, groups)``.

    Arrays of ``K`` rows (positions and velocities ``(K, 2)``), one per disc added, in log order.

    Example:
        >>> log = EventLog()
        >>> log.add(1.5, [2], np.array([[1.0, 2.0]]), np.array([[0.5, 0.0]]), [0.25], [3.0], [7])
        >>> ids, times, pos, vel, radii, masses, groups = added_discs(log.to_array())
        >>> ids.tolist(), pos.tolist(), radii.tolist(), masses.tolist(), groups.tolist()
        ([2], [[1.0, 2.0]], [0.25], [3.0], [7])
    """
    rows = events[events["kind"] == ADD]
    return (
        rows["i"].astype(np.int64),
        rows["time"].astype(np.float64),
        np.column_stack([rows["xi"], rows["yi"]]).reshape(-1, 2),
        np.column_stack([rows["vxi"], rows["vyi"]]).reshape(-1, 2),
        rows["xj"].astype(np.float64),
        rows["yj"].astype(np.float64),
        np.ascontiguousarray(rows["vxj"]).view(np.int64).copy(),
    )
