"""Walls and cell crossings: where a disc next leaves its cell, or meets the box's wall beyond it.

The cell grid tiles the box, so the box's walls stand at the outer edges of the edge cells: along each axis a
moving disc either crosses its cell's edge (a crossing: the path goes on, only the neighbourhood changes) or,
in an edge cell of a walled box, its rim meets the wall (a wall hit, resolved by the collision law's
:func:`~discsim.physics.laws.reflect`). The time comes from the law of motion
(:func:`~discsim.physics.dynamics.exit_x`, :func:`~discsim.physics.dynamics.exit_y`).

``other`` of a crossing is its direction, ``PLUS_X``, ``MINUS_X``, ``PLUS_Y`` or ``MINUS_Y``; of a wall hit the
axis, 0 for x and 1 for y.

Example:
    >>> t, kind, other = predict_x(5.0, 2.0, 1.0, 4.0, 6.0, 10.0, False, False)
    >>> t, kind == CROSSING, other == PLUS_X
    (0.5, True, True)
    >>> predict_x(5.0, 2.0, 1.0, 4.0, 6.0, 10.0, False, True)[:2] == (2.0, WALL)
    True
"""

from __future__ import annotations

from discsim.events import EventKind
from discsim.physics.dynamics import exit_x, exit_y

__all__ = ["MINUS_X", "MINUS_Y", "PLUS_X", "PLUS_Y", "cross", "predict_x", "predict_y", "wall_time"]

INF = float("inf")
WALL, CROSSING = int(EventKind.WALL), int(EventKind.CROSSING)
#: Directions of a cell crossing.
PLUS_X, MINUS_X, PLUS_Y, MINUS_Y = 0, 1, 2, 3


def predict_x(
    x: float, vx: float, r: float, lo: float, hi: float, width: float, wall_lo: bool, wall_hi: bool, a: float = 0.0,
    drag: float = 0.0,
) -> tuple[float, int, int]:  # fmt: skip
    """The next crossing of the cell's edge ``lo`` or ``hi`` along x, or the wall beyond it.

    Args:
        x, vx: the centre and velocity along x now.
        r: the radius (a wall stops the centre at ``r`` or ``width - r``).
        lo, hi: the cell's edges (length).
        width: the box's width.
        wall_lo, wall_hi: whether a wall stands beyond ``lo`` (``hi``).
        a: the acceleration along x (gravity; default none).
        drag: the drag ``gamma`` (1 / time; default none).

    Returns:
        ``(t, kind, other)``: the time from now (not clamped), ``WALL`` or ``CROSSING`` and its ``other``;
        ``(inf, CROSSING, 0)`` when the disc does not move along x.
    """
    t, side = exit_x(x, vx, r if wall_lo else lo, width - r if wall_hi else hi, a, drag)
    if side > 0:
        return (t, WALL, 0) if wall_hi else (t, CROSSING, PLUS_X)
    if side < 0:
        return (t, WALL, 0) if wall_lo else (t, CROSSING, MINUS_X)
    return INF, CROSSING, 0


def predict_y(
    y: float, vy: float, r: float, lo: float, hi: float, height: float, wall_lo: bool, wall_hi: bool, a: float = 0.0,
    drag: float = 0.0,
) -> tuple[float, int, int]:  # fmt: skip
    """:func:`predict_x` along y (a wall hit's ``other`` is 1)."""
    t, side = exit_y(y, vy, r if wall_lo else lo, height - r if wall_hi else hi, a, drag)
    if side > 0:
        return (t, WALL, 1) if wall_hi else (t, CROSSING, PLUS_Y)
    if side < 0:
        return (t, WALL, 1) if wall_lo else (t, CROSSING, MINUS_Y)
    return INF, CROSSING, 0


def wall_time(x: float, v: float, radius: float, length: float) -> float:
    """Time until a disc at coordinate ``x`` moving at ``v`` touches a wall at 0 or ``length`` (one axis).

    Returns ``math.inf`` when ``v == 0``, and 0 when the disc is already at or past the wall it moves
    towards (the fixed-step policies and the oracle ask this of a box with walls only).

    Example:
        >>> wall_time(5.0, 2.0, 1.0, 10.0)
        2.0
    """
    t, _ = exit_x(x, v, radius, length - radius)
    return max(t, 0.0)


def cross(cx: int, cy: int, direction: int, nx: int, ny: int) -> tuple[int, int, int, int]:
    """The cell a crossing in ``direction`` enters from cell ``(cx, cy)`` of an ``nx`` by ``ny`` grid.

    Returns:
        ``(cx, cy, wrap_x, wrap_y)``: the new cell and the periodic image step taken (-1, 0 or 1 along each
        axis: 1 when the disc left through the high edge of the box and re-enters at the low one, so its stored
        centre moves by minus one box length and its image count by one).

    Example:
        >>> cross(3, 0, PLUS_X, 4, 4)
        (0, 0, 1, 0)
        >>> cross(1, 0, MINUS_Y, 4, 4)
        (1, 3, 0, -1)
    """
    if direction == PLUS_X:
        if cx + 1 == nx:
            return 0, cy, 1, 0
        return cx + 1, cy, 0, 0
    if direction == MINUS_X:
        if cx == 0:
            return nx - 1, cy, -1, 0
        return cx - 1, cy, 0, 0
    if direction == PLUS_Y:
        if cy + 1 == ny:
            return cx, 0, 0, 1
        return cx, cy + 1, 0, 0
    if cy == 0:
        return cx, ny - 1, 0, -1
    return cx, cy - 1, 0, 0
