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
from discsim.engines.event_driven.numba.reads import CompiledReads
from discsim.engines.event_driven.numbering import fresh_state
from discsim.engines.event_driven.state import EventDrivenState
from discsim.errors import InvalidArgumentError
from discsim.events import EVENT_DTYPE, SENSED, SPIN_DTYPE, EventKind, EventLog
from discsim.laws import Laws
from discsim.physics import dynamics
from discsim.scene import Scene
from discsim.sensors import inside_table, on_periodic_edge, sensor_rows

__all__ = ["NumbaBackend"]

#: Queue pops per call of the compiled loop: how soon Ctrl-C is seen (about 10-50 ms of work).
BUDGET = 1 << 16
# Physical events between moves of the internal clock's epoch (as the Python backend).
_REBASE_EVENTS = 1 << 18
_COLLISION = int(EventKind.COLLISION)


def _loop():
    """The compiled functions (imported on first use: importing numba takes a while)."""
    from discsim.engines.event_driven.numba import loop

    return loop


def _moving():
    """The compiled piston's layout (:mod:`~discsim.engines.event_driven.numba.moving`)."""
    from discsim.engines.event_driven.numba import moving

    return moving


def _variants():
    """The builders of the loop over other physics (:mod:`~discsim.engines.event_driven.numba.variants`)."""
    from discsim.engines.event_driven.numba import variants

    return variants


