"""The sub-frame policies: answer each contact inside the frame, at its contact time ("alternate PIC").

Candidates (pairs, walls, segments) go into a small queue by contact time (:class:`SubFrame`); each
response moves the discs back to the contact, applies the impulse there, and lets them finish the frame
with their new velocities; then the discs that changed course are tested again over the rest of the frame
against their broad-phase neighbours, the walls and the segments (a candidate of a disc that has changed
course since is dropped). The two policies differ in how they find a contact and its time:

- ``"bisect"`` (:class:`Bisect`): the interference test at the frame, as the frame policies do; for each
  overlap found, the frame interval is halved with the same test until the contact is known to
  ``bisect_tol`` (:func:`~discsim.kernels.time_of_impact_bisect`); the response is at the last time
  found without overlap. Costs ``counts["bisection_tests"]``. A disc that passes right through another
  (or a segment) between two frames is still missed.
- ``"swept"`` (:class:`Swept`): the swept-volume test: the relative motion of each pair over the frame
  (the capsule each centre sweeps, seen from the other disc) is tested for a distance below the contact
  distance, ``min over s in [0, 1] of |d + s dv dt| < sigma``; a disc's path against a segment likewise.
  The broad phase uses the positions at mid-frame and cells of side ``2 r_max + v_max dt``, which hold
  every pair that can touch during the frame. The contact time is the analytic root
  (:func:`~discsim.kernels.time_of_impact`, :func:`~discsim.kernels.segment_time_of_impact`), so fast
  small discs do not tunnel. In a periodic box the minimum image of a pair is taken at mid-frame, so a
  frame must move a disc less than about a quarter of the box (:meth:`Swept.check`).

Both stay approximations of the exact engine: ``"bisect"`` sees only the contacts that leave an overlap
at the frame (after the responses before them), and ``"swept"`` follows straight paths from the frame, so
it finds a chain of contacts inside one frame but takes each disc's course from the last response.
"""

from __future__ import annotations

import heapq
import math
from abc import abstractmethod

import numpy as np

from discsim.engines.fixed_step.arrays import Paths, Shapes, Tally
from discsim.engines.fixed_step.broad_phase import AllDiscs, BroadPhase, CellTable
from discsim.engines.fixed_step.frame import Policy, point_segment_distance, segments_cut, walls_crossed
from discsim.engines.fixed_step.parts import (
    impulse_virial,
    kinetic_loss,
    restitution,
    rough_pair,
    segment_bounce,
    spin_loss,
    wall_bounce,
)
from discsim.errors import InvalidArgumentError, JammedError
from discsim.events import Event, EventKind
from discsim.kernels import (
    closest_point_on_segment,
    resolve_collision,
    segment_time_of_impact,
    time_of_impact,
    time_of_impact_bisect,
    wall_time,
)
from discsim.model import minimum_image_1d
from discsim.physics.dynamics import advance

__all__ = ["SUB_FRAME_POLICY_CLASSES", "Bisect", "SubFrame", "SubFramePolicy", "Swept"]

COLLISION, WALL, SEGMENT = EventKind.COLLISION, EventKind.WALL, EventKind.SEGMENT


