"""The law of motion between events: free flight under a uniform acceleration (gravity), written once.

A disc's state is its centre ``(x, y)`` and velocity ``(vx, vy)`` at a reference time (the lazy clocks of the
event-driven engine); between events it moves along ``x + vx t + ax t^2 / 2`` with a constant acceleration
``(ax, ay)``: gravity for a disc that falls, zero for an obstacle, a disc at rest, or a run without gravity
(free flight, ``x + vx t``). Everything derived from that law is defined once in this module:

- :func:`advance`: a disc's centre and velocity ``dt`` after its reference time;
- :func:`exit_x` and :func:`exit_y`: the time to leave a slab ``lo <= x <= hi`` (a wall the disc's edge reaches,
  a cell edge its centre crosses) and the side it leaves by;
- :func:`pair_time_of_impact`: the time two discs come into contact (the relative motion of a pair);
- :func:`segment_time_of_impact`: the time a disc touches a fixed segment.

Each takes the acceleration, then the drag ``gamma`` last, both defaulting to zero: without them (or with
zeros) each function is free flight, the same operations bit for bit as before gravity. Under drag the flight is
exponential (:mod:`discsim.physics.damped` solves its times). Two discs that both fall keep a linear relative motion, so
their time of impact is the free-flight one; a falling disc against one that does not fall (or against a
segment's end point) solves a quartic (:func:`discsim.physics.roots.accelerated_time_of_impact`), and a
slab's edges quadratics (:func:`discsim.physics.roots.accelerated_exit`). The roots themselves, free flight's
included, live in :mod:`discsim.physics.roots`. Each function uses only arithmetic
and :mod:`math`, so numba compiles it into the compiled loops from this very source.
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np

from discsim.physics.damped import damped_exit, damped_time_of_impact, spans, spans_many
from discsim.physics.roots import accelerated_exit, accelerated_time_of_impact, linear_contact, linear_exit

__all__ = ["advance", "advance_many", "exit_x", "exit_y", "pair_time_of_impact", "segment_time_of_impact"]

INF = math.inf
#: A float, or a numpy array of them (``advance`` takes either: the loops pass floats, trajectories arrays).
Real = TypeVar("Real", float, "np.ndarray")


def advance(
    x: Real, y: Real, vx: Real, vy: Real, dt: Real, ax: float = 0.0, ay: float = 0.0, drag: float = 0.0
) -> tuple[Real, Real, Real, Real]:
    """A disc's centre and velocity ``dt`` after a time at which it was at ``(x, y)`` moving at ``(vx, vy)``.

    Args:
        x, y: the centre at the reference time (length).
        vx, vy: the velocity at the reference time (length / time).
        dt: time since the reference time (may be negative: back along the path).
        ax, ay: the disc's constant acceleration (length / time^2; numbers, not arrays); zero: free flight.
        drag: the drag ``gamma`` (1 / time; a number): the velocity relaxes as ``e^(-gamma t)`` towards
            ``(ax, ay) / gamma``. Under drag ``dt`` must be a number (the loops); trajectories take
            :func:`discsim.physics.damped.spans` of their arrays themselves.

    Returns:
        ``(x, y, vx, vy)`` at the reference time plus ``dt``.

    Example:
        >>> advance(1.0, 2.0, 0.5, -1.0, 2.0)
        (2.0, 0.0, 0.5, -1.0)
        >>> advance(0.0, 10.0, 1.0, 0.0, 2.0, 0.0, -2.0)  # thrown sideways, falling
        (2.0, 6.0, 1.0, -4.0)
    """
    if drag != 0.0:
        tau, s, e = spans(dt, drag)  # type: ignore[arg-type]
        return x + vx * tau + ax * s, y + vy * tau + ay * s, vx * e + ax * tau, vy * e + ay * tau
    if ax == 0.0 and ay == 0.0:
        return x + vx * dt, y + vy * dt, vx, vy
    return x + (vx + 0.5 * ax * dt) * dt, y + (vy + 0.5 * ay * dt) * dt, vx + ax * dt, vy + ay * dt


def advance_many(
    x: np.ndarray, y: np.ndarray, vx: np.ndarray, vy: np.ndarray, dt: np.ndarray, ax: float = 0.0, ay: float = 0.0,
    drag: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`advance` of arrays (numpy; not compiled), under drag too: what states, reads and trajectories use.
    Equal element by element to :func:`advance` of each.

    Example:
        >>> x, y, vx, vy = advance_many(np.zeros(2), np.zeros(2), np.ones(2), np.zeros(2), np.array([1.0, 2.0]))
        >>> x.tolist()
        [1.0, 2.0]
    """
    if drag == 0.0:
        return advance(x, y, vx, vy, dt, ax, ay)
    tau, s, e = spans_many(dt, drag)
    return x + vx * tau + ax * s, y + vy * tau + ay * s, vx * e + ax * tau, vy * e + ay * tau


