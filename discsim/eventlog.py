"""The event log: one record per processed event, enough to rebuild every path.

Each record holds the time, the kind (disc-disc collision or wall hit), the
discs involved, and their positions and velocities just after the event.
Between events discs fly in straight lines, so :func:`reconstruct` gives the
exact position of every disc at any time covered by the log, with no
re-simulation. Both engines write the same records.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from discsim.errors import CheckpointError, DiscsimError, TimeError
from discsim.io import read_stream
from discsim.state import Box, Discs

__all__ = [
    "COLLISION",
    "EVENT_DTYPE",
    "KIND_NAMES",
    "WALL",
    "EventLog",
    "StreamedEvents",
    "read_events",
    "reconstruct",
    "stream_header",
    "trajectory_from_events",
]

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

    def drain(self) -> np.ndarray:
        """Return every record as a structured array ``(E,)`` and empty the log.

        Used to stream a long run's log to disk in chunks so that memory stays flat.

        Example:
            >>> log = EventLog()
            >>> log.wall(0.5, 3, 1.0, 2.0, -1.0, 0.0)
            >>> log.drain()["i"].tolist(), len(log)
            ([3], 0)
        """
        records = np.array(self._rows, dtype=EVENT_DTYPE)
        del self._rows[:]  # in place: a caller may hold the list's bound methods
        return records

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


# --- event logs streamed to disk ---------------------------------------------------------------
#: ``kind`` in the header of an event log written by ``run(record_to=...)``.
STREAM_KIND = "discsim event log"


def stream_header(discs: Discs, box: Box, start_time: float, run_id: str, base: int) -> tuple[dict, dict]:
    """Header ``(meta, arrays)`` of a streamed event log: the discs at ``start_time`` and the box.

    Args:
        discs: the discs' state at ``start_time`` (where the log starts).
        box: the box. start_time: simulated time of ``discs``.
        run_id: identifies the run, so that a resumed run appends only to its own log.
        base: physical events the run had processed before the log starts.
    """
    meta = {
        "kind": STREAM_KIND,
        "run_id": run_id,
        "start_time": float(start_time),
        "base": int(base),
        "n": len(discs),
        "box": {"width": box.width, "height": box.height, "periodic": box.periodic},
    }
    arrays = {
        "positions": discs.positions,
        "velocities": discs.velocities,
        "radii": discs.radii,
        "masses": discs.masses,
        "groups": discs.groups,
    }
    return meta, arrays


@dataclass(frozen=True)
class StreamedEvents:
    """An event log read back from disk by :func:`read_events`.

    Attributes:
        events: ``(E,)`` structured array of :data:`EVENT_DTYPE`, in time order.
        discs: the discs at ``start_time``, where the log starts.
        box: the box.
        start_time: simulated time at which the log starts.
        end_time: simulated time up to which the log is complete (the run's
            time when it last wrote to the log).
        run_id: the run that wrote the log.
    """

    events: np.ndarray
    discs: Discs
    box: Box
    start_time: float
    end_time: float
    run_id: str

    def trajectory(self, times) -> np.ndarray:
        """Exact positions ``(T, N, 2)`` at ``times`` ``(T,)`` in ``[start_time, end_time]``.

        Raises:
            TimeError: if a time is not finite or lies outside the logged span.
        """
        times = np.atleast_1d(np.asarray(times, dtype=float))
        if times.size and not np.isfinite(times).all():
            msg = f"trajectory times must be finite, got {times[~np.isfinite(times)][0]!r}"
            raise TimeError(msg)
        tol = 1e-12 * max(1.0, abs(self.end_time))
        if times.size and (times.min() < self.start_time - tol or times.max() > self.end_time + tol):
            bad = times.min() if times.min() < self.start_time - tol else times.max()
            msg = f"trajectory time {bad!r} is outside the logged span [{self.start_time!r}, {self.end_time!r}]"
            raise TimeError(msg)
        return reconstruct(self.events, self.discs.positions, self.discs.velocities, self.start_time, times, self.box)


def read_events(path, *, partial: bool = False) -> StreamedEvents:
    """Read an event log written by ``EventDriven.run(record_to=path)``.

    Every chunk's checksum is verified. The whole log is loaded into memory
    (89 bytes per event).

    Args:
        path: the log file.
        partial: accept a log whose last chunk is incomplete (a run killed
            while writing it) and return the complete chunks; a corrupted
            chunk is refused either way.

    Returns:
        A :class:`StreamedEvents`: the events, the discs and time where the log
        starts, the box, and the time up to which it is complete.

    Raises:
        FileNotFoundError: if there is no such file.
        CheckpointError: if the file is truncated (unless ``partial``),
            corrupted, of another format version or not an event log.

    Example:
        >>> import os, tempfile, discsim as ds
        >>> path = os.path.join(tempfile.mkdtemp(), "events.dse")
        >>> discs, box = ds.random_gas(20, 0.3, seed=1)
        >>> sim = ds.EventDriven(discs, box, record=False).run(until=2.0, record_to=path)
        >>> log = ds.read_events(path)
        >>> len(log.events) == sim.counts["collisions"] + sim.counts["wall_hits"], log.end_time
        (True, 2.0)
        >>> bool(np.allclose(log.trajectory([2.0])[0], sim.positions))
        True
    """
    stream = read_stream(path, partial=partial)
    meta, arrays = stream.meta, stream.arrays
    if not isinstance(meta, dict) or meta.get("kind") != STREAM_KIND:
        msg = f"{path}: a discsim record stream, but not an event log"
        raise CheckpointError(msg)
    if stream.records.dtype != EVENT_DTYPE:
        msg = f"{path}: records of dtype {stream.records.dtype}, expected the event dtype"
        raise CheckpointError(msg)
    try:
        box = Box(**meta["box"])
        discs = Discs(arrays["positions"], arrays["velocities"], arrays["radii"], arrays["masses"], arrays["groups"])
        start_time = float(meta["start_time"])
        end_time = float(stream.last.get("time", start_time))
        run_id = str(meta["run_id"])
    except (KeyError, TypeError, DiscsimError) as exc:
        msg = f"{path}: the event log's header is incomplete or invalid ({exc})"
        raise CheckpointError(msg) from exc
    return StreamedEvents(stream.records, discs, box, start_time, end_time, run_id)


def trajectory_from_events(source, times) -> np.ndarray:
    """Exact positions ``(T, N, 2)`` at ``times`` ``(T,)`` from a streamed event log.

    Args:
        source: a path to a log written by ``run(record_to=...)``, or a
            :class:`StreamedEvents` already read by :func:`read_events`.
        times: times within the logged span ``[start_time, end_time]``.

    Raises:
        CheckpointError: if the file is damaged (see :func:`read_events`).
        TimeError: if a time lies outside the logged span.

    Example:
        >>> import os, tempfile, discsim as ds
        >>> path = os.path.join(tempfile.mkdtemp(), "events.dse")
        >>> discs, box = ds.random_gas(20, 0.3, seed=1)
        >>> sim = ds.EventDriven(discs, box).run(until=1.0)
        >>> _ = ds.EventDriven(discs, box, record=False).run(until=1.0, record_to=path)
        >>> bool((ds.trajectory_from_events(path, [0.3, 1.0]) == sim.trajectory([0.3, 1.0])).all())
        True
    """
    log = source if isinstance(source, StreamedEvents) else read_events(Path(source))
    return log.trajectory(times)
