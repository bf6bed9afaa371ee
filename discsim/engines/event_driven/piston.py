"""The piston of an event-driven run (:class:`discsim.Piston`): where it is, its pressure changed, and the edits it
must allow.

:class:`PistonRun` is the part of :class:`~discsim.engines.event_driven.engine.EventDriven` that reads the piston
from the backend (``sim.piston``), changes its pressure or velocity mid-run (``sim.set_piston``: the backend starts
afresh from there, as after ``add_discs``, since a piston pushed harder may meet discs sooner than predicted), and
refuses an edit that would put a disc above it or give the gas the energy to lift it out of the box.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from discsim.engines.event_driven.protocol import Backend
from discsim.errors import InvalidArgumentError, OutsideBoxError
from discsim.model import OVERLAP_TOLERANCE, Box, Discs
from discsim.piston import Piston, PistonState
from discsim.scene import Scene

__all__ = ["PistonRun", "check_room"]


class PistonRun:
    """The piston's part of an event-driven run (a mixin of
    :class:`~discsim.engines.event_driven.engine.EventDriven`)."""

    _backend: Backend
    box: Box
    time: float
    scene: Scene
    laws: Any
    #: The pressure and velocity :meth:`set_piston` asks for while the backend starts afresh (None: as they are).
    _piston_asked: tuple[float | None, float | None] = (None, None)
    #: The time of the last :meth:`set_piston` (what ``ds.thermo`` averages starts after it).
    _piston_since: float = 0.0

    if TYPE_CHECKING:

        def snapshot(self) -> Discs: ...
        def _restructure(self, keep: np.ndarray, added: Discs | None, scene: Scene, last=None) -> None: ...

    @property
    def piston(self) -> PistonState | None:
        """The piston now (:class:`~discsim.piston.PistonState`: ``height``, ``velocity``, ``pressure``, ``hits``);
        None without one. The gas's area is ``box.width * sim.piston.height``."""
        if self.scene.piston is None:
            return None
        height, velocity, hits, pressure = self._piston_now()
        return PistonState(height, velocity, self.scene.piston.mass, pressure, hits, self._piston_since)

    def set_piston(self, *, pressure: float | None = None, velocity: float | None = None):
        """Change the piston's pressure (and so the force on it) or its velocity from now on; returns ``self``.

        The backend starts afresh here, every disc predicted again (O(N)), as after ``add_discs``. A slow ramp of
        the pressure in many small steps is a slow (adiabatic) compression; one large step a sudden one.

        Args:
            pressure: the new external pressure (> 0; 0 for a kinematic lid, whose pressure cannot change); None:
                as it is.
            velocity: the piston's new velocity along y (length / time); None: as it is.

        Raises:
            InvalidArgumentError: without a piston, on a pressure or velocity a :class:`~discsim.piston.Piston`
                would refuse, or when the piston could then rise above the box (nothing changes).
        """
        given = self.scene.piston
        if given is None:
            msg = "set_piston needs a piston (EventDriven(..., piston=ds.Piston(...)))"
            raise InvalidArgumentError(msg)
        height, now_velocity, _, now_pressure = self._piston_now()
        pressure = now_pressure if pressure is None else pressure
        velocity = now_velocity if velocity is None else velocity
        Piston(given.mass, pressure, height, velocity)  # refuses what a new piston would (names the value)
        discs = self.snapshot()
        check_room(given, self.box, discs, height, float(velocity), float(pressure), -self.laws.gravity[1])
        self._piston_asked = (float(pressure), float(velocity))
        try:
            self._restructure(np.arange(len(discs)), None, self.scene.but(discs), self._backend.last_event())
        finally:
            self._piston_asked = (None, None)
        self._piston_since = float(self.time)
        return self

    # --- for the engine ----------------------------------------------------------------------
    def _check_piston_edit(self, indices: np.ndarray, positions: np.ndarray | None, velocities: np.ndarray) -> None:
        """Refuse, before anything changes, new ``positions`` (None: where they are) and ``velocities`` of discs
        ``indices`` that would put a disc above the piston or give the gas the energy to lift it out of the box
        (:func:`check_room`); nothing without a piston."""
        if self.scene.piston is None:
            return
        now = self.snapshot()
        places, speeds = now.positions.copy(), now.velocities.copy()
        if positions is not None:
            places[indices] = positions
        speeds[indices] = velocities
        height, velocity, _, pressure = self._piston_now()
        discs = Discs(places, speeds, now.radii, now.masses, now.groups, now.spins, now.inertia)
        check_room(self.scene.piston, self.box, discs, height, velocity, pressure, -self.laws.gravity[1])

    def _piston_now(self) -> tuple[float, float, int, float]:
        """The piston's height, velocity, impacts and pressure now (a piston runs on the compiled loop's backend)."""
        backend: Any = self._backend
        return backend.piston_now()

    def _piston_from(self, discs: Discs) -> np.ndarray:
        """The piston's numbers for a backend that starts afresh now (internal time 0) with ``discs``: where it
        is now, its impacts so far, and the pressure and velocity :meth:`set_piston` asked for; ``(0,)`` without
        one. Refuses discs above it or with the energy to lift it out of the box (before anything changes)."""
        if self.scene.piston is None:
            return np.zeros(0)
        height, velocity, hits, pressure = self._piston_now()
        asked_pressure, asked_velocity = self._piston_asked
        pressure = pressure if asked_pressure is None else asked_pressure
        velocity = velocity if asked_velocity is None else asked_velocity
        if not self.scene.piston.kinematic and not len(discs):
            msg = "a piston of finite mass needs discs under it: with none it would fall for ever"
            raise InvalidArgumentError(msg)
        check_room(self.scene.piston, self.box, discs, height, velocity, pressure, -self.laws.gravity[1])
        return np.array([height, velocity, 0.0, float(hits), pressure])


