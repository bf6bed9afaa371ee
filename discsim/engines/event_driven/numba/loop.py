"""The compiled event loop: the Python backend's algorithm, on plain arrays, compiled by numba.

Imported only by :class:`~discsim.engines.event_driven.numba.backend.NumbaBackend`, and only when numba
imports (``discsim._numba``). Every function is ``njit(cache=True)``: the first process compiles them
(seconds) and writes machine code next to this file's ``__pycache__``; later processes load it. Those the
loop calls on every event with many arrays (``predict``, ``push``, the prefetches) are ``inline``: compiled
into each caller, since a call between compiled functions passes every array argument as a struct of seven
words (``predict`` takes twenty arrays), which cost 1.24x at N = 10^4 (a first compile 8 s longer). The
queue's block updates stay calls: inlined too, they made the loop larger and slower (0.94x at N = 10^4) and
the first compile 12 s longer.

The algorithm, the order of the floating-point operations and the tie-breaking are those of
:mod:`discsim.engines.event_driven.python.backend`, so both backends give the same events bit for bit;
only the data structures differ:

- ``rec`` ``(N, 8)`` float64, one 64-byte row per disc (one cache line): x, y, vx, vy, t_ref, radius,
  mass (inf for an obstacle), and the time of the disc's kept collision;
- cells as singly linked lists (``head`` per cell, ``nxt`` per disc), which keep
  each cell's members in the order they entered, as the Python backend's tuples do;
- the queue, one pending event per disc (``qt``, ``qk``, ``qo``, ``qs``: time, kind, other, stamp) and a
  binary heap of blocks of 16 discs ordered by their earliest ``(time, owner)``, popping in the same order as
  the Python backend's queues;
- counters and scalars in two small arrays, ``ints`` and ``floats`` (the ``I_*`` and ``F_*`` slots);
- ``rot`` ``(N, 4)`` float64, each disc's turning: its spin, moment of inertia, and its angle at an absolute time
  (``W``, ``INERTIA``, ``ANGLE``, ``ANGLE_T``); only ``run_events`` takes it, and only its rough branches
  (``LAWS``, roughness above -1) write it: spins change at collisions of rough discs only.
"""

from __future__ import annotations

import math

import numpy as np

from discsim._compiled import inline, jit
from discsim.engines.event_driven.numba import blocks, moving
from discsim.engines.event_driven.numba.blocks import BLOCK, BLOCK_SHIFT, discard, push, reblock  # noqa: F401
from discsim.engines.event_driven.numba.cells import _enter, _leave, link, unlink  # noqa: F401
from discsim.engines.event_driven.numba.sensing import resense, sense, wrap_sense
from discsim.engines.event_driven.numba.support import (  # noqa: F401
    ANGLE,
    ANGLE_T,
    INERTIA,
    KEPT,
    VX,
    VY,
    M,
    R,
    T,
    W,
    X,
    Y,
    _prefetch_cells,
    _prefetch_disc,
    accel,
    drag_loss,
    restitution,
    spin_energy,
    supported,
    turn,
)
from discsim.events import EventKind
from discsim.laws import BETA, DRAG, GX, GY, LAW_SLOTS, REST_SPEED, TC
from discsim.physics.compiled import (
    advance,
    closest_point_on_segment,
    collide,
    cross,
    pair_predict,
    pair_resolve,
    predict_x,
    predict_y,
    reflect,
    reflect_off_segment,
    rough_impulse,
    segment_time_of_impact,
    sensor_predict,
)
from discsim.physics.sources.boundaries import MINUS_X, MINUS_Y, PLUS_X, PLUS_Y

INF = math.inf
COLLISION, WALL, CROSSING, SEGMENT, SET = (
    int(k) for k in (EventKind.COLLISION, EventKind.WALL, EventKind.CROSSING, EventKind.SEGMENT, EventKind.SET)
)
SENSOR, PISTON = int(EventKind.SENSOR), int(EventKind.PISTON)
# Slots of ``ints``.
I_PRED, I_COLL, I_WALL, I_CROSS, I_STALE, I_SINCE, I_MAXQ, I_SIZE, I_LKIND, I_LI, I_LJ, I_RESTS, I_SENSE = range(13)
N_INTS = 13
if I_SIZE != blocks.I_SIZE:  # the queue (blocks.py) counts its events in the same slot
    raise ImportError("blocks.I_SIZE is not the loop's I_SIZE")
