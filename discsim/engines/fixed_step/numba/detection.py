"""The first candidates of a compiled sub-frame (``Bisect.detect``, ``Swept.detect``), and the bisection.

The order of the floating-point operations is that of :mod:`discsim.engines.fixed_step.sub_frame`. Python's
``x ** 2`` is the C library's ``pow``, which is not ``x * x`` to the last bit (about one value in a thousand):
``bisect`` squares with ``math.pow`` and an exponent that comes from the caller (``two``), so that LLVM cannot
turn it into a product. The minimum image of a pair found by the broad phase is
:meth:`~discsim.model.Box.minimum_image`'s (``_image``); that of two paths, the Python frame's scalar
:func:`~discsim.model.minimum_image_1d` (``_nearest_image``: they differ in the sign of a zero).
"""

from __future__ import annotations

import math

import numpy as np

from discsim._compiled import compile_from_source
from discsim.cells import cells_along, grid_counts
from discsim.engines.fixed_step.numba.candidates import (
    C_BISECTION_TESTS,
    C_PAIR_TESTS,
    C_SEGMENT_TESTS,
    COLLISION,
    INF,
    SEGMENT,
    WALL,
    _push_growing,
    leaf,
)
from discsim.engines.fixed_step.numba.kernels import (
    _cells,
    _closest_point,
    _heapsort,
    _image,
    _near_pairs,
    _nearest_image,
    _segment_distance,
    jit,
)
from discsim.physics.compiled import advance
from discsim.physics.compiled import pair_time_of_impact as _time_of_impact
from discsim.physics.compiled import segment_time_of_impact as _segment_time_of_impact
from discsim.physics.compiled import wall_time as _wall_time

# The one cell-sizing rule (discsim.cells.grid_shape's), compiled from its source.
_grid_counts = compile_from_source((cells_along, grid_counts), jit)[grid_counts]


# --- scalar kernels ----------------------------------------------------------------------------------------
@leaf
def _cross(ux, uy, vx, vy):
    return ux * vy - uy * vx


@leaf
def _path_segment_distance(px, py, ex, ey, ax, ay, bx, by):
    """``sub_frame._segment_segment_distance`` of one path ``p``-``e`` and one segment ``a``-``b``."""
    dist = min(
        min(_segment_distance(px, py, ax, ay, bx, by), _segment_distance(ex, ey, ax, ay, bx, by)),
        min(_segment_distance(ax, ay, px, py, ex, ey), _segment_distance(bx, by, px, py, ex, ey)),
    )
    sx, sy = bx - ax, by - ay
    fx, fy = ex - px, ey - py
    if (
        _cross(sx, sy, px - ax, py - ay) * _cross(sx, sy, ex - ax, ey - ay) < 0.0
        and _cross(fx, fy, ax - px, ay - py) * _cross(fx, fy, bx - px, by - py) < 0.0
    ):
        return 0.0
    return dist


# --- bisection (Bisect._bisect_pair, _bisect_wall, _bisect_segment) ------------------------------------------
# ``p`` holds the two paths or the path and the obstacle: PAIR x_a y_a vx_a vy_a t_a x_b y_b vx_b vy_b t_b
# sigma^2; WALL x v t_ref limit radius high; SEGMENT x y vx vy t_ref r^2 ax ay bx by.
@leaf
def _overlapping(kind, s, p, periodic, width, height, two):
    """The interference test at time ``s`` of the candidate in ``p``."""
    if kind == COLLISION:
        xa, ya, _, _ = advance(p[0], p[1], p[2], p[3], s - p[4])
        xb, yb, _, _ = advance(p[5], p[6], p[7], p[8], s - p[9])
        dx, dy = xb - xa, yb - ya
        if periodic:
            dx, dy = _nearest_image(dx, width), _nearest_image(dy, height)
        return dx * dx + dy * dy < p[10]
    if kind == WALL:
        position = p[0] + p[1] * (s - p[2])
        return position > p[3] if p[5] > 0.0 else position < p[4]
    px, py, _, _ = advance(p[0], p[1], p[2], p[3], s - p[4])
    qx, qy = _closest_point(px, py, p[6], p[7], p[8], p[9])
    return math.pow(px - qx, two) + math.pow(py - qy, two) < p[5]


@leaf
def _bisect(kind, s0, t1, tol, p, periodic, width, height, two, counts):
    """``Bisect._bisect``: the last time without overlap in ``[s0, t1]``; counts the tests."""
    calls = 1
    if _overlapping(kind, s0, p, periodic, width, height, two):
        found = s0
    else:  # discsim.kernels.time_of_impact_bisect
        lo, hi = s0, t1
        while hi - lo >= tol:
            mid = lo + 0.5 * (hi - lo)
            if not lo < mid < hi:
                break
            calls += 1
            if _overlapping(kind, mid, p, periodic, width, height, two):
                hi = mid
            else:
                lo = mid
        found = lo
    counts[C_BISECTION_TESTS] += calls
    return found


