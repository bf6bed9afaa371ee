"""Observers of a run: what happens between the chunks of the engine's loop.

The driver (:func:`discsim.run.driver.drive`) serves each observer in turn after every chunk. Four come
ready: :class:`ProgressBar`, :class:`EventStream` (the log to disk), :class:`Checkpointer` and
:class:`Callback` (a user function). A user observer subclasses :class:`Observer` and overrides what it
needs; it sees the engine only through its public protocol.

Example:
    >>> import discsim as ds
    >>> seen = []
    >>> sim = ds.EventDriven(*ds.random_gas(30, 0.3, seed=1), record=False)
    >>> _ = sim.run(events=50, observers=[ds.Callback(lambda sim, events: seen.append(len(events)), every=20)])
    >>> seen
    [20, 20, 10]
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path

import numpy as np

from discsim._validate import is_count
from discsim.errors import CheckpointError, InvalidArgumentError
from discsim.events import EVENT_DTYPE
from discsim.io.checkpoints import write_checkpoint
from discsim.io.container import RecordWriter, read_state
from discsim.io.streams import stream_header
from discsim.run.progress import progress_bar

__all__ = ["Callback", "Checkpointer", "EventStream", "Observer", "ProgressBar"]


class Observer:
    """Base class of run observers. Every method does nothing unless overridden.

    Attributes:
        wants_events (bool): if True, :meth:`update` receives each chunk's
            events, and the engine records them meanwhile even with ``record=False``.
    """

    wants_events = False

    def check(self, engine, plan) -> None:
        """Refuse the run (raise) before anything has changed; ``plan`` is the :class:`~discsim.run.driver.RunPlan`."""

    def start(self, engine, plan) -> None:
        """The run starts."""

    def next_stop(self, engine) -> int | None:
        """Units of work (events or frames) until this observer wants :meth:`update` again; None: any time."""
        return None

    def update(self, engine, events: np.ndarray | None, done: int, finishing: bool) -> None:
        """After a chunk of ``done`` units; ``events`` is the chunk's log (if :attr:`wants_events`)."""

    def finish(self, engine, completed: bool) -> None:
        """The run ends: ``completed`` is False when an exception (Ctrl-C included) stopped it."""

    def undo_start(self) -> None:
        """Undo what :meth:`start` left behind (a new file), when another observer's start failed."""


class Callback(Observer):
    """Calls ``fn(engine, events)`` after every chunk of at most ``every`` units of work.

    ``events`` is the chunk's events, a structured array of :data:`~discsim.events.EVENT_DTYPE`;
    ``every=1`` calls it after each event (or frame) with the engine at that moment. The last call
    sees the engine at the end of the run (its chunk may be empty).

    Args:
        fn: the function.
        every: units of work per call at most (None: as the other observers chunk the run,
            20,000 events or 1,000 frames at the most).
    """

    wants_events = True

    def __init__(self, fn, every: int | None = None):
        if not callable(fn):
            msg = f"Callback needs a callable fn(engine, events), got {type(fn).__name__}"
            raise InvalidArgumentError(msg)
        if every is not None and (not is_count(every) or every == 0):
            msg = f"every must be a positive integer, got {every!r}"
            raise InvalidArgumentError(msg)
        self.fn = fn
        self.every = None if every is None else int(every)

    def next_stop(self, engine) -> int:
        return self.every if self.every is not None else engine.progress_chunk

    def update(self, engine, events, done, finishing) -> None:
        if len(events) or done or finishing:  # the last call sees the engine at the run's end
            self.fn(engine, events)


class ProgressBar(Observer):
    """A progress bar over simulated time (runs with ``until`` only) or units of work, with a rate.

    What it measures is the engine's (``engine._progress(plan)``): a compression shows its packing.
    """

    def start(self, engine, plan) -> None:
        self._plan = plan
        self._at, total, by_time, unit = engine._progress(plan)
        self._context = progress_bar(total, by_time, unit=unit, rate=engine.rate_count)
        self._bar = self._context.__enter__()
        self._bar.start(engine.counts[engine.rate_count])

    def next_stop(self, engine) -> int:
        return engine.progress_chunk

    def update(self, engine, events, done, finishing) -> None:
        at = engine._progress(self._plan)[0]
        self._bar.update(at - self._at, engine.counts[engine.rate_count])
        self._at = at

    def finish(self, engine, completed) -> None:
        self._context.__exit__(None, None, None)


