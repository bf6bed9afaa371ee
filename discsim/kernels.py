"""The pure float kernels under their first names: time of impact, elastic response, walls and segments.

Each is defined once, in :mod:`discsim.physics` (the law of motion in :mod:`~discsim.physics.dynamics`, the
collision law in :mod:`~discsim.physics.laws`); this module keeps the names the tests, the oracle and the
benchmarks have always used, and the generic :func:`time_of_impact_bisect` of the fixed-step policies.

Example:
    >>> time_of_impact(4.0, 0.0, -1.0, 0.0, 2.0), time_of_impact(4.0, 0.0, 1.0, 0.0, 2.0)
    (2.0, inf)
    >>> resolve_collision(2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0)
    (0.0, 0.0, 1.0, 0.0)
"""

from __future__ import annotations

import math

from discsim.errors import InvalidArgumentError
from discsim.physics.dynamics import pair_time_of_impact as time_of_impact
from discsim.physics.dynamics import segment_time_of_impact
from discsim.physics.laws import closest_point_on_segment, reflect_off_segment
from discsim.physics.laws import collide as resolve_collision
from discsim.physics.sources.boundaries import wall_time

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
