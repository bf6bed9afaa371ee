"""Pure kernels on plain floats: time of impact and elastic response.

These know nothing of engines, grids or queues. The event-driven engine inlines
:func:`time_of_impact` in its neighbour loop for speed; the tests hold the two
to the same numbers through a brute-force oracle built on this module.
"""

from __future__ import annotations

import math

from discsim.errors import InvalidArgumentError

__all__ = [
    "closest_point_on_segment",
    "reflect_off_segment",
    "resolve_collision",
    "segment_time_of_impact",
    "time_of_impact",
    "time_of_impact_bisect",
    "wall_time",
]

INF = math.inf


def time_of_impact(dx: float, dy: float, dvx: float, dvy: float, sigma: float) -> float:
    """Time until two discs, now ``(dx, dy)`` apart, come to distance ``sigma``.

    Solves ``a t^2 + 2 b t + c = 0`` with ``a = |dv|^2``, ``b = dr . dv`` and
    ``c = |dr|^2 - sigma^2`` by the cancellation-free root
    ``t = c / (-b + sqrt(b^2 - a c))``. Only approaching pairs (``b < 0``)
    collide; a pair already touching or overlapping while approaching collides
    at once (``t = 0``), so discs neither tunnel nor stick.

    Args:
        dx, dy: position of disc 2 minus disc 1 (length).
        dvx, dvy: velocity of disc 2 minus disc 1 (length / time).
        sigma: contact distance ``r1 + r2`` (length).

    Returns:
        The time (>= 0) of the next contact, or ``math.inf`` if none.

    Example:
        >>> time_of_impact(4.0, 0.0, -1.0, 0.0, 2.0)
        2.0
        >>> time_of_impact(4.0, 0.0, 1.0, 0.0, 2.0)
        inf
    """
    b = dx * dvx + dy * dvy
    if b >= 0.0:
        return INF
    c = dx * dx + dy * dy - sigma * sigma
    if c <= 0.0:
        return 0.0
    a = dvx * dvx + dvy * dvy
    disc = b * b - a * c
    if disc <= 0.0:
        return INF
    return c / (-b + math.sqrt(disc))


