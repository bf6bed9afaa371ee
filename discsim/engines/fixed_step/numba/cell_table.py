"""The cell table of a compiled sub-frame (:class:`~discsim.engines.fixed_step.broad_phase.CellTable`): the
discs near a new path after a change of course.

The discs are filed by cell at the broad phase's positions; a disc that changes course in the frame is filed
under the cells of its new path too (extra entries, a linked list per cell); a query gathers the discs of the
cells a box meets, each once, sorted, as the Python frame's set does.
"""

from __future__ import annotations

import numpy as np

from discsim._compiled import compile_from_source
from discsim.engines.fixed_step import parts
from discsim.engines.fixed_step.numba.candidates import S_EXT, S_STAMP, leaf
from discsim.engines.fixed_step.numba.kernels import _heapsort, jit

# The table's shape and the cells a box meets: CellTable's own functions, compiled from their source.
_compiled = compile_from_source((parts.table_shape, parts.cell_span), leaf)
_table_shape = _compiled[parts.table_shape]
_span = _compiled[parts.cell_span]


@jit
def _table(pos, nx, ny, lx, ly):
    """``(start, order)``: the members of cell ``c = cx * ny + cy`` are ``order[start[c]:start[c + 1]]``."""
    n = len(pos)
    cell = np.empty(n, dtype=np.int64)
    start = np.zeros(nx * ny + 1, dtype=np.int64)
    for i in range(n):
        cx = min(max(int(pos[i, 0] / lx), 0), nx - 1)
        cy = min(max(int(pos[i, 1] / ly), 0), ny - 1)
        cell[i] = cx * ny + cy
        start[cell[i] + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(n, dtype=np.int64)
    for i in range(n):
        order[fill[cell[i]]] = i
        fill[cell[i]] += 1
    return start, order


@leaf
def _cell_count(lo_x, lo_y, hi_x, hi_y, shape, periodic):
    """How many cells the box from ``lo`` to ``hi`` meets (``shape``: nx, ny and the sides lx, ly)."""
    nx, ny, lx, ly = int(shape[0]), int(shape[1]), shape[2], shape[3]
    x0, x1, _ = _span(lo_x, hi_x, lx, nx, periodic)
    y0, y1, _ = _span(lo_y, hi_y, ly, ny, periodic)
    return (x1 - x0 + 1) * (y1 - y0 + 1)


@leaf
def _table_add(disc, lo_x, lo_y, hi_x, hi_y, shape, periodic, ext_head, ext, st):
    """``CellTable.add``: file ``disc`` under the cells the box meets too (room made already)."""
    nx, ny, lx, ly = int(shape[0]), int(shape[1]), shape[2], shape[3]
    x0, x1, wrap_x = _span(lo_x, hi_x, lx, nx, periodic)
    y0, y1, wrap_y = _span(lo_y, hi_y, ly, ny, periodic)
    for qx in range(x0, x1 + 1):
        cx = qx % nx if wrap_x else qx
        for qy in range(y0, y1 + 1):
            c = cx * ny + (qy % ny if wrap_y else qy)
            e = st[S_EXT]
            ext[e, 0], ext[e, 1] = disc, ext_head[c]
            ext_head[c] = e
            st[S_EXT] = e + 1


@leaf
def _near(
    a, partner, lo_x, lo_y, hi_x, hi_y, shape, periodic, start, order, ext_head, ext, all_pairs, scene, mark, near, st
):
    """``SubFrame._near``: the discs that may touch disc ``a`` (``a`` and ``partner`` left out), sorted, in
    ``near[:count]``; returns ``count``."""
    group, blocked, filtering = scene[6], scene[7], scene[8]
    n = len(mark)
    count = 0
    if all_pairs:  # AllDiscs: every disc, in order
        for m in range(n):
            if m != a and m != partner and not (filtering and blocked[group[a], group[m]]):
                near[count] = m
                count += 1
        return count
    st[S_STAMP] += 1
    stamp = st[S_STAMP]
    nx, ny, lx, ly = int(shape[0]), int(shape[1]), shape[2], shape[3]
    x0, x1, wrap_x = _span(lo_x, hi_x, lx, nx, periodic)
    y0, y1, wrap_y = _span(lo_y, hi_y, ly, ny, periodic)
    mark[a] = stamp
    if partner >= 0:
        mark[partner] = stamp
    for qx in range(x0, x1 + 1):
        cx = qx % nx if wrap_x else qx
        for qy in range(y0, y1 + 1):
            c = cx * ny + (qy % ny if wrap_y else qy)
            for p in range(start[c], start[c + 1]):
                m = order[p]
                if mark[m] != stamp:
                    mark[m] = stamp
                    if not (filtering and blocked[group[a], group[m]]):
                        near[count] = m
                        count += 1
            e = ext_head[c]
            while e >= 0:
                m = ext[e, 0]
                if mark[m] != stamp:
                    mark[m] = stamp
                    if not (filtering and blocked[group[a], group[m]]):
                        near[count] = m
                        count += 1
                e = ext[e, 1]
    _heapsort(near, count)
    return count
