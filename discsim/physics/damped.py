"""Contact times under linear drag: the exponential flights that ``drag=gamma`` gives (issue 27).

Under a drag ``-gamma v`` (the same ``gamma`` for every disc, 1 / time) and a constant acceleration ``a``
(gravity, or none), a disc's velocity relaxes towards the terminal velocity ``a / gamma``:

    v(t) = v e^(-gamma t) + a tau(t),        x(t) = x + v tau(t) + a s(t),

with the two spans ``tau(t) = (1 - e^(-gamma t)) / gamma`` and ``s(t) = (t - tau(t)) / gamma``
(:func:`spans`; as ``gamma -> 0``, ``tau -> t`` and ``s -> t^2 / 2``: free flight and the parabola).

- Without acceleration, a path is a straight line run through in the transformed time ``tau``, which never
  exceeds ``1 / gamma`` (the disc stops after ``|v| / gamma``). So are the relative paths of two discs that both
  fall (their accelerations cancel), of a disc and an obstacle without gravity, and every wall and cell edge
  without gravity: free flight's closed forms in ``tau``, then ``t = -log1p(-gamma tau) / gamma``
  (:func:`time_of_span`; none when ``gamma tau >= 1``).
- With gravity, a coordinate along gravity is a sum of an exponential and a line, with one sign of curvature
  (``x'' = (a - gamma v) e^(-gamma t)``): at most one turn, so at most two monotone pieces, each holding at most
  one crossing of a line, which :func:`_root` closes in on (Newton's method from the safe side, then bisection)
  to adjacent floats
  (:func:`damped_exit`).
- A falling disc against something that does not fall (an obstacle, a disc at rest, a segment's end point) has
  no closed form: :func:`damped_time_of_impact` advances in time by steps that a certified lower bound of
  ``f(t) = |p(t)|^2 - sigma^2`` (its value, slope and a bound on its curvature) proves free of contact, within
  the one window of time in which the pair can touch at all (its separation along gravity below ``sigma``).
  It never steps past a contact; see its docstring for the bound.

Every function uses only arithmetic, comparisons and :mod:`math`, so numba compiles it from this source:
compile :data:`PARTS` in their order (callees first).
"""

from __future__ import annotations

import math

import numpy as np

from discsim.physics.roots import linear_contact, linear_exit

__all__ = ["PARTS", "damped_exit", "damped_time_of_impact", "spans", "spans_many", "time_of_span"]

INF = math.inf
#: Below this ``|gamma t|`` the span ``s`` comes from its series (``t - tau`` would cancel); above, directly.
_SERIES = 0.5
#: Times beyond this count as never (the positions there overflow the floats).
_NEVER = 1e250
#: The most steps :func:`damped_time_of_impact` takes; far more than any case of the tests needs (tens).
_MAX_STEPS = 2000


def spans(dt: float, gamma: float) -> tuple[float, float, float]:
    """The spans of a flight of ``dt`` under drag ``gamma > 0``: ``(tau, s, e)``.

    ``tau = (1 - e^(-gamma dt)) / gamma`` multiplies the velocity, ``s = (dt - tau) / gamma`` the acceleration
    in the displacement, and ``e = e^(-gamma dt)`` is the velocity's decay. ``s`` comes from its series while
    ``|gamma dt| < 0.5`` (``dt^2 (1/2 - x/6 + x^2/24 - ...)``, ``x = gamma dt``), so it keeps full precision as
    ``gamma dt -> 0``.

    Example:
        >>> tau, s, e = spans(2.0, 1e-12)  # almost no drag: free flight's t and t^2 / 2
        >>> round(tau, 9), round(s, 9), round(e, 9)
        (2.0, 2.0, 1.0)
    """
    x = gamma * dt
    em = math.expm1(-x)
    tau = -em / gamma
    if -_SERIES < x < _SERIES:
        # s / dt^2 = sum_k (-x)^k / (k + 2)!, to x^14 (its last term below 1e-17 of the first at x = 0.5).
        c = _INVERSE[14]
        for k in range(13, -1, -1):
            c = _INVERSE[k] - x * c
        s = dt * dt * c
    else:
        s = (dt - tau) / gamma
    # e^(-x): from expm1 while it keeps its digits; past x = 0.5 from exp itself (1 + expm1 is exactly 0 once
    # e^(-x) drops below half an ulp of 1, at x = 37, and a decayed velocity would read exactly 0).
    return tau, s, (1.0 + em if x < _SERIES else math.exp(-x))


