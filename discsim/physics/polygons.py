"""Rotating convex polygons: the certified first contact of two of them, and of one with a fixed line (issue 33).

A polygon body is its vertices in its own frame, ``vertices`` ((K, 2) float array, counter-clockwise, convex,
about its centre), its centre ``(cx, cy)``, angle ``theta`` (rad), velocity ``(vx, vy)`` and spin ``w``
(rad / time), all at time 0. Under constant velocity and spin its vertex ``k`` is at
``c + v t + R(theta + w t) p_k`` at time ``t`` (:func:`world_vertices`).

Two disjoint convex polygons first touch with a vertex of one on an edge of the other. Their distance ``D(t)``
(the least distance of a vertex of one to an edge of the other, :func:`polygon_distance`) is Lipschitz in time
with the constant ``L = |vB - vA| + |wA| rA + |wB| rB`` (``r``: a polygon's circumradius about its centre):
every point of a body moves at most at ``|v| + |w| r``, so each point-to-point distance changes at most at
``L``, and a minimum of functions that change at most at ``L`` does too. So no contact lies before
``t + D(t) / L``: conservative advancement (Mirtich 1996) steps there (less the roundoff of ``D``), never past
the first contact, and closes in on it geometrically, until the polygons are within roundoff of touching
(``D <=`` :data:`ROUNDOFF` times the size of the problem). From there a probe, doubling its step, looks for a
time they overlap (separating-axis gap ``<= 0``, :func:`polygon_separation`), and the sign change of the gap
is bisected to two adjacent floats: the time returned is the first float at which the computed gap is
``<= 0`` (or, if no overlap follows, a graze within roundoff, the time the advancement stopped). No contact
is missed: every time before the advancement's last stop is certified clear. The bisection's bracket spans
about twice the roundoff of ``D`` divided by the approach speed. :func:`polygon_wall_time` advances a polygon
against a fixed line likewise, with ``L = |n . v| + |w| r``; its gap (the least signed distance of a vertex to
the line) has a sign, so the advancement alone stops at its sign change, or within an ulp of it.

Where two edges are parallel when they touch (edge on edge, physically a segment of contact) the contact point
returned is the midpoint of the segment the two edges share (:func:`polygon_contact`).

Every function but :func:`world_vertices` and :func:`check_polygon` uses only arithmetic, comparisons, indexing
of the vertex arrays and :mod:`math`, so numba compiles it from this source: compile :data:`PARTS` in their
order (callees first), e.g. ``compile_from_source(PARTS, jit)``. They trust their input; :func:`check_polygon`
is the check at the boundary.

Example:
    >>> import numpy as np
    >>> square = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    >>> polygon_time_of_impact(square, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, square, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 10.0)
    (2.0, 2.5, 0.0, 1.0, 0.0)
"""

from __future__ import annotations

import math

import numpy as np

from discsim.errors import InvalidArgumentError

__all__ = [
    "EDGE_TOLERANCE",
    "PARTS",
    "check_polygon",
    "circumradius",
    "polygon_contact",
    "polygon_distance",
    "polygon_separation",
    "polygon_time_of_impact",
    "polygon_wall_time",
    "world_vertices",
]

INF = math.inf
NAN = math.nan
#: Two edges touch edge on edge when both ends of one are within this fraction of ``rA + rB`` of the other's
#: line (:func:`polygon_contact`).
EDGE_TOLERANCE = 1e-9
#: Conservative advancement gives up after this many steps (a near miss within roundoff of touching, met at an
#: angle of roundoff) and returns its time so far: early, never late.
MAX_STEPS = 1_000_000
#: The distance of two polygons is computed to within this many ulp of the size of the problem (the distance
#: of the centres plus both circumradii): at most that, they touch within roundoff.
ROUNDOFF = 16.0 * 2.0**-52
#: How many times the probe for an overlap after the advancement doubles its step (from the roundoff's
#: reach), before the time it stopped at is taken as the contact (a graze within roundoff).
PROBES = 64