def exit_x(x: float, vx: float, lo: float, hi: float, a: float = 0.0, drag: float = 0.0) -> tuple[float, int]:
    """Time until a centre at ``x`` moving at ``vx`` reaches ``hi`` (moving up) or ``lo`` (moving down).

    Under an acceleration ``a`` along x, :func:`~discsim.physics.roots.accelerated_exit` answers (a disc
    may turn back and leave by the side it moved away from); under drag,
    :func:`~discsim.physics.damped.damped_exit`.

    A wall at ``length`` stops a disc of radius ``r`` when its centre reaches ``length - r`` (``hi``); a cell
    edge, when the centre reaches it. The time is not clamped: a centre already past the line it moves
    towards gives a negative time, which the caller clamps to now.

    Returns:
        ``(t, side)``: ``side`` is 1 for ``hi``, -1 for ``lo``, 0 when the disc does not move along x
        (``t = inf``).

    Example:
        >>> exit_x(5.0, 2.0, 1.0, 9.0)
        (2.0, 1)
        >>> exit_x(5.0, 0.0, 1.0, 9.0)
        (inf, 0)
    """
    if drag != 0.0:
        return damped_exit(x, vx, a, drag, lo, hi)
    if a != 0.0:
        return accelerated_exit(x, vx, a, lo, hi)
    return linear_exit(x, vx, lo, hi)


def exit_y(y: float, vy: float, lo: float, hi: float, a: float = 0.0, drag: float = 0.0) -> tuple[float, int]:
    """:func:`exit_x` along y (a separate function: a law that bends one axis only replaces this one).

    Example:
        >>> exit_y(5.0, -2.0, 1.0, 9.0)
        (2.0, -1)
    """
    if drag != 0.0:
        return damped_exit(y, vy, a, drag, lo, hi)
    if a != 0.0:
        return accelerated_exit(y, vy, a, lo, hi)
    return linear_exit(y, vy, lo, hi)


def pair_time_of_impact(
    dx: float, dy: float, dvx: float, dvy: float, sigma: float, dax: float = 0.0, day: float = 0.0,
    drag: float = 0.0,
) -> float:  # fmt: skip
    """Time until two discs, now ``(dx, dy)`` apart, come to distance ``sigma``.

    ``(dax, day)`` is the relative acceleration (disc 2's minus disc 1's): zero when both fall or neither
    does; otherwise the quartic's earliest contact while approaching
    (:func:`~discsim.physics.roots.accelerated_time_of_impact`). Under drag ``gamma``,
    :func:`~discsim.physics.damped.damped_time_of_impact`.

    Solves ``a t^2 + 2 b t + c = 0`` with ``a = |dv|^2``, ``b = dr . dv`` and ``c = |dr|^2 - sigma^2`` by the
    cancellation-free root ``t = c / (-b + sqrt(b^2 - a c))``. Only approaching pairs (``b < 0``) collide; a
    pair already touching or overlapping while approaching collides at once (``t = 0``), so discs neither
    tunnel nor stick.

    Free flight's quadratic is :func:`~discsim.physics.roots.linear_contact`.

    Args:
        dx, dy: position of disc 2 minus disc 1 (length).
        dvx, dvy: velocity of disc 2 minus disc 1 (length / time).
        sigma: contact distance ``r1 + r2`` (length).

    Returns:
        The time (>= 0) of the next contact, or ``math.inf`` if none.

    Example:
        >>> pair_time_of_impact(4.0, 0.0, -1.0, 0.0, 2.0)
        2.0
        >>> pair_time_of_impact(4.0, 0.0, 1.0, 0.0, 2.0)
        inf
    """
    if drag != 0.0:
        return damped_time_of_impact(dx, dy, dvx, dvy, dax, day, drag, sigma)
    if dax != 0.0 or day != 0.0:
        return accelerated_time_of_impact(dx, dy, dvx, dvy, dax, day, sigma)
    return linear_contact(dx, dy, dvx, dvy, sigma)


