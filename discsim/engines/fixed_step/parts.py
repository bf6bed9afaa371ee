"""The fixed-step frame's own plain float parts, written once for both backends.

Like :mod:`discsim.physics`, each is a function of floats (arithmetic, comparisons and :mod:`math` only): the
Python frames call it, and the compiled frames (:mod:`~discsim.engines.fixed_step.numba`) compile it from this
very source (``discsim._compiled.compile_from_source``), so the two cannot drift apart:

- :func:`wrap`: :meth:`~discsim.model.Box.wrap` of one coordinate;
- :func:`nearest_image` and :func:`box_image`: the minimum image of one coordinate of a displacement,
  :func:`~discsim.model.minimum_image_1d` (the rule ``d - L round(d / L)``) as a scalar loop computes it, and
  as :meth:`~discsim.model.Box.minimum_image` computes it on arrays (the two differ in the sign of a zero);
- :func:`impulse_virial`: the term one pair response adds to the collision virial;
- :func:`separate_pair` and :func:`push_off_segment`: where the ``"separate"`` policy leaves two overlapping
  discs, or a disc cutting a segment (the caller passes the distance: Python's ``math.hypot`` is not the C
  library's, so the compiled frames pass CPython's, ``numba.kernels.cpython_hypot``);
- :func:`table_shape` and :func:`cell_span`: the cells of the sub-frame policies' cell table
  (:class:`~discsim.engines.fixed_step.broad_phase.CellTable`) and the cells a box meets;
- :func:`restitution` and :func:`kinetic_loss`: the coefficient of restitution of one response (one number,
  or the pair of groups', 1 within the TC time) and the kinetic energy it takes from one disc;
- :func:`wall_bounce`, :func:`segment_bounce` and :func:`rough_pair`: a response with roughness (the collision
  law's :func:`~discsim.physics.laws.rough_impulse` after its normal impulse, as the event-driven loop applies
  it), :func:`spin_loss` the rotational energy it takes from one disc; :func:`moving_segment_bounce`: a bounce off a
  moving segment, in its frame.

The free flight, the collision law and the times of impact are the physics parts themselves
(:mod:`discsim.physics.dynamics`, :mod:`discsim.physics.laws`, :mod:`discsim.physics.sources`).
"""

from __future__ import annotations

import math

from discsim.model import minimum_image_1d
from discsim.physics.laws import closest_point_on_segment, reflect, reflect_off_segment, rough_impulse

__all__ = [
    "box_image",
    "cell_span",
    "impulse_virial",
    "kinetic_loss",
    "moving_segment_bounce",
    "nearest_image",
    "push_off_segment",
    "restitution",
    "rough_pair",
    "segment_bounce",
    "separate_pair",
    "spin_loss",
    "table_shape",
    "wall_bounce",
    "wrap",
]

INF = math.inf
WHOLE = 4503599627370496.0  # 2 ** 52: every float this large or larger is a whole number


def wrap(v: float, size: float) -> float:
    """:meth:`~discsim.model.Box.wrap` of one coordinate ``v`` of a periodic box ``size`` long: ``v % size``,
    the size itself (a tiny negative ``v`` rounds up to it) to 0, and ``-0.0`` to ``+0.0``.

    The usual cases are done without the remainder, with the floats it gives (the exact ``fmod`` of a number
    within one box length of the box is itself, or itself less the length): 4x faster compiled.

    Example:
        >>> wrap(12.5, 10.0), wrap(-2.5, 10.0), wrap(-1e-20, 10.0), wrap(-0.0, 10.0)
        (2.5, 7.5, 0.0, 0.0)
    """
    if 0.0 < v < size:
        return v
    if v == 0.0:
        return 0.0  # -0.0 % size is +0.0
    if -size <= v < 0.0:
        m = v + size
        return 0.0 if m >= size else m
    if size <= v < 2.0 * size:
        return v - size  # exact
    m = v % size
    return 0.0 if m >= size else m


def nearest_image(d: float, length: float) -> float:
    """:func:`~discsim.model.minimum_image_1d` to the bit (a ``-0.0`` stays ``-0.0``, as Python's ``round``
    leaves it), without the division when ``|d|`` is within half a box length (the rounding gives 0 there;
    the compiled frames test most pairs there).

    Past ``2 ** 52`` box lengths every float is a whole number, so ``round(d / length)`` is ``d / length``
    itself: written so, compiled code needs no integer that large (numba's ``round`` gives an int64).

    Example:
        >>> nearest_image(9.0, 10.0), nearest_image(-6.0, 10.0), nearest_image(-0.0, 10.0)
        (-1.0, 4.0, -0.0)
    """
    if abs(d) <= 0.5 * length:
        return d
    q = d / length
    if abs(q) < WHOLE:
        return minimum_image_1d(d, length)
    return d - length * q  # also inf and nan, as numpy's round gives them


