"""A piston: the top wall of a walled box as a body of mass ``M`` pushed down by a constant force ``F``.

Between impacts the piston falls with the uniform acceleration ``a = F / M`` (its height
``h(s) = h + u s - a s^2 / 2``); a disc under it flies freely, so the gap between the disc's rim and the piston,
``h(s) - r - y(s)``, is a parabola of curvature ``-a`` and its first fall to zero is the time of contact
(:func:`~discsim.physics.sources.sensors.fall_to_zero`, the slab exit of one coordinate). At contact the two
exchange momentum along y, as two discs do along their line of centres (:func:`bounce`). A piston of infinite
mass (``a = 0``) is a kinematic wall that moves at a constant velocity, whatever hits it.

Every impact pushes the piston up (the disc approaches it from below), so its path after an impact lies above the
one predicted before, at every later time: the contacts other discs were predicted to make with it can only come
later. That is what lets the loop keep them and drop each when it comes up, as it drops a collision whose partner
has changed course (the piston's counter, in the event's stamp).

Example:
    >>> contact_time(1.0, 0.0, 0.5, 5.5, 0.0, 2.0)  # the gap 4 closes under a = 2: sqrt(2 * 4 / 2)
    2.0
    >>> bounce(1.0, 1.0, math.inf, -1.0)  # off a wall coming down at 1: back at 3, the wall unmoved
    (-3.0, -1.0)
"""

from __future__ import annotations

import math

from discsim.physics.sources.sensors import fall_to_zero

__all__ = ["PARTS", "at", "bounce", "contact_time"]


def at(h: float, u: float, a: float, s: float) -> tuple[float, float]:
    """The piston's height and velocity ``s`` after it was at height ``h`` moving at ``u`` (``a``: its fall's
    acceleration, ``F / M``)."""
    return h + s * (u - 0.5 * a * s), u - a * s


def contact_time(y: float, vy: float, r: float, h: float, u: float, a: float) -> float:
    """Time from now until a disc (centre height ``y``, velocity ``vy``, radius ``r``, flying freely) touches the
    piston at height ``h`` moving at ``u`` and falling with acceleration ``a``; ``inf`` if never (a kinematic lid
    moving away as fast as the disc); 0 or below when the gap is already closed and closing."""
    return fall_to_zero(h - r - y, u - vy, -a, 0.0)


def bounce(m: float, vy: float, mass: float, u: float) -> tuple[float, float]:
    """The velocities along y of a disc of mass ``m`` and the piston of mass ``mass`` (``inf``: kinematic) after an
    elastic impact, from ``vy`` and ``u`` before: ``(vy', u')``; momentum and energy are kept."""
    if mass == math.inf:
        return 2.0 * u - vy, u
    total = m + mass
    return ((m - mass) * vy + 2.0 * mass * u) / total, ((mass - m) * u + 2.0 * m * vy) / total


#: The parts the compiled loops compile, callees first.
PARTS = (at, contact_time, bounce)
