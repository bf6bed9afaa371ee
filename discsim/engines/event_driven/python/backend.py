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

The hot loop, :meth:`PythonBackend._process_events`, reads top to bottom: pop, validate the counter, advance
the discs involved, resolve, record, re-predict, push.
"""

from __future__ import annotations

import gc
import math
import struct
from operator import itemgetter

import numpy as np

from discsim._interrupt import deferred_interrupt
from discsim.cells import CellGrid
from discsim.engines.event_driven.numbering import TILE, fresh_state
from discsim.engines.event_driven.state import EventDrivenState
from discsim.events import EventKind, EventLog
from discsim.physics.dynamics import advance
from discsim.physics.laws import reflect
from discsim.physics.sources import boundaries, pairs, segments
from discsim.queue import CalendarEventQueue, EventQueue, HeapEventQueue
from discsim.scene import Scene

__all__ = ["QUEUES", "PythonBackend"]

# A disc's record in the state buffer: x, y, vx, vy, t_ref, radius (float64).
_RECORD = struct.Struct("6d")
_RECORD_BYTES = _RECORD.size
# Positions in a cell's static record (see PythonBackend._make_predictor): the cell's index,
# its slot in its tile, and the ghost copies of it in other tiles.
_CELL_INDEX, _SLOT, _GHOSTS = 9, 10, 11
# Side, in cells, of the square tiles the table of cell members is cut into (see _tile_cells): the
# tiles of the internal numbering. With a ring of ghost cells a tile holds 12 x 12 = 144 slots, so every
# slot index is one of CPython's cached small ints and a 3x3 block reads no memory outside its tile.
_TILE = TILE

INF = math.inf
# Kinds of queued events, as plain ints for the hot loop (one numbering: EventKind).
_COLLISION, _WALL, _CROSSING, _SEGMENT = (
    int(k) for k in (EventKind.COLLISION, EventKind.WALL, EventKind.CROSSING, EventKind.SEGMENT)
)
# Physical events between moves of the internal clock's epoch (at least 16 per disc).
_REBASE_EVENTS = 1 << 18
# Directions of a cell crossing (one numbering: discsim.physics.sources.boundaries).
_PLUS_X, _MINUS_X, _PLUS_Y, _MINUS_Y = boundaries.PLUS_X, boundaries.MINUS_X, boundaries.PLUS_Y, boundaries.MINUS_Y

#: The event queues, by name; all give the same events bit for bit.
QUEUES = {"calendar": CalendarEventQueue, "sorted": EventQueue, "heap": HeapEventQueue}


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
        self.load(fresh_state(self.scene, self.grid) if state is None else state)
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
        self._disc = _pack_records(
            pos[:, 0], pos[:, 1], vel[:, 0], vel[:, 1], state.ref_times[order], discs.radii[order]
        )
        self._image_x = state.images[order, 0].tolist()
        self._image_y = state.images[order, 1].tolist()
        self._count = state.collision_counts[order].tolist()
        members = rank[state.cell_members].tolist()
        # One tuple per cell; empty cells share the one empty tuple, so scanning them touches
        # no memory. _make_predictor moves them into tiles (see _tile_cells).
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
        self._predict, self._predictions = self._make_predictor(state.predictions, cells, state.cell[order].tolist())

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
        pending = [(o, *self._queue.pending(o)) for o in range(n)]
        pending = [(o, t, p) for o, t, p in pending if t != INF]
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
            **self._counts,
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
                    done += self._process_events(
                        until, limit if limit < 0 else limit - done, crossings, log, interrupted
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
    def _make_predictor(self, n_pred: int, cells: list[tuple[int, ...]], cell: list[int]):
        """Build the prediction closures over the state lists (closures read locals fast).

        Returns ``(predict, predictions)``:

        - ``predict(i, t, exclude, direction=-1)`` schedules disc ``i``'s
          earliest event after time ``t``: its wall or segment hit, its cell
          crossing, or its collision with a disc in the 3x3 block of cells
          around it, never with ``exclude`` (the partner it has just left:
          roundoff must not make a pair collide twice). The earliest collision
          found is also kept per disc. After ``i`` crossed into a new cell in
          ``direction``, only the 3 cells that just became adjacent are scanned
          and the kept collision stands for the 6 that stay adjacent: that
          equals a full 3x3 re-prediction as long as the kept partner has not
          changed course since (else the full scan runs).
        - ``predictions()`` counts the predictions made (from ``n_pred``).

        The neighbour loop and the wall and cell-edge times inline the law of motion's parts
        (:func:`discsim.physics.sources.pairs.predict`, :func:`discsim.physics.sources.boundaries.predict_x`
        and ``predict_y``), the only copies left: a Python call per candidate or per axis would cost this
        loop more than its speed budget allows. The compiled loop calls the parts themselves, and the
        cross-backend tests hold the two to the same events bit for bit.
        Also builds the tiles of cell members from ``cells`` (the discs of each
        cell, in order), the static per-cell records (``_cell_info``), and points
        each disc at its cell's record (``_where``, from its cell index in ``cell``).
        """
        disc, unpack = self._disc, _RECORD.unpack_from
        count = self._count
        grid, box = self.grid, self.box
        front = {_PLUS_X: (6, 7, 8), _MINUS_X: (0, 1, 2), _PLUS_Y: (2, 5, 8), _MINUS_Y: (0, 3, 6)}
        width, height, periodic = box.width, box.height, box.periodic
        # Segments near each cell (a static structure built once).
        segment_ends = [(*s.p0.tolist(), *s.p1.tolist()) for s in self.segments]
        reach = max(self._radius, default=0.0)
        segments_near = grid.segments_by_cell(self.segments, reach) if segment_ends else [()] * len(grid)
        # One static record per cell, so a prediction reads one tuple:
        # (block, tile, minimum-image shifts of the block, xlo, xhi, ylo, yhi, walls,
        # segments, the cell's index, its slot in the tile, its ghost copies). Each disc
        # holds its cell's record in ``where`` (built here from the cell indices in
        # ``_cell``), one pointer away. The cell members live in tiles (``_tile_cells``):
        # ``block(tile)`` fetches the 9 member tuples of the 3x3 block in one call, and
        # cells a wall cuts off are ghost slots that stay empty. ``walls`` has bit 1, 2,
        # 4, 8 set when a wall stands beyond the low-x, high-x, low-y, high-y side.
        # Records share one float per column and per row, which keeps them small.
        blocks, tiles, slots, ghosts = _tile_cells(grid, cells, periodic)
        col_lo = [cx * grid.lx for cx in range(grid.nx)]
        col_hi = [*col_lo[1:], width]
        row_lo = [cy * grid.ly for cy in range(grid.ny)]
        row_hi = [*row_lo[1:], height]
        info = []
        for c, (shift, segs) in enumerate(zip(grid.shifts, segments_near)):
            cx, cy = divmod(c, grid.ny)
            walls = (
                0 if periodic else ((cx == 0) | (cx == grid.nx - 1) << 1 | (cy == 0) << 2 | (cy == grid.ny - 1) << 3)
            )
            here = (blocks[c], tiles[c], shift, col_lo[cx], col_hi[cx], row_lo[cy], row_hi[cy], walls, segs, c)
            info.append((*here, slots[c], ghosts[c]))
        self._cell_info = info
        self._where = where = [info[c] for c in cell]
        kept_time, kept_partner, kept_stamp = self._kept_time, self._kept_partner, self._kept_stamp
        push, discard = self._queue.push, self._queue.discard
        # Collision filter: blocked[g][h] is True when groups g and h pass through each other.
        filtering = self.scene.filtering
        group = self.scene.group[self._order].tolist()
        blocked = self.scene.blocked.tolist()
        sqrt = math.sqrt
        predict_segment = segments.predict
        # The payloads of wall, crossing and segment events, made once and shared:
        # ``payloads[kind][other]``. A pop then reads no freshly scattered tuple for them.
        payloads = [
            None,
            [(_WALL, 0, 0), (_WALL, 1, 0)],
            [(_CROSSING, direction, 0) for direction in range(4)],
            [(_SEGMENT, k, 0) for k in range(len(segment_ends))],
        ]

        def predict(i: int, t: float, exclude: int, direction: int = -1) -> None:
            nonlocal n_pred
            n_pred += 1
            xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
            dti = t - ti
            xi += vxi * dti
            yi += vyi * dti
            block, tile, shift, x_lo, x_hi, y_lo, y_hi, walls, segs, _, _, _ = where[i]
            block = block(tile)
            # 1. The earliest collision with a neighbour.
            partner = kept_partner[i]
            after_crossing = direction >= 0 and (partner < 0 or count[partner] == kept_stamp[i])
            if after_crossing:  # the 3 cells that just became adjacent; the kept collision covers the other 6
                k0, k1, k2 = front[direction]
                near = ((block[k0], shift[k0]), (block[k1], shift[k1]), (block[k2], shift[k2]))
            else:
                near = zip(block, shift)
            best, new_partner = INF, -1
            passes = blocked[group[i]] if filtering else None
            for others, (sx, sy) in near:
                if not others:
                    continue
                ox, oy = sx - xi, sy - yi
                for j in others:
                    if j == i or j == exclude or (filtering and passes[group[j]]):
                        continue
                    xj, yj, vxj, vyj, tj, rj = unpack(disc, j * _RECORD_BYTES)
                    dvx = vxj - vxi
                    dvy = vyj - vyi
                    dtj = t - tj
                    dx = xj + vxj * dtj + ox
                    dy = yj + vyj * dtj + oy
                    b = dx * dvx + dy * dvy
                    if b >= 0.0:
                        continue
                    s = ri + rj
                    cc = dx * dx + dy * dy - s * s
                    if cc <= 0.0:
                        tij = 0.0
                    else:
                        a = dvx * dvx + dvy * dvy
                        d = b * b - a * cc
                        if d <= 0.0:
                            continue
                        tij = cc / (-b + sqrt(d))
                    if tij < best:
                        best, new_partner = tij, j
            if after_crossing:
                t_hit = kept_time[i]
                if t + best < t_hit:
                    t_hit, partner = t + best, new_partner
                    kept_time[i], kept_partner[i], kept_stamp[i] = t_hit, partner, count[partner]
            else:
                t_hit, partner = t + best, new_partner
                kept_time[i], kept_partner[i] = t_hit, partner
                if partner >= 0:
                    kept_stamp[i] = count[partner]
            # 2. The next wall, segment or cell boundary.
            best, kind, other = INF, _CROSSING, 0
            if vxi > 0.0:
                if walls & 2:
                    best, kind = (width - ri - xi) / vxi, _WALL
                else:
                    best, other = (x_hi - xi) / vxi, _PLUS_X
            elif vxi < 0.0:
                if walls & 1:
                    best, kind = (ri - xi) / vxi, _WALL
                else:
                    best, other = (x_lo - xi) / vxi, _MINUS_X
            if vyi > 0.0:
                if walls & 8:
                    ty = (height - ri - yi) / vyi
                    if ty < best:
                        best, kind, other = ty, _WALL, 1
                else:
                    ty = (y_hi - yi) / vyi
                    if ty < best:
                        best, kind, other = ty, _CROSSING, _PLUS_Y
            elif vyi < 0.0:
                if walls & 4:
                    ty = (ri - yi) / vyi
                    if ty < best:
                        best, kind, other = ty, _WALL, 1
                else:
                    ty = (y_lo - yi) / vyi
                    if ty < best:
                        best, kind, other = ty, _CROSSING, _MINUS_Y
            for k in segs:
                if k != -2 - exclude:  # not the segment just left
                    ts = predict_segment(xi, yi, vxi, vyi, ri, *segment_ends[k])
                    if ts < best:
                        best, kind, other = ts, _SEGMENT, k
            if best < 0.0:
                best = 0.0
            # 3. Schedule the earlier of the two.
            t_best = t + best
            if t_hit <= t_best and partner >= 0:
                push(i, t_hit, (_COLLISION, partner, count[partner]))
            elif best == INF:
                discard(i)
            else:
                push(i, t_best, payloads[kind][other])

        def predictions() -> int:
            return n_pred

        return predict, predictions

    # --- the hot loop ----------------------------------------------------------------------
    def _process_events(self, until: float, limit: int, crossings: int, log: EventLog | None, interrupted) -> int:
        """The hot loop of :meth:`advance` (-1: no limit on ``limit`` or ``crossings``).

        Stops before the next event once ``interrupted[0]`` is true
        (see :func:`~discsim._interrupt.deferred_interrupt`).
        """
        queue = self._queue
        pop_before = queue.pop_before
        predict = self._predict
        disc, unpack, pack = self._disc, _RECORD.unpack_from, _RECORD.pack_into
        count, mass, one_mass = self._count, self._mass, self._one_mass
        image_x, image_y = self._image_x, self._image_y  # box lengths to unwrap, changed only at the edges
        where, info, grid = self._where, self._cell_info, self.grid
        nx, ny = grid.nx, grid.ny
        width, height, periodic = self.box.width, self.box.height, self.box.periodic
        caller = self._caller_id  # the caller's numbering, for the log
        counts = self._counts
        segment_ends = [(*seg.p0.tolist(), *seg.p1.tolist()) for seg in self.segments]
        resolve_pair, resolve_segment, cross = pairs.resolve, segments.resolve, boundaries.cross
        n_coll = n_wall = n_cross = n_stale = 0
        done = 0
        max_queue = self.max_queue
        now, last, virial = None, None, self._virial
        sqrt, max_overlap = math.sqrt, self.max_overlap
        # Internal times run from the epoch, which moves every _rebase_every physical events.
        epoch = self._epoch
        horizon = until - epoch
        rebase_at = self._rebase_every - self._since_rebase
        while done != limit:
            if interrupted[0]:  # Ctrl-C: stop between two whole events
                break
            popped = pop_before(horizon)
            if popped is None:
                break
            t, i, (kind, other, stamp) = popped
            if kind == _COLLISION:
                j = other
                if count[j] != stamp:  # the partner has changed course since the prediction
                    n_stale += 1
                    predict(i, t, -1)
                    continue
                # Advance the two discs to the contact.
                xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                dt = t - ti
                xi += vxi * dt
                yi += vyi * dt
                xj, yj, vxj, vyj, tj, rj = unpack(disc, j * _RECORD_BYTES)
                dt = t - tj
                xj += vxj * dt
                yj += vyj * dt
                if one_mass is None:
                    mi, mj = mass[i], mass[j]
                else:
                    mi = mj = one_mass
                dx, dy, uxi, uyi, uxj, uyj = resolve_pair(
                    xi, yi, vxi, vyi, mi, xj, yj, vxj, vyj, mj, width, height, periodic
                )
                overlap = 1.0 - sqrt(dx * dx + dy * dy) / (ri + rj)
                if overlap > max_overlap:
                    max_overlap = overlap
                pack(disc, i * _RECORD_BYTES, xi, yi, uxi, uyi, t, ri)
                pack(disc, j * _RECORD_BYTES, xj, yj, uxj, uyj, t, rj)
                virial -= mi * ((uxi - vxi) * dx + (uyi - vyi) * dy)  # owners are never obstacles
                count[i] += 1
                n_coll += 1
                done += 1
                if log is not None:
                    log.collision(t + epoch, caller[i], caller[j], xi, yi, uxi, uyi, xj, yj, uxj, uyj)
                predict(i, t, j)
                if mj != INF:  # obstacles never move, and their counter never changes
                    count[j] += 1
                    predict(j, t, i)
                    # Only here can the queue grow (j's slot may have been empty); other
                    # events pop their owner's event and push at most one back.
                    size = len(queue)
                    if size > max_queue:
                        max_queue = size
                last = (t + epoch, _COLLISION, i, j)
            elif kind == _WALL:
                xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                dt = t - ti
                xi += vxi * dt
                yi += vyi * dt
                vxi, vyi = reflect(vxi, vyi, other)
                pack(disc, i * _RECORD_BYTES, xi, yi, vxi, vyi, t, ri)
                count[i] += 1
                n_wall += 1
                done += 1
                if log is not None:
                    log.wall(t + epoch, caller[i], xi, yi, vxi, vyi)
                predict(i, t, -1)
                last = (t + epoch, _WALL, i, -1)
            elif kind == _SEGMENT:
                xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                dt = t - ti
                xi += vxi * dt
                yi += vyi * dt
                vxi, vyi = resolve_segment(xi, yi, vxi, vyi, *segment_ends[other])
                pack(disc, i * _RECORD_BYTES, xi, yi, vxi, vyi, t, ri)
                count[i] += 1
                n_wall += 1
                done += 1
                if log is not None:
                    log.wall(t + epoch, caller[i], xi, yi, vxi, vyi)
                predict(i, t, -2 - other)  # never the same segment again straight away
                last = (t + epoch, _WALL, i, -1)
            else:  # cell crossing: the trajectory is unchanged, only the neighbourhood
                here = where[i]
                tile, slot = here[1], here[_SLOT]
                others = tile[slot]
                if len(others) == 1:
                    others = ()
                else:
                    k = others.index(i)
                    others = others[:k] + others[k + 1 :]
                tile[slot] = others
                for tile, slot in here[_GHOSTS]:  # the copies in the rings of neighbouring tiles
                    tile[slot] = others
                cx, cy = divmod(here[_CELL_INDEX], ny)
                cx, cy, wrap_x, wrap_y = cross(cx, cy, other, nx, ny)
                if wrap_x or wrap_y:  # out through one edge of the box, in through the other
                    xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                    pack(disc, i * _RECORD_BYTES, xi - wrap_x * width, yi - wrap_y * height, vxi, vyi, ti, ri)
                    image_x[i] += wrap_x
                    image_y[i] += wrap_y
                here = where[i] = info[cx * ny + cy]
                tile, slot = here[1], here[_SLOT]
                others = tile[slot] + (i,)
                tile[slot] = others
                for tile, slot in here[_GHOSTS]:
                    tile[slot] = others
                n_cross += 1
                predict(i, t, -1, other)
                if n_cross == crossings:
                    now = t
                    break
            now = t
            if done >= rebase_at:
                self._rebase(now)
                epoch, now = self._epoch, 0.0
                horizon = until - epoch
                rebase_at = done + self._rebase_every
        self._since_rebase = self._rebase_every - (rebase_at - done)
        self.max_queue = max_queue
        self._virial, self.max_overlap = virial, max_overlap
        if now is not None:
            self.time = now + epoch
        if last is not None:
            self._last = last
        counts["collisions"] += n_coll
        counts["wall_hits"] += n_wall
        counts["cell_crossings"] += n_cross
        counts["stale"] += n_stale
        return done

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


def _tile_cells(grid: CellGrid, members: list[tuple[int, ...]], periodic: bool):
    """Cut the table of cell members into tiles of ``_TILE`` x ``_TILE`` cells with a ring of ghost cells.

    A prediction fetches the member tuples of the 3x3 block of cells around a
    disc. From one table of all cells, with an ``itemgetter`` per cell over 9
    global indices, that reads the getter, its 9 index ints and 3 stretches of
    the table, far apart at large N: 10 cache misses or so before the first
    neighbour. A tile instead holds its cells and a ring of copies (ghosts) of
    the cells around it, so every block lies in one tile, and the getters, one
    per position in a tile and shared by all tiles, index with small ints that
    stay in cache. A wall leaves its ghost slots empty; a periodic box fills
    them from the opposite side. A cell's tuple is replaced in its own slot
    and in every ghost copy at once (a cell has copies in up to 3 other tiles).

    Args:
        grid: the cell grid.
        members: the discs in each cell, indexed as the grid's cells.
        periodic: whether the box wraps around.

    Returns:
        ``(blocks, tiles, slots, ghosts)``, lists indexed by cell: the getter that
        fetches the cell's 3x3 block from its tile (in the order of
        ``grid.shifts``), the tile (a list), the cell's slot in it, and a tuple of
        ``(tile, slot)`` pairs, the cell's ghost copies.
    """
    nx, ny, size = grid.nx, grid.ny, _TILE + 2
    n_cells = nx * ny
    blocks: list = [None] * n_cells
    tiles: list = [None] * n_cells
    slots = [0] * n_cells
    ghosts: list[list] = [[] for _ in range(n_cells)]
    getters: dict[tuple[int, int], itemgetter] = {}
    for x0 in range(0, nx, _TILE):
        for y0 in range(0, ny, _TILE):
            w, h = min(_TILE, nx - x0), min(_TILE, ny - y0)
            tile = [()] * (size * size)
            for lx in range(w + 2):
                for ly in range(h + 2):
                    cx, cy = x0 + lx - 1, y0 + ly - 1
                    if periodic:
                        cx, cy = cx % nx, cy % ny
                    elif not (0 <= cx < nx and 0 <= cy < ny):
                        continue  # beyond a wall: always empty
                    c, slot = cx * ny + cy, lx * size + ly
                    tile[slot] = members[c]
                    if 1 <= lx <= w and 1 <= ly <= h:  # the cell's own slot
                        if (lx, ly) not in getters:
                            near = [(lx + dx) * size + ly + dy for dx in (-1, 0, 1) for dy in (-1, 0, 1)]
                            getters[lx, ly] = itemgetter(*near)
                        blocks[c], tiles[c], slots[c] = getters[lx, ly], tile, slot
                    else:
                        ghosts[c].append((tile, slot))
    return blocks, tiles, slots, [tuple(copies) for copies in ghosts]


def _pack_records(x, y, vx, vy, t_ref, radius) -> bytearray:
    """The state buffer of per-disc records from ``(N,)`` arrays, one per field."""
    return bytearray(np.column_stack([x, y, vx, vy, t_ref, radius]).astype(np.float64).tobytes())
