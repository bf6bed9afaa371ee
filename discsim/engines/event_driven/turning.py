"""How the discs of an event-driven run turn: their spins and angles, the spins' log, and the kinetic energy with
its rotational part.

:class:`Turning` is the part of :class:`~discsim.engines.event_driven.engine.EventDriven` that reads the discs'
turning from the backend (``turning()``; spins change only at collisions of rough discs, ``roughness`` above -1:
``docs/laws.md``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from discsim.engines.event_driven.protocol import Backend
from discsim.events import SPIN_DTYPE
from discsim.model import Discs, _readonly, kinetic_energy, rotational_energy

__all__ = ["Turning"]


class Turning:
    """The discs' turning (a mixin of :class:`~discsim.engines.event_driven.engine.EventDriven`)."""

    # What the engine provides (declared for readers and the type checker).
    _backend: Backend
    discs: Discs

    if TYPE_CHECKING:  # the engine's own properties, named for the type checker only

        @property
        def positions(self) -> np.ndarray: ...

        @property
        def velocities(self) -> np.ndarray: ...

    @property
    def spins(self) -> np.ndarray:
        """``(N,)`` angular velocities at ``time`` (radians per time unit, counter-clockwise positive; a fresh
        read-only copy). Constant between collisions; changed only by those of rough discs (``roughness``)."""
        return _readonly(self._backend.turning()[0])

    @property
    def angles(self) -> np.ndarray:
        """``(N,)`` each disc's angle at ``time`` (radians, counter-clockwise, 0 at the start; not wrapped): the
        angle at its last collision plus its spin times the time since (a fresh read-only copy)."""
        return _readonly(self._backend.turning()[1])

    @property
    def spin_events(self) -> np.ndarray:
        """A rough run's spins after each of its logged collisions and wall hits, in order: a
        :data:`~discsim.events.SPIN_DTYPE` array (``time``, ``i``, ``j``, ``wi``, ``wj``; ``wj`` NaN for a wall
        hit), the rows of :attr:`events`'s collisions and wall hits. Empty for smooth discs (``roughness=-1``:
        spins never change) and when ``record=False``; kept in checkpoints (with the log), not in streamed logs."""
        chunks = getattr(self._backend, "spin_log", [])
        return np.concatenate(chunks) if chunks else np.zeros(0, dtype=SPIN_DTYPE)

    def _restore_spin_events(self, rows: np.ndarray) -> None:
        """Take back the :attr:`spin_events` a checkpoint holds (:data:`~discsim.events.SPIN_DTYPE` rows).

        Raises:
            ValueError: rows of another dtype.
        """
        if rows.dtype != SPIN_DTYPE:
            msg = f"spin_events of dtype {rows.dtype}, expected {SPIN_DTYPE}"
            raise ValueError(msg)
        if len(rows) and hasattr(self._backend, "spin_log"):
            self._backend.spin_log = [np.array(rows)]

    def kinetic_energy(self) -> float:
        """Total kinetic energy: translation ``sum(m |v|^2) / 2`` plus rotation ``sum(I w^2) / 2`` (over discs of
        finite mass and inertia; the rotational part is zero unless discs spin)."""
        return kinetic_energy(self.velocities, self.discs.masses) + rotational_energy(self.spins, self.discs.inertia)

    def snapshot(self) -> Discs:
        """The discs as they are now: a new :class:`~discsim.model.Discs` at ``time``, spins included."""
        d = self.discs
        return Discs(self.positions, self.velocities, d.radii, d.masses, d.groups, self.spins, d.inertia)
