"""The frame policies: move every disc one frame, then answer what overlaps, after the fact.

A frame is vectorised with numpy: the move, the wall and segment tests, the broad phase and the narrow
phase are array operations; only the few discs found past a wall, cutting a segment or overlapping are
visited one by one. Wall hits are answered first, then segment hits, then the overlapping pairs, in a
fixed order (by first disc, then second disc), because a disc may sit in several pairs and each response
changes the velocities the next one sees. The three policies differ in where they leave the discs:

- ``"resolve"`` (:class:`Resolve`): where they were found. A pair gets the elastic impulse along the
  line of centres at the frame (if approaching); a disc past a wall and moving outwards has its normal
  velocity reversed; a disc cutting a segment and approaching it is reflected off it
  (:func:`~discsim.kernels.reflect_off_segment`, the normal from the segment's nearest point to the centre).
  Rough discs (``roughness`` above -1) get the tangential impulse at the contact point too, and turn
  (:func:`~discsim.engines.fixed_step.parts.rough_pair`, ``wall_bounce``, ``segment_bounce``).
- ``"revert"`` (:class:`Revert`): back where they were at the previous frame; a pair's impulse is along
  the line of centres there (if the pair approaches along it).
- ``"separate"`` (:class:`Separate`): pushed apart along the line of centres until they just touch (each
  in inverse proportion to its mass), clamped to touch a wall, pushed out along the normal to touch a
  segment; then the impulse or the reflection.

The interference tests (:func:`walls_crossed`, :func:`segments_cut`) serve the ``"bisect"`` policy too.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

import numpy as np

from discsim.engines.fixed_step.arrays import Paths, Shapes, Tally
from discsim.engines.fixed_step.broad_phase import BroadPhase
from discsim.engines.fixed_step.parts import (
    impulse_virial,
    kinetic_loss,
    moving_segment_bounce,
    push_off_segment,
    restitution,
    rough_pair,
    separate_pair,
    spin_loss,
    wall_bounce,
)
from discsim.events import Event
from discsim.kernels import closest_point_on_segment, resolve_collision
from discsim.model import minimum_image_1d

__all__ = [
    "FRAME_POLICY_CLASSES",
    "FramePolicy",
    "Resolve",
    "Revert",
    "Separate",
    "point_segment_distance",
    "segments_cut",
    "walls_crossed",
]


def point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points ``p`` to segments ``a``-``b`` (broadcast shapes ``(..., 2)``; ``a == b`` allowed)."""
    e = b - a
    ee = np.sum(e * e, axis=-1)
    w = p - a
    u = np.divide(np.sum(w * e, axis=-1), ee, out=np.zeros(np.broadcast_shapes(ee.shape, w.shape[:-1])), where=ee > 0)
    u = np.clip(u, 0.0, 1.0)
    off = w - u[..., None] * e
    return np.hypot(off[..., 0], off[..., 1])


def walls_crossed(pos: np.ndarray, vel: np.ndarray, radii: np.ndarray, size: np.ndarray):
    """``(low, high)``: ``(N, 2)`` bool, discs past the wall at 0 (or at ``size``) and still moving outwards."""
    r = radii[:, None]
    return (pos < r) & (vel < 0.0), (pos > size - r) & (vel > 0.0)


def segments_cut(pos: np.ndarray, shapes: Shapes, counts: dict[str, int], ends=None):
    """``(discs, segments)``: int arrays of the pairs where a segment cuts a disc at ``pos``; counts the tests.

    ``ends``: ``(seg_a, seg_b)``, where the segments are (:meth:`Shapes.segments_at`; None: at time 0).
    """
    counts["segment_tests"] += len(pos) * len(shapes.seg_ends)
    seg_a, seg_b = (shapes.seg_a, shapes.seg_b) if ends is None else ends
    dist = point_segment_distance(pos[:, None, :], seg_a[None], seg_b[None])
    return np.nonzero(dist < shapes.radii[:, None])


class Policy(ABC):
    """What every policy shares: the scene as arrays, the broad phase, and a check before each frame.

    Args:
        shapes: the scene as arrays. broad: the broad phase.
    """

    name = ""

    def __init__(self, shapes: Shapes, broad: BroadPhase):
        self.shapes = shapes
        self.broad = broad

    def check(self, paths: Paths, dt: float) -> None:
        """Refuse a frame this policy cannot do (raise before anything changes)."""
        return  # most policies can do any frame

    @abstractmethod
    def frame(self, paths: Paths, tally: Tally, t0: float, t: float) -> list[Event]:
        """Advance every disc from the frame at ``t0`` to the frame at ``t`` and answer what touches."""


