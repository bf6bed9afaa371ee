"""The collision law: what an impact does to the velocities (frictionless, restitution ``e``), written once.

- :func:`collide`: two discs, the impulse along the line of centres;
- :func:`reflect`: a disc off a wall of the box (one component reverses);
- :func:`reflect_off_segment`: a disc off a fixed segment (along the normal from its nearest point).

Each takes the normal coefficient of restitution ``e`` last (default 1: elastic, the same operations bit for bit).
A collision law is a module with these functions and the same signatures: rough discs would add spin. Plain float functions, compiled by numba into
the compiled loops from this very source.
"""

from __future__ import annotations

import math

__all__ = ["closest_point_on_segment", "collide", "reflect", "reflect_off_segment"]

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
