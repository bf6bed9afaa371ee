"""The Verlet list of the compiled ``"grid"`` broad phase: rebuilt in the order
:func:`discsim.cells.neighbour_pairs` gives its pairs (so the exported state is the Python frame's), and stale once
some disc moved more than half the skin.
"""

from __future__ import annotations

import numpy as np

from discsim.engines.fixed_step.numba.frame_parts import _image, jit

__all__ = ["build_list"]

# The cell offsets of discsim.cells.neighbour_pairs, in its order.
_OFFSETS_X = (0, 1, 1, 0, -1)
_OFFSETS_Y = (0, 0, 1, 1, 1)


@jit
def _stale(pos, list_pos, periodic, width, height, limit2):
    """Whether some disc moved more than half the skin since the list was built."""
    worst = 0.0
    for i in range(len(pos)):
        dx, dy = pos[i, 0] - list_pos[i, 0], pos[i, 1] - list_pos[i, 1]
        if periodic:
            dx, dy = _image(dx, width), _image(dy, height)
        worst = max(worst, dx * dx + dy * dy)
    return worst > limit2


@jit
def _cells(pos, nx, ny, per_x, per_y):
    """Discs by cell, as :func:`discsim.cells.neighbour_pairs` files them.

    Returns:
        ``(cx, cy, start, order, rank)``: each disc's cell column and row; the members of cell
        ``c = cx * ny + cy`` are ``order[start[c]:start[c + 1]]``, in disc order (a stable sort by
        cell), and disc ``i`` is ``order[rank[i]]``.
    """
    n = len(pos)
    cx = np.empty(n, dtype=np.int64)
    cy = np.empty(n, dtype=np.int64)
    start = np.zeros(nx * ny + 1, dtype=np.int64)
    for i in range(n):
        cx[i] = min(max(int(pos[i, 0] * per_x), 0), nx - 1)  # int(): truncation, as astype(np.int64)
        cy[i] = min(max(int(pos[i, 1] * per_y), 0), ny - 1)
        start[cx[i] * ny + cy[i] + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(n, dtype=np.int64)
    rank = np.empty(n, dtype=np.int64)
    for i in range(n):
        c = cx[i] * ny + cy[i]
        order[fill[c]] = i
        rank[i] = fill[c]
        fill[c] += 1
    return cx, cy, start, order, rank


@jit
def _near_pairs(
    li, lj, pos, cx, cy, start, order, rank, nx, ny, reach2, periodic, width, height, group, blocked, filtering
):
    """The pairs of discs in the same or adjacent cells nearer than ``sqrt(reach2)``, as :func:`build_list`.

    Writes the first ones into ``li``, ``lj`` (as many as fit) and returns how many there are (call again
    with longer arrays if they did not fit: growing them inside the loop costs a third more).
    """
    n = len(pos)
    m = 0
    single = nx * ny == 1
    for o in range(1 if single else 5):
        for i in range(n):
            if single:  # every pair (i, j > i)
                first, last = i + 1, n
            else:
                ox, oy = cx[i] + _OFFSETS_X[o], cy[i] + _OFFSETS_Y[o]
                if periodic:
                    ox, oy = ox % nx, oy % ny
                elif ox < 0 or ox >= nx or oy >= ny:
                    continue
                c = ox * ny + oy
                first = rank[i] + 1 if o == 0 else start[c]  # the same cell: only later members
                last = start[c + 1]
            for p in range(first, last):
                j = p if single else order[p]
                if filtering and blocked[group[i], group[j]]:
                    continue
                dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
                if periodic:
                    dx, dy = _image(dx, width), _image(dy, height)
                if dx * dx + dy * dy < reach2:
                    if m < len(li):
                        li[m] = i
                        lj[m] = j
                    m += 1
    return m


@jit
def build_list(pos, reach2, nx, ny, per_x, per_y, periodic, width, height, group, blocked, filtering, hint=0):
    """The Verlet list ``(i, j)``: :func:`discsim.cells.neighbour_pairs` on ``nx x ny`` cells, then filtered.

    The pairs come in ``neighbour_pairs``' order (cell offset, first disc, then rank in the cell), the
    ones that pass through each other or lie ``sqrt(reach2)`` or farther apart left out, as
    ``VerletGrid`` builds its list. ``per_x``, ``per_y``: cells per unit length (``nx / width``, ...);
    ``hint``: the length of the last list (the new one is about as long).
    """
    if len(pos) < 2:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    cx, cy, start, order, rank = _cells(pos, nx, ny, per_x, per_y)
    size = hint + hint // 4 + 64
    while True:
        li = np.empty(size, dtype=np.int64)
        lj = np.empty(size, dtype=np.int64)
        m = _near_pairs(
            li, lj, pos, cx, cy, start, order, rank, nx, ny, reach2, periodic, width, height, group, blocked, filtering
        )
        if m <= size:
            return li[:m].copy(), lj[:m].copy()
        size = m
