"""What a fixed-step run shows: positions and velocities at any time, spins and angles, the counters, the pressure,
the energies, the trajectory under gravity, the frame clock (and the frames still due).

:class:`FrameReadout` is the read-only side of :class:`~discsim.engines.fixed_step.engine.FixedStep`: it reads
the paths (:class:`~discsim.engines.fixed_step.arrays.Paths`) between frames and changes nothing.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from discsim.engines.fixed_step.arrays import Paths, Shapes, Tally
from discsim.errors import InvalidArgumentError
from discsim.events import SENSED
from discsim.laws import Laws
from discsim.model import Box, Discs, _readonly, frame_count, kinetic_energy, rotational_energy
from discsim.physics.damped import spans_many

__all__ = ["FrameReadout"]


class FrameReadout:
    """Positions, velocities, counters, pressure and frame times of a fixed-step run (a mixin of :class:`FixedStep`)."""

    # What the engine provides (declared for readers and the type checker).
    box: Box
    discs: Discs
    laws: Laws
    time: float
    start_time: float
    frame_rate: float
    dt: float
    _by_rate: bool
    _frame_time: float
    _paths: Paths
    _tally: Tally
    _shapes: Shapes
    run_context: Any

    if TYPE_CHECKING:

        @property
        def events(self) -> np.ndarray: ...  # EventRecord's

    @property
    def frames(self) -> int:
        """Frames done since the start."""
        return self._tally.counts["frames"]

    @property
    def counts(self) -> dict[str, int]:
        """The counters (a fresh dict): see the class docstring."""
        return dict(self._tally.counts)

    @property
    def max_overlap(self) -> float:
        """The deepest disc-disc overlap seen, as a fraction of the contact distance (see the class docstring)."""
        return self._tally.max_overlap

    @property
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time`` (a fresh copy; wrapped into a periodic box)."""
        if self.time == self._frame_time:
            return _readonly(self._paths.frame_positions.copy())
        return _readonly(self.box.wrap(self._paths.flown(self.time)))

    @property
    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, each disc followed across the edges of a periodic box (a fresh copy).

        In a walled box, the same as :attr:`positions`. ``unwrapped_positions - discs.positions`` is each
        disc's displacement since the start, as a mean-squared displacement needs.

        Example:
            >>> import discsim as ds
            >>> sim = ds.FixedStep(ds.Discs([[3.5, 1.0]], [[1.0, 0.0]], 0.5), ds.Box(4.0, 4.0, periodic=True), dt=0.25)
            >>> sim.run(frames=4).positions.tolist(), sim.unwrapped_positions.tolist()
            ([[0.5, 1.0]], [[4.5, 1.0]])
        """
        if not self.box.periodic:
            return self.positions
        return _readonly(self._paths.unwrapped(self.time))

    @property
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time`` (a fresh copy; under gravity or drag, between frames, on the exact
        path)."""
        if self._paths.falls is not None and self.time != self._frame_time:
            return _readonly(self._paths.velocities_at(self.time))
        return _readonly(self._paths.velocities.copy())

    @property
    def spins(self) -> np.ndarray:
        """``(N,)`` angular velocities at ``time`` (radians per time unit, counter-clockwise positive; a fresh
        read-only copy). Changed only by the responses of rough discs (``roughness``)."""
        return _readonly(self._paths.spins.copy())

    @property
    def angles(self) -> np.ndarray:
        """``(N,)`` each disc's angle at ``time`` (radians, counter-clockwise, 0 at the start; not wrapped; a fresh
        read-only copy)."""
        return _readonly(self._paths.turning(self.time)[1])

    def kinetic_energy(self) -> float:
        """Total kinetic energy: translation ``sum(m |v|^2) / 2`` plus rotation ``sum(I w^2) / 2`` (over discs of
        finite mass and inertia; the rotational part is zero unless discs spin)."""
        spinning = rotational_energy(self._paths.spins, self.discs.inertia)
        return kinetic_energy(self.velocities, self.discs.masses) + spinning

    def snapshot(self) -> Discs:
        """The discs as they are now: a new :class:`~discsim.model.Discs` at ``time``, spins included."""
        d = self.discs
        return Discs(self.positions, self.velocities, d.radii, d.masses, d.groups, self.spins, d.inertia)

    @property
    def dissipated(self) -> float:
        """Kinetic energy taken since the start by the responses with restitution below 1 or roughness strictly
        between -1 and 1, the rotational energy included, and by the drag (0 for elastic, smooth discs without
        drag).

        The drag's part is what it took over each exact flight, up to ``time`` (the flights under way included):
        the kinetic energy lost plus the work gravity did. Only the laws' losses: what the frames' own errors
        add or take (a disc that sinks into the floor before its bounce, ``"separate"`` lifting it out,
        ``"revert"`` sending it back) is not counted, so ``energy() + dissipated`` drifts from its start by the
        stepping's error alone.
        """
        paths = self._paths
        if paths.drag == 0.0 or paths.falls is None or self.time == self._frame_time:
            return self._tally.dissipated
        return self._tally.dissipated + float(np.sum(paths.drag_loss(self.time, self._shapes.mass)))

    def pressure(self) -> float:
        """Pressure from the virial of the impulses the frames applied, averaged since the start.

        The definition of :meth:`EventDriven.pressure <discsim.engines.event_driven.EventDriven.pressure>`:
        ``P = (N kT + W / (2 t)) / A`` in 2D, with ``N kT`` the kinetic energy, ``t = time - start_time``,
        ``A`` the box area and ``W`` the sum over the disc-disc impulses applied of ``dp_i . (r_i - r_j)``
        (``dp_i`` the momentum disc ``i`` gets, ``r_i - r_j`` the pair's minimum-image separation where the
        impulse is applied). With walls this is the bulk estimate: wall and segment hits are not counted,
        as for the event-driven engine. Units: energy per area; ``P A / (N kT)`` is
        :func:`discsim.compressibility_factor`.

        Where the impulse is applied depends on the policy: at the frame, overlapping (``"resolve"``:
        ``|r_i - r_j| < sigma``, so ``W`` falls short by the overlap depth at detection, a fraction of order
        ``v dt / sigma``); at the previous frame (``"revert"``); just touching (``"separate"``); at the
        contact found inside the frame (``"bisect"``, to ``bisect_tol``; ``"swept"``). Moves without an
        impulse (``"separate"`` pushing discs apart or back inside a wall, ``"revert"`` sending them back
        to the previous frame) add nothing: they are not forces, and counting them (``sum m v . dr``) would
        make ``P`` the virial of the fixed-step dynamics' artefacts rather than an estimate of the hard-disc
        pressure. As ``dt -> 0`` every policy tends to the event-driven value (``tests/engines/fixed_step/
        test_pressure.py`` measures the gap at a small step).

        Raises:
            InvalidArgumentError: if no time has passed since the start, or the run was loaded from a
                checkpoint written before the fixed-step engine counted its virial whose log does not
                hold the whole run (the virial of its first part is unknown).

        Example:
            >>> import discsim as ds
            >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
            >>> sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.25, policy="separate").run(until=4.0)
            >>> sim.pressure() * 100.0  # (N kT + |dp| sigma / (2 t)) / A with N kT = 1, |dp| = 2, sigma = 2
            1.5
        """
        elapsed = self.time - self.start_time
        if elapsed <= 0:
            msg = "pressure() needs a run of positive duration"
            raise InvalidArgumentError(msg)
        if self.laws.falls:
            msg = (
                f"pressure() is the bulk pressure of a uniform gas; under gravity {self.laws.gravity} the "
                "pressure varies with height (measure the density profile instead)"
            )
            raise InvalidArgumentError(msg)
        virial = self._tally.virial
        if math.isnan(virial):
            msg = (
                "pressure() is unknown for this run: it was loaded from a checkpoint written before FixedStep "
                "counted its collision virial, and that file's event log does not hold the whole run"
            )
            raise InvalidArgumentError(msg)
        return (self.kinetic_energy() + virial / (2.0 * elapsed)) / self.box.area

    def trajectory(self, times, *, unwrapped: bool = False) -> np.ndarray:
        """Positions ``(T, N, 2)`` at ``times`` ``(T,)``, rebuilt from the event log (see
        :meth:`~discsim.engines.record.EventRecord.trajectory`).

        Under gravity each disc of finite mass follows its parabola from its last record (the log's straight
        path plus ``g dt^2 / 2``, ``dt`` the time since that record); under drag its exact exponential flight
        (the log's, :func:`~discsim.physics.dynamics.advance_many`, plus ``g s(dt)`` under gravity): the engine's
        own positions at the frames, to rounding.

        Raises:
            InvalidArgumentError: as the log's trajectory; and under gravity, after ``add_discs`` or
                ``remove_discs`` (not rebuilt).
        """
        out = super().trajectory(times, unwrapped=unwrapped)  # type: ignore[misc]  # the log's (EventRecord)
        falls = self._shapes.falls
        if not (self.laws.falls and falls.any()):  # under drag alone the log's flights are the engine's
            return out
        if self.run_context.origin is not None:
            msg = "trajectory() under gravity is not rebuilt after add_discs or remove_discs"
            raise InvalidArgumentError(msg)
        asked = np.atleast_1d(np.asarray(times, dtype=float))
        events = self.events
        g, drag = np.array(self.laws.gravity), self.laws.drag
        for d in np.flatnonzero(falls).tolist():
            # In time order; a sensor's record names the sensor in j, not a disc.
            records = events["time"][(events["i"] == d) | ((events["j"] == d) & ~np.isin(events["kind"], SENSED))]
            last = np.concatenate([[self.start_time], records])[np.searchsorted(records, asked, side="right")]
            since = asked - last
            fall = spans_many(since, drag)[1] if drag != 0.0 else 0.5 * (since * since)
            out[:, d] += g * fall[:, None]
        if self.box.periodic and not unwrapped:
            out = self.box.wrap(out)
        return out

    def _gravity(self):
        """None: the log's trajectory is rebuilt in free flight, and :meth:`trajectory` adds the fall (a PIT run
        has no rest, so the event-driven rule "a record of zero velocity rests" must not apply)."""
        return None

    def _frames_due(self, until: float) -> int | None:
        """Frames still to do up to time ``until``, allowing for the roundoff of ``k * dt``; None (no count) for
        ``until = inf``.

        Counted from the start, so that a run gives the same frames however it is cut into calls.
        """
        if until == math.inf:
            return None
        last = frame_count(self.start_time, until, self.dt)
        return max(0, last - self.frames)

    def _units(self) -> int:
        """Frames done since the start."""
        return self.frames

    def frame_time(self, k):
        """The time of frame ``k`` (frame 0 is the start); ``k`` may be an int array."""
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
        return self.frame_time(np.arange(self.frames + 1))
