"""The compiled backend of the event-driven engine: the Python backend's algorithm, compiled by numba.

State lives in plain arrays in the internal numbering (see :mod:`discsim.engines.event_driven.numba.loop`
for their layout); :meth:`NumbaBackend.load` builds them from an
:class:`~discsim.engines.event_driven.state.EventDrivenState` and :meth:`NumbaBackend.export` gives one
back, the same state the Python backend would export after the same events. The loop runs in chunks of at
most ``BUDGET`` queue pops, so Ctrl-C is seen within milliseconds and lands between two whole events.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from discsim._interrupt import deferred_interrupt
from discsim.cells import CellGrid
from discsim.engines.event_driven.numbering import fresh_state
from discsim.engines.event_driven.state import EventDrivenState
from discsim.events import EVENT_DTYPE, EventKind, EventLog
from discsim.laws import Laws
from discsim.physics import dynamics
from discsim.scene import Scene

__all__ = ["NumbaBackend"]

#: Queue pops per call of the compiled loop: how soon Ctrl-C is seen (about 10-50 ms of work).
BUDGET = 1 << 16
#: Rows of the buffer the compiled loop writes the event log into, per call (0.1 MB: a streamed run's
#: memory stays flat and small).
LOG_ROWS = 1 << 10
# Physical events between moves of the internal clock's epoch (as the Python backend).
_REBASE_EVENTS = 1 << 18
_COLLISION = int(EventKind.COLLISION)


def _loop():
    """The compiled functions (imported on first use: importing numba takes a while)."""
    from discsim.engines.event_driven.numba import loop

    return loop


class NumbaBackend:
    """The event loop compiled by numba, behind :class:`~discsim.engines.event_driven.protocol.Backend`.

    Args:
        scene: the validated scene.
        grid: the cell grid (cells at least one largest diameter a side).
        queue: the queue the caller asked for; this backend always uses its array-based queue (each disc's
            pending time and a binary heap of blocks of discs), which pops events in the same ``(time, disc)``
            order as every Python queue.
        law_of_motion, collision_law: other physics for the loop (modules with the functions of
            :mod:`discsim.physics.dynamics` and :mod:`discsim.physics.laws`; None: free flight and the elastic
            law), compiled into it by :func:`~discsim.engines.event_driven.numba.loop.with_physics`. No engine
            passes them yet: ``docs/adding-physics.md`` shows a test that does.
        interpreted: run the same loop in the interpreter, compiled by nothing (``name`` is then
            ``"python"``): how the pure-Python backend runs a law of motion or a collision law its own loop
            does not inline, or laws other than the defaults; it needs no numba, and gives the compiled loop's
            events bit for bit.
        laws: gravity, restitution, the TC time and the rest speed (:class:`~discsim.laws.Laws`; None: the
            defaults), numbers the loop reads at run time (one compiled loop serves every value).
    """

    name = "numba"

    def __init__(
        self,
        scene: Scene,
        grid: CellGrid,
        queue: str,
        law_of_motion=None,
        collision_law=None,
        *,
        interpreted=False,
        laws: Laws | None = None,
    ):
        self.scene = scene
        self.laws = laws or Laws()
        self.box = scene.box
        self.grid = grid
        self.queue_kind = queue
        self._rebase_every = max(_REBASE_EVENTS, 16 * len(scene))
        self._lp = _loop()
        self._law_of_motion = law_of_motion or dynamics
        if law_of_motion is not None or collision_law is not None or interpreted:
            self._lp = SimpleNamespace(**self._lp.with_physics(law_of_motion, collision_law, interpreted=interpreted))
        if interpreted:
            self.name = "python"
        box = self.box
        nx, ny = grid.nx, grid.ny
        # The cells' edges: x of the columns' left sides and the box's width, then y of the rows' lower sides
        # and the box's height, then the laws' numbers (one array: a compiled call passes each array as seven
        # words, and a call of more than 30 arguments cannot be inlined: CPython passes them as a tuple).
        self._edges = np.concatenate(
            [
                np.arange(nx) * grid.lx,
                [box.width],
                np.arange(ny) * grid.ly,
                [box.height],
                self.laws.array(scene.discs.radii),
            ]
        )
        segments = scene.segments
        if segments:
            self._seg = np.array([[*s.p0.tolist(), *s.p1.tolist()] for s in segments], dtype=np.float64)
            reach = float(np.max(scene.discs.radii)) if len(scene) else 0.0
            near = grid.segments_by_cell(segments, reach)
        else:
            self._seg = np.zeros((0, 4))
            near = [()] * len(grid)
        sizes = np.array([len(s) for s in near], dtype=np.int64)
        self._seg_start = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self._seg_idx = np.array([k for s in near for k in s], dtype=np.int64)
        self._events: tuple[np.ndarray, ...] | None = None  # the log buffer, made on the first recorded run

    # --- the protocol --------------------------------------------------------------------
    def start(self, state: EventDrivenState | None = None) -> None:
        """A fresh run at time 0 from the scene's discs (or from ``state``, a fresh state with an empty queue
        whose clock moved on): every moving disc predicted at the epoch, in internal order."""
        self.load(fresh_state(self.scene, self.grid) if state is None else state)
        carried = int(self._ints[self._lp.I_MAXQ])
        self._lp.predict_all(*self._predict_args())
        self._ints[self._lp.I_MAXQ] = max(carried, int(self._ints[self._lp.I_MAXQ]))

    def load(self, state: EventDrivenState) -> None:
        """Take over ``state`` (caller's numbering), building the internal arrays from it."""
        lp, discs = self._lp, self.scene.discs
        n = len(discs)
        order = np.asarray(state.order, dtype=np.int64)
        rank = np.empty(n, dtype=np.int64)
        rank[order] = np.arange(n)
        self._order = order.astype(np.int32)  # internal disc k is the caller's disc order[k] (also in the log)
        rec = np.empty((n, 8))
        rec[:, 0:2] = state.ref_positions[order]
        rec[:, 2:4] = state.velocities[order]
        rec[:, 4] = state.ref_times[order]
        rec[:, 5] = discs.radii[order]
        rec[:, 6] = discs.masses[order]
        rec[:, 7] = state.kept_time[order]
        self._rec = rec
        self._count = state.collision_counts[order].astype(np.int64)
        self._images = state.images[order].astype(np.int32)  # box lengths crossed: int32 holds 2^31 laps
        partner = state.kept_partner[order]
        self._kept_partner = np.where(partner >= 0, rank[np.maximum(partner, 0)], -1).astype(np.int32)
        self._kept_stamp = state.kept_stamp[order].astype(np.int64)
        self._cell = state.cell[order].astype(np.int32)
        n_cells = len(self.grid)
        # Disc and cell indices are int32 (grids hold at most 4 N + 9 cells): a smaller state, fewer misses.
        self._head = np.full(n_cells, -1, dtype=np.int32)
        self._nxt = np.full(n, -1, dtype=np.int32)
        members = rank[state.cell_members] if n else np.zeros(0, dtype=np.int64)
        lp.link(members, state.cell_sizes.astype(np.int64), self._head, self._nxt)
        # The queue: one slot per disc (time, kind, other, stamp), and the heap of blocks of discs.
        owners = rank[state.queue_owner] if len(state.queue_owner) else np.zeros(0, dtype=np.int64)
        self._qk = np.zeros(n, dtype=np.int8)
        self._qo = np.zeros(n, dtype=np.int32)
        self._qs = np.zeros(n, dtype=np.int64)
        self._qk[owners] = state.queue_kind
        collision = state.queue_kind == _COLLISION
        self._qo[owners] = np.where(collision, rank[np.where(collision, state.queue_other, 0)], state.queue_other)
        self._qs[owners] = state.queue_stamp
        n_blocks = (n + lp.BLOCK - 1) >> lp.BLOCK_SHIFT
        self._qt = np.full(n_blocks << lp.BLOCK_SHIFT, np.inf)  # padded to whole blocks with discs of no event
        self._qt[owners] = state.queue_time
        self._bheap = np.zeros(n_blocks, dtype=np.int32)
        self._bht = np.zeros(n_blocks)
        self._bpos = np.zeros(n_blocks, dtype=np.int32)
        self._barg = np.zeros(n_blocks, dtype=np.int32)
        lp.reblock(self._qt, self._bheap, self._bht, self._bpos, self._barg)
        ints = self._ints = np.zeros(lp.N_INTS, dtype=np.int64)
        floats = self._floats = np.zeros(lp.N_FLOATS)
        ints[lp.I_SIZE] = len(owners)
        ints[lp.I_PRED] = state.predictions
        ints[lp.I_COLL] = state.collisions
        ints[lp.I_WALL] = state.wall_hits
        ints[lp.I_CROSS] = state.cell_crossings
        ints[lp.I_STALE] = state.stale
        ints[lp.I_SINCE] = state.since_rebase
        ints[lp.I_MAXQ] = state.max_queue
        ints[lp.I_LKIND] = state.last_kind
        if state.last_kind >= 0:
            ints[lp.I_LI] = rank[state.last_i]
            ints[lp.I_LJ] = rank[state.last_j] if state.last_j >= 0 else state.last_j
        else:
            ints[lp.I_LI] = ints[lp.I_LJ] = -1
        floats[lp.F_EPOCH] = state.epoch
        floats[lp.F_VIRIAL] = state.virial
        floats[lp.F_OVERLAP] = state.max_overlap
        floats[lp.F_TIME] = state.time
        floats[lp.F_LTIME] = state.last_time
        floats[lp.F_LOST] = state.dissipated
        ints[lp.I_RESTS] = state.rests
        self._rest = state.resting[order].astype(np.int8)
        self._tlast = state.last_collision[order].astype(np.float64)
        scene = self.scene
        self._egroup = scene.group[order].astype(np.int64) if len(scene) else np.zeros(1, dtype=np.int64)
        self._etab = self.laws.table(np.unique(scene.discs.groups))
        filtering = bool(scene.filtering)  # no groups: the loop filters nothing
        self._group = scene.group[order].astype(np.int64) if filtering else np.zeros(0, dtype=np.int64)
        self._blocked = np.asarray(scene.blocked, dtype=np.bool_) if filtering else np.zeros((1, 1), np.bool_)

    def export(self) -> EventDrivenState:
        """The run state, in the caller's numbering (new arrays)."""
        lp, order, n = self._lp, self._order, len(self._order)

        def caller(values) -> np.ndarray:
            values = np.asarray(values)
            out = np.empty(values.shape, dtype=np.float64 if values.dtype.kind == "f" else np.int64)
            out[order] = values
            return out

        rec, ints, floats = self._rec, self._ints, self._floats
        members = np.zeros(n, dtype=np.int64)
        sizes = np.zeros(len(self.grid), dtype=np.int64)
        lp.unlink(self._head, self._nxt, members, sizes)
        owners = np.flatnonzero(self._qt[:n] != np.inf)
        kinds = self._qk[owners].astype(np.int64)
        others = self._qo[owners].astype(np.int64)
        partner = self._kept_partner
        if ints[lp.I_LKIND] < 0:
            last = (0.0, -1, -1, -1)
        else:
            i, j = int(ints[lp.I_LI]), int(ints[lp.I_LJ])
            last = (float(floats[lp.F_LTIME]), int(ints[lp.I_LKIND]), int(order[i]), int(order[j]) if j >= 0 else j)
        return EventDrivenState(
            time=float(floats[lp.F_TIME]),
            epoch=float(floats[lp.F_EPOCH]),
            since_rebase=int(ints[lp.I_SINCE]),
            collisions=int(ints[lp.I_COLL]),
            wall_hits=int(ints[lp.I_WALL]),
            cell_crossings=int(ints[lp.I_CROSS]),
            stale=int(ints[lp.I_STALE]),
            predictions=int(ints[lp.I_PRED]),
            virial=float(floats[lp.F_VIRIAL]),
            max_overlap=float(floats[lp.F_OVERLAP]),
            max_queue=int(ints[lp.I_MAXQ]),
            last_time=last[0],
            last_kind=last[1],
            last_i=last[2],
            last_j=last[3],
            grid_nx=self.grid.nx,
            grid_ny=self.grid.ny,
            ref_positions=caller(rec[:, 0:2]),
            velocities=caller(rec[:, 2:4]),
            ref_times=caller(rec[:, 4]),
            images=caller(self._images),
            collision_counts=caller(self._count),
            cell=caller(self._cell),
            cell_members=order[members].astype(np.int64),
            cell_sizes=sizes,
            kept_time=caller(rec[:, 7]),
            kept_partner=caller(np.where(partner >= 0, order[np.maximum(partner, 0)], -1)),
            kept_stamp=caller(self._kept_stamp),
            order=order.astype(np.int64),
            queue_owner=order[owners].astype(np.int64),
            queue_time=self._qt[owners],
            queue_kind=kinds,
            queue_other=np.where(kinds == _COLLISION, order[np.where(kinds == _COLLISION, others, 0)], others),
            queue_stamp=self._qs[owners].copy(),
            resting=caller(self._rest),
            last_collision=caller(self._tlast),
            dissipated=float(floats[lp.F_LOST]),
            rests=int(ints[lp.I_RESTS]),
        )

    def advance(self, until: float, limit: int | None, log: EventLog | None, crossings: int | None = None) -> int:
        """Process events with time <= ``until``; stop after ``limit`` physical events (None: no limit).

        As :meth:`discsim.engines.event_driven.python.PythonBackend.advance`: also returns after
        ``crossings`` cell crossings (None: no such limit); ``log`` receives each physical event.

        Raises:
            Interrupted: on Ctrl-C, after the event under way.
        """
        lp = self._lp
        limit = -1 if limit is None else int(limit)
        crossings = -1 if crossings is None else int(crossings)
        recording = log is not None
        if recording and self._events is None:
            self._events = (
                np.empty(LOG_ROWS),
                np.empty(LOG_ROWS, dtype=np.int8),
                np.empty(LOG_ROWS, dtype=np.int64),
                np.empty(LOG_ROWS, dtype=np.int64),
                np.empty((LOG_ROWS, 8)),
            )
        events: tuple[np.ndarray, ...] = self._events if self._events is not None and recording else _NO_EVENTS
        args = self._loop_args()
        done = 0
        while True:
            with deferred_interrupt() as interrupted:
                while True:
                    k, crossed, logged, why = lp.run_events(
                        float(until),
                        limit if limit < 0 else limit - done,
                        crossings,
                        BUDGET,
                        self._rebase_every,
                        recording,
                        *args,
                        *events,
                    )
                    done += k
                    if logged and log is not None:  # logged > 0 only when recording
                        log.extend(_records(events, logged))
                    if crossings >= 0:
                        crossings -= crossed
                    if why != lp.MORE or interrupted[0]:
                        break
            if not interrupted[0]:
                return done

    def set_disc(self, i: int, vx: float, vy: float, position: tuple[float, float] | None = None) -> None:
        """As :meth:`discsim.engines.event_driven.python.PythonBackend.set_disc`: restart moving disc ``i``'s
        path at ``time`` with ``(vx, vy)`` (and ``position``, in the box), stale every event predicted against
        it, move it to its new cell and re-predict it alone."""
        lp, rec = self._lp, self._rec
        k = int(np.flatnonzero(self._order == i)[0])
        t = self.time - float(self._floats[lp.F_EPOCH])
        if position is None:
            falls = self.laws.falls and rec[k, 6] != np.inf and self._rest[k] == 0
            x, y, _, _ = self._law_of_motion.advance(
                float(rec[k, 0]), float(rec[k, 1]), float(rec[k, 2]), float(rec[k, 3]), t - float(rec[k, 4]),
                *(self.laws.gravity if falls else (0.0, 0.0)),
            )
            cell = int(self._cell[k])
        else:
            x, y = float(position[0]), float(position[1])
            cell = int(self.grid.cells_of(np.array([[x, y]]))[0])
        lp.set_disc(k, x, y, float(vx), float(vy), cell, t, *self._predict_args())

    # --- cheap reads -----------------------------------------------------------------------
    @property
    def time(self) -> float:
        return float(self._floats[self._lp.F_TIME])

    @time.setter
    def time(self, value: float) -> None:
        self._floats[self._lp.F_TIME] = value

    @property
    def max_overlap(self) -> float:
        return float(self._floats[self._lp.F_OVERLAP])

    @max_overlap.setter
    def max_overlap(self, value: float) -> None:
        self._floats[self._lp.F_OVERLAP] = value

    @property
    def max_queue(self) -> int:
        return int(self._ints[self._lp.I_MAXQ])

    @property
    def virial(self) -> float:
        """Sum over collisions of ``dp_i . (r_i - r_j)`` since the start (for the pressure)."""
        return float(self._floats[self._lp.F_VIRIAL])

    def counts(self) -> dict[str, int]:
        """``collisions``, ``wall_hits``, ``cell_crossings``, ``stale``, ``predictions`` (and ``rests``, discs
        put to rest, under gravity)."""
        lp, ints = self._lp, self._ints
        counts = {
            "collisions": int(ints[lp.I_COLL]),
            "wall_hits": int(ints[lp.I_WALL]),
            "cell_crossings": int(ints[lp.I_CROSS]),
            "stale": int(ints[lp.I_STALE]),
            "predictions": int(ints[lp.I_PRED]),
        }
        if self.laws.falls:
            counts["rests"] = int(ints[lp.I_RESTS])
        return counts

    @property
    def dissipated(self) -> float:
        """Kinetic energy lost in collisions (restitution) and by discs coming to rest, since the start."""
        return float(self._floats[self._lp.F_LOST])

    def resting(self) -> np.ndarray:
        """``(N,)`` bool: the discs at rest (under gravity), in the caller's numbering."""
        return self._rest[self._rank()].astype(bool)

    def disc_counts(self) -> np.ndarray:
        """``(N,)`` each disc's collision counter, in the caller's numbering (a new array)."""
        out = np.empty(len(self._order), dtype=np.int64)
        out[self._order] = self._count
        return out

    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, not wrapped."""
        x, y, _, _ = self._now()
        return np.column_stack([x, y]).reshape(-1, 2)

    def _now(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Every disc's ``(x, y, vx, vy)`` at ``time``, in the caller's numbering (the discs that fall under
        gravity advanced with it)."""
        t = self.time - float(self._floats[self._lp.F_EPOCH])
        rank = self._rank()
        rx, ry, vx, vy, tr = self._rec[rank, :5].T
        advance = self._law_of_motion.advance
        x, y, vx, vy = advance(rx, ry, vx, vy, t - tr)
        if self.laws.falls:
            falls = (self._rec[rank, 6] != np.inf) & (self._rest[rank] == 0)
            fx, fy, fvx, fvy = advance(rx, ry, self._rec[rank, 2], self._rec[rank, 3], t - tr, *self.laws.gravity)
            x, y, vx, vy = (np.where(falls, f, v) for f, v in ((fx, x), (fy, y), (fvx, vx), (fvy, vy)))
        return x, y, vx, vy

    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, each disc followed across the periodic edges."""
        images = self._images[self._rank()].astype(np.float64)
        return self.positions() + images * np.array([self.box.width, self.box.height])

    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time``."""
        _, _, vx, vy = self._now()
        return np.column_stack([vx, vy]).reshape(-1, 2)

    def last_event(self) -> tuple[float, int, int, int] | None:
        """``(time, kind, i, j)`` of the last physical event in the caller's numbering, or None."""
        lp, ints = self._lp, self._ints
        if ints[lp.I_LKIND] < 0:
            return None
        i, j = int(ints[lp.I_LI]), int(ints[lp.I_LJ])
        order = self._order
        return float(self._floats[lp.F_LTIME]), int(ints[lp.I_LKIND]), int(order[i]), int(order[j]) if j >= 0 else j

    def _rank(self) -> np.ndarray:
        """Internal number of each caller's disc, ``(N,)`` (built when asked: O(N), as every read that needs it)."""
        rank = np.empty_like(self._order)
        rank[self._order] = np.arange(len(self._order))
        return rank

    def nbytes(self) -> int:
        """Bytes of the run state's arrays (per disc, per cell and the queue; not the log buffer)."""
        arrays = (
            self._rec, self._count, self._images, self._kept_partner, self._kept_stamp, self._cell,
            self._head, self._nxt, self._qk, self._qo, self._qs,
            self._qt, self._bheap, self._bht, self._bpos, self._barg, self._order, self._group,
            self._rest, self._tlast, self._egroup,
        )  # fmt: skip
        return sum(a.nbytes for a in arrays)

    def queue_size(self) -> int:
        """Events pending now (at most N)."""
        return int(self._ints[self._lp.I_SIZE])

    def queue_storage(self) -> int:
        """Entries the queue holds: one slot per pending event (no dead entries)."""
        return self.queue_size()

    def _check(self) -> None:
        """Assert the backend's own invariants (each block's earliest event, the heap of blocks, linked cells); O(N)."""
        qt, n = self._qt, len(self._order)
        assert np.isinf(qt[n:]).all() and np.count_nonzero(qt != np.inf) == self.queue_size(), "queue size out of date"
        blocks = qt.reshape(-1, self._lp.BLOCK)
        first = blocks.min(axis=1)
        assert np.array_equal(self._bht[self._bpos], first), "a block's time out of date"
        earliest = np.argmax(blocks == first[:, None], axis=1) + np.arange(len(blocks)) * self._lp.BLOCK
        finite = first != np.inf
        assert np.array_equal(self._barg[finite], earliest[finite]), "a block's earliest disc out of date"
        heap, times = self._bheap, self._bht
        assert np.array_equal(heap[self._bpos], np.arange(len(heap))), "heap positions out of date"
        parent = (np.arange(1, len(heap)) - 1) >> 1
        pt, ct, po, co = times[parent], times[1:], heap[parent], heap[1:]
        ordered = (pt < ct) | ((pt == ct) & (po < co))
        assert ordered.all(), "heap order broken"
        members = np.zeros(len(self._order), dtype=np.int64)
        sizes = np.zeros(len(self.grid), dtype=np.int64)
        self._lp.unlink(self._head, self._nxt, members, sizes)
        assert np.array_equal(np.repeat(np.arange(len(sizes)), sizes), self._cell[members]), "cells out of date"

    # --- argument lists of the compiled functions --------------------------------------------
    def _geometry(self) -> tuple:
        grid, box = self.grid, self.box
        return (grid.nx, grid.ny, bool(box.periodic), self._edges)

    def _filter(self) -> tuple:
        return (self._seg, self._seg_start, self._seg_idx, self._group, self._blocked, self._rest)

    def _queue(self) -> tuple:
        return (self._qt, self._bheap, self._bht, self._bpos, self._barg, self._qk, self._qo, self._qs, self._ints)

    def _predict_args(self) -> tuple:
        return (
            self._rec, self._count, self._kept_partner, self._kept_stamp, self._cell, self._head, self._nxt,
            *self._geometry(), *self._filter(), *self._queue(),
        )  # fmt: skip

    def _loop_args(self) -> tuple:
        return (
            self._rec, self._count, self._order, self._images, self._kept_partner, self._kept_stamp,
            self._cell, self._head, self._nxt,
            *self._geometry(), *self._filter(), *self._queue(), self._floats, self._etab, self._egroup, self._tlast,
        )  # fmt: skip


_NO_EVENTS = (
    np.empty(0),
    np.empty(0, dtype=np.int8),
    np.empty(0, dtype=np.int64),
    np.empty(0, dtype=np.int64),
    np.empty((0, 8)),
)


def _records(events, k: int) -> np.ndarray:
    """The first ``k`` rows of the loop's log buffer as an :data:`~discsim.events.EVENT_DTYPE` array."""
    ev_t, ev_kind, ev_i, ev_j, ev_f = events
    out = np.empty(k, dtype=EVENT_DTYPE)
    out["time"] = ev_t[:k]
    out["kind"] = ev_kind[:k]
    out["i"] = ev_i[:k]
    out["j"] = ev_j[:k]
    for c, name in enumerate(("xi", "yi", "vxi", "vyi", "xj", "yj", "vxj", "vyj")):
        out[name] = ev_f[:k, c]
    return out
