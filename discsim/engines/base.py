"""What every engine shares: the public protocol, the run state's form, and what is derived from them.

An engine holds a validated :class:`~discsim.scene.Scene` (``discs`` at the start, ``box``, ``segments``,
``pass_through``), its ``time``, ``positions`` and ``velocities``, ``counts`` and an event log. Each engine
implements three small protocols, all here as abstract methods:

- the **driver's** (:mod:`discsim.run.driver`): ``_advance(until, limit)`` does up to ``limit`` units of
  work (physical events, or frames) up to time ``until``, logging each event in ``_log`` when ``record``
  or ``_recording`` (set by the driver while an observer wants events) is on; ``_units()`` counts the
  units, ``_event_count()`` the events the log would hold; ``_settle(until)`` moves the clock to ``until``
  when the run stopped on time;
- the **checkpoint's** (:mod:`discsim.io.checkpoints`): ``state()`` exports the public run state (an
  :class:`EngineState`: numpy arrays and scalars, versioned), ``_settings()`` the constructor's options as
  JSON, and ``_restore(scene, settings, state, events, start_time)`` rebuilds the engine;
- the **user's**: ``step()``, ``positions``, ``velocities``, ``unwrapped_positions``, ``counts``.

Everything else (``run``, ``save``, ``events``, exact ``trajectory``, energies, momentum, ``snapshot``) is
written here once, so ``compare``, ``plot``, notebooks and benchmarks work with any engine and backend.
``run`` and ``save`` hand the engine to the driver and to :mod:`discsim.io`, imported when called: those
layers sit above the engines, which never import them at module level.
"""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from discsim.errors import CheckpointError, DiscsimError, InvalidArgumentError
from discsim.events import EVENT_DTYPE, EventLog
from discsim.model import Box, Discs, kinetic_energy, momentum
from discsim.scene import Scene
from discsim.trajectory import positions_from_log

__all__ = ["Engine", "EngineState"]


class EngineState:
    """Base of the engines' public run states: a dataclass of numpy arrays and plain scalars.

    A state is everything an engine needs to continue bit for bit, in a form any backend, observer or
    file can read: it is what a checkpoint stores and what a backend loads and exports. ``VERSION``
    changes whenever a field's meaning changes.
    """

    VERSION: ClassVar[int] = 1

    def to_arrays(self) -> tuple[dict, dict[str, np.ndarray]]:
        """``(scalars, arrays)``: the JSON-able fields and the numpy fields, by name."""
        scalars, arrays = {}, {}
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            (arrays if isinstance(value, np.ndarray) else scalars)[field.name] = value
        return scalars, arrays

    @classmethod
    def from_arrays(cls, scalars: dict, arrays: dict[str, np.ndarray], version: int):
        """Rebuild a state from :meth:`to_arrays` output written under ``version``.

        Raises:
            CheckpointError: on another version, or a missing or unknown field.
        """
        if version != cls.VERSION:
            msg = f"{cls.__name__} version {version!r} cannot be read (this discsim reads version {cls.VERSION})"
            raise CheckpointError(msg)
        names = {field.name for field in dataclasses.fields(cls)}
        given = {**scalars, **arrays}
        if set(given) != names:
            msg = f"{cls.__name__}: fields missing {sorted(names - set(given))}, unknown {sorted(set(given) - names)}"
            raise CheckpointError(msg)
        return cls(**given)


