"""The pure-Python backend of the event-driven engine: today's hot loop, with every measured trick.

State lives here in forms that are fast in CPython and nowhere else: per-disc records of six float64
``(x, y, vx, vy, t_ref, radius)`` in one ``bytearray`` read with one :class:`struct.Struct` call (a
neighbour costs one cache line), one static record per cell that each disc points at, cell members as
tuples in tiles of cells with ghost rings, and prediction closures. :meth:`PythonBackend.load` builds them
from an :class:`~discsim.engines.event_driven.state.EventDrivenState` and :meth:`PythonBackend.export` gives
one back, so nothing Python-specific crosses the backend's edge. Measured figures of each trick are in
``docs/performance.md``.

Each moving disc owns at most one pending event in the queue: the earliest of its next wall hit, its next
cell crossing and its next collision with a disc in the 3x3 cells around it. A collision event carries the
partner's collision counter at prediction time and is stale when popped if the partner's counter has moved
on. The owner's own event is replaced whenever the owner is re-predicted, so the queue never holds more than
N events.

The class holds the state and the protocol; its parts are modules beside it: :mod:`.layout` (the records),
:mod:`.predictor` (``predict``, over tiles of cells) and :mod:`.loop` (the hot loop,
:func:`~discsim.engines.event_driven.python.loop.process_events`, which reads top to bottom: pop, validate
the counter, advance the discs involved, resolve, record, re-predict, push).
"""

from __future__ import annotations

import gc
from collections.abc import Callable

import numpy as np

from discsim._interrupt import deferred_interrupt
from discsim.cells import CellGrid
from discsim.engines.event_driven.numbering import fresh_state
from discsim.engines.event_driven.python.layout import (
    _CELL_INDEX,
    _COLLISION,
    _GHOSTS,
    _REBASE_EVENTS,
    _RECORD,
    _RECORD_BYTES,
    _SLOT,
    INF,
    pack_records,
)
from discsim.engines.event_driven.python.loop import process_events
from discsim.engines.event_driven.python.predictor import make_predictor
from discsim.engines.event_driven.state import EventDrivenState
from discsim.events import EventLog
from discsim.physics.dynamics import advance
from discsim.queue import CalendarEventQueue, EventQueue, EventQueueProtocol, HeapEventQueue
from discsim.scene import Scene

__all__ = ["QUEUES", "PythonBackend"]

#: The event queues, by name; all give the same events bit for bit.
QUEUES: dict[str, Callable[[int], EventQueueProtocol[tuple[int, int, int]]]] = {
    "calendar": CalendarEventQueue,
    "sorted": EventQueue,
    "heap": HeapEventQueue,
}


