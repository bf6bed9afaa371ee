"""The frame policies ``resolve``, ``revert`` and ``separate``, compiled: one call does a whole frame.

The algorithm and the order of the floating-point operations are those of
:mod:`discsim.engines.fixed_step.frame` and :mod:`discsim.engines.fixed_step.broad_phase`, so both
backends give the same frames bit for bit: the move on the lazy clocks, the wall hits (by disc), the
segment hits (by disc, then segment), then the overlapping pairs sorted by ``(i, j)``, each pair seeing the
velocities the pairs before it left. The Verlet list of the ``"grid"`` broad phase is rebuilt in the same
order as :func:`discsim.cells.neighbour_pairs` gives its pairs, so the exported state is the same too.
Python's ``math.hypot`` (used by ``"separate"``) is not the C library's ``hypot``: ``cpython_hypot``
(:mod:`~discsim.engines.fixed_step.numba.hypot`) is CPython's own algorithm, so the two agree to the last bit.

:func:`frames` does a batch of frames in one call (a run's frames cost no interpreter time between them).
Every function is ``njit(cache=True)`` (no fastmath: it would reorder the floating-point operations); the
first process compiles them (about 10 s of CPU) and writes the machine code to ``__pycache__``; later
processes load it (about half a second). Without numba the functions stay plain Python: importable (for
doctests) and correct, only slow. The hot loops reassign no array and call no function that takes one:
either costs reference counts on every pass.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.engines.fixed_step.numba.frame_parts import (  # noqa: F401 (the frame's parts, used here and by the other kernels)
    _image,
    _image_step,
    _impulse_virial,
    _kinetic_loss,
    _moving_segment_bounce,
    _nearest_image,
    _parts,
    _push_off_segment,
    _restitution,
    _rough_pair,
    _segment_bounce,
    _separate_pair,
    _spin_loss,
    _wall_bounce,
    _wrap,
    jit,
)
from discsim.engines.fixed_step.numba.hypot import cpython_hypot
from discsim.engines.fixed_step.numba.verlet import _cells, _near_pairs, _stale, build_list  # noqa: F401
from discsim.physics.compiled import advance
from discsim.physics.compiled import closest_point_on_segment as _closest_point
from discsim.physics.compiled import collide as _collide

#: The compiled policies by name: the ``policy`` argument of :func:`frames`.
POLICY_CODES = {"resolve": 0, "revert": 1, "separate": 2}
RESOLVE, REVERT, SEPARATE = 0, 1, 2
INF = math.inf


# --- scalar helpers --------------------------------------------------------------------------------------
@jit
def _segment_distance(px, py, ax, ay, bx, by):
    """:func:`discsim.engines.fixed_step.frame.point_segment_distance` of one point and one segment."""
    ex, ey = bx - ax, by - ay
    ee = ex * ex + ey * ey
    wx, wy = px - ax, py - ay
    u = (wx * ex + wy * ey) / ee if ee > 0.0 else 0.0
    u = min(max(u, 0.0), 1.0)
    return math.hypot(wx - u * ex, wy - u * ey)  # numpy's hypot: the C library's, as numba's


# --- the event buffer ------------------------------------------------------------------------------------
# A frame's events go to ``ev_n`` (E, 3) int64: the frame's index in the batch, disc i, disc j (-1 for a
# wall or segment hit); and ``ev_f`` (E, 8): the discs' positions and velocities after (NaN for no j).
@jit
def _grow(ev_n, ev_f, need):
    """The buffer with room for ``need`` events (copied into larger arrays when short)."""
    if need <= len(ev_n):
        return ev_n, ev_f
    size = max(need, 2 * len(ev_n))
    new_n = np.empty((size, 3), dtype=np.int64)
    new_f = np.empty((size, 8))
    for k in range(len(ev_n)):  # loops, not slice assignments: they compile in a fraction of the time
        for c in range(3):
            new_n[k, c] = ev_n[k, c]
        for c in range(8):
            new_f[k, c] = ev_f[k, c]
    return new_n, new_f


@jit
def _log_wall(ev_n, ev_f, k, frame, i, x, y, vx, vy):
    """The buffer with the hit of disc ``i`` written at row ``k``."""
    ev_n, ev_f = _grow(ev_n, ev_f, k + 1)
    ev_n[k, 0], ev_n[k, 1], ev_n[k, 2] = frame, i, -1
    ev_f[k, 0], ev_f[k, 1], ev_f[k, 2], ev_f[k, 3] = x, y, vx, vy
    for c in range(4, 8):
        ev_f[k, c] = math.nan
    return ev_n, ev_f


@jit
def _spin_to(i, t, spins, angles, angle_t):
    """``Paths.spin_to``: disc ``i``'s angle brought to time ``t`` (before its spin changes there)."""
    angles[i] += spins[i] * (t - angle_t[i])
    angle_t[i] = t


