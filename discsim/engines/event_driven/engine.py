"""The event-driven engine (PIC): jump from one predicted collision to the next.

:class:`EventDriven` is the front: it validates the scene and the options, owns the public API, the event
log and the end of open-ended runs, and hands the event loop to a backend (:data:`BACKENDS`) behind a small
protocol: ``start()`` or ``load(state)``, ``advance(until, limit, log)``, ``export() -> state``. The run
state crossing that edge is an :class:`~discsim.engines.event_driven.state.EventDrivenState` of plain arrays.
"""

from __future__ import annotations

import math

import numpy as np

from discsim._numba import resolve_backend
from discsim.cells import CellGrid, neighbour_pairs
from discsim.engines.base import Engine, register_engine
from discsim.engines.event_driven.numba import NumbaBackend
from discsim.engines.event_driven.numbering import fresh_state
from discsim.engines.event_driven.protocol import BackendClass
from discsim.engines.event_driven.python import QUEUES, PythonBackend
from discsim.engines.event_driven.state import EventDrivenState
from discsim.errors import CheckpointError, Interrupted, InvalidArgumentError, JammedError
from discsim.events import KIND_NAMES, Event
from discsim.model import Box, Discs, _readonly
from discsim.scene import Scene

__all__ = ["BACKENDS", "EventDriven"]

INF = math.inf
#: The backends of the event loop, by name: each meets :class:`~discsim.engines.event_driven.protocol.Backend`
#: (the type checker checks both classes against it, through
#: :class:`~discsim.engines.event_driven.protocol.BackendClass`).
BACKENDS: dict[str, BackendClass] = {"python": PythonBackend, "numba": NumbaBackend}