class Engine(ABC):
    """Base class of discsim engines; see the module docstring for the protocols."""

    #: The name of ``run()``'s count of units of work ("events" or "frames").
    unit: ClassVar[str] = "events"
    #: The counter whose rate a progress bar shows.
    rate_count: ClassVar[str] = "collisions"
    #: Units of work between progress-bar updates.
    progress_chunk: ClassVar[int] = 20_000
    #: Events per chunk of a log streamed by ``run(record_to=...)``; at most this many are held in memory.
    stream_chunk: int = 16_384

    discs: Discs
    box: Box
    time: float

    def __init__(self, scene: Scene, record: bool):
        self.scene = scene
        self.discs = scene.discs
        self.box = scene.box
        self.segments = scene.segments
        self.pass_through = scene.pass_through
        if not isinstance(record, (bool, np.bool_)):  # bool("False") would be True
            msg = f"record must be True or False, got {record!r}"
            raise InvalidArgumentError(msg)
        self.record = bool(record)
        self.start_time = 0.0
        self._log = EventLog()
        self._recording = False  # the driver records for its observers meanwhile, whatever ``record`` says
        self._broken: str | None = None  # why the engine cannot go on (an exception inside its loop)
        self._run_id: str | None = None  # identifies this run in its checkpoints and streamed log
        self._stream: dict | None = None  # this run's log on disk: path, run_id, base, records, end

    # --- the driver's protocol ---------------------------------------------------------
    @abstractmethod
    def _advance(self, until: float, limit: int | None) -> int:
        """Do units of work at times <= ``until`` (may be inf), at most ``limit`` (None: no limit).

        Returns how many were done; fewer than ``limit`` means the run reached ``until`` (or nothing is
        left to do). Leaves ``time`` at the last unit done; the driver then calls :meth:`_settle`.
        """

    @abstractmethod
    def _units(self) -> int:
        """Units of work done since the start (physical events, or frames)."""

    @abstractmethod
    def _event_count(self) -> int:
        """Events the log holds (or would hold if recorded from the start) since the start."""

    @property
    def _logging(self) -> bool:
        """Whether the loop logs events now: ``record``, or an observer of the current run wants them."""
        return self.record or self._recording

    def _check_usable(self) -> None:
        """Refuse to go on after an exception inside the engine's own loop left it half-way through an event.

        Raises:
            DiscsimError: naming what happened and how to go on (a checkpoint and :func:`discsim.resume`).
        """
        if self._broken is not None:
            msg = (
                f"this {type(self).__name__} was interrupted inside its event loop ({self._broken}) and its state "
                "may be half-way through an event; continue from a checkpoint (ds.resume or ds.load) instead"
            )
            raise DiscsimError(msg)

    def _settle(self, until: float) -> None:
        """Move the clock to ``until`` after a run that stopped on time."""
        self.time = until

    # --- the checkpoint's protocol -----------------------------------------------------
    @abstractmethod
    def state(self) -> EngineState:
        """The run state: a new :class:`EngineState` of numpy arrays and scalars (copies)."""

    @abstractmethod
    def _settings(self) -> dict:
        """The constructor's options, as JSON-able values (``record``, queue, frame rate, ...)."""

    @classmethod
    @abstractmethod
    def _restore(cls, scene: Scene, settings: dict, state: EngineState, events: np.ndarray, start_time: float):
        """An engine built from ``scene`` and ``settings`` and put in ``state``, with ``events`` in its log."""

    # --- the user's protocol, implemented by each engine --------------------------------
    @property
    @abstractmethod
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time`` (a fresh copy; wrapped into a periodic box)."""

    @property
    @abstractmethod
    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, not wrapped: each disc followed across the periodic edges."""

    @property
    @abstractmethod
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time`` (a fresh copy)."""

    @abstractmethod
    def step(self):
        """Advance by one unit of work (an event, or a frame) and return what happened."""

    # --- derived -------------------------------------------------------------------------
    def run(
        self,
        until: float | None = None,
        *,
        events: int | None = None,
        observers=(),
        progress: bool = False,
        record_to=None,
        checkpoint=None,
        checkpoint_every: int | None = None,
    ):
        """Advance up to time ``until`` and/or for ``events`` units of work; see :func:`discsim.run.driver.drive`.

        Returns:
            ``self``, so calls chain.
        """
        from discsim.run.driver import drive

        drive(
            self,
            until=until,
            limit=events,
            observers=observers,
            progress=progress,
            record_to=record_to,
            checkpoint=checkpoint,
            checkpoint_every=checkpoint_every,
        )
        return self

    def save(self, path):
        """Write the whole state to one file, so that :func:`discsim.load` continues bit for bit.

        The file holds the scene, the settings, the run state (:meth:`state`) and the event log if
        recorded (or where it was streamed), written atomically with a checksum; no pickle. An existing
        ``path`` is replaced. Returns the path written, as a :class:`~pathlib.Path`.

        Example:
            >>> import os, tempfile, discsim as ds
            >>> discs, box = ds.random_gas(50, 0.4, seed=2)
            >>> path = os.path.join(tempfile.mkdtemp(), "sim.dsc")
            >>> a = ds.EventDriven(discs, box).run(until=1.0)
            >>> _ = a.save(path)
            >>> b = ds.load(path)
            >>> a.run(until=3.0).events.tobytes() == b.run(until=3.0).events.tobytes()
            True
        """
        from discsim.io.checkpoints import save

        self._check_usable()
        return save(self, path)

    @property
    def events(self) -> np.ndarray:
        """The recorded event log: a structured array ``(E,)`` of :data:`~discsim.events.EVENT_DTYPE`.

        Empty when the engine was built with ``record=False``.

        Raises:
            InvalidArgumentError: if the log was streamed to disk (``run(record_to=...)``):
                read it with :func:`discsim.read_events`.
        """
        self._refuse_if_streamed("events")
        if not self.record:
            return np.zeros(0, dtype=EVENT_DTYPE)
        return self._log.to_array()

    def snapshot(self) -> Discs:
        """The discs as they are now: a new :class:`~discsim.model.Discs` at ``time``.

        Use it to start a fresh engine (or measurement) from an equilibrated state.
        """
        d = self.discs
        return Discs(self.positions, self.velocities, d.radii, d.masses, d.groups)

    def kinetic_energy(self) -> float:
        """Total kinetic energy ``sum(m |v|^2) / 2`` (obstacles contribute zero)."""
        return kinetic_energy(self.velocities, self.discs.masses)

    def momentum(self) -> np.ndarray:
        """Total momentum ``(2,)`` of the discs of finite mass."""
        return momentum(self.velocities, self.discs.masses)

    def trajectory(self, times, *, unwrapped: bool = False) -> np.ndarray:
        """Exact positions ``(T, N, 2)`` at ``times`` ``(T,)``, rebuilt from the event log.

        Args:
            times: simulated times within ``[start_time, time]``, any order.
            unwrapped: in a periodic box, follow each disc across the edges
                instead of wrapping it into the box (as a mean-squared
                displacement needs); the same as wrapped in a walled box.

        Raises:
            InvalidArgumentError: if the engine does not hold its log
                (``record=False``, or streamed to disk: use
                :func:`discsim.trajectory_from_events`).
            TimeError: if a time is not finite or lies outside the simulated span.
        """
        self._refuse_if_streamed("trajectory()")
        if not self.record:
            msg = "trajectory() needs the event log; build the engine with record=True"
            raise InvalidArgumentError(msg)
        return positions_from_log(
            self._log.to_array(),
            self.discs,
            self.box,
            self.start_time,
            self.time,
            times,
            span="simulated span",
            unwrapped=unwrapped,
        )

    def _refuse_if_streamed(self, what: str) -> None:
        if self._stream is not None:
            path = self._stream["path"]
            msg = (
                f"{what} is not kept in memory: this run streamed its event log to {path!r}; "
                f"read it with ds.read_events({path!r}) and rebuild positions with "
                f"ds.trajectory_from_events({path!r}, times)"
            )
            raise InvalidArgumentError(msg)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n={len(self.discs)}, time={self.time:g}, box={self.box})"