def check_room(
    piston: Piston, box: Box, discs: Discs, height: float, velocity: float, pressure: float, fall: float = 0.0
) -> None:
    """Refuse ``discs`` with a top above ``piston`` at ``height`` (by more than ``OVERLAP_TOLERANCE`` of its radius,
    as a wall), or a gas that could lift it (at ``velocity``, under ``pressure``) above the box, naming the disc or
    the height it could reach: energy bounds its height by ``H + (K + V + M U^2 / 2) / F`` (``K`` the discs' kinetic
    energy, ``V = g sum m (y - r)`` their potential energy above the floor under gravity ``g = fall`` down along y,
    ``F`` the pressure times the box's width plus the piston's weight ``M g``)."""
    tops = discs.positions[:, 1] + discs.radii
    over = tops - height - OVERLAP_TOLERANCE * discs.radii  # (a disc just off the piston touches it to roundoff)
    if len(tops) and float(over.max()) > 0.0:
        k = int(np.argmax(over))
        msg = f"disc {k}'s top y + r = {float(tops[k])!r} is above the piston's height {height!r}"
        raise OutsideBoxError(msg)
    if piston.kinematic:
        return
    kinetic = 0.5 * float(np.sum(discs.masses * np.sum(discs.velocities**2, axis=1)))
    kinetic += fall * float(np.sum(discs.masses * (discs.positions[:, 1] - discs.radii)))
    highest = height + (kinetic + 0.5 * piston.mass * velocity**2) / (pressure * box.width + piston.mass * fall)
    if highest > box.height:
        msg = (
            f"the piston (mass {piston.mass!r}, pressure {pressure!r}, velocity {velocity!r}) could rise to "
            f"{highest!r} with the discs' kinetic energy {kinetic!r}, above the box's height {box.height!r}: make "
            "the box at least that tall, or raise the pressure"
        )
        raise InvalidArgumentError(msg)
