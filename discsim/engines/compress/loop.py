"""The event loop of growing discs (Lubachevsky-Stillinger), written once for two runtimes.

Every function here uses only indexing, arithmetic and :mod:`math`, so the same source runs

- in pure Python on plain lists (list indexing and Python floats are 3-5x faster than numpy scalars), and
- compiled by numba on numpy arrays (:mod:`discsim.engines.compress.compiled` jits these very functions).

One call of :func:`run_epoch` runs the dynamics of one epoch: all discs start synchronised at epoch time 0,
radius ``r0[i] * (1 + g t)`` at epoch time ``t``, and the loop stops at ``t_end`` or after ``max_coll``
collisions or ``max_coll`` wall hits (a disc squeezed between two walls hits them ever faster), with every
disc advanced to the stopping time. Between epochs the caller rescales the
velocities (the thermostat) and rebases the radii, so all predictions start afresh.

Data (per disc ``i``): ``x, y, vx, vy`` at time ``tr[i]`` (a lazy clock), ``r0`` (radius at epoch time 0),
``m`` (mass), ``count`` (collision counter: bumped whenever the disc changes course), ``cell``, and the cell
lists ``head`` (per cell), ``nxt``, ``prv`` (doubly linked). The queue is an indexed binary heap with one
pending event per disc, ordered by ``(time, owner)``: ``heap``, ``ht`` (times beside the owners), ``hpos``;
the event itself is ``qk`` (kind), ``qo`` (partner disc, wall or direction), ``qs`` (the partner's counter
when predicted: the event is stale when it has changed).

``par`` (floats): width, height, g, t_end, cell width, cell height. ``ipar`` (ints): nx, ny, periodic,
max_coll. ``out`` (floats): stopping time, pair virial (sum of impulse times contact distance), wall virial.
``iout`` (ints): collisions, wall events, crossings, stale events.
"""

from __future__ import annotations

import math

from discsim.cells import link, unlink
from discsim.physics.dynamics import advance
from discsim.queue import sift_down, sift_up  # the indexed heap (by (time, owner)) of the compiled loops

INF = math.inf
COLLISION, WALL, CROSSING, NONE = 0, 1, 2, 3
# Walls (``qo`` of a wall event) and crossing directions (``qo`` of a crossing).
LEFT, RIGHT, BOTTOM, TOP = 0, 1, 2, 3


def growing_time_of_impact(dx, dy, dvx, dvy, s, sp):
    """Time until ``|dr + dv t| = s + sp t`` (discs whose contact distance grows at ``sp``), or inf.

    With ``A = |dv|^2 - sp^2``, ``B = dr.dv - s sp``, ``C = |dr|^2 - s^2`` the contact solves
    ``A t^2 + 2 B t + C = 0``. Each branch takes the root without cancellation: ``C / (-B + sqrt(D))``
    when ``B < 0`` (closing faster than the contact distance grows), ``(B + sqrt(D)) / -A`` when ``B >= 0``
    and ``A < 0`` (separating now, caught up by the growth later). A pair touching or overlapping
    (``C <= 0``) while closing collides at once.
    """
    b = dx * dvx + dy * dvy - s * sp
    c = dx * dx + dy * dy - s * s
    a = dvx * dvx + dvy * dvy - sp * sp
    if b < 0.0:
        if c <= 0.0:
            return 0.0
        d = b * b - a * c
        if d < 0.0:  # only when a > 0: the pair passes by
            return INF
        return c / (-b + math.sqrt(d))
    if a >= 0.0:
        return INF
    d = b * b - a * c
    if d < 0.0:  # c < 0 by roundoff: the smaller root stands for the contact
        d = 0.0
    return (b + math.sqrt(d)) / -a


def set_time(i, t, n, heap, ht, hpos):
    """Give disc ``i`` the event time ``t`` and restore the heap."""
    k = hpos[i]
    old = ht[k]
    ht[k] = t
    if t < old or (t == old and k > 0):
        sift_up(k, heap, ht, hpos)
    else:
        sift_down(k, n, heap, ht, hpos)


