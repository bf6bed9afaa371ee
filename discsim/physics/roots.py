"""Contact times under a uniform acceleration: the parabolic motions that gravity gives (issue 27).

Two discs that both fall keep a linear relative motion (:func:`discsim.physics.dynamics.pair_time_of_impact`);
a falling disc against one that does not fall (an obstacle of infinite mass, a disc at rest) or against a fixed
point (a segment's end point) moves along ``p(t) = d + w t + a t^2 / 2`` relative to it, and the two touch where
the quartic ``f(t) = |p(t)|^2 - sigma^2`` has a root. A coordinate under a uniform acceleration leaves a slab
(a wall, a cell edge) where a quadratic has one.

- :func:`accelerated_time_of_impact`: the first contact of the quartic, never missed: the roots of ``f''`` (a
  quadratic) cut time into at most three pieces where ``f`` is convex or concave (:func:`convex_piece`,
  :func:`concave_piece`), on which one crossing is bracketed and bisected (:func:`crossing_time`).
- :func:`accelerated_exit`: the time a coordinate leaves a slab, by cancellation-free quadratic roots.

With no acceleration each is free flight's (:func:`linear_contact`, :func:`linear_exit`, which live here too:
this module is the floor of the law of motion; :mod:`discsim.physics.dynamics` calls it, and it calls nothing of
discsim). Every function uses only arithmetic, comparisons and :mod:`math`, so numba compiles it from this
source: compile :data:`PARTS` in their order (callees first), e.g. ``compile_from_source(PARTS, jit)``.
"""

from __future__ import annotations

import math

__all__ = [
    "PARTS",
    "accelerated_exit",
    "accelerated_time_of_impact",
    "concave_piece",
    "convex_piece",
    "crossing_time",
    "inflections",
    "linear_contact",
    "linear_exit",
]

INF = math.inf


def linear_exit(x: float, v: float, lo: float, hi: float) -> tuple[float, int]:
    """Free flight's exit from the slab ``lo <= x <= hi``: the time until ``x + v t`` reaches ``hi`` (moving up)
    or ``lo`` (moving down), not clamped (negative when already past it), and the side (1, -1; 0 and ``inf``
    when ``v == 0``). :func:`discsim.physics.dynamics.exit_x` without acceleration.

    Example:
        >>> linear_exit(5.0, 2.0, 1.0, 9.0)
        (2.0, 1)
    """
    if v > 0.0:
        return (hi - x) / v, 1
    if v < 0.0:
        return (lo - x) / v, -1
    return INF, 0


def linear_contact(dx: float, dy: float, dvx: float, dvy: float, sigma: float) -> float:
    """Free flight's time of impact: the time until two discs ``(dx, dy)`` apart with relative velocity
    ``(dvx, dvy)`` come to distance ``sigma``, or ``inf``; :func:`discsim.physics.dynamics.pair_time_of_impact`
    without acceleration.

    Solves ``a t^2 + 2 b t + c = 0`` with ``a = |dv|^2``, ``b = dr . dv`` and ``c = |dr|^2 - sigma^2`` by the
    cancellation-free root ``t = c / (-b + sqrt(b^2 - a c))``. Only approaching pairs (``b < 0``) collide; a
    pair already touching or overlapping while approaching collides at once (``t = 0``), so discs neither
    tunnel nor stick.

    The test for a hit is one comparison of a ``min``: a pair hits when it approaches (``b < 0``) and its path
    reaches contact (``b^2 - a c > 0``) or it touches (``c <= 0``). Compiled into the neighbour loops it stays
    one well-predicted branch (about 6% of a 1:10 mixture's candidates hit), which spares the rest the square
    root and the division; written with ``and``, LLVM branches on ``b < 0`` first, a coin toss.

    Example:
        >>> linear_contact(4.0, 0.0, -1.0, 0.0, 2.0)
        2.0
    """
    b = dx * dvx + dy * dvy
    c = dx * dx + dy * dy - sigma * sigma
    a = dvx * dvx + dvy * dvy
    d = b * b - a * c
    if min(-b, d if c > 0.0 else 1.0) > 0.0:
        return 0.0 if c <= 0.0 else c / (-b + math.sqrt(d))
    return INF


