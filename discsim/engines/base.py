"""What every engine shares: the public protocol, the run state's form, and the registry of engines.

An engine holds a validated :class:`~discsim.scene.Scene` (``discs`` at the start, ``box``, ``segments``,
``pass_through``), its ``time``, ``positions`` and ``velocities``, ``counts`` and an event log. Each engine
implements three small protocols, all here as abstract methods:

- the **driver's** (:mod:`discsim.run.driver`): ``_advance(until, limit)`` does up to ``limit`` units of
  work (physical events, or frames) up to time ``until`` (``math.inf``: no time limit; ``limit`` None: no
  count limit), logging each event in ``_log`` while ``_logging``; ``_units()`` counts the units,
  ``_event_count()`` the events the log would hold; ``_settle(until)`` moves the clock to ``until`` when
  the run stopped on time;
- the **checkpoint's** (:mod:`discsim.io.checkpoints`): ``state()`` exports the public run state (an
  :class:`EngineState`: numpy arrays and scalars, versioned), ``_settings()`` the constructor's options as
  JSON, and ``_restore(scene, settings, state, events, start_time)`` rebuilds the engine;
- the **user's**: ``step()``, ``positions``, ``velocities``, ``unwrapped_positions``, ``counts``, and the
  changes ``_set_discs(indices, positions, velocities)`` and ``_restructure(keep, added, scene)`` behind
  the editing methods (:mod:`discsim.engines.editing`).

The rest is written once, so ``compare``, ``plot``, notebooks and benchmarks work with any engine and
backend: ``run``, ``save``, ``snapshot``, energies and momentum here, disc editing in
:mod:`~discsim.engines.editing`, ``events`` and the exact ``trajectory`` in :mod:`~discsim.engines.record`.
The run's bookkeeping (the log in memory, the run id and streamed log, the disc ids, the callbacks) is
``engine.run_context`` (:class:`~discsim.engines.context.RunContext`): the layers above use that, not the
engine's private attributes.

Two tables join the engines to the layers above without an import pointing up, not even inside a function:

- the **registry**: each engine class adds itself where it is defined (``@register_engine``), and
  :mod:`discsim.io.checkpoints` finds the class a file names with :func:`engine_class`, so a new engine
  edits no module of ``io/``;
- the **services**: ``Engine.run`` and ``Engine.save`` are thin delegates to the functions that
  :mod:`discsim.run.driver` and :mod:`discsim.io.checkpoints` hand down with :func:`provide` when they are
  imported. ``import discsim`` imports both (as does any ``import discsim.<module>``, since Python imports
  the package first), so every engine can run and save. The cut sits here, rather than the driver patching
  ``Engine.run`` or the engine importing the driver late, because it keeps the engine's methods where a
  reader looks for them, keeps their docstrings, and lets ``tests/test_architecture.py`` check every import.
"""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any, ClassVar, cast

import numpy as np

from discsim.engines.context import RunContext
from discsim.engines.editing import DiscEditing
from discsim.engines.queries import SpatialQueries
from discsim.engines.record import EventRecord
from discsim.errors import CheckpointError, DiscsimError, InvalidArgumentError, WrongTypeError
from discsim.model import Box, Discs, kinetic_energy, momentum
from discsim.repair import Repair, restart_scene
from discsim.scene import Scene

__all__ = ["Engine", "EngineState", "engine_class", "provide", "register_engine", "registered_engines"]

#: Engine classes by name (the name a checkpoint stores): see :func:`register_engine`.
_ENGINES: dict[str, type[Engine]] = {}
#: What the layers above provide to the engines, by service name: see :func:`provide`.
_SERVICES: dict[str, Callable] = {}
#: The services an engine uses, and the module that provides each.
SERVICES = {"run": "discsim.run.driver", "save": "discsim.io.checkpoints"}


