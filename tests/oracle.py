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


def _first_downward_root(coefficients, value_at, slope_at, t_min=-1e-12):
    """The earliest root ``t >= 0`` of a polynomial (``numpy.roots`` order) where it crosses zero downwards;
    ``inf`` if none. Touching (value <= 0) and approaching now counts as ``t = 0``."""
    if value_at(0.0) <= 0.0 and slope_at(0.0) < 0.0:
        return 0.0
    roots = np.roots(np.trim_zeros(np.asarray(coefficients, dtype=float), "f"))
    real = np.sort(roots[np.abs(roots.imag) <= 1e-7 * (1.0 + np.abs(roots.real))].real)
    for t in real:
        if t > t_min and slope_at(t) < 0.0:
            # Polish the root by Newton on the polynomial (numpy's roots lose digits near double roots).
            for _ in range(3):
                s = slope_at(t)
                if s != 0.0:
                    t = t - value_at(t) / s
            return max(float(t), 0.0)
    return math.inf


def next_event_under_gravity(positions, velocities, radii, masses, box, gravity, resting):
    """``(dt, kind, i, j)`` of the earliest event under uniform ``gravity``, by brute force over every pair and
    wall (walled boxes), from the polynomials' coefficients and ``numpy.roots``: independent of the engine's
    root finders. Discs of infinite mass and discs ``resting`` do not fall."""
    g = np.asarray(gravity, dtype=float)
    n = len(radii)
    accel = np.where((np.isfinite(masses) & ~np.asarray(resting, dtype=bool))[:, None], g, 0.0)
    best = (math.inf, None, -1, -1)
    for i in range(n):
        for j in range(i + 1, n):
            d = positions[j] - positions[i]
            w = velocities[j] - velocities[i]
            a = accel[j] - accel[i]
            sigma = radii[i] + radii[j]
            # |d + w t + a t^2 / 2|^2 - sigma^2
            c4 = a @ a / 4.0
            c3 = w @ a
            c2 = w @ w + d @ a
            c1 = 2.0 * (d @ w)
            c0 = d @ d - sigma * sigma

            def value(t, c=(c4, c3, c2, c1, c0)):
                return (((c[0] * t + c[1]) * t + c[2]) * t + c[3]) * t + c[4]

            def slope(t, c=(c4, c3, c2, c1)):
                return ((4 * c[0] * t + 3 * c[1]) * t + 2 * c[2]) * t + c[3]

            t = _first_downward_root((c4, c3, c2, c1, c0), value, slope)
            if t < best[0]:
                best = (t, "collision", i, j)
    if not box.periodic:
        for i in range(n):
            for axis, length in ((0, box.width), (1, box.height)):
                for wall, sign in ((radii[i], -1.0), (length - radii[i], 1.0)):
                    # sign * (x + v t + a t^2 / 2 - wall) rises through 0: the disc reaches the wall
                    x, v, acc = positions[i, axis], velocities[i, axis], accel[i, axis]
                    coeffs = (-sign * acc / 2.0, -sign * v, -sign * (x - wall))

                    def value(t, c=coeffs):
                        return (c[0] * t + c[1]) * t + c[2]

                    def slope(t, c=coeffs):
                        return 2 * c[0] * t + c[1]

                    t = _first_downward_root(coeffs, value, slope)
                    if t < best[0]:
                        best = (t, "wall", i, -1)
    return best


def scattered_discs(n, size, radii, speed, obstacles, seed=11):
    """``n`` discs at random places in a ``size`` x ``size`` walled box, none overlapping: radii uniform in
    ``radii`` ``(lo, hi)``, masses in [0.5, 2], velocities normal with scale ``speed``; the first ``obstacles`` of
    them obstacles (infinite mass, at rest). For the oracle tests in lock-step."""
    import discsim as ds

    rng = np.random.default_rng(seed)
    pos, rad = [], []
    while len(pos) < n:
        r = rng.uniform(*radii)
        p = rng.uniform(r, size - r, size=2)
        if all(np.hypot(*(p - q)) > r + s + 1e-6 for q, s in zip(pos, rad)):
            pos.append(p)
            rad.append(r)
    masses = rng.uniform(0.5, 2.0, size=n)
    masses[:obstacles] = np.inf
    vel = rng.normal(scale=speed, size=(n, 2))
    vel[:obstacles] = 0.0
    return ds.Discs(np.array(pos), vel, np.array(rad), masses)