# --- the steps of a frame --------------------------------------------------------------------------------
@jit
def _walls(
    policy, pos, prev, vel, radii, masses, width, height, ref_pos, ref_t, t, ev_n, ev_f, k, frame, laws, turning
):
    """Discs past a wall and moving outwards: reverse the normal velocity (with restitution and roughness);
    returns ``(k, ev_n, ev_f)``."""
    _, _, _, _, e0, per_group, table, group, tc, last, lost = laws
    beta, inertia, spins, angles, angle_t = turning
    rough = beta != -1.0
    for i in range(len(pos)):
        r = radii[i]
        hit = False
        wx, wy = vel[i, 0], vel[i, 1]
        e = 1.0
        w0 = w = spins[i]
        for axis in range(2):
            size = width if axis == 0 else height
            p, v = pos[i, axis], (wx if axis == 0 else wy)  # walls_crossed: the velocity at the frame
            low = p < r and v < 0.0
            high = p > size - r and v > 0.0
            if low or high:
                if not hit:
                    e = _restitution(i, i, t, e0, per_group, table, group, tc, last)
                hit = True
                u = vel[i, axis]
                if (u < 0.0) if low else (u > 0.0):  # still outwards (a rough bounce off the other wall may turn it)
                    vel[i, 0], vel[i, 1], w = _wall_bounce(
                        vel[i, 0], vel[i, 1], axis, low, e, w, r, masses[i], inertia[i], beta
                    )
                if policy == SEPARATE:
                    pos[i, axis] = r if low else size - r
        if not hit:
            continue
        if rough:
            _spin_to(i, t, spins, angles, angle_t)
        if e != 1.0 or rough:
            lost[0] += _kinetic_loss(masses[i], wx, wy, vel[i, 0], vel[i, 1])
        if rough:
            spins[i] = w
            lost[0] += _spin_loss(inertia[i], w0, w)
        if tc > 0.0:
            last[i] = t
        if policy == REVERT:
            pos[i, 0], pos[i, 1] = prev[i, 0], prev[i, 1]
        ref_pos[i, 0], ref_pos[i, 1] = pos[i, 0], pos[i, 1]
        ref_t[i] = t
        ev_n, ev_f = _log_wall(ev_n, ev_f, k, frame, i, pos[i, 0], pos[i, 1], vel[i, 0], vel[i, 1])
        k += 1
    return k, ev_n, ev_f


@jit
def _off_segments(policy, x, y, vx, vy, px, py, segments, cut, r, e, w, m, inertia, beta):
    """One disc cutting the segments ``cut`` (in order): ``(x, y, vx, vy, w, responded)``.

    ``FramePolicy.off_segments`` (``"resolve"``, ``"separate"``) and ``Revert.off_segments``; ``(px, py)``
    is the disc's position at the previous frame; ``w``, ``m``, ``inertia``: its spin, mass, moment of inertia;
    ``beta``: the roughness. ``segments`` ``(S, 6)``: the ends where they are at the frame and the velocities (a
    moving segment is approached, and bounces the disc, in its frame; ``"revert"`` tests it where it is at the frame).
    """
    responded = False
    reverted = False
    for s in cut:
        ax, ay, bx, by = segments[s, 0], segments[s, 1], segments[s, 2], segments[s, 3]
        sx, sy = segments[s, 4], segments[s, 5]
        qx, qy = _closest_point(x, y, ax, ay, bx, by)
        nx, ny = x - qx, y - qy
        if policy == REVERT and not reverted:
            cx, cy = _closest_point(px, py, ax, ay, bx, by)
            if (vx - sx) * (px - cx) + (vy - sy) * (py - cy) < 0.0:  # approaching there: reflect at the restored place
                x, y, nx, ny = px, py, px - cx, py - cy
                reverted = True
            elif (vx - sx) * nx + (vy - sy) * ny < 0.0:  # approaching only at the frame: restore, keep its normal
                fx, fy = x, y
                x, y = px, py
                reverted = True
                vx, vy, w = _moving_segment_bounce(fx, fy, vx, vy, ax, ay, bx, by, sx, sy, e, w, r, m, inertia, beta)
                responded = True
                continue
        if (vx - sx) * nx + (vy - sy) * ny >= 0.0:  # receding (or the centre is on the segment): leave it
            continue
        if policy == SEPARATE:
            x, y = _push_off_segment(x, y, qx, qy, nx, ny, r, cpython_hypot(nx, ny))
        vx, vy, w = _moving_segment_bounce(x, y, vx, vy, ax, ay, bx, by, sx, sy, e, w, r, m, inertia, beta)
        responded = True
    return x, y, vx, vy, w, responded


