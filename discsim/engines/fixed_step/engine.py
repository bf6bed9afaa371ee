"""The fixed-step engine (PIT): move every disc one frame, then test for interference.

This is the periodic interference test of the study: time advances in frames
of length ``dt``; after each move the engine looks for pairs of discs that
overlap and discs that cross a wall or a segment, and responds with one of
five policies. Between responses discs fly straight, so the event log (one
record per response, with the state just after it) rebuilds the exact path
the engine took, and :meth:`~discsim.engine.Engine.trajectory` works as for
the event-driven engine.

A frame is vectorised with numpy: the move, the wall and segment tests, the
broad phase (:func:`discsim.cells.neighbour_pairs`, or all pairs) and the
narrow phase are array operations. Only the few pairs found overlapping are
visited one by one.

Policies (the issue's names). The first three respond at the frame, after
the fact, visiting the overlapping pairs in a fixed order (by first disc,
then second disc), because a disc may sit in several of them and each
response changes the velocities the next one sees:

- ``"resolve"``: apply the elastic impulse along the line of centres found at
  the frame, to approaching pairs, and leave the discs where they are;
- ``"revert"``: put the pair back where it was at the previous frame, then
  apply the impulse along the line of centres there;
- ``"separate"``: push the pair apart along the line of centres until the
  discs just touch (each moves in inverse proportion to its mass), then apply
  the impulse.

A disc found past a wall and still moving outwards has its normal velocity
reversed; under ``"revert"`` it goes back to its previous-frame position,
under ``"separate"`` it is clamped to touch the wall. A disc found cutting a
segment and approaching it is reflected off it
(:func:`~discsim.kernels.reflect_off_segment`, the normal running from the
segment's nearest point to the centre); under ``"revert"`` it first goes back
to its previous-frame position, under ``"separate"`` it is first pushed out
along the normal to touch the segment.

The other two respond inside the frame, at the contact time (section 3.1 of
the study, "alternate PIC"). Their candidates (pairs, walls, segments) go into
a small queue by contact time; each response moves the discs back to the
contact, applies the impulse there, and lets them finish the frame with their
new velocities; then the discs that changed course are tested again over the
rest of the frame against their broad-phase neighbours, the walls and the
segments (a candidate of a disc that has changed course since is dropped):

- ``"bisect"``: the interference test at the frame, as above; for each
  overlap found, the frame interval is halved with the same test until the
  contact is known to ``bisect_tol``
  (:func:`~discsim.kernels.time_of_impact_bisect`); the response is at the
  last time found without overlap. Costs ``counts["bisection_tests"]``.
  A disc that passes right through another (or a segment) between two frames
  is still missed.
- ``"swept"``: the swept-volume test: the relative motion of each pair over
  the frame (the capsule each centre sweeps, seen from the other disc) is
  tested for a distance below the contact distance, ``min over s in [0, 1]
  of |d + s dv dt| < sigma``; a disc's path against a segment likewise. The
  broad phase uses the positions at mid-frame and cells of side
  ``2 r_max + v_max dt``, which hold every pair that can touch during the
  frame. The contact time is the analytic root
  (:func:`~discsim.kernels.time_of_impact`,
  :func:`~discsim.kernels.segment_time_of_impact`), so fast small discs no
  longer tunnel (case 1 of the study). In a periodic box the minimum image
  of a pair is taken at mid-frame, so a frame should move a disc less than
  about a quarter of the box.

Both stay approximations of the exact engine: ``"bisect"`` sees only the
contacts that leave an overlap at the frame (after the responses before them),
and ``"swept"`` follows straight paths from the frame, so it finds a chain of
contacts inside one frame but takes each disc's course from the last response.

Collision filtering (``pass_through``) drops the pairs of groups that pass
through each other before the narrow phase, under every policy.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from discsim.cells import CellGrid, neighbour_pairs
from discsim.engines.base import Engine
from discsim.errors import InvalidArgumentError
from discsim.events import Event, EventLog
from discsim.kernels import (
    closest_point_on_segment,
    reflect_off_segment,
    resolve_collision,
    segment_time_of_impact,
    time_of_impact,
    time_of_impact_bisect,
    wall_time,
)
from discsim.model import Box, Discs
from discsim.scene import check_scene

__all__ = ["BROAD_PHASES", "POLICIES", "SUB_FRAME_POLICIES", "FixedStep"]

#: Response policies of :class:`FixedStep`.
POLICIES = ("resolve", "revert", "separate", "bisect", "swept")
#: The policies that respond at the contact time inside the frame.
SUB_FRAME_POLICIES = ("bisect", "swept")
#: Broad phases of :class:`FixedStep`.
BROAD_PHASES = ("grid", "all-pairs")

#: Default frames per unit of time.
DEFAULT_FRAME_RATE = 30.0
#: Candidate pairs tested at once by the all-pairs broad phase (bounds its memory).
_ALL_PAIRS_BLOCK = 1 << 21
#: Default bisection tolerance of the ``"bisect"`` policy, as a fraction of ``dt``.
DEFAULT_BISECT_FRACTION = 1e-6
# Kinds of the candidates of a sub-frame policy.
_PAIR, _WALL, _SEGMENT = 0, 1, 2


def _positive_finite(name: str, value) -> float:
    if isinstance(value, bool):
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise InvalidArgumentError(msg)
    try:
        number = float(value)
    except (TypeError, ValueError) as exc:
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise InvalidArgumentError(msg) from exc
    if not (math.isfinite(number) and number > 0.0):
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise InvalidArgumentError(msg)
    return number


class FixedStep(Engine):
    """Fixed-step simulation with a periodic interference test (PIT).

    Args:
        discs: the discs at ``time = 0``.
        box: the box (reflecting walls or periodic).
        frame_rate: frames per unit of time (default 30). Give this or ``dt``.
        dt: the frame interval (time units), instead of ``frame_rate``.
        policy: the response to a detected overlap: ``"resolve"`` (default),
            ``"revert"``, ``"separate"``, ``"bisect"`` or ``"swept"`` (see the
            module docstring).
        broad_phase: ``"grid"`` (a Verlet list of the pairs within ``2 r_max + skin``,
            skin half a radius, rebuilt with the cell grid when a disc has moved
            half the skin: O(N) per frame) or ``"all-pairs"`` (every pair tested,
            O(N^2) per frame). Both give identical results.
        record: keep the event log (needed by ``events`` and ``trajectory``).
        segments: fixed :class:`~discsim.model.Segment` walls (walled boxes
            only), tested against every disc at each frame (few segments).
        pass_through: pairs of group labels (``discs.groups``) whose discs do
            not collide with each other, as for
            :class:`~discsim.engines.event_driven.EventDriven`. Free when empty.
        bisect_tol: the ``"bisect"`` policy's tolerance on contact times (time
            units; default ``1e-6 * dt``).

    Raises:
        ValueError: on a frame rate, ``dt`` or ``bisect_tol`` that is not a
            positive finite number, both of ``frame_rate`` and ``dt`` given
            and disagreeing, an unknown policy or broad phase, or segments in
            a periodic box.
        TypeError: if a segment is not a :class:`~discsim.model.Segment`.
        InvalidDiscsError: on a malformed ``pass_through``.
        OutsideBoxError, OverlapError: if the discs do not fit in the box (or
            are cut by a segment).
        BoxTooSmallError: if a periodic box is under three disc diameters a
            side (as for :class:`~discsim.engines.event_driven.EventDriven`).

    Attributes:
        time (float): the current time; frames fall at ``k * dt``.
        dt (float): the frame interval. frame_rate (float): ``1 / dt``.
        frames (int): frames done so far.
        counts (dict[str, int]): ``frames``; ``pair_tests`` (narrow-phase
            disc-disc checks: distances at the frame, swept-volume tests, and
            the tests again after a response inside a frame); ``segment_tests``
            (disc-segment checks); ``bisection_tests`` (interference tests
            spent by ``"bisect"``, one at the start of each interval and one
            per halving); ``detections`` (pairs that got an impulse);
            ``wall_hits`` (discs reflected by a wall or a segment);
            ``list_builds`` (rebuilds of the grid's Verlet list).
        max_overlap (float): deepest disc-disc overlap seen, as a fraction of
            the pair's contact distance (0 if discs never overlapped): at the
            frames for the first three policies; on the path kept (at contacts
            and frames) for ``"bisect"`` and ``"swept"``, which undo the
            overlaps they find.

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
        >>> sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), frame_rate=4.0).run(until=2.5)
        >>> sim.counts["detections"], sim.velocities.tolist(), sim.max_overlap
        (1, [[-1.0, 0.0], [1.0, 0.0]], 0.25)
        >>> exact = ds.FixedStep(discs, ds.Box(10.0, 10.0), frame_rate=4.0, policy="bisect").run(until=2.5)
        >>> round(float(exact.events["time"][0]), 6), exact.counts["bisection_tests"], exact.max_overlap
        (2.0, 21, 0.0)
        >>> case = ds.scenarios.missed_collision()  # a small fast disc crosses another between frames
        >>> [ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=p).run(until=case.until)
        ...  .counts["detections"] for p in ("resolve", "bisect", "swept")]
        [0, 0, 1]
    """

    def __init__(
        self,
        discs: Discs,
        box: Box,
        *,
        frame_rate: float | None = None,
        dt: float | None = None,
        policy: str = "resolve",
        broad_phase: str = "grid",
        record: bool = True,
        segments=(),
        pass_through=(),
        bisect_tol: float | None = None,
    ):
        super().__init__(discs, box, record)
        if dt is None:
            rate = DEFAULT_FRAME_RATE if frame_rate is None else _positive_finite("frame_rate", frame_rate)
            step, by_rate = 1.0 / rate, True
        else:
            step = _positive_finite("dt", dt)
            if frame_rate is not None:
                rate = _positive_finite("frame_rate", frame_rate)
                if not math.isclose(rate * step, 1.0, rel_tol=1e-12):
                    msg = f"give frame_rate or dt, not both: frame_rate={frame_rate!r} but dt={dt!r}"
                    raise InvalidArgumentError(msg)
            rate, by_rate = 1.0 / step, False
        if policy not in POLICIES:
            msg = f"policy must be one of {list(POLICIES)}, got {policy!r}"
            raise InvalidArgumentError(msg)
        if broad_phase not in BROAD_PHASES:
            msg = f"broad_phase must be one of {list(BROAD_PHASES)}, got {broad_phase!r}"
            raise InvalidArgumentError(msg)
        tol = DEFAULT_BISECT_FRACTION * step if bisect_tol is None else _positive_finite("bisect_tol", bisect_tol)
        segments, pass_through = check_scene(discs, box, segments, pass_through)
        n = len(discs)
        diameter = 2.0 * float(discs.radii.max()) if n else 1.0
        # The same box check as EventDriven's cell grid (a periodic box needs 3 cells a side);
        # max_cells=9 keeps the throw-away grid tiny.
        CellGrid(box, diameter, max_cells=9)
        self.frame_rate = rate
        self.dt = step
        self._by_rate = by_rate
        self.policy = policy
        self.broad_phase = broad_phase
        self.bisect_tol = tol
        self.segments = segments
        self.pass_through = pass_through
        self.time = 0.0
        self.frames = 0
        self.max_overlap = 0.0
        self.counts = {
            "frames": 0,
            "pair_tests": 0,
            "segment_tests": 0,
            "bisection_tests": 0,
            "detections": 0,
            "wall_hits": 0,
            "list_builds": 0,
        }
        self._cell_size = diameter
        self._max_radius = 0.5 * diameter
        # Verlet list of the grid broad phase (see _listed_pairs).
        self._skin = 0.25 * diameter
        self._list_pos = None
        self._list_i = self._list_j = np.zeros(0, dtype=np.int64)
        self._radii = np.array(discs.radii)
        self._radius = discs.radii.tolist()
        self._masses = discs.masses.tolist()
        self._moving = np.isfinite(discs.masses).tolist()
        # Collision filter: pairs (i, j) with _blocked[_group[i], _group[j]] pass through each other.
        self._blocked = None
        self._group_list: list[int] = []
        self._blocked_list: list[list[bool]] = []
        if pass_through:
            labels = np.unique(discs.groups)
            self._group = np.searchsorted(labels, discs.groups)
            self._blocked = np.array(
                [[(min(g, h), max(g, h)) in pass_through for h in labels.tolist()] for g in labels.tolist()],
                dtype=bool,
            )
            self._group_list = self._group.tolist()
            self._blocked_list = self._blocked.tolist()
        self._seg_a = np.array([seg.p0 for seg in segments]).reshape(-1, 2)
        self._seg_b = np.array([seg.p1 for seg in segments]).reshape(-1, 2)
        self._seg_ends = [(*seg.p0.tolist(), *seg.p1.tolist()) for seg in segments]
        # Lazy clocks, as in the event log: disc i is at _ref_pos[i] + v (t - _ref_time[i]),
        # so frame positions and trajectory() agree to the last bit.
        self._ref_pos = np.array(discs.positions)
        self._ref_time = np.zeros(n)
        self._vel = np.array(discs.velocities)
        self._pos = np.array(discs.positions)  # at the last frame time
        self._frame_time = 0.0
        self._log = EventLog()

    # --- public protocol -------------------------------------------------------------
    @property
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time`` (a fresh copy; wrapped into a periodic box)."""
        if self.time == self._frame_time:
            return self._pos.copy()
        return self._wrap(self._ref_pos + self._vel * (self.time - self._ref_time)[:, None])

    @property
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time`` (a fresh copy)."""
        return self._vel.copy()

    def _event_array(self) -> np.ndarray:
        return self._log.to_array()

    def frame_time(self, k: int) -> float:
        """The time of frame ``k`` (frame 0 is the start)."""
        if self._by_rate:
            return self.start_time + k / self.frame_rate
        return self.start_time + k * self.dt

    def frame_times(self) -> np.ndarray:
        """Times ``(frames + 1,)`` of the frames done so far, the start included.

        Example:
            >>> import discsim as ds
            >>> sim = ds.FixedStep(ds.Discs([[1.0, 1.0]], [[1.0, 0.0]], 0.5), ds.Box(4.0, 2.0), frame_rate=4.0)
            >>> sim.run(until=0.6).frame_times().tolist(), sim.time
            ([0.0, 0.25, 0.5], 0.6)
        """
        k = np.arange(self.frames + 1)
        if self._by_rate:
            return self.start_time + k / self.frame_rate
        return self.start_time + k * self.dt

    def run(self, until: float | None = None, *, frames: int | None = None, progress: bool = False):
        """Advance frame by frame up to time ``until`` and/or for ``frames`` frames.

        Args:
            until: stop time. Every frame at or before ``until`` is done; then
                ``time`` is set to ``until`` (discs drift straight from the last
                frame, and the next frame still falls at its usual time).
            frames: stop after this many frames.
            progress: show a progress bar.

        Returns:
            ``self``, so calls chain.

        Raises:
            TimeError: if ``until`` is before ``time`` or NaN.
            ValueError: if neither limit is given, or ``frames`` is negative.
        """
        if until is None and frames is None:
            msg = "run() needs until=... or frames=..."
            raise InvalidArgumentError(msg)
        limit_t = math.inf if until is None else self._check_until(until)
        if frames is not None and (isinstance(frames, bool) or int(frames) != frames or frames < 0):
            msg = f"frames must be a non-negative integer, got {frames!r}"
            raise InvalidArgumentError(msg)
        if limit_t == math.inf and frames is None:
            msg = "run(until=inf) never ends for a fixed-step engine; give frames=... as well"
            raise InvalidArgumentError(msg)
        # Frames up to `until`, allowing for the roundoff of k * dt.
        due = math.inf
        if limit_t != math.inf:
            due = max(0, math.floor((limit_t - self.frame_time(self.frames)) / self.dt * (1 + 1e-12) + 1e-9))
        todo = int(min(due, math.inf if frames is None else int(frames)))
        if progress:
            from discsim.run.progress import progress_bar

            with progress_bar(todo, by_time=False) as bar:
                done = 0
                while done < todo:
                    chunk = min(1000, todo - done)
                    for _ in range(chunk):
                        self._frame()
                    done += chunk
                    bar.update(chunk, self.counts["detections"])
        else:
            for _ in range(todo):
                self._frame()
        if todo == due:  # stopped by the clock
            self.time = max(limit_t, self._frame_time)
        return self

    def step(self) -> list[Event]:
        """Do one frame: move, test, respond.

        Returns:
            The :class:`~discsim.engine.Event` of each response in the frame,
            empty if nothing touched: for ``"resolve"``, ``"revert"`` and
            ``"separate"`` wall hits first, then segment hits, then disc pairs
            in the order they were handled, all at the frame time; for
            ``"bisect"`` and ``"swept"`` in the order of their contact times.

        Example:
            >>> import discsim as ds
            >>> sim = ds.FixedStep(ds.Discs([[3.0, 1.0]], [[2.0, 0.0]], 0.5), ds.Box(4.0, 2.0), dt=0.5)
            >>> sim.step()  # x = 4.0: past the wall at 3.5
            [Event(time=0.5, kind='wall', i=0, j=-1)]
            >>> sim.velocities.tolist()
            [[-2.0, 0.0]]
        """
        return self._frame()

    # --- one frame -------------------------------------------------------------------
    def _wrap(self, pos: np.ndarray) -> np.ndarray:
        if not self.box.periodic:
            return pos
        size = self.box.size
        pos = np.mod(pos, size)
        return np.where(pos >= size, pos - size, pos)  # np.mod(-1e-17, L) is L

    def _candidates(self, pos: np.ndarray, cell_size: float | None = None):
        """Candidate pairs of the broad phase, as chunks ``(i, j, d)``, ``d`` the minimum-image ``pos[j] - pos[i]``.

        Pairs of groups that pass through each other are left out.
        """
        if self.broad_phase == "grid":
            if cell_size is None:
                yield self._listed_pairs(pos)
            else:
                yield self._unblocked(*neighbour_pairs(pos, cell_size, self.box))
            return
        n = len(pos)
        size = self.box.size
        rows = max(1, _ALL_PAIRS_BLOCK // max(n, 1))
        later = np.arange(n)
        for start in range(0, n - 1, rows):
            first = np.arange(start, min(n - 1, start + rows))
            bi, jj = np.nonzero(later[None, :] > first[:, None])
            ii = first[bi]
            d = pos[jj] - pos[ii]
            if self.box.periodic:
                d -= size * np.round(d / size)
            yield self._unblocked(ii, jj, d)

    def _check_sweep_fits(self) -> None:
        """Refuse a swept frame whose relative sweeps could reach a second periodic image.

        The swept test follows one image per pair (the nearest at mid-frame), which
        is exact while two discs' relative path over a frame plus their contact
        distance stays under half the box's shorter side.
        """
        speed = float(np.sqrt(np.max(np.einsum("ij,ij->i", self._vel, self._vel), initial=0.0)))
        reach = 2.0 * speed * self.dt + 2.0 * self._max_radius
        half = 0.5 * min(self.box.width, self.box.height)
        if reach >= half:
            msg = (
                f"policy 'swept' in a periodic box needs 2 v_max dt + 2 r_max < half the box side: "
                f"2 * {speed:.6g} * {self.dt:.6g} + {2.0 * self._max_radius:.6g} = {reach:.6g} >= {half:.6g}; "
                "use a smaller dt or a larger box"
            )
            raise InvalidArgumentError(msg)

    def _listed_pairs(self, pos: np.ndarray):
        """Candidate pairs from a Verlet list: the pairs within ``2 r_max + skin`` when it was built.

        The list is rebuilt with the cell grid once some disc has moved more than
        half the skin since the last build (responses that move discs count), so
        every pair that can overlap now is in it. Between rebuilds a frame's
        broad phase is one gather. Returns ``(i, j, d)`` like :meth:`_candidates`.
        """
        size = self.box.size
        if self._list_pos is not None:
            moved = pos - self._list_pos
            if self.box.periodic:
                moved -= size * np.round(moved / size)
            stale = float(np.max(np.einsum("ij,ij->i", moved, moved), initial=0.0)) > (0.5 * self._skin) ** 2
        if self._list_pos is None or stale:
            reach = self._cell_size + self._skin
            i, j, d = self._unblocked(*neighbour_pairs(pos, reach, self.box))
            near = np.einsum("ij,ij->i", d, d) < reach * reach
            self._list_i, self._list_j = i[near], j[near]
            self._list_pos = pos.copy()
            self.counts["list_builds"] += 1
        i, j = self._list_i, self._list_j
        d = pos[j] - pos[i]
        if self.box.periodic:
            d -= size * np.round(d / size)
        return i, j, d

    def _unblocked(self, i, j, d):
        """The pairs of ``(i, j, d)`` whose groups collide (all of them when there is no filter)."""
        if self._blocked is None or not len(i):
            return i, j, d
        keep = ~self._blocked[self._group[i], self._group[j]]
        return i[keep], j[keep], d[keep]

    def _overlapping_pairs(self, pos: np.ndarray):
        """Pairs ``(i, j)`` with ``i < j`` whose discs overlap at ``pos``, sorted by ``i`` then ``j``."""
        parts_i, parts_j = [], []
        for i, j, d in self._candidates(pos):
            self.counts["pair_tests"] += len(i)
            i, j = self._narrow(i, j, d)
            parts_i.append(i)
            parts_j.append(j)
        if not parts_i:
            return [], []
        i = np.concatenate(parts_i)
        j = np.concatenate(parts_j)
        i, j = np.minimum(i, j), np.maximum(i, j)
        order = np.lexsort((j, i))
        return i[order].tolist(), j[order].tolist()

    def _narrow(self, i, j, d):
        """The candidate pairs that overlap; updates ``max_overlap``."""
        radii = self._radii
        contact = radii[i] + radii[j]
        dist2 = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]
        hit = dist2 < contact * contact
        if hit.any():
            depth = 1.0 - np.sqrt(dist2[hit]) / contact[hit]
            self.max_overlap = max(self.max_overlap, float(depth.max()))
        return i[hit], j[hit]

    def _frame(self) -> list[Event]:
        if self.policy == "swept" and self.box.periodic:
            self._check_sweep_fits()
        if self.policy in SUB_FRAME_POLICIES:
            return _SubFrame(self).run()
        k = self.frames + 1
        t = self.frame_time(k)
        prev = self._pos
        vel = self._vel
        pos = self._wrap(self._ref_pos + vel * (t - self._ref_time)[:, None])
        record = self.record
        log = self._log
        events: list[Event] = []
        policy = self.policy
        # Walls: discs past a wall and still moving outwards.
        if not self.box.periodic:
            r = self._radii[:, None]
            size = self.box.size
            low = (pos < r) & (vel < 0.0)
            high = (pos > size - r) & (vel > 0.0)
            hit = low | high
            if hit.any():
                vel[hit] = -vel[hit]
                rows = np.flatnonzero(hit.any(axis=1))
                if policy == "revert":
                    pos[rows] = prev[rows]
                elif policy == "separate":
                    pos = np.where(low, r, np.where(high, size - r, pos))
                self._ref_pos[rows] = pos[rows]
                self._ref_time[rows] = t
                self.counts["wall_hits"] += len(rows)
                for i in rows.tolist():
                    events.append(Event(t, "wall", i, -1))
                    if record:
                        log.wall(t, i, *pos[i].tolist(), *vel[i].tolist())
        if self.segments:
            events.extend(self._segment_hits(t, prev, pos, vel))
        # Disc pairs.
        ii, jj = self._overlapping_pairs(pos)
        if ii:
            events.extend(self._respond(t, ii, jj, prev, pos, vel))
            pos = self._wrap(pos)
        self._pos = pos
        self._frame_time = t
        self.time = t
        self.frames = k
        self.counts["frames"] += 1
        return events

    def _segment_hits(self, t, prev, pos, vel) -> list[Event]:
        """Respond to discs cutting a segment at ``pos`` (frame policies); update ``pos`` and ``vel`` in place.

        A disc's segments are visited in order, each seeing the position and
        velocity the one before left (a disc in a corner may touch two).
        """
        self.counts["segment_tests"] += len(pos) * len(self.segments)
        dist = _point_segment_distance(pos[:, None, :], self._seg_a[None], self._seg_b[None])
        rows, cols = np.nonzero(dist < self._radii[:, None])
        if not len(rows):
            return []
        policy = self.policy
        radius, ends = self._radius, self._seg_ends
        log = self._log if self.record else None
        events = []
        by_disc: dict[int, list[int]] = {}
        for i, k in zip(rows.tolist(), cols.tolist()):
            by_disc.setdefault(i, []).append(k)
        for i, hits in by_disc.items():
            x, y = pos[i].tolist()
            vx, vy = vel[i].tolist()
            reverted = False
            responded = False
            for k in hits:
                qx, qy = closest_point_on_segment(x, y, *ends[k])
                nx, ny = x - qx, y - qy
                if policy == "revert" and not reverted:
                    px, py = prev[i].tolist()
                    bx, by = closest_point_on_segment(px, py, *ends[k])
                    if vx * (px - bx) + vy * (py - by) < 0.0:  # approaching there: reflect at the restored place
                        x, y, nx, ny = px, py, px - bx, py - by
                        reverted = True
                    elif vx * nx + vy * ny < 0.0:  # approaching only at the frame: restore, keep the frame's normal
                        fx, fy = x, y
                        x, y = px, py
                        reverted = True
                        vx, vy = reflect_off_segment(fx, fy, vx, vy, *ends[k])
                        responded = True
                        continue
                if vx * nx + vy * ny >= 0.0:  # receding (or the centre is on the segment): leave it
                    continue
                if policy == "separate":
                    dist_k = math.hypot(nx, ny)
                    if dist_k < radius[i]:
                        x, y = qx + nx / dist_k * radius[i], qy + ny / dist_k * radius[i]
                vx, vy = reflect_off_segment(x, y, vx, vy, *ends[k])
                responded = True
            if responded:
                pos[i] = (x, y)
                vel[i] = (vx, vy)
                self._ref_pos[i] = (x, y)
                self._ref_time[i] = t
                self.counts["wall_hits"] += 1
                events.append(Event(t, "wall", i, -1))
                if log is not None:
                    log.wall(t, i, x, y, vx, vy)
        return events

    def _respond(self, t, ii, jj, prev, pos, vel) -> list[Event]:
        """Respond to the overlapping pairs ``ii[k] < jj[k]`` in order; update ``pos`` and ``vel`` in place.

        The discs involved are read into Python floats once and written back once
        (a pair sees the velocities left by the pairs before it in the frame).
        """
        mass = self._masses
        radius = self._radius
        periodic = self.box.periodic
        width, height = self.box.width, self.box.height
        policy = self.policy
        log = self._log if self.record else None
        involved = np.unique(np.concatenate([ii, jj]))
        keys = involved.tolist()
        at = dict(zip(keys, pos[involved].tolist(), strict=True))
        speed = dict(zip(keys, vel[involved].tolist(), strict=True))
        before = dict(zip(keys, prev[involved].tolist(), strict=True)) if policy == "revert" else None
        changed = set()
        events = []
        for i, j in zip(ii, jj, strict=True):
            xi, yi = at[i]
            xj, yj = at[j]
            dx, dy = xj - xi, yj - yi
            if periodic:
                dx -= width * round(dx / width)
                dy -= height * round(dy / height)
            vxi, vyi = speed[i]
            vxj, vyj = speed[j]
            dvx, dvy = vxj - vxi, vyj - vyi
            if dvx * dx + dvy * dy >= 0.0:  # separating already (an earlier response this frame)
                continue
            mi, mj = mass[i], mass[j]
            if policy == "revert":
                xi, yi = before[i]
                xj, yj = before[j]
                px, py = xj - xi, yj - yi
                if periodic:
                    px -= width * round(px / width)
                    py -= height * round(py / height)
                if dvx * px + dvy * py < 0.0:  # else keep the frame's line, which is approaching
                    dx, dy = px, py
            elif policy == "separate":
                dist = math.hypot(dx, dy)
                depth = radius[i] + radius[j] - dist
                if depth > 0.0 and dist > 0.0:
                    if mi == math.inf:
                        wi, wj = 0.0, 1.0
                    elif mj == math.inf:
                        wi, wj = 1.0, 0.0
                    else:
                        wi, wj = mj / (mi + mj), mi / (mi + mj)
                    ux, uy = dx / dist, dy / dist
                    xi, yi = xi - wi * depth * ux, yi - wi * depth * uy
                    xj, yj = xj + wj * depth * ux, yj + wj * depth * uy
                    dx, dy = ux * (dist + depth), uy * (dist + depth)
            uxi, uyi, uxj, uyj = resolve_collision(dx, dy, vxi, vyi, vxj, vyj, mi, mj)
            at[i], at[j] = (xi, yi), (xj, yj)
            speed[i], speed[j] = (uxi, uyi), (uxj, uyj)
            changed.add(i)
            changed.add(j)
            events.append(Event(t, "collision", i, j))
            if log is not None:
                log.collision(t, i, j, xi, yi, uxi, uyi, xj, yj, uxj, uyj)
        if changed:
            done = sorted(changed)
            pos[done] = [at[k] for k in done]
            vel[done] = [speed[k] for k in done]
            self._ref_pos[done] = pos[done]
            self._ref_time[done] = t
        self.counts["detections"] += len(events)
        return events


# --- helpers of the segment tests and the sub-frame policies ------------------------------------------------


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points ``p`` to segments ``a``-``b`` (broadcast shapes ``(..., 2)``; ``a == b`` allowed)."""
    e = b - a
    ee = np.sum(e * e, axis=-1)
    w = p - a
    u = np.divide(np.sum(w * e, axis=-1), ee, out=np.zeros(np.broadcast_shapes(ee.shape, w.shape[:-1])), where=ee > 0)
    u = np.clip(u, 0.0, 1.0)
    off = w - u[..., None] * e
    return np.hypot(off[..., 0], off[..., 1])