def world_vertices(vertices, cx, cy, theta, vx=0.0, vy=0.0, w=0.0, t=0.0):
    """The vertices at time ``t`` in the world frame, ``c + v t + R(theta + w t) p_k`` ((K, 2) float array).

    Example:
        >>> world_vertices(np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]]), 2.0, 0.0, 0.0, t=0.0).tolist()
        [[3.0, 0.0], [2.0, 1.0], [1.0, 0.0]]
    """
    p = np.asarray(vertices, dtype=float)
    c, s = math.cos(theta + w * t), math.sin(theta + w * t)
    x = cx + vx * t + c * p[:, 0] - s * p[:, 1]
    y = cy + vy * t + s * p[:, 0] + c * p[:, 1]
    return np.stack([x, y], axis=1)


def check_polygon(vertices, name: str = "vertices") -> np.ndarray:
    """``vertices`` as a (K, 2) float array, or an :class:`~discsim.errors.InvalidArgumentError` naming ``name``
    and what is wrong: not (K, 2) with K >= 3, not finite, not counter-clockwise and strictly convex (every
    turn left, by more than roundoff), or a circumradius of 0."""
    p = np.asarray(vertices, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 3:
        msg = f"{name} must be a (K, 2) array with K >= 3, got shape {p.shape}"
        raise InvalidArgumentError(msg)
    if not np.all(np.isfinite(p)):
        msg = f"{name} must be finite, got {p.tolist()}"
        raise InvalidArgumentError(msg)
    e = np.roll(p, -1, axis=0) - p
    turns = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
    scale = float(np.max(np.sum(e * e, axis=1)))
    bad = np.flatnonzero(turns <= 1e-12 * scale)
    if scale == 0.0 or bad.size:
        k = int((bad[0] + 1) % len(p)) if bad.size else 0
        msg = (
            f"{name} must be a strictly convex polygon listed counter-clockwise; vertex {k} "
            f"({p[k].tolist()}) turns {'right or not at all' if bad.size else 'nowhere'}"
        )
        raise InvalidArgumentError(msg)
    return p


def circumradius(vertices) -> float:
    """The largest distance of a vertex from the body's centre (its own origin) (length).

    Example:
        >>> circumradius(np.array([[3.0, 4.0], [-1.0, 0.0], [0.0, -1.0]]))
        5.0
    """
    r2 = 0.0
    for k in range(vertices.shape[0]):
        r2 = max(r2, vertices[k, 0] * vertices[k, 0] + vertices[k, 1] * vertices[k, 1])
    return math.sqrt(r2)


def _point_segment(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    """Squared distance of point ``p`` to the segment ``a b``."""
    ex, ey = bx - ax, by - ay
    dx, dy = px - ax, py - ay
    u = (dx * ex + dy * ey) / (ex * ex + ey * ey)
    u = 0.0 if u <= 0.0 else (1.0 if u >= 1.0 else u)
    dx, dy = dx - u * ex, dy - u * ey
    return dx * dx + dy * dy


def polygon_distance(va, cax: float, cay: float, ta: float, vb, cbx: float, cby: float, tb: float):
    """The distance of two disjoint convex polygons posed at centres ``ca``, ``cb`` and angles ``ta``, ``tb``,
    and where it is: ``(distance, side, i, j)``, vertex ``i`` of A on edge ``j`` (from vertex ``j`` to
    ``j + 1``) of B when ``side == 0``, vertex ``i`` of B on edge ``j`` of A when ``side == 1``; the first
    such pair in that order on a tie. Computed in B's frame (rotating A by ``ta - tb``), where B's vertices
    are its own. Not meaningful for overlapping polygons (see :func:`polygon_separation`).

    Example:
        >>> sq = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
        >>> polygon_distance(sq, 0.0, 0.0, 0.0, sq, 3.0, 0.0, 0.0)
        (2.0, 0, 1, 0)
    """
    c, s = math.cos(ta - tb), math.sin(ta - tb)
    cb, sb = math.cos(tb), math.sin(tb)
    ox, oy = cb * (cax - cbx) + sb * (cay - cby), cb * (cay - cby) - sb * (cax - cbx)
    na, nb = va.shape[0], vb.shape[0]
    best, side, bi, bj = INF, 0, 0, 0
    for i in range(na):
        px, py = ox + c * va[i, 0] - s * va[i, 1], oy + s * va[i, 0] + c * va[i, 1]
        for j in range(nb):
            k = j + 1 if j + 1 < nb else 0
            d2 = _point_segment(px, py, vb[j, 0], vb[j, 1], vb[k, 0], vb[k, 1])
            if d2 < best:
                best, side, bi, bj = d2, 0, i, j
    for j in range(na):
        k = j + 1 if j + 1 < na else 0
        ax, ay = ox + c * va[j, 0] - s * va[j, 1], oy + s * va[j, 0] + c * va[j, 1]
        bx, by = ox + c * va[k, 0] - s * va[k, 1], oy + s * va[k, 0] + c * va[k, 1]
        for i in range(nb):
            d2 = _point_segment(vb[i, 0], vb[i, 1], ax, ay, bx, by)
            if d2 < best:
                best, side, bi, bj = d2, 1, i, j
    return math.sqrt(float(best)), side, bi, bj


def _edge_gap(vp, ox: float, oy: float, c: float, s: float, ve):
    """The largest gap, over the edges of ``ve`` (own frame), between an edge's line and the nearest vertex of
    ``vp`` (placed in ``ve``'s frame by the rotation ``(c, s)`` and the offset ``o``), signed outward:
    ``(gap, j, i)``, edge ``j`` of ``ve`` and vertex ``i`` of ``vp`` (the first on a tie)."""
    gap, bj, bi = -INF, 0, 0
    ne, nv = ve.shape[0], vp.shape[0]
    for j in range(ne):
        k = j + 1 if j + 1 < ne else 0
        ex, ey = ve[k, 0] - ve[j, 0], ve[k, 1] - ve[j, 1]
        norm = math.sqrt(ex * ex + ey * ey)
        nx, ny = ey / norm, -ex / norm  # outward for a counter-clockwise polygon
        least, at = INF, 0
        for i in range(nv):
            px, py = ox + c * vp[i, 0] - s * vp[i, 1], oy + s * vp[i, 0] + c * vp[i, 1]
            h = nx * (px - ve[j, 0]) + ny * (py - ve[j, 1])
            if h < least:
                least, at = h, i
        if least > gap:
            gap, bj, bi = least, j, at
    return gap, bj, bi


def _separating_edge(va, cax: float, cay: float, ta: float, vb, cbx: float, cby: float, tb: float):
    """The separating-axis gap of two posed polygons and the edge that gives it: ``(gap, side, j, i)``, edge
    ``j`` of B and vertex ``i`` of A when ``side == 0`` (B's edges win a tie), edge ``j`` of A and vertex ``i``
    of B when ``side == 1``."""
    cb, sb = math.cos(tb), math.sin(tb)
    ox, oy = cb * (cax - cbx) + sb * (cay - cby), cb * (cay - cby) - sb * (cax - cbx)
    c, s = math.cos(ta - tb), math.sin(ta - tb)
    gap_b, jb, ib = _edge_gap(va, ox, oy, c, s, vb)
    ca, sa = math.cos(ta), math.sin(ta)
    ox, oy = ca * (cbx - cax) + sa * (cby - cay), ca * (cby - cay) - sa * (cbx - cax)
    gap_a, ja, ia = _edge_gap(vb, ox, oy, c, -s, va)
    if gap_a > gap_b:
        return float(gap_a), 1, ja, ia
    return float(gap_b), 0, jb, ib


def polygon_separation(va, cax: float, cay: float, ta: float, vb, cbx: float, cby: float, tb: float) -> float:
    """The separating-axis gap of two posed convex polygons: the largest, over the edges of both, of the
    distance from the edge's line to the other polygon (signed, outward). Positive when they are apart (at most
    their distance), 0 when they touch, negative when they overlap (minus the least push along an edge normal
    that parts them).

    Example:
        >>> sq = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
        >>> polygon_separation(sq, 0.0, 0.0, 0.0, sq, 0.75, 0.0, 0.0)
        -0.25
    """
    return _separating_edge(va, cax, cay, ta, vb, cbx, cby, tb)[0]


def polygon_contact(va, cax: float, cay: float, ta: float, vb, cbx: float, cby: float, tb: float):
    """Where two posed polygons touch (or nearly): ``(px, py, nx, ny)``, the contact point and the unit normal
    from A to B (world frame).

    The normal is that of the separating edge (the edge whose line is farthest from the other polygon,
    :func:`polygon_separation`; at a vertex-on-edge contact, the only edge with a gap of 0), and the point the
    other polygon's vertex nearest that line (the first in order on a tie). Edge on edge (that vertex and one
    of its neighbours both within ``EDGE_TOLERANCE (rA + rB)`` of the edge's line): the midpoint of the segment
    the two edges share, on the edge's line. The rule is deterministic (the same poses give the same point)
    and symmetric along the shared segment.

    Example:
        >>> sq = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
        >>> polygon_contact(sq, 0.0, 0.0, 0.0, sq, 1.0, 0.25, 0.0)  # right side on left side, offset 0.25
        (0.5, 0.125, 1.0, 0.0)
    """
    _, side, j, i = _separating_edge(va, cax, cay, ta, vb, cbx, cby, tb)
    if side == 0:  # edge j of B (e), vertex i of A (p)
        vp, pcx, pcy, tp, ve, ecx, ecy, te, sign = va, cax, cay, ta, vb, cbx, cby, tb, -1.0
    else:
        vp, pcx, pcy, tp, ve, ecx, ecy, te, sign = vb, cbx, cby, tb, va, cax, cay, ta, 1.0
    tol = EDGE_TOLERANCE * (circumradius(va) + circumradius(vb))
    ec, es = math.cos(te), math.sin(te)
    pc, ps = math.cos(tp), math.sin(tp)
    ne = ve.shape[0]
    k = j + 1 if j + 1 < ne else 0
    ax = ecx + ec * ve[j, 0] - es * ve[j, 1]
    ay = ecy + es * ve[j, 0] + ec * ve[j, 1]
    bx = ecx + ec * ve[k, 0] - es * ve[k, 1]
    by = ecy + es * ve[k, 0] + ec * ve[k, 1]
    ex, ey = bx - ax, by - ay
    length = math.sqrt(ex * ex + ey * ey)
    ux, uy = ex / length, ey / length
    nx, ny = uy, -ux  # outward from the polygon that owns the edge
    nv = vp.shape[0]
    px = pcx + pc * vp[i, 0] - ps * vp[i, 1]
    py = pcy + ps * vp[i, 0] + pc * vp[i, 1]
    for m in (i - 1 if i > 0 else nv - 1, i + 1 if i + 1 < nv else 0):  # the vertex's neighbours, in order
        qx = pcx + pc * vp[m, 0] - ps * vp[m, 1]
        qy = pcy + ps * vp[m, 0] + pc * vp[m, 1]
        if abs(nx * (qx - ax) + ny * (qy - ay)) <= tol and abs(nx * (px - ax) + ny * (py - ay)) <= tol:
            s1, s2 = ux * (px - ax) + uy * (py - ay), ux * (qx - ax) + uy * (qy - ay)
            lo = max(0.0, min(s1, s2))
            hi = min(length, max(s1, s2))
            mid = 0.5 * (lo + hi)
            return float(ax + mid * ux), float(ay + mid * uy), float(sign * nx), float(sign * ny)
    return float(px), float(py), float(sign * nx), float(sign * ny)


def polygon_time_of_impact(
    va,
    cax: float,
    cay: float,
    ta: float,
    vax: float,
    vay: float,
    wa: float,
    vb,
    cbx: float,
    cby: float,
    tb: float,
    vbx: float,
    vby: float,
    wb: float,
    horizon: float,
):
    """The first time in ``[0, horizon]`` at which polygons A and B touch, and where: ``(t, px, py, nx, ny)``,
    the contact point and the unit normal from A to B at ``t`` (:func:`polygon_contact`), or
    ``(inf, nan, nan, nan, nan)`` if they do not touch by ``horizon``.

    Certified never to miss a contact: the distance ``D(t)`` of the two (:func:`polygon_distance`) changes
    at most at ``L = |vB - vA| + |wA| rA + |wB| rB`` (each point of a body moves at most at ``|v| + |w| r``),
    so no contact lies in ``[t, t + D(t) / L)``, and conservative advancement steps there; its times rise to
    the first contact (or pass ``horizon``: ``inf``) and never beyond it. Within roundoff of touching it
    stops, and the sign change of the separating-axis gap just after is bisected to adjacent floats (see the
    module's notes). Near a contact the steps shrink by about ``1 - (approach speed) / L`` each: a fast spin
    past a slow approach takes more steps (about 100 for random pairs turning up to 3 turns per unit time), a
    near graze the most (at most :data:`MAX_STEPS`, then the time reached: early, never late).
    Polygons that overlap or touch at time 0 (:func:`polygon_separation` ``<= 0``) give ``t = 0``.

    Args:
        va, vb ((K, 2) float arrays): the vertices in each body's frame, counter-clockwise, convex.
        cax, cay, cbx, cby: the centres at time 0 (length).
        ta, tb: the angles at time 0 (rad).
        vax, vay, vbx, vby: the velocities (length / time).
        wa, wb: the spins (rad / time).
        horizon: the latest time of interest (time, ``>= 0``).

    Example:
        >>> sq = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
        >>> t, px, py, nx, ny = polygon_time_of_impact(sq, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ...                                            sq, 1.2, 0.0, 0.0, 0.0, 0.0, 0.0, 5.0)
        >>> exact = math.pi / 4 - math.acos(0.7 / math.sqrt(0.5))  # A's corner reaches x = 0.7
        >>> abs(t - exact) < 1e-15, round(px, 12), (nx, ny)
        (True, 0.7, (1.0, 0.0))
    """
    if polygon_separation(va, cax, cay, ta, vb, cbx, cby, tb) <= 0.0:
        px, py, nx, ny = polygon_contact(va, cax, cay, ta, vb, cbx, cby, tb)
        return 0.0, px, py, nx, ny
    ra, rb = circumradius(va), circumradius(vb)
    dvx, dvy = vbx - vax, vby - vay
    bound = math.sqrt(dvx * dvx + dvy * dvy) + abs(wa) * ra + abs(wb) * rb
    if bound == 0.0:
        return INF, NAN, NAN, NAN, NAN
    t = 0.0
    tol = 0.0
    for _ in range(MAX_STEPS):
        ox, oy = cbx - cax + dvx * t, cby - cay + dvy * t
        tol = ROUNDOFF * (math.sqrt(ox * ox + oy * oy) + ra + rb)
        d = polygon_distance(
            va, cax + vax * t, cay + vay * t, ta + wa * t, vb, cbx + vbx * t, cby + vby * t, tb + wb * t
        )[0]
        if d <= tol:  # touching within roundoff
            break
        after = t + (d - tol) / bound  # the distance is at least d - tol
        if after > horizon:
            return INF, NAN, NAN, NAN, NAN
        if after == t:  # a step below half an ulp of t
            break
        t = float(after)
    # Refine: probe ahead, doubling, for a time they overlap, then bisect the sign change of the gap.
    lo, hi, step = t, -1.0, tol / bound
    for _ in range(PROBES):
        probe = min(t + step, horizon)
        if polygon_separation(va, cax + vax * probe, cay + vay * probe, ta + wa * probe,
                              vb, cbx + vbx * probe, cby + vby * probe, tb + wb * probe) <= 0.0:  # fmt: skip
            hi = probe
            break
        if probe == horizon:
            break
        step += step
    while hi > lo:
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            lo = hi
            break
        if polygon_separation(va, cax + vax * mid, cay + vay * mid, ta + wa * mid,
                              vb, cbx + vbx * mid, cby + vby * mid, tb + wb * mid) <= 0.0:  # fmt: skip
            hi = mid
        else:
            lo = mid
    t = float(lo)
    px, py, nx, ny = polygon_contact(
        va, cax + vax * t, cay + vay * t, ta + wa * t, vb, cbx + vbx * t, cby + vby * t, tb + wb * t
    )
    return t, px, py, nx, ny


def _line_gap(v, cx: float, cy: float, theta: float, qx: float, qy: float, nx: float, ny: float):
    """The least signed distance of a posed polygon's vertices to the line through ``q`` with unit normal
    ``n``, and the vertex: ``(gap, k)``, the first on a tie."""
    c, s = math.cos(theta), math.sin(theta)
    base = nx * (cx - qx) + ny * (cy - qy)
    least, at = INF, 0
    for k in range(v.shape[0]):
        h = base + nx * (c * v[k, 0] - s * v[k, 1]) + ny * (s * v[k, 0] + c * v[k, 1])
        if h < least:
            least, at = h, k
    return least, at


def polygon_wall_time(
    v,
    cx: float,
    cy: float,
    theta: float,
    vx: float,
    vy: float,
    w: float,
    qx: float,
    qy: float,
    nx: float,
    ny: float,
    horizon: float,
):
    """The first time in ``[0, horizon]`` at which a polygon touches the fixed line through ``q`` with unit
    normal ``n`` (pointing to the polygon's side: a box wall, a segment's line), and where:
    ``(t, px, py, nx, ny)``, the contact point and the line's normal ``n``, or ``(inf, nan, nan, nan, nan)``.

    Certified as :func:`polygon_time_of_impact` is: the gap ``min_k n . (x_k(t) - q)`` changes at most at
    ``L = |n . v| + |w| r``, so conservative advancement steps by ``gap / L`` and never passes the first
    contact. The point is the lowest vertex; where an edge lies flat on the line (its two ends within
    ``EDGE_TOLERANCE r`` of it), the edge's midpoint. A polygon on or across the line at time 0 gives ``t = 0``.

    Args:
        v ((K, 2) float array): the vertices in the body's frame, counter-clockwise, convex.
        cx, cy, theta, vx, vy, w: the centre, angle (rad), velocity and spin (rad / time) at time 0.
        qx, qy: a point of the line (length). nx, ny: its unit normal, towards the polygon.
        horizon: the latest time of interest (time).

    Example:
        >>> sq = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
        >>> polygon_wall_time(sq, 0.0, 2.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 9.0)  # falls flat
        (1.5, 0.0, 0.0, 0.0, 1.0)
    """
    bound = abs(nx * vx + ny * vy) + abs(w) * circumradius(v)
    t = 0.0
    for _ in range(MAX_STEPS):
        gap = _line_gap(v, cx + vx * t, cy + vy * t, theta + w * t, qx, qy, nx, ny)[0]
        if gap <= 0.0:
            break
        if bound == 0.0:
            return INF, NAN, NAN, NAN, NAN
        after = t + gap / bound
        if after > horizon:
            return INF, NAN, NAN, NAN, NAN
        if after == t:
            break
        t = float(after)
    x, y, angle = cx + vx * t, cy + vy * t, theta + w * t
    k = _line_gap(v, x, y, angle, qx, qy, nx, ny)[1]
    c, s = math.cos(angle), math.sin(angle)
    px, py = x + c * v[k, 0] - s * v[k, 1], y + s * v[k, 0] + c * v[k, 1]
    tol = EDGE_TOLERANCE * circumradius(v)
    n = v.shape[0]
    for m in (k - 1 if k > 0 else n - 1, k + 1 if k + 1 < n else 0):
        mx, my = x + c * v[m, 0] - s * v[m, 1], y + s * v[m, 0] + c * v[m, 1]
        if abs(nx * (mx - px) + ny * (my - py)) <= tol:
            return t, float(0.5 * (px + mx)), float(0.5 * (py + my)), nx, ny
    return t, float(px), float(py), nx, ny


#: The functions to compile, callees first.
PARTS = (
    circumradius,
    _point_segment,
    polygon_distance,
    _edge_gap,
    _separating_edge,
    polygon_separation,
    polygon_contact,
    polygon_time_of_impact,
    _line_gap,
    polygon_wall_time,
)