class PythonBackend:
    """The event loop in pure Python, behind :class:`~discsim.engines.event_driven.protocol.Backend`.

    :meth:`start` (a fresh run from the scene's discs at time 0) or :meth:`load` (a run state),
    :meth:`advance` (process events), :meth:`export` (the run state), and cheap reads: ``time``,
    :meth:`counts`, :meth:`positions`, :meth:`unwrapped_positions`, :meth:`velocities`,
    :meth:`last_event`, ``max_queue``, ``max_overlap``, ``virial``, :meth:`queue_size`,
    :meth:`queue_storage`. The front class uses nothing else.

    Args:
        scene: the validated scene.
        grid: the cell grid (cells at least one largest diameter a side).
        queue: the event queue's name, a key of :data:`QUEUES`.
    """

    name = "python"
    # The state (built by load and make_predictor), typed for readers and mypy.
    _queue: EventQueueProtocol[tuple[int, int, int]]
    _predict: Callable[..., None]
    _predictions: Callable[[], int]
    _where: list[tuple]  # each disc's cell record
    _cell_info: list[tuple]  # each cell's static record
    max_queue: int
    max_overlap: float
    time: float

    def __init__(self, scene: Scene, grid: CellGrid, queue: str):
        self.scene = scene
        self.box = scene.box
        self.segments = scene.segments
        self.grid = grid
        self.queue_kind = queue
        self._rebase_every = max(_REBASE_EVENTS, 16 * len(scene))

    # --- the protocol --------------------------------------------------------------------
    def start(self, state: EventDrivenState | None = None) -> None:
        """A fresh run at time 0 from the scene's discs (or from ``state``, a fresh state with an empty queue
        whose clock moved on): every moving disc predicted at the epoch, in internal order."""
        self.load(fresh_state(self.scene, self.grid, read_only=True) if state is None else state)
        predict, moving = self._predict, self._moving
        for i in range(len(moving)):
            if moving[i]:
                predict(i, 0.0, -1)
        self.max_queue = max(self.max_queue, len(self._queue))

    def load(self, state: EventDrivenState) -> None:
        """Take over ``state`` (caller's numbering), building the fast internal forms from it."""
        discs = self.scene.discs
        n = len(discs)
        order = np.asarray(state.order, dtype=np.int64)
        rank = np.empty(n, dtype=np.int64)
        rank[order] = np.arange(n)
        identity = bool(np.array_equal(order, np.arange(n)))
        self._order = order
        self._rank = None if identity else rank
        self._caller_id = list(range(n)) if identity else order.tolist()
        self._radius = discs.radii[order].tolist()
        # Equal masses share one float object, so reading them costs no cache miss.
        shared: dict[float, float] = {}
        self._mass = [shared.setdefault(m, m) for m in discs.masses[order].tolist()]
        # The mass of every disc when all are equal and finite (the common case), else None:
        # the hot loop then skips two per-disc lookups, two cache misses at large N.
        self._one_mass = self._mass[0] if len(shared) == 1 and self._mass[0] != INF else None
        self._moving = np.isfinite(discs.masses[order]).tolist()
        pos, vel = state.ref_positions[order], state.velocities[order]
        self._disc = pack_records(
            pos[:, 0], pos[:, 1], vel[:, 0], vel[:, 1], state.ref_times[order], discs.radii[order]
        )
        self._image_x = state.images[order, 0].tolist()
        self._image_y = state.images[order, 1].tolist()
        self._count = state.collision_counts[order].tolist()
        members = rank[state.cell_members].tolist()
        # One tuple per cell; empty cells share the one empty tuple, so scanning them touches
        # no memory. make_predictor moves them into tiles (see predictor.tile_cells).
        cells, k = [], 0
        for size in state.cell_sizes.tolist():
            cells.append(tuple(members[k : k + size]))
            k += size
        partner = state.kept_partner[order]
        self._kept_time = state.kept_time[order].tolist()
        self._kept_partner = np.where(partner >= 0, rank[np.maximum(partner, 0)], -1).tolist()
        self._kept_stamp = state.kept_stamp[order].tolist()
        self._queue = QUEUES[self.queue_kind](n)
        owners = rank[state.queue_owner].tolist()
        others = np.where(state.queue_kind == _COLLISION, rank[state.queue_other], state.queue_other).tolist()
        kinds, stamps = state.queue_kind.tolist(), state.queue_stamp.tolist()
        for owner, t, kind, other, stamp in zip(owners, state.queue_time.tolist(), kinds, others, stamps):
            self._queue.push(owner, t, (kind, other, stamp))
        self.time = state.time
        self._epoch = state.epoch
        self._since_rebase = state.since_rebase
        self._virial = state.virial
        self.max_overlap = state.max_overlap
        self.max_queue = state.max_queue
        self._counts = {
            "collisions": state.collisions,
            "wall_hits": state.wall_hits,
            "cell_crossings": state.cell_crossings,
            "stale": state.stale,
        }
        if state.last_kind < 0:
            self._last = None
        else:
            i, j = int(rank[state.last_i]), (int(rank[state.last_j]) if state.last_j >= 0 else state.last_j)
            self._last = (state.last_time, state.last_kind, i, j)
        self._predict, self._predictions = make_predictor(self, state.predictions, cells, state.cell[order].tolist())
        # Spins never change in this loop (smooth discs: EventDriven's rule): the angles at load time suffice.
        self._spins, self._angles, self._angle_time = state.spins.copy(), state.angles.copy(), state.time

    def export(self) -> EventDrivenState:
        """The run state, in the caller's numbering (new arrays)."""
        order, n = self._order, len(self._order)

        def caller(values, dtype) -> np.ndarray:
            out = np.empty((n, *np.shape(values)[1:]), dtype=dtype)
            out[order] = values
            return out

        records = np.frombuffer(self._disc, dtype=np.float64).reshape(-1, 6)
        cells = self._cell_members()
        members = np.array([j for m in cells for j in m], dtype=np.int64)
        partner = np.array(self._kept_partner, dtype=np.int64)
        pending: list[tuple[int, float, tuple[int, int, int]]] = []  # (owner, time, payload) of each event
        for o in range(n):
            t, p = self._queue.pending(o)
            if t != INF and p is not None:
                pending.append((o, t, p))
        kinds = np.array([p[0] for _, _, p in pending], dtype=np.int64)
        others = np.array([p[1] for _, _, p in pending], dtype=np.int64)
        last = self._last
        if last is None:
            last_time, last_kind, last_i, last_j = 0.0, -1, -1, -1
        else:
            last_time, last_kind, i, j = last
            last_i, last_j = int(order[i]), int(order[j]) if j >= 0 else j
        return EventDrivenState(
            time=self.time,
            epoch=self._epoch,
            since_rebase=self._since_rebase,
            collisions=self._counts["collisions"],
            wall_hits=self._counts["wall_hits"],
            cell_crossings=self._counts["cell_crossings"],
            stale=self._counts["stale"],
            predictions=self._predictions(),
            virial=self._virial,
            max_overlap=self.max_overlap,
            max_queue=self.max_queue,
            last_time=last_time,
            last_kind=last_kind,
            last_i=last_i,
            last_j=last_j,
            grid_nx=self.grid.nx,
            grid_ny=self.grid.ny,
            ref_positions=caller(records[:, :2], np.float64),
            velocities=caller(records[:, 2:4], np.float64),
            ref_times=caller(records[:, 4], np.float64),
            images=caller(np.column_stack([self._image_x, self._image_y]).reshape(n, 2), np.int64),
            collision_counts=caller(self._count, np.int64),
            cell=caller([here[_CELL_INDEX] for here in self._where], np.int64),
            cell_members=order[members] if len(members) else members,
            cell_sizes=np.array([len(m) for m in cells], dtype=np.int64),
            kept_time=caller(self._kept_time, np.float64),
            kept_partner=caller(np.where(partner >= 0, order[np.maximum(partner, 0)], -1), np.int64),
            kept_stamp=caller(self._kept_stamp, np.int64),
            order=order.copy(),
            queue_owner=order[np.array([o for o, _, _ in pending], dtype=np.int64)],
            queue_time=np.array([t for _, t, _ in pending], dtype=np.float64),
            queue_kind=kinds,
            queue_other=np.where(kinds == _COLLISION, order[np.maximum(others, 0)], others) if len(kinds) else others,
            queue_stamp=np.array([p[2] for _, _, p in pending], dtype=np.int64),
            resting=np.zeros(n, dtype=np.int64),  # this loop runs the default laws only (EventDriven's rule)
            last_collision=np.full(n, -np.inf),
            spins=self._spins.copy(),
            angles=self.turning()[1],
        )

    def advance(self, until: float, limit: int | None, log: EventLog | None, crossings: int | None = None) -> int:
        """Process events with time <= ``until``; stop after ``limit`` physical events (None: no limit).

        Also returns after ``crossings`` cell crossings (None: no such limit): the
        front class ends open-ended runs in a periodic box with it.
        ``log`` receives each physical event (None: nothing recorded). Returns
        the number of physical events (collisions plus wall hits) processed.

        Python's cyclic garbage collector is paused meanwhile (and restored as it
        was): the loop allocates millions of short-lived tuples and never a
        reference cycle, yet each allocation burst would trigger a collection that
        walks memory scattered over the whole system.

        Raises:
            Interrupted: on Ctrl-C, after the event under way: the state is that of
                the last whole event, and a later call goes on exactly.
        """
        limit = -1 if limit is None else limit
        crossings = -1 if crossings is None else crossings
        collecting = gc.isenabled()
        gc.disable()
        try:
            done = 0
            while True:
                # Ctrl-C ends the loop at a whole event; a handler of the program's own may let it go on.
                with deferred_interrupt() as interrupted:
                    done += process_events(
                        self, until, limit if limit < 0 else limit - done, crossings, log, interrupted
                    )
                if not interrupted[0]:
                    return done
        finally:
            if collecting:
                gc.enable()

    def set_disc(self, i: int, vx: float, vy: float, position: tuple[float, float] | None = None) -> None:
        """Give moving disc ``i`` (caller's numbering) velocity ``(vx, vy)`` at ``time``, and ``position`` if given.

        Its path restarts at ``time``; its collision counter moves on, so every event predicted against it
        is stale; it changes cell if its position did; and it alone is re-predicted (its prediction scans
        every neighbour, and any other disc's pending event stays valid or is stale).
        ``position`` must lie in the box (wrapped); the caller has checked the disc fits there.
        """
        k = i if self._rank is None else int(self._rank[i])
        t = self.time - self._epoch
        offset = k * _RECORD_BYTES
        xi, yi, vxi, vyi, ti, ri = _RECORD.unpack_from(self._disc, offset)
        if position is None:
            dt = t - ti
            xi += vxi * dt
            yi += vyi * dt
        else:
            xi, yi = float(position[0]), float(position[1])
            cell = int(self.grid.cells_of(np.array([[xi, yi]]))[0])
            if cell != self._where[k][_CELL_INDEX]:
                self._move(k, cell)
        _RECORD.pack_into(self._disc, offset, xi, yi, float(vx), float(vy), t, ri)
        self._count[k] += 1
        self._predict(k, t, -1)
        self.max_queue = max(self.max_queue, len(self._queue))

    def _move(self, k: int, cell: int) -> None:
        """Move disc ``k`` (internal numbering) from its cell to ``cell``, in every ghost copy too."""
        here = self._where[k]
        tile, slot = here[1], here[_SLOT]
        others = tuple(m for m in tile[slot] if m != k)
        tile[slot] = others
        for tile, slot in here[_GHOSTS]:
            tile[slot] = others
        here = self._where[k] = self._cell_info[cell]
        tile, slot = here[1], here[_SLOT]
        others = tile[slot] + (k,)
        tile[slot] = others
        for tile, slot in here[_GHOSTS]:
            tile[slot] = others

    # --- cheap reads -----------------------------------------------------------------------
    def counts(self) -> dict[str, int]:
        """``collisions``, ``wall_hits``, ``cell_crossings``, ``stale``, ``predictions``."""
        return {**self._counts, "predictions": self._predictions()}

    @property
    def dissipated(self) -> float:
        """Kinetic energy lost: none (this loop runs the default laws only: elastic, no gravity)."""
        return 0.0

    def turning(self) -> tuple[np.ndarray, np.ndarray]:
        """``(spins, angles)``, each ``(N,)`` at ``time`` in the caller's numbering (new arrays): the spins as
        loaded (smooth discs never change them), the angles turned on since."""
        return self._spins.copy(), self._angles + self._spins * (self.time - self._angle_time)

    def resting(self) -> np.ndarray:
        """``(N,)`` bool: no disc rests without gravity."""
        return np.zeros(len(self._count), dtype=bool)

    def disc_counts(self) -> np.ndarray:
        """``(N,)`` each disc's collision counter, in the caller's numbering (a new array)."""
        out = np.empty(len(self._order), dtype=np.int64)
        out[self._order] = self._count
        return out

    @property
    def virial(self) -> float:
        """Sum over collisions of ``dp_i . (r_i - r_j)`` since the start (for the pressure)."""
        return self._virial

    def _records(self) -> np.ndarray:
        """``(N, 6)`` records x, y, vx, vy, t_ref, radius in the caller's numbering (a copy)."""
        records = np.frombuffer(self._disc, dtype=np.float64).reshape(-1, 6)
        return records[self._rank] if self._rank is not None else records.copy()

    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, not wrapped."""
        t = self.time - self._epoch
        rx, ry, vx, vy, tr, _ = self._records().T
        x, y, _, _ = advance(rx, ry, vx, vy, t - tr)
        return np.column_stack([x, y]).reshape(-1, 2)

    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, each disc followed across the periodic edges."""
        images = np.column_stack([self._image_x, self._image_y]).reshape(-1, 2).astype(np.float64)
        if self._rank is not None:
            images = images[self._rank]
        return self.positions() + images * np.array([self.box.width, self.box.height])

    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time``."""
        return self._records()[:, 2:4].copy()

    def last_event(self) -> tuple[float, int, int, int] | None:
        """``(time, kind, i, j)`` of the last physical event in the caller's numbering, or None."""
        if self._last is None:
            return None
        t, kind, i, j = self._last
        caller = self._caller_id
        return t, kind, caller[i], caller[j] if j >= 0 else j

    def queue_size(self) -> int:
        """Events pending now (at most N)."""
        return len(self._queue)

    def queue_storage(self) -> int:
        """Entries the queue holds in memory, replaced (dead) ones included."""
        return self._queue.storage()

    def _cell_members(self) -> list[tuple[int, ...]]:
        """The discs in each cell (internal numbering; a new list, indexed as the grid's cells)."""
        return [here[1][here[_SLOT]] for here in self._cell_info]

    def _check(self) -> None:
        """Assert the backend's own invariants (queue structure, ghost copies of cells); O(N)."""
        self._queue._check()
        assert len(self._queue) <= len(self._order)
        for here in self._cell_info:
            members = here[1][here[_SLOT]]
            assert all(tile[slot] is members for tile, slot in here[_GHOSTS]), "a ghost copy is out of date"
            assert all(self._where[i] is here for i in members), "a disc points at another cell's record"

    # --- prediction ------------------------------------------------------------------------
    # --- the hot loop ----------------------------------------------------------------------
    def _rebase(self, shift: float) -> None:
        """Move the epoch of the internal clock forward by ``shift`` (the current internal time).

        Positions are ``r + v (t - t_ref)`` with times measured from the epoch;
        keeping those times small keeps their resolution, and so the contact
        geometry, at the roundoff of the first steps of the run however long
        it goes on. O(N log N); the hot loop calls it every ``_rebase_every``
        physical events, a count that does not depend on how a run is split.
        """
        records = np.frombuffer(self._disc, dtype=np.float64).reshape(-1, 6)  # a view: edits in place
        records[:, 4] -= shift
        self._kept_time[:] = [t - shift for t in self._kept_time]
        self._queue.shift_times(shift)
        self._epoch += shift