def _segment_segment_distance(p0: np.ndarray, p1: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance ``(N, S)`` between paths ``p0``-``p1`` ``(N, 2)`` and segments ``a``-``b`` ``(S, 2)``."""
    p0, p1 = p0[:, None, :], p1[:, None, :]
    a, b = a[None], b[None]
    dist = np.minimum(
        np.minimum(_point_segment_distance(p0, a, b), _point_segment_distance(p1, a, b)),
        np.minimum(_point_segment_distance(a, p0, p1), _point_segment_distance(b, p0, p1)),
    )

    def cross(u, v):
        return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

    e, f = b - a, p1 - p0
    crossing = (cross(e, p0 - a) * cross(e, p1 - a) < 0.0) & (cross(f, a - p0) * cross(f, b - p0) < 0.0)
    return np.where(crossing, 0.0, dist)


def _times_of_impact(dx, dy, dvx, dvy, sigma) -> np.ndarray:
    """:func:`~discsim.kernels.time_of_impact` over arrays (the same floats, element by element)."""
    b = dx * dvx + dy * dvy
    c = dx * dx + dy * dy - sigma * sigma
    a = dvx * dvx + dvy * dvy
    disc = b * b - a * c
    with np.errstate(divide="ignore", invalid="ignore"):
        root = c / (-b + np.sqrt(np.maximum(disc, 0.0)))
    toi = np.where(c <= 0.0, 0.0, root)
    return np.where((b < 0.0) & ((c <= 0.0) | (disc > 0.0)), toi, np.inf)


class _CellTable:
    """Discs by cell of a uniform grid, for box queries (the discs near a path after a change of course).

    Args:
        pos: ``(N, 2)`` positions (points outside a walled box go to its edge cells).
        cell: smallest cell side (length); cells grow so that there are at most
            ``max(4 N, 65536)`` of them.
        box: the box (a periodic one wraps the queries).
    """

    def __init__(self, pos: np.ndarray, cell: float, box: Box):
        n = len(pos)
        nx = max(1, int(box.width // cell))
        ny = max(1, int(box.height // cell))
        cap = max(4 * n, 1 << 16)
        if nx * ny > cap:
            scale = math.sqrt(nx * ny / cap)
            nx, ny = max(1, int(nx / scale)), max(1, int(ny / scale))
        self.nx, self.ny = nx, ny
        self.lx, self.ly = box.width / nx, box.height / ny
        self.periodic = box.periodic
        cx = np.clip((pos[:, 0] / self.lx).astype(np.int64), 0, nx - 1)
        cy = np.clip((pos[:, 1] / self.ly).astype(np.int64), 0, ny - 1)
        cells = cx * ny + cy
        self.extra: dict[int, list[int]] = {}
        start = np.zeros(nx * ny + 1, dtype=np.int64)
        np.cumsum(np.bincount(cells, minlength=nx * ny), out=start[1:])
        # Plain lists: a query reads a few cells, faster from lists than from numpy.
        self.order = np.argsort(cells, kind="stable").tolist()
        self.start = start.tolist()

    def _span(self, lo: float, hi: float, size: float, count: int) -> list[int]:
        first, last = math.floor(lo / size), math.floor(hi / size)
        if self.periodic:
            if last - first + 1 >= count:
                return list(range(count))
            return [c % count for c in range(first, last + 1)]
        return list(range(min(max(first, 0), count - 1), min(max(last, 0), count - 1) + 1))

    def _cells(self, lo: tuple[float, float], hi: tuple[float, float]) -> list[int]:
        ny = self.ny
        rows = self._span(lo[1], hi[1], self.ly, ny)
        return [cx * ny + cy for cx in self._span(lo[0], hi[0], self.lx, self.nx) for cy in rows]

    def add(self, disc: int, lo: tuple[float, float], hi: tuple[float, float]) -> None:
        """File ``disc`` (which changed course) under the cells that meet the box from ``lo`` to ``hi`` too."""
        extra = self.extra
        for c in self._cells(lo, hi):
            extra.setdefault(c, []).append(disc)

    def near(self, lo: tuple[float, float], hi: tuple[float, float]) -> set[int]:
        """The discs filed under the cells that meet the box from ``lo`` to ``hi``."""
        order, start, extra = self.order, self.start, self.extra
        found: set[int] = set()
        for c in self._cells(lo, hi):
            found.update(order[start[c] : start[c + 1]])
            if c in extra:
                found.update(extra[c])
        return found


class _SubFrame:
    """One frame of ``"bisect"`` or ``"swept"``: candidates in contact-time order, responses at the contact.

    Candidates are ``(time, seq, kind, a, b, stamp_a, stamp_b)`` in a heap:
    ``kind`` is ``_PAIR`` (discs ``a < b``), ``_WALL`` (disc ``a``, wall
    ``b = 2 * axis + high``) or ``_SEGMENT`` (disc ``a``, segment ``b``); the
    stamps are the discs' response counts in this frame when the candidate
    was found, so that a candidate of a disc that has changed course since is
    dropped (its new path was tested when it changed course).
    """

    def __init__(self, sim: FixedStep):
        self.sim = sim
        self.t0 = sim._frame_time
        self.k = sim.frames + 1
        self.t = sim.frame_time(self.k)
        self.swept = sim.policy == "swept"
        self.heap: list = []
        self.seq = 0
        self.version: dict[int, int] = {}
        self.done: dict[tuple[int, int, int], float] = {}  # when each contact was last responded to
        self.events: list[Event] = []
        self.found: set = set()  # pairs that were candidates, for the overlap at the frame's end
        self.table_pos: np.ndarray | None = None  # where the broad phase saw the discs
        self.table_reach = 0.0  # how far (length) a disc unchanged in course can be from there
        self._table: _CellTable | None = None
        self.log = sim._log if sim.record else None
        box = sim.box
        self.periodic = box.periodic
        self.width, self.height = box.width, box.height

    # --- the frame ---------------------------------------------------------------------------------------
    def run(self) -> list[Event]:
        sim = self.sim
        if self.swept:
            self._detect_swept()
        else:
            self._detect_overlaps()
        heap, version, done = self.heap, self.version, self.done
        while heap:
            tc, _, kind, a, b, stamp_a, stamp_b = heapq.heappop(heap)
            if version.get(a, 0) != stamp_a or (kind == _PAIR and version.get(b, 0) != stamp_b):
                continue
            if done.get((kind, a, b)) == tc:
                # The same contact again at the same instant: a disc caught overlapping two things (a
                # wall and a segment, say) would be sent back and forth between them for ever.
                continue
            done[(kind, a, b)] = tc
            if kind == _PAIR:
                self._collide(tc, a, b)
            elif kind == _WALL:
                self._wall(tc, a, b)
            else:
                self._segment(tc, a, b)
        t = self.t
        pos = sim._wrap(sim._ref_pos + sim._vel * (t - sim._ref_time)[:, None])
        if self.found:
            pairs = np.array(sorted(self.found), dtype=np.int64).reshape(-1, 2)
            d = pos[pairs[:, 1]] - pos[pairs[:, 0]]
            if self.periodic:
                d -= sim.box.size * np.round(d / sim.box.size)
            depth = 1.0 - np.hypot(d[:, 0], d[:, 1]) / (sim._radii[pairs[:, 0]] + sim._radii[pairs[:, 1]])
            sim.max_overlap = max(sim.max_overlap, float(depth.max()))
        sim._pos = pos
        sim._frame_time = t
        sim.time = t
        sim.frames = self.k
        sim.counts["frames"] += 1
        return self.events

    def _push(self, tc: float, kind: int, a: int, b: int) -> None:
        version = self.version
        stamp_b = version.get(b, 0) if kind == _PAIR else 0
        heapq.heappush(self.heap, (tc, self.seq, kind, a, b, version.get(a, 0), stamp_b))
        self.seq += 1
        if kind == _PAIR:
            self.found.add((a, b) if a < b else (b, a))

    def _pairs(self, pos: np.ndarray, cell: float):
        """Broad-phase candidate pairs at ``pos``: ``(i, j, d)`` with ``i < j``, sorted by ``(i, j)``."""
        sim = self.sim
        parts = []
        for i, j, d in sim._candidates(pos, cell):
            sim.counts["pair_tests"] += len(i)
            flip = i > j
            d[flip] = -d[flip]
            parts.append((np.where(flip, j, i), np.where(flip, i, j), d))
        if not parts:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros((0, 2))
        i = np.concatenate([p[0] for p in parts])
        j = np.concatenate([p[1] for p in parts])
        d = np.concatenate([p[2] for p in parts])
        order = np.lexsort((j, i))
        return i[order], j[order], d[order]

    def _near(self, a: int, lo: tuple[float, float], hi: tuple[float, float], partner: int) -> list[int]:
        """Discs that may touch disc ``a`` in the rest of the frame, sorted; ``a`` and ``partner`` left out.

        ``lo``, ``hi``: corners of a box that holds every point of ``a``'s new
        path that matters, grown by the largest contact distance and
        ``table_reach``. Discs are found through a cell table of the broad
        phase's positions, where each disc that changed course in this frame
        is also filed under the cells of its new path (see :meth:`_file`).
        The all-pairs broad phase returns every disc.
        """
        sim = self.sim
        if sim.broad_phase == "all-pairs":
            near = set(range(len(sim._radius)))
        else:
            near = self._cell_table().near(lo, hi)
        near.discard(a)
        near.discard(partner)
        if sim._blocked is not None:
            group = sim._group_list
            passes = sim._blocked_list[group[a]]
            return sorted(m for m in near if not passes[group[m]])
        return sorted(near)

    def _cell_table(self) -> _CellTable:
        if self._table is None:
            self._table = _CellTable(self.table_pos, self.sim._cell_size + self.table_reach, self.sim.box)
        return self._table

    def _file(self, a: int, now: float) -> None:
        """File disc ``a``, which changed course at ``now``, under the cells of its new path."""
        if self.sim.broad_phase == "all-pairs":
            return
        x, y = self.sim._ref_pos[a].tolist()
        vx, vy = self.sim._vel[a].tolist()
        span = self.t - now
        ex, ey = x + vx * span, y + vy * span
        if self.swept:  # the whole path
            self._cell_table().add(a, (min(x, ex), min(y, ey)), (max(x, ex), max(y, ey)))
        else:  # where it ends: "bisect" tests at the frame
            self._cell_table().add(a, (ex, ey), (ex, ey))

    # --- detection at the start of the frame -----------------------------------------------------------
    def _detect_overlaps(self) -> None:
        """``"bisect"``: interference tests at the frame, then the contact times by bisection."""
        sim, t, t0 = self.sim, self.t, self.t0
        vel, radii = sim._vel, sim._radii
        pos = sim._wrap(sim._ref_pos + vel * (t - sim._ref_time)[:, None])
        self.table_pos = pos
        i, j, d = self._pairs(pos, sim._cell_size)
        contact = radii[i] + radii[j]
        hit = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] < contact * contact
        for a, b in zip(i[hit].tolist(), j[hit].tolist()):
            self._push(self._bisect_pair(a, b, t0), _PAIR, a, b)
        if not self.periodic:
            r = radii[:, None]
            low = (pos < r) & (vel < 0.0)
            high = (pos > sim.box.size - r) & (vel > 0.0)
            for a, axis in zip(*np.nonzero(low | high)):
                wall = 2 * int(axis) + int(high[a, axis])
                self._push(self._bisect_wall(int(a), wall, t0), _WALL, int(a), wall)
        if sim.segments:
            sim.counts["segment_tests"] += len(pos) * len(sim.segments)
            dist = _point_segment_distance(pos[:, None, :], sim._seg_a[None], sim._seg_b[None])
            for a, k in zip(*np.nonzero(dist < radii[:, None])):
                self._push(self._bisect_segment(int(a), int(k), t0), _SEGMENT, int(a), int(k))

    def _detect_swept(self) -> None:
        """``"swept"``: the relative motion over the frame against the contact distance, then the exact roots."""
        sim, t, t0 = self.sim, self.t, self.t0
        span = t - t0
        vel, radii = sim._vel, sim._radii
        start = sim._pos  # the positions at t0
        speed = float(np.sqrt((vel * vel).sum(axis=1)).max()) if len(vel) else 0.0
        cell = sim._cell_size + speed * span
        mid = sim._wrap(start + vel * (0.5 * span))
        self.table_pos, self.table_reach = mid, 0.5 * speed * span
        i, j, d = self._pairs(mid, cell)
        if len(i):
            dv = vel[j] - vel[i]
            d0 = d - dv * (0.5 * span)
            sweep = dv * span
            sweep2 = np.sum(sweep * sweep, axis=1)
            s = np.clip(np.divide(-np.sum(d0 * sweep, axis=1), sweep2, out=np.zeros(len(i)), where=sweep2 > 0), 0, 1)
            closest = d0 + s[:, None] * sweep
            contact = radii[i] + radii[j]
            hit = np.sum(closest * closest, axis=1) <= contact * contact  # touching at the frame counts
            if hit.any():
                toi = _times_of_impact(d0[hit, 0], d0[hit, 1], dv[hit, 0], dv[hit, 1], contact[hit])
                due = toi <= span
                for a, b, tau in zip(i[hit][due].tolist(), j[hit][due].tolist(), toi[due].tolist()):
                    self._push(t0 + tau, _PAIR, a, b)
        if not self.periodic:
            for axis, length in ((0, self.width), (1, self.height)):
                x, v, r = start[:, axis], vel[:, axis], radii
                with np.errstate(divide="ignore", invalid="ignore"):
                    wt = np.where(v > 0.0, (length - r - x) / v, np.where(v < 0.0, (r - x) / v, np.inf))
                for a in np.flatnonzero(wt <= span).tolist():
                    self._push(t0 + max(float(wt[a]), 0.0), _WALL, a, 2 * axis + int(vel[a, axis] > 0.0))
        if sim.segments:
            sim.counts["segment_tests"] += len(start) * len(sim.segments)
            dist = _segment_segment_distance(start, start + vel * span, sim._seg_a, sim._seg_b)
            ends = sim._seg_ends
            for a, k in zip(*np.nonzero(dist <= radii[:, None])):
                a, k = int(a), int(k)
                tau = segment_time_of_impact(*start[a].tolist(), *vel[a].tolist(), sim._radius[a], *ends[k])
                if tau <= span:
                    self._push(t0 + tau, _SEGMENT, a, k)

    # --- paths and contact times ---------------------------------------------------------------------------
    def _at(self, a: int, s: float) -> tuple[float, float]:
        """Centre of disc ``a`` at time ``s`` on its current path (not wrapped)."""
        sim = self.sim
        x, y = sim._ref_pos[a].tolist()
        vx, vy = sim._vel[a].tolist()
        tr = float(sim._ref_time[a])
        return x + vx * (s - tr), y + vy * (s - tr)

    def _bisect(self, test, s0: float) -> float:
        """The last time without overlap in ``[s0, t]``, overlap at ``t`` being known; counts the tests."""
        calls = [1]

        def counted(s: float) -> bool:
            calls[0] += 1
            return test(s)

        if test(s0):  # overlapping already where the interval starts: respond there
            found = s0
        else:
            found = time_of_impact_bisect(counted, s0, self.t, self.sim.bisect_tol)
        self.sim.counts["bisection_tests"] += calls[0]
        return found

    def _bisect_pair(self, a: int, b: int, s0: float) -> float:
        sim = self.sim
        xa, ya = sim._ref_pos[a].tolist()
        ua, wa = sim._vel[a].tolist()
        ta = float(sim._ref_time[a])
        xb, yb = sim._ref_pos[b].tolist()
        ub, wb = sim._vel[b].tolist()
        tb = float(sim._ref_time[b])
        sigma2 = (sim._radius[a] + sim._radius[b]) ** 2
        periodic, width, height = self.periodic, self.width, self.height

        def overlapping(s: float) -> bool:
            dx = xb + ub * (s - tb) - (xa + ua * (s - ta))
            dy = yb + wb * (s - tb) - (ya + wa * (s - ta))
            if periodic:
                dx -= width * round(dx / width)
                dy -= height * round(dy / height)
            return dx * dx + dy * dy < sigma2

        return self._bisect(overlapping, s0)

    def _bisect_wall(self, a: int, wall: int, s0: float) -> float:
        sim = self.sim
        axis, high = divmod(wall, 2)
        x = float(sim._ref_pos[a, axis])
        v = float(sim._vel[a, axis])
        tr = float(sim._ref_time[a])
        r = sim._radius[a]
        limit = (self.width if axis == 0 else self.height) - r

        def overlapping(s: float) -> bool:
            position = x + v * (s - tr)
            return position > limit if high else position < r

        return self._bisect(overlapping, s0)

    def _bisect_segment(self, a: int, k: int, s0: float) -> float:
        sim = self.sim
        x, y = sim._ref_pos[a].tolist()
        vx, vy = sim._vel[a].tolist()
        tr = float(sim._ref_time[a])
        r2 = sim._radius[a] ** 2
        ends = sim._seg_ends[k]

        def overlapping(s: float) -> bool:
            px, py = x + vx * (s - tr), y + vy * (s - tr)
            qx, qy = closest_point_on_segment(px, py, *ends)
            return (px - qx) ** 2 + (py - qy) ** 2 < r2

        return self._bisect(overlapping, s0)

    # --- responses -----------------------------------------------------------------------------------------
    def _moved(self, a: int, tc: float, x: float, y: float, vx: float, vy: float) -> None:
        """Disc ``a`` changed course at ``tc``, at ``(x, y)``: new path from there."""
        sim = self.sim
        if self.periodic:
            x, y = x % self.width, y % self.height
            if x >= self.width:
                x -= self.width
            if y >= self.height:
                y -= self.height
        sim._ref_pos[a] = (x, y)
        sim._ref_time[a] = tc
        sim._vel[a] = (vx, vy)
        self.version[a] = self.version.get(a, 0) + 1

    def _collide(self, tc: float, a: int, b: int) -> None:
        sim = self.sim
        xa, ya = self._at(a, tc)
        xb, yb = self._at(b, tc)
        dx, dy = xb - xa, yb - ya
        if self.periodic:
            dx -= self.width * round(dx / self.width)
            dy -= self.height * round(dy / self.height)
        vxa, vya = sim._vel[a].tolist()
        vxb, vyb = sim._vel[b].tolist()
        if (vxb - vxa) * dx + (vyb - vya) * dy >= 0.0:  # not approaching: nothing to do
            return
        sigma = sim._radius[a] + sim._radius[b]
        sim.max_overlap = max(sim.max_overlap, 1.0 - math.hypot(dx, dy) / sigma)
        uxa, uya, uxb, uyb = resolve_collision(dx, dy, vxa, vya, vxb, vyb, sim._masses[a], sim._masses[b])
        moving = sim._moving
        if moving[a]:
            self._moved(a, tc, xa, ya, uxa, uya)
        if moving[b]:
            self._moved(b, tc, xb, yb, uxb, uyb)
        sim.counts["detections"] += 1
        self.events.append(Event(tc, "collision", a, b))
        if self.log is not None:
            xa, ya = sim._ref_pos[a].tolist() if moving[a] else (xa, ya)
            xb, yb = sim._ref_pos[b].tolist() if moving[b] else (xb, yb)
            self.log.collision(tc, a, b, xa, ya, uxa, uya, xb, yb, uxb, uyb)
        if moving[a]:
            self._recheck(a, tc, _PAIR, b)
        if moving[b]:
            self._recheck(b, tc, _PAIR, a)

    def _wall(self, tc: float, a: int, wall: int) -> None:
        sim = self.sim
        axis, high = divmod(wall, 2)
        x, y = self._at(a, tc)
        vx, vy = sim._vel[a].tolist()
        v = (vx, vy)[axis]
        if (v <= 0.0) if high else (v >= 0.0):  # moving away from this wall already
            return
        if axis == 0:
            vx = -vx
        else:
            vy = -vy
        self._reflected(tc, a, x, y, vx, vy, _WALL, wall)

    def _segment(self, tc: float, a: int, k: int) -> None:
        sim = self.sim
        x, y = self._at(a, tc)
        vx, vy = sim._vel[a].tolist()
        ends = sim._seg_ends[k]
        qx, qy = closest_point_on_segment(x, y, *ends)
        if vx * (x - qx) + vy * (y - qy) >= 0.0:  # receding
            return
        vx, vy = reflect_off_segment(x, y, vx, vy, *ends)
        self._reflected(tc, a, x, y, vx, vy, _SEGMENT, k)

    def _reflected(self, tc: float, a: int, x: float, y: float, vx: float, vy: float, kind: int, other: int) -> None:
        sim = self.sim
        self._moved(a, tc, x, y, vx, vy)
        sim.counts["wall_hits"] += 1
        self.events.append(Event(tc, "wall", a, -1))
        if self.log is not None:
            self.log.wall(tc, a, *sim._ref_pos[a].tolist(), vx, vy)
        self._recheck(a, tc, kind, other)

    # --- after a change of course ------------------------------------------------------------------------
    def _recheck(self, a: int, now: float, kind: int, other: int) -> None:
        """Test disc ``a``'s new path over ``[now, t]`` against its neighbours, the walls and the segments.

        The partner of the response just made (``kind``, ``other``) is left
        out: after an elastic response the two separate, and straight paths
        do not meet again.
        """
        sim, t = self.sim, self.t
        span = t - now
        radius, vel = sim._radius, sim._vel
        x, y = sim._ref_pos[a].tolist()
        vx, vy = vel[a].tolist()
        r = radius[a]
        # Discs.
        self._file(a, now)
        ex, ey = x + vx * span, y + vy * span  # where the new path ends
        grow = 2.0 * sim._max_radius + self.table_reach
        lo = (min(x, ex) - grow, min(y, ey) - grow) if self.swept else (ex - grow, ey - grow)
        hi = (max(x, ex) + grow, max(y, ey) + grow) if self.swept else (ex + grow, ey + grow)
        nb = self._near(a, lo, hi, other if kind == _PAIR else -1)
        if nb:
            sim.counts["pair_tests"] += len(nb)
            periodic, width, height, swept = self.periodic, self.width, self.height, self.swept
            paths = zip(
                nb, sim._ref_pos[nb].tolist(), vel[nb].tolist(), sim._ref_time[nb].tolist(), sim._radii[nb].tolist()
            )
            for m, (px, py), (ux, uy), tm, rm in paths:
                dx, dy = px + ux * (now - tm) - x, py + uy * (now - tm) - y
                if periodic:
                    dx -= width * round(dx / width)
                    dy -= height * round(dy / height)
                dvx, dvy = ux - vx, uy - vy
                if swept:
                    tau = time_of_impact(dx, dy, dvx, dvy, r + rm)
                    if tau <= span:
                        self._push(now + tau, _PAIR, min(a, m), max(a, m))
                else:
                    gx, gy = dx + dvx * span, dy + dvy * span  # the gap at the frame
                    if gx * gx + gy * gy < (r + rm) * (r + rm):
                        self._push(self._bisect_pair(a, m, now), _PAIR, min(a, m), max(a, m))
        # Walls.
        if not self.periodic:
            for axis, (p, v, length) in enumerate(((x, vx, self.width), (y, vy, self.height))):
                wall = 2 * axis + int(v > 0.0)
                if v == 0.0 or (kind == _WALL and wall == other):
                    continue
                if self.swept:
                    tau = wall_time(p, v, r, length)
                    if tau <= span:
                        self._push(now + tau, _WALL, a, wall)
                else:
                    end = p + v * span
                    if (end > length - r) if v > 0.0 else (end < r):
                        self._push(self._bisect_wall(a, wall, now), _WALL, a, wall)
        # Segments.
        ends = sim._seg_ends
        if ends:
            sim.counts["segment_tests"] += len(ends)
            for k, segment in enumerate(ends):
                if kind == _SEGMENT and k == other:
                    continue
                if self.swept:
                    tau = segment_time_of_impact(x, y, vx, vy, r, *segment)
                    if tau <= span:
                        self._push(now + tau, _SEGMENT, a, k)
                else:
                    qx, qy = closest_point_on_segment(ex, ey, *segment)
                    if (ex - qx) ** 2 + (ey - qy) ** 2 < r * r:
                        self._push(self._bisect_segment(a, k, now), _SEGMENT, a, k)
