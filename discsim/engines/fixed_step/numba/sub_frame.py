"""The sub-frame policies ``bisect`` and ``swept``, compiled: one call does a batch of frames.

The algorithm, the order of the floating-point operations and the tie-breaking are those of
:mod:`discsim.engines.fixed_step.sub_frame`, so both backends give the same frames bit for bit:

- the candidates of a frame (pairs sorted by ``(i, j)``, then walls, then segments, in the Python
  policy's order) go into a binary heap ordered by ``(time, seq)``, ``seq`` counting the pushes, which
  pops in the order of Python's ``heapq`` of ``(time, seq, ...)`` tuples;
- a candidate is dropped when a disc has changed course since it was found (the per-disc response
  counts, ``version``), or when the same contact was answered at the same instant (``done``: per disc, a
  linked list of the contacts answered in the frame, newest first);
- after a response the disc's new path is tested against the discs filed in the cells it may reach
  (the :class:`~discsim.engines.fixed_step.broad_phase.CellTable` of the frame, with its extra entries for
  discs that changed course), sorted, as the Python frame does.

The broad phase of the frame is :func:`discsim.cells.neighbour_pairs` (through the compiled frame's
``_cells`` and ``_near_pairs``) or every pair. Python's ``x ** 2`` is the C library's ``pow``, which is not
``x * x`` to the last bit (about one value in a thousand): ``bisect`` squares with ``math.pow`` and an
exponent that comes from the caller (``two``), so that LLVM cannot turn it into a product. Python's
``round`` of the inline minimum image keeps a ``-0.0`` that :meth:`~discsim.model.Box.minimum_image`
turns into ``+0.0``: :func:`_round_image` does what the inline formula does.

The functions that run per candidate take ``_nrt=False`` (no reference counts on their array arguments)
and allocate nothing: :func:`sub_frames` makes room in the growing buffers before it calls them.
"""

from __future__ import annotations

import math

import numpy as np

from discsim._numba import numba
from discsim.engines.fixed_step.numba.kernels import (
    _cells,
    _closest_point,
    _collide,
    _heapsort,
    _image,
    _impulse_virial,
    _near_pairs,
    _reflect,
    _segment_distance,
    _wrap,
    cpython_hypot,
    jit,
)
from discsim.physics.compiled import pair_time_of_impact as _time_of_impact
from discsim.physics.compiled import segment_time_of_impact as _segment_time_of_impact
from discsim.physics.compiled import wall_time as _wall_time

_nb = numba()
if _nb is None:  # pragma: no cover - importable without numba (doctests); the engine needs numba to use it

    def leaf(function):
        return function

else:
    leaf = _nb.njit(cache=True, error_model="numpy", _nrt=False)

#: The compiled sub-frame policies by name: the ``policy`` argument of :func:`sub_frames`.
SUB_FRAME_CODES = {"bisect": 3, "swept": 4}
BISECT, SWEPT = 3, 4
INF = math.inf
COLLISION, WALL, SEGMENT = 0, 1, 2  # candidate kinds (discsim.events.EventKind's order: no log kind is kept)
#: Slots of the ``counts`` array of :func:`sub_frames`: the engine's counters of the same names.
C_PAIR_TESTS, C_SEGMENT_TESTS, C_BISECTION_TESTS, C_DETECTIONS, C_WALL_HITS = range(5)
# Slots of ``st``, the fill levels of one frame's buffers.
S_HEAP, S_SEQ, S_DONE, S_FOUND, S_EXT, S_EVENTS, S_STAMP, S_NEAR = range(8)
# Why sub_frames returned.
DONE, JAMMED = 0, 1
#: A frame with more responses than this, plus this many per disc, is jammed (``SubFrame.MAX_RESPONSES``).
MAX_RESPONSES = 1000
MAX_RESPONSES_PER_DISC = 50