class FramePolicy(Policy):
    """The frame shared by the three policies that answer at the frame; its answers are ``"resolve"``'s.

    Subclasses override where the discs are left (:meth:`off_walls`, :meth:`off_segments`,
    :meth:`off_segment`) and the line of centres of a pair's impulse (:meth:`contact`).
    """

    def frame(self, paths: Paths, tally: Tally, t0: float, t: float) -> list[Event]:
        """Move every disc from the frame at ``t0`` to ``t``, then answer what overlaps there.

        Returns:
            The :class:`~discsim.events.Event` of each response: wall hits, segment hits, then pairs.
        """
        box = self.shapes.box
        prev = paths.frame_positions
        flown = paths.flown(t)
        if paths.drag != 0.0 and paths.falls is not None:  # what the drag took since the last frame
            tally.lose(paths.drag_loss(t, self.shapes.mass))
        paths.fall(t, flown)  # under gravity or drag: the velocities at the frame
        pos = box.wrap(flown)
        events: list[Event] = []
        if not box.periodic:
            pos = self._walls(t, prev, pos, paths, tally, events)
        if self.shapes.seg_ends:
            self._segments(t, prev, pos, paths, tally, events)
        ii, jj = self._overlapping_pairs(pos, tally)
        if ii:
            self._pairs(t, ii, jj, prev, pos, flown, paths, tally, events)
            pos = box.wrap(pos)
        paths.frame_positions = pos
        return events

    # --- what each policy changes -------------------------------------------------------------------------
    def off_walls(self, pos, prev, rows, low, high, r, size) -> np.ndarray:
        """Where discs ``rows`` found past a wall (``low``, ``high``: see :func:`walls_crossed`) are left."""
        return pos

    def off_segments(self, x, y, vx, vy, previous, hits, r, e=1.0, turn=(0.0, 1.0, math.inf, -1.0), speeds=None):
        """Answer one disc at ``(x, y)`` moving at ``(vx, vy)`` that cuts segments ``hits`` (end point tuples).

        The segments are visited in order, each seeing the position and velocity the one before left
        (a disc in a corner may touch two). ``previous``: the disc's ``(2,)`` position at the previous frame;
        ``e``: the restitution of its bounces; ``turn``: ``(spin, mass, inertia, roughness)`` (smooth: -1);
        ``speeds``: each segment's velocity ``(fx, fy)`` (None: all fixed): a moving segment is approached,
        and bounces the disc, in its own frame (:func:`~discsim.engines.fixed_step.parts.moving_segment_bounce`).

        Returns:
            ``(x, y, vx, vy, spin, responded)``.
        """
        responded = False
        w, m, inertia, beta = turn
        for k, ends in enumerate(hits):
            fx, fy = (0.0, 0.0) if speeds is None else speeds[k]
            qx, qy = closest_point_on_segment(x, y, *ends)
            nx, ny = x - qx, y - qy
            if (vx - fx) * nx + (vy - fy) * ny >= 0.0:  # receding (or the centre is on the segment): leave it
                continue
            x, y = self.off_segment(x, y, qx, qy, nx, ny, r)
            vx, vy, w = moving_segment_bounce(x, y, vx, vy, *ends, fx, fy, e, w, r, m, inertia, beta)
            responded = True
        return x, y, vx, vy, w, responded

    def off_segment(self, x, y, qx, qy, nx, ny, r) -> tuple[float, float]:
        """Where a disc at ``(x, y)`` approaching a segment is left (nearest point ``(qx, qy)``, normal ``n``)."""
        return x, y

    def contact(self, xi, yi, xj, yj, dx, dy, dvx, dvy, mi, mj, sigma, before_i, before_j):
        """An approaching pair: where its discs are left, and the line of centres of its impulse.

        Args:
            xi, yi, xj, yj: the discs' positions at the frame. dx, dy: the minimum-image ``j - i`` there.
            dvx, dvy: the relative velocity ``v_j - v_i``. mi, mj: the masses. sigma: the contact distance.
            before_i, before_j: the discs' positions at the previous frame (None unless :attr:`uses_previous`).

        Returns:
            ``(xi, yi, xj, yj, dx, dy)``.
        """
        return xi, yi, xj, yj, dx, dy

    #: Whether :meth:`contact` reads the positions at the previous frame.
    uses_previous = False

    # --- the frame, step by step ----------------------------------------------------------------------------
    def _walls(self, t, prev, pos, paths, tally, events) -> np.ndarray:
        """Discs past a wall and still moving outwards: reverse the normal velocity; return the positions."""
        shapes = self.shapes
        vel = paths.velocities
        size = shapes.box.size
        low, high = walls_crossed(pos, vel, shapes.radii, size)
        hit = low | high
        if not hit.any():
            return pos
        rows = np.flatnonzero(hit.any(axis=1))
        self._reflect_off_walls(t, rows, hit, low, paths, tally)
        pos = self.off_walls(pos, prev, rows, low, high, self.shapes.radii[:, None], size)
        paths.restart(rows, pos[rows], t)  # a walled box: no images
        tally.counts["wall_hits"] += len(rows)
        log = tally.log
        for i in rows.tolist():
            events.append(Event(t, "wall", i, -1))
            if log is not None:
                log.wall(t, i, *pos[i].tolist(), *vel[i].tolist())
        return pos

    def _reflect_off_walls(self, t, rows, hit, low, paths, tally) -> None:
        """Reverse the normal velocity of discs ``rows`` along each axis ``hit`` ``(N, 2)`` (on the ``low`` side
        ``(N, 2)`` or the high one), with restitution and roughness."""
        shapes, vel, last, spins = self.shapes, paths.velocities, paths.last_collision, paths.spins
        e0, per_group, table, group, tc = shapes.e, shapes.per_group, shapes.e_table, shapes.e_group, shapes.tc
        rough, beta = shapes.rough, shapes.beta
        for i, (vx, vy), hits, lows in zip(rows.tolist(), vel[rows].tolist(), hit[rows].tolist(), low[rows].tolist()):
            e = restitution(i, i, t, e0, per_group, table, group, tc, last)
            m, inertia, r = shapes.masses[i], shapes.inertias[i], shapes.radius[i]
            if rough:
                paths.spin_to(i, t)
            w0 = w = float(spins[i])
            ux, uy = vx, vy
            for axis in (0, 1):
                u = ux if axis == 0 else uy
                if hits[axis] and ((u < 0.0) if lows[axis] else (u > 0.0)):  # still outwards: a rough bounce off
                    # the other wall (a corner) may have turned it away already
                    ux, uy, w = wall_bounce(ux, uy, axis, lows[axis], e, w, r, m, inertia, beta)
            vel[i] = (ux, uy)
            if e != 1.0 or rough:
                tally.dissipated += kinetic_loss(m, vx, vy, ux, uy)
            if rough:
                spins[i] = w
                tally.dissipated += spin_loss(inertia, w0, w)
            if tc > 0.0:
                last[i] = t

    def _segments(self, t, prev, pos, paths, tally, events) -> None:
        """Discs cutting a segment at ``pos``; updates ``pos`` and the paths in place."""
        shapes = self.shapes
        seg_a, seg_b, ends = shapes.segments_at(t)  # where the segments are at the frame
        rows, cols = segments_cut(pos, shapes, tally.counts, (seg_a, seg_b))
        if not len(rows):
            return
        vel, last, spins = paths.velocities, paths.last_collision, paths.spins
        radius, seg_speeds = shapes.radius, shapes.seg_speeds if shapes.seg_moving else None
        e0, per_group, table, group, tc = shapes.e, shapes.per_group, shapes.e_table, shapes.e_group, shapes.tc
        rough, beta = shapes.rough, shapes.beta
        log = tally.log
        by_disc: dict[int, list[int]] = {}
        for i, k in zip(rows.tolist(), cols.tolist()):
            by_disc.setdefault(i, []).append(k)
        for i, cut in by_disc.items():
            x, y = pos[i].tolist()
            wx, wy = vel[i].tolist()
            e = restitution(i, i, t, e0, per_group, table, group, tc, last)
            w0 = float(spins[i])
            turn = (w0, shapes.masses[i], shapes.inertias[i], beta)
            hits, speeds = [ends[k] for k in cut], None if seg_speeds is None else [seg_speeds[k] for k in cut]
            x, y, vx, vy, w, responded = self.off_segments(x, y, wx, wy, prev[i], hits, radius[i], e, turn, speeds)
            if responded:
                if speeds is not None:  # what the bounces took, in the segments' frames (a moving one does work)
                    fx, fy = speeds[0]
                    tally.dissipated += kinetic_loss(shapes.masses[i], wx - fx, wy - fy, vx - fx, vy - fy)
                elif e != 1.0 or rough:
                    tally.dissipated += kinetic_loss(shapes.masses[i], wx, wy, vx, vy)
                if rough:
                    paths.spin_to(i, t)
                    spins[i] = w
                    tally.dissipated += spin_loss(shapes.inertias[i], w0, w)
                if tc > 0.0:
                    last[i] = t
                pos[i] = (x, y)
                vel[i] = (vx, vy)
                paths.restart(i, (x, y), t)  # a walled box: no images
                tally.counts["wall_hits"] += 1
                events.append(Event(t, "wall", i, -1))
                if log is not None:
                    log.wall(t, i, x, y, vx, vy)

    def _overlapping_pairs(self, pos: np.ndarray, tally: Tally):
        """Pairs ``(i, j)`` with ``i < j`` whose discs overlap at ``pos``, sorted by ``i`` then ``j``."""
        parts_i, parts_j = [], []
        radii = self.shapes.radii
        for i, j, d in self.broad.frame_pairs(pos, tally.counts):
            tally.counts["pair_tests"] += len(i)
            contact = radii[i] + radii[j]
            dist2 = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]
            hit = dist2 < contact * contact
            if hit.any():
                depth = 1.0 - np.sqrt(dist2[hit]) / contact[hit]
                tally.max_overlap = max(tally.max_overlap, float(depth.max()))
            parts_i.append(i[hit])
            parts_j.append(j[hit])
        if not parts_i:
            return [], []
        i = np.concatenate(parts_i)
        j = np.concatenate(parts_j)
        i, j = np.minimum(i, j), np.maximum(i, j)
        order = np.lexsort((j, i))
        return i[order].tolist(), j[order].tolist()

    def _pairs(self, t, ii, jj, prev, pos, flown, paths, tally, events) -> None:
        """Answer the overlapping pairs ``ii[k] < jj[k]`` in order; updates ``pos`` and the paths in place.

        The discs involved are read into Python floats once and written back once (a pair sees the
        velocities left by the pairs before it in the frame).
        """
        shapes = self.shapes
        mass, radius = shapes.masses, shapes.radius
        box = shapes.box
        periodic, width, height = box.periodic, box.width, box.height
        vel, last, spins, inertia = paths.velocities, paths.last_collision, paths.spins, shapes.inertias
        e0, per_group, table, group, tc = shapes.e, shapes.per_group, shapes.e_table, shapes.e_group, shapes.tc
        rough, beta = shapes.rough, shapes.beta
        log = tally.log
        involved = np.unique(np.concatenate([ii, jj]))
        keys = involved.tolist()
        at = dict(zip(keys, pos[involved].tolist(), strict=True))
        speed = dict(zip(keys, vel[involved].tolist(), strict=True))
        before = dict(zip(keys, prev[involved].tolist(), strict=True)) if self.uses_previous else None
        changed = set()
        detections = 0
        virial = tally.virial
        for i, j in zip(ii, jj, strict=True):
            xi, yi = at[i]
            xj, yj = at[j]
            dx, dy = xj - xi, yj - yi
            if periodic:
                dx, dy = minimum_image_1d(dx, width), minimum_image_1d(dy, height)
            vxi, vyi = speed[i]
            vxj, vyj = speed[j]
            dvx, dvy = vxj - vxi, vyj - vyi
            if dvx * dx + dvy * dy >= 0.0:  # separating already (an earlier response this frame)
                continue
            mi, mj = mass[i], mass[j]
            before_i, before_j = (before[i], before[j]) if before is not None else (None, None)
            sigma = radius[i] + radius[j]
            xi, yi, xj, yj, dx, dy = self.contact(xi, yi, xj, yj, dx, dy, dvx, dvy, mi, mj, sigma, before_i, before_j)
            e = restitution(i, j, t, e0, per_group, table, group, tc, last)
            uxi, uyi, uxj, uyj = resolve_collision(dx, dy, vxi, vyi, vxj, vyj, mi, mj, e)
            if rough:  # the tangential impulse at the contact point turns both
                paths.spin_to(i, t)
                paths.spin_to(j, t)
                wi, wj = float(spins[i]), float(spins[j])
                uxi, uyi, uxj, uyj, spins[i], spins[j] = rough_pair(
                    dx, dy, vxi, vyi, vxj, vyj, uxi, uyi, uxj, uyj, wi, wj, radius[i], radius[j], mi, mj,
                    inertia[i], inertia[j], beta,
                )  # fmt: skip
                tally.dissipated += spin_loss(inertia[i], wi, float(spins[i]))
                tally.dissipated += spin_loss(inertia[j], wj, float(spins[j]))
            if e != 1.0 or rough:
                tally.dissipated += kinetic_loss(mi, vxi, vyi, uxi, uyi) + kinetic_loss(mj, vxj, vyj, uxj, uyj)
            if tc > 0.0:  # the TC model's clocks (an obstacle keeps none, as in EventDriven)
                if shapes.moving[i]:
                    last[i] = t
                if shapes.moving[j]:
                    last[j] = t
            sx, sy = xj - xi, yj - yi  # where the impulse is applied (moved there by "revert" or "separate")
            if periodic:
                sx, sy = minimum_image_1d(sx, width), minimum_image_1d(sy, height)
            virial += impulse_virial(sx, sy, vxi, vyi, uxi, uyi, vxj, vyj, uxj, uyj, mi, mj)
            at[i], at[j] = (xi, yi), (xj, yj)
            speed[i], speed[j] = (uxi, uyi), (uxj, uyj)
            changed.add(i)
            changed.add(j)
            detections += 1
            events.append(Event(t, "collision", i, j))
            if log is not None:
                log.collision(t, i, j, xi, yi, uxi, uyi, xj, yj, uxj, uyj)
        if changed:
            done = sorted(changed)
            pos[done] = [at[k] for k in done]
            vel[done] = [speed[k] for k in done]
            paths.restart(done, pos[done], t, flown[done])
        tally.counts["detections"] += detections
        tally.virial = virial