# Slots of ``floats``.
F_EPOCH, F_VIRIAL, F_OVERLAP, F_TIME, F_LTIME, F_LOST = range(6)
N_FLOATS = 6
#: Whether the loop reads the laws (gravity, restitution, the TC model, rest; :class:`~discsim.laws.Laws`): a
#: constant, so that this module's loop, the one every run of the default laws takes, compiles no branch of
#: theirs (reading them at run time cost 15% at N = 10^3 and 10^4); :func:`with_laws` compiles the loop again
#: with it True, cached under its own names.
LAWS = False
# Why run_events returned: the queue holds nothing before ``until`` or the event limit was met; the
# budget of pops or the log buffer ran out (call again); the crossing budget was spent.
DONE, MORE, CROSSINGS = 0, 1, 2


# --- prediction ----------------------------------------------------------------------------------------
@inline
def predict(
    i, t, exclude, direction,
    rec, count, kept_partner, kept_stamp, cell, head, nxt,
    nx, ny, periodic, edges,
    seg, seg_start, seg_idx, group, blocked, rest,
    qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
):  # fmt: skip
    """Schedule disc ``i``'s earliest event after ``t``, as the Python backend's ``predict`` does.

    Its collision with a disc in the 3x3 cells around it (never ``exclude``; after a crossing in
    ``direction`` only the 3 cells that just became adjacent, with the kept collision standing for
    the other 6 while its partner has not changed course), its wall or segment hit, or its cell
    crossing; the earliest collision found is kept per disc.
    """
    ints[I_PRED] += 1
    width = edges[nx]
    height = edges[nx + 1 + ny]
    ri = rec[i, R]
    gx = gy = drag = 0.0
    if LAWS:  # a constant: the loop of the default laws compiles none of this (see with_laws)
        gx, gy = edges[nx + ny + 2 + GX], edges[nx + ny + 2 + GY]
        drag = edges[nx + ny + 2 + DRAG]
    gravity = LAWS and (gx != 0.0 or gy != 0.0)
    axi, ayi = accel(i, gravity, gx, gy, rec, rest)
    xi, yi, vxi, vyi = advance(rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], t - rec[i, T], axi, ayi, drag)
    c = cell[i]
    cx = c // ny
    cy = c - cx * ny
    # 1. The earliest collision with a neighbour.
    partner = kept_partner[i]
    after_crossing = direction >= 0 and (partner < 0 or count[partner] == kept_stamp[i])
    best = INF
    new_partner = -1
    filtering = group.shape[0] != 0  # the filter's groups, or none (nothing passes through anything)
    gi = group[i] if filtering else 0
    for ddx in range(-1, 2):
        if after_crossing and ((direction == PLUS_X and ddx != 1) or (direction == MINUS_X and ddx != -1)):
            continue
        ox = cx + ddx
        sx = 0.0
        if periodic:
            if ox < 0:
                ox += nx
                sx = -width
            elif ox >= nx:
                ox -= nx
                sx = width
        elif ox < 0 or ox >= nx:
            continue
        for ddy in range(-1, 2):
            if after_crossing and ((direction == PLUS_Y and ddy != 1) or (direction == MINUS_Y and ddy != -1)):
                continue
            oy = cy + ddy
            sy = 0.0
            if periodic:
                if oy < 0:
                    oy += ny
                    sy = -height
                elif oy >= ny:
                    oy -= ny
                    sy = height
            elif oy < 0 or oy >= ny:
                continue
            j = head[ox * ny + oy]
            if j < 0:
                continue
            offx = sx - xi
            offy = sy - yi
            while j >= 0:
                if j == i or j == exclude or (filtering and blocked[gi, group[j]]):
                    j = nxt[j]
                    continue
                axj = ayj = 0.0
                if gravity:
                    axj, ayj = accel(j, gravity, gx, gy, rec, rest)
                tij = pair_predict(
                    rec[j, X], rec[j, Y], rec[j, VX], rec[j, VY], t - rec[j, T], rec[j, R], offx, offy, vxi, vyi, ri,
                    axj, ayj, axj - axi, ayj - ayi, drag,
                )  # fmt: skip
                if tij < best:
                    best = tij
                    new_partner = j
                j = nxt[j]
    if after_crossing:
        t_hit = rec[i, KEPT]
        if t + best < t_hit:
            t_hit = t + best
            partner = new_partner
            rec[i, KEPT] = t_hit
            kept_partner[i] = partner
            kept_stamp[i] = count[partner]
    else:
        t_hit = t + best
        partner = new_partner
        rec[i, KEPT] = t_hit
        kept_partner[i] = partner
        if partner >= 0:
            kept_stamp[i] = count[partner]
    # 2. The next wall, segment or cell boundary.
    walled = not periodic
    best, kind, other = predict_x(
        xi, vxi, ri, edges[cx], edges[cx + 1], width, walled and cx == 0, walled and cx == nx - 1, axi, drag
    )
    ty, kind_y, other_y = predict_y(
        yi, vyi, ri, edges[nx + 1 + cy], edges[nx + 2 + cy], height, walled and cy == 0, walled and cy == ny - 1, ayi,
        drag,
    )  # fmt: skip
    if ty < best:
        best, kind, other = ty, kind_y, other_y
    for m in range(seg_start[c], seg_start[c + 1]):
        k = seg_idx[m]
        if LAWS and seg[k, 4] != 0.0:  # a sensor (row k of seg): when i's centre next changes sides of it
            n = rec.shape[0]
            ts = sensor_predict(
                xi, yi, vxi, vyi, axi, ayi, drag, seg[k, 4], seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3],
                rest[n + i * ((rest.shape[0] - n) // n) + int(seg[k, 5])] != 0,
            )  # fmt: skip
            if ts < best or (ts == best and kind != SENSOR):  # a tie with the box's edge: sensed first (the wrap
                # after would take the side unseen); among sensors, the first
                best, kind, other = ts, SENSOR, k
        elif k != -2 - exclude:  # not the segment just left
            if LAWS and (seg[k, 6] != 0.0 or seg[k, 7] != 0.0):  # a moving segment: where it is now, in its frame
                ux, uy = seg[k, 6], seg[k, 7]
                ts = segment_time_of_impact(  # (drag -gamma v is -gamma (w + u) in its frame: an added force)
                    xi, yi, vxi - ux, vyi - uy, ri, seg[k, 0] + ux * t, seg[k, 1] + uy * t, seg[k, 2] + ux * t,
                    seg[k, 3] + uy * t, axi - drag * ux, ayi - drag * uy, drag,
                )  # fmt: skip
            else:
                ts = segment_time_of_impact(
                    xi, yi, vxi, vyi, ri, seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3], axi, ayi, drag
                )
            if ts < best:
                best, kind, other = ts, SEGMENT, k
    stamp = 0
    if LAWS and edges.shape[0] > nx + ny + 2 + LAW_SLOTS:  # the piston above (its numbers last): when i meets it
        ts = moving.time(yi, vyi, ayi, ri, t, edges)
        if ts < best:
            best, kind, other, stamp = ts, PISTON, -1, int(edges[edges.shape[0] - moving.SLOTS + moving.P_HITS])
    if best < 0.0:
        best = 0.0
    # 3. Schedule the earlier of the two.
    t_best = t + best
    if t_hit <= t_best and partner >= 0:
        push(i, t_hit, COLLISION, partner, count[partner], qt, bheap, bht, bpos, barg, qk, qo, qs, ints)
    elif best == INF:
        discard(i, qt, bheap, bht, bpos, barg, ints)
    else:
        push(i, t_best, kind, other, stamp, qt, bheap, bht, bpos, barg, qk, qo, qs, ints)