def predict(i, t, x, y, vx, vy, tr, r0, count, cell, head, nxt, qk, qo, qs, par, ipar):
    """The earliest event of disc ``i`` (synchronised at ``t``): kind, partner and stamp in ``qk, qo, qs``.

    Returns the event's time. Scans the 3x3 cells around the disc's cell; the cells are at least the
    largest contact distance of the whole compression, so no partner lies farther.
    """
    width = par[0]
    height = par[1]
    g = par[2]
    cw = par[4]
    ch = par[5]
    ncx = ipar[0]
    ncy = ipar[1]
    periodic = ipar[2]
    xi = x[i]
    yi = y[i]
    vxi = vx[i]
    vyi = vy[i]
    ri = r0[i]
    grow = 1.0 + g * t
    best = INF
    kind = NONE
    other = -1
    stamp = 0
    c = cell[i]
    cx = c // ncy
    cy = c - cx * ncy
    for ox in range(-1, 2):
        ax = cx + ox
        if ax < 0 or ax >= ncx:
            if periodic == 0:
                continue
            ax = (ax + ncx) % ncx
        for oy in range(-1, 2):
            ay = cy + oy
            if ay < 0 or ay >= ncy:
                if periodic == 0:
                    continue
                ay = (ay + ncy) % ncy
            j = head[ax * ncy + ay]
            while j >= 0:
                if j != i:
                    dt = t - tr[j]
                    dx = x[j] + vx[j] * dt - xi
                    dy = y[j] + vy[j] * dt - yi
                    if periodic != 0:  # the minimum image (cells >= 3 a side, so one image at most)
                        if dx > 0.5 * width:
                            dx -= width
                        elif dx < -0.5 * width:
                            dx += width
                        if dy > 0.5 * height:
                            dy -= height
                        elif dy < -0.5 * height:
                            dy += height
                    s0 = ri + r0[j]
                    tau = growing_time_of_impact(dx, dy, vx[j] - vxi, vy[j] - vyi, s0 * grow, s0 * g)
                    if t + tau < best:
                        best = t + tau
                        kind = COLLISION
                        other = j
                        stamp = count[j]
                j = nxt[j]
    if periodic == 0:
        r = ri * grow
        rp = ri * g
        if rp - vxi > 0.0:
            tau = max((xi - r) / (rp - vxi), 0.0)
            if t + tau < best:
                best, kind, other = t + tau, WALL, LEFT
        if vxi + rp > 0.0:
            tau = max((width - xi - r) / (vxi + rp), 0.0)
            if t + tau < best:
                best, kind, other = t + tau, WALL, RIGHT
        if rp - vyi > 0.0:
            tau = max((yi - r) / (rp - vyi), 0.0)
            if t + tau < best:
                best, kind, other = t + tau, WALL, BOTTOM
        if vyi + rp > 0.0:
            tau = max((height - yi - r) / (vyi + rp), 0.0)
            if t + tau < best:
                best, kind, other = t + tau, WALL, TOP
    # leaving the cell (a walled box has no crossing out of its edge cells: the wall comes first)
    if vxi > 0.0 and (periodic != 0 or cx < ncx - 1):
        tau = max(((cx + 1) * cw - xi) / vxi, 0.0)
        if t + tau < best:
            best, kind, other = t + tau, CROSSING, RIGHT
    elif vxi < 0.0 and (periodic != 0 or cx > 0):
        tau = max((cx * cw - xi) / vxi, 0.0)
        if t + tau < best:
            best, kind, other = t + tau, CROSSING, LEFT
    if vyi > 0.0 and (periodic != 0 or cy < ncy - 1):
        tau = max(((cy + 1) * ch - yi) / vyi, 0.0)
        if t + tau < best:
            best, kind, other = t + tau, CROSSING, TOP
    elif vyi < 0.0 and (periodic != 0 or cy > 0):
        tau = max((cy * ch - yi) / vyi, 0.0)
        if t + tau < best:
            best, kind, other = t + tau, CROSSING, BOTTOM
    qk[i] = kind
    qo[i] = other
    qs[i] = stamp
    return best


def _advance(i, t, x, y, vx, vy, tr):
    x[i], y[i], vx[i], vy[i] = advance(x[i], y[i], vx[i], vy[i], t - tr[i])
    tr[i] = t