@leaf
def _bisect_pair(a, b, s0, t1, tol, p, paths, radii, periodic, width, height, two, counts):
    ref_pos, vel, ref_t, _ = paths
    p[0], p[1], p[2], p[3], p[4] = ref_pos[a, 0], ref_pos[a, 1], vel[a, 0], vel[a, 1], ref_t[a]
    p[5], p[6], p[7], p[8], p[9] = ref_pos[b, 0], ref_pos[b, 1], vel[b, 0], vel[b, 1], ref_t[b]
    p[10] = math.pow(radii[a] + radii[b], two)
    return _bisect(COLLISION, s0, t1, tol, p, periodic, width, height, two, counts)


@leaf
def _bisect_wall(a, wall, s0, t1, tol, p, paths, radii, width, height, two, counts):
    ref_pos, vel, ref_t, _ = paths
    axis, high = wall // 2, wall % 2
    r = radii[a]
    p[0], p[1], p[2] = ref_pos[a, axis], vel[a, axis], ref_t[a]
    p[3], p[4], p[5] = (width if axis == 0 else height) - r, r, float(high)
    return _bisect(WALL, s0, t1, tol, p, False, width, height, two, counts)


@leaf
def _bisect_segment(a, k, s0, t1, tol, p, paths, radii, segments, width, height, two, counts):
    ref_pos, vel, ref_t, _ = paths
    p[0], p[1], p[2], p[3], p[4] = ref_pos[a, 0], ref_pos[a, 1], vel[a, 0], vel[a, 1], ref_t[a]
    p[5] = math.pow(radii[a], two)
    p[6], p[7], p[8], p[9] = segments[k, 0], segments[k, 1], segments[k, 2], segments[k, 3]
    return _bisect(SEGMENT, s0, t1, tol, p, False, width, height, two, counts)


# --- the frame's first candidates (Bisect.detect, Swept.detect) --------------------------------------------
@jit
def _candidates(pos, reach, all_pairs, scene):
    """``SubFrame.pairs`` of the ``"grid"`` broad phase: the pairs at ``pos`` as keys ``i * N + j``
    (``i < j``), sorted: :func:`discsim.cells.neighbour_pairs` with cells of side ``reach``, less the pairs
    of groups that pass through each other. Empty for ``all_pairs`` (see :func:`_next_pair`).
    """
    _, _, periodic, width, height, _, group, blocked, filtering = scene
    n = len(pos)
    if n < 2:
        return np.zeros(0, dtype=np.int64)
    if all_pairs:  # the detection walks every pair itself (_next_pair)
        return np.zeros(0, dtype=np.int64)
    nx, ny = _grid_counts(width, height, periodic, reach, max(4 * n, 1 << 16))
    cx, cy, start, order, rank = _cells(pos, nx, ny, nx / width, ny / height)
    size = 8 * n + 64
    while True:
        li = np.empty(size, dtype=np.int64)
        lj = np.empty(size, dtype=np.int64)
        m = _near_pairs(
            li, lj, pos, cx, cy, start, order, rank, nx, ny, INF, periodic, width, height, group, blocked, filtering
        )
        if m <= size:
            break
        size = m
    keys = np.empty(m, dtype=np.int64)
    for p in range(m):
        keys[p] = min(li[p], lj[p]) * n + max(li[p], lj[p])
    _heapsort(keys, m)
    return keys


@leaf
def _next_pair(k, keys, all_pairs, n, i, j, scene):
    """The broad phase's pair after ``(i, j)``: ``(k, i, j)``, ``i = -1`` at the end.

    The ``k``-th key of ``keys`` (``i * N + j``), or with ``all_pairs`` every pair ``i < j`` in order
    (pairs of groups that pass through each other left out), without a list of them (O(N^2)).
    """
    if not all_pairs:
        if k >= len(keys):
            return k, -1, -1
        return k + 1, keys[k] // n, keys[k] % n
    group, blocked, filtering = scene[6], scene[7], scene[8]
    while True:
        j += 1
        if j >= n:
            i += 1
            j = i + 1
            if j >= n:
                return k, -1, -1
        if not (filtering and blocked[group[i], group[j]]):
            return k + 1, i, j