#: A contact is ruled out early only when the motion keeps farther than ``sigma`` from contact by this fraction
#: of the problem's length scale: far beyond rounding, so the early outs never decide a close call.
_MARGIN = 1e-9
#: Likewise, a convex piece of ``f`` is found apart by its tangents only above this fraction of their roundoff.
_TANGENT_MARGIN = 1e-12


def crossing_time(
    lo: float, hi: float, dx: float, dy: float, dvx: float, dvy: float, hx: float, hy: float, s2: float
) -> float:
    """The downward crossing of ``f`` in ``(lo, hi]``, given ``f(lo) > 0 >= f(hi)``: bisection of ``f`` until the
    bracket is two adjacent floats, and its upper end (``f`` is ``<= 0`` there and ``> 0`` at the float before).

    ``f(t) = |p(t)|^2 - s2`` with ``p(t) = d + t (w + t h)``; the callers choose a bracket holding one crossing.

    Args:
        lo, hi: the bracket (time; ``0 <= lo < hi``).
        dx, dy, dvx, dvy: the relative position and velocity at time 0 (``d``, ``w``).
        hx, hy: half the relative acceleration (``h``, length / time^2).
        s2: the contact distance squared (length^2).

    Example:
        >>> crossing_time(0.0, 2.5, 0.0, 3.0, 0.0, 0.0, 0.0, -0.5, 1.0)  # falls 2 from rest at 1: t = 2
        2.0
    """
    while True:
        t = 0.5 * (lo + hi)
        if not lo < t < hi:  # adjacent floats (or no number: never loop for ever)
            return hi
        px, py = dx + t * (dvx + t * hx), dy + t * (dvy + t * hy)
        if px * px + py * py - s2 > 0.0:
            lo = t
        else:
            hi = t


def convex_piece(
    lo: float, hi: float, dx: float, dy: float, dvx: float, dvy: float, hx: float, hy: float, s2: float
) -> float:
    """The first contact while approaching in ``[lo, hi]``, where ``f`` is convex (``f'' >= 0``: ``f'`` rises).

    ``lo`` if the pair touches or overlaps there and approaches. Else a crossing needs ``f`` falling at ``lo``;
    if ``f(hi) <= 0`` it is the one crossing of the span (:func:`crossing_time`); if ``f`` still falls at
    ``hi``, there is none; otherwise ``f`` has its minimum inside, which bisection of ``f'`` closes in on until
    a time with ``f <= 0`` brackets the crossing (before the minimum), or the tangents at the bracket's ends,
    below a convex ``f``, keep it above 0 (no contact, told with a margin far beyond roundoff), or the bracket
    is two adjacent floats, both apart (no contact).

    Args:
        lo, hi: the span (time; ``0 <= lo < hi``).
        dx, dy, dvx, dvy, hx, hy, s2: as for :func:`crossing_time`.

    Returns:
        The time of contact in ``[lo, hi]``, or ``math.inf`` if none.

    Example:
        >>> convex_piece(1.5, 10.0, 0.0, 3.0, 0.0, 0.0, 0.0, -0.5, 1.0)  # falling through the disc: lands at 2
        2.0
    """
    ax, ay = hx + hx, hy + hy
    px, py = dx + lo * (dvx + lo * hx), dy + lo * (dvy + lo * hy)
    f_lo = px * px + py * py - s2
    g_lo = px * (dvx + lo * ax) + py * (dvy + lo * ay)  # f' / 2
    if g_lo >= 0.0:  # f' rises from >= 0: f rises all along, never approaching
        return INF
    if f_lo <= 0.0:
        return lo
    px, py = dx + hi * (dvx + hi * hx), dy + hi * (dvy + hi * hy)
    f_hi = px * px + py * py - s2
    if f_hi <= 0.0:
        return crossing_time(lo, hi, dx, dy, dvx, dvy, hx, hy, s2)
    g_hi = px * (dvx + hi * ax) + py * (dvy + hi * ay)
    if g_hi <= 0.0:  # falling all along, and still apart at hi
        return INF
    while True:
        # The tangents at lo and hi meet at the lowest point of their maximum, below f: if that is above 0,
        # no contact. Times (g_hi - g_lo) > 0; every term of the margin is >= 0.
        width = hi - lo
        lowest = f_lo * g_hi - g_lo * f_hi + 2.0 * g_lo * g_hi * width
        margin = (f_lo + f_hi + 2.0 * s2) * (g_hi - g_lo) + f_lo * g_hi - g_lo * f_hi - 2.0 * g_lo * g_hi * width
        if lowest > _TANGENT_MARGIN * margin:
            return INF
        t = 0.5 * (lo + hi)
        if not lo < t < hi:  # at the minimum, apart on both sides
            return INF
        px, py = dx + t * (dvx + t * hx), dy + t * (dvy + t * hy)
        f_t = px * px + py * py - s2
        if f_t <= 0.0:  # apart at lo, in contact at t: the crossing lies between
            return crossing_time(lo, t, dx, dy, dvx, dvy, hx, hy, s2)
        g_t = px * (dvx + t * ax) + py * (dvy + t * ay)
        if g_t < 0.0:
            lo, f_lo, g_lo = t, f_t, g_t
        else:
            hi, f_hi, g_hi = t, f_t, g_t