class Resolve(FramePolicy):
    """The ``"resolve"`` policy: discs stay where they were found; only their velocities change."""

    name = "resolve"


class Revert(FramePolicy):
    """The ``"revert"`` policy: discs go back to where they were at the previous frame."""

    name = "revert"
    uses_previous = True

    def off_walls(self, pos, prev, rows, low, high, r, size):
        pos[rows] = prev[rows]
        return pos

    def off_segments(self, x, y, vx, vy, previous, hits, r, e=1.0, turn=(0.0, 1.0, math.inf, -1.0), speeds=None):
        # A moving segment stays where it is at the frame; the disc goes back, and is tested and bounced in the
        # segment's frame.
        reverted = False
        responded = False
        w, m, inertia, beta = turn
        for k, ends in enumerate(hits):
            sx, sy = (0.0, 0.0) if speeds is None else speeds[k]
            qx, qy = closest_point_on_segment(x, y, *ends)
            nx, ny = x - qx, y - qy
            if not reverted:
                px, py = previous.tolist()
                bx, by = closest_point_on_segment(px, py, *ends)
                if (vx - sx) * (px - bx) + (vy - sy) * (
                    py - by
                ) < 0.0:  # approaching there: reflect at the restored place
                    x, y, nx, ny = px, py, px - bx, py - by
                    reverted = True
                elif (vx - sx) * nx + (vy - sy) * ny < 0.0:  # approaching only at the frame: restore, keep its normal
                    fx, fy = x, y
                    x, y = px, py
                    reverted = True
                    vx, vy, w = moving_segment_bounce(fx, fy, vx, vy, *ends, sx, sy, e, w, r, m, inertia, beta)
                    responded = True
                    continue
            if (vx - sx) * nx + (vy - sy) * ny >= 0.0:  # receding (or the centre is on the segment): leave it
                continue
            vx, vy, w = moving_segment_bounce(x, y, vx, vy, *ends, sx, sy, e, w, r, m, inertia, beta)
            responded = True
        return x, y, vx, vy, w, responded

    def contact(self, xi, yi, xj, yj, dx, dy, dvx, dvy, mi, mj, sigma, before_i, before_j):
        xi, yi = before_i
        xj, yj = before_j
        px, py = xj - xi, yj - yi
        box = self.shapes.box
        if box.periodic:
            px, py = minimum_image_1d(px, box.width), minimum_image_1d(py, box.height)
        if dvx * px + dvy * py < 0.0:  # else keep the frame's line, which is approaching
            dx, dy = px, py
        return xi, yi, xj, yj, dx, dy


class Separate(FramePolicy):
    """The ``"separate"`` policy: discs are pushed apart (or out of a wall or segment) until they just touch."""

    name = "separate"

    def off_walls(self, pos, prev, rows, low, high, r, size):
        return np.where(low, r, np.where(high, size - r, pos))

    def off_segment(self, x, y, qx, qy, nx, ny, r):
        return push_off_segment(x, y, qx, qy, nx, ny, r, math.hypot(nx, ny))

    def contact(self, xi, yi, xj, yj, dx, dy, dvx, dvy, mi, mj, sigma, before_i, before_j):
        return separate_pair(xi, yi, xj, yj, dx, dy, mi, mj, sigma, math.hypot(dx, dy))


#: The frame policies by name.
FRAME_POLICY_CLASSES = {policy.name: policy for policy in (Resolve, Revert, Separate)}