# --- scalar kernels ----------------------------------------------------------------------------------------
@leaf
def _round_image(d, size):
    """``d - size * round(d / size)`` as the Python frame writes it inline (``-0.0`` stays ``-0.0``)."""
    if abs(d) <= 0.5 * size:
        return d
    return d - size * np.rint(d / size)


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
        dx = p[5] + p[7] * (s - p[9]) - (p[0] + p[2] * (s - p[4]))
        dy = p[6] + p[8] * (s - p[9]) - (p[1] + p[3] * (s - p[4]))
        if periodic:
            dx, dy = _round_image(dx, width), _round_image(dy, height)
        return dx * dx + dy * dy < p[10]
    if kind == WALL:
        position = p[0] + p[1] * (s - p[2])
        return position > p[3] if p[5] > 0.0 else position < p[4]
    px, py = p[0] + p[2] * (s - p[4]), p[1] + p[3] * (s - p[4])
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


# --- the candidates' heap, ordered by (time, seq) -----------------------------------------------------------
# ``ht[k]`` the time of entry k; ``hn[k]``: seq, kind, a, b, stamp of a, stamp of b.
@leaf
def _before(ht, hn, x, y):
    return ht[x] < ht[y] or (ht[x] == ht[y] and hn[x, 0] < hn[y, 0])


@leaf
def _swap(ht, hn, x, y):
    ht[x], ht[y] = ht[y], ht[x]
    for c in range(6):
        hn[x, c], hn[y, c] = hn[y, c], hn[x, c]


@leaf
def _push(ht, hn, st, found, version, tc, kind, a, b):
    """``SubFrame.push``: queue a candidate (room made already); a pair goes to ``found`` too."""
    k = st[S_HEAP]
    ht[k] = tc
    hn[k, 0], hn[k, 1], hn[k, 2], hn[k, 3] = st[S_SEQ], kind, a, b
    hn[k, 4], hn[k, 5] = version[a], version[b] if kind == COLLISION else 0
    st[S_SEQ] += 1
    st[S_HEAP] = k + 1
    while k > 0:
        parent = (k - 1) >> 1
        if not _before(ht, hn, k, parent):
            break
        _swap(ht, hn, k, parent)
        k = parent
    if kind == COLLISION:
        m = st[S_FOUND]
        found[m, 0], found[m, 1] = a, b
        st[S_FOUND] = m + 1


@leaf
def _pop(ht, hn, st):
    """Take the first candidate off the heap: ``(time, kind, a, b, stamp_a, stamp_b)``."""
    tc, kind, a, b, sa, sb = ht[0], hn[0, 1], hn[0, 2], hn[0, 3], hn[0, 4], hn[0, 5]
    size = st[S_HEAP] - 1
    st[S_HEAP] = size
    if size > 0:
        _swap(ht, hn, 0, size)
        k = 0
        while 2 * k + 1 < size:
            child = 2 * k + 1
            if child + 1 < size and _before(ht, hn, child + 1, child):
                child += 1
            if not _before(ht, hn, child, k):
                break
            _swap(ht, hn, k, child)
            k = child
    return tc, kind, a, b, sa, sb


# --- contacts answered in the frame (SubFrame.done) -----------------------------------------------------------
@leaf
def _answered_at(done_head, done_next, done_key, done_time, kind, a, b, tc):
    """Whether contact ``(kind, a, b)`` was last answered at ``tc``; then files it as answered at ``tc``."""
    e = done_head[a]
    again = False
    while e >= 0:
        if done_key[e, 0] == kind and done_key[e, 1] == b:
            again = done_time[e] == tc
            break
        e = done_next[e]
    return again


@leaf
def _file_answer(done_head, done_next, done_key, done_time, st, kind, a, b, tc):
    e = st[S_DONE]
    done_next[e] = done_head[a]
    done_key[e, 0], done_key[e, 1] = kind, b
    done_time[e] = tc
    done_head[a] = e
    st[S_DONE] = e + 1