@register_engine
class EventDriven(Engine):
    """Exact event-driven simulation of elastic hard discs (PIC).

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
        backend: the event loop: ``"auto"`` (the default: ``"numba"`` when numba
            imports, else ``"python"``), ``"numba"`` (compiled, from the ``fast`` extra:
            ``pip install "discsim[fast]"``; :mod:`discsim.engines.event_driven.numba`) or
            ``"python"`` (pure Python; :mod:`discsim.engines.event_driven.python`). Both give the
            same events bit for bit and the same checkpoints; ``sim.backend`` names the one that runs.

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
    ):
        self._configure(Scene(discs, box, segments, pass_through), record, queue, cell_size, backend)
        self._backend.start()

    def _configure(self, scene: Scene, record: bool, queue: str, cell_size, backend: str) -> None:
        """Check the options and build the grid and the backend (not yet started or loaded)."""
        if not isinstance(queue, str) or queue not in QUEUES:
            msg = f"queue must be one of {sorted(QUEUES)}, got {queue!r}"
            raise InvalidArgumentError(msg)
        backend = resolve_backend(backend, BACKENDS, "EventDriven")
        super().__init__(scene, record)
        grid = self.grid = self.cell_grid(scene.discs.radii, scene.box, cell_size)
        self.queue_kind = queue
        self.cell_size = cell_size
        self._backend = BACKENDS[backend](scene, grid, queue)

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
            "backend": self.backend,
            "edits": self._edits,
        }

    @classmethod
    def _restore(cls, scene, settings, state, events, start_time) -> EventDriven:
        sim = cls.__new__(cls)
        sim._configure(
            scene, settings["record"], settings["queue"], settings["cell_size"], settings.get("backend", "auto")
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
        set_disc = self._backend.set_disc
        for k, i in enumerate(indices.tolist()):
            vx, vy = velocities[k].tolist()
            set_disc(i, vx, vy, None if positions is None else tuple(positions[k].tolist()))

    def _restructure(self, keep: np.ndarray, added: Discs | None, scene: Scene, last=None) -> None:
        """A fresh start at ``time`` from the discs of ``scene`` (``keep``, then ``added``): new cell grid, new
        backend, every disc predicted, as ``EventDriven(scene.discs, box)`` would start (its times then
        shifted by ``time``: the internal clock's epoch is ``time``). The counters, the virial and the
        images of the kept discs (so ``unwrapped_positions`` stay continuous) carry over, and ``last`` (the
        backend's ``last_event()``, when the discs keep their numbers) as the last event."""
        old, box = self._backend, self.box
        grid = self.cell_grid(scene.discs.radii, box, self.cell_size)  # may refuse the new discs: nothing changed
        backend = BACKENDS[old.name](scene, grid, self.queue_kind)
        state = fresh_state(scene, grid)
        state.time = state.epoch = old.time
        for name, value in old.counts().items():
            setattr(state, name, value)
        state.virial, state.max_overlap, state.max_queue = old.virial, old.max_overlap, old.max_queue
        if last is not None:
            state.last_time, state.last_kind, state.last_i, state.last_j = last
        if box.periodic and len(keep):
            unwrapped = old.unwrapped_positions()[keep]
            state.images[: len(keep)] = np.round((unwrapped - scene.discs.positions[: len(keep)]) / box.size)
        backend.start(state)
        self.grid, self._backend, self._jam_mark = grid, backend, None

    def _advance(self, until: float, limit: int | None) -> int:
        log = self._log if self._logging else None
        try:
            if until != INF:
                return self._chunked(until, limit, log)
            return self._advance_open(limit, log)
        except (Interrupted, JammedError):  # raised between two whole events: the state is consistent
            raise
        except BaseException as exc:  # half-way through an event: the state cannot be trusted
            self._broken = f"{type(exc).__name__} at time {self.time!r}"
            raise

    def _advance_open(self, limit: int | None, log) -> int:
        """:meth:`_advance` with no time limit: also stop when no disc can ever hit anything again.

        In a periodic box, discs that never meet cross cells forever. The loop
        therefore returns after ``budget`` cell crossings in a row of calls;
        when a whole budget passed without a collision or wall hit,
        :meth:`_never_again` looks for a proof that none will ever come, and
        the budget doubles if it finds none (so the check costs O(log) calls).
        When it finds one, ``time`` goes back to the last collision or wall hit
        (or to where the call started): the crossings after it changed nothing.
        """
        backend = self._backend
        done, start = 0, self.time
        budget = 64 + 16 * len(self.discs)
        while True:
            crossings = backend.counts()["cell_crossings"]
            k = self._chunked(INF, None if limit is None else limit - done, log, budget)
            done += k
            if done == limit or backend.counts()["cell_crossings"] - crossings < budget:
                return done  # the event limit, or nothing left in the queue
            if k == 0:
                if self._never_again():
                    last = backend.last_event() if done else None  # done > 0: there is one
                    self._rewind(start if last is None else last[0])
                    return done
                budget *= 2

    def _rewind(self, time: float) -> None:
        """Back to ``time``, after a proof that no disc will ever hit anything again (:meth:`_never_again`).

        The discs have crossed cells since ``time``, so the clock alone cannot go back: each disc's cell would
        be one it reaches only later, and after a change of course (``set_velocities``) the predictions would
        scan the wrong neighbours and miss collisions. The backend starts afresh at ``time`` from the discs as
        they are then (what ``EventDriven(sim.snapshot(), box)`` would do), keeping the counters, the virial,
        the periodic images and the last event. O(N), once per proof.
        """
        old = self._backend
        last = old.last_event()
        old.time = time
        now = self.snapshot()
        scene = Scene(now, self.box, self.scene.segments, self.scene.pass_through, check=False)
        self._restructure(np.arange(len(now)), None, scene, last)

    #: A run raises :class:`~discsim.errors.JammedError` after ``jam_events + jam_events_per_disc * N``
    #: physical events in a row at one instant: far more than a finite cascade of simultaneous collisions
    #: (``N (N - 1) / 2`` at most for a touching row), while wedged discs collide there for ever.
    jam_events: int = 10_000
    jam_events_per_disc: int = 100
    _jam_mark: tuple[float, int] | None = None  # (time, physical events) when the clock was last seen there

    def _chunked(self, until: float, limit: int | None, log, crossings: int | None = None) -> int:
        """``backend.advance(until, limit, log, crossings)`` in chunks, watching the clock between them.

        The same result as one call (chunks change nothing in the dynamics), for every backend. Each chunk
        holds at most the jam threshold of physical events; when that many pass, over any number of calls
        (a driver's chunks, ``step()`` after ``step()``), with the clock standing still, the discs are jammed.

        Raises:
            JammedError: naming the jammed discs; the engine is consistent at its last whole event.
        """
        backend = self._backend
        chunk = self.jam_events + self.jam_events_per_disc * len(self.discs)
        done, left = 0, crossings
        while True:
            ask = chunk if limit is None else min(chunk, limit - done)
            if self._jam_mark is None or self._jam_mark[0] != backend.time:
                self._jam_mark = (backend.time, self._units())
            crossed = backend.counts()["cell_crossings"] if crossings is not None else 0
            k = backend.advance(until, ask, log, left)
            done += k
            units = self._units()
            if backend.time != self._jam_mark[0]:
                self._jam_mark = (backend.time, units)
            elif units - self._jam_mark[1] >= chunk:
                raise JammedError(self._jam_message(units - self._jam_mark[1]))
            if k < ask or done == limit:
                return done  # the time or event limit, an empty queue, or the crossings asked for
            if left is not None:
                left -= backend.counts()["cell_crossings"] - crossed
                if left <= 0:
                    return done

    def _jammed_discs(self) -> np.ndarray:
        """The discs of the last event and every disc touching them, transitively (sorted, caller's numbering).

        Touching: centres within the contact distance plus 1e-9 of it, minimum image, collision filter obeyed.
        """
        last = self._backend.last_event()
        if last is None:
            return np.zeros(0, dtype=np.int64)
        seeds = [d for d in last[2:] if d >= 0]
        n = len(self.discs)
        radii = self.discs.radii
        i, j, d = neighbour_pairs(self.positions, 2.0 * float(radii.max()), self.box)
        touch = np.hypot(d[:, 0], d[:, 1]) <= (radii[i] + radii[j]) * (1.0 + 1e-9)
        if self.scene.filtering:
            touch &= ~self.scene.passes(i, j)
        i, j = i[touch], j[touch]
        jammed = np.zeros(n, dtype=bool)
        jammed[seeds] = True
        while True:  # grow the touching cluster around the last event's discs
            grown = jammed.copy()
            grown[j[jammed[i]]] = True
            grown[i[jammed[j]]] = True
            if grown.sum() == jammed.sum():
                return np.flatnonzero(jammed)
            jammed = grown

    def _jam_message(self, events: int) -> str:
        discs = self._jammed_discs().tolist()
        named = ", ".join(map(str, discs[:20])) + (f", ... ({len(discs)} discs)" if len(discs) > 20 else "")
        return (
            f"discs {named} are jammed at time {self.time!r}: wedged against each other or a wall, they made "
            f"{events} collisions and wall hits without the clock moving; give them room (a gap) or velocities "
            "that part them"
        )

    def _never_again(self) -> bool:
        """True if, from now on, no pair of discs can ever meet and no disc hits a wall or segment.

        Only periodic boxes (a moving disc always reaches a wall). A pair can
        never meet when its relative velocity is exactly zero, when its groups
        pass through each other, or when it moves relative to itself only along
        x (or only along y) and its minimum-image gap across that motion exceeds
        the contact distance. Any other pair might meet some day, and the answer is False.
        """
        box, scene = self.box, self.scene
        if not box.periodic or len(self.discs) < 2:
            return box.periodic or not self.velocities.any()
        pos, vel, radii = self.positions, self.velocities, self.discs.radii
        # Discs that drift alike never meet: only pairs of different velocities need a look, so N discs
        # drifting alike cost O(N log N), not O(N^2).
        label = np.unique(vel, axis=0, return_inverse=True)[1].reshape(-1)
        groups = [np.flatnonzero(label == g) for g in range(int(label.max()) + 1)]
        tol = 1e-12 * box.size.max()
        for g, a in enumerate(groups[:-1]):
            b = np.concatenate(groups[g + 1 :])
            dv = vel[b] - vel[a[0]]  # the same for every disc of group a
            still = (dv == 0.0).all(axis=1)  # rows of -0.0 and 0.0 land in two groups
            block = max(1, (1 << 22) // len(b))  # bounds memory: block x |b| pairs at a time
            for start in range(0, len(a), block):
                rows = a[start : start + block]
                gap = box.minimum_image(pos[b][None, :, :] - pos[rows][:, None, :])
                reach = (radii[rows][:, None] + radii[b][None, :]) * (1.0 + 1e-9) + tol
                along_y = (dv[:, 0] == 0.0) & (np.abs(gap[..., 0]) > reach)  # x gap fixed for good
                along_x = (dv[:, 1] == 0.0) & (np.abs(gap[..., 1]) > reach)
                never = still | along_y | along_x
                if scene.filtering:
                    never |= scene.blocked[scene.group[rows][:, None], scene.group[b][None, :]]
                if not never.all():
                    return False
        return True

    # --- the user's protocol -------------------------------------------------------------
    @property
    def backend(self) -> str:
        """The name of the backend that runs the event loop."""
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
        return (self.kinetic_energy() + self._backend.virial / (2.0 * elapsed)) / self.box.area

    def step(self) -> Event | None:
        """Process events up to and including the next collision or wall hit.

        Returns:
            The :class:`~discsim.events.Event` processed, or None if no disc
            will ever hit anything (in a periodic box that is proven when every
            pair drifts alike, or moves relative to itself only along x or only
            along y and misses; see :meth:`_never_again`).
        """
        self._check_usable()
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