@jit
def _segments(
    policy, pos, prev, vel, radii, masses, segments, ref_pos, ref_t, t, ev_n, ev_f, k, frame, laws, turning, moving
):
    """Discs cutting a segment (``segments`` ``(S, 6)`` where they are at the frame, see :func:`_segments_at`), each
    answered by :func:`_off_segments`; ``moving``: some segment moves. Returns ``(k, ev_n, ev_f)``."""
    _, _, _, _, e0, per_group, table, group, tc, last, lost = laws
    beta, inertia, spins, angles, angle_t = turning
    rough = beta != -1.0
    cut = np.empty(len(segments), dtype=np.int64)
    for i in range(len(pos)):
        x, y, r = pos[i, 0], pos[i, 1], radii[i]
        m = 0
        for s in range(len(segments)):
            if _segment_distance(x, y, segments[s, 0], segments[s, 1], segments[s, 2], segments[s, 3]) < r:
                cut[m] = s
                m += 1
        if m == 0:
            continue
        wx, wy = vel[i, 0], vel[i, 1]
        e = _restitution(i, i, t, e0, per_group, table, group, tc, last)
        w0 = spins[i]
        x, y, vx, vy, w, responded = _off_segments(
            policy, x, y, wx, wy, prev[i, 0], prev[i, 1], segments, cut[:m], r, e, w0, masses[i], inertia[i], beta
        )
        if responded:
            if moving:  # what the bounces took, in the first segment's frame (FramePolicy._segments)
                fx, fy = segments[cut[0], 4], segments[cut[0], 5]
                lost[0] += _kinetic_loss(masses[i], wx - fx, wy - fy, vx - fx, vy - fy)
            elif e != 1.0 or rough:
                lost[0] += _kinetic_loss(masses[i], wx, wy, vx, vy)
            if rough:
                _spin_to(i, t, spins, angles, angle_t)
                spins[i] = w
                lost[0] += _spin_loss(inertia[i], w0, w)
            if tc > 0.0:
                last[i] = t
            pos[i, 0], pos[i, 1] = x, y
            vel[i, 0], vel[i, 1] = vx, vy
            ref_pos[i, 0], ref_pos[i, 1] = x, y
            ref_t[i] = t
            ev_n, ev_f = _log_wall(ev_n, ev_f, k, frame, i, x, y, vx, vy)
            k += 1
    return k, ev_n, ev_f


@jit
def _moves(segments):
    """Whether some segment of ``segments`` ``(S, 6)`` has a velocity."""
    for s in range(len(segments)):
        if segments[s, 4] != 0.0 or segments[s, 5] != 0.0:
            return True
    return False


@jit
def _segments_at(segments, t):
    """``segments`` ``(S, 6)`` (ends at time 0, velocities) where they are at time ``t``: ``p0 + velocity t``, as
    :meth:`~discsim.engines.fixed_step.arrays.Shapes.segments_at` computes them."""
    out = np.empty_like(segments)
    for s in range(len(segments)):
        vx, vy = segments[s, 4], segments[s, 5]
        out[s, 0], out[s, 1] = segments[s, 0] + vx * t, segments[s, 1] + vy * t
        out[s, 2], out[s, 3] = segments[s, 2] + vx * t, segments[s, 3] + vy * t
        out[s, 4], out[s, 5] = vx, vy
    return out


@jit
def _depth(dx, dy, contact):
    """``(overlapping, depth)``: whether discs ``(dx, dy)`` apart overlap, and how deep (a fraction of contact)."""
    dist2 = dx * dx + dy * dy
    if dist2 < contact * contact:
        return True, 1.0 - math.sqrt(dist2) / contact
    return False, 0.0


