"""Event logs streamed to disk by a run: the header, and reading them back.

A log is a record stream of :mod:`discsim.io.container` whose header holds the discs where the log starts and
the box, and whose records are :data:`~discsim.events.EVENT_DTYPE` rows.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from discsim.errors import CheckpointError, DiscsimError
from discsim.events import EVENT_DTYPE
from discsim.io.container import read_stream
from discsim.model import Box, Discs
from discsim.trajectory import positions_from_log

__all__ = ["STREAM_KIND", "StreamedEvents", "read_events", "stream_header", "trajectory_from_events"]

#: ``kind`` in the header of an event log written by ``run(record_to=...)``.
STREAM_KIND = "discsim event log"


def stream_header(
    discs: Discs, box: Box, start_time: float, run_id: str, base: int, ids: np.ndarray | None = None
) -> tuple[dict, dict]:
    """Header ``(meta, arrays)`` of a streamed event log: the discs at ``start_time`` and the box.

    Args:
        discs: the discs' state at ``start_time`` (where the log starts).
        box: the box. start_time: simulated time of ``discs``.
        run_id: identifies the run, so that a resumed run appends only to its own log.
        base: physical events the run had processed before the log starts.
        ids: ``(N,)`` the discs' ids (``sim.ids``), stored only when given (None: their indices).
    """
    meta = {
        "kind": STREAM_KIND,
        "run_id": run_id,
        "start_time": float(start_time),
        "base": int(base),
        "n": len(discs),
        "box": box.as_dict(),
    }
    arrays = {
        "positions": discs.positions,
        "velocities": discs.velocities,
        "radii": discs.radii,
        "masses": discs.masses,
        "groups": discs.groups,
    }
    if ids is not None:
        arrays["ids"] = np.asarray(ids, dtype=np.int64)
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
    """

    events: np.ndarray
    discs: Discs
    box: Box
    start_time: float
    end_time: float
    run_id: str
    ids: np.ndarray | None = None

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
        )


def read_events(path, *, partial: bool = False) -> StreamedEvents:
    """Read an event log written by ``run(record_to=path)`` (either engine).

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
        ids = arrays.get("ids")
        if ids is not None and np.shape(ids) != (len(discs),):
            msg = f"ids of shape {np.shape(ids)} for {len(discs)} discs"
            raise TypeError(msg)
    except (KeyError, TypeError, DiscsimError) as exc:
        msg = f"{path}: the event log's header is incomplete or invalid ({exc})"
        raise CheckpointError(msg) from exc
    return StreamedEvents(stream.records, discs, box, start_time, end_time, run_id, ids)


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
    log = source if isinstance(source, StreamedEvents) else read_events(Path(source))
    return log.trajectory(times, unwrapped=unwrapped)
