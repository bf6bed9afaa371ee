"""The collision law: what an impact does to the velocities (frictionless, restitution ``e``), written once.

- :func:`collide`: two discs, the impulse along the line of centres;
- :func:`reflect`: a disc off a wall of the box (one component reverses);
- :func:`reflect_off_segment`: a disc off a fixed segment (along the normal from its nearest point);
- :func:`rough_impulse`: what roughness adds to any of them, the tangential impulse at the contact point that
  turns the discs (spins), for rough discs (tangential restitution ``beta``); :func:`collide_rough` is
  :func:`collide` followed by it, the textbook law of two rough discs.

Each takes the normal coefficient of restitution ``e`` last (default 1: elastic, the same operations bit for bit).
A collision law is a module with these functions and the same signatures: rough discs would add spin. Plain
float functions, compiled by numba into the compiled loops from this very source.
"""

from __future__ import annotations

import math

__all__ = ["closest_point_on_segment", "collide", "collide_rough", "reflect", "reflect_off_segment", "rough_impulse"]

INF = math.inf


def collide(
    dx: float, dy: float, v1x: float, v1y: float, v2x: float, v2y: float, m1: float, m2: float, e: float = 1.0
) -> tuple[float, float, float, float]:
    """Velocities after a frictionless collision of two discs with normal restitution ``e`` (1: elastic).

    The impulse acts along the line of centres ``(dx, dy)`` (disc 2 minus disc 1 at contact); tangential
    components are unchanged and momentum is conserved; the normal relative velocity is reversed and scaled by
    ``e``, so a fraction ``1 - e^2`` of the kinetic energy of the normal relative motion is lost (none at
    ``e = 1``, the default: the elastic law, bit for bit). A mass of ``math.inf`` is a fixed obstacle: the other
    disc is reflected as by a mirror (its normal velocity scaled by ``e``).

    Returns:
        ``(u1x, u1y, u2x, u2y)``, the velocities after the collision.

    Example:
        >>> collide(2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0)
        (0.0, 0.0, 1.0, 0.0)
        >>> collide(2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, math.inf)
        (-1.0, 0.0, 0.0, 0.0)
        >>> collide(2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.5)  # half the closing speed survives
        (0.25, 0.0, 0.75, 0.0)
    """
    d2 = dx * dx + dy * dy
    b = (v2x - v1x) * dx + (v2y - v1y) * dy  # normal relative velocity times |d|
    s = 1.0 + e  # 2.0 exactly when elastic: the same operations as the elastic law
    if m1 == INF:
        f1, f2 = 0.0, s
    elif m2 == INF:
        f1, f2 = s, 0.0
    else:
        f1, f2 = s * m2 / (m1 + m2), s * m1 / (m1 + m2)
    k = b / d2
    return v1x + f1 * k * dx, v1y + f1 * k * dy, v2x - f2 * k * dx, v2y - f2 * k * dy


def reflect(vx: float, vy: float, axis: int, e: float = 1.0) -> tuple[float, float]:
    """Velocity after a bounce off a wall of the box with restitution ``e``: ``axis`` 0 (a wall at x = const)
    reverses ``vx`` (scaled by ``e``), 1 reverses ``vy``.

    Example:
        >>> reflect(1.0, 2.0, 0)
        (-1.0, 2.0)
        >>> reflect(1.0, -2.0, 1, 0.5)
        (1.0, 1.0)
    """
    if axis == 0:
        return -e * vx, vy  # -1.0 * vx is -vx exactly: elastic bit for bit
    return vx, -e * vy


