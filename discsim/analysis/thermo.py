"""Thermodynamic measurements of a run: packing fraction, compressibility factor.

Numbers in, numbers out: these read a finished engine (any engine with ``pressure()``,
``kinetic_energy()`` and ``box``) and know nothing of how it ran.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.errors import InvalidArgumentError

__all__ = ["compressibility_factor", "packing_fraction"]


def packing_fraction(radii: np.ndarray, area: float) -> float:
    """Fraction of ``area`` covered by discs of ``radii`` ``(N,)``."""
    return float(math.pi * np.sum(np.asarray(radii, dtype=float) ** 2) / area)


def compressibility_factor(sim) -> float:
    """``Z = P A / (N kT)`` of an event-driven run (``N kT`` is the kinetic energy).

    Raises:
        InvalidArgumentError: if the engine has no ``pressure()`` (``FixedStep`` has none yet) or no
            kinetic energy (no free disc moves).
    """
    if not callable(getattr(sim, "pressure", None)):
        msg = f"compressibility_factor needs an engine with pressure() (an EventDriven run), got {type(sim).__name__}"
        raise InvalidArgumentError(msg)
    energy = sim.kinetic_energy()
    if energy <= 0.0:
        msg = "compressibility_factor needs moving discs: the kinetic energy is 0"
        raise InvalidArgumentError(msg)
    return sim.pressure() * sim.box.area / energy