def box_image(d: float, length: float) -> float:
    """:meth:`~discsim.model.Box.minimum_image` of one coordinate, to the bit: :func:`nearest_image`, a zero
    as ``+0.0`` (numpy's ``round`` keeps the sign of ``-0.0``, so ``d - L * round(d / L)`` is ``+0.0`` there).

    Example:
        >>> box_image(9.0, 10.0), box_image(-0.0, 10.0)
        (-1.0, 0.0)
    """
    return nearest_image(d, length) + 0.0


def impulse_virial(
    sx: float, sy: float, vxi: float, vyi: float, uxi: float, uyi: float,
    vxj: float, vyj: float, uxj: float, uyj: float, mi: float, mj: float,
) -> float:  # fmt: skip
    """``dp_i . (r_i - r_j)`` of one pair response: the term it adds to the collision virial (energy).

    ``(sx, sy)``: the separation ``r_j - r_i`` where the impulse is applied; ``v`` the velocities
    before, ``u`` after; ``mi``, ``mj`` the masses. ``dp_i = m_i (u_i - v_i)``, or ``-m_j (u_j - v_j)``
    when disc ``i`` is an obstacle (infinite mass). The event-driven loop adds the same term.

    Example:
        >>> impulse_virial(2.0, 0.0, 1.0, 0.0, -1.0, 0.0, -1.0, 0.0, 1.0, 0.0, 1.0, 1.0)  # head on, touching
        4.0
    """
    if mi != INF:
        return -mi * ((uxi - vxi) * sx + (uyi - vyi) * sy)
    return mj * ((uxj - vxj) * sx + (uyj - vyj) * sy)


def separate_pair(
    xi: float, yi: float, xj: float, yj: float, dx: float, dy: float,
    mi: float, mj: float, sigma: float, dist: float,
) -> tuple[float, float, float, float, float, float]:  # fmt: skip
    """Discs ``i`` at ``(xi, yi)`` and ``j`` at ``(xj, yj)``, ``(dx, dy)`` apart (``j - i``, minimum image) and
    ``dist = hypot(dx, dy)`` apart, pushed apart along the line of centres until they touch (``sigma``), each
    in inverse proportion to its mass (an infinite mass stays).

    Returns:
        ``(xi, yi, xj, yj, dx, dy)``: the new centres and the line of centres at contact (unchanged when the
        discs do not overlap or coincide).

    Example:
        >>> separate_pair(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 1.0, 2.0, 1.0)
        (-0.5, 0.0, 1.5, 0.0, 2.0, 0.0)
    """
    depth = sigma - dist
    if depth > 0.0 and dist > 0.0:
        if mi == INF:
            wi, wj = 0.0, 1.0
        elif mj == INF:
            wi, wj = 1.0, 0.0
        else:
            wi, wj = mj / (mi + mj), mi / (mi + mj)
        ux, uy = dx / dist, dy / dist
        xi, yi = xi - wi * depth * ux, yi - wi * depth * uy
        xj, yj = xj + wj * depth * ux, yj + wj * depth * uy
        dx, dy = ux * (dist + depth), uy * (dist + depth)
    return xi, yi, xj, yj, dx, dy


def push_off_segment(
    x: float, y: float, qx: float, qy: float, nx: float, ny: float, r: float, dist: float
) -> tuple[float, float]:
    """A disc of radius ``r`` at ``(x, y)``, ``dist = hypot(nx, ny)`` from its nearest point ``(qx, qy)`` of a
    segment along the normal ``(nx, ny)``, pushed out along the normal until it touches.

    Example:
        >>> push_off_segment(0.0, 0.5, 0.0, 0.0, 0.0, 0.5, 1.0, 0.5)
        (0.0, 1.0)
    """
    if dist < r:
        return qx + nx / dist * r, qy + ny / dist * r
    return x, y