class SubFramePolicy(Policy):
    """What the two sub-frame policies share: the frame is a :class:`SubFrame`; the policy finds contacts."""

    def frame(self, paths: Paths, tally: Tally, t0: float, t: float) -> list[Event]:
        """Advance every disc from the frame at ``t0`` to ``t``, answering each contact at its time.

        Returns:
            The :class:`~discsim.events.Event` of each response, in the order of their contact times.
        """
        return SubFrame(self, paths, tally, t0, t).run()

    # --- the policy's part, used by SubFrame ------------------------------------------------------------
    @abstractmethod
    def detect(self, frame: SubFrame) -> None:
        """Queue the frame's first candidates; set ``frame.table_pos`` and ``frame.table_reach``."""

    @abstractmethod
    def path_box(self, x: float, y: float, ex: float, ey: float) -> tuple[tuple, tuple]:
        """``(lo, hi)``: the corners of the part of a new path from ``(x, y)`` to ``(ex, ey)`` that the tests see."""

    @abstractmethod
    def pair_contact(self, frame, a, m, now, span, dx, dy, dvx, dvy, sigma) -> float | None:
        """When disc ``a``'s new path (from ``now``) touches disc ``m``'s in the frame, or None.

        ``(dx, dy)``: the minimum-image ``m - a`` at ``now``; ``(dvx, dvy)``: ``v_m - v_a``;
        ``span``: the time left in the frame; ``sigma``: the contact distance.
        """

    @abstractmethod
    def wall_contact(self, frame, a, wall, now, span, p, v, r, length) -> float | None:
        """When disc ``a`` (coordinate ``p``, velocity ``v`` along the wall's axis) reaches ``wall``, or None."""

    @abstractmethod
    def segment_contact(self, frame, a, k, now, span, x, y, vx, vy, ex, ey, r, ends) -> float | None:
        """When disc ``a``'s new path from ``(x, y)`` at ``now`` to ``(ex, ey)`` touches segment ``k``, or None."""