@jit
def _push(keys, m, key):
    """``keys`` with ``key`` at index ``m`` (copied into a larger array when full)."""
    if m == len(keys):
        grown = np.empty(2 * m, dtype=np.int64)
        for p in range(m):
            grown[p] = keys[p]
        keys = grown
    keys[m] = key
    return keys


@jit
def _overlaps(pos, radii, li, lj, all_pairs, periodic, width, height, group, blocked, filtering, overlap):
    """Overlapping pairs as sorted keys ``min * N + max``, the pairs tested, and the deepest overlap.

    The candidates are the Verlet list ``(li, lj)``, or every pair ``i < j`` (``all_pairs``) less
    those that pass through each other.
    """
    if all_pairs:
        keys, m, tests, overlap = _overlaps_all(pos, radii, periodic, width, height, group, blocked, filtering, overlap)
    else:
        keys = np.empty(len(li), dtype=np.int64)
        m, overlap = _overlaps_listed(keys, pos, radii, li, lj, periodic, width, height, overlap)
        tests = len(li)
    _heapsort(keys, m)
    return keys[:m], tests, overlap


@jit
def _sift(keys, root, end):
    """Move ``keys[root]`` down the max-heap ``keys[:end]`` to its place."""
    while 2 * root + 1 < end:
        child = 2 * root + 1
        if child + 1 < end and keys[child] < keys[child + 1]:
            child += 1
        if keys[root] >= keys[child]:
            return
        keys[root], keys[child] = keys[child], keys[root]
        root = child