def table_shape(n: int, cell: float, width: float, height: float) -> tuple[int, int]:
    """``(nx, ny)`` of the cell table of ``n`` discs: cells of side ``cell`` or more (length), at most
    ``max(4 n, 65536)`` of them.

    Example:
        >>> table_shape(10, 1.0, 10.0, 4.5)
        (10, 4)
    """
    nx = max(1, int(width // cell))
    ny = max(1, int(height // cell))
    cap = max(4 * n, 1 << 16)
    if nx * ny > cap:
        scale = math.sqrt(nx * ny / cap)
        nx, ny = max(1, int(nx / scale)), max(1, int(ny / scale))
    return nx, ny


def cell_span(lo: float, hi: float, size: float, count: int, periodic: bool) -> tuple[int, int, bool]:
    """The cells of side ``size`` (``count`` of them along the axis) that the interval ``[lo, hi]`` meets.

    Returns:
        ``(first, last, wrap)``: the cells ``first..last``, each ``% count`` when ``wrap`` (a periodic axis);
        clamped to the edge cells along a walled axis.

    Example:
        >>> cell_span(-1.5, 2.5, 1.0, 10, True), cell_span(-1.5, 2.5, 1.0, 10, False)
        ((-2, 2, True), (0, 2, False))
    """
    first, last = math.floor(lo / size), math.floor(hi / size)
    if periodic:
        if last - first + 1 >= count:
            return 0, count - 1, False
        return first, last, True
    return min(max(first, 0), count - 1), min(max(last, 0), count - 1), False


def restitution(i: int, j: int, now: float, e: float, per_group: bool, table, group, tc: float, last) -> float:
    """The coefficient of restitution of a response of discs ``i`` and ``j`` (``i`` twice: a wall or a segment)
    at time ``now``: ``e``, or ``table[group[i], group[j]]`` when it depends on the pair of groups
    (:meth:`discsim.laws.Laws.table`); 1 (elastic) when either disc's last response was within ``tc`` of ``now``
    (the TC model; ``last``: each disc's last response time, ``-inf`` for none; ``tc = 0``: no TC model).

    Example:
        >>> restitution(0, 1, 5.0, 0.5, False, None, None, 0.0, None)
        0.5
        >>> restitution(0, 1, 5.0, 0.5, True, [[1.0, 0.2], [0.2, 0.9]], [0, 1], 0.1, [4.0, 4.95])  # TC: elastic
        1.0
    """
    if per_group:
        e = table[group[i]][group[j]]
    if tc > 0.0 and (now - last[i] < tc or now - last[j] < tc):
        e = 1.0
    return e


def kinetic_loss(m: float, vx: float, vy: float, ux: float, uy: float) -> float:
    """The kinetic energy a disc of mass ``m`` loses going from velocity ``v`` to ``u`` (0 for an obstacle).

    Example:
        >>> kinetic_loss(2.0, 3.0, 0.0, 1.0, 0.0)
        8.0
    """
    if m == INF:
        return 0.0
    return 0.5 * m * ((vx * vx + vy * vy) - (ux * ux + uy * uy))


def spin_loss(inertia: float, w: float, u: float) -> float:
    """The rotational energy a disc of moment of inertia ``inertia`` loses going from spin ``w`` to ``u`` (0 for a
    disc that cannot turn, ``inertia`` inf).

    Example:
        >>> spin_loss(0.5, 2.0, 1.0), spin_loss(math.inf, 0.0, 0.0)
        (0.75, 0.0)
    """
    if inertia == INF:
        return 0.0
    return 0.5 * inertia * (w * w - u * u)


def rough_pair(
    dx: float, dy: float, vxi: float, vyi: float, vxj: float, vyj: float, uxi: float, uyi: float, uxj: float,
    uyj: float, wi: float, wj: float, ri: float, rj: float, mi: float, mj: float, ii: float, ij: float, beta: float,
) -> tuple[float, float, float, float, float, float]:  # fmt: skip
    """A pair response with roughness ``beta``: velocities ``u`` after the normal impulse (from ``v``, along the line
    of centres ``(dx, dy)``, ``j - i``), then the tangential impulse of
    :func:`~discsim.physics.laws.rough_impulse` at the contact point (arms ``ri``, ``rj``: the radii), as the
    event-driven loop adds it.

    Returns:
        ``(uxi, uyi, uxj, uyj, wi, wj)``: the velocities and spins after.

    Example:
        >>> rough_pair(2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 3.0, 1.0, 1.0, 1.0, 1.0, 0.5, 0.5, 1.0)
        (0.0, -1.0, 1.0, 1.0, -2.0, 1.0)
    """
    txi, tyi, txj, tyj, wi, wj = rough_impulse(dx, dy, vxi, vyi, vxj, vyj, wi, wj, ri, rj, mi, mj, ii, ij, beta)
    return uxi + (txi - vxi), uyi + (tyi - vyi), uxj + (txj - vxj), uyj + (tyj - vyj), wi, wj


def _rough_bounce(
    cx: float, cy: float, vx: float, vy: float, ux: float, uy: float, w: float, r: float, m: float, inertia: float,
    beta: float,
) -> tuple[float, float, float]:  # fmt: skip
    """A bounce's tangential impulse (roughness ``beta``) against an infinite mass that does not turn, the contact
    point towards ``(cx, cy)`` from the centre, ``r`` away; ``v`` the velocity before the normal bounce, ``u``
    after. Returns ``(ux, uy, w)`` after both."""
    tx, ty, _, _, w, _ = rough_impulse(cx, cy, vx, vy, 0.0, 0.0, w, 0.0, r, 0.0, m, INF, inertia, INF, beta)
    return ux + (tx - vx), uy + (ty - vy), w


def wall_bounce(
    vx: float, vy: float, axis: int, low: bool, e: float, w: float, r: float, m: float, inertia: float, beta: float
) -> tuple[float, float, float]:
    """A bounce off the wall ``axis`` (0: at x = const) on the ``low`` side (at 0) or the high one:
    :func:`~discsim.physics.laws.reflect` with restitution ``e``, then, for rough discs (``beta`` above -1), the
    tangential impulse at the contact point (the wall as rough as the discs, as in the event-driven engine).

    Returns:
        ``(vx, vy, w)``: the velocity and spin after.

    Example:
        >>> wall_bounce(1.0, -1.0, 1, True, 1.0, 0.0, 1.0, 1.0, 0.5, 1.0)  # onto the floor at 45 degrees
        (0.33333333333333337, 1.0, -1.3333333333333333)
    """
    ux, uy = reflect(vx, vy, axis, e)
    if beta != -1.0:
        c = -1.0 if low else 1.0
        if axis == 0:
            ux, uy, w = _rough_bounce(c, 0.0, vx, vy, ux, uy, w, r, m, inertia, beta)
        else:
            ux, uy, w = _rough_bounce(0.0, c, vx, vy, ux, uy, w, r, m, inertia, beta)
    return ux, uy, w


def segment_bounce(
    x: float, y: float, vx: float, vy: float, ax: float, ay: float, bx: float, by: float, e: float, w: float,
    r: float, m: float, inertia: float, beta: float,
) -> tuple[float, float, float]:  # fmt: skip
    """A bounce of a disc at ``(x, y)`` off segment ``a``-``b``: :func:`~discsim.physics.laws.reflect_off_segment`
    with restitution ``e``, then, for rough discs (``beta`` above -1), the tangential impulse at the contact point
    (towards the segment's nearest point).

    Returns:
        ``(vx, vy, w)``: the velocity and spin after.

    Example:
        >>> segment_bounce(0.0, 0.5, 1.0, -1.0, -3.0, 0.0, 3.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.5, 1.0)
        (0.33333333333333337, 1.0, -1.3333333333333333)
    """
    ux, uy = reflect_off_segment(x, y, vx, vy, ax, ay, bx, by, e)
    if beta != -1.0:
        qx, qy = closest_point_on_segment(x, y, ax, ay, bx, by)
        ux, uy, w = _rough_bounce(qx - x, qy - y, vx, vy, ux, uy, w, r, m, inertia, beta)
    return ux, uy, w


def moving_segment_bounce(
    x: float, y: float, vx: float, vy: float, ax: float, ay: float, bx: float, by: float, fx: float, fy: float,
    e: float, w: float, r: float, m: float, inertia: float, beta: float,
) -> tuple[float, float, float]:  # fmt: skip
    """A bounce of a disc at ``(x, y)`` off segment ``a``-``b`` (where it is at the frame) moving at ``(fx, fy)``
    (length / time): :func:`segment_bounce` of the velocity relative to the segment, the segment's velocity added
    back, as the event-driven loop bounces a disc in a moving segment's frame; a fixed segment's is
    :func:`segment_bounce`'s, to the bit.

    Returns:
        ``(vx, vy, w)``: the velocity and spin after.

    Example:
        >>> moving_segment_bounce(0.0, 0.5, 0.0, 0.0, -3.0, 0.0, 3.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.5, 1.0, 0.5, -1.0)
        (0.0, 2.0, 0.0)
    """
    if fx == 0.0 and fy == 0.0:
        return segment_bounce(x, y, vx, vy, ax, ay, bx, by, e, w, r, m, inertia, beta)
    ux, uy, w = segment_bounce(x, y, vx - fx, vy - fy, ax, ay, bx, by, e, w, r, m, inertia, beta)
    return ux + fx, uy + fy, w
