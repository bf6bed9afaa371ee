"""Event logs streamed to disk by a run: the header, and reading them back.

A log is a record stream of :mod:`discsim.io.container` whose header holds the discs where the log starts and
the box, and whose records are :data:`~discsim.events.EVENT_DTYPE` rows.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from discsim.errors import CheckpointError, DiscsimError, InvalidArgumentError
from discsim.events import EVENT_DTYPE
from discsim.io.container import iter_stream, read_stream, stream_index
from discsim.model import Box, Discs, Segment
from discsim.sensors import CIRCLE, LINE, RECTANGLE, Sensor
from discsim.trajectory import LastRecords, check_times, flight, positions_from_log, replay

__all__ = [
    "DEFAULT_CHUNK",
    "STREAM_KIND",
    "EventChunk",
    "EventChunks",
    "StreamedEvents",
    "iter_events",
    "read_events",
    "segment_past_rows",
    "segment_rows",
    "segments_from_rows",
    "sensors_from_rows",
    "stream_header",
    "trajectory_from_events",
]

#: ``kind`` in the header of an event log written by ``run(record_to=...)``.
STREAM_KIND = "discsim event log"
#: Records per chunk that :func:`iter_events` hands out at most by default (89 bytes each: 5.8 MB).
DEFAULT_CHUNK = 65_536


def stream_header(
    discs: Discs,
    box: Box,
    start_time: float,
    run_id: str,
    base: int,
    ids: np.ndarray | None = None,
    gravity=None,
    resting=None,
    drag: float = 0.0,
    sensors=(),
    segments=(),
) -> tuple[dict, dict]:
    """Header ``(meta, arrays)`` of a streamed event log: the discs at ``start_time`` and the box.

    Args:
        discs: the discs' state at ``start_time`` (where the log starts).
        box: the box. start_time: simulated time of ``discs``.
        run_id: identifies the run, so that a resumed run appends only to its own log.
        base: physical events the run had processed before the log starts.
        ids: ``(N,)`` the discs' ids (``sim.ids``), stored only when given (None: their indices).
        gravity: the run's ``(gx, gy)``, stored when given: a replay of the log then follows the parabolas
            between records (and each disc's rest).
        resting: ``(N,)`` bool, the discs at rest at ``start_time`` (under gravity), stored when any is: a log
            started in the middle of a run replays them at rest until their next record.
        drag: the run's drag ``gamma``, stored when not 0: replays (free flight and parabolas only) refuse the log
            then, naming it.
        sensors: the run's :class:`~discsim.sensors.Sensor` s, stored when any as rows ``[code, a0, a1, a2, a3]``
            (as checkpoints store them), so that a viewer of the log alone draws them.
        segments: the run's :class:`~discsim.model.Segment` s, stored when any as rows (:func:`segment_rows`),
            so that a viewer of the log alone draws them where they are (a moving one with its velocity).
    """
    meta = {
        "kind": STREAM_KIND,
        "run_id": run_id,
        "start_time": float(start_time),
        "base": int(base),
        "n": len(discs),
        "box": box.as_dict(),
    }
    if gravity is not None:
        meta["gravity"] = [float(gravity[0]), float(gravity[1])]
    if drag:
        meta["drag"] = float(drag)
    if len(sensors):
        meta["sensors"] = [[sensor.code, *sensor.params.tolist()] for sensor in sensors]
    if len(segments):
        meta["segments"] = segment_rows(segments)
    arrays = {
        "positions": discs.positions,
        "velocities": discs.velocities,
        "radii": discs.radii,
        "masses": discs.masses,
        "groups": discs.groups,
    }
    if ids is not None:
        arrays["ids"] = np.asarray(ids, dtype=np.int64)
    if gravity is not None and resting is not None and np.any(resting):
        arrays["resting"] = np.asarray(resting, dtype=bool)
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
        ids: ``(N,)`` the ids of ``discs`` (the names the records give them), or None: their indices.
        gravity: the run's ``(gx, gy)`` if it ran under gravity (:meth:`trajectory` follows its parabolas), else None.
        resting: ``(N,)`` bool, the ``discs`` at rest at ``start_time`` (under gravity), or None: none.
        drag: the run's drag ``gamma`` (0: none; :meth:`trajectory` follows its exponential flights).
        sensors: the run's :class:`~discsim.sensors.Sensor` s, if its header holds them (else ``()``).
        segments: the run's :class:`~discsim.model.Segment` s (with their velocities), if its header holds them
            (else ``()``).
    """

    events: np.ndarray
    discs: Discs
    box: Box
    start_time: float
    end_time: float
    run_id: str
    ids: np.ndarray | None = None
    gravity: tuple | None = None
    resting: np.ndarray | None = None
    drag: float = 0.0
    sensors: tuple = ()
    segments: tuple = ()

    def trajectory(self, times, *, unwrapped: bool = False) -> np.ndarray:
        """Exact positions ``(T, M, 2)`` at ``times`` ``(T,)`` in ``[start_time, end_time]``, one column per disc id.

        ``unwrapped=True`` follows each disc across the edges of a periodic box. Without added or removed
        discs (``add_discs``, ``remove_discs``) ``M = N``; else see ``Engine.trajectory``: NaN where a disc
        was not there.

        Raises:
            TimeError: if a time is not finite or lies outside the logged span.
        """
        return positions_from_log(
            self.events,
            self.discs,
            self.box,
            self.start_time,
            self.end_time,
            times,
            span="logged span",
            unwrapped=unwrapped,
            ids=self.ids,
            gravity=self.gravity,
            still=self.resting,
            drag=self.drag,
        )


def read_events(path, *, partial: bool = False) -> StreamedEvents:
    """Read an event log written by ``run(record_to=path)`` (either engine).

    Every chunk's checksum is verified. The whole log is loaded into memory
    (89 bytes per event): :func:`iter_events` reads a large one chunk by chunk.

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
    discs, box, start_time, run_id, ids = _header(path, stream.meta, stream.arrays)
    if stream.records.dtype != EVENT_DTYPE:
        msg = f"{path}: records of dtype {stream.records.dtype}, expected the event dtype"
        raise CheckpointError(msg)
    end_time = float(stream.last.get("time", start_time))
    gravity = stream.meta.get("gravity")
    return StreamedEvents(
        stream.records,
        discs,
        box,
        start_time,
        end_time,
        run_id,
        ids,
        None if gravity is None else tuple(gravity),
        _resting(path, stream.arrays, len(discs)),
        float(stream.meta.get("drag", 0.0)),
        sensors_from_rows(stream.meta.get("sensors"), path),
        segments_from_rows(stream.meta.get("segments"), path),
    )


def sensors_from_rows(rows, where) -> tuple[Sensor, ...]:
    """The :class:`~discsim.sensors.Sensor` s stored as rows ``[code, a0, a1, a2, a3]`` (None: none), checked.

    Args:
        rows: the rows of an event log's header or a checkpoint's scene (``(S, 5)``: shape code, then
            :attr:`~discsim.sensors.Sensor.params`).
        where: the file they come from, named in the error.

    Raises:
        CheckpointError: naming the file and the first row that is not a valid sensor.
    """
    sensors = []
    for k, row in enumerate(rows or ()):
        try:
            code, a0, a1, a2, a3 = (float(x) for x in row)
            if code == CIRCLE:
                sensor = Sensor.circle((a0, a1), a2)
            elif code == RECTANGLE:
                sensor = Sensor.rectangle((a0, a1), (a2, a3))
            elif code == LINE:
                sensor = Sensor.line((a0, a1), (a2, a3))
            else:
                msg = f"shape code {code!r} is none of {CIRCLE} (circle), {RECTANGLE} (rectangle), {LINE} (line)"
                raise ValueError(msg)
        except (TypeError, ValueError, DiscsimError) as exc:
            msg = f"{where}: sensors[{k}] = {row!r} is not a sensor ({exc})"
            raise CheckpointError(msg) from exc
        sensors.append(sensor)
    return tuple(sensors)


def segment_rows(segments) -> list[list[float]]:
    """Rows ``[p0x, p0y, p1x, p1y]`` of fixed :class:`~discsim.model.Segment` s and ``[p0x, p0y, p1x, p1y, vx, vy]``
    of moving ones (end points at time 0, velocity in length / time), as checkpoints and event-log headers store them.

    Example:
        >>> segment_rows([Segment((0, 0), (1, 0)), Segment((0, 1), (1, 1), velocity=(0, -0.5))])
        [[0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 1.0, 1.0, 0.0, -0.5]]
    """
    return [[*s.p0.tolist(), *s.p1.tolist(), *(s.velocity.tolist() if s.moving else [])] for s in segments]


def segment_past_rows(segment: Segment) -> list[list[float]]:
    """Rows ``[until, p0x, p0y, p1x, p1y, vx, vy]``: the motions a steered segment had before each steer, earliest
    first (:meth:`~discsim.model.Segment.pieces`; end points at time 0, as :func:`segment_rows` holds them)."""
    return [
        [until, *piece.p0.tolist(), *piece.p1.tolist(), *piece.velocity.tolist()] for until, piece in segment.pieces()
    ]


def segments_from_rows(rows, where, past=None) -> tuple[Segment, ...]:
    """The :class:`~discsim.model.Segment` s stored as :func:`segment_rows` (None: none), checked.

    Args:
        rows: the rows of an event log's header or a checkpoint's scene (4 numbers a fixed segment, 6 a moving one).
        where: the file they come from, named in the error.
        past: for each segment, its :func:`segment_past_rows` (None: none steered): a steered one is rebuilt with
            its earlier motions, and must come out as its row says.

    Raises:
        CheckpointError: naming the file and the first row that is not a valid segment.
    """
    segments = []
    for k, row in enumerate(rows or ()):
        try:
            values = [float(x) for x in row]
            if len(values) not in (4, 6):
                msg = f"{len(values)} numbers, expected 4 (p0, p1) or 6 (p0, p1, velocity)"
                raise ValueError(msg)
            segment = Segment(values[:2], values[2:4], values[4:6] if len(values) == 6 else (0.0, 0.0))
            segments.append(_with_past(segment, past[k] if past else ()))
        except (TypeError, ValueError, IndexError, DiscsimError) as exc:
            msg = f"{where}: segments[{k}] = {row!r} is not a segment ({exc})"
            raise CheckpointError(msg) from exc
    return tuple(segments)


def _with_past(segment: Segment, rows) -> Segment:
    """``segment`` with the earlier motions ``rows`` (:func:`segment_past_rows`) replayed through
    :meth:`~discsim.model.Segment.steered`, as the run steered it (the same arithmetic: the same end points)."""
    if not rows:
        return segment
    rows = [[float(x) for x in row] for row in rows]
    if any(len(row) != 7 for row in rows):
        msg = f"its earlier motions {rows!r} are not rows of 7 numbers (until, p0, p1, velocity)"
        raise ValueError(msg)
    steered = Segment(rows[0][1:3], rows[0][3:5], rows[0][5:7])
    for row, later in zip(rows, [*(row[5:7] for row in rows[1:]), segment.velocity]):
        steered = steered.steered(row[0], later)
    if not (np.array_equal(steered.p0, segment.p0) and np.array_equal(steered.p1, segment.p1)):
        msg = f"its earlier motions {rows!r} do not lead to where it is"
        raise ValueError(msg)
    return steered


def _resting(path, arrays, n: int) -> np.ndarray | None:
    """The header's ``resting`` ``(N,)`` bool (None: absent, no disc at rest where the log starts), checked."""
    resting = arrays.get("resting")
    if resting is None:
        return None
    if np.shape(resting) != (n,):
        msg = f"{path}: the event log's header has resting of shape {np.shape(resting)} for {n} discs"
        raise CheckpointError(msg)
    return np.asarray(resting, dtype=bool)


def _header(path, meta, arrays) -> tuple[Discs, Box, float, str, np.ndarray | None]:
    """``(discs, box, start_time, run_id, ids)`` of an event log's header, checked."""
    if not isinstance(meta, dict) or meta.get("kind") != STREAM_KIND:
        msg = f"{path}: a discsim record stream, but not an event log"
        raise CheckpointError(msg)
    try:
        box = Box(**meta["box"])
        discs = Discs(arrays["positions"], arrays["velocities"], arrays["radii"], arrays["masses"], arrays["groups"])
        start_time = float(meta["start_time"])
        run_id = str(meta["run_id"])
        ids = arrays.get("ids")
        if ids is not None and np.shape(ids) != (len(discs),):
            msg = f"ids of shape {np.shape(ids)} for {len(discs)} discs"
            raise TypeError(msg)
    except (KeyError, TypeError, DiscsimError) as exc:
        msg = f"{path}: the event log's header is incomplete or invalid ({exc})"
        raise CheckpointError(msg) from exc
    return discs, box, start_time, run_id, ids


@dataclass(frozen=True)
class EventChunk:
    """A slice of an event log, with where the log stood before it (yielded by :func:`iter_events`).

    Attributes:
        records: ``(R,)`` structured array of :data:`EVENT_DTYPE`, in time order.
        before: a :class:`~discsim.trajectory.LastRecords`: each disc id's last record before ``records``
            (its time ``(M,)``, position and velocity ``(M, 2)`` just after it, radius, mass and group
            ``(M,)``; NaN for a disc not there), from which ``records`` go on exactly.
        first: the index in the whole log of ``records[0]``.
    """

    records: np.ndarray
    before: LastRecords
    first: int


@dataclass(frozen=True)
class EventChunks:
    """An event log on disk, read chunk by chunk: iterate over it for :class:`EventChunk` s (see :func:`iter_events`).

    Attributes:
        path: the log file. discs: the discs where the log starts (ids ``ids``, None: their indices).
        box: the box. start_time, end_time: the span the log covers. run_id: the run that wrote it.
        records: the number of records in the log (known from its index, before reading them).
        chunk: records per chunk at most. start: the time the chunks start from (None: the log's start).
        unwrapped: the ``before`` positions are unwrapped (periodic box).
        gravity: the run's ``(gx, gy)`` from the header (None: free flight), which the unwrapped ``before``
            positions follow between records. resting: ``(N,)`` bool, the ``discs`` at rest where the log starts
            (None: none). sensors: the run's :class:`~discsim.sensors.Sensor` s, if the header holds them.
        segments: the run's :class:`~discsim.model.Segment` s (with their velocities), if the header holds them.
    """

    path: Path
    discs: Discs
    ids: np.ndarray | None
    box: Box
    start_time: float
    end_time: float
    run_id: str
    records: int
    chunk: int
    start: float | None
    unwrapped: bool
    partial: bool
    gravity: tuple | None = None
    resting: np.ndarray | None = None
    sensors: tuple = ()
    segments: tuple = ()

    def __iter__(self) -> Iterator[EventChunk]:
        carry = LastRecords.at_start(self.discs, self.start_time, self.ids, self.resting)
        walk = iter_stream(self.path, partial=self.partial)
        next(walk)  # the header
        start = -np.inf if self.start is None else self.start
        first = 0
        for _meta, _arrays, records, _end in walk:
            if records.dtype != EVENT_DTYPE:
                msg = f"{self.path}: records of dtype {records.dtype}, expected the event dtype"
                raise CheckpointError(msg)
            if len(records) and records["time"].max() < start:  # wholly before the start: only where it leaves discs
                carry = carry.after(records, self.box, unwrapped=self.unwrapped, gravity=self.gravity)
                first += len(records)
                continue
            skip = int(np.count_nonzero(records["time"] < start)) if self.start is not None else 0
            if skip:
                carry = carry.after(records[:skip], self.box, unwrapped=self.unwrapped, gravity=self.gravity)
            for at in range(skip, len(records), self.chunk):
                piece = records[at : at + self.chunk]
                yield EventChunk(piece, carry, first + at)
                carry = carry.after(piece, self.box, unwrapped=self.unwrapped, gravity=self.gravity)
            first += len(records)

    def record_arrays(self) -> Iterator[np.ndarray]:
        """The records alone, chunk by chunk from the log's start (no ``before`` states: faster)."""
        walk = iter_stream(self.path, partial=self.partial)
        next(walk)
        for _meta, _arrays, records, _end in walk:
            for at in range(0, len(records), self.chunk):
                yield records[at : at + self.chunk]


def iter_events(
    path, *, chunk: int = DEFAULT_CHUNK, start: float | None = None, unwrapped: bool = False, partial: bool = False
) -> EventChunks:
    """Read an event log written by ``run(record_to=path)`` chunk by chunk: memory flat in the log's length.

    Where :func:`read_events` loads the whole log (89 bytes an event), this holds one chunk of the file and
    each disc's last record (about 80 bytes a disc). Each :class:`EventChunk` carries ``records`` ``(R,)``
    (``R <= chunk``) and ``before``, where every disc stood before them, so any chunk can be replayed on
    its own (:func:`discsim.trajectory.replay`). The header (box, span, number of records) is read at once,
    from the file's index; the chunks, with their checksums, as they are iterated (again on each iteration).

    Args:
        path: the log file.
        chunk: records per chunk at most (the file's own chunks are cut to this size).
        start: begin with the records at or after this time: those before are read, to know where each disc
            stood, but not handed out (the log is in time order).
        unwrapped: keep ``before``'s positions unwrapped (continuous across periodic edges since the log's start).
        partial: accept an incomplete last chunk (a run killed while writing it).

    Returns:
        An :class:`EventChunks`: iterate over it for the chunks.

    Raises:
        FileNotFoundError: if there is no such file.
        InvalidArgumentError: for a ``chunk`` that is not a positive integer, or a ``start`` that is not a
            finite time.
        CheckpointError: see :func:`read_events` (a damaged chunk when it is reached).

    Example:
        >>> import os, tempfile, discsim as ds
        >>> path = os.path.join(tempfile.mkdtemp(), "events.dse")
        >>> sim = ds.EventDriven(*ds.random_gas(20, 0.3, seed=1), record=False).run(until=2.0, record_to=path)
        >>> log = ds.iter_events(path, chunk=100)
        >>> sizes = [len(c.records) for c in log]
        >>> max(sizes) <= 100, sum(sizes) == log.records, log.end_time
        (True, True, 2.0)
        >>> late = next(iter(ds.iter_events(path, start=1.5)))
        >>> bool(late.records["time"][0] >= 1.5), late.before.positions.shape
        (True, (20, 2))
    """
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        msg = f"chunk must be a positive integer (records per chunk), got {chunk!r}"
        raise InvalidArgumentError(msg)
    if start is not None and not (isinstance(start, (int, float, np.number)) and np.isfinite(start)):
        msg = f"start must be a finite time or None, got {start!r}"
        raise InvalidArgumentError(msg)
    path = Path(path)
    meta, arrays, chunks = stream_index(path, partial=partial)
    discs, box, start_time, run_id, ids = _header(path, meta, arrays)
    end_time = float(chunks[-1].get("time", start_time)) if chunks else start_time
    total = sum(int(c.get("count", 0)) for c in chunks)
    start = None if start is None else float(start)
    gravity = meta.get("gravity")
    return EventChunks(
        path,
        discs,
        ids,
        box,
        start_time,
        end_time,
        run_id,
        total,
        int(chunk),
        start,
        unwrapped,
        partial,
        None if gravity is None else (float(gravity[0]), float(gravity[1])),
        _resting(path, arrays, len(discs)),
        sensors_from_rows(meta.get("sensors"), path),
        segments_from_rows(meta.get("segments"), path),
    )


def trajectory_from_events(source, times, *, unwrapped: bool = False) -> np.ndarray:
    """Exact positions ``(T, N, 2)`` at ``times`` ``(T,)`` from a streamed event log.

    Args:
        source: a path to a log written by ``run(record_to=...)``, or a
            :class:`StreamedEvents` already read by :func:`read_events`.
        times: times within the logged span ``[start_time, end_time]``.
        unwrapped: follow each disc across the edges of a periodic box.

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
    if isinstance(source, StreamedEvents):
        return source.trajectory(times, unwrapped=unwrapped)
    meta = stream_index(Path(source))[0]
    gravity = flight(meta.get("gravity"), meta.get("drag", 0.0), what=f"the replay of {str(source)!r}")
    log = iter_events(Path(source), unwrapped=unwrapped)
    times = check_times(times, log.start_time, log.end_time, "logged span")
    origin = LastRecords.at_start(log.discs, log.start_time, log.ids, log.resting)
    return replay(log.record_arrays(), origin, times, log.box, unwrapped=unwrapped, gravity=gravity)