def closest_point_on_segment(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> tuple[float, float]:
    """The point of segment ``a``-``b`` nearest to ``p``.

    Example:
        >>> closest_point_on_segment(1.0, 2.0, 0.0, 0.0, 4.0, 0.0)
        (1.0, 0.0)
    """
    ex, ey = bx - ax, by - ay
    u = ((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey)
    if 0.0 > u:  # min(max(u, 0.0), 1.0) as Python picks (-0.0 and NaN kept), also when numba compiles it
        u = 0.0
    if 1.0 < u:
        u = 1.0
    return ax + u * ex, ay + u * ey


def reflect_off_segment(
    px: float, py: float, vx: float, vy: float, ax: float, ay: float, bx: float, by: float, e: float = 1.0
) -> tuple[float, float]:
    """Velocity after a bounce of a disc at ``p`` off segment ``a``-``b``, with restitution ``e`` (1: elastic).

    The normal runs from the nearest point of the segment to the centre: the face's normal on the face, the
    radial direction at an end point.

    Example:
        >>> reflect_off_segment(0.0, 1.0, 1.0, -2.0, -3.0, 0.0, 3.0, 0.0)
        (1.0, 2.0)
    """
    qx, qy = closest_point_on_segment(px, py, ax, ay, bx, by)
    nx, ny = px - qx, py - qy
    k = (1.0 + e) * (vx * nx + vy * ny) / (nx * nx + ny * ny)
    return vx - k * nx, vy - k * ny


def rough_impulse(
    dx: float, dy: float, v1x: float, v1y: float, v2x: float, v2y: float, w1: float, w2: float,
    r1: float, r2: float, m1: float, m2: float, i1: float, i2: float, beta: float,
) -> tuple[float, float, float, float, float, float]:  # fmt: skip
    """Velocities and spins after the tangential impulse of a contact of two rough discs (tangential restitution
    ``beta`` in [-1, 1]), the normal impulse left aside (it is :func:`collide`'s, and at right angles).

    ``(dx, dy)`` points from disc 1's centre towards disc 2's (any length); ``r1``, ``r2`` are the distances
    from each centre to the contact point; ``w1``, ``w2`` the spins (counter-clockwise positive), ``i1``, ``i2``
    the moments of inertia. With ``n = d / |d|`` and ``t = (-n_y, n_x)``, the contact points' relative
    tangential velocity is ``g_t = (v1 - v2) . t + r1 w1 + r2 w2``; the impulse ``J t`` on disc 1 (``-J t`` on
    disc 2), ``J = -(1 + beta) g_t / (1/m1 + 1/m2 + r1^2/i1 + r2^2/i2)``, makes it ``-beta g_t``; each spin
    changes by ``r J / i``. A mass and inertia of ``math.inf`` make a fixed obstacle, or a wall (``r2 = 0``,
    ``v2 = 0``, ``w2 = 0``): it neither moves nor turns. The kinetic energy (translation and rotation) falls by
    ``(1 - beta^2) g_t^2 / 2`` times the tangential effective mass: none at ``beta = +1`` or ``-1`` (where
    nothing changes).

    Returns:
        ``(u1x, u1y, u2x, u2y, w1', w2')``.

    Example:
        >>> rough_impulse(2.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.5, 0.5, 1.0)
        (0.0, 0.6666666666666667, 0.0, 0.3333333333333333, -0.6666666666666666, -0.6666666666666666)
    """
    norm = math.sqrt(dx * dx + dy * dy)
    tx, ty = -dy / norm, dx / norm
    g = (v1x - v2x) * tx + (v1y - v2y) * ty + r1 * w1 + r2 * w2
    j = -(1.0 + beta) * g / (1.0 / m1 + 1.0 / m2 + r1 * r1 / i1 + r2 * r2 / i2)
    k1, k2 = j / m1, j / m2  # 0.0 for an obstacle (inf)
    return v1x + k1 * tx, v1y + k1 * ty, v2x - k2 * tx, v2y - k2 * ty, w1 + r1 * j / i1, w2 + r2 * j / i2


def collide_rough(
    dx: float, dy: float, v1x: float, v1y: float, v2x: float, v2y: float, w1: float, w2: float,
    r1: float, r2: float, m1: float, m2: float, i1: float, i2: float, e: float = 1.0, beta: float = -1.0,
) -> tuple[float, float, float, float, float, float]:  # fmt: skip
    """Velocities and spins after a collision of two rough discs: :func:`collide`'s normal impulse (restitution
    ``e``), then :func:`rough_impulse`'s tangential one (roughness ``beta``; -1: smooth, the spins unchanged).

    Example:
        >>> collide_rough(2.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.5, 0.5, 1.0, 1.0)
        (0.0, 0.6666666666666667, 1.0, 0.3333333333333333, -0.6666666666666666, -0.6666666666666666)
    """
    u1x, u1y, u2x, u2y = collide(dx, dy, v1x, v1y, v2x, v2y, m1, m2, e)
    if beta == -1.0:
        return u1x, u1y, u2x, u2y, w1, w2
    # The tangential components of the velocities are the same before and after the normal impulse.
    t1x, t1y, t2x, t2y, w1, w2 = rough_impulse(dx, dy, v1x, v1y, v2x, v2y, w1, w2, r1, r2, m1, m2, i1, i2, beta)
    return u1x + (t1x - v1x), u1y + (t1y - v1y), u2x + (t2x - v2x), u2y + (t2y - v2y), w1, w2