class EventStream(Observer):
    """Streams the event log to ``path`` in chunks of ``engine.stream_chunk`` events; memory stays flat.

    A new file starts with the discs where its log starts (the start of the run if the engine's log in
    memory covers it, else the current state). The engine's own log file (after a resume, or a second
    ``run`` call) is continued; any other existing file is refused. Read it with
    :func:`discsim.read_events`.
    """

    wants_events = True

    def __init__(self, path: str | PathLike[str]) -> None:
        self.path = Path(path)
        self._writer: RecordWriter | None = None  # opened by start(); flush, sync and finish come after it
        self._pending: list[np.ndarray] = []
        self._held = 0
        self._created = False
        self._time: float | None = None  # the engine's time after the last chunk handed over

    def check(self, engine, plan) -> None:
        context = engine.run_context
        stream, logged = context.stream, engine._event_count()
        if not self.path.parent.is_dir():
            msg = f"cannot write the event log record_to={str(self.path)!r}: no folder {self.path.parent}"
            raise FileNotFoundError(msg)
        if not self.path.exists():
            if stream is not None and Path(stream["path"]) == self.path.absolute():
                msg = (
                    f"{self.path}: this run's event log is missing (moved or deleted); pass its new place "
                    "(resume(..., record_to=...)), or stream to another file to start a new log"
                )
                raise CheckpointError(msg)
            return
        if stream is None:
            msg = (
                f"{self.path} already exists and is not this run's event log; discsim will not overwrite it "
                "(choose another path or remove the file)"
            )
            raise CheckpointError(msg)
        missed = logged - stream["base"] - stream["records"] - len(context.log)
        if missed:
            why = (
                f"writing them failed: {stream['write_error']}"
                if stream.get("write_error")
                else "they ran without record_to and record=False"
            )
            msg = (
                f"{self.path}: the log on disk stops {missed} events before the engine ({why}); continue from "
                "the last checkpoint (discsim.resume), or stream to a new file"
            )
            raise CheckpointError(msg)
        # Opening checks the file's own header against this run (a foreign or damaged file is refused).
        RecordWriter.reopen(
            self.path, stream["records"], stream["end"], expect={"run_id": stream["run_id"], "base": stream["base"]}
        ).close()

    def start(self, engine, plan) -> None:
        context = engine.run_context
        stream, logged = context.stream, engine._event_count()
        if stream is not None and self.path.exists():
            self._writer = RecordWriter.reopen(  # check() has just verified every chunk
                self.path,
                stream["records"],
                stream["end"],
                expect={"run_id": stream["run_id"], "base": stream["base"]},
                verify=False,
            )
            context.stream = {**stream, "path": str(self.path.absolute())}
            self._hold(context.log.since(0))  # recorded since the last flush
            return
        from_start = stream is None and len(context.log) == logged  # the log in memory covers the whole run
        if from_start:
            (discs, ids), start, base = context.log_origin(engine.discs), engine.start_time, 0
            self._hold(context.log.since(0))
        else:  # earlier events stay out of this file
            discs, ids, start, base = engine.snapshot(), context.ids, engine.time, logged
        run_id = context.ensure_run_id()
        laws = getattr(engine, "laws", None)
        gravity = laws.gravity if laws is not None and laws.falls else None
        resting = None if from_start else getattr(engine, "resting", None)  # a log from mid-run: who rests then
        drag = laws.drag if laws is not None else 0.0
        sensors = getattr(engine, "sensors", ())
        segments = getattr(engine, "segments", ())
        meta, arrays = stream_header(
            discs, engine.box, start, run_id, base, ids, gravity, resting, drag, sensors, segments
        )
        self._writer = RecordWriter.create(self.path, EVENT_DTYPE, meta, arrays)
        self._created = True
        context.stream = {
            "path": str(self.path.absolute()),
            "run_id": run_id,
            "base": base,
            "records": 0,
            "end": self._writer.end,
        }

    def _hold(self, events: np.ndarray) -> None:
        if len(events):
            self._pending.append(events)
            self._held += len(events)

    def next_stop(self, engine) -> int:
        return engine.stream_chunk - self._held

    def update(self, engine, events, done, finishing) -> None:
        self._hold(events)
        self._time = engine.time
        if self._held >= engine.stream_chunk:
            self.flush(engine)

    def flush(self, engine) -> None:
        """Write the events held as one chunk, stamped with the time it covers up to."""
        context, writer = engine.run_context, self._writer
        assert writer is not None, "start() opens the writer"
        records = np.concatenate(self._pending) if self._pending else np.zeros(0, dtype=EVENT_DTYPE)
        self._pending, self._held = [], 0
        try:
            writer.append(records, {"time": engine.time if self._time is None else self._time})
        except OSError as exc:  # a full disk, say: these events are lost to the log; say so if asked again
            context.stream = {**context.stream, "write_error": f"{type(exc).__name__}: {exc}"}
            raise
        context.stream = {**context.stream, "records": writer.records, "end": writer.end}

    def sync(self) -> None:
        """Force what was written to disk."""
        assert self._writer is not None, "start() opens the writer"
        self._writer.sync()

    def finish(self, engine, completed) -> None:
        try:
            if completed or self._held:  # the chunks handed over were processed whole: keep them
                self.flush(engine)
        finally:
            assert self._writer is not None, "start() opens the writer"
            self._writer.close()

    def undo_start(self) -> None:
        if self._created:
            self.path.unlink(missing_ok=True)


