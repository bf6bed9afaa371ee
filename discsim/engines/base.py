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
- the **user's**: ``step()``, ``positions``, ``velocities``, ``unwrapped_positions``, ``counts``, and the
  changes ``_set_discs(indices, positions, velocities)`` and ``_restructure(keep, added, scene)`` behind
  ``set_velocities``, ``apply_impulse``, ``set_positions``, ``add_discs`` and ``remove_discs``.

Everything else (``run``, ``save``, ``events``, exact ``trajectory``, energies, momentum, ``snapshot``) is
written here once, so ``compare``, ``plot``, notebooks and benchmarks work with any engine and backend.

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
from typing import ClassVar

import numpy as np

from discsim.errors import (
    CheckpointError,
    DiscsimError,
    InvalidArgumentError,
    OutsideBoxError,
    OverlapError,
    UnitsError,
    WrongTypeError,
)
from discsim.events import EVENT_DTYPE, EventLog
from discsim.model import OVERLAP_TOLERANCE, SPEED_RANGE, Box, Discs, kinetic_energy, momentum
from discsim.repair import Repair, restart_scene
from discsim.scene import Scene, check_added
from discsim.trajectory import positions_from_log

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
        InvalidArgumentError: if another class is registered under the same name.
    """
    if not (isinstance(cls, type) and issubclass(cls, Engine)):
        msg = f"register_engine needs a subclass of discsim.engines.base.Engine, got {cls!r}"
        raise WrongTypeError(msg)
    known = _ENGINES.get(cls.__name__)
    if known is not None and (known.__module__, known.__qualname__) != (cls.__module__, cls.__qualname__):
        msg = f"an engine named {cls.__name__!r} is registered already ({known.__module__}.{known.__qualname__})"
        raise InvalidArgumentError(msg)
    _ENGINES[cls.__name__] = cls
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
        self._edits = 0  # discs changed by the user (one SET record each in a recorded log)
        self._handlers: dict[str, list] = {}  # sim.on(kind, fn): callbacks after each event of that kind
        # Disc ids (add_discs, remove_discs): the log names discs by id; None while ids are the indices.
        self._ids: np.ndarray | None = None  # (N,) each disc's id
        self._next_id = len(scene)  # the id the next disc added gets
        self._origin: tuple[Discs, np.ndarray | None] | None = None  # (discs, ids) where the log starts, once
        # the discs changed (``discs`` is then the current scene); None: (``discs``, their indices)
        self._structure = 0  # add_discs / remove_discs calls so far (observers notice the disc set changed)

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

    @abstractmethod
    def _set_discs(self, indices: np.ndarray, positions: np.ndarray | None, velocities: np.ndarray) -> None:
        """Restart the paths of moving discs ``indices`` ``(K,)`` at ``time`` with ``velocities`` ``(K, 2)`` from
        ``positions`` ``(K, 2)`` (in the box), or from where they are (None). Checked by the caller."""

    @abstractmethod
    def _restructure(self, keep: np.ndarray, added: Discs | None, scene: Scene) -> None:
        """Go on at ``time`` with discs ``keep`` ``(N',)`` (increasing indices) and then ``added``, the discs of
        ``scene`` (checked by the caller). Raises before changing anything if the engine cannot hold them."""

    # --- changing the simulation ----------------------------------------------------------
    #: Event kinds a callback can follow with :meth:`on`.
    CALLBACK_KINDS: ClassVar[tuple[str, ...]] = ("collision", "wall", "segment")

    def set_velocities(self, indices, velocities):
        """Give discs ``indices`` new ``velocities`` ``(K, 2)`` (or one ``(2,)`` for all) at ``time``.

        Each change is an event of its own in the log (kind ``"set"``), so :meth:`trajectory` stays exact;
        only the discs changed are re-predicted. Returns ``self``.

        Raises:
            InvalidArgumentError: an index that is not a disc, a repeated index, a wrong shape, a NaN or
                infinite velocity, or an obstacle (infinite mass; obstacles stay where they are).
            UnitsError: a speed outside the supported range. Nothing changes then.

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[0.0, 0.0], [0.0, 0.0]], 1.0), ds.Box(10, 10))
            >>> sim.set_velocities([0], [[1.0, 0.0]]).run(until=4.5).velocities.tolist()
            [[0.0, 0.0], [1.0, 0.0]]
        """
        idx = self._disc_indices(indices)
        self._change(idx, None, self._rows("velocities", velocities, idx))
        return self

    def apply_impulse(self, indices, impulses):
        """Push discs ``indices`` with ``impulses`` ``(K, 2)`` (momentum, or one ``(2,)`` for all): ``dv = J / m``.

        Returns ``self``. Raises as :meth:`set_velocities` (obstacles refuse to be pushed).

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], 1.0, masses=2.0), ds.Box(10, 10))
            >>> sim.apply_impulse([0], [0.0, 4.0]).velocities.tolist()
            [[1.0, 2.0]]
        """
        idx = self._disc_indices(indices)
        impulses = self._rows("impulses", impulses, idx)
        self._refuse_obstacles(idx)
        velocities = self.velocities[idx] + impulses / self.discs.masses[idx][:, None]
        self._change(idx, None, velocities)
        return self

    def set_positions(self, indices, positions):
        """Move discs ``indices`` to ``positions`` ``(K, 2)`` at ``time``, keeping their velocities.

        Validated as the constructor validates: each disc must lie in the box (in ``[0, width) x
        [0, height)`` when periodic), clear of the walls, the segments and every other disc (pairs that
        pass through each other excepted). Returns ``self``.

        Raises:
            OutsideBoxError, OverlapError: naming the disc (and the disc it would overlap).
            InvalidArgumentError: as :meth:`set_velocities`. Nothing changes then.
        """
        idx = self._disc_indices(indices)
        self._change(idx, self._rows("positions", positions, idx), None)
        return self

    def add_discs(self, discs: Discs) -> np.ndarray:
        """Add ``discs`` (a :class:`~discsim.model.Discs` of ``K`` discs: positions in the box, velocities, radii,
        masses, groups) at ``time``. Returns their indices ``N, ..., N + K - 1`` ``(K,)`` int64.

        Validated as the constructor validates the discs: each new disc must lie in the box (in ``[0, width)
        x [0, height)`` when periodic), clear of the walls, the segments, every disc already there and every
        other new one (pairs whose groups pass through each other excepted); NaN, non-positive radii or
        negative masses are refused by ``Discs`` itself. Each new disc gets the next disc id (:attr:`ids`)
        and an ``ADD`` record in the log (:meth:`~discsim.events.EventLog.add`), so :meth:`trajectory` and
        the log's readers know where it came from.

        The run goes on from a fresh start at ``time``: every disc is re-predicted (O(N), the cost of
        building the engine), so ``EventDriven`` then gives, event for event and bit for bit, what a new
        ``EventDriven(sim.snapshot(), box)`` would give from the same discs (its times shifted by ``time``).
        Add many discs in one call rather than one by one.

        Raises:
            WrongTypeError: ``discs`` is not a ``Discs``.
            OutsideBoxError: a new disc is outside the box or cut by a wall or segment, named by the index it
                would get. Nothing changes then, for this error and every one below.
            OverlapError: a new disc would overlap a disc (named, with the other disc and the depth).
            UnitsError: a radius or speed outside what discsim resolves.
            BoxTooSmallError: the larger discs no longer fit a periodic box's cell grid (3 cells of the
                largest diameter a side).
            InvalidArgumentError: the larger discs no longer fit the engine's ``cell_size``.

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], 1.0), ds.Box(10, 10)).run(until=1.0)
            >>> sim.add_discs(ds.Discs([[8.0, 5.0]], [[-1.0, 0.0]], 1.0)).tolist()
            [1]
            >>> sim.run(until=3.0).counts["collisions"], sim.velocities.tolist()
            (1, [[-1.0, 0.0], [1.0, 0.0]])
        """
        self._check_usable()
        if not isinstance(discs, Discs):
            msg = f"add_discs needs a discsim.Discs, got {type(discs).__name__} {str(discs)[:60]}"
            raise WrongTypeError(msg)
        n, k = len(self.discs), len(discs)
        if k == 0:
            return np.zeros(0, dtype=np.int64)
        speed = np.hypot(discs.velocities[:, 0], discs.velocities[:, 1])
        lo, hi = SPEED_RANGE
        bad = (speed > hi) | ((speed < lo) & (speed != 0.0))
        if bad.any():
            b = int(np.flatnonzero(bad)[0])
            msg = (
                f"new disc {n + b} would have speed {float(speed[b])!r}, outside the range discsim supports "
                f"([{lo:g}, {hi:g}] or 0; discsim.model.SPEED_RANGE)"
            )
            raise UnitsError(msg)
        now = self.snapshot()
        everyone = Discs(
            np.concatenate([now.positions, discs.positions]),
            np.concatenate([now.velocities, discs.velocities]),
            np.concatenate([now.radii, discs.radii]),
            np.concatenate([now.masses, discs.masses]),
            np.concatenate([now.groups, discs.groups]),
        )
        scene = self.scene
        check_added(everyone, self.box, n, scene.segments, scene.pass_through)
        new_scene = Scene(everyone, self.box, scene.segments, scene.pass_through, check=False)
        ids = np.arange(self._next_id, self._next_id + k, dtype=np.int64)
        ids_after, origin = np.concatenate([self.ids, ids]), self._log_origin()
        self._restructure(np.arange(n), discs, new_scene)
        self._new_discs(new_scene, ids_after, self._next_id + k, origin)
        if self._logging or self._stream is not None:
            self._log.add(self.time, ids, discs.positions, discs.velocities, discs.radii, discs.masses, discs.groups)
        self._edits += k
        return np.arange(n, n + k, dtype=np.int64)

    def remove_discs(self, indices):
        """Remove discs ``indices`` (a list of distinct indices, or one) at ``time``. Returns ``self``.

        The discs after them move down to fill the gaps, as ``np.delete`` does: with ``N`` discs,
        removing disc ``i`` makes disc ``k > i`` disc ``k - 1``. Indices always number the discs there
        now (``positions``, ``velocities``, ``discs``, ``step()``'s events, callbacks' contacts), while the
        log names every disc by its id, which never changes (:attr:`ids` gives the id of each disc now).
        Each removed disc gets a ``REMOVE`` record (:meth:`~discsim.events.EventLog.remove`); its column of
        :meth:`trajectory` is NaN from then on. The run goes on from a fresh start at ``time``, as after
        :meth:`add_discs`.

        Raises:
            InvalidArgumentError: an index that is not a disc, a repeated index, or one that is not an
                integer. Nothing changes then.

        Example:
            >>> import discsim as ds
            >>> discs = ds.Discs([[2.0, 5.0], [5.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [0.0, 0.0], [-1.0, 0.0]], 0.5)
            >>> sim = ds.EventDriven(discs, ds.Box(10, 10)).remove_discs([1])
            >>> sim.ids.tolist(), sim.run(until=2.9).counts["collisions"], sim.velocities.tolist()
            ([0, 2], 1, [[-1.0, 0.0], [1.0, 0.0]])
        """
        idx = self._disc_indices(indices)
        self._check_usable()
        if not len(idx):
            return self
        n = len(self.discs)
        keep = np.delete(np.arange(n), idx)
        now = self.snapshot()
        gone_positions, gone_velocities = now.positions[np.sort(idx)], now.velocities[np.sort(idx)]
        rest = Discs(now.positions[keep], now.velocities[keep], now.radii[keep], now.masses[keep], now.groups[keep])
        scene = self.scene
        new_scene = Scene(rest, self.box, scene.segments, scene.pass_through, check=False)
        gone, ids_after, origin = self.ids[np.sort(idx)], self.ids[keep], self._log_origin()
        self._restructure(keep, None, new_scene)
        self._new_discs(new_scene, ids_after, self._next_id, origin)
        if self._logging or self._stream is not None:
            self._log.remove(self.time, gone, gone_positions, gone_velocities)
        self._edits += len(idx)
        return self

    def _new_discs(self, scene: Scene, ids: np.ndarray, next_id: int, origin: tuple) -> None:
        """After :meth:`_restructure`: the new scene and ids (the log's rows so far renamed by the old ones), and
        ``origin``, the discs where the log starts (:meth:`_log_origin` before the change)."""
        self._origin = origin
        self._log.flush()
        self.scene, self.discs = scene, scene.discs
        identity = bool(np.array_equal(ids, np.arange(len(ids))))
        self._ids = None if identity else _readonly_ids(ids)
        self._next_id = int(next_id)
        self._log.ids = self._ids
        self._structure += 1

    @property
    def ids(self) -> np.ndarray:
        """``(N,)`` int64, read-only: the id of each disc, the name the event log and :meth:`trajectory` give it.

        A disc's id is its index until some disc is removed (:meth:`remove_discs`): indices then shift down
        while ids never change; a disc added later gets the next id never used.
        """
        if self._ids is None:
            return _readonly_ids(np.arange(len(self.discs), dtype=np.int64))
        return self._ids

    def _log_origin(self) -> tuple[Discs, np.ndarray | None]:
        """``(discs, ids)`` where the log starts, at ``start_time`` (ids None: their indices)."""
        return (self.discs, None) if self._origin is None else self._origin

    def on(self, kind: str, fn):
        """Call ``fn(sim, contact)`` after each event of ``kind`` (``"collision"``, ``"wall"`` or ``"segment"``).

        ``contact`` is a :class:`~discsim.analysis.contacts.Contact` (time, kind, discs, contact point,
        unit normal, impulse, normal speed). The callback may change the simulation (``set_velocities``,
        ``apply_impulse``, ``set_positions``) and the run goes on exactly from there. While a callback is
        registered, ``run()`` advances one physical event (or frame) at a time, so each callback sees the
        state just after its event: see the README for the cost. Returns ``self``.

        Raises:
            InvalidArgumentError: an unknown kind (naming it) or a ``fn`` that is not callable.
        """
        if not isinstance(kind, str) or kind not in self.CALLBACK_KINDS:
            msg = f"on() follows one of {list(self.CALLBACK_KINDS)}, got {kind!r}"
            raise InvalidArgumentError(msg)
        if not callable(fn):
            msg = f"on({kind!r}, fn) needs a callable fn(sim, contact), got {type(fn).__name__}"
            raise InvalidArgumentError(msg)
        self._handlers.setdefault(kind, []).append(fn)
        return self

    def _disc_indices(self, indices) -> np.ndarray:
        """``indices`` as a ``(K,)`` int array of distinct existing discs."""
        n = len(self.discs)
        try:
            idx = np.atleast_1d(np.asarray(indices))
        except (TypeError, ValueError) as exc:
            msg = f"indices must be integers in [0, {n}), got {indices!r}"
            raise InvalidArgumentError(msg) from exc
        if idx.ndim != 1 or (idx.size and not np.issubdtype(idx.dtype, np.integer)):
            msg = f"indices must be a list of integers in [0, {n}), got {indices!r}"
            raise InvalidArgumentError(msg)
        idx = idx.astype(np.int64)
        bad = (idx < 0) | (idx >= n)
        if bad.any():
            msg = f"disc index {int(idx[bad][0])} does not exist (this simulation has discs 0 to {n - 1})"
            raise InvalidArgumentError(msg)
        unique, counts = np.unique(idx, return_counts=True)
        if (counts > 1).any():
            msg = f"disc index {int(unique[counts > 1][0])} is given twice"
            raise InvalidArgumentError(msg)
        return idx

    @staticmethod
    def _rows(name: str, values, idx: np.ndarray) -> np.ndarray:
        """``values`` as a finite ``(K, 2)`` float array (one ``(2,)`` row is repeated for every disc)."""
        try:
            rows = np.array(values, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            msg = f"{name} must be numbers of shape ({len(idx)}, 2), got {values!r}"
            raise InvalidArgumentError(msg) from exc
        if rows.shape == (2,):
            rows = np.tile(rows, (len(idx), 1))
        if rows.shape != (len(idx), 2):
            msg = f"{name} must have shape ({len(idx)}, 2) for {len(idx)} discs, got shape {rows.shape}"
            raise InvalidArgumentError(msg)
        bad = ~np.isfinite(rows).all(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            msg = f"disc {int(idx[k])} would get non-finite {name} {rows[k].tolist()}"
            raise InvalidArgumentError(msg)
        return rows

    def _refuse_obstacles(self, idx: np.ndarray) -> None:
        fixed = np.isinf(self.discs.masses[idx])
        if fixed.any():
            msg = f"disc {int(idx[fixed][0])} is an obstacle (infinite mass): it cannot be moved or pushed"
            raise InvalidArgumentError(msg)

    def _change(self, idx: np.ndarray, positions: np.ndarray | None, velocities: np.ndarray | None) -> None:
        """Check every change first, then make them all, log them, and count them."""
        self._check_usable()
        self._refuse_obstacles(idx)
        if velocities is None:
            velocities = self.velocities[idx]
        speed = np.hypot(velocities[:, 0], velocities[:, 1])
        lo, hi = SPEED_RANGE
        bad = (speed > hi) | ((speed < lo) & (speed != 0.0))
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            msg = (
                f"disc {int(idx[k])} would get speed {float(speed[k])!r}, outside the range discsim supports "
                f"([{lo:g}, {hi:g}] or 0; discsim.model.SPEED_RANGE)"
            )
            raise UnitsError(msg)
        if positions is not None:
            self._check_places(idx, positions)
        if len(idx):
            self._set_discs(idx, positions, velocities)
        self._edits += len(idx)
        if (self._logging or self._stream is not None) and len(idx):  # a streamed log takes it at the next run
            t, pos, vel, ids = self.time, self.positions[idx], self.velocities[idx], self.ids[idx]
            for k, i in enumerate(ids.tolist()):
                self._log.set(t, i, pos[k, 0], pos[k, 1], vel[k, 0], vel[k, 1])

    def _check_places(self, idx: np.ndarray, positions: np.ndarray) -> None:
        """Refuse positions outside the box, cut by a wall or a segment, or overlapping another disc."""
        box, radii = self.box, self.discs.radii
        size = box.size
        for k, i in enumerate(idx.tolist()):
            p, r = positions[k], radii[i]
            if box.periodic:
                outside, what = bool(((p < 0) | (p >= size)).any()), "outside the periodic box [0, width) x [0, height)"
            else:
                slack = OVERLAP_TOLERANCE * r
                outside, what = (
                    bool(((p - r < -slack) | (p + r > size + slack)).any()),
                    "outside the box or cut by a wall",
                )
            if outside:
                msg = f"disc {i} at {p.tolist()} with radius {r:g} would be {what} (box {box.width:g} x {box.height:g})"
                raise OutsideBoxError(msg)
            for s, segment in enumerate(self.segments):
                if float(segment.distance(p[None, :])[0]) < r * (1.0 - OVERLAP_TOLERANCE):
                    msg = f"disc {i} at {p.tolist()} with radius {r:g} would be cut by segment {s} {segment!r}"
                    raise OutsideBoxError(msg)
        places = np.array(self.positions)  # a writable copy
        places[idx] = positions
        everyone = np.arange(len(radii))
        for k, i in enumerate(idx.tolist()):
            d = box.minimum_image(places - places[i])
            dist = np.hypot(d[:, 0], d[:, 1])
            contact = radii + radii[i]
            depth = contact - dist
            bad = depth > OVERLAP_TOLERANCE * contact
            bad[i] = False
            if self.scene.filtering:
                bad &= ~self.scene.passes(np.full(len(radii), i), everyone)
            if bad.any():
                j = int(np.flatnonzero(bad)[np.argmax((depth / contact)[bad])])
                msg = (
                    f"disc {i} at {positions[k].tolist()} would overlap disc {j} by {depth[j]:.6g} "
                    f"(distance {dist[j]:.6g}, contact distance {contact[j]:.6g})"
                )
                raise OverlapError(msg)

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
        sim = cls(discs, box, segments=segments, pass_through=pass_through, **options)
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

    def trajectory(self, times, *, unwrapped: bool = False) -> np.ndarray:
        """Exact positions ``(T, N, 2)`` at ``times`` ``(T,)``, rebuilt from the event log.

        Column ``k`` is the disc of id ``k`` (:attr:`ids`): the disc of index ``k`` unless discs were
        removed. After :meth:`add_discs` or :meth:`remove_discs` there is one column per disc the run ever
        held (``M >= N``: ``trajectory(t)[:, sim.ids]`` are the discs there now), NaN at times the disc was
        not there (before its ``ADD`` record, from its ``REMOVE`` record on). After such a change the engine
        restarts every disc's path from where it is, so positions rebuilt between that change and a
        disc's next event may differ from the engine's own in the last bits.

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
        discs, ids = self._log_origin()
        return positions_from_log(
            self._log.to_array(),
            discs,
            self.box,
            self.start_time,
            self.time,
            times,
            span="simulated span",
            unwrapped=unwrapped,
            ids=ids,
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


def _readonly_ids(ids: np.ndarray) -> np.ndarray:
    out = np.array(ids, dtype=np.int64)
    out.flags.writeable = False
    return out