class SubFrame:
    """One frame of a sub-frame policy: candidates in contact-time order, responses at the contact.

    Candidates are ``(time, seq, kind, a, b, stamp_a, stamp_b)`` in a heap: ``kind`` is an
    :class:`~discsim.events.EventKind`: ``COLLISION`` (discs ``a < b``), ``WALL`` (disc ``a``, wall
    ``b = 2 * axis + high``) or ``SEGMENT`` (disc ``a``, segment ``b``); the stamps are the discs'
    response counts in this frame when the candidate was found, so that a candidate of a disc that has
    changed course since is dropped (its new path was tested when it changed course).

    Args:
        policy: the :class:`SubFramePolicy`. paths: the discs' paths (changed in place).
        tally: the counters and the log. t0, t: the times of the previous frame and of this one.
    """

    def __init__(self, policy: SubFramePolicy, paths: Paths, tally: Tally, t0: float, t: float):
        self.policy = policy
        self.shapes = policy.shapes
        self.paths = paths
        self.tally = tally
        self.counts = tally.counts
        self.t0 = t0
        self.t = t
        self.heap: list = []
        self.seq = 0
        self.version: dict[int, int] = {}
        self.done: dict[tuple[int, int, int], float] = {}  # when each contact was last responded to
        self.events: list[Event] = []
        self.found: set = set()  # pairs that were candidates, for the overlap at the frame's end
        self.table_pos: np.ndarray = np.zeros((0, 2))  # where the broad phase saw the discs (set by detect)
        self.table_reach = 0.0  # how far (length) a disc unchanged in course can be from there
        self._table: CellTable | AllDiscs | None = None
        self.log = tally.log
        box = self.shapes.box
        self.periodic = box.periodic
        self.width, self.height = box.width, box.height

    # --- the frame ---------------------------------------------------------------------------------------
    #: A frame with more responses than this, plus this many per disc, raises JammedError: discs wedged
    #: against each other (an exactly touching lattice, say) would otherwise answer contacts for ever.
    MAX_RESPONSES = 1000
    MAX_RESPONSES_PER_DISC = 50

    def run(self) -> list[Event]:
        """Do the frame; return its events.

        Raises:
            JammedError: after more than ``MAX_RESPONSES + MAX_RESPONSES_PER_DISC * N`` responses in the frame.
        """
        self.policy.detect(self)
        heap, version, done = self.heap, self.version, self.done
        cap = self.MAX_RESPONSES + self.MAX_RESPONSES_PER_DISC * len(self.paths.velocities)
        answered = 0
        while heap:
            tc, _, kind, a, b, stamp_a, stamp_b = heapq.heappop(heap)
            if version.get(a, 0) != stamp_a or (kind == COLLISION and version.get(b, 0) != stamp_b):
                continue
            if done.get((kind, a, b)) == tc:
                # The same contact again at the same instant: a disc caught overlapping two things (a
                # wall and a segment, say) would be sent back and forth between them for ever.
                continue
            done[(kind, a, b)] = tc
            answered += 1
            if answered > cap:
                partner = f"disc {b}" if kind == COLLISION else "a wall or segment"
                msg = (
                    f"disc {a} and {partner} are jammed at time {tc!r}: this frame answered more than {cap} "
                    "contacts; give the discs room (a gap), or use a shorter frame"
                )
                raise JammedError(msg)
            if kind == COLLISION:
                self._collide(tc, a, b)
            elif kind == WALL:
                self._wall(tc, a, b)
            else:
                self._segment(tc, a, b)
        paths, shapes = self.paths, self.shapes
        pos = shapes.box.wrap(paths.flown(self.t))
        if self.found:
            pairs = np.array(sorted(self.found), dtype=np.int64).reshape(-1, 2)
            d = shapes.box.displacement(pos[pairs[:, 0]], pos[pairs[:, 1]])
            depth = 1.0 - np.hypot(d[:, 0], d[:, 1]) / (shapes.radii[pairs[:, 0]] + shapes.radii[pairs[:, 1]])
            self.tally.max_overlap = max(self.tally.max_overlap, float(depth.max()))
        paths.frame_positions = pos
        return self.events

    def push(self, tc: float, kind: EventKind, a: int, b: int) -> None:
        """Queue a candidate contact at time ``tc`` (see the class docstring for ``kind``, ``a``, ``b``)."""
        version = self.version
        stamp_b = version.get(b, 0) if kind == COLLISION else 0
        heapq.heappush(self.heap, (tc, self.seq, kind, a, b, version.get(a, 0), stamp_b))
        self.seq += 1
        if kind == COLLISION:
            self.found.add((a, b) if a < b else (b, a))

    def pairs(self, pos: np.ndarray, reach: float):
        """Broad-phase candidate pairs at ``pos``: ``(i, j, d)`` with ``i < j``, sorted by ``(i, j)``."""
        parts = []
        for i, j, d in self.policy.broad.pairs_within(pos, reach):
            self.counts["pair_tests"] += len(i)
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

    def path(self, a: int) -> tuple[float, float, float, float, float]:
        """Disc ``a``'s current path: ``(x, y, vx, vy, t_ref)``, at ``(x, y)`` at ``t_ref`` (not wrapped)."""
        paths = self.paths
        x, y = paths.ref_positions[a].tolist()
        vx, vy = paths.velocities[a].tolist()
        return x, y, vx, vy, float(paths.ref_times[a])

    def at(self, a: int, s: float) -> tuple[float, float]:
        """Centre of disc ``a`` at time ``s`` on its current path (not wrapped)."""
        x, y, vx, vy, tr = self.path(a)
        x, y, _, _ = advance(x, y, vx, vy, s - tr)
        return x, y

    def _near(self, a: int, lo: tuple[float, float], hi: tuple[float, float], partner: int) -> list[int]:
        """Discs that may touch disc ``a`` in the rest of the frame, sorted; ``a`` and ``partner`` left out.

        ``lo``, ``hi``: corners of a box that holds every point of ``a``'s new path that matters, grown
        by the largest contact distance and ``table_reach``. Discs are found through a cell table of the
        broad phase's positions, where each disc that changed course in this frame is also filed under
        the cells of its new path (see :meth:`_file`); the all-pairs broad phase returns every disc.
        """
        near = self._cell_table().near(lo, hi)
        near.discard(a)
        near.discard(partner)
        group, blocked = self.shapes.group, self.shapes.blocked
        if group is not None and blocked is not None:  # both or neither
            passes = blocked[group[a]]
            return sorted(m for m in near if not passes[group[m]])
        return sorted(near)

    def _cell_table(self) -> CellTable | AllDiscs:
        if self._table is None:
            self._table = self.policy.broad.table(self.table_pos, self.shapes.diameter + self.table_reach)
        return self._table

    def _file(self, a: int, now: float) -> None:
        """File disc ``a``, which changed course at ``now``, under the cells of its new path."""
        x, y = self.paths.ref_positions[a].tolist()
        vx, vy = self.paths.velocities[a].tolist()
        span = self.t - now
        ex, ey = x + vx * span, y + vy * span
        lo, hi = self.policy.path_box(x, y, ex, ey)
        self._cell_table().add(a, lo, hi)

    # --- responses -----------------------------------------------------------------------------------------
    def _collide(self, tc: float, a: int, b: int) -> None:
        shapes, paths, counts = self.shapes, self.paths, self.counts
        xa, ya = self.at(a, tc)
        xb, yb = self.at(b, tc)
        dx, dy = xb - xa, yb - ya
        if self.periodic:
            dx, dy = minimum_image_1d(dx, self.width), minimum_image_1d(dy, self.height)
        vxa, vya = paths.velocities[a].tolist()
        vxb, vyb = paths.velocities[b].tolist()
        if (vxb - vxa) * dx + (vyb - vya) * dy >= 0.0:  # not approaching: nothing to do
            return
        sigma = shapes.radius[a] + shapes.radius[b]
        self.tally.max_overlap = max(self.tally.max_overlap, 1.0 - math.hypot(dx, dy) / sigma)
        ma, mb = shapes.masses[a], shapes.masses[b]
        e = self._restitution(a, b, tc)
        uxa, uya, uxb, uyb = resolve_collision(dx, dy, vxa, vya, vxb, vyb, ma, mb, e)
        if shapes.rough:  # the tangential impulse at the contact point turns both
            spins, inertia = paths.spins, shapes.inertias
            paths.spin_to(a, tc)
            paths.spin_to(b, tc)
            wa, wb = float(spins[a]), float(spins[b])
            uxa, uya, uxb, uyb, spins[a], spins[b] = rough_pair(
                dx, dy, vxa, vya, vxb, vyb, uxa, uya, uxb, uyb, wa, wb, shapes.radius[a], shapes.radius[b], ma, mb,
                inertia[a], inertia[b], shapes.beta,
            )  # fmt: skip
            self.tally.dissipated += spin_loss(inertia[a], wa, float(spins[a]))
            self.tally.dissipated += spin_loss(inertia[b], wb, float(spins[b]))
        if e != 1.0 or shapes.rough:
            self.tally.dissipated += kinetic_loss(ma, vxa, vya, uxa, uya) + kinetic_loss(mb, vxb, vyb, uxb, uyb)
        if shapes.tc > 0.0:  # the TC model's clocks (an obstacle keeps none, as in EventDriven)
            for d in (a, b):
                if shapes.moving[d]:
                    self.paths.last_collision[d] = tc
        self.tally.virial += impulse_virial(dx, dy, vxa, vya, uxa, uya, vxb, vyb, uxb, uyb, ma, mb)
        moving = shapes.moving
        if moving[a]:
            xa, ya = self._turn(a, tc, xa, ya, uxa, uya)
        if moving[b]:
            xb, yb = self._turn(b, tc, xb, yb, uxb, uyb)
        counts["detections"] += 1
        self.events.append(Event(tc, "collision", a, b))
        if self.log is not None:
            self.log.collision(tc, a, b, xa, ya, uxa, uya, xb, yb, uxb, uyb)
        if moving[a]:
            self._recheck(a, tc, COLLISION, b)
        if moving[b]:
            self._recheck(b, tc, COLLISION, a)

    def _wall(self, tc: float, a: int, wall: int) -> None:
        axis, high = divmod(wall, 2)
        x, y = self.at(a, tc)
        vx, vy = self.paths.velocities[a].tolist()
        v = (vx, vy)[axis]
        if (v <= 0.0) if high else (v >= 0.0):  # moving away from this wall already
            return
        e = self._restitution(a, a, tc)
        shapes, w = self.shapes, float(self.paths.spins[a])
        r, m, inertia = shapes.radius[a], shapes.masses[a], shapes.inertias[a]
        ux, uy, w = wall_bounce(vx, vy, axis, not high, e, w, r, m, inertia, shapes.beta)
        self._reflected(tc, a, x, y, vx, vy, ux, uy, e, WALL, wall, w)

    def _segment(self, tc: float, a: int, k: int) -> None:
        x, y = self.at(a, tc)
        vx, vy = self.paths.velocities[a].tolist()
        ax, ay, bx, by = self.shapes.seg_ends[k]
        qx, qy = closest_point_on_segment(x, y, ax, ay, bx, by)
        if vx * (x - qx) + vy * (y - qy) >= 0.0:  # receding
            return
        e = self._restitution(a, a, tc)
        shapes, w = self.shapes, float(self.paths.spins[a])
        r, m, inertia = shapes.radius[a], shapes.masses[a], shapes.inertias[a]
        ux, uy, w = segment_bounce(x, y, vx, vy, ax, ay, bx, by, e, w, r, m, inertia, shapes.beta)
        self._reflected(tc, a, x, y, vx, vy, ux, uy, e, SEGMENT, k, w)

    def _restitution(self, a: int, b: int, now: float) -> float:
        """The restitution of a response of discs ``a`` and ``b`` (``a`` twice: a wall or segment) at ``now``."""
        shapes = self.shapes
        return restitution(
            a, b, now, shapes.e, shapes.per_group, shapes.e_table, shapes.e_group, shapes.tc, self.paths.last_collision
        )

    def _reflected(self, tc, a, x, y, wx, wy, vx, vy, e, kind: EventKind, other: int, spin: float) -> None:
        """Disc ``a`` bounced at ``tc`` at ``(x, y)`` from velocity ``(wx, wy)`` to ``(vx, vy)`` (restitution ``e``),
        its spin now ``spin``."""
        shapes, paths = self.shapes, self.paths
        if shapes.rough:
            paths.spin_to(a, tc)
            self.tally.dissipated += spin_loss(shapes.inertias[a], float(paths.spins[a]), spin)
            paths.spins[a] = spin
        if e != 1.0 or shapes.rough:
            self.tally.dissipated += kinetic_loss(self.shapes.masses[a], wx, wy, vx, vy)
        if self.shapes.tc > 0.0:
            self.paths.last_collision[a] = tc
        x, y = self._turn(a, tc, x, y, vx, vy)
        self.counts["wall_hits"] += 1
        self.events.append(Event(tc, "wall", a, -1))
        if self.log is not None:
            self.log.wall(tc, a, x, y, vx, vy)
        self._recheck(a, tc, kind, other)

    def _turn(self, a: int, tc: float, x: float, y: float, vx: float, vy: float) -> tuple[float, float]:
        """Disc ``a`` changes course at ``tc`` at ``(x, y)``; returns its new reference position (wrapped)."""
        self.version[a] = self.version.get(a, 0) + 1
        return self.paths.turn(a, tc, x, y, vx, vy)

    # --- after a change of course ------------------------------------------------------------------------
    def _recheck(self, a: int, now: float, kind: EventKind, other: int) -> None:
        """Test disc ``a``'s new path over ``[now, t]`` against its neighbours, the walls and the segments.

        The partner of the response just made (``kind``, ``other``) is left out: after an elastic
        response the two separate, and straight paths do not meet again.
        """
        policy, shapes, paths = self.policy, self.shapes, self.paths
        span = self.t - now
        x, y, vx, vy, _ = self.path(a)
        r = shapes.radius[a]
        # Discs.
        self._file(a, now)
        ex, ey = x + vx * span, y + vy * span  # where the new path ends
        grow = 2.0 * shapes.max_radius + self.table_reach
        (lo_x, lo_y), (hi_x, hi_y) = policy.path_box(x, y, ex, ey)
        nb = self._near(a, (lo_x - grow, lo_y - grow), (hi_x + grow, hi_y + grow), other if kind == COLLISION else -1)
        if nb:
            self.counts["pair_tests"] += len(nb)
            periodic, width, height = self.periodic, self.width, self.height
            neighbours = zip(
                nb,
                paths.ref_positions[nb].tolist(),
                paths.velocities[nb].tolist(),
                paths.ref_times[nb].tolist(),
                shapes.radii[nb].tolist(),
            )
            for m, (px, py), (ux, uy), tm, rm in neighbours:
                # Free flight and the minimum image (minimum_image_1d) inline: this loop runs per neighbour.
                dx, dy = px + ux * (now - tm) - x, py + uy * (now - tm) - y
                if periodic:
                    dx -= width * round(dx / width)
                    dy -= height * round(dy / height)
                tc = policy.pair_contact(self, a, m, now, span, dx, dy, ux - vx, uy - vy, r + rm)
                if tc is not None:
                    self.push(tc, COLLISION, min(a, m), max(a, m))
        # Walls.
        if not self.periodic:
            for axis, (p, v, length) in enumerate(((x, vx, self.width), (y, vy, self.height))):
                wall = 2 * axis + int(v > 0.0)
                if v == 0.0 or (kind == WALL and wall == other):
                    continue
                tc = policy.wall_contact(self, a, wall, now, span, p, v, r, length)
                if tc is not None:
                    self.push(tc, WALL, a, wall)
        # Segments.
        ends = shapes.seg_ends
        if ends:
            self.counts["segment_tests"] += len(ends)
            for k, segment in enumerate(ends):
                if kind == SEGMENT and k == other:
                    continue
                tc = policy.segment_contact(self, a, k, now, span, x, y, vx, vy, ex, ey, r, segment)
                if tc is not None:
                    self.push(tc, SEGMENT, a, k)