def resolve_collision(
    dx: float, dy: float, v1x: float, v1y: float, v2x: float, v2y: float, m1: float, m2: float
) -> tuple[float, float, float, float]:
    """Velocities after an elastic, frictionless collision of two discs.

    The impulse acts along the line of centres ``(dx, dy)`` (disc 2 minus disc 1
    at contact); tangential components are unchanged, momentum and kinetic
    energy are conserved. A mass of ``math.inf`` is a fixed obstacle: the
    other disc is reflected as by a mirror.

    Returns:
        ``(u1x, u1y, u2x, u2y)``, the velocities after the collision.

    Example:
        >>> resolve_collision(2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0)
        (0.0, 0.0, 1.0, 0.0)
        >>> resolve_collision(2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, math.inf)
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


def wall_time(x: float, v: float, radius: float, length: float) -> float:
    """Time until a disc at coordinate ``x`` moving at ``v`` touches a wall at 0 or ``length``.

    Returns ``math.inf`` when ``v == 0``, and 0 when the disc is already at or
    past the wall it moves towards.

    Example:
        >>> wall_time(5.0, 2.0, 1.0, 10.0)
        2.0
    """
    if v > 0.0:
        return max((length - radius - x) / v, 0.0)
    if v < 0.0:
        return max((radius - x) / v, 0.0)
    return INF


def segment_time_of_impact(
    px: float, py: float, vx: float, vy: float, radius: float, ax: float, ay: float, bx: float, by: float
) -> float:
    """Time until a moving disc touches the fixed segment from ``a`` to ``b``.

    The disc (centre ``p``, velocity ``v``, ``radius``) can touch the segment's
    face, where the contact point is the foot of the perpendicular, or one of
    its end points, which act as discs of radius 0. A disc already touching or
    overlapping while approaching touches at once (``t = 0``).

    Returns:
        The time (>= 0) of the first contact, or ``math.inf`` if none.

    Example:
        >>> segment_time_of_impact(0.0, 5.0, 0.0, -1.0, 1.0, -3.0, 0.0, 3.0, 0.0)
        4.0
        >>> round(segment_time_of_impact(5.0, 0.6, -1.0, 0.0, 1.0, 0.0, -3.0, 0.0, 0.0), 12)  # the end (0, 0)
        4.2
    """
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    best = INF
    length = math.sqrt(length2)
    nx, ny = -ey / length, ex / length
    s = (px - ax) * nx + (py - ay) * ny  # signed distance of the centre from the line
    vn = vx * nx + vy * ny
    if s < 0.0:
        s, vn = -s, -vn
    if vn < 0.0:  # moving towards the line
        t = (s - radius) / -vn if s > radius else 0.0
        u = ((px + vx * t - ax) * ex + (py + vy * t - ay) * ey) / length2
        if 0.0 <= u <= 1.0:
            best = t
    for qx, qy in ((ax, ay), (bx, by)):
        t = time_of_impact(qx - px, qy - py, -vx, -vy, radius)
        if t < best:
            best = t
    return best


def closest_point_on_segment(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> tuple[float, float]:
    """The point of segment ``a``-``b`` nearest to ``p``.

    Example:
        >>> closest_point_on_segment(1.0, 2.0, 0.0, 0.0, 4.0, 0.0)
        (1.0, 0.0)
    """
    ex, ey = bx - ax, by - ay
    u = ((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey)
    u = min(max(u, 0.0), 1.0)
    return ax + u * ex, ay + u * ey


def reflect_off_segment(
    px: float, py: float, vx: float, vy: float, ax: float, ay: float, bx: float, by: float
) -> tuple[float, float]:
    """Velocity after an elastic bounce of a disc at ``p`` off segment ``a``-``b``.

    The normal runs from the nearest point of the segment to the centre: the
    face's normal on the face, the radial direction at an end point.

    Example:
        >>> reflect_off_segment(0.0, 1.0, 1.0, -2.0, -3.0, 0.0, 3.0, 0.0)
        (1.0, 2.0)
    """
    qx, qy = closest_point_on_segment(px, py, ax, ay, bx, by)
    nx, ny = px - qx, py - qy
    k = 2.0 * (vx * nx + vy * ny) / (nx * nx + ny * ny)
    return vx - k * nx, vy - k * ny


def time_of_impact_bisect(test, t0: float, t1: float, tol: float) -> float:
    """Contact time by bisection of an interference test (the study's "alternate PIC").

    Works with any shapes: ``test(t)`` says whether they overlap at time ``t``.
    Given no overlap at ``t0`` and overlap at ``t1`` (the caller has seen both;
    neither end is tested again), the interval is halved, keeping the half
    whose ends disagree, until it is shorter than ``tol``. ``test`` is called
    ``floor(log2((t1 - t0) / tol)) + 1`` times when ``t1 - t0 >= tol``, never
    otherwise (fewer if the halves reach the spacing of floats first).

    Args:
        test: ``test(t) -> bool``, True when the shapes overlap at time ``t``.
        t0: a time without overlap (time units).
        t1: a later (or equal) time with overlap.
        tol: the width of the final bracket (time units, positive).

    Returns:
        The last time found without overlap, ``lo`` with ``t0 <= lo <= t1``:
        the first contact lies in ``[lo, lo + tol)`` when the overlap starts
        once in ``[t0, t1]`` (straight paths of convex shapes). Respond at
        ``lo`` and the shapes have not yet interpenetrated.

    Raises:
        ValueError: if ``t0`` or ``t1`` is not finite, ``t1 < t0``, or ``tol``
            is not a positive finite number.

    Example:
        >>> # Two discs of radius 1, 4 apart, closing at speed 1: contact at t = 2.
        >>> overlaps = lambda t: 4.0 - t < 2.0
        >>> lo = time_of_impact_bisect(overlaps, 0.0, 3.0, 1e-6)
        >>> round(lo, 6), 2.0 - lo < 1e-6, overlaps(lo)
        (2.0, True, False)
    """
    if not (math.isfinite(t0) and math.isfinite(t1)):
        msg = f"t0 and t1 must be finite, got t0={t0!r}, t1={t1!r}"
        raise InvalidArgumentError(msg)
    if t1 < t0:
        msg = f"t1 must not be before t0, got t0={t0!r}, t1={t1!r}"
        raise InvalidArgumentError(msg)
    if not (tol > 0.0 and math.isfinite(tol)):
        msg = f"tol must be a positive, finite number of time units, got {tol!r}"
        raise InvalidArgumentError(msg)
    lo, hi = t0, t1
    while hi - lo >= tol:
        mid = lo + 0.5 * (hi - lo)
        if not lo < mid < hi:  # the bracket is down to adjacent floats
            break
        if test(mid):
            hi = mid
        else:
            lo = mid
    return lo
