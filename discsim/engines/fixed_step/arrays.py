"""What a frame works on: the scene as arrays (:class:`Shapes`), the discs' paths (:class:`Paths`) and the tally.

The policies (:mod:`~discsim.engines.fixed_step.frame`, :mod:`~discsim.engines.fixed_step.sub_frame`) read
and change these objects only; the engine owns them, exports them as a
:class:`~discsim.engines.fixed_step.state.FixedStepState` and loads them back.
"""

from __future__ import annotations

import numpy as np

from discsim.engines.fixed_step.parts import impulse_virial, wrap
from discsim.events import EventLog
from discsim.laws import PER_GROUP, E, Laws
from discsim.model import image_step, image_steps
from discsim.physics.damped import spans
from discsim.physics.dynamics import advance
from discsim.scene import Scene

__all__ = ["Paths", "Shapes", "Tally", "impulse_virial"]


class Shapes:
    """The scene as the frame code reads it: fixed for the whole run.

    Attributes:
        box: the :class:`~discsim.model.Box`. scene: the :class:`~discsim.scene.Scene`.
        radii ``(N,)`` float array and radius (list of N floats): the radii (length).
        mass ``(N,)`` float array and masses (list of N floats): the masses (inf for an obstacle).
        moving (list of N bools): finite mass.
        diameter: the largest diameter (a third of the box's shorter side with no discs): the broad phase's
            cell side.
        max_radius: half of ``diameter``.
        seg_a, seg_b ``(S, 2)``: the segments' end points at time 0; seg_ends (list of S tuples
            ``(x0, y0, x1, y1)``): the same as floats. seg_v ``(S, 2)``: the segments' velocities (length / time);
            seg_speeds (list of S tuples ``(vx, vy)``): the same as floats; seg_moving (bool): some segment moves
            (:meth:`segments_at` gives the ends at a frame's time).
        group (list of N ints) and blocked (G lists of G bools): the collision filter
            (:meth:`~discsim.scene.Scene.passes`) as lists, or None when no groups pass through each other.
        laws: the run's :class:`~discsim.laws.Laws`. gravity: ``(gx, gy)``. drag: the drag ``gamma`` (0: none).
            falls ``(N,)`` bool: the discs on a curved path, that gravity or drag moves (finite mass; all False
            without either).
        e (float), per_group (bool), e_table (G lists of G floats), e_group (list of N ints), tc (float): the
            arguments of :func:`~discsim.engines.fixed_step.parts.restitution` (``e_group`` indexes
            ``e_table`` by the rank of each disc's group label).
        beta (float): the roughness (-1: smooth); rough (bool): ``beta`` above -1, the responses turn the discs.
        inertia ``(N,)`` float array and inertias (list of N floats): the moments of inertia (inf: cannot turn).
    """

    def __init__(self, scene: Scene, laws: Laws | None = None):
        discs, box = scene.discs, scene.box
        self.scene = scene
        self.box = box
        # With no discs any cell will do: a third of the shorter side fits every box (3 cells a side).
        self.diameter = 2.0 * float(discs.radii.max()) if len(discs) else min(box.width, box.height) / 3.0
        self.max_radius = 0.5 * self.diameter
        self.radii = np.array(discs.radii)
        self.radius = discs.radii.tolist()
        self.mass = np.array(discs.masses)
        self.masses = discs.masses.tolist()
        self.moving = np.isfinite(discs.masses).tolist()
        self.seg_a = np.array([segment.p0 for segment in scene.segments]).reshape(-1, 2)
        self.seg_b = np.array([segment.p1 for segment in scene.segments]).reshape(-1, 2)
        self.seg_ends = [(*segment.p0.tolist(), *segment.p1.tolist()) for segment in scene.segments]
        self.seg_v = np.array([segment.velocity for segment in scene.segments]).reshape(-1, 2)
        self.seg_speeds = [tuple(segment.velocity.tolist()) for segment in scene.segments]
        self.seg_moving = bool(self.seg_v.any())
        self.group = scene.group.tolist() if scene.filtering else None
        self.blocked = scene.blocked.tolist() if scene.filtering else None
        laws = Laws.build() if laws is None else laws
        self.laws = laws
        self.gravity = laws.gravity
        self.drag = laws.drag
        self.falls = np.isfinite(discs.masses) & (laws.falls or laws.drag != 0.0)
        law = laws.array(discs.radii)
        self.e, self.per_group, self.tc = float(law[E]), bool(law[PER_GROUP]), laws.tc
        labels = np.unique(discs.groups)
        self.e_table = laws.table(labels).tolist()
        self.e_group = np.searchsorted(labels, discs.groups).tolist()
        self.beta, self.rough = laws.roughness, laws.rough
        self.inertia = np.array(discs.inertia)
        self.inertias = discs.inertia.tolist()

    def segments_at(self, t: float) -> tuple[np.ndarray, np.ndarray, list]:
        """``(seg_a, seg_b, seg_ends)`` where the segments are at time ``t``: ``p0 + velocity * t`` (the attributes
        themselves when no segment moves; the compiled frame computes the same floats)."""
        if not self.seg_moving:
            return self.seg_a, self.seg_b, self.seg_ends
        a, b = self.seg_a + self.seg_v * t, self.seg_b + self.seg_v * t
        return a, b, [tuple(row) for row in np.concatenate([a, b], axis=1).tolist()]


