"""Cell grids: the engine's neighbour table and vectorised neighbour pairs.

Two views of one idea. :class:`CellGrid` is the event-driven engine's grid:
plain Python tables, so a prediction looks only at the 3x3 cells around a disc.
:func:`neighbour_pairs` finds every pair of discs in the same or adjacent cells
with numpy, for bulk work (input checks, the fixed-step broad phase).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from discsim.errors import BoxTooSmallError, InvalidArgumentError
from discsim.model import Box

__all__ = [
    "CellGrid", "cell_lists", "cells_along", "flat_cells", "grid_counts", "grid_shape", "link",
    "neighbour_pair_chunks", "neighbour_pairs", "unlink",
]  # fmt: skip


def grid_shape(box: Box, min_cell: float, max_cells: int | None = None, what: str | None = None) -> tuple[int, int]:
    """The one cell-sizing rule: ``(nx, ny)`` cells of at least ``min_cell`` a side over ``box``.

    As many cells as fit along each side (with a relative slack of 1e-12 for
    roundoff), then fewer, in proportion, where needed to stay under
    ``max_cells`` (never under 3 a side in a periodic box).

    Args:
        box: the box. min_cell: the smallest cell side (length units).
        max_cells: upper bound on ``nx * ny``, or None.
        what: what ``min_cell`` is; when given, a periodic box with fewer
            than 3 cells a side raises. When None, such a box gets one cell
            (every pair of discs is then a candidate neighbour).

    Raises:
        BoxTooSmallError: see ``what``.

    Example:
        >>> grid_shape(Box(10.0, 4.0), 1.0), grid_shape(Box(10.0, 4.0), 1.0, max_cells=10)
        ((10, 4), (5, 2))
    """
    nx, ny = grid_counts(box.width, box.height, box.periodic, min_cell, 0 if max_cells is None else max_cells)
    if what is not None and box.periodic and nx * ny == 1:  # a periodic box gets one cell only when too small
        axis, length = ("x", box.width) if cells_along(box.width, min_cell) < 3 else ("y", box.height)
        msg = (
            f"periodic box {axis}-extent {length:g} is too small for its cell grid: it needs at "
            f"least 3 cells of side >= {min_cell:g} ({what}), i.e. >= {3 * min_cell:g}"
        )
        raise BoxTooSmallError(msg)
    return nx, ny


def cells_along(length: float, min_cell: float) -> int:
    """Cells of side ``min_cell`` or more that fit along ``length`` (at least 1), with a relative slack of 1e-12.

    Example:
        >>> cells_along(10.0, 1.0), cells_along(0.3, 0.1), cells_along(0.5, 1.0)
        (10, 3, 1)
    """
    return max(1, math.floor(length / min_cell * (1 + 1e-12)))


def grid_counts(width: float, height: float, periodic: bool, min_cell: float, max_cells: int) -> tuple[int, int]:
    """:func:`grid_shape` on plain numbers, for the loops (numba compiles this very function into the compiled
    fixed-step frames): ``max_cells`` 0 for no bound; a periodic box under 3 cells a side gets one cell.

    Example:
        >>> grid_counts(10.0, 4.0, False, 1.0, 10), grid_counts(10.0, 2.0, True, 1.0, 0)
        ((5, 2), (1, 1))
    """
    nx, ny = cells_along(width, min_cell), cells_along(height, min_cell)
    if periodic and min(nx, ny) < 3:
        return 1, 1
    if 0 < max_cells < nx * ny:
        scale = math.sqrt(nx * ny / max_cells)
        floor_n = 3 if periodic else 1
        nx = max(floor_n, int(nx / scale))
        ny = max(floor_n, int(ny / scale))
    return nx, ny


class CellGrid:
    """A uniform ``nx`` by ``ny`` grid of cells over a box.

    Args:
        box: the box to cover.
        min_cell_size: smallest allowed cell side (at least the largest disc
            diameter, so that touching discs are always in adjacent cells).
        max_cells: upper bound on ``nx * ny``; cells grow beyond
            ``min_cell_size`` to respect it (few discs in a large box).
        what: what ``min_cell_size`` is, for the error message.

    Raises:
        BoxTooSmallError: if the box is periodic and fewer than 3 cells fit
            along a side (the minimum image would then be ambiguous).

    Attributes:
        nx, ny (int): cells along x and y. ``lx, ly`` (float): cell sides.
        neighbours (list[tuple[int, ...]]): built on first use; for each cell, the 9 cells of its 3x3
            block in the order ``(dx, dy)`` for ``dx`` in (-1, 0, 1) for ``dy`` in
            (-1, 0, 1) (itself at position 4); -1 where a wall cuts the block off.
            Entries 6-8 are the block's column on the +x side, 0-2 on the -x
            side, 2, 5, 8 on the +y side and 0, 3, 6 on the -y side.
        shifts (list[tuple[tuple[float, float], ...]]): for each cell, one
            ``(sx, sy)`` per neighbour: the offset to add to a neighbour's
            position to get its image next to the cell (zero except across a
            periodic edge). Equal tuples are shared to keep the table small.
    """

    def __init__(
        self, box: Box, min_cell_size: float, max_cells: int | None = None, what: str = "the largest disc diameter"
    ):
        if not (min_cell_size > 0 and math.isfinite(min_cell_size)):
            msg = f"min_cell_size must be positive and finite, got {min_cell_size!r}"
            raise InvalidArgumentError(msg)
        nx, ny = grid_shape(box, min_cell_size, max_cells, what)
        self.box = box
        self.nx, self.ny = nx, ny
        self.lx, self.ly = box.width / nx, box.height / ny

    def __len__(self) -> int:
        return self.nx * self.ny

    def cells_of(self, positions: np.ndarray) -> np.ndarray:
        """Flat cell index ``(N,)`` of each row of ``positions`` ``(N, 2)``."""
        return flat_cells(positions, self.nx, self.ny, self.lx, self.ly)

    def segments_by_cell(self, segments, reach: float) -> list[tuple[int, ...]]:
        """For each cell, the indices of the segments that pass within ``reach`` of it.

        A disc of radius <= ``reach`` in a cell can only touch segments listed for
        that cell. Conservative: a segment within ``reach`` plus half a cell
        diagonal of the cell's centre is listed.
        """
        table: list[list[int]] = [[] for _ in range(len(self))]
        half_diagonal = 0.5 * math.hypot(self.lx, self.ly)
        cx, cy = np.meshgrid(np.arange(self.nx), np.arange(self.ny), indexing="ij")
        centres = np.column_stack([(cx.ravel() + 0.5) * self.lx, (cy.ravel() + 0.5) * self.ly])
        for k, segment in enumerate(segments):
            near = np.flatnonzero(segment.distance(centres) <= reach + half_diagonal)
            for c in near.tolist():
                table[c].append(k)
        empty: tuple[int, ...] = ()
        return [tuple(cell) if cell else empty for cell in table]

    @functools.cached_property
    def shifts(self) -> list[tuple]:
        """The offsets of each cell's neighbours (see the class docstring); built on first use (the pure-Python
        backend's predictor reads them; the compiled one never does), 8 bytes a cell and a loop over the cells."""
        return self._build_tables(with_neighbours=False)[1]

    @functools.cached_property
    def neighbours(self) -> list[tuple[int, ...]]:
        """The 3x3 block of each cell (see the class docstring); built on first use, 0.3 KB per cell."""
        return self._build_tables(with_neighbours=True)[0]

    def _build_tables(self, with_neighbours: bool):
        """``(neighbours, shifts)``; ``neighbours`` is None unless ``with_neighbours``."""
        nx, ny, periodic = self.nx, self.ny, self.box.periodic
        width, height = self.box.width, self.box.height
        ids = list(range(nx * ny))  # shared int objects keep the table small
        neighbours: list[tuple[int, ...]] = []
        shifts: list[tuple] = []
        shared: dict[tuple, tuple] = {}
        for cx in range(nx):
            for cy in range(ny):
                cells: list[int] = []
                offs: list[tuple[float, float]] = []
                for dx in (-1, 0, 1):
                    for dy in (-1, 0, 1):
                        ox, oy, sx, sy = cx + dx, cy + dy, 0.0, 0.0
                        if periodic:
                            ox, oy = ox % nx, oy % ny
                            sx = width * ((cx + dx) // nx)
                            sy = height * ((cy + dy) // ny)
                        elif not (0 <= ox < nx and 0 <= oy < ny):
                            cells.append(-1)
                            offs.append((0.0, 0.0))
                            continue
                        cells.append(ids[ox * ny + oy])
                        offs.append((sx, sy))
                if with_neighbours:
                    neighbours.append(tuple(cells))
                key = tuple(offs)
                shifts.append(shared.setdefault(key, key))
        return (neighbours if with_neighbours else None), shifts


def neighbour_pairs(positions: np.ndarray, cell_size: float, box: Box):
    """All pairs of points closer than ``cell_size`` candidates, found with a cell grid.

    Every pair whose separation (minimum image when periodic) is below
    ``cell_size`` is returned once; so are some farther pairs in adjacent cells.

    Args:
        positions: ``(N, 2)`` points inside the box.
        cell_size: smallest cell side, e.g. the largest contact distance.
        box: the box (its periodicity decides the minimum image).

    Returns:
        ``(i, j, d)``: int arrays ``(P,)`` with ``i != j`` and ``d`` ``(P, 2)``
        the displacement from ``i`` to ``j``. O(N + P): ``P`` grows as ``N^2`` when points crowd one
        cell; :func:`neighbour_pair_chunks` gives the same pairs in pieces of bounded memory.

    Example:
        >>> import numpy as np
        >>> from discsim import Box
        >>> i, j, d = neighbour_pairs(np.array([[1.0, 1.0], [1.5, 1.0], [8.0, 8.0]]), 1.0, Box(10, 10))
        >>> sorted(zip(i.tolist(), j.tolist()))
        [(0, 1)]
    """
    parts = list(neighbour_pair_chunks(positions, cell_size, box, max_pairs=None))
    if not parts:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, np.zeros((0, 2))
    if len(parts) == 1:
        return parts[0]
    i, j, d = zip(*parts)
    return np.concatenate(i), np.concatenate(j), np.concatenate(d)


#: Pairs per piece of :func:`neighbour_pair_chunks` by default: about 50 MB of arrays.
CHUNK_PAIRS = 1 << 20


def neighbour_pair_chunks(positions: np.ndarray, cell_size: float, box: Box, max_pairs: int | None = CHUNK_PAIRS):
    """The pairs of :func:`neighbour_pairs`, in the same order, as pieces of at most ``max_pairs`` pairs.

    A piece holds more only when one point alone has more candidates (at most ``N - 1``), so memory stays
    O(N + max_pairs) however the points crowd: 10^5 points at one spot make 5 10^9 pairs, which no one
    holds at once, and a caller looking for the first bad pair stops at the first piece holding one.

    Args:
        positions, cell_size, box: as :func:`neighbour_pairs`.
        max_pairs: pairs per piece (None: one piece per cell offset, as they come).

    Yields:
        ``(i, j, d)`` as :func:`neighbour_pairs` returns them; no empty piece.
    """
    n = len(positions)
    if n < 2:
        return
    # At most max(4 N, 65536) cells bounds the cell-start table when few points share a large box;
    # a tiny periodic box gets one cell, and every pair is a candidate.
    nx, ny = grid_shape(box, cell_size, max(4 * n, 1 << 16))
    cx = np.clip((positions[:, 0] * (nx / box.width)).astype(np.int64), 0, nx - 1)
    cy = np.clip((positions[:, 1] * (ny / box.height)).astype(np.int64), 0, ny - 1)
    cell = cx * ny + cy
    order = np.argsort(cell, kind="stable")
    cell_start = np.zeros(nx * ny + 1, dtype=np.int64)  # members of cell c: order[cell_start[c]:cell_start[c + 1]]
    np.cumsum(np.bincount(cell, minlength=nx * ny), out=cell_start[1:])
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n)
    # One cell: its later members are every pair once (the other offsets would count them again).
    offsets = ((0, 0),) if nx * ny == 1 else ((0, 0), (1, 0), (1, 1), (0, 1), (-1, 1))
    for dx, dy in offsets:
        ox, oy = cx + dx, cy + dy
        if box.periodic:
            ox, oy = ox % nx, oy % ny
            valid = np.ones(n, dtype=bool)
        else:
            valid = (ox >= 0) & (ox < nx) & (oy < ny)
        target = np.where(valid, ox * ny + oy, 0)
        start = cell_start[target]
        stop = cell_start[target + 1]
        if dx == 0 and dy == 0:
            start = rank + 1  # same cell: only later members, each pair once
        count = np.where(valid, np.maximum(stop - start, 0), 0)
        ends = np.cumsum(count)  # pairs of the owners up to and including each one
        total = int(ends[-1])
        if total == 0:
            continue
        # Owners [lo, hi) at a time, their pairs at most max_pairs (or one owner's, when it alone has more).
        lo = 0
        while lo < n:
            base = int(ends[lo] - count[lo])
            hi = n if max_pairs is None else max(lo + 1, int(np.searchsorted(ends, base + max_pairs, "right")))
            size = int(ends[hi - 1]) - base
            if size:
                owners = np.arange(lo, hi)
                piece = count[lo:hi]
                owner = np.repeat(owners, piece)
                first = np.repeat(start[lo:hi] - (ends[lo:hi] - piece - base), piece)
                i = owner
                j = order[first + np.arange(size)]
                yield i, j, box.minimum_image(positions[j] - positions[i])
            lo = hi


def cell_lists(cells: np.ndarray, size: int):
    """``head`` ``(size,)`` (first disc of each cell, -1 if none), ``nxt`` and ``prv`` ``(N,)``: the discs of
    ``cells`` ``(N,)`` (each disc's flat cell index) as doubly linked lists by cell, as the compiled loops keep
    them (the compression's, the event chains'); int64, numpy only."""
    order = np.argsort(cells, kind="stable")
    ordered = cells[order]
    same = ordered[1:] == ordered[:-1]
    nxt = np.full(len(cells), -1, dtype=np.int64)
    prv = np.full(len(cells), -1, dtype=np.int64)
    nxt[order[:-1][same]] = order[1:][same]
    prv[order[1:][same]] = order[:-1][same]
    head = np.full(size, -1, dtype=np.int64)
    first = np.ones(len(cells), dtype=bool)
    first[1:] = ~same
    head[ordered[first]] = order[first]
    return head, nxt, prv


def flat_cells(positions: np.ndarray, nx: int, ny: int, lx: float, ly: float) -> np.ndarray:
    """Flat cell index ``cx * ny + cy`` ``(N,)`` of each row of ``positions`` ``(N, 2)`` in a grid of ``nx`` by
    ``ny`` cells of ``lx`` by ``ly`` (clipped to the grid: a centre on the far edge is in the last cell)."""
    cx = np.clip((positions[:, 0] / lx).astype(np.int64), 0, nx - 1)
    cy = np.clip((positions[:, 1] / ly).astype(np.int64), 0, ny - 1)
    return cx * ny + cy


# The doubly linked cell lists of the loops that keep them (the compression's, the event chains'): plain
# arithmetic on indexable ``head``, ``nxt``, ``prv``, so numba compiles these very functions into those loops.
def unlink(i, c, head, nxt, prv):
    """Take disc ``i`` out of cell ``c``'s list."""
    p = prv[i]
    q = nxt[i]
    if p >= 0:
        nxt[p] = q
    else:
        head[c] = q
    if q >= 0:
        prv[q] = p


def link(i, c, head, nxt, prv):
    """Put disc ``i`` at the head of cell ``c``'s list."""
    q = head[c]
    nxt[i] = q
    prv[i] = -1
    if q >= 0:
        prv[q] = i
    head[c] = i
