"""Kinematic walls that crush a disc: a moving segment or a kinematic lid closing on it against another wall.

A kinematic wall moves at its velocity whatever hits it. A disc caught between it and a wall facing it is hit
faster and faster as the gap closes (its speed grows by twice the closing speed at each return), while the clock
creeps towards the instant the gap reaches the disc's diameter: infinitely many bounces come before that instant,
so no run can pass it, and the jam guard, which watches for a clock standing still, never fires (the clock moves;
it only converges). This module finds such a crush before the run spends for ever on it:

- :func:`lid_crush`: a kinematic lid moving down crushes the discs at the latest when it is lower than the largest
  disc's diameter, or when the area under it is less than the discs' own area (whatever they do: it spans the box;
  not when some discs pass through others, which then need no room of their own).
- :func:`squeeze`: one disc between a kinematic wall and a wall or segment facing it (parallel), which stays
  between their ends until the gap closes, with no third wall, segment or disc it could reach before then (on the
  other discs' present speeds): a crush that nothing but the user (steering the wall) can prevent.

Both return the crush's time from now and what it crushes, for the engine's :class:`~discsim.errors.JammedError`
(``RunStops._check_squeeze`` asks once per half a jam threshold of events; not in a periodic box, where the
walls' images would need minimum images along their spans).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from discsim.model import Box, Segment

__all__ = ["Crush", "lid_crush", "squeeze"]

INF = math.inf


class Crush(NamedTuple):
    """A crush ``after`` (time from now); ``what``: a clause that names the walls and the disc they crush."""

    after: float
    what: str


class _Wall(NamedTuple):
    name: str
    q: np.ndarray  # a point of its line now
    e: np.ndarray  # unit tangent
    lo: float  # its extent along e from q (-inf, inf: a box wall spans its side)
    hi: float
    w: np.ndarray  # velocity
    kinematic: bool  # moves whatever hits it


def lid_crush(radii: np.ndarray, width: float, height: float, velocity: float, apart: bool = True) -> Crush | None:
    """When a kinematic lid at ``height`` moving at ``velocity`` (down: < 0) over discs of ``radii`` in a box of
    ``width`` crushes them for certain: once it is below the largest diameter, or (when the discs keep ``apart``:
    no collision filter lets some pass through others) the area under it is below the discs' area. None when it
    does not move down or there are no discs."""
    if velocity >= 0.0 or not len(radii):
        return None
    k = int(np.argmax(radii))
    diameter = 2.0 * float(radii[k])
    packed = float(np.sum(np.pi * radii**2)) / width if apart else 0.0
    if diameter >= packed:
        lowest, what = diameter, f"disc {k} (its diameter {diameter!r})"
    else:
        lowest, what = packed, f"the discs (their area {packed * width!r} over the box's width {width!r})"
    return Crush(
        max(0.0, (height - lowest) / -velocity), f"the kinematic lid reaches height {lowest!r} and crushes {what}"
    )


def _walls(box: Box, segments: list[Segment], lid: tuple[float, float] | None) -> list[_Wall]:
    """The box's walls (none when periodic; the lid, if any, as the top), then the segments, where they are now."""
    zero, walls = np.zeros(2), []
    x, y = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    if not box.periodic:
        walls += [
            _Wall("the box's left wall", zero, y, -INF, INF, zero, False),
            _Wall("the box's right wall", np.array([box.width, 0.0]), y, -INF, INF, zero, False),
            _Wall("the box's floor", zero, x, -INF, INF, zero, False),
        ]
        if lid is None:
            walls.append(_Wall("the box's top wall", np.array([0.0, box.height]), x, -INF, INF, zero, False))
        else:
            walls.append(
                _Wall("the kinematic lid", np.array([0.0, lid[0]]), x, -INF, INF, np.array([0.0, lid[1]]), True)
            )
    for k, segment in enumerate(segments):
        e = segment.p1 - segment.p0
        length = float(np.hypot(*e))
        walls.append(_Wall(f"segments[{k}]", segment.p0, e / length, 0.0, length, segment.velocity, segment.moving))
    return walls


def _extent(start: float, speed: float, accel: float, span: float) -> tuple[float, float]:
    """The least and greatest of ``start + speed s + accel s^2 / 2`` over ``s`` in ``[0, span]``."""
    ends = [start, start + speed * span + 0.5 * accel * span * span]
    if accel != 0.0 and 0.0 < -speed / accel < span:
        s = -speed / accel
        ends.append(start + speed * s + 0.5 * accel * s * s)
    return min(ends), max(ends)


