"""The pure-Python backend's prediction: each disc's next event, over tiles of cells (closures read locals fast).

:func:`make_predictor` builds the ``predict`` closure the hot loop calls after every event, and the tiles of
cell members it scans (:func:`tile_cells`). The neighbour scan and the wall and cell-edge times inline the
law of motion's parts (:mod:`discsim.physics.sources`) for speed; the compiled loop calls the parts, and the
cross-backend tests hold the two to the same events bit for bit.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from operator import itemgetter
from typing import Any

from discsim.cells import CellGrid
from discsim.engines.event_driven.python.layout import (
    _COLLISION,
    _CROSSING,
    _MINUS_X,
    _MINUS_Y,
    _PLUS_X,
    _PLUS_Y,
    _RECORD,
    _RECORD_BYTES,
    _SEGMENT,
    _TILE,
    _WALL,
    INF,
)
from discsim.physics.sources import segments

__all__ = ["make_predictor", "tile_cells"]


def make_predictor(backend, n_pred: int, cells: list[tuple[int, ...]], cell: list[int]):
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
    disc, unpack = backend._disc, _RECORD.unpack_from
    count = backend._count
    grid, box = backend.grid, backend.box
    front = {_PLUS_X: (6, 7, 8), _MINUS_X: (0, 1, 2), _PLUS_Y: (2, 5, 8), _MINUS_Y: (0, 3, 6)}
    width, height, periodic = box.width, box.height, box.periodic
    # Segments near each cell (a static structure built once).
    segment_ends = [(*s.p0.tolist(), *s.p1.tolist()) for s in backend.segments]
    reach = max(backend._radius, default=0.0)
    segments_near = grid.segments_by_cell(backend.segments, reach) if segment_ends else [()] * len(grid)
    # One static record per cell, so a prediction reads one tuple:
    # (block, tile, minimum-image shifts of the block, xlo, xhi, ylo, yhi, walls,
    # segments, the cell's index, its slot in the tile, its ghost copies). Each disc
    # holds its cell's record in ``where`` (built here from the cell indices in
    # ``_cell``), one pointer away. The cell members live in tiles (``tile_cells``):
    # ``block(tile)`` fetches the 9 member tuples of the 3x3 block in one call, and
    # cells a wall cuts off are ghost slots that stay empty. ``walls`` has bit 1, 2,
    # 4, 8 set when a wall stands beyond the low-x, high-x, low-y, high-y side.
    # Records share one float per column and per row, which keeps them small.
    blocks, tiles, slots, ghosts = tile_cells(grid, cells, periodic)
    col_lo = [cx * grid.lx for cx in range(grid.nx)]
    col_hi = [*col_lo[1:], width]
    row_lo = [cy * grid.ly for cy in range(grid.ny)]
    row_hi = [*row_lo[1:], height]
    info = []
    for c, (shift, segs) in enumerate(zip(grid.shifts, segments_near)):
        cx, cy = divmod(c, grid.ny)
        walls = 0 if periodic else ((cx == 0) | (cx == grid.nx - 1) << 1 | (cy == 0) << 2 | (cy == grid.ny - 1) << 3)
        here = (blocks[c], tiles[c], shift, col_lo[cx], col_hi[cx], row_lo[cy], row_hi[cy], walls, segs, c)
        info.append((*here, slots[c], ghosts[c]))
    backend._cell_info = info
    backend._where = where = [info[c] for c in cell]
    kept_time, kept_partner, kept_stamp = backend._kept_time, backend._kept_partner, backend._kept_stamp
    push, discard = backend._queue.push, backend._queue.discard
    # Collision filter: blocked[g][h] is True when groups g and h pass through each other.
    filtering = backend.scene.filtering
    group = backend.scene.group[backend._order].tolist()
    blocked = backend.scene.blocked.tolist()
    sqrt = math.sqrt
    predict_segment = segments.predict
    # The payloads of wall, crossing and segment events, made once and shared:
    # ``payloads[kind][other]``. A pop then reads no freshly scattered tuple for them.
    payloads: list[Any] = [
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
        near: Iterable[tuple[Any, Any]]
        if after_crossing:  # the 3 cells that just became adjacent; the kept collision covers the other 6
            k0, k1, k2 = front[direction]
            near = ((block[k0], shift[k0]), (block[k1], shift[k1]), (block[k2], shift[k2]))
        else:
            near = zip(block, shift)
        best, new_partner = INF, -1
        passes: Any = blocked[group[i]] if filtering else None
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


def tile_cells(grid: CellGrid, members: list[tuple[int, ...]], periodic: bool):
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
            tile: list[tuple[int, ...]] = [()] * (size * size)
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