@jit
def _heapsort(keys, m):
    """Sort ``keys[:m]`` in place (ints: the order ``np.sort`` gives; written out, it compiles 10x faster)."""
    for root in range(m // 2 - 1, -1, -1):
        _sift(keys, root, m)
    for end in range(m - 1, 0, -1):
        keys[0], keys[end] = keys[end], keys[0]
        _sift(keys, 0, end)


@jit
def _overlaps_listed(keys, pos, radii, li, lj, periodic, width, height, overlap):
    """The pairs of the Verlet list that overlap, as keys written to ``keys``; ``(how many, overlap)``.

    (No array is reassigned in the loop and no function that takes one is called: either costs
    reference counts on every pass, which made the test of a pair several times slower.)
    """
    n = len(pos)
    m = 0
    for p in range(len(li)):
        i, j = li[p], lj[p]
        dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
        if periodic:
            dx, dy = _image(dx, width), _image(dy, height)
        hit, depth = _depth(dx, dy, radii[i] + radii[j])
        if hit:
            overlap = max(overlap, depth)
            keys[m] = min(i, j) * n + max(i, j)
            m += 1
    return m, overlap


@jit
def _overlaps_all(pos, radii, periodic, width, height, group, blocked, filtering, overlap):
    """Every pair ``i < j`` that overlaps (the ``"all-pairs"`` broad phase): ``(keys, m, tests, overlap)``."""
    n = len(pos)
    keys = np.empty(16, dtype=np.int64)
    m = 0
    tests = 0
    for i in range(n):
        for j in range(i + 1, n):
            if filtering and blocked[group[i], group[j]]:
                continue
            tests += 1
            dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
            if periodic:
                dx, dy = _image(dx, width), _image(dy, height)
            hit, depth = _depth(dx, dy, radii[i] + radii[j])
            if hit:
                overlap = max(overlap, depth)
                keys = _push(keys, m, i * n + j)
                m += 1
    return keys, m, tests, overlap


@jit
def _contact(policy, xi, yi, xj, yj, dx, dy, dvx, dvy, mi, mj, sigma, prev, i, j, periodic, width, height):
    """``FramePolicy.contact`` of each policy: where the discs are left and the line of the impulse."""
    if policy == REVERT:
        xi, yi = prev[i, 0], prev[i, 1]
        xj, yj = prev[j, 0], prev[j, 1]
        px, py = xj - xi, yj - yi
        if periodic:
            px, py = _nearest_image(px, width), _nearest_image(py, height)
        if dvx * px + dvy * py < 0.0:  # else keep the frame's line, which is approaching
            dx, dy = px, py
    elif policy == SEPARATE:
        xi, yi, xj, yj, dx, dy = _separate_pair(xi, yi, xj, yj, dx, dy, mi, mj, sigma, cpython_hypot(dx, dy))
    return xi, yi, xj, yj, dx, dy


@jit
def _pairs(policy, keys, pos, prev, paths, t, scene, changed, flown, ev_n, ev_f, k, frame, virial, laws, turning):
    """Answer the overlapping pairs in order (keys ``i * N + j``); returns ``(k, virial)``: the events
    written so far and the collision virial with these responses added.

    Marks the discs that change course in ``changed``; in a periodic box, keeps in ``flown`` where each
    one's old path put it at ``t`` (``Paths.flown``, not wrapped), for its image count.
    """
    ref_pos, vel, ref_t, _ = paths
    radii, masses, periodic, width, height, _, _, _, _ = scene
    _, _, _, _, e0, per_group, table, group, tc, last, lost = laws
    beta, inertia, spins, angles, angle_t = turning
    rough = beta != -1.0
    n = len(pos)
    for key in keys:
        i, j = key // n, key % n
        xi, yi, xj, yj = pos[i, 0], pos[i, 1], pos[j, 0], pos[j, 1]
        dx, dy = xj - xi, yj - yi
        if periodic:
            dx, dy = _nearest_image(dx, width), _nearest_image(dy, height)
        vxi, vyi, vxj, vyj = vel[i, 0], vel[i, 1], vel[j, 0], vel[j, 1]
        dvx, dvy = vxj - vxi, vyj - vyi
        if dvx * dx + dvy * dy >= 0.0:  # separating already (an earlier response this frame)
            continue
        mi, mj = masses[i], masses[j]
        sigma = radii[i] + radii[j]
        xi, yi, xj, yj, dx, dy = _contact(
            policy, xi, yi, xj, yj, dx, dy, dvx, dvy, mi, mj, sigma, prev, i, j, periodic, width, height
        )
        e = _restitution(i, j, t, e0, per_group, table, group, tc, last)
        uxi, uyi, uxj, uyj = _collide(dx, dy, vxi, vyi, vxj, vyj, mi, mj, e)
        if rough:  # the tangential impulse at the contact point turns both
            _spin_to(i, t, spins, angles, angle_t)
            _spin_to(j, t, spins, angles, angle_t)
            wi, wj = spins[i], spins[j]
            uxi, uyi, uxj, uyj, spins[i], spins[j] = _rough_pair(
                dx, dy, vxi, vyi, vxj, vyj, uxi, uyi, uxj, uyj, wi, wj, radii[i], radii[j], mi, mj,
                inertia[i], inertia[j], beta,
            )  # fmt: skip
            lost[0] += _spin_loss(inertia[i], wi, spins[i])
            lost[0] += _spin_loss(inertia[j], wj, spins[j])
        if e != 1.0 or rough:
            lost[0] += _kinetic_loss(mi, vxi, vyi, uxi, uyi) + _kinetic_loss(mj, vxj, vyj, uxj, uyj)
        if tc > 0.0:  # the TC model's clocks (an obstacle keeps none)
            if mi != INF:
                last[i] = t
            if mj != INF:
                last[j] = t
        sx, sy = xj - xi, yj - yi  # where the impulse is applied
        if periodic:
            sx, sy = _nearest_image(sx, width), _nearest_image(sy, height)
        virial += _impulse_virial(sx, sy, vxi, vyi, uxi, uyi, vxj, vyj, uxj, uyj, mi, mj)
        if periodic:  # no walls: ref_pos, ref_t and vel still hold the path the disc had at the last frame
            for d in (i, j):
                if not changed[d]:
                    flown[d, 0], flown[d, 1], _, _ = advance(
                        ref_pos[d, 0], ref_pos[d, 1], vel[d, 0], vel[d, 1], t - ref_t[d]
                    )
        pos[i, 0], pos[i, 1], pos[j, 0], pos[j, 1] = xi, yi, xj, yj
        vel[i, 0], vel[i, 1], vel[j, 0], vel[j, 1] = uxi, uyi, uxj, uyj
        changed[i] = changed[j] = True
        ev_n[k, 0], ev_n[k, 1], ev_n[k, 2] = frame, i, j
        f = ev_f[k]
        f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7] = xi, yi, uxi, uyi, xj, yj, uxj, uyj
        k += 1
    return k, virial


