"""Broad phases of the fixed-step engine: which pairs of discs the narrow phase tests.

Two, giving identical runs: ``"grid"`` (:class:`VerletGrid`: a Verlet list of the pairs within
``2 r_max + skin``, rebuilt with the cell grid :func:`~discsim.cells.neighbour_pairs` when a disc has moved
half the skin; O(N) per frame) and ``"all-pairs"`` (:class:`AllPairs`: every pair, in blocks; O(N^2) per
frame). Pairs of groups that pass through each other are left out. Each also answers the sub-frame
policies' queries: the pairs near each other at some positions, and the discs near a box
(:meth:`BroadPhase.table`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from discsim.cells import neighbour_pairs
from discsim.engines.fixed_step.arrays import Shapes
from discsim.engines.fixed_step.parts import cell_span, table_shape
from discsim.model import Box

__all__ = ["BROAD_PHASE_CLASSES", "AllPairs", "BroadPhase", "CellTable", "VerletGrid"]

#: Candidate pairs tested at once by the all-pairs broad phase (bounds its memory).
_ALL_PAIRS_BLOCK = 1 << 21


class BroadPhase(ABC):
    """Candidate pairs as chunks ``(i, j, d)``: int arrays ``(P,)`` and ``d`` ``(P, 2)`` the minimum-image
    ``pos[j] - pos[i]``, pairs that pass through each other left out.
    """

    name = ""

    def __init__(self, shapes: Shapes):
        self.shapes = shapes
        self.box = shapes.box

    @abstractmethod
    def frame_pairs(self, pos: np.ndarray, counts: dict[str, int]):
        """Chunks of the pairs that may overlap at ``pos`` (the positions at a frame)."""

    @abstractmethod
    def pairs_within(self, pos: np.ndarray, reach: float):
        """Chunks holding every pair nearer than ``reach`` (length) at ``pos``."""

    @abstractmethod
    def table(self, pos: np.ndarray, reach: float):
        """A :class:`CellTable` (or :class:`AllDiscs`) of the discs at ``pos``, for box queries."""

    def export(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The Verlet list ``(positions, i, j)``; positions ``(0, 2)`` before the first build."""
        empty = np.zeros(0, dtype=np.int64)
        return np.zeros((0, 2)), empty, empty.copy()

    def load(self, positions: np.ndarray, i: np.ndarray, j: np.ndarray, built: bool) -> None:
        """Take back a Verlet list from :meth:`export` (``built``: it was built at least once)."""
        return  # a broad phase without a list has nothing to take back

    def _colliding(self, i, j, d):
        """The pairs of ``(i, j, d)`` whose groups collide (all of them when there is no filter)."""
        scene = self.shapes.scene
        if not scene.filtering or not len(i):
            return i, j, d
        keep = ~scene.passes(i, j)
        return i[keep], j[keep], d[keep]


class VerletGrid(BroadPhase):
    """The ``"grid"`` broad phase: a Verlet list at the frames, the cell grid in the sub-frame queries.

    The list holds the pairs within ``2 r_max + skin`` (skin half a radius) when it was built; it is
    rebuilt once some disc has moved more than half the skin since (responses that move discs count),
    so every pair that can overlap now is in it. Between rebuilds a frame's broad phase is one gather.
    """

    name = "grid"

    def __init__(self, shapes: Shapes):
        super().__init__(shapes)
        self.skin = 0.25 * shapes.diameter
        self.list_positions: np.ndarray | None = None  # where the discs were at the last build
        self.list_i = self.list_j = np.zeros(0, dtype=np.int64)

    def frame_pairs(self, pos, counts):
        box = self.box
        if self.list_positions is not None:
            moved = box.displacement(self.list_positions, pos)
            stale = float(np.max(np.einsum("ij,ij->i", moved, moved), initial=0.0)) > (0.5 * self.skin) ** 2
        if self.list_positions is None or stale:
            reach = self.shapes.diameter + self.skin
            i, j, d = self._colliding(*neighbour_pairs(pos, reach, box))
            near = np.einsum("ij,ij->i", d, d) < reach * reach
            self.list_i, self.list_j = i[near], j[near]
            self.list_positions = pos.copy()
            counts["list_builds"] += 1
        i, j = self.list_i, self.list_j
        yield i, j, box.displacement(pos[i], pos[j])

    def pairs_within(self, pos, reach):
        yield self._colliding(*neighbour_pairs(pos, reach, self.box))

    def table(self, pos, reach):
        return CellTable(pos, reach, self.box)

    def export(self):
        if self.list_positions is None:
            return super().export()
        return self.list_positions.copy(), self.list_i.copy(), self.list_j.copy()

    def load(self, positions, i, j, built):
        self.list_positions = np.array(positions, dtype=np.float64).reshape(-1, 2) if built else None
        self.list_i = np.array(i, dtype=np.int64)
        self.list_j = np.array(j, dtype=np.int64)


