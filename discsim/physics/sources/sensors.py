"""Sensors: when a disc's centre next enters or leaves a circle, a rectangle or the side of a trip wire.

A sensor never changes the motion; it is an event source all the same. Each disc keeps, per sensor, whether
its centre is inside (:meth:`discsim.sensors.Sensor.contains`: a line's inside is the left of ``p1 - p0``), and
:func:`predict` answers the first time that changes, over the law of motion's exact flight:

- a line: its left-side coordinate ``u = cross(p1 - p0, p - p0)`` moves as one coordinate does (free flight,
  gravity's parabola, drag's exponential), so the time ``u`` reaches 0 is a slab's exit
  (:func:`~discsim.physics.dynamics.exit_x`, :func:`fall_to_zero`). The loop logs it only where the centre
  meets the segment itself; crossing the line beyond an end changes the side silently.
- a rectangle: leaving is the first exit of the two slabs; entering, the first time both coordinates are
  inside their slabs (each enters its slab at most twice along one flight: :func:`rectangle_time` steps
  from one entry to the next).
- a circle: free flight's quadratic (``|d + v t|^2 = R^2``); under drag alone, the same in the span ``tau``;
  under gravity, entering is the time of impact of a point with the centre (``sigma = R``) and leaving the
  first rise of ``|d + v t + g t^2 / 2|^2 - R^2`` through 0 (:func:`accelerated_leave`). Gravity and drag at
  once are refused for circles (``EventDriven`` says so).

Every function takes the disc's centre, velocity and acceleration now and the drag, and returns the time
from now (``inf``: never; not clamped: a negative time means at once).

Example:
    >>> circle_time(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 1.0, False)  # enters at x = 4
    4.0
    >>> circle_time(5.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 1.0, True)  # inside: leaves at x = 6
    1.0
"""

from __future__ import annotations

import math

from discsim.physics.damped import (
    _MAX_STEPS,
    _position,
    _rising_root,
    _turn,
    damped_exit,
    damped_time_of_impact,
    spans,
    time_of_span,
)
from discsim.physics.dynamics import advance, exit_x, exit_y
from discsim.physics.roots import accelerated_time_of_impact, inflections, linear_contact

__all__ = [
    "accelerated_leave",
    "circle_time",
    "contains",
    "fall_to_zero",
    "line_time",
    "on_wire",
    "predict",
    "rectangle_time",
    "rise_time",
]

INF = math.inf
CIRCLE, RECTANGLE, LINE = 1, 2, 3  # discsim.sensors' shape codes (this floor cannot import that module)


def fall_to_zero(u: float, v: float, a: float, drag: float) -> float:
    """Time until a coordinate ``u`` (``>= 0``, or below by roundoff) moving at ``v`` under ``a`` and ``drag``
    reaches 0 moving down; ``inf`` if never; negative (at once) when already below it and not coming back up.

    Example:
        >>> fall_to_zero(4.0, 0.0, -2.0, 0.0)  # dropped from 4 under 2: sqrt(2 h / g) = 2
        2.0
    """
    if drag != 0.0:
        t, side = damped_exit(u, v, a, drag, 0.0, INF)
        return t if side < 0 else INF
    if a == 0.0:
        return -u / v if v < 0.0 else INF
    d = v * v - 2.0 * a * u
    if a > 0.0:  # turns up for ever: crosses 0 only on the way down, before it turns
        if v >= 0.0 or d <= 0.0:
            return INF
        return 2.0 * u / (math.sqrt(d) - v)
    if d < 0.0:  # below 0 by roundoff and never back up to it
        return 0.0
    s = math.sqrt(d)
    if v > 0.0:  # rises, turns, falls through 0 (the larger root, without cancellation)
        return (v + s) / -a
    if s == 0.0 and v == 0.0:  # at rest at 0 (or so near it that 2 a u underflows): not 0 / 0
        return math.sqrt(2.0 * u / -a) if u > 0.0 else 0.0
    return 2.0 * u / (s - v)