# --- the frame -------------------------------------------------------------------------------------------
#: Slots of the ``counts`` array of :func:`frames`: the engine's counters of the same names.
C_PAIR_TESTS, C_SEGMENT_TESTS, C_DETECTIONS, C_WALL_HITS, C_LIST_BUILDS = range(5)


@jit
def _frame(
    policy, t, frame, scene, paths, broad, frame_pos, pos, ev_n, ev_f, k, counts, overlap, virial, laws, turning
):
    """One frame at time ``t`` (index ``frame`` in the batch): from ``frame_pos`` (the last frame's
    positions) to ``pos`` (written); see :func:`frames`.

    Returns:
        ``(k, ev_n, ev_f, list_pos, list_i, list_j, overlap, virial)``: the events written so far, the
        buffer, the Verlet list, the deepest overlap and the collision virial.
    """
    ref_pos, vel, ref_t, images = paths
    radii, masses, periodic, width, height, segments, group, blocked, filtering = scene
    all_pairs, list_pos, list_i, list_j, limit2, reach2, nx, ny, per_x, per_y = broad
    gx, gy, drag, falls, lost = laws[0], laws[1], laws[2], laws[3], laws[10]
    falling = gx != 0.0 or gy != 0.0 or drag != 0.0  # (spares the free-flight loop a read of falls per disc)
    n = len(ref_pos)
    for i in range(n):  # Paths.flown and Paths.fall, then Box.wrap
        if falling and falls[i]:  # under gravity or drag: along the exact path, and a new path from the frame
            x0, y0, vx0, vy0 = ref_pos[i, 0], ref_pos[i, 1], vel[i, 0], vel[i, 1]
            x, y, vx, vy = advance(x0, y0, vx0, vy0, t - ref_t[i], gx, gy, drag)
            if drag != 0.0:  # what the drag took since the last frame (Paths.drag_loss, Tally.lose)
                kinetic = 0.5 * ((vx0 * vx0 + vy0 * vy0) - (vx * vx + vy * vy))
                lost[0] += masses[i] * (kinetic + gx * (x - x0) + gy * (y - y0))
            vel[i, 0], vel[i, 1] = vx, vy
            ref_pos[i, 0], ref_pos[i, 1] = x, y
            ref_t[i] = t
        else:
            x, y, _, _ = advance(ref_pos[i, 0], ref_pos[i, 1], vel[i, 0], vel[i, 1], t - ref_t[i])
        if periodic:
            x, y = _wrap(x, width), _wrap(y, height)
        pos[i, 0], pos[i, 1] = x, y
    first = k
    if not periodic:
        k, ev_n, ev_f = _walls(
            policy, pos, frame_pos, vel, radii, masses, width, height, ref_pos, ref_t, t, ev_n, ev_f, k, frame, laws,
            turning,
        )  # fmt: skip
    if len(segments):
        counts[C_SEGMENT_TESTS] += n * len(segments)
        moving = _moves(segments)
        here = _segments_at(segments, t) if moving else segments
        k, ev_n, ev_f = _segments(
            policy, pos, frame_pos, vel, radii, masses, here, ref_pos, ref_t, t, ev_n, ev_f, k, frame, laws,
            turning, moving,
        )  # fmt: skip
    counts[C_WALL_HITS] += k - first
    if not all_pairs and (len(list_pos) == 0 or _stale(pos, list_pos, periodic, width, height, limit2)):
        list_i, list_j = build_list(
            pos, reach2, nx, ny, per_x, per_y, periodic, width, height, group, blocked, filtering, len(list_i)
        )
        list_pos = pos.copy()
        counts[C_LIST_BUILDS] += 1
    keys, tests, overlap = _overlaps(
        pos, radii, list_i, list_j, all_pairs, periodic, width, height, group, blocked, filtering, overlap
    )
    counts[C_PAIR_TESTS] += tests
    if len(keys):
        ev_n, ev_f = _grow(ev_n, ev_f, k + len(keys))
        changed = np.zeros(n, dtype=np.bool_)
        flown = np.empty((n if periodic else 0, 2))
        before = k
        k, virial = _pairs(
            policy, keys, pos, frame_pos, paths, t, scene, changed, flown, ev_n, ev_f, k, frame, virial, laws, turning
        )
        counts[C_DETECTIONS] += k - before
        for i in range(n):  # Paths.restart
            if not changed[i]:
                continue
            if periodic:
                images[i, 0] += _image_step(flown[i, 0], pos[i, 0], width)
                images[i, 1] += _image_step(flown[i, 1], pos[i, 1], height)
            ref_pos[i, 0], ref_pos[i, 1] = pos[i, 0], pos[i, 1]
            ref_t[i] = t
        if periodic:
            for i in range(n):
                pos[i, 0], pos[i, 1] = _wrap(pos[i, 0], width), _wrap(pos[i, 1], height)
    return k, ev_n, ev_f, list_pos, list_i, list_j, overlap, virial


