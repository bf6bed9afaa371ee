"""A piston: the top wall of a walled box as a body of finite mass under a constant pressure (a run at constant
pressure), or as a kinematic lid moving at a constant velocity.

``EventDriven(discs, box, piston=ds.Piston(mass=, pressure=))`` makes the box's top wall a horizontal piston as
wide as the box: the external pressure ``P`` pushes it down with the force ``F = P w`` (``w`` the box's width,
force per length in 2D); between impacts it falls with the uniform acceleration ``F / M``, and every disc that
hits it exchanges momentum with it along y (elastic). The gas's area ``w H`` then fluctuates about the one at which
the gas's pressure balances ``P``. The box's height stays a hard ceiling and the cell grid spans it; the energy
bound ``H <= (K + M U^2 / 2 + F H) / F`` (``K`` the discs' kinetic energy) keeps the piston below it, so the box
must be at least that tall (the engine says how tall).

A piston of infinite mass and no pressure is a kinematic lid: it moves at its ``velocity`` for ever, whatever hits
it, and discs bounce off it in its frame (a closing box, as a moving segment is a paddle).

Example:
    >>> Piston(mass=10.0, pressure=2.0)
    Piston(mass=10.0, pressure=2.0)
    >>> Piston(mass=float("inf"), pressure=0.0, velocity=-0.5).kinematic
    True
"""

from __future__ import annotations

import math

import numpy as np

from discsim.errors import InvalidArgumentError

__all__ = ["Piston", "PistonState"]


def _number(name: str, value) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        msg = f"piston {name} must be a real number, got {type(value).__name__} {value!r}"
        raise InvalidArgumentError(msg)
    return float(value)


class Piston:
    """The top wall of a walled box as a piston of ``mass`` pushed down by an external ``pressure``.

    Args:
        mass: the piston's mass (mass units, > 0); ``inf`` for a kinematic lid (then ``pressure`` must be 0).
        pressure: the external pressure (force per length in 2D, >= 0; > 0 for a finite mass, or nothing would
            bring the piston back down); the piston feels the force ``pressure * box.width`` downwards.
        height: the piston's height at time 0 (length; the box's height when None), at least every disc's top
            ``y + r`` and at most the box's height.
        velocity: the piston's velocity along y at time 0 (length / time; finite).

    Attributes:
        mass, pressure, velocity (float), height (float | None): as given.

    Raises:
        InvalidArgumentError: on a mass that is not positive, a negative or non-finite pressure, a finite mass
            without pressure, a kinematic lid under pressure, or a height or velocity that is not finite,
            naming the argument and its value.
    """

    __slots__ = ("height", "mass", "pressure", "velocity")

    def __init__(self, mass: float, pressure: float, height: float | None = None, velocity: float = 0.0):
        mass, pressure, velocity = _number("mass", mass), _number("pressure", pressure), _number("velocity", velocity)
        if not mass > 0.0:
            msg = f"piston mass must be > 0 (inf for a kinematic lid), got {mass!r}"
            raise InvalidArgumentError(msg)
        if not (0.0 <= pressure < math.inf):
            msg = f"piston pressure must be finite and >= 0, got {pressure!r}"
            raise InvalidArgumentError(msg)
        if mass < math.inf and pressure == 0.0:
            msg = f"a piston of finite mass {mass!r} needs a pressure > 0 (nothing would stop it rising), got 0"
            raise InvalidArgumentError(msg)
        if mass == math.inf and pressure != 0.0:
            msg = f"a piston of infinite mass is a kinematic lid: its pressure must be 0, got {pressure!r}"
            raise InvalidArgumentError(msg)
        if not math.isfinite(velocity):
            msg = f"piston velocity must be finite, got {velocity!r}"
            raise InvalidArgumentError(msg)
        if height is not None:
            height = _number("height", height)
            if not (0.0 < height < math.inf):
                msg = f"piston height must be finite and > 0, got {height!r}"
                raise InvalidArgumentError(msg)
        self.mass, self.pressure, self.height, self.velocity = mass, pressure, height, velocity

    @property
    def kinematic(self) -> bool:
        """Whether the piston is a kinematic lid (infinite mass: it moves at its velocity whatever hits it)."""
        return self.mass == math.inf

    def force(self, width: float) -> float:
        """The external force on a piston ``width`` wide (``pressure * width``, downwards)."""
        return self.pressure * width

    def settings(self) -> list:
        """``[mass, pressure, height, velocity]`` as a checkpoint stores them (``height`` None: the box's)."""
        return [self.mass, self.pressure, self.height, self.velocity]

    def __repr__(self) -> str:
        extra = "" if self.height is None else f", height={self.height!r}"
        extra += "" if self.velocity == 0.0 else f", velocity={self.velocity!r}"
        return f"Piston(mass={self.mass!r}, pressure={self.pressure!r}{extra})"

    def __eq__(self, other) -> bool:
        return isinstance(other, Piston) and self.settings() == other.settings()

    __hash__ = None  # type: ignore[assignment]


class PistonState:
    """Where a running piston is: ``sim.piston``.

    Attributes:
        height (float): its height now (length): the gas's area is ``box.width * height``.
        velocity (float): its velocity along y now (length / time).
        mass, pressure (float): as the :class:`Piston` was given (``pressure`` as last set).
        hits (int): the impacts of discs on it so far.
        since (float): the time of the last ``set_piston`` (0.0 if none in this process: a run loaded from a
            checkpoint starts from its load).
    """

    __slots__ = ("height", "hits", "mass", "pressure", "since", "velocity")

    def __init__(self, height: float, velocity: float, mass: float, pressure: float, hits: int, since: float = 0.0):
        self.height, self.velocity, self.mass, self.pressure, self.hits = height, velocity, mass, pressure, hits
        self.since = since

    def __repr__(self) -> str:
        return f"PistonState(height={self.height!r}, velocity={self.velocity!r}, hits={self.hits})"