def line_time(
    x: float, y: float, vx: float, vy: float, ax: float, ay: float, drag: float,
    x0: float, y0: float, x1: float, y1: float, inside: bool,
) -> float:  # fmt: skip
    """When the centre next crosses the line through ``(x0, y0)`` and ``(x1, y1)`` to the other side
    (``inside``: it is on the left of ``p1 - p0`` now), the segment or beyond its ends.

    Example:
        >>> line_time(0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 3.0, -1.0, 3.0, 1.0, True)  # left of the wire: x = 3 at 1.5
        1.5
    """
    ex, ey = x1 - x0, y1 - y0
    u = ex * (y - y0) - ey * (x - x0)
    v = ex * vy - ey * vx
    a = ex * ay - ey * ax
    if inside:
        return fall_to_zero(u, v, a, drag)
    return fall_to_zero(-u, -v, -a, drag)


def _enter_slab(x: float, v: float, a: float, drag: float, lo: float, hi: float) -> float:
    """Time until a coordinate enters the slab ``lo < x < hi`` (0 if in it now), or ``inf``. On an edge it is
    outside (:meth:`discsim.sensors.Sensor.contains`): it enters at once only moving (or pulled) inwards."""
    if x <= lo:
        return fall_to_zero(lo - x, -v, -a, drag)
    if x >= hi:
        return fall_to_zero(x - hi, v, a, drag)
    return 0.0


def rectangle_time(
    x: float, y: float, vx: float, vy: float, ax: float, ay: float, drag: float,
    x0: float, y0: float, x1: float, y1: float, inside: bool,
) -> float:  # fmt: skip
    """When the centre next leaves (``inside``) or enters the rectangle ``[x0, x1] x [y0, y1]``.

    Example:
        >>> rectangle_time(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 2.0, 3.0, 5.0, 5.0, False)  # y reaches 3 last
        3.0
    """
    if inside:
        tx, sx = exit_x(x, vx, x0, x1, ax, drag)
        ty, sy = exit_y(y, vy, y0, y1, ay, drag)
        if sx == 0:
            tx = INF
        if sy == 0:
            ty = INF
        return tx if tx < ty else ty
    if x0 < x < x1 and y0 < y < y1:  # inside by roundoff, just after leaving: on the nearest edge, whence it
        # enters at once only moving inwards (a hair in and moving out, it would enter and leave at one instant)
        near = min(x - x0, x1 - x, y - y0, y1 - y)
        if near == x - x0:
            x = x0
        elif near == x1 - x:
            x = x1
        elif near == y - y0:
            y = y0
        else:
            y = y1
    start = 0.0  # from now, each coordinate's next entry into its slab; both in at once: the entry
    px, py, ux, uy = x, y, vx, vy
    for _ in range(16):  # each coordinate enters its slab at most twice along one flight
        tx = _enter_slab(px, ux, ax, drag, x0, x1)
        ty = _enter_slab(py, uy, ay, drag, y0, y1)
        if tx < 0.0:
            tx = 0.0
        if ty < 0.0:
            ty = 0.0
        t = tx if tx > ty else ty
        if t == INF:
            return INF
        if t == 0.0:
            return start
        qx, qy, wx, wy = advance(x, y, vx, vy, start + t, ax, ay, drag)
        # The coordinate that enters last is on its edge then by construction (its position may round a hair
        # outside: a step to it would not move start, and the entry would be missed); the other must be in, not
        # on its edge (leaving it: the path only touches a corner).
        if (tx == t or x0 < qx < x1) and (ty == t or y0 < qy < y1):
            return start + t
        start += t
        px, py, ux, uy = qx, qy, wx, wy
    return INF


def rise_time(lo: float, hi: float, dx: float, dy: float, dvx: float, dvy: float, hx: float, hy: float, s2: float):
    """The upward crossing of ``f(t) = |d + t (w + t h)|^2 - s2`` in ``(lo, hi]``, given ``f(lo) <= 0 < f(hi)``
    and one crossing between: bisection to adjacent floats; the upper end (``f > 0`` there)."""
    while True:
        t = 0.5 * (lo + hi)
        if not lo < t < hi:
            return hi
        px, py = dx + t * (dvx + t * hx), dy + t * (dvy + t * hy)
        if px * px + py * py - s2 > 0.0:
            hi = t
        else:
            lo = t