@jit
def frames(policy, times, scene, paths, broad, counts, overlap, virial, laws, turning):
    """Frames at ``times`` one after the other: move every disc to the frame, then answer what overlaps there.

    Changes the paths in place, as ``FramePolicy.frame`` changes
    :class:`~discsim.engines.fixed_step.arrays.Paths`, and adds to ``counts`` (``C_*`` slots). The
    positions at the last frame come back as a new array (``frame_pos`` may be overwritten).

    Args:
        policy: :data:`POLICY_CODES`. times ``(F,)``: the frames' times.
        scene: ``(radii, masses, periodic, width, height, segments, group, blocked, filtering)``:
            per-disc radii and masses, the box, the segments' end points at time 0 and velocities ``(S, 6)``
            (``x0, y0, x1, y1, vx, vy``), the collision
            filter (``Scene.group``, ``Scene.blocked``, ``Scene.filtering``).
        paths: ``(ref_pos, vel, ref_t, images, frame_pos)``, as in ``Paths``.
        broad: ``(all_pairs, list_pos, list_i, list_j, limit2, reach2, nx, ny, per_x, per_y)``: every
            pair (``all_pairs``), or the ``"grid"`` broad phase's Verlet list (``list_pos`` of length 0
            before the first build), rebuilt when a disc has moved more than ``sqrt(limit2)`` since, from
            the pairs nearer than ``sqrt(reach2)``, found on ``nx x ny`` cells (``per_x``, ``per_y`` cells
            per unit length).
        counts: the counters (int64, changed in place). overlap: the deepest overlap seen so far.
        virial: the collision virial so far (``Tally.virial``).
        laws: ``(gx, gy, drag, falls, e, per_group, e_table, e_group, tc, last_collision, lost)``: gravity, the
            drag, the discs they move ``(N,)`` bool, the arguments of
            :func:`~discsim.engines.fixed_step.parts.restitution` (``Shapes``' ``e``, ``per_group``, ``e_table``
            ``(G, G)``, ``e_group`` ``(N,)`` int64, ``tc``, and ``Paths.last_collision``, changed in place), and
            ``lost`` ``(1,)``: ``Tally.dissipated``, added to in place (the responses' losses and the drag's).
        turning: ``(beta, inertia, spins, angles, angle_times)``: the roughness (-1: smooth, the rest unread), the
            moments of inertia ``(N,)``, and ``Paths.spins``, ``angles``, ``angle_times`` (changed in place).

    Returns:
        ``(ev_n, ev_f, frame_pos, list_pos, list_i, list_j, overlap, virial)``: the events, in order, as
        ``ev_n`` ``(E, 3)`` (frame index in ``times``, disc i, disc j or -1 for a wall or segment hit) and
        ``ev_f`` ``(E, 8)`` (positions and velocities after, as the log holds them); the positions at the
        last frame; the Verlet list; the deepest overlap; the collision virial.
    """
    ref_pos, vel, ref_t, images, frame_pos = paths
    moving = (ref_pos, vel, ref_t, images)
    prev, pos = frame_pos, np.empty_like(frame_pos)  # two buffers, swapped after each frame
    ev_n = np.empty((16, 3), dtype=np.int64)
    ev_f = np.empty((16, 8))
    k = 0
    all_pairs, list_pos, list_i, list_j, limit2, reach2, nx, ny, per_x, per_y = broad
    for f in range(len(times)):
        here = (all_pairs, list_pos, list_i, list_j, limit2, reach2, nx, ny, per_x, per_y)
        k, ev_n, ev_f, list_pos, list_i, list_j, overlap, virial = _frame(
            policy, times[f], f, scene, moving, here, prev, pos, ev_n, ev_f, k, counts, overlap, virial, laws, turning
        )
        prev, pos = pos, prev
    return ev_n[:k], ev_f[:k], prev, list_pos, list_i, list_j, overlap, virial
