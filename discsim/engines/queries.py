"""Spatial queries at an engine's current time: ``disc_at``, ``nearest``, ``within``, ``ray_cast``.

:class:`SpatialQueries` is a mixin of every engine (:class:`~discsim.engines.base.Engine`): each query checks
its arguments, then asks a :class:`~discsim.spatial.SpatialIndex` of the discs as they are at ``time`` (built
once per state and reused by every query until the engine moves or a disc changes).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from discsim.errors import InvalidArgumentError
from discsim.spatial import RAY_KINDS, RayHit, SpatialIndex, check_points

if TYPE_CHECKING:
    from discsim.model import Box, Discs

__all__ = ["SpatialQueries"]


class SpatialQueries:
    """Queries of where the discs are now (a mixin of :class:`~discsim.engines.base.Engine`)."""

    # What the engine provides (declared for readers and the type checker).
    box: Box
    discs: Discs
    segments: tuple
    time: float
    _edits: int

    if TYPE_CHECKING:

        @property
        def positions(self) -> np.ndarray: ...

        def _units(self) -> int: ...

    def _radii_now(self) -> np.ndarray:
        """``(N,)`` the discs' radii at ``time`` (an engine whose discs grow says so here)."""
        return self.discs.radii

    def _spatial_index(self) -> SpatialIndex:
        """The index of the discs at ``time`` (cached while nothing moves or changes)."""
        key = (self.time, self._units(), self._edits, len(self.discs))
        cached = getattr(self, "_spatial_cache", None)
        if cached is None or cached[0] != key:
            segments = [segment.at(self.time) for segment in self.segments]  # where the moving ones are now
            cached = (key, SpatialIndex(self.positions, self._radii_now(), self.box, segments))
            self._spatial_cache = cached
        return cached[1]

    def disc_at(self, points):
        """The disc covering each point now (its edge included), or -1.

        Args:
            points: one point ``(2,)`` or ``K`` points ``(K, 2)`` (length; in a periodic box, any point:
                it is wrapped).

        Returns:
            The disc's index (an int for one point, ``(K,)`` int64 for many), -1 where no disc covers the
            point. Where discs overlap (a fixed-step run), the one whose centre is nearest.

        Raises:
            InvalidArgumentError: a wrong shape, or a value that is not a finite real number.

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[2.0, 2.0], [6.0, 2.0]], [[1.0, 0.0], [0.0, 0.0]], 1.0), ds.Box(10, 5))
            >>> sim.disc_at([[2.5, 2.0], [5.0, 4.5]]).tolist(), sim.run(until=1.0).disc_at([3.9, 2.0])
            ([0, -1], 0)
        """
        array, single = check_points("points", points)
        out = self._spatial_index().disc_at(self.box.wrap(array))
        return int(out[0]) if single else out

    def nearest(self, points):
        """The disc whose edge is nearest each point now, and that distance.

        Args:
            points: one point ``(2,)`` or ``K`` points ``(K, 2)``.

        Returns:
            ``(index, distance)``: ints and floats for one point, ``(K,)`` arrays for many. The distance is
            to the disc's edge, ``|p - c| - r`` (negative inside a disc; the nearest image in a periodic box);
            on a tie, the lower index. ``(-1, inf)`` when there are no discs.

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[2.0, 2.0], [6.0, 2.0]], [[0.0, 0.0], [0.0, 0.0]], 1.0), ds.Box(10, 5))
            >>> sim.nearest([5.0, 4.0])
            (1, 1.2360679774997898)
        """
        array, single = check_points("points", points)
        index, distance = self._spatial_index().nearest(self.box.wrap(array))
        return (int(index[0]), float(distance[0])) if single else (index, distance)

    def within(self, point, distance: float) -> np.ndarray:
        """The discs whose edge lies within ``distance`` of ``point`` now (touching counts).

        Args:
            point: ``(2,)``.
            distance: a finite length >= 0 (0: the discs covering the point).

        Returns:
            Their indices, increasing, ``(M,)`` int64. In a periodic box, by the nearest image.

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[2.0, 2.0], [6.0, 2.0]], [[0.0, 0.0], [0.0, 0.0]], 1.0), ds.Box(10, 5))
            >>> sim.within([4.0, 2.0], 1.0).tolist(), sim.within([4.0, 2.0], 0.5).tolist()
            ([0, 1], [])
        """
        array, single = check_points("point", point)
        if not single:
            msg = f"point must be one point of shape (2,), got shape {array.shape}"
            raise InvalidArgumentError(msg)
        if isinstance(distance, bool) or not isinstance(distance, (int, float, np.integer, np.floating)):
            msg = f"distance must be a finite number >= 0, got {distance!r}"
            raise InvalidArgumentError(msg)
        if not (0.0 <= distance < math.inf):
            msg = f"distance must be a finite number >= 0, got {distance!r}"
            raise InvalidArgumentError(msg)
        return self._spatial_index().within(self.box.wrap(array)[0], float(distance))

    def ray_cast(self, origin, direction, max_distance: float | None = None) -> RayHit:
        """What a ray from ``origin`` along ``direction`` hits first now: a disc, a wall or a segment.

        Args:
            origin: ``(2,)``, or ``(K, 2)`` for ``K`` rays (inside a walled box; wrapped into a periodic one).
            direction: ``(2,)`` or ``(K, 2)``, not zero; its length sets the unit of the result's ``t``.
            max_distance: how far the rays go (length); None: to the walls in a walled box, ten times the
                box's longer side in a periodic box (where a ray runs on through the images).

        Returns:
            A :class:`~discsim.spatial.RayHit`: ``kind`` (``"disc"``, ``"wall"``, ``"segment"`` or
            ``"none"``), ``index``, ``t`` (the hit is at ``origin + t * direction``) and ``point``; scalars
            for one ray, arrays for many. A ray starting inside a disc hits it at ``t = 0``.

        Raises:
            InvalidArgumentError: a direction of zero length, an origin outside a walled box, a
                ``max_distance`` that is not positive, a wrong shape or a value that is not finite.

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[6.0, 2.0]], [[0.0, 0.0]], 1.0), ds.Box(10, 5))
            >>> hit = sim.ray_cast([1.0, 2.0], [2.0, 0.0])
            >>> hit.kind, hit.index, hit.t, hit.point.tolist()
            ('disc', 0, 2.0, [5.0, 2.0])
            >>> sim.ray_cast([1.0, 2.0], [0.0, 1.0]).kind
            'wall'
        """
        origins, single = check_points("origin", origin)
        directions, one_direction = check_points("direction", direction)
        if len(origins) != len(directions) and not (single or one_direction):
            msg = f"origin and direction must have the same number of rays, got {len(origins)} and {len(directions)}"
            raise InvalidArgumentError(msg)
        k = max(len(origins), len(directions))
        origins, directions = np.broadcast_to(origins, (k, 2)).copy(), np.broadcast_to(directions, (k, 2)).copy()
        length = np.hypot(directions[:, 0], directions[:, 1])
        if (length == 0.0).any():
            r = int(np.flatnonzero(length == 0.0)[0])
            msg = f"direction[{r}] = {directions[r].tolist()} has zero length: a ray needs a direction"
            raise InvalidArgumentError(msg)
        box = self.box
        if box.periodic:
            origins = box.wrap(origins)
        else:
            outside = (origins < 0.0).any(axis=1) | (origins > box.size).any(axis=1)
            if outside.any():
                r = int(np.flatnonzero(outside)[0])
                msg = f"origin[{r}] = {origins[r].tolist()} is outside the walled box {box.width:g} x {box.height:g}"
                raise InvalidArgumentError(msg)
        if max_distance is None:
            reach = 10.0 * max(box.width, box.height) if box.periodic else math.inf
        elif (
            isinstance(max_distance, bool)
            or not isinstance(max_distance, (int, float, np.integer, np.floating))
            or not 0.0 < max_distance <= math.inf
        ):
            msg = f"max_distance must be a positive number or None, got {max_distance!r}"
            raise InvalidArgumentError(msg)
        else:
            reach = float(max_distance)
        if box.periodic and reach == math.inf:
            msg = "max_distance must be finite in a periodic box (a ray there may run on for ever)"
            raise InvalidArgumentError(msg)
        kind, index, t, point = self._spatial_index().ray_cast(origins, directions, reach / length)
        kinds = np.array(RAY_KINDS, dtype=object)[kind]
        if single and one_direction:
            return RayHit(str(kinds[0]), int(index[0]), float(t[0]), point[0])
        return RayHit(kinds, index, t, point)