class Bisect(SubFramePolicy):
    """The ``"bisect"`` policy: interference tests at the frame, then each contact time by bisection.

    Args:
        shapes, broad: as for :class:`SubFramePolicy`. tol: the tolerance on contact times (time).
    """

    name = "bisect"

    def __init__(self, shapes: Shapes, broad: BroadPhase, tol: float):
        super().__init__(shapes, broad)
        self.tol = tol

    def detect(self, frame: SubFrame) -> None:
        shapes, paths, t0 = self.shapes, frame.paths, frame.t0
        vel, radii = paths.velocities, shapes.radii
        pos = shapes.box.wrap(paths.flown(frame.t))
        frame.table_pos = pos
        i, j, d = frame.pairs(pos, shapes.diameter)
        contact = radii[i] + radii[j]
        hit = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] < contact * contact
        for a, b in zip(i[hit].tolist(), j[hit].tolist()):
            frame.push(self._bisect_pair(frame, a, b, t0), COLLISION, a, b)
        if not frame.periodic:
            low, high = walls_crossed(pos, vel, radii, shapes.box.size)
            for a, axis in zip(*np.nonzero(low | high)):
                wall = 2 * int(axis) + int(high[a, axis])
                frame.push(self._bisect_wall(frame, int(a), wall, t0), WALL, int(a), wall)
        if shapes.seg_ends:
            for a, k in zip(*segments_cut(pos, shapes, frame.counts)):
                frame.push(self._bisect_segment(frame, int(a), int(k), t0), SEGMENT, int(a), int(k))

    def path_box(self, x, y, ex, ey):
        return (ex, ey), (ex, ey)  # where it ends: the test is at the frame

    def pair_contact(self, frame, a, m, now, span, dx, dy, dvx, dvy, sigma):
        gx, gy = dx + dvx * span, dy + dvy * span  # the gap at the frame
        if gx * gx + gy * gy < sigma * sigma:
            return self._bisect_pair(frame, a, m, now)
        return None

    def wall_contact(self, frame, a, wall, now, span, p, v, r, length):
        end = p + v * span
        if (end > length - r) if v > 0.0 else (end < r):
            return self._bisect_wall(frame, a, wall, now)
        return None

    def segment_contact(self, frame, a, k, now, span, x, y, vx, vy, ex, ey, r, ends):
        qx, qy = closest_point_on_segment(ex, ey, *ends)
        if (ex - qx) ** 2 + (ey - qy) ** 2 < r * r:
            return self._bisect_segment(frame, a, k, now)
        return None

    # --- contact times by bisection ---------------------------------------------------------------------
    def _bisect(self, frame: SubFrame, test, s0: float) -> float:
        """The last time without overlap in ``[s0, t]``, overlap at ``t`` being known; counts the tests."""
        calls = [1]

        def counted(s: float) -> bool:
            calls[0] += 1
            return test(s)

        if test(s0):  # overlapping already where the interval starts: respond there
            found = s0
        else:
            found = time_of_impact_bisect(counted, s0, frame.t, self.tol)
        frame.counts["bisection_tests"] += calls[0]
        return found

    def _bisect_pair(self, frame: SubFrame, a: int, b: int, s0: float) -> float:
        xa, ya, ua, wa, ta = frame.path(a)
        xb, yb, ub, wb, tb = frame.path(b)
        sigma2 = (self.shapes.radius[a] + self.shapes.radius[b]) ** 2
        periodic, width, height = frame.periodic, frame.width, frame.height

        def overlapping(s: float) -> bool:  # free flight and minimum_image_1d inline: the bisection's test
            dx = xb + ub * (s - tb) - (xa + ua * (s - ta))
            dy = yb + wb * (s - tb) - (ya + wa * (s - ta))
            if periodic:
                dx -= width * round(dx / width)
                dy -= height * round(dy / height)
            return dx * dx + dy * dy < sigma2

        return self._bisect(frame, overlapping, s0)

    def _bisect_wall(self, frame: SubFrame, a: int, wall: int, s0: float) -> float:
        axis, high = divmod(wall, 2)
        paths = frame.paths
        x = float(paths.ref_positions[a, axis])
        v = float(paths.velocities[a, axis])
        tr = float(paths.ref_times[a])
        r = self.shapes.radius[a]
        limit = (frame.width if axis == 0 else frame.height) - r

        def overlapping(s: float) -> bool:
            position = x + v * (s - tr)
            return position > limit if high else position < r

        return self._bisect(frame, overlapping, s0)

    def _bisect_segment(self, frame: SubFrame, a: int, k: int, s0: float) -> float:
        x, y, vx, vy, tr = frame.path(a)
        r2 = self.shapes.radius[a] ** 2
        ends = self.shapes.seg_ends[k]

        def overlapping(s: float) -> bool:
            px, py = x + vx * (s - tr), y + vy * (s - tr)
            qx, qy = closest_point_on_segment(px, py, *ends)
            return (px - qx) ** 2 + (py - qy) ** 2 < r2

        return self._bisect(frame, overlapping, s0)