@jit
def predict_all(
    rec, count, kept_partner, kept_stamp, cell, head, nxt,
    nx, ny, periodic, edges,
    seg, seg_start, seg_idx, group, blocked, rest,
    qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
):  # fmt: skip
    """The start of a run: predict every moving disc at time 0, in internal order."""
    for i in range(rec.shape[0]):
        if rec[i, M] != INF:
            predict(
                i, 0.0, -1, -1, rec, count, kept_partner, kept_stamp, cell, head, nxt,
                nx, ny, periodic, edges,
                seg, seg_start, seg_idx, group, blocked, rest,
                qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
            )  # fmt: skip
    ints[I_MAXQ] = ints[I_SIZE]


@jit
def set_disc(
    i, x, y, vx, vy, new_cell, t,
    rec, count, kept_partner, kept_stamp, cell, head, nxt,
    nx, ny, periodic, edges,
    seg, seg_start, seg_idx, group, blocked, rest,
    qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
):  # fmt: skip
    """Restart disc ``i``'s path at ``t`` from ``(x, y)`` with ``(vx, vy)`` (in cell ``new_cell``), as the Python
    backend's ``set_disc``: its counter moves on (events predicted against it go stale) and it alone is re-predicted.
    """
    if new_cell != cell[i]:
        _leave(i, cell[i], head, nxt)
        _enter(i, new_cell, head, nxt)
        cell[i] = new_cell
    rec[i, X] = x
    rec[i, Y] = y
    rec[i, VX] = vx
    rec[i, VY] = vy
    rec[i, T] = t
    rest[i] = 0  # an edited disc falls again
    count[i] += 1
    predict(
        i, t, -1, -1, rec, count, kept_partner, kept_stamp, cell, head, nxt,
        nx, ny, periodic, edges,
        seg, seg_start, seg_idx, group, blocked, rest,
        qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
    )  # fmt: skip
    if ints[I_SIZE] > ints[I_MAXQ]:
        ints[I_MAXQ] = ints[I_SIZE]