def _leave_piece(
    lo: float, hi: float, convex: bool, dx: float, dy: float, dvx: float, dvy: float, hx: float, hy: float, s2: float
) -> float:
    """The first upward crossing of ``f`` in ``(lo, hi]`` (``f(lo) <= 0``), where ``f`` is convex or concave."""
    px, py = dx + hi * (dvx + hi * hx), dy + hi * (dvy + hi * hy)
    if px * px + py * py - s2 > 0.0:  # out at hi: one crossing (below 0 at lo; convex or concave, once only)
        return rise_time(lo, hi, dx, dy, dvx, dvy, hx, hy, s2)
    if convex:  # a convex f is below its chord: inside all along
        return INF
    # Concave, inside at both ends: out in between only if its maximum is above 0.
    ax, ay = hx + hx, hy + hy
    px, py = dx + lo * (dvx + lo * hx), dy + lo * (dvy + lo * hy)
    if px * (dvx + lo * ax) + py * (dvy + lo * ay) <= 0.0:  # falls from lo on
        return INF
    px, py = dx + hi * (dvx + hi * hx), dy + hi * (dvy + hi * hy)
    if px * (dvx + hi * ax) + py * (dvy + hi * ay) >= 0.0:  # rises until hi
        return INF
    start = lo
    while True:  # bisection of f' towards the maximum; out at a midpoint: the crossing lies before it
        t = 0.5 * (lo + hi)
        if not lo < t < hi:
            return INF
        px, py = dx + t * (dvx + t * hx), dy + t * (dvy + t * hy)
        if px * px + py * py - s2 > 0.0:
            return rise_time(start, t, dx, dy, dvx, dvy, hx, hy, s2)
        if px * (dvx + t * ax) + py * (dvy + t * ay) > 0.0:
            lo = t
        else:
            hi = t


