"""What every engine shares: the public protocol and the methods derived from it.

An engine holds ``discs`` (the initial :class:`~discsim.model.Discs`), ``box``,
``time``, ``positions`` and ``velocities``, ``counts`` and an event log, and
implements ``run`` and ``step``. Everything else (energies, momentum, the log
as an array, exact trajectories) is derived here once for all engines, so that
``compare``, ``plot``, notebooks and benchmarks work with any of them.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

import numpy as np

from discsim.errors import InvalidArgumentError, TimeError
from discsim.events import EVENT_DTYPE
from discsim.model import Box, Discs, kinetic_energy, momentum
from discsim.trajectory import reconstruct

__all__ = ["Engine"]


class Engine(ABC):
    """Base class of discsim engines; see the module docstring for the protocol."""

    discs: Discs
    box: Box

    def __init__(self, discs: Discs, box: Box, record: bool):
        if not isinstance(discs, Discs):
            msg = f"discs must be a discsim.Discs, got {type(discs).__name__}"
            raise TypeError(msg)
        if not isinstance(box, Box):
            msg = f"box must be a discsim.Box, got {type(box).__name__}"
            raise TypeError(msg)
        self.discs = discs
        self.box = box
        self.record = bool(record)
        self.start_time = 0.0

    # --- implemented by each engine -------------------------------------------------
    time: float

    @property
    @abstractmethod
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time`` (a fresh copy)."""

    @property
    @abstractmethod
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time`` (a fresh copy)."""

    @abstractmethod
    def _event_array(self) -> np.ndarray:
        """The log as a structured array, whatever ``record`` says."""

    @abstractmethod
    def run(self, until=None, **kwargs):
        """Advance the simulation; return ``self``."""

    @abstractmethod
    def step(self):
        """Advance by one unit of work (an event, or a frame) and return what happened."""

    # --- derived ---------------------------------------------------------------------
    @property
    def events(self) -> np.ndarray:
        """The recorded event log: a structured array ``(E,)`` of :data:`~discsim.events.EVENT_DTYPE`.

        Empty when the engine was built with ``record=False``.
        """
        if not self.record:
            return np.zeros(0, dtype=EVENT_DTYPE)
        return self._event_array()

    def snapshot(self) -> Discs:
        """The discs as they are now: a new :class:`~discsim.model.Discs` at ``time``.

        Use it to start a fresh engine (or measurement) from an equilibrated state.
        """
        d = self.discs
        return Discs(self.positions, self.velocities, d.radii, d.masses, d.groups)

    def kinetic_energy(self) -> float:
        """Total kinetic energy ``sum(m |v|^2) / 2`` (obstacles contribute zero)."""
        return kinetic_energy(self.velocities, self.discs.masses)

    def momentum(self) -> np.ndarray:
        """Total momentum ``(2,)`` of the discs of finite mass."""
        return momentum(self.velocities, self.discs.masses)

    def trajectory(self, times) -> np.ndarray:
        """Exact positions ``(T, N, 2)`` at ``times`` ``(T,)``, rebuilt from the event log.

        Times must lie within ``[start_time, time]``, the span already simulated.
        Needs ``record=True``.
        """
        times = np.atleast_1d(np.asarray(times, dtype=float))
        if not self.record:
            msg = "trajectory() needs the event log; build the engine with record=True"
            raise InvalidArgumentError(msg)
        if times.size and not np.isfinite(times).all():
            msg = f"trajectory times must be finite, got {times[~np.isfinite(times)][0]!r}"
            raise TimeError(msg)
        tol = 1e-12 * max(1.0, abs(self.time))
        if times.size and (times.min() < self.start_time - tol or times.max() > self.time + tol):
            bad = times.min() if times.min() < self.start_time - tol else times.max()
            msg = f"trajectory time {bad!r} is outside the simulated span [{self.start_time!r}, {self.time!r}]"
            raise TimeError(msg)
        return reconstruct(
            self._event_array(), self.discs.positions, self.discs.velocities, self.start_time, times, self.box
        )

    def _check_until(self, until) -> float:
        try:
            until = float(until)
        except (TypeError, ValueError) as exc:
            msg = f"until must be a number, got {until!r}"
            raise TimeError(msg) from exc
        if math.isnan(until):
            msg = "until must not be NaN"
            raise TimeError(msg)
        if until < self.time:
            msg = f"until={until!r} is before the current time {float(self.time)!r}"
            raise TimeError(msg)
        return until

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n={len(self.discs)}, time={self.time:g}, box={self.box})"
