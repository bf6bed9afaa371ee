"""Pairs of discs: when two discs meet, and what their collision does.

Example:
    >>> predict(4.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0)  # 4 apart, closing at 1, radii 1
    2.0
"""

from __future__ import annotations

from discsim.model import minimum_image_1d
from discsim.physics.dynamics import advance, pair_time_of_impact
from discsim.physics.laws import collide

__all__ = ["predict", "resolve"]


def predict(
    xj: float, yj: float, vxj: float, vyj: float, dtj: float, rj: float,
    offx: float, offy: float, vxi: float, vyi: float, ri: float,
    axj: float = 0.0, ayj: float = 0.0, dax: float = 0.0, day: float = 0.0, drag: float = 0.0,
) -> float:  # fmt: skip
    """Time from now until disc ``j`` meets disc ``i``, or ``inf``.

    Disc ``j`` was at ``(xj, yj)`` moving at ``(vxj, vyj)`` a time ``dtj`` ago; ``(offx, offy)`` is the image
    shift of its cell minus disc ``i``'s centre now, so that ``j``'s centre now plus the offset is the pair's
    separation. The loops compute the offset once per cell of the 3x3 block.

    Args:
        xj, yj, vxj, vyj: disc ``j`` at its reference time (length, length / time).
        dtj: now minus ``j``'s reference time.
        rj, ri: the radii.
        offx, offy: image shift of ``j``'s cell minus ``i``'s centre now (length).
        vxi, vyi: disc ``i``'s velocity now.
        axj, ayj: disc ``j``'s acceleration (gravity if it falls; default none).
        dax, day: ``j``'s acceleration minus ``i``'s (zero when both fall or neither does).
        drag: the drag ``gamma`` of every disc (1 / time; default none).
    """
    xj, yj, vxj, vyj = advance(xj, yj, vxj, vyj, dtj, axj, ayj, drag)
    return pair_time_of_impact(xj + offx, yj + offy, vxj - vxi, vyj - vyi, ri + rj, dax, day, drag)


def resolve(
    xi: float, yi: float, vxi: float, vyi: float, mi: float,
    xj: float, yj: float, vxj: float, vyj: float, mj: float,
    width: float, height: float, periodic: bool, e: float = 1.0,
) -> tuple[float, float, float, float, float, float]:  # fmt: skip
    """The collision of discs ``i`` and ``j``, both at contact now, with restitution ``e`` (default elastic).

    Returns:
        ``(dx, dy, uxi, uyi, uxj, uyj)``: the line of centres (``j`` minus ``i``, minimum image in a periodic
        box) and the velocities after the collision law (:func:`discsim.physics.laws.collide`).

    Example:
        >>> resolve(0.0, 0.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 1.0, 10.0, 10.0, False)
        (2.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    """
    dx, dy = xj - xi, yj - yi
    if periodic:
        dx = minimum_image_1d(dx, width)
        dy = minimum_image_1d(dy, height)
    uxi, uyi, uxj, uyj = collide(dx, dy, vxi, vyi, vxj, vyj, mi, mj, e)
    return dx, dy, uxi, uyi, uxj, uyj