# --- the cell table of the frame (broad_phase.CellTable), for the discs near a new path ----------------------
@jit
def _table_shape(n, cell, width, height):
    """``(nx, ny)`` of ``CellTable``: cells of side ``cell`` or more, at most ``max(4 N, 65536)``."""
    nx = max(1, int(width // cell))
    ny = max(1, int(height // cell))
    cap = max(4 * n, 1 << 16)
    if nx * ny > cap:
        scale = math.sqrt(nx * ny / cap)
        nx, ny = max(1, int(nx / scale)), max(1, int(ny / scale))
    return nx, ny


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
def _span(lo, hi, size, count, periodic):
    """``CellTable._span``: ``(first, last, wrap)``, the cells ``first..last`` (``% count`` when ``wrap``)."""
    first, last = math.floor(lo / size), math.floor(hi / size)
    if periodic:
        if last - first + 1 >= count:
            return 0, count - 1, False
        return first, last, True
    return min(max(first, 0), count - 1), min(max(last, 0), count - 1), False


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


# --- the frame's first candidates (Bisect.detect, Swept.detect) --------------------------------------------
@jit
def _grid_shape(periodic, width, height, min_cell, max_cells):
    """:func:`discsim.cells.grid_shape` without ``what`` (a periodic box under 3 cells a side gets one)."""
    nx = max(1, math.floor(width / min_cell * (1 + 1e-12)))
    ny = max(1, math.floor(height / min_cell * (1 + 1e-12)))
    if periodic and min(nx, ny) < 3:
        return 1, 1
    if nx * ny > max_cells:
        scale = math.sqrt(nx * ny / max_cells)
        floor_n = 3 if periodic else 1
        nx, ny = max(floor_n, int(nx / scale)), max(floor_n, int(ny / scale))
    return nx, ny


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
    nx, ny = _grid_shape(periodic, width, height, reach, max(4 * n, 1 << 16))
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


@jit
def _push_growing(heap, found, st, version, tc, kind, a, b):
    """:func:`_push` after making room: returns the heap and ``found``, grown when they were full."""
    ht, hn = heap
    if st[S_HEAP] == len(ht):
        ht, hn = _room_f(ht, st[S_HEAP] + 1), _room_i2(hn, st[S_HEAP] + 1)
    if kind == COLLISION:
        found = _room_i2(found, st[S_FOUND] + 1)
    _push(ht, hn, st, found, version, tc, kind, a, b)
    return (ht, hn), found


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
                if v > 0.0:
                    wt = (length - r - x) / v
                elif v < 0.0:
                    wt = (r - x) / v
                else:
                    wt = INF
                if wt <= span:
                    wall = 2 * axis + (1 if v > 0.0 else 0)
                    heap, found = _push_growing(heap, found, st, version, t0 + (0.0 if 0.0 > wt else wt), WALL, a, wall)
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


# --- responses (SubFrame._collide, _wall, _segment) -----------------------------------------------------------
@leaf
def _turn(a, tc, x, y, vx, vy, paths, version, periodic, width, height):
    """``SubFrame._turn`` (``Paths.turn``): disc ``a`` changes course at ``tc``; its new (wrapped) place."""
    ref_pos, vel, ref_t, images = paths
    version[a] += 1
    if periodic:
        wx, wy = _wrap(x, width), _wrap(y, height)
        if wx != x or wy != y:  # it left the box since its last change of course
            images[a, 0] += np.int64(np.rint((x - wx) / width))
            images[a, 1] += np.int64(np.rint((y - wy) / height))
        x, y = wx, wy
    ref_pos[a, 0], ref_pos[a, 1] = x, y
    ref_t[a] = tc
    vel[a, 0], vel[a, 1] = vx, vy
    return x, y


@leaf
def _log(ev_n, ev_f, st, frame, tc, a, b, xa, ya, vxa, vya, xb, yb, vxb, vyb):
    """Write one response to the event buffer (room made already)."""
    k = st[S_EVENTS]
    ev_n[k, 0], ev_n[k, 1], ev_n[k, 2] = frame, a, b
    f = ev_f[k]
    f[0], f[1], f[2], f[3], f[4] = tc, xa, ya, vxa, vya
    f[5], f[6], f[7], f[8] = xb, yb, vxb, vyb
    st[S_EVENTS] = k + 1


@leaf
def _at(paths, a, s):
    """Centre of disc ``a`` at time ``s`` on its current path (not wrapped)."""
    ref_pos, vel, ref_t, _ = paths
    return ref_pos[a, 0] + vel[a, 0] * (s - ref_t[a]), ref_pos[a, 1] + vel[a, 1] * (s - ref_t[a])


@leaf
def _respond(kind, tc, a, b, frame, paths, scene, moving, version, ev, st, counts, acc):
    """Answer the candidate: ``SubFrame._collide``, ``_wall`` or ``_segment``. Returns whether it did.

    ``acc``: the deepest overlap and the collision virial (changed in place).
    """
    radii, masses, periodic, width, height, segments, _, _, _ = scene
    vel = paths[1]
    ev_n, ev_f = ev
    nan = math.nan
    if kind == COLLISION:
        xa, ya = _at(paths, a, tc)
        xb, yb = _at(paths, b, tc)
        dx, dy = xb - xa, yb - ya
        if periodic:
            dx, dy = _round_image(dx, width), _round_image(dy, height)
        vxa, vya, vxb, vyb = vel[a, 0], vel[a, 1], vel[b, 0], vel[b, 1]
        if (vxb - vxa) * dx + (vyb - vya) * dy >= 0.0:  # not approaching: nothing to do
            return False
        sigma = radii[a] + radii[b]
        depth = 1.0 - cpython_hypot(dx, dy) / sigma
        if depth > acc[0]:
            acc[0] = depth
        ma, mb = masses[a], masses[b]
        uxa, uya, uxb, uyb = _collide(dx, dy, vxa, vya, vxb, vyb, ma, mb)
        acc[1] += _impulse_virial(dx, dy, vxa, vya, uxa, uya, vxb, vyb, uxb, uyb, ma, mb)
        if moving[a]:
            xa, ya = _turn(a, tc, xa, ya, uxa, uya, paths, version, periodic, width, height)
        if moving[b]:
            xb, yb = _turn(b, tc, xb, yb, uxb, uyb, paths, version, periodic, width, height)
        counts[C_DETECTIONS] += 1
        _log(ev_n, ev_f, st, frame, tc, a, b, xa, ya, uxa, uya, xb, yb, uxb, uyb)
        return True
    x, y = _at(paths, a, tc)
    vx, vy = vel[a, 0], vel[a, 1]
    if kind == WALL:
        axis, high = b // 2, b % 2
        v = vx if axis == 0 else vy
        if (v <= 0.0) if high else (v >= 0.0):  # moving away from this wall already
            return False
        if axis == 0:
            vx = -vx
        else:
            vy = -vy
    else:
        ax, ay, bx, by = segments[b, 0], segments[b, 1], segments[b, 2], segments[b, 3]
        qx, qy = _closest_point(x, y, ax, ay, bx, by)
        if vx * (x - qx) + vy * (y - qy) >= 0.0:  # receding
            return False
        vx, vy = _reflect(x, y, vx, vy, ax, ay, bx, by)
    x, y = _turn(a, tc, x, y, vx, vy, paths, version, periodic, width, height)
    counts[C_WALL_HITS] += 1
    _log(ev_n, ev_f, st, frame, tc, a, -1, x, y, vx, vy, nan, nan, nan, nan)
    return True


# --- after a change of course (SubFrame._recheck) --------------------------------------------------------------
@leaf
def _path_box(code, x, y, ex, ey):
    """``path_box``: ``(lo_x, lo_y, hi_x, hi_y)`` of the part of a new path the tests see."""
    if code == BISECT:
        return ex, ey, ex, ey  # where it ends: the test is at the frame
    return min(x, ex), min(y, ey), max(x, ex), max(y, ey)


@leaf
def _recheck(code, a, now, t, kind, other, near, count, p, tol, paths, scene, two, heap, found, version, st, counts):
    """Test disc ``a``'s new path over ``[now, t]`` against ``near[:count]``, the walls and the segments."""
    radii, _, periodic, width, height, segments, _, _, _ = scene
    ref_pos, vel, ref_t, _ = paths
    ht, hn = heap
    span = t - now
    x, y, vx, vy = ref_pos[a, 0], ref_pos[a, 1], vel[a, 0], vel[a, 1]
    r = radii[a]
    ex, ey = x + vx * span, y + vy * span
    if count:
        counts[C_PAIR_TESTS] += count
        for q in range(count):
            m = near[q]
            dx = ref_pos[m, 0] + vel[m, 0] * (now - ref_t[m]) - x
            dy = ref_pos[m, 1] + vel[m, 1] * (now - ref_t[m]) - y
            if periodic:
                dx, dy = _round_image(dx, width), _round_image(dy, height)
            dvx, dvy, sigma = vel[m, 0] - vx, vel[m, 1] - vy, r + radii[m]
            tc = INF
            if code == BISECT:
                gx, gy = dx + dvx * span, dy + dvy * span  # the gap at the frame
                if gx * gx + gy * gy < sigma * sigma:
                    tc = _bisect_pair(a, m, now, t, tol, p, paths, radii, periodic, width, height, two, counts)
            else:
                tau = _time_of_impact(dx, dy, dvx, dvy, sigma)
                if tau <= span:
                    tc = now + tau
            if tc != INF:
                _push(ht, hn, st, found, version, tc, COLLISION, min(a, m), max(a, m))
    if not periodic:
        for axis in range(2):
            p_, v, length = (x, vx, width) if axis == 0 else (y, vy, height)
            wall = 2 * axis + (1 if v > 0.0 else 0)
            if v == 0.0 or (kind == WALL and wall == other):
                continue
            tc = INF
            if code == BISECT:
                end = p_ + v * span
                if (end > length - r) if v > 0.0 else (end < r):
                    tc = _bisect_wall(a, wall, now, t, tol, p, paths, radii, width, height, two, counts)
            else:
                tau = _wall_time(p_, v, r, length)
                if tau <= span:
                    tc = now + tau
            if tc != INF:
                _push(ht, hn, st, found, version, tc, WALL, a, wall)
    if len(segments):
        counts[C_SEGMENT_TESTS] += len(segments)
        for k in range(len(segments)):
            if kind == SEGMENT and k == other:
                continue
            ax, ay, bx, by = segments[k, 0], segments[k, 1], segments[k, 2], segments[k, 3]
            tc = INF
            if code == BISECT:
                qx, qy = _closest_point(ex, ey, ax, ay, bx, by)
                if math.pow(ex - qx, two) + math.pow(ey - qy, two) < r * r:
                    tc = _bisect_segment(a, k, now, t, tol, p, paths, radii, segments, width, height, two, counts)
            else:
                tau = _segment_time_of_impact(x, y, vx, vy, r, ax, ay, bx, by)
                if tau <= span:
                    tc = now + tau
            if tc != INF:
                _push(ht, hn, st, found, version, tc, SEGMENT, a, k)


# --- growing buffers -------------------------------------------------------------------------------------------
@jit
def _room_f(a, need):
    """``a`` (1-D float) with room for ``need`` entries (copied into a larger array when short)."""
    if need <= len(a):
        return a
    b = np.empty(max(need, 2 * len(a)))
    for k in range(len(a)):
        b[k] = a[k]
    return b


@jit
def _room_i(a, need):
    """``a`` (1-D int) with room for ``need`` entries."""
    if need <= len(a):
        return a
    b = np.empty(max(need, 2 * len(a)), dtype=np.int64)
    for k in range(len(a)):
        b[k] = a[k]
    return b


@jit
def _room_i2(a, need):
    """``a`` (2-D int) with room for ``need`` rows."""
    if need <= len(a):
        return a
    b = np.empty((max(need, 2 * len(a)), a.shape[1]), dtype=np.int64)
    for k in range(len(a)):
        for c in range(a.shape[1]):
            b[k, c] = a[k, c]
    return b


@jit
def _room_f2(a, need):
    """``a`` (2-D float) with room for ``need`` rows."""
    if need <= len(a):
        return a
    b = np.empty((max(need, 2 * len(a)), a.shape[1]))
    for k in range(len(a)):
        for c in range(a.shape[1]):
            b[k, c] = a[k, c]
    return b


# --- the frames ------------------------------------------------------------------------------------------------
@jit
def sub_frames(code, times, t0, scene, sub, paths, counts, acc, jam):
    """Frames at ``times`` one after the other, each answering its contacts at their times.

    Changes the paths in place as ``SubFramePolicy.frame`` changes
    :class:`~discsim.engines.fixed_step.arrays.Paths`, and adds to ``counts`` (``C_*`` slots).

    Args:
        code: :data:`SUB_FRAME_CODES`. times ``(F,)``: the frames' times; t0: the last frame's time.
        scene: ``(radii, masses, periodic, width, height, segments, group, blocked, filtering)``, as for
            :func:`~discsim.engines.fixed_step.numba.kernels.frames`.
        sub: ``(moving, diameter, tol, two, all_pairs)``: finite masses ``(N,)`` bool, the largest
            diameter (``Shapes.diameter``), ``bisect_tol``, the float 2.0 (see the module's docstring) and
            whether the broad phase is ``"all-pairs"``.
        paths: ``(ref_pos, vel, ref_t, images, frame_pos)``, as in ``Paths``.
        counts: the counters (int64, changed in place). acc: ``[deepest overlap, collision virial]``
            (changed in place). jam: ``[a, b, kind]`` of the contact that jammed a frame (written then).

    Returns:
        ``(status, frames, ev_n, ev_f, frame_pos, jam_time)``: :data:`DONE`, or :data:`JAMMED` when a
        frame answered more than ``MAX_RESPONSES + MAX_RESPONSES_PER_DISC * N`` contacts (``jam`` and
        ``jam_time`` say which, ``frames`` the frames done before it); the events, in order, as ``ev_n``
        ``(E, 3)`` (frame index in ``times``, disc a, disc b or -1) and ``ev_f`` ``(E, 9)`` (time, then
        the positions and velocities after, as the log holds them); the positions at the last frame done.
    """
    ref_pos, vel, ref_t, images, frame_pos = paths
    radii, _, periodic, width, height, segments, _, _, _ = scene
    moving, diameter, tol, two, all_pairs = sub
    moved = (ref_pos, vel, ref_t, images)
    n = len(ref_pos)
    n_seg = len(segments)
    max_radius = 0.5 * diameter
    cap = MAX_RESPONSES + MAX_RESPONSES_PER_DISC * n
    st = np.zeros(8, dtype=np.int64)
    ht = np.empty(64)
    hn = np.empty((64, 6), dtype=np.int64)
    found = np.empty((64, 2), dtype=np.int64)
    version = np.zeros(n, dtype=np.int64)
    done_head = np.full(n, -1, dtype=np.int64)
    done_next = np.empty(64, dtype=np.int64)
    done_key = np.empty((64, 2), dtype=np.int64)
    done_time = np.empty(64)
    mark = np.zeros(n, dtype=np.int64)
    near = np.empty(n, dtype=np.int64)
    ext = np.empty((64, 2), dtype=np.int64)
    ev_n = np.empty((16, 3), dtype=np.int64)
    ev_f = np.empty((16, 9))
    p = np.empty(12)
    shape = np.empty(4)
    start, order, ext_head = np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    pos = np.empty((n, 2))
    prev = frame_pos
    for f in range(len(times)):
        t = times[f]
        span = t - t0
        for i in range(n):
            version[i] = 0
            done_head[i] = -1
        st[S_HEAP] = st[S_SEQ] = st[S_DONE] = st[S_FOUND] = st[S_EXT] = 0
        # The frame's first candidates, and where the cell table sees the discs.
        if code == BISECT:
            for i in range(n):  # Paths.flown, then Box.wrap
                x, y = ref_pos[i, 0] + vel[i, 0] * (t - ref_t[i]), ref_pos[i, 1] + vel[i, 1] * (t - ref_t[i])
                pos[i, 0], pos[i, 1] = (_wrap(x, width), _wrap(y, height)) if periodic else (x, y)
            table_reach = 0.0
            keys = _candidates(pos, diameter, all_pairs, scene)
        else:
            speed = 0.0
            for i in range(n):
                speed = max(speed, math.sqrt(vel[i, 0] * vel[i, 0] + vel[i, 1] * vel[i, 1]))
            for i in range(n):
                x, y = prev[i, 0] + vel[i, 0] * (0.5 * span), prev[i, 1] + vel[i, 1] * (0.5 * span)
                pos[i, 0], pos[i, 1] = (_wrap(x, width), _wrap(y, height)) if periodic else (x, y)
            table_reach = 0.5 * speed * span
            keys = _candidates(pos, diameter + speed * span, all_pairs, scene)
        if code == BISECT:
            (ht, hn), found = _detect_bisect(
                keys, all_pairs, pos, t0, t, tol, p, moved, scene, two, (ht, hn), found, version, st, counts
            )
        else:
            (ht, hn), found = _detect_swept(
                keys, all_pairs, pos, prev, t0, t, moved, scene, (ht, hn), found, version, st, counts
            )
        # The candidates in time order.
        table = False
        answered = 0
        while st[S_HEAP] > 0:
            tc, kind, a, b, sa, sb = _pop(ht, hn, st)
            if version[a] != sa or (kind == COLLISION and version[b] != sb):
                continue
            if _answered_at(done_head, done_next, done_key, done_time, kind, a, b, tc):
                continue  # the same contact again at the same instant (a disc caught between two things)
            done_next, done_time = _room_i(done_next, st[S_DONE] + 1), _room_f(done_time, st[S_DONE] + 1)
            done_key = _room_i2(done_key, st[S_DONE] + 1)
            _file_answer(done_head, done_next, done_key, done_time, st, kind, a, b, tc)
            answered += 1
            if answered > cap:
                jam[0], jam[1], jam[2] = a, b, kind
                return JAMMED, f, ev_n[: st[S_EVENTS]], ev_f[: st[S_EVENTS]], prev, tc
            ev_n, ev_f = _room_i2(ev_n, st[S_EVENTS] + 1), _room_f2(ev_f, st[S_EVENTS] + 1)
            if not _respond(kind, tc, a, b, f, moved, scene, moving, version, (ev_n, ev_f), st, counts, acc):
                continue
            for q in range(2):  # the discs that changed course test their new paths
                disc, partner = (a, b) if q == 0 else (b, a)
                if kind != COLLISION and q == 1:
                    break
                if kind == COLLISION and not moving[disc]:  # a wall or segment turns any disc it answers
                    continue
                if not table and not all_pairs:  # the cell table, built at the first change of course
                    cell = diameter + table_reach
                    nx, ny = _table_shape(n, cell, width, height)
                    shape[0], shape[1], shape[2], shape[3] = nx, ny, width / nx, height / ny
                    start, order = _table(pos, nx, ny, shape[2], shape[3])
                    ext_head = np.full(nx * ny, -1, dtype=np.int64)
                    table = True
                now = tc
                left = t - now
                x, y = ref_pos[disc, 0], ref_pos[disc, 1]
                ex, ey = x + vel[disc, 0] * left, y + vel[disc, 1] * left
                lo_x, lo_y, hi_x, hi_y = _path_box(code, x, y, ex, ey)
                if not all_pairs:  # SubFrame._file
                    ext = _room_i2(ext, st[S_EXT] + _cell_count(lo_x, lo_y, hi_x, hi_y, shape, periodic))
                    _table_add(disc, lo_x, lo_y, hi_x, hi_y, shape, periodic, ext_head, ext, st)
                grow = 2.0 * max_radius + table_reach
                count = _near(
                    disc,
                    partner if kind == COLLISION else -1,
                    lo_x - grow,
                    lo_y - grow,
                    hi_x + grow,
                    hi_y + grow,
                    shape,
                    periodic,
                    start,
                    order,
                    ext_head,
                    ext,
                    all_pairs,
                    scene,
                    mark,
                    near,
                    st,
                )
                need = st[S_HEAP] + count + 2 + n_seg
                ht, hn, found = _room_f(ht, need), _room_i2(hn, need), _room_i2(found, st[S_FOUND] + count)
                other = partner if kind == COLLISION else b
                _recheck(
                    code, disc, now, t, kind, other, near, count, p, tol, moved, scene, two, (ht, hn), found,
                    version, st, counts,
                )  # fmt: skip
        # The frame's end: the discs' places, and the deepest overlap of the pairs that were candidates.
        for i in range(n):
            x, y = ref_pos[i, 0] + vel[i, 0] * (t - ref_t[i]), ref_pos[i, 1] + vel[i, 1] * (t - ref_t[i])
            pos[i, 0], pos[i, 1] = (_wrap(x, width), _wrap(y, height)) if periodic else (x, y)
        for k in range(st[S_FOUND]):
            i, j = found[k, 0], found[k, 1]
            dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
            if periodic:
                dx, dy = _image(dx, width), _image(dy, height)
            depth = 1.0 - math.hypot(dx, dy) / (radii[i] + radii[j])
            if depth > acc[0]:
                acc[0] = depth
        prev, pos = pos, prev
        t0 = t
    k = st[S_EVENTS]
    return DONE, len(times), ev_n[:k], ev_f[:k], prev, 0.0
