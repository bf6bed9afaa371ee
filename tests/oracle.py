"""A brute-force O(N^2) oracle: the next event of a system, from scratch.

Independent of the engine's grid, queue and lazy clocks: it looks at every pair
(and every periodic image of it) and every wall, using only
:mod:`discsim.kernels`, and returns the earliest event.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.kernels import segment_time_of_impact, time_of_impact, wall_time


def next_event(positions, velocities, radii, masses, box, exclude=(), segments=(), groups=None, pass_through=()):
    """``(dt, kind, i, j)`` of the earliest event from this state; kind 'collision' or 'wall'.

    ``exclude`` holds unordered pairs (frozensets) that have just collided and are
    separating, which the engine likewise skips. Segment hits count as 'wall'.
    Pairs whose sorted groups are in ``pass_through`` never collide.
    """
    n = len(radii)
    best = (math.inf, None, -1, -1)
    images = [(0.0, 0.0)]
    if box.periodic:
        images = [(a * box.width, b * box.height) for a in (-1, 0, 1) for b in (-1, 0, 1)]
    moving = np.isfinite(masses)
    for i in range(n):
        for j in range(i + 1, n):
            if not (moving[i] or moving[j]) or frozenset((i, j)) in exclude:
                continue
            if groups is not None and (min(groups[i], groups[j]), max(groups[i], groups[j])) in pass_through:
                continue
            d = positions[j] - positions[i]
            if box.periodic:
                d = d - box.size * np.round(d / box.size)
            dv = velocities[j] - velocities[i]
            for sx, sy in images:
                t = time_of_impact(d[0] + sx, d[1] + sy, dv[0], dv[1], radii[i] + radii[j])
                if t < best[0]:
                    best = (t, "collision", i, j)
    if not box.periodic:
        for i in range(n):
            for axis, length in ((0, box.width), (1, box.height)):
                t = wall_time(positions[i, axis], velocities[i, axis], radii[i], length)
                if t < best[0]:
                    best = (t, "wall", i, -1)
    for i in range(n):
        for k, seg in enumerate(segments):
            if frozenset((i, -2 - k)) in exclude:
                continue
            t = segment_time_of_impact(*positions[i], *velocities[i], radii[i], *seg.p0, *seg.p1)
            if t < best[0]:
                best = (t, "wall", i, -1)
    return best
