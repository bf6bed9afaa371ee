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
``_cells`` and ``_near_pairs``) or every pair. The parts live in their own modules:
:mod:`~discsim.engines.fixed_step.numba.detection` (the frame's first candidates and the bisection),
:mod:`~discsim.engines.fixed_step.numba.candidates` (the heap, the contacts answered, the growing buffers)
and :mod:`~discsim.engines.fixed_step.numba.cell_table`; this module answers the candidates
(``SubFrame._collide``, ``_wall``, ``_segment``), tests the new paths (``SubFrame._recheck``) and drives the
frames (:func:`sub_frames`).

The functions that run per candidate take ``_nrt=False`` (no reference counts on their array arguments)
and allocate nothing: :func:`sub_frames` makes room in the growing buffers before it calls them.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.engines.fixed_step.numba.candidates import (
    BISECT,
    C_DETECTIONS,
    C_PAIR_TESTS,
    C_SEGMENT_TESTS,
    C_WALL_HITS,
    COLLISION,
    INF,
    S_DONE,
    S_EVENTS,
    S_EXT,
    S_FOUND,
    S_HEAP,
    S_SEQ,
    SEGMENT,
    SUB_FRAME_CODES,
    SWEPT,
    WALL,
    _answered_at,
    _file_answer,
    _pop,
    _push,
    _room_f,
    _room_f2,
    _room_i,
    _room_i2,
    leaf,
)
from discsim.engines.fixed_step.numba.cell_table import _cell_count, _near, _table, _table_add, _table_shape
from discsim.engines.fixed_step.numba.detection import (
    _bisect_pair,
    _bisect_segment,
    _bisect_wall,
    _candidates,
    _detect_bisect,
    _detect_swept,
    _overlapping,
)
from discsim.engines.fixed_step.numba.kernels import (
    _closest_point,
    _collide,
    _image,
    _image_step,
    _impulse_virial,
    _kinetic_loss,
    _nearest_image,
    _restitution,
    _rough_pair,
    _segment_bounce,
    _spin_loss,
    _spin_to,
    _wall_bounce,
    _wrap,
    cpython_hypot,
    jit,
)
from discsim.physics.compiled import advance
from discsim.physics.compiled import pair_time_of_impact as _time_of_impact
from discsim.physics.compiled import segment_time_of_impact as _segment_time_of_impact
from discsim.physics.compiled import wall_time as _wall_time

__all__ = ["BISECT", "COLLISION", "JAMMED", "SEGMENT", "SUB_FRAME_CODES", "SWEPT", "WALL", "_overlapping", "sub_frames"]

# Why sub_frames returned.
DONE, JAMMED = 0, 1
#: A frame with more responses than this, plus this many per disc, is jammed (``SubFrame.MAX_RESPONSES``).
MAX_RESPONSES = 1000
MAX_RESPONSES_PER_DISC = 50


# --- responses (SubFrame._collide, _wall, _segment) -----------------------------------------------------------
@leaf
def _turn(a, tc, x, y, vx, vy, paths, version, periodic, width, height):
    """``SubFrame._turn`` (``Paths.turn``): disc ``a`` changes course at ``tc``; its new (wrapped) place."""
    ref_pos, vel, ref_t, images = paths
    version[a] += 1
    if periodic:
        wx, wy = _wrap(x, width), _wrap(y, height)
        if wx != x or wy != y:  # it left the box since its last change of course
            images[a, 0] += _image_step(x, wx, width)
            images[a, 1] += _image_step(y, wy, height)
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
    x, y, _, _ = advance(ref_pos[a, 0], ref_pos[a, 1], vel[a, 0], vel[a, 1], s - ref_t[a])
    return x, y


@leaf
def _respond(kind, tc, a, b, frame, paths, scene, moving, version, ev, st, counts, acc, laws, turning):
    """Answer the candidate: ``SubFrame._collide``, ``_wall`` or ``_segment``. Returns whether it did.

    ``acc``: the deepest overlap, the collision virial and the energy dissipated (changed in place);
    ``laws``: the restitution, ``turning``: the roughness and the spins, as for :func:`sub_frames`.
    """
    radii, masses, periodic, width, height, segments, _, _, _ = scene
    e0, per_group, table, group, tc_model, last = laws
    beta, inertia, spins, angles, angle_t = turning
    rough = beta != -1.0
    vel = paths[1]
    ev_n, ev_f = ev
    nan = math.nan
    if kind == COLLISION:
        xa, ya = _at(paths, a, tc)
        xb, yb = _at(paths, b, tc)
        dx, dy = xb - xa, yb - ya
        if periodic:
            dx, dy = _nearest_image(dx, width), _nearest_image(dy, height)
        vxa, vya, vxb, vyb = vel[a, 0], vel[a, 1], vel[b, 0], vel[b, 1]
        if (vxb - vxa) * dx + (vyb - vya) * dy >= 0.0:  # not approaching: nothing to do
            return False
        sigma = radii[a] + radii[b]
        depth = 1.0 - cpython_hypot(dx, dy) / sigma
        if depth > acc[0]:
            acc[0] = depth
        ma, mb = masses[a], masses[b]
        e = _restitution(a, b, tc, e0, per_group, table, group, tc_model, last)
        uxa, uya, uxb, uyb = _collide(dx, dy, vxa, vya, vxb, vyb, ma, mb, e)
        if rough:  # the tangential impulse at the contact point turns both
            _spin_to(a, tc, spins, angles, angle_t)
            _spin_to(b, tc, spins, angles, angle_t)
            wa, wb = spins[a], spins[b]
            uxa, uya, uxb, uyb, spins[a], spins[b] = _rough_pair(
                dx, dy, vxa, vya, vxb, vyb, uxa, uya, uxb, uyb, wa, wb, radii[a], radii[b], ma, mb,
                inertia[a], inertia[b], beta,
            )  # fmt: skip
            acc[2] += _spin_loss(inertia[a], wa, spins[a])
            acc[2] += _spin_loss(inertia[b], wb, spins[b])
        if e != 1.0 or rough:
            acc[2] += _kinetic_loss(ma, vxa, vya, uxa, uya) + _kinetic_loss(mb, vxb, vyb, uxb, uyb)
        if tc_model > 0.0:  # the TC model's clocks (an obstacle keeps none)
            if moving[a]:
                last[a] = tc
            if moving[b]:
                last[b] = tc
        acc[1] += _impulse_virial(dx, dy, vxa, vya, uxa, uya, vxb, vyb, uxb, uyb, ma, mb)
        if moving[a]:
            xa, ya = _turn(a, tc, xa, ya, uxa, uya, paths, version, periodic, width, height)
        if moving[b]:
            xb, yb = _turn(b, tc, xb, yb, uxb, uyb, paths, version, periodic, width, height)
        counts[C_DETECTIONS] += 1
        _log(ev_n, ev_f, st, frame, tc, a, b, xa, ya, uxa, uya, xb, yb, uxb, uyb)
        return True
    x, y = _at(paths, a, tc)
    wx, wy = vel[a, 0], vel[a, 1]
    if kind == WALL:
        axis, high = b // 2, b % 2
        v = wx if axis == 0 else wy
        if (v <= 0.0) if high else (v >= 0.0):  # moving away from this wall already
            return False
        e = _restitution(a, a, tc, e0, per_group, table, group, tc_model, last)
        vx, vy, w = _wall_bounce(wx, wy, axis, high == 0, e, spins[a], radii[a], masses[a], inertia[a], beta)
    else:
        ax, ay, bx, by = segments[b, 0], segments[b, 1], segments[b, 2], segments[b, 3]
        qx, qy = _closest_point(x, y, ax, ay, bx, by)
        if wx * (x - qx) + wy * (y - qy) >= 0.0:  # receding
            return False
        e = _restitution(a, a, tc, e0, per_group, table, group, tc_model, last)
        vx, vy, w = _segment_bounce(x, y, wx, wy, ax, ay, bx, by, e, spins[a], radii[a], masses[a], inertia[a], beta)
    if rough:
        _spin_to(a, tc, spins, angles, angle_t)
        acc[2] += _spin_loss(inertia[a], spins[a], w)
        spins[a] = w
    if e != 1.0 or rough:
        acc[2] += _kinetic_loss(masses[a], wx, wy, vx, vy)
    if tc_model > 0.0:
        last[a] = tc
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
            xm, ym, _, _ = advance(ref_pos[m, 0], ref_pos[m, 1], vel[m, 0], vel[m, 1], now - ref_t[m])
            dx, dy = xm - x, ym - y
            if periodic:
                dx, dy = _nearest_image(dx, width), _nearest_image(dy, height)
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


# --- the frames ------------------------------------------------------------------------------------------------
@jit
def sub_frames(code, times, t0, scene, sub, paths, counts, acc, jam, laws, turning):
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
        counts: the counters (int64, changed in place). acc: ``[deepest overlap, collision virial, energy
            dissipated]`` (changed in place). jam: ``[a, b, kind]`` of the contact that jammed a frame
            (written then).
        laws: ``(e, per_group, e_table, e_group, tc, last_collision)``: the arguments of
            :func:`~discsim.engines.fixed_step.parts.restitution` (``last_collision`` changed in place; no
            gravity: the sub-frame policies refuse it).
        turning: ``(beta, inertia, spins, angles, angle_times)``, as for
            :func:`~discsim.engines.fixed_step.numba.kernels.frames`.

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
                x, y, _, _ = advance(ref_pos[i, 0], ref_pos[i, 1], vel[i, 0], vel[i, 1], t - ref_t[i])
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
            ev = (ev_n, ev_f)
            if not _respond(kind, tc, a, b, f, moved, scene, moving, version, ev, st, counts, acc, laws, turning):
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
            x, y, _, _ = advance(ref_pos[i, 0], ref_pos[i, 1], vel[i, 0], vel[i, 1], t - ref_t[i])
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
