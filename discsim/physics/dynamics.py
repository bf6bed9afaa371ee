"""Free flight, the law of motion between events: every loop advances discs and times its events here.

A disc's state is its centre ``(x, y)`` and velocity ``(vx, vy)`` at a reference time (the lazy clocks of the
event-driven engine); between events it moves along ``x + vx t``, ``y + vy t``. Everything derived from that law
is defined once in this module:

- :func:`advance`: a disc's centre and velocity ``dt`` after its reference time;
- :func:`exit_x` and :func:`exit_y`: the time to leave a slab ``lo <= x <= hi`` (a wall the disc's edge reaches,
  a cell edge its centre crosses) and the side it leaves by;
- :func:`pair_time_of_impact`: the time two discs come into contact (the relative motion of a pair);
- :func:`segment_time_of_impact`: the time a disc touches a fixed segment.

A law of motion is a module with these five functions and the same signatures: uniform gravity would bend
:func:`advance`, :func:`exit_y` and :func:`segment_time_of_impact` into parabolas and keep
:func:`pair_time_of_impact` (a pair's relative motion stays linear). Each function uses only arithmetic and
:mod:`math`, so numba compiles it into the compiled loops from this very source.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, TypeVar

if TYPE_CHECKING:
    import numpy as np

__all__ = ["advance", "exit_x", "exit_y", "pair_time_of_impact", "segment_time_of_impact"]

INF = math.inf
#: A float, or a numpy array of them (``advance`` takes either: the loops pass floats, trajectories arrays).
Real = TypeVar("Real", float, "np.ndarray")


def advance(x: Real, y: Real, vx: Real, vy: Real, dt: Real) -> tuple[Real, Real, Real, Real]:
    """A disc's centre and velocity ``dt`` after a time at which it was at ``(x, y)`` moving at ``(vx, vy)``.

    Args:
        x, y: the centre at the reference time (length).
        vx, vy: the velocity at the reference time (length / time).
        dt: time since the reference time (may be negative: back along the path).

    Returns:
        ``(x, y, vx, vy)`` at the reference time plus ``dt``.

    Example:
        >>> advance(1.0, 2.0, 0.5, -1.0, 2.0)
        (2.0, 0.0, 0.5, -1.0)
    """
    return x + vx * dt, y + vy * dt, vx, vy


def exit_x(x: float, vx: float, lo: float, hi: float) -> tuple[float, int]:
    """Time until a centre at ``x`` moving at ``vx`` reaches ``hi`` (moving up) or ``lo`` (moving down).

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
    if vx > 0.0:
        return (hi - x) / vx, 1
    if vx < 0.0:
        return (lo - x) / vx, -1
    return INF, 0


def exit_y(y: float, vy: float, lo: float, hi: float) -> tuple[float, int]:
    """:func:`exit_x` along y (a separate function: gravity would bend this one only).

    Example:
        >>> exit_y(5.0, -2.0, 1.0, 9.0)
        (2.0, -1)
    """
    if vy > 0.0:
        return (hi - y) / vy, 1
    if vy < 0.0:
        return (lo - y) / vy, -1
    return INF, 0


def pair_time_of_impact(dx: float, dy: float, dvx: float, dvy: float, sigma: float) -> float:
    """Time until two discs, now ``(dx, dy)`` apart, come to distance ``sigma``.

    Solves ``a t^2 + 2 b t + c = 0`` with ``a = |dv|^2``, ``b = dr . dv`` and ``c = |dr|^2 - sigma^2`` by the
    cancellation-free root ``t = c / (-b + sqrt(b^2 - a c))``. Only approaching pairs (``b < 0``) collide; a
    pair already touching or overlapping while approaching collides at once (``t = 0``), so discs neither
    tunnel nor stick.

    The test for a hit is one comparison of a ``min``: a pair hits when it approaches (``b < 0``) and its path
    reaches contact (``b^2 - a c > 0``) or it touches (``c <= 0``). Compiled into the neighbour loops it stays
    one well-predicted branch (about 6% of a 1:10 mixture's candidates hit), which spares the rest the square
    root and the division; written with ``and``, LLVM branches on ``b < 0`` first, a coin toss.

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
    b = dx * dvx + dy * dvy
    c = dx * dx + dy * dy - sigma * sigma
    a = dvx * dvx + dvy * dvy
    d = b * b - a * c
    if min(-b, d if c > 0.0 else 1.0) > 0.0:
        return 0.0 if c <= 0.0 else c / (-b + math.sqrt(d))
    return INF


def segment_time_of_impact(
    px: float, py: float, vx: float, vy: float, radius: float, ax: float, ay: float, bx: float, by: float
) -> float:
    """Time until a moving disc touches the fixed segment from ``a`` to ``b``.

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
    t = pair_time_of_impact(ax - px, ay - py, -vx, -vy, radius)
    if t < best:
        best = t
    t = pair_time_of_impact(bx - px, by - py, -vx, -vy, radius)
    if t < best:
        best = t
    return best