class Swept(SubFramePolicy):
    """The ``"swept"`` policy: swept-volume tests over the frame, then each contact time analytically."""

    name = "swept"

    def check(self, paths: Paths, dt: float) -> None:
        """Refuse a frame whose relative sweeps could reach a second periodic image.

        The swept test follows one image per pair (the nearest at mid-frame), which is exact while two
        discs' relative path over a frame plus their contact distance stays under half the box's
        shorter side.

        Raises:
            InvalidArgumentError: naming the speed, ``dt`` and the box.
        """
        box = self.shapes.box
        if not box.periodic:
            return
        vel = paths.velocities
        speed = float(np.sqrt(np.max(np.einsum("ij,ij->i", vel, vel), initial=0.0)))
        diameter = self.shapes.diameter
        reach = 2.0 * speed * dt + 2.0 * self.shapes.max_radius
        half = 0.5 * min(box.width, box.height)
        if reach >= half:
            msg = (
                f"policy 'swept' in a periodic box needs 2 v_max dt + 2 r_max < half the box side: "
                f"2 * {speed:.6g} * {dt:.6g} + {diameter:.6g} = {reach:.6g} >= {half:.6g}; "
                "use a smaller dt or a larger box"
            )
            raise InvalidArgumentError(msg)

    def detect(self, frame: SubFrame) -> None:
        shapes, paths, t, t0 = self.shapes, frame.paths, frame.t, frame.t0
        span = t - t0
        vel, radii = paths.velocities, shapes.radii
        start = paths.frame_positions  # the positions at t0
        speed = float(np.sqrt((vel * vel).sum(axis=1)).max()) if len(vel) else 0.0
        reach = shapes.diameter + speed * span
        mid = shapes.box.wrap(start + vel * (0.5 * span))
        frame.table_pos, frame.table_reach = mid, 0.5 * speed * span
        i, j, d = frame.pairs(mid, reach)
        if len(i):
            dv = vel[j] - vel[i]
            d0 = d - dv * (0.5 * span)
            sweep = dv * span
            sweep2 = np.sum(sweep * sweep, axis=1)
            s = np.clip(np.divide(-np.sum(d0 * sweep, axis=1), sweep2, out=np.zeros(len(i)), where=sweep2 > 0), 0, 1)
            closest = d0 + s[:, None] * sweep
            contact = radii[i] + radii[j]
            hit = np.sum(closest * closest, axis=1) <= contact * contact  # touching at the frame counts
            hits = zip(i[hit].tolist(), j[hit].tolist(), d0[hit].tolist(), dv[hit].tolist(), contact[hit].tolist())
            for a, b, (dx, dy), (dvx, dvy), sigma in hits:
                tau = time_of_impact(dx, dy, dvx, dvy, sigma)
                if tau <= span:
                    frame.push(t0 + tau, COLLISION, a, b)
        if not frame.periodic:
            for axis, length in ((0, frame.width), (1, frame.height)):
                x, v, r = start[:, axis], vel[:, axis], radii
                with np.errstate(divide="ignore", invalid="ignore"):
                    wt = np.where(v > 0.0, (length - r - x) / v, np.where(v < 0.0, (r - x) / v, np.inf))
                for a in np.flatnonzero(wt <= span).tolist():
                    frame.push(t0 + max(float(wt[a]), 0.0), WALL, a, 2 * axis + int(vel[a, axis] > 0.0))
        if shapes.seg_ends:
            frame.counts["segment_tests"] += len(start) * len(shapes.seg_ends)
            dist = _segment_segment_distance(start, start + vel * span, shapes.seg_a, shapes.seg_b)
            ends = shapes.seg_ends
            for a, k in zip(*np.nonzero(dist <= radii[:, None])):
                a, k = int(a), int(k)
                (x, y), (vx, vy) = start[a].tolist(), vel[a].tolist()
                tau = segment_time_of_impact(x, y, vx, vy, shapes.radius[a], *ends[k])
                if tau <= span:
                    frame.push(t0 + tau, SEGMENT, a, k)

    def path_box(self, x, y, ex, ey):
        return (min(x, ex), min(y, ey)), (max(x, ex), max(y, ey))  # the whole path

    def pair_contact(self, frame, a, m, now, span, dx, dy, dvx, dvy, sigma):
        tau = time_of_impact(dx, dy, dvx, dvy, sigma)
        return now + tau if tau <= span else None

    def wall_contact(self, frame, a, wall, now, span, p, v, r, length):
        tau = wall_time(p, v, r, length)
        return now + tau if tau <= span else None

    def segment_contact(self, frame, a, k, now, span, x, y, vx, vy, ex, ey, r, ends):
        tau = segment_time_of_impact(x, y, vx, vy, r, *ends)
        return now + tau if tau <= span else None


#: The sub-frame policies by name.
SUB_FRAME_POLICY_CLASSES = {policy.name: policy for policy in (Bisect, Swept)}


def _segment_segment_distance(p0: np.ndarray, p1: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance ``(N, S)`` between paths ``p0``-``p1`` ``(N, 2)`` and segments ``a``-``b`` ``(S, 2)``."""
    p0, p1 = p0[:, None, :], p1[:, None, :]
    a, b = a[None], b[None]
    dist = np.minimum(
        np.minimum(point_segment_distance(p0, a, b), point_segment_distance(p1, a, b)),
        np.minimum(point_segment_distance(a, p0, p1), point_segment_distance(b, p0, p1)),
    )

    def cross(u, v):
        return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

    e, f = b - a, p1 - p0
    crossing = (cross(e, p0 - a) * cross(e, p1 - a) < 0.0) & (cross(f, a - p0) * cross(f, b - p0) < 0.0)
    return np.where(crossing, 0.0, dist)
