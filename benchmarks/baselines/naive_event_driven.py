"""The textbook event-driven simulator of hard discs, written plainly, as a baseline.

This is the design found in textbooks and teaching codes (for instance the
``CollisionSystem`` of Sedgewick and Wayne's *Algorithms*): a binary heap
(``heapq``) holds a predicted event for every pair of discs on a collision
course and for every disc heading to a wall; an event is stale when the
collision counter of one of its discs has moved on since the prediction. After
each event the discs involved are re-predicted against *all* other discs
(O(N) predictions) and *every* disc is moved to the event time (O(N) moves).
There is no cell grid and no lazy clock, so each event costs O(N) and the heap
keeps growing between stale pops. It exists to be measured against
:class:`discsim.EventDriven`, and to be simple enough to trust.

The physics is discsim's own (:func:`discsim.kernels.time_of_impact`,
:func:`discsim.kernels.resolve_collision`, :func:`discsim.kernels.wall_time`).

Two details keep it exact:

* Right after two discs collide, the contact image of that pair is not
  re-predicted (roundoff can make them look approaching and touching, which
  would be a spurious second collision at ``t = 0``); in a periodic box the
  pair's other images are.
* In a periodic box a pair is predicted against its 9 nearest images. That is
  exact only while the relative displacement since the prediction stays below
  one box side, so every ``min(width, height) / dv_max`` time units (``dv_max``
  bounds any relative speed from the total kinetic energy) a *refresh* event
  empties the heap and predicts everything afresh.

Example:
    >>> import discsim as ds
    >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
    >>> sim = NaiveEventDriven(discs, ds.Box(10.0, 10.0)).run(until=2.5)
    >>> sim.counts["collisions"], sim.velocities.tolist()
    (1, [[-1.0, 0.0], [1.0, 0.0]])
"""

from __future__ import annotations

import heapq
import itertools
import math

import numpy as np

import discsim as ds
from discsim.kernels import resolve_collision, time_of_impact, wall_time

__all__ = ["NaiveEventDriven"]

INF = math.inf
_COLLISION, _WALL, _REFRESH = 0, 1, 2
_IMAGE_SHIFTS = (-1.0, 0.0, 1.0)