#: ``_INVERSE[k] = 1 / (k + 2)!``, the series' coefficients in :func:`spans`.
_INVERSE = (
    1 / 2, 1 / 6, 1 / 24, 1 / 120, 1 / 720, 1 / 5040, 1 / 40320, 1 / 362880, 1 / 3628800, 1 / 39916800,
    1 / 479001600, 1 / 6227020800, 1 / 87178291200, 1 / 1307674368000, 1 / 20922789888000,
)  # fmt: skip


def spans_many(dt: np.ndarray, gamma: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`spans` of an array of times (numpy; for trajectories and states read at a time), equal to it
    element by element to the last bit (numpy's ``expm1`` and :mod:`math`'s may round apart).

    Example:
        >>> tau, s, e = spans_many(np.array([0.1, 2.0]), 1.0)
        >>> bool(np.allclose(tau, [spans(0.1, 1.0)[0], spans(2.0, 1.0)[0]], rtol=1e-15, atol=0.0))
        True
    """
    dt = np.asarray(dt, dtype=float)
    x = gamma * dt
    em = np.expm1(-x)
    tau = -em / gamma
    small = np.abs(x) < _SERIES
    xs = np.where(small, x, 0.0)  # the series only where it is used (no overflow elsewhere)
    c = np.full_like(x, _INVERSE[14])
    for k in range(13, -1, -1):
        c = _INVERSE[k] - xs * c
    with np.errstate(invalid="ignore", over="ignore"):
        s = np.where(small, dt * dt * c, (dt - tau) / gamma)
    return tau, s, np.where(x < _SERIES, 1.0 + em, np.exp(-x))


def time_of_span(tau: float, gamma: float) -> float:
    """The time at which the span :func:`spans` reaches ``tau``: ``-log1p(-gamma tau) / gamma``; ``inf`` when it
    never does (``gamma tau >= 1``: the drag stops the motion first). A negative ``tau`` gives a negative time.

    Example:
        >>> time_of_span(0.5, 1.0) == math.log(2.0)
        True
        >>> time_of_span(1.0, 1.0)
        inf
    """
    g = gamma * tau
    if g >= 1.0 or tau == INF:
        return INF
    return -math.log1p(-g) / gamma


def _position(t: float, x: float, v: float, a: float, gamma: float) -> tuple[float, float]:
    """A coordinate and its velocity ``t`` after it was at ``x`` moving at ``v``, under ``a`` and drag ``gamma``."""
    tau, s, e = spans(t, gamma)
    return x + v * tau + a * s, v * e + a * tau


def _root(lo: float, hi: float, x: float, v: float, a: float, gamma: float, line: float) -> float:
    """The time in ``(lo, hi]`` at which the rising coordinate ``x(t)``, below ``line`` at ``lo`` and at or above
    it at ``hi`` (one crossing between), reaches ``line``: the upper of two adjacent floats bracketing it.

    ``x'' = (a - gamma v) e^(-gamma t)`` keeps one sign, so Newton's step from the end whose tangent stays on
    the near side of the root (the lower end of a concave rise, the upper end of a convex one) closes in
    monotonically and fast; the far end is then brought within a few steps of it, and bisection ends on two
    adjacent floats.
    """
    below = a - gamma * v < 0.0  # concave: Newton from the lower end
    near_low = below  # which end the root is nearest now
    for _ in range(100):
        t = lo if below else hi
        p, u = _position(t, x, v, a, gamma)
        if not u > 0.0:
            break
        n = t - (p - line) / u
        if not lo < n < hi:
            break
        if _position(n, x, v, a, gamma)[0] < line:
            lo = n
            if not below:  # roundoff put the step past the root, a few ulps from it: stop there
                near_low = True
                break
        else:
            hi = n
            if below:
                near_low = False
                break
    # The far end: the near one is within a few ulps of the root (Newton converges quadratically), so probe from 4
    # ulps outwards, 8 times wider each time (a Newton cut short by the bracket just takes more probes).
    width = 1e-15 * abs(lo if near_low else hi) + 1e-300
    for _ in range(400):
        if near_low:
            c = lo + width
            if not c < hi:
                break
            if _position(c, x, v, a, gamma)[0] >= line:
                hi = c
                break
            lo = c
        else:
            c = hi - width
            if not c > lo:
                break
            if _position(c, x, v, a, gamma)[0] < line:
                lo = c
                break
            hi = c
        width *= 8.0
    while True:
        t = 0.5 * (lo + hi)
        if not lo < t < hi:
            return hi
        if _position(t, x, v, a, gamma)[0] < line:
            lo = t
        else:
            hi = t


def _rising_root(start: float, x: float, v: float, a: float, gamma: float, line: float) -> float:
    """The time after ``start`` at which a coordinate under ``a > 0`` (rising from ``start`` on, below ``line``
    there) reaches ``line``, or ``inf`` if not within the floats (an acceleration too small to matter).

    Bracketed by two lower bounds of the path after ``start`` (``u >= 0`` its velocity there, ``v_T = a / gamma``
    the terminal velocity, ``dt`` the time since): ``x(start) + v_T dt - max(0, v_T - u) / gamma`` (tight when the
    drag dominates), and ``x(start) + u tau + a tau^2 / 2`` (``tau = tau(dt)``; since ``s >= tau^2 / 2``: tight
    when the drag is weak, as the parabola's root); then :func:`_root`."""
    q, u = _position(start, x, v, a, gamma)
    if q >= line:  # there already (at rest on the line, or over it by roundoff): the rise below is 0 / 0
        return start
    u = max(u, 0.0)
    vt = a / gamma
    end = start + (line - q + max(0.0, vt - u) / gamma) / vt * (1.0 + 1e-9)
    rise = line - q
    tau = 2.0 * rise / (u + math.sqrt(u * u + 2.0 * a * rise))  # u tau + a tau^2 / 2 = rise
    end = min(end, start + time_of_span(tau, gamma) * (1.0 + 1e-9))
    end += 1e-300
    if not end < _NEVER:  # (an acceleration so small that the crossing lies beyond any time that can matter)
        return INF
    while _position(end, x, v, a, gamma)[0] < line:  # the bounds hold: only roundoff can leave it short
        end = start + 2.0 * (end - start)
        if not end < INF:
            return INF
    return _root(start, end, x, v, a, gamma, line)


def _turn(v: float, a: float, gamma: float) -> float:
    """The time a coordinate moving at ``v`` against an acceleration ``a`` (``v a < 0``) stops and turns back."""
    return math.log1p(-gamma * v / a) / gamma


def _falling_exit(x: float, v: float, a: float, gamma: float, lo: float, hi: float) -> tuple[float, int]:
    """:func:`damped_exit` for ``a < 0``: the path rises while ``v > 0``, turns once, and falls for ever."""
    if v > 0.0:
        turn = _turn(v, a, gamma)
        top = _position(turn, x, v, a, gamma)[0]
        if top >= hi:  # reaches hi on the way up
            if x >= hi:
                return 0.0, 1
            return _root(0.0, turn, x, v, a, gamma, hi), 1
        # Comes back down to lo; from below lo (by roundoff, just bounced off it) back to where it is, as if it
        # were at lo, never at once (the floor would send it down into itself).
        line = x if x < lo else lo
        return _rising_root(turn, -x, -v, -a, gamma, -line), -1
    if x <= lo:  # at or past the line it moves towards
        return 0.0, -1
    return _rising_root(0.0, -x, -v, -a, gamma, -lo), -1


def damped_exit(x: float, v: float, a: float, gamma: float, lo: float, hi: float) -> tuple[float, int]:
    """Time until a coordinate under drag ``gamma > 0`` and acceleration ``a`` reaches ``hi`` moving up or ``lo``
    moving down: :func:`discsim.physics.dynamics.exit_x` under drag.

    Without acceleration, free flight's exit in the span ``tau`` (:func:`~discsim.physics.roots.linear_exit`),
    and its time (``inf`` if the drag stops the coordinate first; negative when already past the line it moves
    towards, as free flight's). With one, the crossing on the monotone piece that holds it (see the module),
    to adjacent floats; a coordinate just bounced off a floor (or below it by roundoff) comes back to where it
    is, never at once, and one already past the line it moves towards answers 0.

    Returns:
        ``(t, side)``: ``side`` 1 for ``hi``, -1 for ``lo``; ``(inf, 0)`` when it never reaches either (an
        acceleration so small that it would take longer than the largest float counts as none).

    Example:
        >>> t, side = damped_exit(0.0, 1.0, 0.0, 1.0, -5.0, 0.5)  # stops at 1: reaches 0.5 when tau = 0.5
        >>> t == math.log(2.0), side
        (True, 1)
    """
    if a == 0.0:
        tau, side = linear_exit(x, v, lo, hi)
        t = time_of_span(tau, gamma)
        if t == INF:
            return INF, 0
        return t, side
    if a > 0.0:
        t, side = _falling_exit(-x, -v, -a, gamma, -hi, -lo)
        side = -side
    else:
        t, side = _falling_exit(x, v, a, gamma, lo, hi)
    if t == INF:
        return INF, 0
    return t, side


def damped_time_of_impact(
    dx: float, dy: float, dvx: float, dvy: float, ax: float, ay: float, gamma: float, sigma: float
) -> float:
    """Time until two points, now ``(dx, dy)`` apart with relative velocity ``(dvx, dvy)``, relative
    acceleration ``(ax, ay)`` and drag ``gamma > 0``, come to distance ``sigma`` while approaching.

    Without relative acceleration the relative path is a line in the span ``tau``: free flight's contact
    (:func:`~discsim.physics.roots.linear_contact`) and :func:`time_of_span`. With one (a falling disc against
    one that does not fall), ``p(t) = d + w tau(t) + a s(t)``, and the contact is the first root of
    ``f(t) = |p|^2 - sigma^2`` while approaching. The search:

    - a window: the separation along ``a`` tends to ``+inf``, so after it last rises through ``sigma`` the two
      never touch (and if it never comes down to ``sigma``, they never do);
    - steps: at ``t``, over the next ``S``, ``f(t + u) >= f + f' u - M u^2 / 2`` with ``M = 2 |a| e^(-gamma t)
      (|p| + W S) - 2 m``, where the relative velocity runs along the segment from ``p'(t)`` to the terminal
      ``a / gamma``, over the span only as far as ``p'(t) + (a - gamma p'(t)) tau(S)`` (so ``|p'| <= W``, that
      piece's larger end, and ``|p'|^2 >= m``, the piece's distance to 0, squared) and ``|p''| <= |a - gamma
      p'(t)| e^(-gamma u)``. The bound's first root is no later than ``f``'s, so a step
      to it never passes a contact; near a contact the steps shrink as Newton's do (quadratically), and the
      search ends when a step no longer moves ``t`` (contact, if approaching) or leaves the window (none).

    Returns:
        The time (>= 0) of the first contact, or ``math.inf`` if none.

    Example:
        >>> round(damped_time_of_impact(4.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.1, 2.0), 12) == round(-math.log(0.8) / 0.1, 12)
        True
    """
    if ax == 0.0 and ay == 0.0:
        return time_of_span(linear_contact(dx, dy, dvx, dvy, sigma), gamma)
    g = math.sqrt(ax * ax + ay * ay)
    ux, uy = ax / g, ay / g
    # The window: the separation along a, q(t) = q + w tau + g s, comes down to sigma (or is there) and rises
    # through it at ``end``.
    q, wq = dx * ux + dy * uy, dvx * ux + dvy * uy
    start = 0.0
    if wq < 0.0:
        start = _turn(wq, g, gamma)
    if _position(start, q, wq, g, gamma)[0] > sigma:
        return INF
    end = _rising_root(start, q, wq, g, gamma, sigma)
    s2 = sigma * sigma
    t = 0.0
    reach = 0.0  # the span the last curvature bound covered
    for _ in range(_MAX_STEPS):
        tau, s, e = spans(t, gamma)
        px, py = dx + dvx * tau + ax * s, dy + dvy * tau + ay * s
        wx, wy = dvx * e + ax * tau, dvy * e + ay * tau
        f = px * px + py * py - s2
        fp = 2.0 * (px * wx + py * wy)
        if f <= 0.0 and fp <= 0.0:  # touching or overlapping, approaching: contact now
            return t
        if t >= end:
            return INF
        # The bound on f'' over [t, t + span]: span grows while steps do, never past the window's end.
        span = min(end - t, max(2.0 * reach, (math.sqrt(max(f + s2, 0.0)) - sigma) / max(math.hypot(wx, wy), 1e-300)))
        if not span > 0.0:
            span = end - t
        # Over the span p' runs from p'(t) towards the terminal velocity, only as far as p'(t) + (a - gamma p'(t))
        # tau(span) (not all the way: a tiny drag's terminal velocity would make the bound useless, and the steps
        # tiny): the largest and the least |p'| over the span lie on that piece of the segment.
        # p''(t) = a - gamma p'(t) = (a - gamma w) e^(-gamma t), written so: near the terminal velocity the
        # difference is all roundoff, and would bound the curvature 1e16 times too high (a huge drag's steps).
        decay = math.exp(-gamma * t)
        cx, cy = (ax - gamma * dvx) * decay, (ay - gamma * dvy) * decay
        reached = -math.expm1(-gamma * span) / gamma
        ex, ey = cx * reached, cy * reached
        w_big = max(math.hypot(wx, wy), math.hypot(wx + ex, wy + ey))
        ee = ex * ex + ey * ey
        k = 0.0 if ee == 0.0 else min(1.0, max(0.0, -(wx * ex + wy * ey) / ee))
        mx, my = wx + k * ex, wy + k * ey
        m = mx * mx + my * my
        curve = math.hypot(cx, cy)
        big = 2.0 * curve * (math.sqrt(px * px + py * py) + w_big * span) - 2.0 * m
        fc = max(f, 0.0)
        if big <= 0.0:  # f is convex over the span: its tangent is below it
            step = INF if fp >= 0.0 else fc / -fp
        elif fp > 0.0:
            step = (fp + math.sqrt(fp * fp + 2.0 * big * fc)) / big
        else:
            step = 2.0 * fc / (-fp + math.sqrt(fp * fp + 2.0 * big * fc))
        if step >= span:
            step = span
            reach = span
        else:
            reach = step
        after = t + step
        if after == t:  # no longer moves: f is 0 here to within roundoff
            if fp < 0.0:
                return t
            after = t + max(span, 1e-300)  # at a graze's lowest point: the bound lets it move on
            if after == t:
                return INF
        t = after if after < end else end
    return t  # not settled in _MAX_STEPS (never seen): the earliest time not proven free of contact


#: The functions to compile, callees first.
PARTS = (spans, time_of_span, _position, _root, _rising_root, _turn, _falling_exit, damped_exit, damped_time_of_impact)