def concave_piece(
    lo: float, hi: float, dx: float, dy: float, dvx: float, dvy: float, hx: float, hy: float, s2: float
) -> float:
    """The first contact while approaching in ``[lo, hi]``, where ``f`` is concave (``f'' <= 0``: ``f'`` falls).

    Apart at ``lo``: the one crossing of the span if ``f(hi) <= 0`` (a concave ``f`` is above its chord), else
    none. Touching or overlapping at ``lo`` and approaching (or at rest, ``f'`` then falling below 0): ``lo``.
    Overlapping and separating (just after a bounce): ``f`` rises to a maximum and falls; bisection of ``f'``
    closes in on the maximum until a time with ``f > 0`` shows the pair came apart (the contact is then the
    crossing after it), or the bracket is two adjacent floats with ``f <= 0``: a bounce too weak to part the
    pair by more than roundoff turns back in contact, and that time is the contact.

    Args:
        lo, hi: the span (time; ``0 <= lo < hi``).
        dx, dy, dvx, dvy, hx, hy, s2: as for :func:`crossing_time`.

    Returns:
        The time of contact in ``[lo, hi]``, or ``math.inf`` if none.

    Example:
        >>> concave_piece(0.0, 1.0, 0.0, 1.0, 0.0, 3.0, 0.0, -0.5, 1.0)  # bounced up at 3: apart until t = 6
        inf
    """
    px, py = dx + lo * (dvx + lo * hx), dy + lo * (dvy + lo * hy)
    f_lo = px * px + py * py - s2
    if f_lo > 0.0:
        px, py = dx + hi * (dvx + hi * hx), dy + hi * (dvy + hi * hy)
        if px * px + py * py - s2 > 0.0:
            return INF
        return crossing_time(lo, hi, dx, dy, dvx, dvy, hx, hy, s2)
    ax, ay = hx + hx, hy + hy
    if px * (dvx + lo * ax) + py * (dvy + lo * ay) <= 0.0:
        return lo
    px, py = dx + hi * (dvx + hi * hx), dy + hi * (dvy + hi * hy)
    if px * px + py * py - s2 > 0.0:  # apart at hi: no crossing back before it
        return INF
    if px * (dvx + hi * ax) + py * (dvy + hi * ay) >= 0.0:  # still separating at hi, in contact all along
        return INF
    while True:
        t = 0.5 * (lo + hi)
        if not lo < t < hi:  # the turn, still in contact
            return hi
        px, py = dx + t * (dvx + t * hx), dy + t * (dvy + t * hy)
        if px * px + py * py - s2 > 0.0:  # apart at t: the crossing back lies after it
            return crossing_time(t, hi, dx, dy, dvx, dvy, hx, hy, s2)
        if px * (dvx + t * ax) + py * (dvy + t * ay) > 0.0:
            lo = t
        else:
            hi = t


