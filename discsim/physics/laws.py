"""The collision law: what an impact does to the velocities (elastic and frictionless), written once.

- :func:`collide`: two discs, the impulse along the line of centres;
- :func:`reflect`: a disc off a wall of the box (one component reverses);
- :func:`reflect_off_segment`: a disc off a fixed segment (along the normal from its nearest point).

A collision law is a module with these functions and the same signatures: restitution would scale the normal
component of the relative velocity, rough discs would add spin. Plain float functions, compiled by numba into
the compiled loops from this very source.
"""

from __future__ import annotations

import math

__all__ = ["closest_point_on_segment", "collide", "reflect", "reflect_off_segment"]

INF = math.inf


def collide(
    dx: float, dy: float, v1x: float, v1y: float, v2x: float, v2y: float, m1: float, m2: float
) -> tuple[float, float, float, float]:
    """Velocities after an elastic, frictionless collision of two discs.

    The impulse acts along the line of centres ``(dx, dy)`` (disc 2 minus disc 1 at contact); tangential
    components are unchanged, momentum and kinetic energy are conserved. A mass of ``math.inf`` is a fixed
    obstacle: the other disc is reflected as by a mirror.

    Returns:
        ``(u1x, u1y, u2x, u2y)``, the velocities after the collision.

    Example:
        >>> collide(2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0)
        (0.0, 0.0, 1.0, 0.0)
        >>> collide(2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, math.inf)
        (-1.0, 0.0, 0.0, 0.0)
    """
    d2 = dx * dx + dy * dy
    b = (v2x - v1x) * dx + (v2y - v1y) * dy  # normal relative velocity times |d|
    if m1 == INF:
        f1, f2 = 0.0, 2.0
    elif m2 == INF:
        f1, f2 = 2.0, 0.0
    else:
        f1, f2 = 2.0 * m2 / (m1 + m2), 2.0 * m1 / (m1 + m2)
    k = b / d2
    return v1x + f1 * k * dx, v1y + f1 * k * dy, v2x - f2 * k * dx, v2y - f2 * k * dy


def reflect(vx: float, vy: float, axis: int) -> tuple[float, float]:
    """Velocity after an elastic bounce off a wall of the box: ``axis`` 0 (a wall at x = const) reverses
    ``vx``, 1 reverses ``vy``.

    Example:
        >>> reflect(1.0, 2.0, 0)
        (-1.0, 2.0)
    """
    if axis == 0:
        return -vx, vy
    return vx, -vy


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
    px: float, py: float, vx: float, vy: float, ax: float, ay: float, bx: float, by: float
) -> tuple[float, float]:
    """Velocity after an elastic bounce of a disc at ``p`` off segment ``a``-``b``.

    The normal runs from the nearest point of the segment to the centre: the face's normal on the face, the
    radial direction at an end point.

    Example:
        >>> reflect_off_segment(0.0, 1.0, 1.0, -2.0, -3.0, 0.0, 3.0, 0.0)
        (1.0, 2.0)
    """
    qx, qy = closest_point_on_segment(px, py, ax, ay, bx, by)
    nx, ny = px - qx, py - qy
    k = 2.0 * (vx * nx + vy * ny) / (nx * nx + ny * ny)
    return vx - k * nx, vy - k * ny