def run_epoch(x, y, vx, vy, tr, r0, m, count, cell, head, nxt, prv, heap, ht, hpos, qk, qo, qs, par, ipar, out, iout):
    """Run one epoch from time 0 (all discs synchronised there, cells filled); see the module's docstring.

    Returns the stopping time; every disc is advanced to it (``tr[i]`` equals it), with ``x, y`` wrapped.
    """
    n = len(x)
    width = par[0]
    height = par[1]
    g = par[2]
    t_end = par[3]
    ncx = ipar[0]
    ncy = ipar[1]
    periodic = ipar[2]
    max_coll = ipar[3]
    for i in range(n):
        tr[i] = 0.0
        hpos[i] = i
        heap[i] = i
        ht[i] = predict(i, 0.0, x, y, vx, vy, tr, r0, count, cell, head, nxt, qk, qo, qs, par, ipar)
    for k in range(n):
        sift_up(k, heap, ht, hpos)
    collisions = 0
    t_last = 0.0
    virial = 0.0
    wall_virial = 0.0
    walls = 0
    crossings = 0
    stale = 0
    while n > 0:
        i = heap[0]
        t = ht[0]
        if collisions >= max_coll or walls >= max_coll:  # stop at the last collision (or wall hit)
            break
        if t >= t_end:
            t_last = t_end
            break
        t_last = t
        kind = qk[i]
        if kind == COLLISION:
            j = qo[i]
            if qs[i] != count[j]:  # the partner changed course since: predict again
                stale += 1
                _advance(i, t, x, y, vx, vy, tr)
                set_time(
                    i,
                    predict(i, t, x, y, vx, vy, tr, r0, count, cell, head, nxt, qk, qo, qs, par, ipar),
                    n,
                    heap,
                    ht,
                    hpos,
                )
                continue
            _advance(i, t, x, y, vx, vy, tr)
            _advance(j, t, x, y, vx, vy, tr)
            dx = x[j] - x[i]
            dy = y[j] - y[i]
            if periodic != 0:
                if dx > 0.5 * width:
                    dx -= width
                elif dx < -0.5 * width:
                    dx += width
                if dy > 0.5 * height:
                    dy -= height
                elif dy < -0.5 * height:
                    dy += height
            dist = math.sqrt(dx * dx + dy * dy)
            nx_ = dx / dist
            ny_ = dy / dist
            sp = (r0[i] + r0[j]) * g
            vn = (vx[j] - vx[i]) * nx_ + (vy[j] - vy[i]) * ny_
            if vn < sp:  # elastic in the frame of the growing surfaces: vn' - sp = sp - vn
                mi = m[i]
                mj = m[j]
                impulse = 2.0 * (sp - vn) * mi * mj / (mi + mj)
                vx[i] -= impulse / mi * nx_
                vy[i] -= impulse / mi * ny_
                vx[j] += impulse / mj * nx_
                vy[j] += impulse / mj * ny_
                virial += impulse * dist
            count[i] += 1
            count[j] += 1
            collisions += 1
            set_time(
                i, predict(i, t, x, y, vx, vy, tr, r0, count, cell, head, nxt, qk, qo, qs, par, ipar), n, heap, ht, hpos
            )
            set_time(
                j, predict(j, t, x, y, vx, vy, tr, r0, count, cell, head, nxt, qk, qo, qs, par, ipar), n, heap, ht, hpos
            )
            continue
        _advance(i, t, x, y, vx, vy, tr)
        side = qo[i]
        if kind == WALL:
            rp = r0[i] * g  # the surface moves at rp: reflect in its frame
            if side == LEFT:
                new = 2.0 * rp - vx[i]
                wall_virial += m[i] * (new - vx[i])
                vx[i] = new
            elif side == RIGHT:
                new = -2.0 * rp - vx[i]
                wall_virial += m[i] * (vx[i] - new)
                vx[i] = new
            elif side == BOTTOM:
                new = 2.0 * rp - vy[i]
                wall_virial += m[i] * (new - vy[i])
                vy[i] = new
            else:
                new = -2.0 * rp - vy[i]
                wall_virial += m[i] * (vy[i] - new)
                vy[i] = new
            count[i] += 1
            walls += 1
        elif kind == CROSSING:
            c = cell[i]
            cx = c // ncy
            cy = c - cx * ncy
            if side == RIGHT:
                cx += 1
                if cx == ncx:
                    cx = 0
                    x[i] -= width
            elif side == LEFT:
                cx -= 1
                if cx < 0:
                    cx = ncx - 1
                    x[i] += width
            elif side == TOP:
                cy += 1
                if cy == ncy:
                    cy = 0
                    y[i] -= height
            else:
                cy -= 1
                if cy < 0:
                    cy = ncy - 1
                    y[i] += height
            unlink(i, c, head, nxt, prv)
            c = cx * ncy + cy
            link(i, c, head, nxt, prv)
            cell[i] = c
            crossings += 1
        set_time(
            i, predict(i, t, x, y, vx, vy, tr, r0, count, cell, head, nxt, qk, qo, qs, par, ipar), n, heap, ht, hpos
        )
    for i in range(n):
        _advance(i, t_last, x, y, vx, vy, tr)
    out[0] = t_last
    out[1] = virial
    out[2] = wall_virial
    iout[0] = collisions
    iout[1] = walls
    iout[2] = crossings
    iout[3] = stale
    return t_last


#: The functions, callees before callers, in the order :mod:`.compiled` compiles them.
ORDER = (
    "advance",
    "growing_time_of_impact",
    "sift_up",
    "sift_down",
    "set_time",
    "predict",
    "_advance",
    "unlink",
    "link",
    "run_epoch",
)