class Paths:
    """Each disc's path since it last changed course, and where the discs were at the last frame.

    Disc ``i`` is at ``ref_positions[i] + velocities[i] * (t - ref_times[i])`` (lazy clocks, as in the
    event log, so frame positions and ``trajectory()`` agree to the last bit); that point is not wrapped,
    and adding ``images[i] * box.size`` to it unwraps it. Under gravity a disc that falls follows the
    parabola of :func:`~discsim.physics.dynamics.advance` from there instead, ``velocities[i]`` being its
    velocity at ``ref_times[i]``, and under drag its exact exponential flight (with gravity or without); every
    frame starts its path afresh (:meth:`fall`).

    Attributes:
        box: the :class:`~discsim.model.Box`.
        ref_positions ``(N, 2)``: each disc's position at its reference time (length).
        ref_times ``(N,)``: when each disc last changed course (time).
        velocities ``(N, 2)``: the velocities (length per time).
        images ``(N, 2)`` int64: box lengths to add to ``ref_positions`` to unwrap them.
        frame_positions ``(N, 2)``: the positions at the last frame, wrapped into a periodic box.
        last_collision ``(N,)``: each disc's last response time (``-inf``: none; kept for the TC model only).
        gravity: ``(gx, gy)``; drag: the drag ``gamma`` (1 / time; 0: none); falls ``(N,)`` bool: the discs on
            a curved path, that gravity or drag moves (None: neither).
        spins ``(N,)``: the angular velocities (radians per time, counter-clockwise); changed only by the
            responses of rough discs. angles ``(N,)``: each disc's angle at its time in ``angle_times``
            ``(N,)`` (:meth:`turning` gives them all at one time).
    """

    def __init__(
        self, box, ref_positions, ref_times, velocities, images, frame_positions, last_collision=None,
        gravity=(0.0, 0.0), falls=None, spins=None, angles=None, angle_time=0.0, drag=0.0,
    ):  # fmt: skip
        self.box = box
        self.ref_positions = ref_positions
        self.ref_times = ref_times
        self.velocities = velocities
        self.images = images
        self.frame_positions = frame_positions
        self.last_collision = np.full(len(ref_times), -np.inf) if last_collision is None else last_collision
        self.gravity = (float(gravity[0]), float(gravity[1]))
        self.drag = float(drag)
        curved = self.gravity != (0.0, 0.0) or self.drag != 0.0
        self.falls = falls if falls is not None and curved and falls.any() else None
        n = len(ref_times)
        self.spins = np.zeros(n) if spins is None else spins
        self.angles = np.zeros(n) if angles is None else angles
        self.angle_times = np.full(n, float(angle_time))

    def turning(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """``(spins, angles)`` at time ``t``, ``(N,)`` each (new arrays)."""
        return self.spins.copy(), self.angles + self.spins * (t - self.angle_times)

    def spin_to(self, disc: int, t: float) -> None:
        """Bring disc ``disc``'s angle to time ``t`` (before its spin changes there)."""
        self.angles[disc] += self.spins[disc] * (t - self.angle_times[disc])
        self.angle_times[disc] = t

    def flown(self, t: float) -> np.ndarray:
        """``(N, 2)`` positions at time ``t`` on the current paths, not wrapped."""
        out = self.ref_positions + self.velocities * (t - self.ref_times)[:, None]
        falls = self.falls
        if falls is not None:  # the parabola or the damped flight, as the compiled frame computes it disc by disc
            out[falls, 0], out[falls, 1], _, _ = self._curved(t)
        return out

    def velocities_at(self, t: float) -> np.ndarray:
        """``(N, 2)`` velocities at time ``t`` on the current paths (a new array)."""
        out = self.velocities.copy()
        falls = self.falls
        if falls is not None:
            _, _, out[falls, 0], out[falls, 1] = self._curved(t)
        return out

    def _curved(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(x, y, vx, vy)`` at time ``t`` of the discs on curved paths (``falls``), each an array.

        Under drag the spans come from :func:`~discsim.physics.damped.spans` (:mod:`math`, as the compiled
        frame computes them), once per distinct flight time (one, at a frame), then the operations of
        :func:`~discsim.physics.dynamics.advance`: the same bits as the compiled frame's.
        """
        falls = self.falls
        (x, y), (vx, vy) = self.ref_positions[falls].T, self.velocities[falls].T
        dt = t - self.ref_times[falls]
        gx, gy = self.gravity
        if self.drag == 0.0:
            return advance(x, y, vx, vy, dt, gx, gy)
        flights, which = np.unique(dt, return_inverse=True)
        tau, s, e = np.array([spans(float(d), self.drag) for d in flights.tolist()]).reshape(-1, 3)[which].T
        return x + vx * tau + gx * s, y + vy * tau + gy * s, vx * e + gx * tau, vy * e + gy * tau

    def drag_loss(self, t: float, mass: np.ndarray, rows=None) -> np.ndarray:
        """What the drag took from each disc on a curved path (``falls``, in order; or of those, ``rows``) over its
        flight from its reference time to ``t`` (energy): its kinetic energy lost plus the work gravity did on it,
        ``m (|v0|^2 - |v|^2) / 2 + m g . (r - r0)``, with the compiled frame's operations. ``mass`` ``(N,)``: the
        masses (:attr:`Shapes.mass`)."""
        falls = self.falls
        x, y, vx, vy = self._curved(t)
        (x0, y0), (vx0, vy0) = self.ref_positions[falls].T, self.velocities[falls].T
        gx, gy = self.gravity
        loss = mass[falls] * (0.5 * ((vx0 * vx0 + vy0 * vy0) - (vx * vx + vy * vy)) + gx * (x - x0) + gy * (y - y0))
        if rows is not None:
            loss = loss[np.searchsorted(np.flatnonzero(falls), rows)]
        return loss

    def fall(self, t: float, flown: np.ndarray) -> None:
        """Under gravity or drag, every disc on a curved path starts a new path at time ``t`` from ``flown``
        (:meth:`flown` at ``t``, not wrapped), with its velocity there: a frame's responses see the velocities at
        the frame."""
        falls = self.falls
        if falls is None:
            return
        self.velocities[falls] = self.velocities_at(t)[falls]
        self.ref_positions[falls] = flown[falls]
        self.ref_times[falls] = t

    def restart(self, rows, positions, t: float, flown=None) -> None:
        """Discs ``rows`` start new paths at time ``t`` from ``positions`` (their velocities set apart).

        Args:
            rows: disc indices (an int, a list or an int array).
            positions: their new reference positions (``(2,)`` or ``(len(rows), 2)``).
            t: the new reference time.
            flown: in a periodic box, where the old paths put the discs at ``t`` (:meth:`flown`, not
                wrapped); the whole box lengths between it and ``positions`` go to ``images``.
        """
        if flown is not None and self.box.periodic:
            size = self.box.size
            self.images[rows] += image_steps(flown, positions, size).astype(np.int64)
        self.ref_positions[rows] = positions
        self.ref_times[rows] = t

    def turn(self, disc: int, t: float, x: float, y: float, vx: float, vy: float) -> tuple[float, float]:
        """Disc ``disc`` changes course at time ``t`` at ``(x, y)`` (on its path, not wrapped) to ``(vx, vy)``.

        Returns the new reference position, wrapped into a periodic box.
        """
        box = self.box
        if box.periodic:
            wx, wy = wrap(x, box.width), wrap(y, box.height)
            if wx != x or wy != y:  # it left the box since its last change of course
                self.images[disc] += (image_step(x, wx, box.width), image_step(y, wy, box.height))
            x, y = wx, wy
        self.ref_positions[disc] = (x, y)
        self.ref_times[disc] = t
        self.velocities[disc] = (vx, vy)
        return x, y

    def unwrapped(self, t: float) -> np.ndarray:
        """``(N, 2)`` positions at time ``t``, each disc followed across the edges of a periodic box."""
        if self.falls is not None:
            return self.flown(t) + self.images * self.box.size
        return self.ref_positions + self.images * self.box.size + self.velocities * (t - self.ref_times)[:, None]


class Tally:
    """The run's counters, the deepest overlap seen, the collision virial, and the log the current frame writes to.

    Attributes:
        counts (dict[str, int]): see :attr:`FixedStep.counts <discsim.engines.fixed_step.FixedStep>`.
        max_overlap (float): the deepest disc-disc overlap seen, as a fraction of the contact distance.
        virial (float): the sum over the disc-disc impulses applied of ``dp_i . (r_i - r_j)`` (energy):
            ``dp_i`` the momentum disc ``i`` receives, ``r_i - r_j`` the minimum-image separation of the
            pair where the impulse is applied (see :func:`impulse_virial`).
        dissipated (float): the kinetic energy the responses with restitution below 1 or roughness took, and
            what the drag took over the flights up to the last frame (energy; :meth:`lose`).
        log (EventLog or None): where responses are logged (None: not recorded).
    """

    NAMES = (
        "frames", "pair_tests", "segment_tests", "bisection_tests", "detections", "wall_hits", "list_builds",
        "sensor_events",
    )  # fmt: skip

    def __init__(
        self, counts: dict[str, int] | None = None, max_overlap: float = 0.0, virial: float = 0.0,
        dissipated: float = 0.0,
    ):  # fmt: skip
        self.counts = {name: 0 for name in self.NAMES} if counts is None else {n: int(counts[n]) for n in self.NAMES}
        self.max_overlap = float(max_overlap)
        self.virial = float(virial)
        self.dissipated = float(dissipated)
        self.log: EventLog | None = None

    def lose(self, losses: np.ndarray) -> None:
        """Add ``losses`` (energy) to :attr:`dissipated` one by one in order, as the compiled frame adds them."""
        dissipated = self.dissipated
        for loss in losses.tolist():
            dissipated += loss
        self.dissipated = dissipated
