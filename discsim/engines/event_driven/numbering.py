"""The state of a fresh run, shared by every backend: the internal numbering of the discs and their cells.

Backends must agree on the numbering, since it decides the order of simultaneous events; so it lives here,
not in a backend.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.cells import CellGrid
from discsim.engines.event_driven.state import EventDrivenState
from discsim.scene import Scene
from discsim.sensors import inside_table

__all__ = ["RENUMBER_MIN", "TILE", "cell_order", "fresh_state", "internal_order"]

#: Side, in cells, of the square tiles by which large systems are numbered (see :func:`internal_order`).
TILE = 10
#: Systems of at least this many discs are numbered internally tile by tile. Smaller ones fit in the
#: caches, gain nothing, and keep the caller's numbering, which then also decides the order of
#: simultaneous events, as the caller would expect.
RENUMBER_MIN = 4096


def internal_order(grid: CellGrid, positions: np.ndarray) -> np.ndarray:
    """The internal numbering of the discs: tile by tile of ``TILE`` x ``TILE`` cells.

    Discs are sorted by tile, then by cell within the tile (stable, so the
    caller's order stands within a cell). Neighbours then have nearby numbers,
    and their records, counters and kept collisions share cache lines and
    pages (figures in docs/performance.md). Returns ``order``, ``(N,)``: internal disc k is
    the caller's disc ``order[k]``.
    """
    if not len(positions):
        return np.zeros(0, dtype=np.int64)
    return cell_order(grid, grid.cells_of(positions))


def cell_order(grid: CellGrid, cells: np.ndarray, before: np.ndarray | None = None) -> np.ndarray:
    """The discs in cells ``cells`` (``(N,)`` cell indices) ordered tile by tile, as :func:`internal_order`.

    Within a cell the discs keep the order of ``before`` (``(N,)``, a permutation of the discs; default
    ``arange(N)``). Returns ``order``, ``(N,)``: disc ``order[k]`` comes k-th.
    """
    before = np.arange(len(cells)) if before is None else np.asarray(before)
    cx, cy = np.divmod(np.asarray(cells)[before], grid.ny)
    tiles_y = -(-grid.ny // TILE)
    tile = (cx // TILE) * tiles_y + cy // TILE
    key = (tile * TILE + cx % TILE) * TILE + cy % TILE
    return before[np.argsort(key, kind="stable")].astype(np.int64)


def fresh_state(scene: Scene, grid: CellGrid, *, read_only: bool = False) -> EventDrivenState:
    """The state at time 0 from the scene's discs, with an empty queue (the backend predicts every disc).

    With ``read_only``, for a backend's ``load`` that only reads it: the discs' positions, velocities and spins
    are the scene's own arrays, and the per-disc constants (zeros, infinities, -1) are read-only broadcast
    views, so that the state costs about 24 bytes a disc (its numbering and cells), not 150 (issue 32).
    """
    discs = scene.discs
    n = len(discs)
    cell = grid.cells_of(discs.positions)
    order = cell_order(grid, cell) if n >= RENUMBER_MIN else np.arange(n)  # as internal_order, cells found once
    members = order[np.argsort(cell[order], kind="stable")]  # by cell, then internal number

    def own(values: np.ndarray) -> np.ndarray:
        return values if read_only else np.array(values)

    def constant(value, shape: tuple = (n,), dtype=np.float64) -> np.ndarray:
        if read_only:
            return np.broadcast_to(np.asarray(value, dtype), shape)
        return np.full(shape, value, dtype) if value else np.zeros(shape, dtype)

    empty_queue = np.zeros(0, dtype=np.int64)
    given = scene.piston  # its height and velocity at time 0, no impact yet, its pressure
    piston = np.zeros(0) if given is None else np.array([scene.piston_height, given.velocity, 0.0, 0.0, given.pressure])
    return EventDrivenState(
        time=0.0,
        epoch=0.0,
        since_rebase=0,
        collisions=0,
        wall_hits=0,
        cell_crossings=0,
        stale=0,
        predictions=0,
        virial=0.0,
        max_overlap=0.0,
        max_queue=0,
        last_time=0.0,
        last_kind=-1,
        last_i=-1,
        last_j=-1,
        grid_nx=grid.nx,
        grid_ny=grid.ny,
        ref_positions=own(discs.positions),
        velocities=own(discs.velocities),
        ref_times=constant(0.0),
        images=constant(0, (n, 2), np.int64),
        collision_counts=constant(0, dtype=np.int64),
        cell=cell,
        cell_members=members,
        cell_sizes=np.bincount(cell, minlength=len(grid)).astype(np.int64),
        kept_time=constant(math.inf),
        kept_partner=constant(-1, dtype=np.int64),
        kept_stamp=constant(0, dtype=np.int64),
        order=np.asarray(order, dtype=np.int64),
        queue_owner=empty_queue,
        queue_time=np.zeros(0),
        queue_kind=empty_queue,
        queue_other=empty_queue,
        queue_stamp=empty_queue,
        resting=constant(0, dtype=np.int64),
        last_collision=constant(-math.inf),
        spins=own(discs.spins),
        angles=constant(0.0),
        sensed=inside_table(scene.sensors, discs.positions, scene.box),
        piston=piston,
    )