def register_engine(cls: type[Engine]) -> type[Engine]:
    """Class decorator: add engine class ``cls`` to the registry under its name; returns ``cls``.

    Raises:
        WrongTypeError: if ``cls`` is not a subclass of :class:`Engine`.
        InvalidArgumentError: if a class from another module (or of another qualified name) is registered
            under the same name.
    """
    if not (isinstance(cls, type) and issubclass(cls, Engine)):
        msg = f"register_engine needs a subclass of discsim.engines.base.Engine, got {cls!r}"
        raise WrongTypeError(msg)
    known = _ENGINES.get(cls.__name__)
    if known is None:
        _ENGINES[cls.__name__] = cls
    elif (known.__module__, known.__qualname__) != (cls.__module__, cls.__qualname__):
        msg = f"an engine named {cls.__name__!r} is registered already ({known.__module__}.{known.__qualname__})"
        raise InvalidArgumentError(msg)
    # The same class, or its file run again (a second copy of the module, as pytest's importlib mode makes):
    # the first stays, the one ``discsim.EventDriven`` and the like name.
    return cls


def registered_engines() -> dict[str, type[Engine]]:
    """The registered engine classes by name (a new dict)."""
    return dict(_ENGINES)


def engine_class(name: str) -> type[Engine]:
    """The registered engine class called ``name``.

    Raises:
        InvalidArgumentError: for a name no engine is registered under, naming the known ones.
    """
    try:
        return _ENGINES[name]
    except (KeyError, TypeError):
        msg = f"no engine is registered as {name!r} (known: {sorted(_ENGINES)})"
        raise InvalidArgumentError(msg) from None


def provide(service: str, fn: Callable) -> None:
    """Hand ``fn`` down to the engines as ``service`` (one of :data:`SERVICES`): the implementation behind
    ``Engine.run`` (``fn(engine, until, **options)``) or ``Engine.save`` (``fn(engine, path)``).

    Raises:
        InvalidArgumentError: an unknown service, or an ``fn`` that is not callable.
    """
    if service not in SERVICES or not callable(fn):
        msg = f"provide() takes one of {sorted(SERVICES)} and a callable, got {service!r} and {fn!r}"
        raise InvalidArgumentError(msg)
    _SERVICES[service] = fn


def _service(service: str) -> Callable:
    """The function provided as ``service``; raises DiscsimError (naming the module to import) if none was."""
    fn = _SERVICES.get(service)
    if fn is None:
        msg = f"Engine.{service}() needs {SERVICES[service]}, which provides it when imported: import discsim"
        raise DiscsimError(msg)
    return fn


class EngineState:
    """Base of the engines' public run states: a dataclass of numpy arrays and plain scalars.

    A state is everything an engine needs to continue bit for bit, in a form any backend, observer or
    file can read: it is what a checkpoint stores and what a backend loads and exports. ``VERSION``
    changes whenever a field's meaning changes.
    """

    VERSION: ClassVar[int] = 1
    #: Declared for type checkers only (no value here): every subclass is a ``@dataclass``, which sets it.
    __dataclass_fields__: ClassVar[dict[str, dataclasses.Field[Any]]]

    def to_arrays(self) -> tuple[dict, dict[str, np.ndarray]]:
        """``(scalars, arrays)``: the JSON-able fields and the numpy fields, by name."""
        scalars: dict[str, Any] = {}
        arrays: dict[str, np.ndarray] = {}
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