class NumbaBackend(CompiledReads):
    """The event loop compiled by numba, behind :class:`~discsim.engines.event_driven.protocol.Backend`.

    Args:
        scene: the validated scene.
        grid: the cell grid (cells at least one largest diameter a side).
        queue: the queue the caller asked for; this backend always uses its array-based queue (each disc's
            pending time and a binary heap of blocks of discs), which pops events in the same ``(time, disc)``
            order as every Python queue.
        law_of_motion, collision_law: other physics for the loop (modules with the functions of
            :mod:`discsim.physics.dynamics` and :mod:`discsim.physics.laws`; None: free flight and the elastic
            law), compiled into it by :func:`~discsim.engines.event_driven.numba.variants.with_physics`. No engine
            passes them yet: ``docs/adding-physics.md`` shows a test that does.
        interpreted: run the same loop in the interpreter, compiled by nothing (``name`` is then
            ``"python"``): how the pure-Python backend runs a law of motion or a collision law its own loop
            does not inline, or laws other than the defaults; it needs no numba, and gives the compiled loop's
            events bit for bit.
        laws: gravity, restitution, the TC time and the rest speed (:class:`~discsim.laws.Laws`; None: the
            defaults), numbers the loop reads at run time (one compiled loop serves every value).

    Raises:
        InvalidArgumentError: a ``law_of_motion`` or ``collision_law`` given with laws other than the defaults
            (the loop that reads the laws is compiled over the built-in parts only), naming both.
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
        if laws is not None and not laws.default and (law_of_motion is not None or collision_law is not None):
            given = ", ".join(
                f"{name}={getattr(part, '__name__', type(part).__name__)}"
                for name, part in (("law_of_motion", law_of_motion), ("collision_law", collision_law))
                if part is not None
            )
            msg = (
                f"{given} runs with the default laws only (free flight, elastic, smooth), and these laws are "
                f"not: {_spelled(laws)}; compile that law with the defaults, or use the built-in laws alone"
            )
            raise InvalidArgumentError(msg)
        self.scene = scene
        self.laws = laws or Laws()
        self.box = scene.box
        self.grid = grid
        self.queue_kind = queue
        self._rebase_every = max(_REBASE_EVENTS, 16 * len(scene))
        self._lp = _loop()
        self._law_of_motion = law_of_motion or dynamics
        if not self.laws.default or scene.sensors or scene.moving or scene.piston is not None:  # the loop that
            # reads the laws (one for every value of them), the sensors, moving segments and the piston
            self._lp = SimpleNamespace(**_variants().with_laws(interpreted=interpreted))
        elif law_of_motion is not None or collision_law is not None or interpreted:
            variants = _variants()
            self._lp = SimpleNamespace(**variants.with_physics(law_of_motion, collision_law, interpreted=interpreted))
        self.name = "python" if interpreted else "numba"
        box = self.box
        nx, ny = grid.nx, grid.ny
        # The cells' edges: x of the columns' left sides and the box's width, then y of the rows' lower sides
        # and the box's height, then the laws' numbers, then the piston's if there is one (moving.SLOTS; one array:
        # a compiled call passes each array as seven words, and a call of more than 30 arguments cannot be inlined:
        # CPython passes them as a tuple).
        self._edges = np.concatenate(
            [
                np.arange(nx) * grid.lx,
                [box.width],
                np.arange(ny) * grid.ly,
                [box.height],
                self.laws.array(scene.discs.radii),
                np.zeros(0 if scene.piston is None else _moving().SLOTS),
            ]
        )
        # The segments' rows (end points now, shape code 0, -, velocity, end points at time 0), then the sensors'
        # (numbers, shape code, index: sensor_rows), with the rows each cell must check: the segments within reach
        # of it (a moving one: every cell), the regions over it, every trip wire.
        segments, sensors = scene.segments, scene.sensors
        self._seg = np.zeros((len(segments) + len(sensors), 12))
        near: list = [()] * len(grid)
        if segments:
            ends = [[*s.p0.tolist(), *s.p1.tolist()] for s in segments]
            self._seg[: len(segments), :4] = self._seg[: len(segments), 8:] = ends
            self._seg[: len(segments), 6:8] = [s.velocity.tolist() for s in segments]
            reach = float(np.max(scene.discs.radii)) if len(scene) else 0.0
            near = grid.segments_by_cell(segments, reach)
            everywhere = [k for k, s in enumerate(segments) if s.moving]
            if everywhere:
                near = [tuple(sorted({*cell, *everywhere})) for cell in near]
        if sensors:
            self._seg[len(segments) :, :5] = sensor_rows(sensors)
            self._seg[len(segments) :, 5] = np.arange(len(sensors))
            near = [list(cell) for cell in near]
            for k, sensor in enumerate(sensors):
                for c in _sensor_cells(grid, sensor):
                    near[c].append(len(segments) + k)
        sizes = np.array([len(s) for s in near], dtype=np.int64)
        self._seg_start = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self._seg_idx = np.array([k for s in near for k in s], dtype=np.int64)
        self._events: tuple[np.ndarray, ...] | None = None  # the log buffer, made on the first recorded run
        #: A rough run's spins after each logged event, in chunks of :data:`~discsim.events.SPIN_DTYPE` rows.
        self.spin_log: list[np.ndarray] = []

    # --- the protocol --------------------------------------------------------------------
    def start(self, state: EventDrivenState | None = None) -> None:
        """A fresh run at time 0 from the scene's discs (or from ``state``, a fresh state with an empty queue
        whose clock moved on): every moving disc predicted at the epoch, in internal order."""
        self.load(fresh_state(self.scene, self.grid, read_only=True) if state is None else state)
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
        self._count = state.collision_counts[order].astype(np.int64, copy=False)
        self._images = state.images[order].astype(np.int32)  # box lengths crossed: int32 holds 2^31 laps
        partner = state.kept_partner[order]
        self._kept_partner = np.where(partner >= 0, rank[np.maximum(partner, 0)], -1).astype(np.int32)
        del partner  # temporaries freed as soon as done: a large N's peak is the sum of what lives at once
        self._kept_stamp = state.kept_stamp[order].astype(np.int64, copy=False)
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
        _counters(lp, state, rank, ints, floats)
        # Each disc's rest flag, then its side of each sensor (disc-major: n + i S + k; one array, so that
        # predict takes no more arguments than it may: see the edges above).
        sensed, sensors = state.sensed, self.scene.sensors
        if sensed.shape != (n, len(sensors)):  # not kept (no sensor before): where the discs are now
            gravity = self.laws.gravity if self.laws.falls else None
            sensed = inside_table(sensors, state.positions_at(state.time, gravity, drag=self.laws.drag), self.box)
        rest = self._rest = np.empty(n + sensed.size, dtype=np.int8)
        rest[:n], rest[n:] = state.resting[order], sensed[order].ravel()
        seg = self._seg  # a moving segment's row: where it is at the epoch (as rebase puts it)
        moving = (seg[:, 6] != 0.0) | (seg[:, 7] != 0.0)
        seg[moving, 0:2] = seg[moving, 8:10] + seg[moving, 6:8] * state.epoch
        seg[moving, 2:4] = seg[moving, 10:12] + seg[moving, 6:8] * state.epoch
        self._tlast = state.last_collision[order].astype(np.float64, copy=False)
        if self.scene.piston is not None:  # its numbers, last in edges
            _moving().put(self._edges, self.scene.piston.mass, state.piston, self.box.width, self.laws.gravity[1])
        self._found = np.zeros(n, dtype=np.int64)  # the loop's room for the discs a woken support held up
        # Each disc's turning: spin, inertia, angle, and the (absolute) time of that angle (loop.W ... ANGLE_T).
        rot = self._rot = np.empty((n, 4))  # filled column by column: no (N, 4) temporaries
        for k, column in enumerate((state.spins[order], discs.inertia[order], state.angles[order], state.time)):
            rot[:, k] = column
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
        spins, angles = self.turning()
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
            pair = j >= 0 and int(ints[lp.I_LKIND]) not in SENSED
            last = (float(floats[lp.F_LTIME]), int(ints[lp.I_LKIND]), int(order[i]), int(order[j]) if pair else j)
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
            resting=caller(self._rest[:n]),
            sensed=caller(self._rest[n:].reshape(n, len(self.scene.sensors))).astype(np.int64),
            last_collision=caller(self._tlast),
            dissipated=float(floats[lp.F_LOST]),
            rests=int(ints[lp.I_RESTS]),
            sensor_events=int(ints[lp.I_SENSE]),
            spins=spins,
            angles=angles,
            piston=_moving().numbers(self._edges) if self.scene.piston is not None else np.zeros(0),
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
        if recording and (self._events is None or len(self._events[0]) < self._log_rows()):
            rows = self._log_rows()
            self._events = (
                np.empty(rows),
                np.empty(rows, dtype=np.int8),
                np.empty(rows, dtype=np.int64),
                np.empty(rows, dtype=np.int64),
                np.empty((rows, 8)),
                np.empty((rows, 2)),
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
                        if self.laws.rough:
                            self.spin_log.append(_spin_records(events, logged))
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
        falls = self.laws.falls and rec[k, 6] != np.inf and self._rest[k] == 0
        gx, gy = self.laws.gravity if falls else (0.0, 0.0)
        drag = self.laws.drag
        x0, y0, vx0, vy0 = (float(v) for v in rec[k, :4])
        args = (x0, y0, vx0, vy0, t - float(rec[k, 4]), gx, gy)
        if drag:
            x, y, ux, uy = dynamics.advance(*args, drag)
            if rec[k, 6] != np.inf:  # what the drag took over the flight the edit ends
                work = gx * (x - x0) + gy * (y - y0)
                self._floats[lp.F_LOST] += rec[k, 6] * (0.5 * (vx0 * vx0 + vy0 * vy0 - ux * ux - uy * uy) + work)
        else:
            x, y, _, _ = self._law_of_motion.advance(*args)
        cell = int(self._cell[k])
        moved = position is not None and (float(position[0]), float(position[1])) != (x, y)
        if position is not None:
            x, y = float(position[0]), float(position[1])
            cell = int(self.grid.cells_of(np.array([[x, y]]))[0])
        if moved and self.scene.sensors:  # its sides are where it is now (put back, a centre on an edge keeps its own)
            sensors, n = self.scene.sensors, len(rec)
            self._rest[n + k * len(sensors) : n + (k + 1) * len(sensors)] = inside_table(sensors, [[x, y]], self.box)[0]
        held: list[int] = []
        if self.laws.falls and self._rest[k] != 0:  # a support at rest moves: what it held up falls again
            gx, gy = self.laws.gravity
            grid = self.grid
            count = lp.supported(
                k, gx, gy, rec, self._rest, self._cell, self._head, self._nxt,
                grid.nx, grid.ny, bool(self.box.periodic), self._edges, self._found,
            )  # fmt: skip
            held = self._found[:count].tolist()
        lp.set_disc(k, x, y, float(vx), float(vy), cell, t, *self._predict_args())
        for d in held:
            lp.set_disc(d, float(rec[d, 0]), float(rec[d, 1]), 0.0, 0.0, int(self._cell[d]), t, *self._predict_args())

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
            self._found, self._rot,
        )  # fmt: skip


_NO_EVENTS = (
    np.empty(0),
    np.empty(0, dtype=np.int8),
    np.empty(0, dtype=np.int64),
    np.empty(0, dtype=np.int64),
    np.empty((0, 8)),
    np.empty((0, 2)),
)


def _sensor_cells(grid: CellGrid, sensor) -> list[int]:
    """The cells a disc's centre may cross ``sensor``'s edge from: over its bounds (a hair wider, for a centre on a
    cell's edge), or every cell for a trip wire (its side changes wherever the line runs, beyond the wire too), but
    none for a trip wire along a periodic box's edge: crossed only by the jumps across it (``sensing.wrap_sense``)."""
    if sensor.shape == "line":
        if on_periodic_edge(sensor, grid.box):
            return []
        return list(range(len(grid)))
    x0, y0, x1, y1 = sensor.bounds()
    hair = 1e-9 * max(grid.box.width, grid.box.height)
    cx0, cx1 = (int(np.clip(np.floor(v / grid.lx), 0, grid.nx - 1)) for v in (x0 - hair, x1 + hair))
    cy0, cy1 = (int(np.clip(np.floor(v / grid.ly), 0, grid.ny - 1)) for v in (y0 - hair, y1 + hair))
    return [cx * grid.ny + cy for cx in range(cx0, cx1 + 1) for cy in range(cy0, cy1 + 1)]


def _records(events, k: int) -> np.ndarray:
    """The first ``k`` rows of the loop's log buffer as an :data:`~discsim.events.EVENT_DTYPE` array."""
    ev_t, ev_kind, ev_i, ev_j, ev_f, _ = events
    out = np.empty(k, dtype=EVENT_DTYPE)
    out["time"] = ev_t[:k]
    out["kind"] = ev_kind[:k]
    out["i"] = ev_i[:k]
    out["j"] = ev_j[:k]
    for c, name in enumerate(("xi", "yi", "vxi", "vyi", "xj", "yj", "vxj", "vyj")):
        out[name] = ev_f[:k, c]
    return out


def _spelled(laws: Laws) -> str:
    """The laws that differ from the defaults, as keywords: ``gravity=(0.0, -9.81), restitution=0.8``."""
    default = Laws()
    return ", ".join(
        f"{name}={getattr(laws, name)!r}"
        for name in ("gravity", "restitution", "tc", "rest_speed", "roughness")
        if getattr(laws, name) != getattr(default, name)
    )


def _spin_records(events, k: int) -> np.ndarray:
    """The spins after the collisions and wall hits among the first ``k`` rows of the loop's log buffer, as
    :data:`~discsim.events.SPIN_DTYPE` rows (not the ``SET`` rows of discs a hit woke: their spins do not change)."""
    ev_t, ev_kind, ev_i, ev_j, _, ev_w = events
    rows = np.flatnonzero((ev_kind[:k] == int(EventKind.COLLISION)) | (ev_kind[:k] == int(EventKind.WALL)))
    out = np.empty(len(rows), dtype=SPIN_DTYPE)
    out["time"] = ev_t[rows]
    out["i"] = ev_i[rows]
    out["j"] = ev_j[rows]
    out["wi"] = ev_w[rows, 0]
    out["wj"] = ev_w[rows, 1]
    return out


def _counters(lp, state, rank: np.ndarray, ints: np.ndarray, floats: np.ndarray) -> None:
    """The loop's counters and clocks (``ints``, ``floats``, slots of the loop module ``lp``) from ``state``; the
    last event's discs by their internal numbers (``rank``)."""
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
        pair = state.last_j >= 0 and state.last_kind not in SENSED  # a sensor's j is the sensor's index
        ints[lp.I_LJ] = rank[state.last_j] if pair else state.last_j
    else:
        ints[lp.I_LI] = ints[lp.I_LJ] = -1
    floats[lp.F_EPOCH] = state.epoch
    floats[lp.F_VIRIAL] = state.virial
    floats[lp.F_OVERLAP] = state.max_overlap
    floats[lp.F_TIME] = state.time
    floats[lp.F_LTIME] = state.last_time
    floats[lp.F_LOST] = state.dissipated
    ints[lp.I_RESTS] = state.rests
    ints[lp.I_SENSE] = state.sensor_events
