"""The one run driver: ``run(until=..., events=..., observers=[...])`` for every engine.

The driver checks the limits once, asks the engine for work in chunks (``engine._advance``), and between
chunks serves the observers: the progress bar, the event stream, the
checkpointer and any user callback (:mod:`discsim.run.observers`). With no observer, a run is one call of
the engine's loop. Chunks change nothing in the dynamics: the engine resumes exactly where it stopped.

"No limit" has one spelling past the public edge (:func:`run_limits`): a stop time is a float, ``math.inf``
for none, and a count is an int, ``None`` for none. That is what ``engine._advance(until, limit)`` gets;
users (``run(until=None)``) and observers (:attr:`RunPlan.until`) see ``None`` for no stop time.

``Engine.run`` is :func:`run_engine`, handed down to the engines when this module is imported
(:func:`discsim.engines.base.provide`): the engines never import the driver.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from discsim._interrupt import interrupted_outside_the_loop
from discsim._validate import check_count, check_until, is_count
from discsim.engines.base import provide
from discsim.errors import Interrupted, InvalidArgumentError, TimeError
from discsim.run.handlers import EventHandlers
from discsim.run.observers import Callback, Checkpointer, EventStream, Observer, ProgressBar

__all__ = ["RunPlan", "drive", "run_engine", "run_limits"]


@dataclass(frozen=True)
class RunPlan:
    """What a run was asked to do, as observers see it.

    Attributes:
        until: stop time, or None (no stop time). limit: units of work to do, or None (no count).
        unit: what a unit is ("events" or "frames").
        start_time: the engine's time when the run started.
        start_units: units of work done before the run (``engine._units()``).
        record: the engine's own ``record`` setting (a run with observers may record meanwhile).
        checkpoint_every: units between checkpoints, or None.
        record_to: the streamed log's absolute path, or None.
    """

    until: float | None
    limit: int | None
    unit: str
    start_time: float
    start_units: int
    record: bool
    checkpoint_every: int | None = None
    record_to: str | None = None

    @property
    def stop(self) -> float:
        """The stop time as the engine takes it: ``until``, or ``math.inf`` for none."""
        return math.inf if self.until is None else self.until

    def target(self, finished: bool) -> dict:
        """The run's goal as a checkpoint stores it: ``until``, total ``events``, ``finished``, ..."""
        return {
            "until": self.until,
            "events": None if self.limit is None else self.start_units + self.limit,
            "checkpoint_every": self.checkpoint_every,
            "record_to": self.record_to,
            "finished": finished,
        }


def run_engine(
    engine,
    until=None,
    *,
    events=None,
    observers=(),
    progress: bool = False,
    record_to=None,
    checkpoint=None,
    checkpoint_every=None,
) -> int:
    """``engine.run(...)``: :func:`drive`, with the engine's ``sim.on(...)`` callbacks as one more observer.

    Returns the units of work done.
    """
    handlers = engine.run_context.handlers
    if handlers:  # sim.on(...): one event (or frame) at a time, callbacks after each
        observers = [*(observers or ()), EventHandlers(handlers)]
    return drive(
        engine,
        until=until,
        limit=events,
        observers=observers,
        progress=progress,
        record_to=record_to,
        checkpoint=checkpoint,
        checkpoint_every=checkpoint_every,
    )


def drive(
    engine,
    *,
    until=None,
    limit=None,
    observers=(),
    progress: bool = False,
    record_to=None,
    checkpoint=None,
    checkpoint_every=None,
) -> int:
    """Run ``engine`` up to time ``until`` and/or for ``limit`` units of work; return the units done.

    Args:
        engine: any discsim engine (:class:`~discsim.engines.base.Engine`).
        until: stop time; events (or frames) at exactly ``until`` are done, and
            ``time`` is ``until`` at the end (unless ``limit`` stopped the run first).
        limit: units of work (physical events for ``EventDriven``, frames for
            ``FixedStep``); None for no limit.
        observers: :class:`~discsim.run.observers.Observer` objects, or plain
            callables ``fn(engine, events)`` called after each chunk with the
            chunk's events (a structured array of :data:`~discsim.events.EVENT_DTYPE`).
        progress: show a progress bar (tqdm when installed).
        record_to: stream the event log to this file (see :class:`~discsim.run.observers.EventStream`).
        checkpoint: write checkpoints to this file (see :class:`~discsim.run.observers.Checkpointer`).
        checkpoint_every: units of work between checkpoints (needs ``checkpoint``).

    Raises:
        TimeError: if ``until`` is before ``time``, NaN, or infinite without ``limit``.
        InvalidArgumentError: if neither limit is given, or a count is not a whole number.
        CheckpointError: if ``record_to`` or ``checkpoint`` names a foreign or damaged file.
            Nothing has been simulated then.
    """
    engine._check_can_advance()  # also refuses a run from inside a run (an observer or a callback)
    unit = engine.unit
    stop, limit = run_limits(until, limit, engine.time, unit, ends=engine.runs_to_end)
    if checkpoint_every is not None and (not is_count(checkpoint_every) or checkpoint_every == 0):
        msg = f"checkpoint_every must be a positive integer ({unit}), got {checkpoint_every!r}"
        raise InvalidArgumentError(msg)
    every = None if checkpoint_every is None else int(checkpoint_every)
    if every is not None and checkpoint is None:
        msg = "checkpoint_every needs checkpoint=path"
        raise InvalidArgumentError(msg)
    chain = _observers(observers, progress, record_to, checkpoint, every)
    if not chain:
        done = engine._advance(stop, limit)
        if stop != math.inf and done != limit:  # stopped by the clock, not by the count
            engine._settle(stop)
        return done
    stream = next((o for o in chain if isinstance(o, EventStream)), None)
    keeper = next((o for o in chain if isinstance(o, Checkpointer)), None)
    plan = RunPlan(
        None if stop == math.inf else stop,
        limit,
        unit,
        engine.time,
        engine._units(),
        engine.record,
        None if keeper is None else keeper.every,
        None if stream is None else str(stream.path.absolute()),
    )
    return _drive_chunks(engine, plan, chain, stream)


