"""The event-driven engine (PIC): jump from one predicted collision to the next.

:class:`EventDriven` is the front: it validates the scene and the options, owns the public API, the event
log and the end of open-ended runs, and hands the event loop to a backend (:data:`BACKENDS`) behind a small
protocol: ``start()`` or ``load(state)``, ``advance(until, limit, log)``, ``export() -> state``. The run
state crossing that edge is an :class:`~discsim.engines.event_driven.state.EventDrivenState` of plain arrays.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from discsim._numba import auto_plan, available, mark_loaded, resolve_backend
from discsim.cells import CellGrid
from discsim.engines.base import Engine, register_engine
from discsim.engines.event_driven.numba import NumbaBackend
from discsim.engines.event_driven.numbering import fresh_state
from discsim.engines.event_driven.piston import PistonRun
from discsim.engines.event_driven.protocol import BackendClass
from discsim.engines.event_driven.python import QUEUES, PythonBackend
from discsim.engines.event_driven.state import EventDrivenState
from discsim.engines.event_driven.stops import RunStops, check_parts
from discsim.engines.event_driven.turning import Turning
from discsim.errors import CheckpointError, InvalidArgumentError
from discsim.events import KIND_NAMES, Event
from discsim.laws import Laws
from discsim.model import Box, Discs, _readonly, image_steps
from discsim.scene import Scene, check_unsteered

__all__ = ["BACKENDS", "EventDriven"]

INF = math.inf
#: The backends of the event loop, by name: each meets :class:`~discsim.engines.event_driven.protocol.Backend`
#: (the type checker checks both classes against it, through
#: :class:`~discsim.engines.event_driven.protocol.BackendClass`).
BACKENDS: dict[str, BackendClass] = {"python": PythonBackend, "numba": NumbaBackend}


@register_engine
class EventDriven(PistonRun, Turning, RunStops, Engine):
    """Exact event-driven simulation of hard discs (PIC): elastic by default, or under gravity, with restitution.

    Args:
        discs: the discs at ``time = 0``.
        box: the box (reflecting walls or periodic).
        record: keep the event log (needed by ``events`` and ``trajectory``);
            switch off for long runs so memory stays flat.
        queue: the event queue, all three giving the same events bit for bit:
            ``"calendar"`` (the default: the near-future events in a
            ``sortedcontainers.SortedList``, later ones appended to time bins,
            O(1) per event; :class:`~discsim.queue.CalendarEventQueue`),
            ``"sorted"`` (every event in one ``SortedList``) or ``"heap"``
            (``heapq`` with lazy deletion).
        cell_size: side of the grid cells; default the largest disc diameter,
            grown where needed so that there are at most ``4 N + 9`` cells.
            Never below the largest diameter.
        segments: fixed :class:`~discsim.model.Segment` walls (walled boxes
            only), kept in a static per-cell table built once.
        pass_through: pairs of group labels (``discs.groups``) whose discs do
            not collide with each other, e.g. ``{(1, 1)}`` for bullets that
            pass through one another. Free when empty.
        backend: the event loop: ``"auto"`` (the default: ``"python"`` for the first
            ``discsim._numba.AUTO_PYTHON_EVENTS`` (20,000) physical events, then ``"numba"`` when numba is
            installed, or ``"numba"`` from the start from ``AUTO_NUMBA_DISCS`` (20,000) discs on: a short run
            does not pay for loading the compiled loop), ``"numba"`` (compiled, from the ``fast`` extra:
            ``pip install "discsim[fast]"``; :mod:`discsim.engines.event_driven.numba`) or
            ``"python"`` (pure Python; :mod:`discsim.engines.event_driven.python`). Both give the
            same events bit for bit and the same checkpoints; ``sim.backend`` names the one that runs.
            Under laws other than the defaults, ``"python"`` runs the compiled loop's own source in the
            interpreter (the pure-Python loop knows free flight only), and ``"auto"`` the compiled loop.
        gravity: ``(gx, gy)``, a uniform acceleration of every disc of finite mass (length / time^2):
            exact parabolic flight (``docs/laws.md``); None: none. Obstacles and segments stay put; under
            gravity a disc that bounces off a support slower than ``rest_speed`` comes to rest.
        restitution: the normal coefficient of restitution ``e`` in [0, 1] of every collision and bounce
            (1: elastic), or a dict from pairs of group labels to ``e`` (pairs not named are elastic; a
            bounce off a wall or segment uses the disc's group's pair with itself). The kinetic energy lost
            is :attr:`dissipated`.
        tc: the TC model's time (Luding & McNamara 1998): a collision within ``tc`` of either disc's previous
            collision is elastic, which prevents inelastic collapse; 0: none (a collapse then ends the run
            with a :class:`~discsim.errors.JammedError` naming the discs).
        rest_speed: under gravity, the speed below which a bounce off a support ends in rest (velocity zero,
            gravity off, until hit harder); None: the speed of a bounce ``1e-3`` of the smallest radius high
            (:class:`~discsim.laws.Laws`).
        roughness: the tangential coefficient of restitution ``beta`` in [-1, 1] of every collision and bounce:
            -1 (the default) smooth, today's physics bit for bit (spins never change); +1 perfectly rough
            (energy conserving); between, energy lost. The impulse at the contact point turns the discs
            (``discs.spins``, ``discs.inertia``; :attr:`spins`, :attr:`angles`, :attr:`spin_events`); walls and
            segments are as rough as the discs (``docs/laws.md``).
        drag: a linear drag ``gamma`` (1 / time; 0, or within :data:`discsim.laws.DRAG_RANGE`) on every disc of
            finite mass, the force ``-m gamma v``: exact exponential flight between events, towards the terminal
            velocity ``gravity / gamma`` (``docs/laws.md``); 0: none. Its energy loss is in :attr:`dissipated`
            with the collisions', so ``energy() + dissipated`` stays constant.
        sensors: :class:`~discsim.sensors.Sensor` circles, rectangles and trip wires (``ds.Sensor.circle``,
            ``.rectangle``, ``.line``) that never touch the motion: the exact time each disc's centre enters or
            leaves one is an event, logged with kind ``"enter"`` or ``"leave"`` (``j`` the sensor's index) and
            passed to ``sim.on("enter" | "leave", fn)``; counted in ``counts["sensor_events"]`` and in
            ``run(events=...)``. They run on the compiled loop, as laws other than the defaults do.
        piston: a :class:`~discsim.piston.Piston` that makes the box's top wall a piston of finite mass under a
            constant pressure (a run at constant pressure: :attr:`piston`, :meth:`set_piston`), or a kinematic lid;
            None: none. Elastic, smooth discs without drag; gravity down along y at most (``docs/users/physics.md``).

    Raises:
        OutsideBoxError, OverlapError: if the discs do not fit in the box.
        BoxTooSmallError: if a periodic box has fewer than 3 cells a side.
        InvalidArgumentError: on an unknown queue or backend, ``backend="numba"`` without numba,
            or a bad ``cell_size``.

    Attributes:
        time (float): the current simulated time.
        backend (str): the backend that runs the event loop.
        counts (dict[str, int]): ``collisions`` (disc-disc), ``wall_hits``,
            ``cell_crossings``, ``stale`` (invalidated events popped) and
            ``predictions`` (discs re-predicted).
        max_queue (int): the most events the queue has held at once (at most N).
        max_overlap (float): the deepest overlap seen at a collision, as a
            fraction of the contact distance (roundoff only: about 1e-15).

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
        >>> sim = ds.EventDriven(discs, ds.Box(10.0, 10.0)).run(until=2.5)
        >>> sim.counts["collisions"], sim.velocities.tolist()
        (1, [[-1.0, 0.0], [1.0, 0.0]])
    """

    STATE = EventDrivenState

    def __init__(
        self,
        discs: Discs,
        box: Box,
        *,
        record: bool = True,
        queue: str = "calendar",
        cell_size: float | None = None,
        segments=(),
        pass_through=(),
        backend: str = "auto",
        gravity=None,
        restitution=1.0,
        tc: float = 0.0,
        rest_speed: float | None = None,
        roughness: float = -1.0,
        drag: float = 0.0,
        sensors=(),
        piston=None,
    ):
        laws = Laws.build(gravity, restitution, tc, rest_speed, roughness, drag)
        if laws.falls and laws.rest_speed is None and isinstance(discs, Discs):  # fixed now: added discs keep it
            laws = dataclasses.replace(laws, rest_speed=laws.rest_speed_for(discs.radii))
        scene = Scene(discs, box, check_unsteered(segments), pass_through, sensors=sensors, piston=piston)
        check_parts(scene, laws)
        self._configure(scene, record, queue, cell_size, backend, laws.checked(scene))
        self._backend.start()

    def _configure(self, scene: Scene, record: bool, queue: str, cell_size, backend: str, laws: Laws) -> None:
        """Check the options and build the grid and the backend (not yet started or loaded)."""
        if not isinstance(queue, str) or queue not in QUEUES:
            msg = f"queue must be one of {sorted(QUEUES)}, got {queue!r}"
            raise InvalidArgumentError(msg)
        self._auto = isinstance(backend, str) and backend == "auto"
        #: physical events the Python loop still runs before ``"auto"`` takes the compiled one (None: no switch)
        self._auto_events: int | None = None
        compiled_laws = not _plain(laws, scene)  # the loop that reads the laws
        if self._auto and compiled_laws:  # the interpreted loop is slow: the compiled one from the start
            backend = "numba" if available() else "python"
        elif self._auto:
            backend, self._auto_events = auto_plan(len(scene))
        else:
            backend = resolve_backend(backend, BACKENDS, "EventDriven")
        super().__init__(scene, record)
        grid = self.grid = self.cell_grid(scene.discs.radii, scene.box, cell_size)
        self.queue_kind = queue
        self.cell_size = cell_size
        self.laws = laws
        self._backend = self._new_backend(backend, scene, grid)
        if backend == "numba":
            mark_loaded()

    def _new_backend(self, name: str, scene: Scene, grid: CellGrid):
        """The backend ``name`` over the engine's laws: the default laws run on :data:`BACKENDS`; others on the
        compiled loop (``"python"``: that loop's source, interpreted), and so do sensors."""
        if _plain(self.laws, scene):
            return BACKENDS[name](scene, grid, self.queue_kind)
        return NumbaBackend(scene, grid, self.queue_kind, interpreted=name == "python", laws=self.laws)

    @staticmethod
    def cell_grid(radii: np.ndarray, box: Box, cell_size: float | None = None) -> CellGrid:
        """The engine's cell grid for discs of ``radii`` ``(N,)`` in ``box``.

        Cells are at least the largest diameter a side, grown where needed so
        that there are at most ``4 N + 9`` of them; or ``cell_size`` a side at
        least, when given (never below the largest diameter).

        Raises:
            InvalidArgumentError: if ``cell_size`` is not finite or is below the largest diameter.
            BoxTooSmallError: if a periodic box has fewer than 3 cells a side.
        """
        n = len(radii)
        if n == 0 and cell_size is None:  # no disc, no contact distance: a 3 x 3 grid fits any box
            return CellGrid(box, min(box.width, box.height) / 3.0, max_cells=9, what="a third of the box")
        diameter = 2.0 * float(np.max(radii)) if n else 1.0
        if cell_size is None:
            return CellGrid(box, diameter, max_cells=4 * n + 9)
        if not (isinstance(cell_size, (int, float, np.integer, np.floating)) and diameter <= cell_size < INF):
            msg = f"cell_size {cell_size!r} is not finite or is below the largest disc diameter {diameter!r}"
            raise InvalidArgumentError(msg)
        return CellGrid(box, float(cell_size), what="the cell_size asked for")

    # --- the checkpoint's protocol -------------------------------------------------------
    def state(self) -> EventDrivenState:
        """The run state (:class:`~discsim.engines.event_driven.state.EventDrivenState`): new arrays."""
        return self._backend.export()

    def _settings(self) -> dict:
        return {
            "record": self.record,
            "queue": self.queue_kind,
            "cell_size": self.cell_size,
            "backend": "auto" if self._auto else self.backend,  # "auto" chooses again when loaded
            "edits": self._edits,
            **({} if self.laws.default else {"laws": self.laws.settings()}),
        }

    @classmethod
    def _restore(cls, scene, settings, state, events, start_time) -> EventDriven:
        sim = cls.__new__(cls)
        laws = Laws.from_settings(settings.get("laws", {}))
        sim._configure(
            scene, settings["record"], settings["queue"], settings["cell_size"], settings.get("backend", "auto"), laws
        )
        if (state.grid_nx, state.grid_ny) != (sim.grid.nx, sim.grid.ny):
            msg = (
                f"the state's cell grid {state.grid_nx} x {state.grid_ny} is not this engine's "
                f"{sim.grid.nx} x {sim.grid.ny}"
            )
            raise CheckpointError(msg)
        state.check(len(scene), len(sim.grid))
        sim._backend.load(state)
        if len(events):
            sim._log.extend(events)
        sim.start_time = start_time
        sim._edits = int(settings.get("edits", 0))
        return sim

    # --- the driver's protocol -----------------------------------------------------------
    @property
    def time(self) -> float:
        """The current simulated time."""
        return self._backend.time

    @time.setter
    def time(self, value: float) -> None:
        self._backend.time = value

    def _units(self) -> int:
        """Physical events (collisions plus wall hits) processed since the start."""
        counts = self._backend.counts()
        return counts["collisions"] + counts["wall_hits"]

    def _event_count(self) -> int:
        """Log records since the start: one per physical event and one per disc the user changed."""
        return self._units() + self._edits

    def _set_discs(self, indices: np.ndarray, positions: np.ndarray | None, velocities: np.ndarray) -> None:
        self._check_piston_edit(indices, positions, velocities)  # before any disc changes
        for k, i in enumerate(indices.tolist()):
            vx, vy = velocities[k].tolist()
            self._backend.set_disc(i, vx, vy, None if positions is None else tuple(positions[k].tolist()))

    def _restructure(self, keep: np.ndarray, added: Discs | None, scene: Scene, last=None) -> None:
        """A fresh start at ``time`` from the discs of ``scene`` (``keep``, then ``added``): new cell grid, new
        backend, every disc predicted, as ``EventDriven(scene.discs, box)`` would start (its times then
        shifted by ``time``: the internal clock's epoch is ``time``). The counters, the virial and the
        images of the kept discs (so ``unwrapped_positions`` stay continuous) carry over, and ``last`` (the
        backend's ``last_event()``, when the discs keep their numbers) as the last event."""
        old, box = self._backend, self.box
        grid = self.cell_grid(scene.discs.radii, box, self.cell_size)  # may refuse the new discs: nothing changed
        backend = self._new_backend(old.name, scene, grid)
        state = fresh_state(scene, grid)
        state.time = state.epoch = old.time
        for name, value in old.counts().items():
            setattr(state, name, value)
        state.virial, state.max_overlap, state.max_queue = old.virial, old.max_overlap, old.max_queue
        if not self.laws.default:  # what the laws keep: the energy lost and the TC model's memory; every disc
            # wakes (a removed disc may have held others up; those still held come to rest again at once)
            state.dissipated = old.dissipated
            state.last_collision[: len(keep)] = old.export().last_collision[keep]
        sensed = old.export().sensed if scene.sensors else None  # the kept discs keep their sides of the sensors
        if sensed is not None and sensed.shape[1] == len(scene.sensors):
            state.sensed[: len(keep)] = sensed[keep]
        spins, angles = old.turning()  # the kept discs keep turning (added ones start with their own spins)
        state.spins[: len(keep)], state.angles[: len(keep)] = spins[keep], angles[keep]
        spin_log = getattr(old, "spin_log", None)
        if spin_log and hasattr(backend, "spin_log"):
            backend.spin_log = spin_log
        state.piston = self._piston_from(scene.discs)
        if last is not None:
            state.last_time, state.last_kind, state.last_i, state.last_j = last
        if box.periodic and len(keep):
            unwrapped = old.unwrapped_positions()[keep]
            state.images[: len(keep)] = image_steps(unwrapped, scene.discs.positions[: len(keep)], box.size)
        backend.start(state)
        self.grid, self._backend = grid, backend
        self._jam_mark = self._jam_counts = self._jam_scale = None  # new discs: the jam guard starts afresh

    def _take_compiled(self) -> None:
        """``backend="auto"`` after its Python events: the compiled loop goes on from the Python loop's state.

        The state crosses as a checkpoint's does, so the events that follow are the same bit for bit. If numba
        fails to import after all, the Python loop goes on.
        """
        self._auto_events = None
        if not available():
            return
        old = self._backend
        compiled = self._new_backend("numba", self.scene, self.grid)
        compiled.load(old.export())
        self._backend = compiled
        mark_loaded()

    # --- the user's protocol -------------------------------------------------------------
    @property
    def backend(self) -> str:
        """The name of the backend that runs the event loop now (under ``"auto"``: ``"python"``, then ``"numba"``)."""
        return self._backend.name

    @property
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time`` (a fresh read-only copy; wrapped into a periodic box).

        Read-only so that ``sim.positions[0] = ...`` raises: change discs with :meth:`set_positions`.
        """
        return _readonly(self.box.wrap(self._backend.positions()))

    @property
    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, each disc followed across the edges of a periodic box (a fresh copy).

        In a walled box, the same as :attr:`positions`. ``unwrapped_positions - discs.positions`` is each
        disc's displacement since the start, as a mean-squared displacement needs.
        """
        return _readonly(self._backend.unwrapped_positions())

    @property
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time`` (a fresh read-only copy: change them with :meth:`set_velocities`)."""
        return _readonly(self._backend.velocities())

    @property
    def counts(self) -> dict[str, int]:
        """Events so far: ``collisions``, ``wall_hits``, ``cell_crossings``, ``stale``, ``predictions``."""
        return self._backend.counts()

    @property
    def max_queue(self) -> int:
        """The most events the queue has held at once (at most N)."""
        return self._backend.max_queue

    @property
    def max_overlap(self) -> float:
        """The deepest overlap seen at a collision, as a fraction of the contact distance (roundoff: ~1e-15).

        Settable (to 0.0, say) to measure the deepest overlap of a stretch of a run.
        """
        return self._backend.max_overlap

    @max_overlap.setter
    def max_overlap(self, value: float) -> None:
        self._backend.max_overlap = float(value)

    @property
    def queue_size(self) -> int:
        """Events pending in the queue now (at most N)."""
        return self._backend.queue_size()

    @property
    def queue_storage(self) -> int:
        """Entries the queue holds in memory now, replaced (dead) ones included.

        Equals ``queue_size`` for ``queue="sorted"``; at most ``3 N + 64`` for
        ``"calendar"`` and ``2 N + 16`` for ``"heap"``, which drop dead entries lazily.
        """
        return self._backend.queue_storage()

    @property
    def dissipated(self) -> float:
        """Kinetic energy lost since the start: by collisions with restitution below 1, by rough collisions, by
        discs coming to rest under gravity, and to the drag (up to ``time``, flights under way included); 0 for
        elastic, smooth discs without drag."""
        return self._backend.dissipated

    @property
    def resting(self) -> np.ndarray:
        """``(N,)`` bool: the discs at rest now (under gravity: velocity zero, gravity off; a fresh copy)."""
        return self._backend.resting()

    def pressure(self) -> float:
        """Pressure from the collision virial, averaged since the start.

        ``P = (N kT + W / (2 t)) / A`` in 2D, with ``N kT`` the kinetic energy,
        ``W`` the sum over disc-disc collisions of ``dp_i . (r_i - r_j)`` and
        ``A`` the box area. With walls this is the bulk estimate (wall contacts
        are not counted). Units: energy per area.
        """
        elapsed = self.time - self.start_time
        if elapsed <= 0:
            msg = "pressure() needs a run of positive duration"
            raise InvalidArgumentError(msg)
        if self.laws.falls:
            msg = (
                f"pressure() is the bulk pressure of a uniform gas; under gravity {self.laws.gravity} the "
                "pressure varies with height (measure the density profile instead)"
            )
            raise InvalidArgumentError(msg)
        return (self.kinetic_energy() + self._backend.virial / (2.0 * elapsed)) / self.box.area

    def step(self) -> Event | None:
        """Process events up to and including the next collision or wall hit.

        Returns:
            The :class:`~discsim.events.Event` processed, or None if no disc
            will ever hit anything (in a periodic box that is proven when every
            pair drifts alike, or moves relative to itself only along x or only
            along y and misses; see :meth:`_never_again`).
        """
        self._check_can_advance()
        if self._advance(INF, 1) == 0:
            return None
        last = self._backend.last_event()
        assert last is not None  # the event just processed
        t, kind, i, j = last
        return Event(t, KIND_NAMES[kind], i, j)

    def _check(self) -> None:
        """Assert every invariant of the engine and its backend; O(N). Called by the stress tests."""
        from discsim.engines.event_driven.invariants import check

        check(self)


def _plain(laws: Laws, scene: Scene) -> bool:
    """Whether both backends' own loops run ``scene`` under ``laws`` (else the loop that reads the laws)."""
    return laws.default and not scene.sensors and not scene.moving and scene.piston is None