class Engine(DiscEditing, EventRecord, SpatialQueries, ABC):
    """Base class of discsim engines; see the module docstring for the protocols.

    The disc-editing methods come from :class:`~discsim.engines.editing.DiscEditing`, the log's readers
    (``events``, ``trajectory``) from :class:`~discsim.engines.record.EventRecord`, the spatial queries
    (``disc_at``, ``nearest``, ``within``, ``ray_cast``) from :class:`~discsim.engines.queries.SpatialQueries`.
    """

    #: The name of ``run()``'s count of units of work ("events" or "frames").
    unit: ClassVar[str] = "events"
    #: The counter whose rate a progress bar shows.
    rate_count: ClassVar[str] = "collisions"
    #: Units of work between progress-bar updates.
    progress_chunk: ClassVar[int] = 20_000
    #: Events per chunk of a log streamed by ``run(record_to=...)``; at most this many are held in memory.
    stream_chunk: int = 16_384
    #: Whether the engine's work ends by itself (a compression reaches its target), so that ``run()`` with no
    #: limit runs to that end; other engines need ``until`` or a count.
    runs_to_end: ClassVar[bool] = False
    #: The class of the engine's run state (each engine sets it).
    STATE: ClassVar[type[EngineState]]

    discs: Discs
    box: Box
    time: float

    def __init__(self, scene: Scene, record: bool):
        self.scene = scene
        self.discs = scene.discs
        self.box = scene.box
        self.segments = scene.segments
        #: The :class:`~discsim.sensors.Sensor` regions and trip wires (a tuple; empty without).
        self.sensors = scene.sensors
        self.pass_through = scene.pass_through
        if not isinstance(record, (bool, np.bool_)):  # bool("False") would be True
            msg = f"record must be True or False, got {record!r}"
            raise InvalidArgumentError(msg)
        self.record = bool(record)
        self.start_time = 0.0
        #: The run's bookkeeping (:class:`~discsim.engines.context.RunContext`): the log in memory, the run id
        #: and streamed log, the disc ids, the callbacks. The driver, ``io`` and ``analysis`` use it.
        self.run_context = RunContext(len(scene))
        self._log = self.run_context.log  # the same object, for the loops (an attribute: step() reads it each call)
        self._broken: str | None = None  # why the engine cannot go on (an exception inside its loop)
        self._edits = 0  # discs changed by the user (one SET record each in a recorded log)

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

    def _check_can_advance(self) -> None:
        """:meth:`_check_usable`, and refuse ``step()`` or ``run()`` from inside a run (an observer or a
        ``sim.on`` callback), before anything changes: a ``run()`` there would serve the same callbacks again,
        down to a ``RecursionError`` that left the engine marked broken.

        Raises:
            DiscsimError: as :meth:`_check_usable`.
            InvalidArgumentError: inside a run.
        """
        self._check_usable()
        if self.run_context.serving:
            msg = (
                "step() or run() inside a run is refused: an observer or a sim.on callback may not advance the "
                "engine (observers may only look, callbacks may change discs); nothing was changed"
            )
            raise InvalidArgumentError(msg)

    def _settle(self, until: float) -> None:
        """Move the clock to ``until`` after a run that stopped on time."""
        self.time = until

    def _progress(self, plan) -> tuple[float, float, bool, str]:
        """``(position, total, by_time, unit)`` of a progress bar over the run ``plan`` (a ``RunPlan``).

        Over simulated time for a run with ``until`` only, else over the units of work; an engine whose
        progress is another quantity (a compression's packing) says so here.
        """
        if plan.limit is None:
            return self.time - plan.start_time, plan.until - plan.start_time, True, self.unit
        return float(self._units() - plan.start_units), float(plan.limit), False, self.unit

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

    @abstractmethod
    def _set_discs(self, indices: np.ndarray, positions: np.ndarray | None, velocities: np.ndarray) -> None:
        """Restart the paths of moving discs ``indices`` ``(K,)`` at ``time`` with ``velocities`` ``(K, 2)`` from
        ``positions`` ``(K, 2)`` (in the box), or from where they are (None). Checked by the caller."""

    @abstractmethod
    def _restructure(self, keep: np.ndarray, added: Discs | None, scene: Scene) -> None:
        """Go on at ``time`` with discs ``keep`` ``(N',)`` (increasing indices) and then ``added``, the discs of
        ``scene`` (checked by the caller). Raises before changing anything if the engine cannot hold them."""

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
        _service("run")(
            self,
            until,
            events=events,
            observers=observers,
            progress=progress,
            record_to=record_to,
            checkpoint=checkpoint,
            checkpoint_every=checkpoint_every,
        )
        return self

    def _count_only(self, until, count, events, record_to, name: str, no_time: str, no_log: str):
        """The count of a ``run()`` that takes no stop time and streams no log (an engine whose unit is not an
        event in time: a compression's epoch, an event chain): ``count`` (named ``name``) or its other name
        ``events``, as :func:`discsim.resume` passes it.

        Raises:
            InvalidArgumentError: ``until`` given (``no_time`` says why), ``record_to`` given (``no_log``), or
                both names of the count.
        """
        if until is not None:
            msg = f"{no_time}: give {name}=..., not until={until!r}"
            raise InvalidArgumentError(msg)
        if record_to is not None:
            msg = f"{no_log}: record_to is not taken"
            raise InvalidArgumentError(msg)
        if events is not None:
            if count is not None:
                msg = f"give {name}=... or events=..., not both: {name}={count!r}, events={events!r}"
                raise InvalidArgumentError(msg)
            count = events
        return count

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
        self._check_usable()
        return _service("save")(self, path)

    #: The moves that made this engine's start valid (:class:`~discsim.repair.Repair`), when it was built by
    #: ``from_snapshot(..., repair="push")``; None otherwise. Not saved in checkpoints.
    repair: Repair | None = None

    @classmethod
    def from_snapshot(
        cls, source, box: Box | None = None, *, repair: str = "refuse", segments=None, pass_through=None, **options
    ):
        """A new engine of this class, started from ``source``'s discs as they are now, repaired if asked.

        A fixed-step run answers overlaps after the fact, so its state may hold overlapping pairs and discs
        cut by a wall or a segment, which the constructors refuse. ``repair`` says what happens to them:

        - ``"refuse"`` (the default): raise, naming every such disc (the deepest ten of each kind) and how
          deep it reaches, before anything is built;
        - ``"push"``: move them the least needed (:func:`discsim.repair.push_apart`: an overlapping pair
          apart along its line of centres, each disc in inverse proportion to its mass; a cut disc along
          the normal until it touches the wall or segment), every velocity unchanged; ``sim.repair``
          (:class:`~discsim.repair.Repair`) then says how far each disc moved.

        A valid snapshot (any event-driven one) starts as it is under both. The new engine starts at time 0,
        as one built from discs does (``source.time`` is where the source was), with an empty log.

        Args:
            source: an engine (its ``snapshot()`` at its ``time``, its box, segments and collision filter)
                or :class:`~discsim.model.Discs` (then give ``box``).
            box: the box of ``Discs``; with an engine, leave it out (or give the engine's own).
            repair: ``"refuse"`` or ``"push"``.
            segments, pass_through: with ``Discs``, as for the constructor (default none); with an
                engine, its own (giving them too is an error).
            **options: the constructor's other options (``record``, ``backend``; ``dt``, ``policy``, ...).

        Returns:
            The engine, at time 0.

        Raises:
            InvalidArgumentError: an unknown ``repair``, ``Discs`` without a box, or a box, segments or
                filter given with an engine (the snapshot restarts in its own).
            WrongTypeError: a ``source`` that is neither an engine nor ``Discs``.
            OverlapError, OutsideBoxError: with ``"refuse"``, naming the overlapping pairs and the cut discs
                with their depths; with ``"push"``, what no move repairs (two obstacles overlapping, an
                obstacle cut by a wall, a disc centred on a segment, no room in the box). Nothing is built.

        Example:
            >>> import discsim as ds
            >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
            >>> coarse = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=1.25).run(until=2.5)  # found 1 apart
            >>> ds.EventDriven.from_snapshot(coarse)  # doctest: +ELLIPSIS
            Traceback (most recent call last):
            ...
            discsim.errors.OverlapError: the snapshot of FixedStep at time 2.5 ...: discs 0 and 1 by 1 overlap ...
            >>> sim = ds.EventDriven.from_snapshot(coarse, repair="push")
            >>> sim.repair.displacements.tolist(), sim.velocities.tolist()
            ([[-0.5, 0.0], [0.5, 0.0]], [[-1.0, 0.0], [1.0, 0.0]])
        """
        discs, box, segments, pass_through, report = restart_scene(source, box, segments, pass_through, repair)
        build = cast("Callable[..., Engine]", cls)  # a concrete engine: (discs, box, *, segments, ...), not __init__
        sim = build(discs, box, segments=segments, pass_through=pass_through, **options)
        sim.repair = report
        return sim

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

    def potential_energy(self) -> float:
        """The potential energy in the gravity field of a run under gravity (``laws``), ``-sum(m g . r)`` over the
        discs of finite mass, zero at the box's origin; 0 without gravity. ``r`` is the unwrapped centre in a
        periodic box (a disc that falls through the floor and comes in at the top keeps falling: its energy stays
        its own). Units: mass length^2 / time^2."""
        laws = getattr(self, "laws", None)
        if laws is None or not laws.falls:
            return 0.0
        masses = self.discs.masses
        finite = np.isfinite(masses)
        return float(-np.sum(masses[finite] * (self.unwrapped_positions[finite] @ np.array(laws.gravity))))

    def energy(self) -> float:
        """Kinetic plus potential energy. Exact runs keep it when collisions are elastic and no disc comes to rest
        (``energy() + dissipated`` always); a fixed-step run changes it by the stepping's error."""
        return self.kinetic_energy() + self.potential_energy()

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n={len(self.discs)}, time={self.time:g}, box={self.box})"