class Checkpointer(Observer):
    """Writes the whole state to ``path`` when the run starts, every ``every`` units of work, and at the end.

    A file already there must be a checkpoint of this same run (it is then replaced); anything else is
    refused. After a crash, :func:`discsim.resume` continues from the last checkpoint to the same final
    state, bit for bit. A streamed log is synced before each checkpoint, so a checkpoint never refers past it.
    """

    def __init__(self, path, every: int | None = None, stream: EventStream | None = None):
        if every is not None and (not is_count(every) or every == 0):
            msg = f"checkpoint_every must be a positive integer, got {every!r}"
            raise InvalidArgumentError(msg)
        self.path = Path(path)
        self.every = every
        self.stream = stream
        self._since = 0
        self._created = False

    def check(self, engine, plan) -> None:
        if not self.path.parent.is_dir():
            msg = f"cannot write the checkpoint {self.path}: no folder {self.path.parent}"
            raise FileNotFoundError(msg)
        if self.path.exists():
            meta, _ = read_state(self.path)
            run_id = engine.run_context.run_id
            if run_id is None or meta.get("run_id") != run_id:
                msg = (
                    f"{self.path} holds a checkpoint of another run; discsim will not overwrite it "
                    "(choose another path, or resume that run with discsim.resume)"
                )
                raise CheckpointError(msg)

    def start(self, engine, plan) -> None:
        self._plan = plan
        self._created = not self.path.exists()
        self._write(engine, finished=False)

    def undo_start(self) -> None:
        if self._created:
            self.path.unlink(missing_ok=True)

    def next_stop(self, engine) -> int | None:
        return None if self.every is None else self.every - self._since

    def update(self, engine, events, done, finishing) -> None:
        self._since += done
        if self.every is not None and self._since >= self.every and not finishing:  # else the final one
            self._write(engine, finished=False)
            self._since = 0

    def finish(self, engine, completed) -> None:
        if completed:
            self._write(engine, finished=True)

    def _write(self, engine, finished: bool) -> None:
        if self.stream is not None:
            self.stream.flush(engine)
            self.stream.sync()
        write_checkpoint(engine, self.path, run=self._plan.target(finished), record=self._plan.record)