def squeeze(
    box: Box,
    segments: list[Segment],
    lid: tuple[float, float] | None,
    positions: np.ndarray,
    velocities: np.ndarray,
    radii: np.ndarray,
    gravity: tuple[float, float],
    i: int,
    horizon: float,
) -> Crush | None:
    """The earliest certain crush of disc ``i`` within ``horizon`` (time from now), or None.

    ``segments`` are where they are now (``Segment.at(time)``), ``lid`` the kinematic lid's ``(height, velocity)``
    (None without one), ``positions``, ``velocities`` ``(N, 2)`` and ``radii`` ``(N,)`` the discs now, under
    ``gravity`` (no drag, smooth discs: the caller asks only then, since a bounce then keeps the disc's velocity
    along the walls). Certain: disc ``i`` lies between a kinematic wall K and a wall B parallel to it and facing
    it, which close on each other; its centre stays between both ends of each until the gap between their lines
    is its diameter; and no other wall, segment or disc is within what it and they could travel by then (the other
    discs at their present speeds, which a later collision could raise: a disc squeezed this tight has no time
    left for that).
    """
    p, v, r = positions[i], velocities[i], float(radii[i])
    g = np.asarray(gravity, dtype=float)
    walls = _walls(box, segments, lid)
    found: Crush | None = None
    for a, K in enumerate(walls):
        if not K.kinematic:
            continue
        nK = np.array([-K.e[1], K.e[0]])
        dK = float(nK @ (p - K.q))
        nK, dK = (nK, dK) if dK >= 0.0 else (-nK, -dK)
        for b, B in enumerate(walls):
            if b == a:
                continue
            nB = np.array([-B.e[1], B.e[0]])
            dB = float(nB @ (p - B.q))
            nB, dB = (nB, dB) if dB >= 0.0 else (-nB, -dB)
            closing = float(nK @ K.w + nB @ B.w)
            if float(nK @ nB) > -1.0 + 1e-12 or closing <= 0.0 or dK + dB < 2.0 * r:
                continue
            after = (dK + dB - 2.0 * r) / closing
            if after > horizon or (found is not None and after >= found.after):
                continue
            if not _stays_between(p, v, g, K, after) or not _stays_between(p, v, g, B, after):
                continue
            # Disc i's centre stays in the rectangle between the two lines (as they move) and its path along
            # them: within ``reach`` of the rectangle's centre ``middle``.
            low, high = _extent(0.0, float(K.e @ v), float(K.e @ g), after)
            across = (min(-dK, -dK + float(nK @ K.w) * after), max(dB, dB - float(nB @ B.w) * after))
            middle = p + K.e * (low + high) / 2.0 + nK * sum(across) / 2.0
            reach = float(np.hypot(high - low, across[1] - across[0])) / 2.0
            if _third_wall(middle, r + reach, after, walls, (a, b)):
                continue
            if _other_disc(box, middle, positions, velocities, radii, i, r + reach, g, after):
                continue
            found = Crush(
                after,
                f"{K.name} (kinematic) and {B.name} crush disc {i} (radius {r!r}) between them: they close on "
                f"each other at {closing!r} per unit time, and the gap between them reaches its diameter",
            )
    return found


def _stays_between(p: np.ndarray, v: np.ndarray, g: np.ndarray, wall: _Wall, span: float) -> bool:
    """Whether the disc's centre stays strictly between ``wall``'s ends (along it, in its frame) for ``span``."""
    if wall.lo == -INF:
        return True
    low, high = _extent(float(wall.e @ (p - wall.q)), float(wall.e @ (v - wall.w)), float(wall.e @ g), span)
    margin = 1e-12 * (wall.hi - wall.lo)
    return low > wall.lo + margin and high < wall.hi - margin


def _third_wall(centre: np.ndarray, reach: float, span: float, walls: list[_Wall], pair: tuple[int, int]) -> bool:
    """Whether a wall or segment other than ``pair`` could come within ``reach`` of ``centre`` within ``span``."""
    for c, C in enumerate(walls):
        if c in pair:
            continue
        if C.lo == -INF:
            n = np.array([-C.e[1], C.e[0]])
            distance = abs(float(n @ (centre - C.q)))
        else:
            distance = float(Segment(C.q, C.q + C.e * (C.hi - C.lo)).distance(centre)[0])
        if distance <= reach + float(np.hypot(*C.w)) * span:
            return True
    return False


def _other_disc(box: Box, centre, positions, velocities, radii, i: int, reach: float, g: np.ndarray, span) -> bool:
    """Whether another disc, at its present speed under ``g``, could come within ``reach`` (plus its radius) of
    ``centre`` within ``span``."""
    if len(positions) < 2:
        return False
    gap = np.hypot(*box.minimum_image(positions - centre).T)
    travel = np.hypot(*velocities.T) * span + 0.5 * float(np.hypot(*g)) * span * span
    near = gap <= radii + reach + travel
    near[i] = False
    return bool(near.any())
