"""Where a run's piston was (a :class:`discsim.Piston`): its knots, read from the log, and its height at any time.

Between impacts the piston falls along ``h_k + u_k s - a_k s^2 / 2`` (``s = t - t_k``); its state at time 0 is the
scene's :class:`~discsim.Piston`, its state after each impact the log's ``WALL`` record (``yj``, ``vyj``), and its
state now ``sim.piston``. The acceleration ``a = pressure * width / mass`` (plus ``g`` under gravity down along y; 0
for a kinematic lid) holds until ``set_piston`` changes the pressure or the velocity, which the log does not record:
a piece whose path under the acceleration in force does not reach the next knot held a change (as
:func:`discsim.analysis.isobaric.isobaric` detects it), and takes the acceleration that joins its two ends (exact at
both, in between an approximation: the log does not say when the change came); the pieces after it take the new
pressure's (``sim.piston``'s) when it fits, else the one that joins their ends.

Example:
    >>> import discsim as ds
    >>> sim = ds.EventDriven(ds.Discs([[5.0, 1.0]], [[0.0, 0.0]], radii=0.5), ds.Box(10.0, 10.0),
    ...                      piston=ds.Piston(mass=3.0, pressure=0.3, height=5.5)).run(until=2.0)
    >>> path = piston_path(sim)
    >>> path.times.tolist(), path.accel.tolist()  # time 0 and now: not hit yet
    ([0.0, 2.0], [1.0, 1.0])
    >>> float(path.height(1.0))  # 5.5 - 1 * 1 / 2
    5.0
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from discsim.errors import InvalidArgumentError
from discsim.events import WALL

__all__ = ["PistonPath", "piston_path"]


class PistonPath(NamedTuple):
    """A piston's knots: its state at time 0, after each impact and now, and the acceleration of the piece after each.

    Attributes:
        times (np.ndarray): ``(K,)`` the knots' times (time units), increasing.
        heights (np.ndarray): ``(K,)`` the piston's height after each (length).
        velocities (np.ndarray): ``(K,)`` its velocity along y after each (length / time).
        accel (np.ndarray): ``(K,)`` its downward acceleration from each knot to the next (length / time^2; 0 for a
            kinematic lid).
    """

    times: np.ndarray
    heights: np.ndarray
    velocities: np.ndarray
    accel: np.ndarray

    def height(self, times) -> np.ndarray:
        """The piston's height at ``times`` (any shape; before the first knot, from it) as an array of that shape."""
        return self.state(times)[0]

    def span(self, t0: float, t1: float) -> PistonPath:
        """The knots that give the path over ``[t0, t1]``: the last at or before ``t0`` (or the first) to the last at or
        before ``t1``."""
        first = max(0, int(np.searchsorted(self.times, t0, side="right")) - 1)
        last = max(first + 1, int(np.searchsorted(self.times, t1, side="right")))
        return PistonPath(*(knots[first:last] for knots in self))

    def state(self, times) -> tuple[np.ndarray, np.ndarray]:
        """``(heights, velocities)`` of the piston at ``times`` (any shape): from the last knot at or before each."""
        t = np.asarray(times, dtype=float)
        k = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, len(self.times) - 1)
        s, a, u = t - self.times[k], self.accel[k], self.velocities[k]
        return self.heights[k] + s * (u - 0.5 * a * s), u - a * s


def piston_path(sim) -> PistonPath:
    """The knots of the piston of ``sim``, an :class:`~discsim.EventDriven` run with a piston that recorded its log
    (in memory, or streamed with ``run(record_to=...)``, read chunk by chunk): its state at time 0 (the scene's
    :class:`~discsim.Piston`), after every impact in the log, and at ``sim.time`` (``sim.piston``).

    Raises:
        InvalidArgumentError: if ``sim`` has no piston, or recorded no log.
    """
    from discsim.analysis.frames import _log_source

    given = getattr(getattr(sim, "scene", None), "piston", None)
    if given is None:
        msg = "piston_path() needs a run with a piston (EventDriven(..., piston=ds.Piston(...)))"
        raise InvalidArgumentError(msg)
    chunks = _log_source(sim, "piston_path()")[0]
    hits = [r[(r["kind"] == WALL) & np.isfinite(r["yj"])] for r in chunks()]
    now, width = float(sim.time), float(sim.box.width)
    start = sim.box.height if given.height is None else given.height
    times = np.concatenate([[0.0], *(h["time"] for h in hits)])
    heights = np.concatenate([[start], *(h["yj"] for h in hits)])
    velocities = np.concatenate([[given.velocity], *(h["vyj"] for h in hits)])
    piston = sim.piston
    if now > times[-1]:
        times, heights = np.append(times, now), np.append(heights, piston.height)
        velocities = np.append(velocities, piston.velocity)
    gravity = getattr(getattr(sim, "laws", None), "gravity", None)  # down along y: the piston's weight
    fall = 0.0 if gravity is None or given.mass == math.inf else -float(gravity[1])
    per_mass = 0.0 if given.mass == math.inf else width / given.mass
    a_start, a_now = given.pressure * per_mass + fall, piston.pressure * per_mass + fall
    accel = _accelerations(times, heights, velocities, a_start, a_now)
    return PistonPath(times, heights, velocities, accel)


def _accelerations(times, heights, velocities, a_start: float, a_now: float) -> np.ndarray:
    """The acceleration of each piece: the one in force (from ``a_start``) where its path reaches the next knot, else
    ``a_now`` (the pressure now's) where that does, else (a change by ``set_piston`` inside the piece) the one that
    joins its ends, in force from there on."""
    accel = np.full(len(times), a_now)
    tol = 1e-9 * (1.0 + float(np.abs(heights).max()))
    s = np.diff(times)
    reach = heights[:-1] + velocities[:-1] * s
    if np.all(np.abs(reach - 0.5 * a_start * s * s - heights[1:]) <= tol):  # no change: one vectorised pass
        accel[:-1] = a_start
        return accel
    current = a_start
    for k in range(len(times) - 1):
        fits = [a for a in (current, a_now) if abs(reach[k] - 0.5 * a * s[k] ** 2 - heights[k + 1]) <= tol]
        if fits or s[k] > 0.0:
            current = fits[0] if fits else 2.0 * (reach[k] - heights[k + 1]) / s[k] ** 2
        accel[k] = current
    return accel