# --- the hot loop --------------------------------------------------------------------------------------
@jit
def run_events(
    until, limit, crossings, budget, rebase_every, recording,
    rec, count, order, images, kept_partner, kept_stamp, cell, head, nxt,
    nx, ny, periodic, edges,
    seg, seg_start, seg_idx, group, blocked, rest,
    qt, bheap, bht, bpos, barg, qk, qo, qs, ints, floats, etab, egroup, tlast, found, rot,
    ev_t, ev_kind, ev_i, ev_j, ev_f, ev_w,
):  # fmt: skip
    """Process events with times <= ``until``: the Python backend's ``process_events``, compiled.

    Stops after ``limit`` physical events (-1: no limit), ``crossings`` cell crossings (-1: none),
    ``budget`` pops, or when the log buffer (``ev_*``, written when ``recording``) is full; a rough run
    (``LAWS``, roughness above -1) also logs the spins after each event in ``ev_w`` (disc ``i``'s, ``j``'s).

    Returns:
        ``(done, crossed, logged, why)``: physical events, crossings, records written, and
        why it stopped (``DONE``, ``MORE`` or ``CROSSINGS``).
    """
    width = edges[nx]
    height = edges[nx + 1 + ny]
    law = edges[nx + ny + 2 :]  # the laws' numbers follow the cells' edges
    gx = gy = drag = 0.0
    if LAWS:
        gx, gy, drag = law[GX], law[GY], law[DRAG]
    gravity = LAWS and (gx != 0.0 or gy != 0.0)
    beta = -1.0
    if LAWS:
        beta = law[BETA]
    rough = LAWS and beta != -1.0
    n_coll = n_wall = n_cross = n_stale = n_sense = 0
    done = 0
    logged = 0
    capacity = ev_t.shape[0]
    pops = 0
    # The log rows one event may write: its own, and under gravity one for every disc it wakes (the backend makes
    # the buffer that much larger).
    room = 1 + (rec.shape[0] if gravity else 0)
    why = DONE
    max_queue = ints[I_MAXQ]
    virial = floats[F_VIRIAL]
    max_overlap = floats[F_OVERLAP]
    epoch = floats[F_EPOCH]
    horizon = until - epoch
    rebase_at = rebase_every - ints[I_SINCE]
    now, have_now = np.nan, False
    last_time, last_kind, last_i, last_j = floats[F_LTIME], ints[I_LKIND], ints[I_LI], ints[I_LJ]
    while done != limit:
        if pops == budget or (recording and logged + room > capacity):
            why = MORE
            break
        # Pop the earliest event if it is due.
        if ints[I_SIZE] == 0:
            break
        i = barg[bheap[0]]
        t = bht[0]
        if t > horizon:
            break
        pops += 1
        kind = qk[i]
        other = qo[i]
        woke = -1  # a disc at rest this event wakes: what it held up falls again (below)
        # At large N every record below waits for memory, and the next disc is known only when the queue
        # pops it: ask now for the records of this event's partner and its cells, and of the two events
        # most likely next (the heap's second and third), so that the fetches overlap (no effect on results).
        for k in range(1, min(3, bheap.shape[0])):
            _prefetch_disc(barg[bheap[k]], rec, count, kept_partner, kept_stamp, cell, qt, qk, qo, qs)
        if kind == COLLISION:
            _prefetch_disc(other, rec, count, kept_partner, kept_stamp, cell, qt, qk, qo, qs)
        c = cell[i]
        if kind == CROSSING:  # the cells around the one it enters
            cx, cy, _, _ = cross(c // ny, c - (c // ny) * ny, other, nx, ny)
            c = cx * ny + cy
        _prefetch_cells(c, head, nx, ny)
        # The event stays at the top of the heap: predicting i again, as every branch below does,
        # replaces it (see push).
        if kind == COLLISION:
            j = other
            if count[j] != qs[i]:  # the partner has changed course since the prediction
                n_stale += 1
                predict(
                    i, t, -1, -1, rec, count, kept_partner, kept_stamp, cell, head, nxt,
                    nx, ny, periodic, edges,
                    seg, seg_start, seg_idx, group, blocked, rest,
                    qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
                )  # fmt: skip
                continue
            mi, mj = rec[i, M], rec[j, M]
            axi, ayi = accel(i, gravity, gx, gy, rec, rest)
            axj, ayj = accel(j, gravity, gx, gy, rec, rest)
            xi, yi, vxi, vyi = advance(rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], t - rec[i, T], axi, ayi, drag)
            xj, yj, vxj, vyj = advance(rec[j, X], rec[j, Y], rec[j, VX], rec[j, VY], t - rec[j, T], axj, ayj, drag)
            if LAWS and drag != 0.0:  # what the drag took over the flights this collision ends
                floats[F_LOST] += drag_loss(i, axi, ayi, rec, xi, yi, vxi, vyi)
                floats[F_LOST] += drag_loss(j, axj, ayj, rec, xj, yj, vxj, vyj)
            e = restitution(i, j, t + epoch, law, etab, egroup, tlast) if LAWS else 1.0
            dx, dy, uxi, uyi, uxj, uyj = pair_resolve(
                xi, yi, vxi, vyi, mi, xj, yj, vxj, vyj, mj, width, height, periodic, e
            )
            moved_j = mj != INF  # obstacles never move, and their counter never changes
            if LAWS and rough:  # the tangential impulse at the contact turns both (at right angles to the normal one)
                turn(i, t + epoch, rot)
                turn(j, t + epoch, rot)
                wi, wj = rot[i, W], rot[j, W]
                txi, tyi, txj, tyj, rot[i, W], rot[j, W] = rough_impulse(
                    dx, dy, vxi, vyi, vxj, vyj, wi, wj, rec[i, R], rec[j, R], mi, mj, rot[i, INERTIA], rot[j, INERTIA],
                    beta,
                )  # fmt: skip
                uxi, uyi, uxj, uyj = uxi + (txi - vxi), uyi + (tyi - vyi), uxj + (txj - vxj), uyj + (tyj - vyj)
                floats[F_LOST] += spin_energy(rot[i, INERTIA], wi) - spin_energy(rot[i, INERTIA], rot[i, W])
                floats[F_LOST] += spin_energy(rot[j, INERTIA], wj) - spin_energy(rot[j, INERTIA], rot[j, W])
            i_falls = gravity and rest[i] == 0  # (owners are never obstacles)
            if gravity and i_falls != (moved_j and rest[j] == 0):
                # One falls onto a support (an obstacle or a disc at rest): too slow a bounce and it rests there.
                if not i_falls:  # i supports j: the normal points from i to j
                    bounce = -e * ((vxj - vxi) * dx + (vyj - vyi) * dy)
                    up = -(gx * dx + gy * dy)
                else:
                    bounce = -e * ((vxi - vxj) * -dx + (vyi - vyj) * -dy)
                    up = gx * dx + gy * dy
                norm = math.sqrt(dx * dx + dy * dy)
                slow = bounce < law[REST_SPEED] * norm
                if slow and up > 0.0:  # landed on it: the faller rests
                    if not i_falls:
                        uxi, uyi, uxj, uyj = vxi, vyi, 0.0, 0.0
                        rest[j] = 1
                    else:
                        uxi, uyi, uxj, uyj = 0.0, 0.0, vxj, vyj
                        rest[i] = 1
                    ints[I_RESTS] += 1
                elif slow:  # a slow touch from the side or below: the support holds, as an obstacle would (waking
                    # it for so little would set a pile resting and waking at one instant for ever)
                    if not i_falls:
                        uxi, uyi = vxi, vyi
                        _, _, uxj, uyj = collide(dx, dy, vxi, vyi, vxj, vyj, INF, mj, e)
                    else:
                        uxi, uyi, _, _ = collide(dx, dy, vxi, vyi, vxj, vyj, mi, INF, e)
                        uxj, uyj = vxj, vyj
                else:  # hit hard enough: a support at rest wakes (an obstacle stays), and what it held up
                    woke = i if not i_falls else (j if moved_j else -1)
                    rest[i] = 0
                    if moved_j:
                        rest[j] = 0
            if LAWS and (e != 1.0 or gravity or rough):
                lost = 0.5 * mi * ((vxi * vxi + vyi * vyi) - (uxi * uxi + uyi * uyi))
                if moved_j:
                    lost += 0.5 * mj * ((vxj * vxj + vyj * vyj) - (uxj * uxj + uyj * uyj))
                floats[F_LOST] += lost
            if LAWS and law[TC] > 0.0:
                tlast[i] = t + epoch
                if moved_j:
                    tlast[j] = t + epoch
            overlap = 1.0 - math.sqrt(dx * dx + dy * dy) / (rec[i, R] + rec[j, R])
            if overlap > max_overlap:
                max_overlap = overlap
            rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], rec[i, T] = xi, yi, uxi, uyi, t
            rec[j, X], rec[j, Y], rec[j, VX], rec[j, VY], rec[j, T] = xj, yj, uxj, uyj, t
            _prefetch_cells(cell[j], head, nx, ny)
            virial -= mi * ((uxi - vxi) * dx + (uyi - vyi) * dy)  # owners are never obstacles
            count[i] += 1
            n_coll += 1
            done += 1
            if recording:
                ev_t[logged] = t + epoch
                ev_kind[logged] = COLLISION
                ev_i[logged] = order[i]
                ev_j[logged] = order[j]
                ev_f[logged, 0], ev_f[logged, 1], ev_f[logged, 2], ev_f[logged, 3] = xi, yi, uxi, uyi
                ev_f[logged, 4], ev_f[logged, 5], ev_f[logged, 6], ev_f[logged, 7] = xj, yj, uxj, uyj
                if LAWS and rough:
                    ev_w[logged, 0], ev_w[logged, 1] = rot[i, W], rot[j, W]
                logged += 1
            # The pair cannot meet again before one of them changes course, unless one falls and the other
            # does not (a ball bouncing on a disc at rest comes back): then neither is excluded.
            alike = not gravity or (rest[i] == 0) == (moved_j and rest[j] == 0)
            predict(
                i, t, j if alike else -1, -1, rec, count, kept_partner, kept_stamp, cell, head, nxt,
                nx, ny, periodic, edges,
                seg, seg_start, seg_idx, group, blocked, rest,
                qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
            )  # fmt: skip
            if moved_j:
                count[j] += 1
                predict(
                    j, t, i if alike else -1, -1, rec, count, kept_partner, kept_stamp, cell, head, nxt,
                    nx, ny, periodic, edges,
                    seg, seg_start, seg_idx, group, blocked, rest,
                    qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
                )  # fmt: skip
                if ints[I_SIZE] > max_queue:
                    max_queue = ints[I_SIZE]
            last_time, last_kind, last_i, last_j = t + epoch, COLLISION, i, j
        elif kind == WALL or kind == SEGMENT:
            axi, ayi = accel(i, gravity, gx, gy, rec, rest)
            xi, yi, vxi, vyi = advance(rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], t - rec[i, T], axi, ayi, drag)
            if LAWS and drag != 0.0:
                floats[F_LOST] += drag_loss(i, axi, ayi, rec, xi, yi, vxi, vyi)
            e = restitution(i, i, t + epoch, law, etab, egroup, tlast) if LAWS else 1.0
            wx, wy = vxi, vyi
            fx = fy = 0.0  # the velocity of what it bounces off
            if LAWS and kind == SEGMENT:
                fx, fy = seg[other, 6], seg[other, 7]
            if LAWS and (fx != 0.0 or fy != 0.0):  # a moving segment: the bounce in its frame, where it is now
                vxi, vyi = reflect_off_segment(
                    xi, yi, vxi - fx, vyi - fy, seg[other, 0] + fx * t, seg[other, 1] + fy * t,
                    seg[other, 2] + fx * t, seg[other, 3] + fy * t, e,
                )  # fmt: skip
                vxi, vyi = vxi + fx, vyi + fy
                exclude = -1 if gravity else -2 - other
                if gravity and rest[i] != 0:  # it hit a disc at rest: it flies, and what it held up falls
                    rest[i] = 0
                    woke = i
            elif kind == SEGMENT:
                vxi, vyi = reflect_off_segment(
                    xi, yi, vxi, vyi, seg[other, 0], seg[other, 1], seg[other, 2], seg[other, 3], e
                )
                # never the same segment again straight away (a falling disc may come back: not excluded)
                exclude = -1 if gravity else -2 - other
            else:
                vxi, vyi = reflect(vxi, vyi, other, e)
                exclude = -1
            if LAWS and rough:  # the wall (or segment) is as rough as the discs: the same law against an infinite mass
                if kind == SEGMENT:  # (where it is now, in its frame if it moves)
                    sx0, sy0, sx1, sy1 = seg[other, 0] + fx * t, seg[other, 1] + fy * t, seg[other, 2], seg[other, 3]
                    qx, qy = closest_point_on_segment(xi, yi, sx0, sy0, sx1 + fx * t, sy1 + fy * t)
                    cxw, cyw = qx - xi, qy - yi  # from the centre towards the contact point
                elif other == 0:
                    cxw, cyw = (-1.0 if xi < 0.5 * width else 1.0), 0.0
                else:
                    cxw, cyw = 0.0, (-1.0 if yi < 0.5 * height else 1.0)
                turn(i, t + epoch, rot)
                wi = rot[i, W]
                txi, tyi, _, _, rot[i, W], _ = rough_impulse(
                    cxw, cyw, wx - fx, wy - fy, 0.0, 0.0, wi, 0.0, rec[i, R], 0.0, rec[i, M], INF, rot[i, INERTIA], INF,
                    beta,
                )  # fmt: skip
                vxi, vyi = vxi + (txi - (wx - fx)), vyi + (tyi - (wy - fy))
                floats[F_LOST] += spin_energy(rot[i, INERTIA], wi) - spin_energy(rot[i, INERTIA], rot[i, W])
            if gravity and fx == 0.0 and fy == 0.0:  # too slow a bounce off a fixed floor: the disc rests
                if kind == SEGMENT:
                    sx0, sy0, sx1, sy1 = seg[other, 0], seg[other, 1], seg[other, 2], seg[other, 3]
                    qx, qy = closest_point_on_segment(xi, yi, sx0, sy0, sx1, sy1)
                    nxw, nyw = xi - qx, yi - qy
                elif other == 0:
                    nxw, nyw = (1.0 if xi < 0.5 * width else -1.0), 0.0
                else:
                    nxw, nyw = 0.0, (1.0 if yi < 0.5 * height else -1.0)
                norm = math.sqrt(nxw * nxw + nyw * nyw)
                if gx * nxw + gy * nyw < 0.0 and vxi * nxw + vyi * nyw < law[REST_SPEED] * norm:
                    vxi = vyi = 0.0
                    rest[i] = 1
                    ints[I_RESTS] += 1
            if LAWS and (fx != 0.0 or fy != 0.0):  # what the bounce took, in the segment's frame (it does work)
                floats[F_LOST] += (
                    0.5
                    * rec[i, M]
                    * (
                        ((wx - fx) * (wx - fx) + (wy - fy) * (wy - fy))
                        - ((vxi - fx) * (vxi - fx) + (vyi - fy) * (vyi - fy))
                    )
                )
            elif LAWS and (e != 1.0 or gravity or rough):
                floats[F_LOST] += 0.5 * rec[i, M] * ((wx * wx + wy * wy) - (vxi * vxi + vyi * vyi))
            if LAWS and law[TC] > 0.0:
                tlast[i] = t + epoch
            rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], rec[i, T] = xi, yi, vxi, vyi, t
            count[i] += 1
            n_wall += 1
            done += 1
            if recording:
                ev_t[logged] = t + epoch
                ev_kind[logged] = WALL
                ev_i[logged] = order[i]
                ev_j[logged] = -1
                ev_f[logged, 0], ev_f[logged, 1], ev_f[logged, 2], ev_f[logged, 3] = xi, yi, vxi, vyi
                ev_f[logged, 4] = ev_f[logged, 5] = ev_f[logged, 6] = ev_f[logged, 7] = np.nan
                if LAWS and rough:
                    ev_w[logged, 0], ev_w[logged, 1] = rot[i, W], np.nan
                logged += 1
            predict(
                i, t, exclude, -1, rec, count, kept_partner, kept_stamp, cell, head, nxt,
                nx, ny, periodic, edges,
                seg, seg_start, seg_idx, group, blocked, rest,
                qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
            )  # fmt: skip
            last_time, last_kind, last_i, last_j = t + epoch, WALL, i, -1
        elif LAWS and (kind == PISTON or kind == SENSOR):  # i meets the piston (unless it was hit since the
            # prediction: its path is higher now) or changes sides of the sensor of row ``other`` (the path goes on)
            if kind == PISTON and qs[i] != int(edges[edges.shape[0] - moving.SLOTS + moving.P_HITS]):
                n_stale += 1
            elif kind == PISTON:
                axi, ayi = accel(i, gravity, gx, gy, rec, rest)
                moving.hit(i, t, epoch, axi, ayi, recording, logged, rec, edges, order, ev_t, ev_kind, ev_i, ev_j, ev_f)
                if gravity and rest[i] != 0:  # it hit a disc at rest: it flies, and what it held up falls
                    rest[i], woke = 0, i
                count[i] += 1
                n_wall, done, logged = n_wall + 1, done + 1, logged + (1 if recording else 0)
                last_time, last_kind, last_i, last_j = t + epoch, WALL, i, -1
            else:
                sensed = sense(
                    i, t, other, epoch, gravity, gx, gy, drag, rough, recording, logged, rec, rest, seg, order, rot,
                    ev_t, ev_kind, ev_i, ev_j, ev_f, ev_w,
                )  # fmt: skip
                if sensed >= 0:  # (not beyond a trip wire's ends)
                    n_sense, done, logged = n_sense + 1, done + 1, logged + (1 if recording else 0)
                    last_time, last_kind, last_i, last_j = t + epoch, sensed, i, int(seg[other, 5])
            predict(
                i, t, -1, -1, rec, count, kept_partner, kept_stamp, cell, head, nxt,
                nx, ny, periodic, edges,
                seg, seg_start, seg_idx, group, blocked, rest,
                qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
            )  # fmt: skip
        else:  # cell crossing: the trajectory is unchanged, only the neighbourhood
            c = cell[i]
            cx, cy, wrap_x, wrap_y = cross(c // ny, c - (c // ny) * ny, other, nx, ny)
            sensed = s = -1
            if LAWS and (wrap_x != 0 or wrap_y != 0) and rest.shape[0] > rec.shape[0]:  # sensors it crosses there
                sensed, s = wrap_sense(
                    i, t, epoch, wrap_x, wrap_y, width, height, gravity, gx, gy, drag, rough, recording, logged, rec,
                    rest, seg, order, rot, ev_t, ev_kind, ev_i, ev_j, ev_f, ev_w,
                )  # fmt: skip
            if sensed >= 0:  # one an event (sensing.py): the jump waits, pushed again
                n_sense, done, logged = n_sense + 1, done + 1, logged + (1 if recording else 0)
                last_time, last_kind, last_i, last_j = t + epoch, sensed, i, s
                push(i, t, CROSSING, other, 0, qt, bheap, bht, bpos, barg, qk, qo, qs, ints)
            else:
                _leave(i, c, head, nxt)
                if wrap_x != 0:  # out through one edge of the box, in through the other
                    rec[i, X], images[i, 0] = rec[i, X] - wrap_x * width, images[i, 0] + wrap_x
                elif wrap_y != 0:
                    rec[i, Y], images[i, 1] = rec[i, Y] - wrap_y * height, images[i, 1] + wrap_y
                if LAWS and (wrap_x != 0 or wrap_y != 0) and rest.shape[0] > rec.shape[0]:  # the sides here
                    resense(i, t, gravity, gx, gy, drag, rec, rest, seg, width, height)
                c = cell[i] = cx * ny + cy
                _enter(i, c, head, nxt)
                n_cross += 1
                predict(
                    i, t, -1, other, rec, count, kept_partner, kept_stamp, cell, head, nxt,
                    nx, ny, periodic, edges,
                    seg, seg_start, seg_idx, group, blocked, rest,
                    qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
                )  # fmt: skip
                if n_cross == crossings:
                    now, have_now, why = t, True, CROSSINGS
                    break
        if LAWS and woke >= 0:  # the discs at rest that the woken support held up fall again from here
            for m in range(supported(woke, gx, gy, rec, rest, cell, head, nxt, nx, ny, periodic, edges, found)):
                d = found[m]
                rec[d, T] = t  # at rest: its record holds where it is, now
                count[d] += 1
                if recording:  # a SET record: it falls from here (trajectories, the viewer and replays know)
                    ev_t[logged] = t + epoch
                    ev_kind[logged] = SET
                    ev_i[logged] = order[d]
                    ev_j[logged] = -1
                    ev_f[logged, 0], ev_f[logged, 1] = rec[d, X], rec[d, Y]
                    ev_f[logged, 2] = ev_f[logged, 3] = 0.0
                    ev_f[logged, 4] = ev_f[logged, 5] = ev_f[logged, 6] = ev_f[logged, 7] = np.nan
                    if rough:
                        ev_w[logged, 0], ev_w[logged, 1] = rot[d, W], np.nan
                    logged += 1
                predict(
                    d, t, -1, -1, rec, count, kept_partner, kept_stamp, cell, head, nxt,
                    nx, ny, periodic, edges,
                    seg, seg_start, seg_idx, group, blocked, rest,
                    qt, bheap, bht, bpos, barg, qk, qo, qs, ints,
                )  # fmt: skip
            if ints[I_SIZE] > max_queue:
                max_queue = ints[I_SIZE]
        now, have_now = t, True
        if done >= rebase_at:
            moving.rebase(now, epoch, rec, qt, bheap, bht, bpos, barg, seg, edges, nx + ny + 2 + LAW_SLOTS)
            floats[F_EPOCH] += now
            epoch = floats[F_EPOCH]
            now, horizon, rebase_at = 0.0, until - epoch, done + rebase_every
    ints[I_SINCE] = rebase_every - (rebase_at - done)
    ints[I_MAXQ] = max_queue
    floats[F_VIRIAL], floats[F_OVERLAP] = virial, max_overlap
    if have_now:
        floats[F_TIME] = now + epoch
    floats[F_LTIME] = last_time
    ints[I_LKIND], ints[I_LI], ints[I_LJ] = last_kind, last_i, last_j
    ints[I_COLL] += n_coll
    ints[I_WALL] += n_wall
    ints[I_CROSS] += n_cross
    ints[I_STALE] += n_stale
    ints[I_SENSE] += n_sense
    return done, n_cross, logged, why


#: The functions above that call the physics parts (directly or through ``predict``), callees first: the ones
#: :mod:`~discsim.engines.event_driven.numba.variants` compiles anew.
PHYSICAL = ("predict", "predict_all", "set_disc", "run_events")
