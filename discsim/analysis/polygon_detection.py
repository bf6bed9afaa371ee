"""How the study's detectors find the contact of two moving, spinning convex polygons (issue 33, item 3).

Two bodies of a :class:`~discsim.polygons.Polygons` move freely (centre ``p + v t``, angle ``theta + w t``) until
they first touch. The detectors the study compares, each over frames of length ``dt``:

- :func:`pit_contact` (PIT, the periodic interference test): the first frame at which the two overlap (the
  separating-axis test, :func:`~discsim.polygons.overlap_depth`), with how deep they are then. A contact that
  begins and ends between two frames (a thin bar spinning past a corner) is missed.
- :func:`bisect_contact`: PIT, then the study's sub-frame bisection between the last frame apart and the first
  overlapping one (to ``tol``): the time is refined, the misses stay.
- :func:`swept_contact` (swept volumes): the first frame whose two swept regions meet. A body's region over a frame
  is the convex hull of its outlines at both ends, pushed out by the most a vertex strays from the chord while it
  turns (``R (1 - cos(a / 2))`` for a turn ``a <= pi``; beyond a half turn, the hull of the circles of radius ``R``
  about the centre's ends). The region holds the body's whole sweep, so a contact is never missed; a frame whose
  regions meet may hold none (a false alarm).
- :func:`reference_contact`: the truth by brute force: the overlap sampled on a grid finer than any contact can
  last (``samples`` per unit time), then bisected.

Each returns the time found (``inf``: none by ``horizon``) and what it costs in overlap tests.

Example:
    >>> from discsim.polygons import Polygons, regular_polygon
    >>> pair = Polygons(regular_polygon(4, 1.0), [[0.0, 0.0], [5.0, 0.0]], velocities=[[1.0, 0.0], [-1.0, 0.0]])
    >>> round(reference_contact(pair, 0, 1, 5.0, samples=100).time, 9)  # corners 3 apart, closing at 2
    1.5
    >>> pit_contact(pair, 0, 1, 0.4, 5.0).time  # the first frame after 1.5
    1.6
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from discsim.polygons import Polygons, overlap_depth

__all__ = ["Detection", "bisect_contact", "pit_contact", "reference_contact", "swept_contact", "swept_region"]


class Detection(NamedTuple):
    """A detector's answer: the contact ``time`` (``inf``: none found by the horizon), how deep the two overlap
    then (``depth``, length; 0 where the time is a refined one), and the separating-axis ``tests`` it took."""

    time: float
    depth: float
    tests: int


def _depth(bodies: Polygons, i: int, j: int, t: float) -> float:
    return overlap_depth(bodies.world_vertices(i, t), bodies.world_vertices(j, t))


def pit_contact(bodies: Polygons, i: int, j: int, dt: float, horizon: float) -> Detection:
    """The first frame ``k dt`` (``k >= 1``, up to ``horizon``) at which bodies ``i`` and ``j`` overlap."""
    frames = math.floor(horizon / dt + 1e-9)
    for k in range(1, frames + 1):
        depth = _depth(bodies, i, j, k * dt)
        if depth > 0.0:
            return Detection(k * dt, depth, k)
    return Detection(math.inf, 0.0, frames)


def bisect_contact(bodies: Polygons, i: int, j: int, dt: float, horizon: float, tol: float = 1e-9) -> Detection:
    """PIT, then bisection between the last frame apart and the first overlapping one, to ``tol`` in time."""
    found = pit_contact(bodies, i, j, dt, horizon)
    if not math.isfinite(found.time):
        return found
    return _bisect(bodies, i, j, found.time - dt, found.time, tol, found.tests)


def _bisect(bodies, i, j, apart: float, over: float, tol: float, tests: int) -> Detection:
    while over - apart > tol:
        mid = 0.5 * (apart + over)
        tests += 1
        if _depth(bodies, i, j, mid) > 0.0:
            over = mid
        else:
            apart = mid
    return Detection(over, 0.0, tests)


def reference_contact(bodies: Polygons, i: int, j: int, horizon: float, samples: int = 20_000) -> Detection:
    """The first contact by brute force: the overlap sampled ``samples`` times per unit time, the first
    overlapping sample bisected back to the last one apart (to 1e-12). Exact while no contact lasts less than
    the sampling step (choose ``samples`` above the fastest corner's speed over the thinnest part)."""
    steps = max(1, math.ceil(horizon * samples))
    times = np.linspace(0.0, horizon, steps + 1)
    for k in range(1, len(times)):
        if _depth(bodies, i, j, float(times[k])) > 0.0:
            return _bisect(bodies, i, j, float(times[k - 1]), float(times[k]), 1e-12, k)
    return Detection(math.inf, 0.0, steps)


def _hull(points: np.ndarray) -> np.ndarray:
    """The convex hull of ``points`` ``(M, 2)``, counter-clockwise (Andrew's monotone chain)."""
    p = np.unique(points, axis=0)
    if len(p) < 3:
        return p

    def half(rows):
        out: list = []
        for q in rows:
            while (
                len(out) >= 2
                and (out[-1][0] - out[-2][0]) * (q[1] - out[-2][1]) - (out[-1][1] - out[-2][1]) * (q[0] - out[-2][0])
                <= 0.0
            ):
                out.pop()
            out.append(q)
        return out

    lower, upper = half(p), half(p[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _pushed_out(hull: np.ndarray, margin: float) -> np.ndarray:
    """A convex polygon that holds ``hull`` pushed out by ``margin`` (its Minkowski sum with a disc): each vertex
    moved out along its two edges' normals, far enough that every edge moves out by ``margin``."""
    if margin <= 0.0 or len(hull) < 3:
        return hull
    edges = np.roll(hull, -1, axis=0) - hull
    normals = np.column_stack([edges[:, 1], -edges[:, 0]]) / np.hypot(edges[:, 0], edges[:, 1])[:, None]
    before = np.roll(normals, 1, axis=0)  # the normal of the edge ending at each vertex
    both = before + normals
    # The corner of the two pushed-out edges: along the bisector, margin / cos(half the turn) out.
    scale = margin / np.maximum(0.5 * np.einsum("ij,ij->i", both, both), 1e-300)
    return hull + both * scale[:, None]


def swept_region(bodies: Polygons, i: int, t0: float, t1: float) -> np.ndarray:
    """A convex polygon holding everything body ``i`` covers between ``t0`` and ``t1`` (see the module)."""
    turn = abs(float(bodies.spins[i]) * (t1 - t0))
    radius = float(bodies.circumradii[i])
    if turn > math.pi:  # the circles of radius R about the centre at both ends, as 32-gons holding them
        phi = np.linspace(0.0, 2.0 * math.pi, 32, endpoint=False)
        ring = (radius / math.cos(math.pi / 32)) * np.column_stack([np.cos(phi), np.sin(phi)])
        ends = [bodies.positions[i] + bodies.velocities[i] * t for t in (t0, t1)]
        return _hull(np.concatenate([ring + end for end in ends]))
    outline = np.concatenate([bodies.world_vertices(i, t0), bodies.world_vertices(i, t1)])
    return _pushed_out(_hull(outline), radius * (1.0 - math.cos(0.5 * turn)))


def swept_contact(bodies: Polygons, i: int, j: int, dt: float, horizon: float) -> Detection:
    """The first frame whose swept regions meet: its end ``time`` and the overlap ``depth`` of the two bodies then
    (<= 0 where they do not overlap at the frame's end). The regions hold the sweeps, so no contact is missed; a
    flagged frame without a contact (the truth comes later) is a false alarm."""
    frames = math.floor(horizon / dt + 1e-9)
    for k in range(frames):
        t0, t1 = k * dt, (k + 1) * dt
        if overlap_depth(swept_region(bodies, i, t0, t1), swept_region(bodies, j, t0, t1)) > 0.0:
            return Detection(t1, _depth(bodies, i, j, t1), k + 1)
    return Detection(math.inf, 0.0, frames)
