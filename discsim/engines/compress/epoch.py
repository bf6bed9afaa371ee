"""One thermostat epoch of the compression, and the final shrink: numpy around the loop of :mod:`.loop`."""

from __future__ import annotations

import numpy as np

from discsim.cells import cell_lists, flat_cells, neighbour_pairs
from discsim.engines.compress import loop
from discsim.model import Box

__all__ = ["SHRINK", "epoch", "shrink_factor"]

#: Relative shrink of all radii at the end, beyond the smallest gap, when roundoff left a contact inside.
SHRINK = 1e-12


def epoch(positions, velocities, radii, masses, box: Box, grid: tuple[int, int], g, t_end, budget, backend):
    """One epoch of growing discs from time 0 (radii ``radii * (1 + g t)``) to ``t_end`` or ``budget`` collisions.

    ``positions`` ``(N, 2)`` in the box (wrapped, when periodic).

    Returns:
        ``(positions, velocities, t, stats)`` at the stopping time ``t`` (positions not wrapped), with
        ``stats``: ``collisions``, ``walls``, ``crossings``, ``stale`` (counts) and ``virial`` (the sum of
        impulse times contact distance over the collisions) and ``wall_virial``.
    """
    n = len(radii)
    nx, ny = grid
    if backend == "numba":
        from discsim.engines.compress import compiled

        run_epoch = compiled.run_epoch

        def floats(a):  # a fresh array: the loop writes into each
            return np.array(a, dtype=np.float64)

        def ints(a):
            return np.array(a, dtype=np.int64)
    else:  # plain lists: the pure-Python loop indexes them 3-5x faster than numpy arrays
        run_epoch = loop.run_epoch

        def floats(a):
            return [float(v) for v in a]

        def ints(a):
            return [int(v) for v in a]

    cw, ch = box.width / nx, box.height / ny
    cells = flat_cells(positions, nx, ny, cw, ch)
    head, nxt, prv = cell_lists(cells, nx * ny)
    x, y = floats(positions[:, 0]), floats(positions[:, 1])
    vx, vy = floats(velocities[:, 0]), floats(velocities[:, 1])
    out, iout = floats([0.0, 0.0, 0.0]), ints([0, 0, 0, 0])
    zeros = np.zeros(n, dtype=np.int64)
    t = run_epoch(
        x, y, vx, vy, floats(np.zeros(n)), floats(radii), floats(masses), ints(zeros), ints(cells), ints(head),
        ints(nxt), ints(prv), ints(zeros), floats(np.zeros(n)), ints(zeros), ints(zeros), ints(zeros), ints(zeros),
        floats([box.width, box.height, g, t_end, cw, ch]), ints([nx, ny, int(box.periodic), budget]), out, iout,
    )  # fmt: skip
    positions = np.column_stack([np.asarray(x, dtype=float), np.asarray(y, dtype=float)])
    velocities = np.column_stack([np.asarray(vx, dtype=float), np.asarray(vy, dtype=float)])
    stats = {
        "collisions": int(iout[0]),
        "walls": int(iout[1]),
        "crossings": int(iout[2]),
        "stale": int(iout[3]),
        "virial": float(out[1]),
        "wall_virial": float(out[2]),
    }
    return positions, velocities, float(t), stats


def shrink_factor(positions: np.ndarray, radii: np.ndarray, box: Box) -> float:
    """1.0, or the factor that leaves every pair and wall a relative ``SHRINK`` apart if one is not."""
    i, j, d = neighbour_pairs(positions, 2.0 * float(radii.max()) * (1.0 + 1e-9), box)
    ratio = 1.0 if len(i) == 0 else float(np.min(np.hypot(d[:, 0], d[:, 1]) / (radii[i] + radii[j])))
    if not box.periodic:
        gaps = np.minimum(positions, box.size - positions) / radii[:, None]
        ratio = min(ratio, float(gaps.min()))
    if ratio >= 1.0 + SHRINK:
        return 1.0
    return min(ratio, 1.0) * (1.0 - SHRINK)