def segment_time_of_impact(
    px: float, py: float, vx: float, vy: float, radius: float, ax: float, ay: float, bx: float, by: float,
    gx: float = 0.0, gy: float = 0.0, drag: float = 0.0,
) -> float:  # fmt: skip
    """Time until a moving disc (acceleration ``(gx, gy)``, drag ``drag``, default none) touches the fixed segment
    ``a``-``b``.

    The disc (centre ``p``, velocity ``v``, ``radius``) can touch the segment's face, where the contact point
    is the foot of the perpendicular, or one of its end points, which act as discs of radius 0 (the pair time
    of impact with the disc's velocity reversed). A disc already touching or overlapping while approaching
    touches at once (``t = 0``).

    Returns:
        The time (>= 0) of the first contact, or ``math.inf`` if none.

    Example:
        >>> segment_time_of_impact(0.0, 5.0, 0.0, -1.0, 1.0, -3.0, 0.0, 3.0, 0.0)
        4.0
        >>> round(segment_time_of_impact(5.0, 0.6, -1.0, 0.0, 1.0, 0.0, -3.0, 0.0, 0.0), 12)  # the end (0, 0)
        4.2
    """
    if gx != 0.0 or gy != 0.0 or drag != 0.0:
        return _falling_segment_time(px, py, vx, vy, radius, ax, ay, bx, by, gx, gy, drag)
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
    t = linear_contact(ax - px, ay - py, -vx, -vy, radius)
    if t < best:
        best = t
    t = linear_contact(bx - px, by - py, -vx, -vy, radius)
    if t < best:
        best = t
    return best


def _falling_segment_time(
    px: float, py: float, vx: float, vy: float, radius: float, ax: float, ay: float, bx: float, by: float,
    gx: float, gy: float, drag: float,
) -> float:  # fmt: skip
    """:func:`segment_time_of_impact` under an acceleration ``(gx, gy)`` or drag (or both).

    The face: the centre's signed distance from the line, ``s + vn t + gn t^2 / 2``, comes down to ``radius``
    (:func:`~discsim.physics.roots.accelerated_exit` of the slab ``[radius, inf)``, which finds a disc that
    just bounced off the face coming back); the foot of the perpendicular must then lie on the segment. The
    end points are fixed points: a quartic each. There is no exclusion of the segment just hit: a falling disc
    may come back to it.
    """
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    best = INF
    length = math.sqrt(length2)
    nx, ny = -ey / length, ex / length
    s = (px - ax) * nx + (py - ay) * ny
    vn = vx * nx + vy * ny
    gn = gx * nx + gy * ny
    if s < 0.0:
        s, vn, gn = -s, -vn, -gn
    t, side = exit_x(s, vn, radius, INF, gn, drag)
    if side < 0:
        if t < 0.0:
            t = 0.0
        qx, qy, _, _ = advance(px, py, vx, vy, t, gx, gy, drag)
        u = ((qx - ax) * ex + (qy - ay) * ey) / length2
        if 0.0 <= u <= 1.0:
            best = t
    t = pair_time_of_impact(ax - px, ay - py, -vx, -vy, radius, -gx, -gy, drag)
    if t < best:
        best = t
    t = pair_time_of_impact(bx - px, by - py, -vx, -vy, radius, -gx, -gy, drag)
    if t < best:
        best = t
    return best
