"""The fixed-step engine (PIT): move every disc one frame, then test for interference.

This is the periodic interference test of the study: time advances in frames
of length ``dt``; after each move the engine looks for pairs of discs that
overlap and discs that cross a wall, and responds after the fact with one of
three policies. Between frames discs fly straight, so the event log (one
record per response, with the state just after it) rebuilds the exact path
the engine took, and :meth:`~discsim.engine.Engine.trajectory` works as for
the event-driven engine.

A frame is vectorised with numpy: the move, the wall test, the broad phase
(:func:`discsim.grid.neighbour_pairs`, or all pairs) and the narrow phase are
array operations. Only the few pairs found overlapping are visited one by one,
in a fixed order (by first disc, then second disc), because a disc may sit in
several of them and each response changes the velocities the next one sees.

Policies (the issue's names):

- ``"resolve"``: apply the elastic impulse along the line of centres found at
  the frame, to approaching pairs, and leave the discs where they are;
- ``"revert"``: put the pair back where it was at the previous frame, then
  apply the impulse along the line of centres there;
- ``"separate"``: push the pair apart along the line of centres until the
  discs just touch (each moves in inverse proportion to its mass), then apply
  the impulse.

A disc found past a wall and still moving outwards has its normal velocity
reversed; under ``"revert"`` it goes back to its previous-frame position,
under ``"separate"`` it is clamped to touch the wall.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.engine import Engine, Event
from discsim.eventlog import EventLog
from discsim.grid import CellGrid, check_fits, neighbour_pairs
from discsim.kernels import resolve_collision
from discsim.state import Box, Discs

__all__ = ["BROAD_PHASES", "POLICIES", "FixedStep"]

#: Response policies of :class:`FixedStep`.
POLICIES = ("resolve", "revert", "separate")
#: Broad phases of :class:`FixedStep`.
BROAD_PHASES = ("grid", "all-pairs")

#: Default frames per unit of time.
DEFAULT_FRAME_RATE = 30.0
#: Candidate pairs tested at once by the all-pairs broad phase (bounds its memory).
_ALL_PAIRS_BLOCK = 1 << 21


def _positive_finite(name: str, value) -> float:
    if isinstance(value, bool):
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise ValueError(msg)
    try:
        number = float(value)
    except (TypeError, ValueError) as exc:
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise ValueError(msg) from exc
    if not (math.isfinite(number) and number > 0.0):
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise ValueError(msg)
    return number


class FixedStep(Engine):
    """Fixed-step simulation with a periodic interference test (PIT).

    Args:
        discs: the discs at ``time = 0``.
        box: the box (reflecting walls or periodic).
        frame_rate: frames per unit of time (default 30). Give this or ``dt``.
        dt: the frame interval (time units), instead of ``frame_rate``.
        policy: the response to a detected overlap: ``"resolve"`` (default),
            ``"revert"`` or ``"separate"`` (see the module docstring).
        broad_phase: ``"grid"`` (cell grid, O(N) per frame) or ``"all-pairs"``
            (every pair tested, O(N^2) per frame). Both give identical results.
        record: keep the event log (needed by ``events`` and ``trajectory``).

    Raises:
        ValueError: on a frame rate or ``dt`` that is not a positive finite
            number, both of them given and disagreeing, or an unknown policy or
            broad phase.
        OutsideBoxError, OverlapError: if the discs do not fit in the box.
        BoxTooSmallError: if a periodic box is under three disc diameters a
            side (as for :class:`~discsim.event_driven.EventDriven`).

    Attributes:
        time (float): the current time; frames fall at ``k * dt``.
        dt (float): the frame interval. frame_rate (float): ``1 / dt``.
        frames (int): frames done so far.
        counts (dict[str, int]): ``frames``; ``pair_tests`` (narrow-phase
            distance checks); ``detections`` (overlapping, approaching pairs
            that got an impulse); ``wall_hits`` (discs reflected by a wall).
        max_overlap (float): deepest overlap seen at any frame, as a fraction
            of the pair's contact distance (0 if discs never overlapped).

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
        >>> sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), frame_rate=4.0).run(until=2.5)
        >>> sim.counts["detections"], sim.velocities.tolist(), sim.max_overlap
        (1, [[-1.0, 0.0], [1.0, 0.0]], 0.25)
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
                    raise ValueError(msg)
            rate, by_rate = 1.0 / step, False
        if policy not in POLICIES:
            msg = f"policy must be one of {list(POLICIES)}, got {policy!r}"
            raise ValueError(msg)
        if broad_phase not in BROAD_PHASES:
            msg = f"broad_phase must be one of {list(BROAD_PHASES)}, got {broad_phase!r}"
            raise ValueError(msg)
        check_fits(discs, box)
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
        self.time = 0.0
        self.frames = 0
        self.max_overlap = 0.0
        self.counts = {"frames": 0, "pair_tests": 0, "detections": 0, "wall_hits": 0}
        self._cell_size = diameter
        self._radii = np.array(discs.radii)
        self._radius = discs.radii.tolist()
        self._masses = discs.masses.tolist()
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
            raise ValueError(msg)
        limit_t = math.inf if until is None else self._check_until(until)
        if frames is not None and (isinstance(frames, bool) or int(frames) != frames or frames < 0):
            msg = f"frames must be a non-negative integer, got {frames!r}"
            raise ValueError(msg)
        if limit_t == math.inf and frames is None:
            msg = "run(until=inf) never ends for a fixed-step engine; give frames=... as well"
            raise ValueError(msg)
        # Frames up to `until`, allowing for the roundoff of k * dt.
        due = math.inf
        if limit_t != math.inf:
            due = max(0, math.floor((limit_t - self.frame_time(self.frames)) / self.dt * (1 + 1e-12) + 1e-9))
        todo = int(min(due, math.inf if frames is None else int(frames)))
        if progress:
            from discsim.progress import progress_bar

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
            The :class:`~discsim.engine.Event` of each response in the frame
            (wall hits first, then disc pairs in the order they were handled);
            empty if nothing touched.

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

    def _candidates(self, pos: np.ndarray):
        """Candidate pairs of the broad phase, as chunks ``(i, j, d)``, ``d`` the minimum-image ``pos[j] - pos[i]``."""
        if self.broad_phase == "grid":
            yield neighbour_pairs(pos, self._cell_size, self.box)
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
            yield ii, jj, d

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
