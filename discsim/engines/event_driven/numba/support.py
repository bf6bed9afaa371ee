"""What the laws add to the compiled event loop, and the layout of its per-disc rows.

- :func:`accel`: a disc's acceleration now (gravity, unless it has none, is an obstacle or rests);
- :func:`restitution`: the coefficient of a collision (one number, the pair of groups', 1 under the TC model);
- :func:`turn`, :func:`spin_energy`: rough discs' angles and rotational energy;
- :func:`drag_loss`: the energy drag took from a disc over a flight;
- :func:`supported`: the discs at rest that a support holds up (they fall again when it goes);
- :func:`_prefetch_disc`, :func:`_prefetch_cells`: the loop's requests for the memory of its next events.

Compiled into :mod:`discsim.engines.event_driven.numba.loop`'s functions (``inline``) or called by them.
"""

from __future__ import annotations

import math

from discsim._compiled import inline, jit, prefetch
from discsim.laws import PER_GROUP, TC, E

__all__ = ["accel", "drag_loss", "restitution", "spin_energy", "supported", "turn"]

INF = math.inf
# Columns of a disc's row in ``rec``.
X, Y, VX, VY, T, R, M, KEPT = 0, 1, 2, 3, 4, 5, 6, 7
# Columns of a disc's row in ``rot``: spin, moment of inertia, angle at the absolute time ``ANGLE_T``.
W, INERTIA, ANGLE, ANGLE_T = 0, 1, 2, 3


@inline
def accel(k, gravity, gx, gy, rec, rest):
    """Disc ``k``'s acceleration: gravity, unless there is none, ``k`` is an obstacle or it is at rest."""
    if gravity and rec[k, M] != INF and rest[k] == 0:
        return gx, gy
    return 0.0, 0.0


@inline
def drag_loss(k, gx, gy, rec, x, y, vx, vy):
    """The energy drag took from disc ``k`` over its flight from its record (``rec[k]``) to ``(x, y)``, ``(vx, vy)``
    under the acceleration ``(gx, gy)`` it had: its kinetic energy lost plus the work gravity did on it
    (``m g . dr``); 0 for an obstacle. What the drag takes, counted at each event that ends a flight, so that
    ``energy() + dissipated`` stays constant under drag too."""
    m = rec[k, M]
    if m == INF:
        return 0.0
    vx0, vy0 = rec[k, VX], rec[k, VY]
    return m * (0.5 * ((vx0 * vx0 + vy0 * vy0) - (vx * vx + vy * vy)) + gx * (x - rec[k, X]) + gy * (y - rec[k, Y]))


@inline
def restitution(i, j, now, law, etab, egroup, tlast):
    """The coefficient of restitution of a collision of ``i`` and ``j`` (``i`` twice: a wall) at time ``now``:
    one number or the pair of groups' (:class:`~discsim.laws.Laws`), 1 within the TC time of either's last."""
    e = law[E]
    if law[PER_GROUP] != 0.0:
        e = etab[egroup[i], egroup[j]]
    tc = law[TC]
    if tc > 0.0 and (now - tlast[i] < tc or now - tlast[j] < tc):
        e = 1.0
    return e


@inline
def turn(k, now, rot):
    """Bring disc ``k``'s angle to the absolute time ``now`` (its spin has been constant since its angle's time)."""
    rot[k, ANGLE] += rot[k, W] * (now - rot[k, ANGLE_T])
    rot[k, ANGLE_T] = now


@inline
def spin_energy(inertia, w):
    """``I w^2 / 2``; 0 for a disc that cannot turn (``I`` inf: its spin never changes)."""
    return 0.0 if inertia == INF else 0.5 * inertia * w * w


@jit
def supported(k, gx, gy, rec, rest, cell, head, nxt, nx, ny, periodic, edges, found):
    """The discs at rest that ``k`` holds up, and those they hold up in turn: every disc at rest touching one of
    them from above (against gravity ``(gx, gy)``), found through the cells around each. Each is marked awake
    (``rest`` 0) as it is found, so none comes twice; their numbers go to ``found[:n]`` (an ``(N,)`` array);
    returns ``n``.

    Called when ``k`` stops being a support where it stood: woken by a hard hit, or edited. Without it the discs
    resting on ``k`` would stay at rest in mid-air."""
    width = edges[nx]
    height = edges[nx + 1 + ny]
    n = 0
    done = -1  # found[done] is the support whose neighbours are scanned (-1: k itself)
    while done < n:
        b = k if done < 0 else found[done]
        done += 1
        xb, yb, rb = rec[b, X], rec[b, Y], rec[b, R]
        c = cell[b]
        cx = c // ny
        cy = c - cx * ny
        for ddx in range(-1, 2):
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
                while j >= 0:
                    if rest[j] != 0 and rec[j, M] != INF and j != k:
                        dx = rec[j, X] + sx - xb  # a disc at rest does not move: its record holds where it is
                        dy = rec[j, Y] + sy - yb
                        reach = (rb + rec[j, R]) * (1.0 + 1e-9)
                        if dx * dx + dy * dy <= reach * reach and gx * dx + gy * dy < 0.0:
                            rest[j] = 0
                            found[n] = j
                            n += 1
                    j = nxt[j]
    return n


@inline
def _prefetch_disc(c, rec, count, kept_partner, kept_stamp, cell, qt, qk, qo, qs):
    """Ask for every record of disc ``c`` that an event of it reads (see :func:`discsim._compiled.prefetch`)."""
    prefetch(rec, c * 8)
    prefetch(count, c)
    prefetch(kept_partner, c)
    prefetch(kept_stamp, c)
    prefetch(cell, c)
    prefetch(qt, c)
    prefetch(qk, c)
    prefetch(qo, c)
    prefetch(qs, c)


@inline
def _prefetch_cells(c, head, nx, ny):
    """Start fetching the heads of the 3 x 3 cells around cell ``c`` (three runs of three in memory)."""
    cx = c // ny
    for ddx in range(-1, 2):
        ox = cx + ddx
        if ox < 0:
            ox += nx
        elif ox >= nx:
            ox -= nx
        prefetch(head, ox * ny + c - cx * ny)
