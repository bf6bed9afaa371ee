"""The protocol every backend of the event-driven engine meets: what the front class uses, and nothing else.

A backend runs the event loop on its own internal forms; what crosses its edge is an
:class:`~discsim.engines.event_driven.state.EventDrivenState` (plain arrays) and plain numbers.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

from discsim.engines.event_driven.state import EventDrivenState
from discsim.events import EventLog

if TYPE_CHECKING:
    from discsim.cells import CellGrid
    from discsim.scene import Scene

__all__ = ["Backend", "BackendClass"]


@runtime_checkable
class Backend(Protocol):
    """An event-driven backend, built as ``Backend(scene, grid, queue)`` and then started or loaded.

    Attributes:
        name: the backend's name (``EventDriven(..., backend=name)``).
        time: the current simulated time (the front class sets it when a run stops on time).
        max_queue: most events pending at once (read only). max_overlap: deepest overlap at a contact
            (settable). virial: sum over collisions of ``dp_i . (r_i - r_j)``.
    """

    name: str
    time: float
    max_overlap: float

    @property
    def max_queue(self) -> int: ...

    @property
    def virial(self) -> float: ...

    def start(self, state: EventDrivenState | None = None) -> None:
        """A fresh run at time 0 from the scene's discs, or from ``state`` (a fresh state with an empty queue,
        from :func:`~discsim.engines.event_driven.numbering.fresh_state`, its clock moved on): every moving
        disc predicted at the state's epoch, in internal order."""

    def load(self, state: EventDrivenState) -> None:
        """Take over ``state``."""

    def export(self) -> EventDrivenState:
        """The run state (new arrays, caller's numbering)."""

    def advance(self, until: float, limit: int | None, log: EventLog | None, crossings: int | None = None) -> int:
        """Process events at times <= ``until``, at most ``limit`` physical events (None: no limit), returning
        after ``crossings`` cell crossings if given; log each physical event in ``log`` (None: none).
        Returns the physical events processed."""

    def set_disc(self, i: int, vx: float, vy: float, position: tuple[float, float] | None = None) -> None:
        """Give moving disc ``i`` velocity ``(vx, vy)`` (and ``position``, in the box) at ``time``: restart its
        path, move its collision counter on (events predicted against it go stale), move it to its new cell,
        and re-predict it alone."""

    def counts(self) -> dict[str, int]:
        """``collisions``, ``wall_hits``, ``cell_crossings``, ``stale``, ``predictions``."""

    @property
    def dissipated(self) -> float:
        """Kinetic energy lost since the start (restitution, rest; 0 under the default laws)."""

    def resting(self) -> np.ndarray:
        """``(N,)`` bool: the discs at rest under gravity (caller's numbering)."""

    def turning(self) -> tuple[np.ndarray, np.ndarray]:
        """``(spins, angles)``: each disc's spin and angle at ``time``, ``(N,)`` each (caller's numbering)."""

    def disc_counts(self) -> np.ndarray:
        """``(N,)`` int64: each disc's collision counter (its collisions, wall hits and edits so far; obstacles'
        stay put), a new array in the caller's numbering. O(N): the jam guard's, once per suspected jam."""

    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, not wrapped."""

    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, followed across the periodic edges."""

    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time``."""

    def last_event(self) -> tuple[float, int, int, int] | None:
        """``(time, kind, i, j)`` of the last physical event, or None."""

    def queue_size(self) -> int:
        """Events pending now."""

    def queue_storage(self) -> int:
        """Entries the queue holds in memory, dead ones included."""

    def _check(self) -> None:
        """Assert the backend's own invariants."""


class BackendClass(Protocol):
    """What builds a backend: ``BACKENDS[name](scene, grid, queue)``, a backend class (or any such factory).

    The front class builds its backend through this call only; the backend is then started or loaded.
    """

    def __call__(self, scene: Scene, grid: CellGrid, queue: str) -> Backend: ...