class AllPairs(BroadPhase):
    """The ``"all-pairs"`` broad phase: every pair, in blocks of at most ``_ALL_PAIRS_BLOCK`` pairs."""

    name = "all-pairs"

    def frame_pairs(self, pos, counts):
        return self._blocks(pos)

    def pairs_within(self, pos, reach):
        return self._blocks(pos)

    def table(self, pos, reach):
        return AllDiscs(len(pos))

    def _blocks(self, pos: np.ndarray):
        n = len(pos)
        rows = max(1, _ALL_PAIRS_BLOCK // max(n, 1))
        later = np.arange(n)
        for start in range(0, n - 1, rows):
            first = np.arange(start, min(n - 1, start + rows))
            bi, jj = np.nonzero(later[None, :] > first[:, None])
            ii = first[bi]
            yield self._colliding(ii, jj, self.box.displacement(pos[ii], pos[jj]))


#: The broad phases by name.
BROAD_PHASE_CLASSES = {phase.name: phase for phase in (VerletGrid, AllPairs)}


class CellTable:
    """Discs by cell of a uniform grid, for box queries (the discs near a path after a change of course).

    Args:
        pos: ``(N, 2)`` positions (points outside a walled box go to its edge cells).
        cell: smallest cell side (length); cells grow so that there are at most
            ``max(4 N, 65536)`` of them.
        box: the box (a periodic one wraps the queries).
    """

    def __init__(self, pos: np.ndarray, cell: float, box: Box):
        nx, ny = table_shape(len(pos), cell, box.width, box.height)
        self.nx, self.ny = nx, ny
        self.lx, self.ly = box.width / nx, box.height / ny
        self.periodic = box.periodic
        cx = np.clip((pos[:, 0] / self.lx).astype(np.int64), 0, nx - 1)
        cy = np.clip((pos[:, 1] / self.ly).astype(np.int64), 0, ny - 1)
        cells = cx * ny + cy
        self.extra: dict[int, list[int]] = {}
        start = np.zeros(nx * ny + 1, dtype=np.int64)
        np.cumsum(np.bincount(cells, minlength=nx * ny), out=start[1:])
        # Plain lists: a query reads a few cells, faster from lists than from numpy.
        self.order = np.argsort(cells, kind="stable").tolist()
        self.start = start.tolist()

    def _span(self, lo: float, hi: float, size: float, count: int) -> list[int]:
        first, last, wraps = cell_span(lo, hi, size, count, self.periodic)
        if wraps:
            return [c % count for c in range(first, last + 1)]
        return list(range(first, last + 1))

    def _cells(self, lo: tuple[float, float], hi: tuple[float, float]) -> list[int]:
        ny = self.ny
        rows = self._span(lo[1], hi[1], self.ly, ny)
        return [cx * ny + cy for cx in self._span(lo[0], hi[0], self.lx, self.nx) for cy in rows]

    def add(self, disc: int, lo: tuple[float, float], hi: tuple[float, float]) -> None:
        """File ``disc`` (which changed course) under the cells that meet the box from ``lo`` to ``hi`` too."""
        extra = self.extra
        for c in self._cells(lo, hi):
            extra.setdefault(c, []).append(disc)

    def near(self, lo: tuple[float, float], hi: tuple[float, float]) -> set[int]:
        """The discs filed under the cells that meet the box from ``lo`` to ``hi``."""
        order, start, extra = self.order, self.start, self.extra
        found: set[int] = set()
        for c in self._cells(lo, hi):
            found.update(order[start[c] : start[c + 1]])
            if c in extra:
                found.update(extra[c])
        return found


class AllDiscs:
    """The all-pairs answer to a box query: every disc, wherever the box is."""

    def __init__(self, n: int):
        self.n = n

    def add(self, disc: int, lo: tuple[float, float], hi: tuple[float, float]) -> None:
        """Nothing to file: every disc is found anyway."""

    def near(self, lo: tuple[float, float], hi: tuple[float, float]) -> set[int]:
        """Every disc."""
        return set(range(self.n))