def inflections(dx: float, dy: float, dvx: float, dvy: float, ax: float, ay: float, horizon: float):
    """Where ``f(t) = |d + w t + a t^2 / 2|^2 - sigma^2`` turns from convex to concave and back in ``[0, horizon]``:
    ``(first, second)``, the roots of ``f''(t) / 2 = A t^2 + 2 B t + C`` (cancellation-free) within it
    (``horizon`` twice when ``f''`` keeps its sign): ``f`` is convex before the first and after the second,
    concave between."""
    a2 = ax * ax + ay * ay
    qa = 1.5 * a2
    qb = 1.5 * (dvx * ax + dvy * ay)
    qc = dvx * dvx + dvy * dvy + dx * ax + dy * ay
    first = second = horizon
    disc = qb * qb - qa * qc
    if disc > 0.0:
        q = -(qb + math.copysign(math.sqrt(disc), qb))
        r1, r2 = q / qa, qc / q
        if r1 > r2:
            r1, r2 = r2, r1
        # Within [0, horizon], written out (not min and max: no -0.0 where one root is -0.0)
        first = 0.0 if r1 <= 0.0 else (horizon if r1 >= horizon else r1)
        second = 0.0 if r2 <= 0.0 else (horizon if r2 >= horizon else r2)
    return first, second