@jit
def _detect_bisect(keys, all_pairs, pos, t0, t, tol, p, paths, scene, two, heap, found, version, st, counts):
    """``Bisect.detect`` after the broad phase: overlapping pairs, walls crossed, segments cut, bisected.

    Returns the heap and ``found`` (grown if need be).
    """
    radii, _, periodic, width, height, segments, _, _, _ = scene
    n = len(pos)
    k, a, b = _next_pair(0, keys, all_pairs, n, 0, 0, scene)
    while a >= 0:
        dx, dy = pos[b, 0] - pos[a, 0], pos[b, 1] - pos[a, 1]
        if periodic:
            dx, dy = _image(dx, width), _image(dy, height)
        contact = radii[a] + radii[b]
        if dx * dx + dy * dy < contact * contact:
            tc = _bisect_pair(a, b, t0, t, tol, p, paths, radii, periodic, width, height, two, counts)
            heap, found = _push_growing(heap, found, st, version, tc, COLLISION, a, b)
        k, a, b = _next_pair(k, keys, all_pairs, n, a, b, scene)
    counts[C_PAIR_TESTS] += k
    vel = paths[1]
    if not periodic:
        for a in range(n):
            r = radii[a]
            for axis in range(2):
                size = width if axis == 0 else height
                low = pos[a, axis] < r and vel[a, axis] < 0.0
                high = pos[a, axis] > size - r and vel[a, axis] > 0.0
                if low or high:
                    wall = 2 * axis + (1 if high else 0)
                    tc = _bisect_wall(a, wall, t0, t, tol, p, paths, radii, width, height, two, counts)
                    heap, found = _push_growing(heap, found, st, version, tc, WALL, a, wall)
    if len(segments):
        counts[C_SEGMENT_TESTS] += n * len(segments)
        for a in range(n):
            for s in range(len(segments)):
                ax, ay, bx, by = segments[s, 0], segments[s, 1], segments[s, 2], segments[s, 3]
                if _segment_distance(pos[a, 0], pos[a, 1], ax, ay, bx, by) < radii[a]:
                    tc = _bisect_segment(a, s, t0, t, tol, p, paths, radii, segments, width, height, two, counts)
                    heap, found = _push_growing(heap, found, st, version, tc, SEGMENT, a, s)
    return heap, found


@leaf
def _swept_pair(i, j, mid, vel, radii, span, periodic, width, height):
    """``Swept.detect``'s test of one pair: the time from the frame's start it touches, or inf."""
    dx, dy = mid[j, 0] - mid[i, 0], mid[j, 1] - mid[i, 1]
    if periodic:
        dx, dy = _image(dx, width), _image(dy, height)
    dvx, dvy = vel[j, 0] - vel[i, 0], vel[j, 1] - vel[i, 1]
    d0x, d0y = dx - dvx * (0.5 * span), dy - dvy * (0.5 * span)
    sx, sy = dvx * span, dvy * span
    sweep2 = sx * sx + sy * sy
    s = -(d0x * sx + d0y * sy) / sweep2 if sweep2 > 0 else 0.0
    s = min(max(s, 0.0), 1.0)
    cx, cy = d0x + s * sx, d0y + s * sy
    contact = radii[i] + radii[j]
    if cx * cx + cy * cy <= contact * contact:  # touching at the frame counts
        tau = _time_of_impact(d0x, d0y, dvx, dvy, contact)
        if tau <= span:
            return tau
    return INF


@jit
def _detect_swept(keys, all_pairs, mid, start, t0, t, paths, scene, heap, found, version, st, counts):
    """``Swept.detect`` after the broad phase: swept-volume tests of pairs, walls and segments.

    Returns the heap and ``found`` (grown if need be).
    """
    radii, _, periodic, width, height, segments, _, _, _ = scene
    vel = paths[1]
    n = len(mid)
    span = t - t0
    k, i, j = _next_pair(0, keys, all_pairs, n, 0, 0, scene)
    while i >= 0:
        tau = _swept_pair(i, j, mid, vel, radii, span, periodic, width, height)
        if tau != INF:
            heap, found = _push_growing(heap, found, st, version, t0 + tau, COLLISION, i, j)
        k, i, j = _next_pair(k, keys, all_pairs, n, i, j, scene)
    counts[C_PAIR_TESTS] += k
    if not periodic:
        for axis in range(2):
            length = width if axis == 0 else height
            for a in range(n):
                x, v, r = start[a, axis], vel[a, axis], radii[a]
                wt = _wall_time(x, v, r, length)
                if wt <= span:
                    wall = 2 * axis + (1 if v > 0.0 else 0)
                    heap, found = _push_growing(heap, found, st, version, t0 + wt, WALL, a, wall)
    if len(segments):
        counts[C_SEGMENT_TESTS] += n * len(segments)
        for a in range(n):
            x, y, vx, vy, r = start[a, 0], start[a, 1], vel[a, 0], vel[a, 1], radii[a]
            for s in range(len(segments)):
                ax, ay, bx, by = segments[s, 0], segments[s, 1], segments[s, 2], segments[s, 3]
                if _path_segment_distance(x, y, x + vx * span, y + vy * span, ax, ay, bx, by) <= r:
                    tau = _segment_time_of_impact(x, y, vx, vy, r, ax, ay, bx, by)
                    if tau <= span:
                        heap, found = _push_growing(heap, found, st, version, t0 + tau, SEGMENT, a, s)
    return heap, found