class NaiveEventDriven:
    """Event-driven hard discs with O(N) work per event (the textbook baseline).

    Args:
        discs: the discs at ``time = 0`` (a validated :class:`discsim.Discs`).
        box: reflecting walls or periodic (a :class:`discsim.Box`).

    Attributes:
        time (float): the current simulated time.
        counts (dict[str, int]): ``collisions`` (disc-disc), ``wall_hits``,
            ``stale`` (invalidated events popped), ``predictions`` (pair and
            wall predictions computed), ``pushed`` (events put on the heap) and
            ``refreshes`` (full re-predictions, periodic box only).
        max_heap (int): the largest heap size seen.
    """

    def __init__(self, discs: ds.Discs, box: ds.Box):
        if not isinstance(discs, ds.Discs) or not isinstance(box, ds.Box):
            msg = f"need a discsim.Discs and a discsim.Box, got {type(discs).__name__} and {type(box).__name__}"
            raise TypeError(msg)
        self.box = box
        self.n = len(discs)
        self.x = discs.positions[:, 0].tolist()
        self.y = discs.positions[:, 1].tolist()
        self.vx = discs.velocities[:, 0].tolist()
        self.vy = discs.velocities[:, 1].tolist()
        self.radius = discs.radii.tolist()
        self.mass = discs.masses.tolist()
        self.collision_count = [0] * self.n
        self.time = 0.0
        self.counts = {"collisions": 0, "wall_hits": 0, "stale": 0, "predictions": 0, "pushed": 0, "refreshes": 0}
        self._heap: list = []
        self._tie = itertools.count()  # breaks ties in time so that payloads are never compared
        self._refresh_interval = self._periodic_refresh_interval(discs)
        self._predict_everything()
        self.max_heap = len(self._heap)

    # --- public protocol (the part of discsim's that the benchmarks use) ----------------
    @property
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time`` (wrapped into a periodic box)."""
        return np.column_stack([self.x, self.y]).reshape(self.n, 2)

    @property
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time``."""
        return np.column_stack([self.vx, self.vy]).reshape(self.n, 2)

    def run(self, until: float | None = None, *, events: int | None = None) -> NaiveEventDriven:
        """Process events up to time ``until`` and/or for ``events`` collisions plus wall hits.

        Args:
            until: stop time; every disc is moved to it at the end.
            events: stop after this many physical events.

        Returns:
            ``self``.
        """
        if until is None and events is None:
            msg = "run() needs until=... or events=..."
            raise ValueError(msg)
        if until is not None and not until >= self.time:
            msg = f"until={until!r} is before the current time {self.time!r}"
            raise ValueError(msg)
        limit_t = INF if until is None else float(until)
        done = 0
        while events is None or done < events:
            if self._process_next(limit_t) is None:
                break
            done += 1
        if until is not None and (events is None or done < events):
            self._move_all(limit_t)
        return self

    def step(self) -> ds.Event | None:
        """Process the next collision or wall hit and return it (None if nothing will ever happen)."""
        return self._process_next(INF)

    # --- prediction ---------------------------------------------------------------------
    def _periodic_refresh_interval(self, discs: ds.Discs) -> float:
        """Time over which a 9-image pair prediction stays exact (inf with walls)."""
        if not self.box.periodic:
            return INF
        moving = np.isfinite(discs.masses)
        energy = discs.kinetic_energy()
        if energy == 0.0 or not moving.any():
            return INF
        speed_max = math.sqrt(2.0 * energy / float(discs.masses[moving].min()))
        return min(self.box.width, self.box.height) / (2.0 * speed_max)

    def _push(self, t: float, kind: int, i: int, j: int) -> None:
        count = self.collision_count
        heapq.heappush(self._heap, (t, next(self._tie), kind, i, j, count[i], count[j] if j >= 0 else 0))
        self.counts["pushed"] += 1

    def _predict_everything(self) -> None:
        """Empty the heap and predict every pair and every wall from scratch."""
        self._heap = []
        for i in range(self.n):
            self._predict_walls(i)
            for j in range(i + 1, self.n):
                self._predict_pair(i, j, skip_contact=False)
        if self._refresh_interval != INF:
            self._push(self.time + self._refresh_interval, _REFRESH, -1, -1)

    def _predict_walls(self, i: int) -> None:
        """Push disc ``i``'s next hit on a vertical and on a horizontal wall."""
        if self.box.periodic:
            return
        self.counts["predictions"] += 1
        tx = wall_time(self.x[i], self.vx[i], self.radius[i], self.box.width)
        ty = wall_time(self.y[i], self.vy[i], self.radius[i], self.box.height)
        if tx != INF:
            self._push(self.time + tx, _WALL, i, 0)
        if ty != INF:
            self._push(self.time + ty, _WALL, i, 1)

    def _predict_pair(self, i: int, j: int, skip_contact: bool) -> None:
        """Push the next collision of discs ``i`` and ``j`` (over the 9 nearest images if periodic).

        ``skip_contact`` leaves out the image the pair has just collided through.
        """
        self.counts["predictions"] += 1
        dx = self.x[j] - self.x[i]
        dy = self.y[j] - self.y[i]
        dvx = self.vx[j] - self.vx[i]
        dvy = self.vy[j] - self.vy[i]
        sigma = self.radius[i] + self.radius[j]
        if not self.box.periodic:
            t = INF if skip_contact else time_of_impact(dx, dy, dvx, dvy, sigma)
        else:
            width, height = self.box.width, self.box.height
            dx -= width * round(dx / width)  # minimum image: the contact image, if they touch
            dy -= height * round(dy / height)
            t = INF
            for kx in _IMAGE_SHIFTS:
                for ky in _IMAGE_SHIFTS:
                    if skip_contact and kx == 0.0 and ky == 0.0:
                        continue
                    t = min(t, time_of_impact(dx + kx * width, dy + ky * height, dvx, dvy, sigma))
        if t != INF:
            self._push(self.time + t, _COLLISION, i, j)

    def _predict_disc(self, i: int, partner: int, done: int = -1) -> None:
        """Re-predict disc ``i`` against the walls and every other disc.

        ``partner``'s contact image is left out, and disc ``done`` (already
        predicted against ``i``) is skipped.
        """
        self._predict_walls(i)
        for k in range(self.n):
            if k != i and k != done:
                self._predict_pair(i, k, skip_contact=k == partner)

    # --- the event loop -----------------------------------------------------------------
    def _move_all(self, t: float) -> None:
        """Move every disc in a straight line to time ``t`` (wrapping into a periodic box)."""
        dt = t - self.time
        x, y, vx, vy = self.x, self.y, self.vx, self.vy
        for k in range(self.n):
            x[k] += vx[k] * dt
            y[k] += vy[k] * dt
        if self.box.periodic:
            width, height = self.box.width, self.box.height
            for k in range(self.n):
                x[k] %= width
                y[k] %= height
        self.time = t

    def _is_valid(self, kind: int, i: int, j: int, count_i: int, count_j: int) -> bool:
        count = self.collision_count
        if kind == _COLLISION:
            return count[i] == count_i and count[j] == count_j
        return kind == _REFRESH or count[i] == count_i

    def _process_next(self, until: float) -> ds.Event | None:
        """Pop events until a valid collision or wall hit at or before ``until``; process and return it."""
        heap = self._heap
        while heap and heap[0][0] <= until:
            t, _, kind, i, j, count_i, count_j = heapq.heappop(heap)
            if not self._is_valid(kind, i, j, count_i, count_j):
                self.counts["stale"] += 1
                continue
            self._move_all(t)
            if kind == _REFRESH:
                self.counts["refreshes"] += 1
                self._predict_everything()
                continue
            event = self._collide(i, j) if kind == _COLLISION else self._bounce(i, j)
            self.max_heap = max(self.max_heap, len(self._heap))
            return event
        return None

    def _collide(self, i: int, j: int) -> ds.Event:
        dx = self.x[j] - self.x[i]
        dy = self.y[j] - self.y[i]
        if self.box.periodic:
            dx -= self.box.width * round(dx / self.box.width)
            dy -= self.box.height * round(dy / self.box.height)
        self.vx[i], self.vy[i], self.vx[j], self.vy[j] = resolve_collision(
            dx, dy, self.vx[i], self.vy[i], self.vx[j], self.vy[j], self.mass[i], self.mass[j]
        )
        self.collision_count[i] += 1
        self.collision_count[j] += 1
        self.counts["collisions"] += 1
        self._predict_disc(i, partner=j)
        self._predict_disc(j, partner=i, done=i)
        return ds.Event(self.time, "collision", i, j)

    def _bounce(self, i: int, axis: int) -> ds.Event:
        if axis == 0:
            self.vx[i] = -self.vx[i]
        else:
            self.vy[i] = -self.vy[i]
        self.collision_count[i] += 1
        self.counts["wall_hits"] += 1
        self._predict_disc(i, partner=-1)
        return ds.Event(self.time, "wall", i, -1)