def accelerated_leave(dx: float, dy: float, dvx: float, dvy: float, ax: float, ay: float, sigma: float) -> float:
    """Time until a point ``(dx, dy)`` from a centre, moving at ``(dvx, dvy)`` under ``(ax, ay)`` (not both 0),
    first gets farther than ``sigma`` from it; 0 if it is farther now and not heading in.

    ``f(t) = |d + w t + a t^2 / 2|^2 - sigma^2`` is convex or concave between the roots of ``f''`` (as in
    :func:`~discsim.physics.roots.accelerated_time_of_impact`), and ``f > 0`` past
    ``T = 2 (|w| + sqrt(|w|^2 + 2 |a| (|d| + sigma))) / |a|``: the first piece that ends outside holds the
    crossing, and a concave piece inside at both ends may still rise out at its maximum.

    A point farther than ``sigma`` (by roundoff: just entered) but heading in leaves as if it were on the edge,
    not at once. An acceleration outside ``1e-100 < max(|ax|, |ay|) < 1e100`` is taken in a time unit of a power
    of two in which it is about 1, as :func:`~discsim.physics.roots.accelerated_time_of_impact` does.

    Example:
        >>> accelerated_leave(0.0, 0.0, 0.0, 0.0, 0.0, -2.0, 1.0)  # dropped at the centre: out just after 1
        1.0000000000000002
    """
    s2 = sigma * sigma
    r2 = dx * dx + dy * dy
    if r2 - s2 > 0.0:
        if dx * dvx + dy * dvy >= 0.0:
            return 0.0
        s2, sigma = r2, math.sqrt(r2)  # f(0) = 0: on the edge
    unit = 1.0
    largest = max(abs(ax), abs(ay))
    if not 1e-100 < largest < 1e100:  # |a|^2 would underflow or overflow: exact scaling, bit for bit
        k = -(math.frexp(largest)[1] // 2)
        ax, ay, dvx, dvy = math.ldexp(ax, 2 * k), math.ldexp(ay, 2 * k), math.ldexp(dvx, k), math.ldexp(dvy, k)
        unit = math.ldexp(1.0, k)
    hx, hy = 0.5 * ax, 0.5 * ay
    a2 = ax * ax + ay * ay
    w2 = dvx * dvx + dvy * dvy
    a_norm = math.sqrt(a2)
    horizon = 2.0 * (math.sqrt(w2) + math.sqrt(w2 + 2.0 * a_norm * (math.sqrt(r2) + sigma))) / a_norm
    horizon *= 1.0 + 1e-9
    first, second = inflections(dx, dy, dvx, dvy, ax, ay, horizon)
    t = INF
    if first > 0.0:
        t = _leave_piece(0.0, first, True, dx, dy, dvx, dvy, hx, hy, s2)
    if t == INF and second > first:
        t = _leave_piece(first, second, False, dx, dy, dvx, dvy, hx, hy, s2)
    if t == INF and horizon > second:
        t = _leave_piece(second, horizon, True, dx, dy, dvx, dvy, hx, hy, s2)
    return t * unit


def damped_leave(
    dx: float, dy: float, dvx: float, dvy: float, ax: float, ay: float, gamma: float, sigma: float
) -> float:  # fmt: skip
    """Time until a point ``(dx, dy)`` from a centre, moving at ``(dvx, dvy)`` under ``(ax, ay)`` (not both 0) and
    drag ``gamma > 0``, first gets farther than ``sigma`` from it: the leaving time of a circle under gravity and
    drag.

    The mirror of :func:`~discsim.physics.damped.damped_time_of_impact`'s search: it leaves before its separation
    along the acceleration rises through ``sigma`` for good (the window's end), and from ``t`` over the next ``S``
    ``f(t + u) <= f + f' u + M u^2 / 2`` with ``f = |p|^2 - sigma^2`` and ``M = 2 W^2 + 2 |a - gamma p'(t)|
    e^(-gamma t) (|p| + W S)`` (``W`` the largest speed over the span, as there), so a step to that bound's first
    root never passes the exit; the steps shrink near it, and the search ends where a step no longer moves ``t``.

    Example:
        >>> round(damped_leave(0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 1e-9, 1.0), 6)  # a feather of drag: sqrt(2) nearly
        1.414214
    """
    g = math.sqrt(ax * ax + ay * ay)
    ux, uy = ax / g, ay / g
    q, wq = dx * ux + dy * uy, dvx * ux + dvy * uy
    start = _turn(wq, g, gamma) if wq < 0.0 else 0.0
    end = start
    if _position(start, q, wq, g, gamma)[0] <= sigma:  # out for good once it rises through sigma along a
        end = _rising_root(start, q, wq, g, gamma, sigma)
    s2 = sigma * sigma
    t = 0.0
    reach = 0.0
    for _ in range(_MAX_STEPS):
        tau, s, e = spans(t, gamma)
        px, py = dx + dvx * tau + ax * s, dy + dvy * tau + ay * s
        wx, wy = dvx * e + ax * tau, dvy * e + ay * tau
        f = px * px + py * py - s2
        fp = 2.0 * (px * wx + py * wy)
        if f > 0.0 or (f == 0.0 and fp > 0.0):
            return t
        if t >= end:
            return end
        span = min(end - t, max(2.0 * reach, (sigma - math.sqrt(max(f + s2, 0.0))) / max(math.hypot(wx, wy), 1e-300)))
        if not span > 0.0:
            span = end - t
        decay = math.exp(-gamma * t)
        cx, cy = (ax - gamma * dvx) * decay, (ay - gamma * dvy) * decay
        reached = -math.expm1(-gamma * span) / gamma
        w_big = max(math.hypot(wx, wy), math.hypot(wx + cx * reached, wy + cy * reached))
        big = 2.0 * w_big * w_big + 2.0 * math.hypot(cx, cy) * (math.sqrt(px * px + py * py) + w_big * span)
        nf = -f
        if big <= 0.0:
            step = INF if fp <= 0.0 else nf / fp
        elif fp >= 0.0:
            step = 2.0 * nf / (fp + math.sqrt(fp * fp + 2.0 * big * nf))
        else:
            step = (-fp + math.sqrt(fp * fp + 2.0 * big * nf)) / big
        if step >= span:
            step = span
            reach = span
        else:
            reach = step
        after = t + step
        if after == t:  # no longer moves: f is 0 here to within roundoff
            if fp > 0.0:
                return t
            after = t + max(span, 1e-300)  # a graze from inside at its highest point: the bound lets it move on
            if after == t:
                return end
        t = after if after < end else end
    return t


def _linear_leave(dx: float, dy: float, vx: float, vy: float, r: float) -> float:
    """Free flight's time until ``|d + v t|`` exceeds ``r`` (0 if it does now, ``inf`` at rest)."""
    a = vx * vx + vy * vy
    b = dx * vx + dy * vy
    c = dx * dx + dy * dy - r * r
    if c > 0.0 and b >= 0.0:
        return 0.0
    if a == 0.0:
        return INF
    disc = b * b - a * c
    if disc < 0.0:  # outside by roundoff, missing the circle
        return 0.0
    if b <= 0.0:
        return (math.sqrt(disc) - b) / a
    return -c / (b + math.sqrt(disc))


def circle_time(
    x: float, y: float, vx: float, vy: float, ax: float, ay: float, drag: float,
    cx: float, cy: float, r: float, inside: bool,
) -> float:  # fmt: skip
    """When the centre next leaves (``inside``) or enters the circle of radius ``r`` around ``(cx, cy)``."""
    dx, dy = x - cx, y - cy
    if ax == 0.0 and ay == 0.0:
        t = _linear_leave(dx, dy, vx, vy, r) if inside else linear_contact(dx, dy, vx, vy, r)
        if drag != 0.0:  # a straight line, in the span tau
            return time_of_span(t, drag)
        return t
    if drag != 0.0:  # gravity and drag: the certified searches
        if inside:
            return damped_leave(dx, dy, vx, vy, ax, ay, drag, r)
        return damped_time_of_impact(dx, dy, vx, vy, ax, ay, drag, r)
    if inside:
        return accelerated_leave(dx, dy, vx, vy, ax, ay, r)
    return accelerated_time_of_impact(dx, dy, vx, vy, ax, ay, r)


def contains(shape: float, a0: float, a1: float, a2: float, a3: float, x: float, y: float) -> bool:
    """Whether ``(x, y)`` is inside a sensor: :meth:`discsim.sensors.Sensor.contains`, on floats."""
    if shape == CIRCLE:
        dx, dy = x - a0, y - a1
        return dx * dx + dy * dy < a2 * a2
    if shape == RECTANGLE:
        return a0 < x < a2 and a1 < y < a3
    return (a2 - a0) * (y - a1) - (a3 - a1) * (x - a0) > 0.0


def on_wire(a0: float, a1: float, a2: float, a3: float, x: float, y: float) -> bool:
    """Whether a centre ``(x, y)`` on a trip wire's line lies on the wire itself (between its ends)."""
    ex, ey = a2 - a0, a3 - a1
    u = (x - a0) * ex + (y - a1) * ey
    return 0.0 <= u <= ex * ex + ey * ey


def predict(
    x: float, y: float, vx: float, vy: float, ax: float, ay: float, drag: float,
    shape: float, a0: float, a1: float, a2: float, a3: float, inside: bool,
) -> float:  # fmt: skip
    """When the centre next changes sides of a sensor (``shape`` its code, ``a0 .. a3`` its numbers:
    :func:`discsim.sensors.sensor_rows`), from inside if ``inside``."""
    if shape == CIRCLE:
        return circle_time(x, y, vx, vy, ax, ay, drag, a0, a1, a2, inside)
    if shape == RECTANGLE:
        return rectangle_time(x, y, vx, vy, ax, ay, drag, a0, a1, a2, a3, inside)
    return line_time(x, y, vx, vy, ax, ay, drag, a0, a1, a2, a3, inside)


#: The functions to compile, callees first.
PARTS = (
    fall_to_zero,
    line_time,
    _enter_slab,
    rectangle_time,
    rise_time,
    _leave_piece,
    accelerated_leave,
    damped_leave,
    _linear_leave,
    circle_time,
    contains,
    on_wire,
    predict,
)