def run_limits(until, limit, now: float, unit: str, *, ends: bool = False) -> tuple[float, int | None]:
    """``(stop, limit)`` from ``run(until=..., events=...)``: the one internal spelling of the limits.

    ``stop`` is a float, ``math.inf`` for no stop time (``until`` None, or ``inf`` with a count); ``limit``
    an int >= 0, or None for no count. ``ends``: the engine's work ends by itself
    (``Engine.runs_to_end``), so neither limit means "to the end".

    Raises:
        TimeError: ``until`` before ``now``, NaN or not a number, or infinite without a count.
        InvalidArgumentError: a count that is not a whole number >= 0, or neither limit (unless ``ends``).

    Example:
        >>> run_limits(None, 5, 0.0, "events"), run_limits(2.0, None, 0.0, "events")
        ((inf, 5), (2.0, None))
    """
    until = check_until(until, now)
    limit = check_count(unit, limit)
    if until is None and limit is None and not ends:
        msg = f"run() needs until=... or {unit}=..."
        raise InvalidArgumentError(msg)
    if until == math.inf and limit is None and not ends:
        msg = f"run(until=inf) never ends: give a finite until or {unit}=..."
        raise TimeError(msg)
    return (math.inf if until is None else until), limit


#: The order in which observers are served: the stream takes each chunk before a checkpoint refers to it.
_RANK = {EventStream: 0, Checkpointer: 1}


def _observers(observers, progress, record_to, checkpoint, every) -> list[Observer]:
    """The run's observers in the order they are served: stream, checkpointer, then the rest as given."""
    if observers is None:
        observers = ()
    if isinstance(observers, Observer) or callable(observers) or isinstance(observers, (str, bytes)):
        msg = f"observers must be a list of observers, got {type(observers).__name__}; wrap it: observers=[...]"
        raise InvalidArgumentError(msg)
    chain: list[Observer] = []
    if record_to is not None:
        chain.append(EventStream(record_to))
    if checkpoint is not None:
        chain.append(Checkpointer(checkpoint, every))
    if progress:
        chain.append(ProgressBar())
    for k, observer in enumerate(observers):
        if isinstance(observer, Observer):
            chain.append(observer)
        elif callable(observer):
            chain.append(Callback(observer))
        else:
            msg = f"observers[{k}] must be a discsim Observer or a callable, got {type(observer).__name__}"
            raise InvalidArgumentError(msg)
    chain.sort(key=lambda observer: _RANK.get(type(observer), 2))  # stable: the rest keep their order
    streams = [o for o in chain if isinstance(o, EventStream)]
    keepers = [o for o in chain if isinstance(o, Checkpointer)]
    if len(streams) > 1 or len(keepers) > 1:
        msg = "a run streams to one file and checkpoints to one file at most"
        raise InvalidArgumentError(msg)
    if streams and keepers:
        keepers[0].stream = streams[0]
        if streams[0].path.absolute() == keepers[0].path.absolute():
            msg = f"record_to and checkpoint must be two different files, got {streams[0].path} twice"
            raise InvalidArgumentError(msg)
    return chain


def _drive_chunks(engine, plan: RunPlan, chain: list[Observer], stream) -> int:
    """Run in chunks of the engine's loop, serving ``chain`` between them."""
    for observer in chain:  # every check before anything changes
        observer.check(engine, plan)
    wants_events = any(observer.wants_events for observer in chain)
    keep = engine.record and stream is None  # the log stays in memory (else the stream takes it)
    context = engine.run_context
    log = context.log
    before = (context.stream, context.run_id)
    started: list[Observer] = []
    done = 0
    completed = False
    try:
        context.recording = wants_events  # the loop logs for the observers, whatever record says
        context.serving = True  # step() and run() refused until the end
        try:
            for observer in chain:
                observer.start(engine, plan)
                started.append(observer)
        except BaseException:
            for observer in reversed(started):  # nothing has run: leave no file and no trace behind
                observer.finish(engine, False)
                observer.undo_start()
            context.stream, context.run_id = before
            started = []
            raise
        if not keep:
            log.clear()  # what the stream wanted of it, it has taken
        mark = len(log)
        while True:
            chunk = plan.limit - done if plan.limit is not None else None
            for observer in chain:
                want = observer.next_stop(engine)
                if want is not None:
                    chunk = max(1, want) if chunk is None else min(chunk, max(1, want))
            k = engine._advance(plan.stop, chunk)
            done += k
            finishing = chunk is None or k < chunk or done == plan.limit  # None: the call did it all
            if plan.until is not None and finishing and done != plan.limit:  # stopped by the clock
                engine._settle(plan.until)
            events = log.since(mark) if wants_events else None
            if not keep:
                log.clear()
            mark = len(log)
            units = engine._units()
            try:
                for observer in chain:
                    observer.update(engine, events, k, finishing)
            except Interrupted:
                raise
            except KeyboardInterrupt as exc:  # Ctrl-C in a slow callback: between two whole events, as Interrupted
                raise interrupted_outside_the_loop() from exc
            if engine._units() != units:
                msg = "an observer advanced the engine (step() or run() inside a run); observers may only look"
                raise InvalidArgumentError(msg)
            if finishing:
                break
        completed = True
    finally:
        context.recording = context.serving = False
        for observer in reversed(started):
            observer.finish(engine, completed)
    return done


provide("run", run_engine)