def accelerated_time_of_impact(
    dx: float, dy: float, dvx: float, dvy: float, ax: float, ay: float, sigma: float
) -> float:
    """Time until two points, now ``(dx, dy)`` apart with relative velocity ``(dvx, dvy)`` and constant relative
    acceleration ``(ax, ay)``, come to distance ``sigma`` while approaching.

    The relative position is ``p(t) = d + w t + a t^2 / 2``; contact is a root of ``f(t) = |p(t)|^2 - sigma^2``.
    The answer is the earliest ``t >= 0`` at which the pair touches or overlaps while approaching:

    - ``f(0) <= 0`` and ``f'(0) < 0`` (touching or overlapping and approaching, as after roundoff): 0.0, as
      :func:`~discsim.physics.dynamics.pair_time_of_impact` does. ``f'(0) == 0`` with ``f`` decreasing just
      after (at rest in contact, pulled in) is approaching too: 0.0.
    - ``f(0) <= 0`` and separating (just after a bounce): not 0, but the next downward crossing of zero after
      ``f`` has gone positive (the ball comes back down). Should ``f`` turn back while still ``<= 0`` as
      computed (a bounce too weak to lift off by more than roundoff), the time it turns.
    - otherwise the first downward crossing of zero, or ``math.inf`` if there is none.

    A crossing is found by bisection to the last bit (:func:`crossing_time`). What the returned ``t`` means:
    ``f`` computed as ``|d + t (w + t a / 2)|^2 - sigma^2`` is ``<= 0`` at ``t`` and ``> 0`` at the float just
    before it, so the discs are at contact or inside it by roundoff, never before it; the loops resolve the
    collision at ``t`` (for an acceleration taken in another time unit, see below, the same in that unit).
    Bisection, not a faster false position: the computed ``f`` of a pair just parted by a bounce is 0 within
    roundoff for a while, and false position, drawn to the end where ``|f|`` is smallest, stops there on a
    crossing of roundoff (a 1e-15 instead of the come-back: tests/physics/test_roots.py keeps such a case).

    No contact is missed: between the roots of ``f''`` (a quadratic, cancellation-free) ``f`` is convex or
    concave, so that on each piece its values and slopes at the ends, and at most one bisection of ``f'``
    towards its minimum or maximum, say whether and where it crosses zero (:func:`convex_piece`,
    :func:`concave_piece`); no contact lies after ``T = 2 (|w| + sqrt(|w|^2 + 2 |a| (|d| + sigma))) / |a|``,
    where ``|p| >= |a| t^2 / 2 - |w| t - |d| > sigma``. Two cheap tests answer ``inf`` first when the motion
    across ``a`` (a line) or along ``a`` (a parabola) keeps the pair farther apart than ``sigma`` until ``T``.
    An acceleration outside ``1e-100 < max(|ax|, |ay|) < 1e100`` is taken in a time unit of a power of two
    in which it is about 1 (exact scaling), so that ``|a|^2`` neither underflows nor overflows.

    With ``ax == ay == 0`` it is :func:`~discsim.physics.dynamics.pair_time_of_impact`, bit for bit.

    Args:
        dx, dy: position of disc 2 (or the falling disc) minus disc 1 (or the fixed point) (length).
        dvx, dvy: velocity of 2 minus 1 (length / time).
        ax, ay: acceleration of 2 minus 1 (length / time^2).
        sigma: contact distance ``r1 + r2`` (length; a fixed point: the disc's radius).

    Returns:
        The time (>= 0) of the next contact, or ``math.inf`` if none.

    Example:
        >>> accelerated_time_of_impact(0.0, 3.0, 0.0, 0.0, 0.0, -1.0, 1.0)  # falls 2 from rest: sqrt(2 h / g)
        2.0
        >>> accelerated_time_of_impact(0.0, 1.0, 0.0, 3.0, 0.0, -1.0, 1.0)  # bounced up at 3: back at 2 v / g
        6.0
        >>> accelerated_time_of_impact(0.0, 3.0, 0.0, 0.0, 0.0, 1.0, 1.0)  # falls away
        inf
    """
    if ax == 0.0 and ay == 0.0:
        return linear_contact(dx, dy, dvx, dvy, sigma)
    c = dx * dx + dy * dy - sigma * sigma
    b = dx * dvx + dy * dvy
    if c <= 0.0 and b < 0.0:
        return 0.0
    unit = 1.0
    largest = max(abs(ax), abs(ay))
    if not 1e-100 < largest < 1e100:
        # A time unit of 2^k (exact) in which the acceleration is about 1, so that |a|^2 neither underflows nor
        # overflows: every step below then scales exactly, bit for bit.
        k = -(math.frexp(largest)[1] // 2)
        ax, ay, dvx, dvy = math.ldexp(ax, 2 * k), math.ldexp(ay, 2 * k), math.ldexp(dvx, k), math.ldexp(dvy, k)
        unit = math.ldexp(1.0, k)
    hx, hy = 0.5 * ax, 0.5 * ay
    a2 = ax * ax + ay * ay
    w2 = dvx * dvx + dvy * dvy
    a_norm, w_norm, d_norm = math.sqrt(a2), math.sqrt(w2), math.sqrt(dx * dx + dy * dy)
    horizon = 2.0 * (w_norm + math.sqrt(w2 + 2.0 * a_norm * (d_norm + sigma))) / a_norm
    reach = sigma + _MARGIN * (sigma + d_norm + horizon * (w_norm + horizon * a_norm))
    # Across a, the motion is a line: it must come within sigma of the point.
    across0 = (dy * ax - dx * ay) / a_norm
    across1 = across0 + horizon * (dvy * ax - dvx * ay) / a_norm
    if (across0 > reach and across1 > reach) or (across0 < -reach and across1 < -reach):
        return INF
    # Along a, a parabola opening towards +a: its lowest point until the horizon must be below sigma, and its
    # highest (an end) above -sigma.
    along0 = (dx * ax + dy * ay) / a_norm
    along_rate = (dvx * ax + dvy * ay) / a_norm
    along1 = along0 + horizon * (along_rate + horizon * 0.5 * a_norm)
    t = -along_rate / a_norm  # the lowest point, kept within [0, horizon]
    t = 0.0 if t <= 0.0 else (horizon if t >= horizon else t)
    if along0 + t * (along_rate + t * 0.5 * a_norm) > reach or (along0 < -reach and along1 < -reach):
        return INF
    first, second = inflections(dx, dy, dvx, dvy, ax, ay, horizon)
    s2 = sigma * sigma
    t = INF
    if first > 0.0:
        t = convex_piece(0.0, first, dx, dy, dvx, dvy, hx, hy, s2)
    if t == INF and second > first:
        t = concave_piece(first, second, dx, dy, dvx, dvy, hx, hy, s2)
    if t == INF and horizon > second:
        t = convex_piece(second, horizon, dx, dy, dvx, dvy, hx, hy, s2)
    return t * unit


def accelerated_exit(x: float, v: float, a: float, lo: float, hi: float) -> tuple[float, int]:
    """Time until a coordinate ``x + v t + a t^2 / 2`` reaches ``hi`` moving up or ``lo`` moving down.

    The roots of ``a t^2 / 2 + v t + (x - line) = 0`` are taken in the form without cancellation
    (``2 (line - x) / (v + s)`` or ``(s - v) / a``, ``s = sqrt(v^2 + 2 a (line - x))`` being the speed at the
    line). A coordinate just bounced off a floor (``x == lo``, ``v > 0``, ``a < 0``) comes back at
    ``-2 v / a``, exactly; one below the floor (by roundoff) moving up at ``-2 v / a`` too, when it comes back
    to where it is: as if it were at the floor, never at once (the floor would send it down into itself).
    Likewise above a ceiling (``x > hi``, ``v < 0``, ``a > 0``).

    With ``a == 0`` it is :func:`~discsim.physics.dynamics.exit_x`, bit for bit, a coordinate already past the
    line it moves towards giving a negative time. With ``a != 0``, a coordinate already past the line it moves
    towards gives the (negative or zero) time it crossed that line in the same direction, or 0.0 if its
    parabola never meets the line; the caller clamps negative times to now.

    Args:
        x: the coordinate at time 0 (length).
        v: its velocity (length / time).
        a: its acceleration (length / time^2).
        lo, hi: the slab (length).

    Returns:
        ``(t, side)``: ``side`` is 1 for ``hi``, -1 for ``lo``; ``(inf, 0)`` when it never moves (``a = v = 0``).

    Example:
        >>> accelerated_exit(0.0, 3.0, -1.0, 0.0, 10.0)  # thrown up from the floor: back down at 2 v / g
        (6.0, -1)
        >>> accelerated_exit(0.0, 3.0, -1.0, 0.0, 4.0)  # reaches the ceiling on the way up
        (2.0, 1)
    """
    if a == 0.0:
        return linear_exit(x, v, lo, hi)
    if a > 0.0:
        if v < 0.0:  # going down: reaches lo before it turns, if it reaches it
            d = v * v + 2.0 * a * (lo - x)
            if d > 0.0:
                return 2.0 * (lo - x) / (v - math.sqrt(d)), -1
            if x > hi:  # above hi by roundoff (just bounced off it): back up to where it is, as if it were at hi
                return -2.0 * v / a, 1
        d = v * v + 2.0 * a * (hi - x)
        if d < 0.0:  # above hi, turning before it gets back down to it
            return 0.0, 1
        s = math.sqrt(d)
        if v > 0.0:
            return 2.0 * (hi - x) / (v + s), 1
        return (s - v) / a, 1
    if v > 0.0:  # going up: reaches hi before it turns, if it reaches it
        d = v * v + 2.0 * a * (hi - x)
        if d > 0.0:
            return 2.0 * (hi - x) / (v + math.sqrt(d)), 1
        if x < lo:  # below lo by roundoff (just bounced off it): back down to where it is, as if it were at lo
            return -2.0 * v / a, -1
    d = v * v + 2.0 * a * (lo - x)
    if d < 0.0:  # below lo, turning before it gets back up to it
        return 0.0, -1
    s = math.sqrt(d)
    if v < 0.0:
        return 2.0 * (lo - x) / (v - s), -1
    return (-v - s) / a, -1


#: The functions to compile, callees first.
PARTS = (
    linear_exit,
    linear_contact,
    crossing_time,
    convex_piece,
    concave_piece,
    inflections,
    accelerated_time_of_impact,
    accelerated_exit,
)
