"""The event-driven engine's invariants, checked over its public run state (any backend).

:func:`check` asserts, in O(N), everything a consistent run must satisfy; the stress tests call it after each
step (as sortedcontainers' ``_check``). A backend adds its own internal checks (``backend._check()``).
"""

from __future__ import annotations

import numpy as np

from discsim.model import Discs
from discsim.scene import check_fits

__all__ = ["check"]


def check(sim) -> None:
    """Assert every invariant of the event-driven engine ``sim`` and of its backend.

    - every disc is in exactly one cell, the cell it lies in (or on its boundary, within roundoff);
    - each disc has at most one pending event, none in the past, and a moving disc has one; the queue
      holds at most N events;
    - collision events name a partner, kept collisions a valid partner;
    - the discs fit in the box without overlap (as the constructor checks), and under the piston if there is one.

    Raises:
        AssertionError, or CheckpointError from :meth:`EventDrivenState.check` for the state's own form.
    """
    sim._backend._check()
    state = sim.state()
    n = len(sim.discs)
    grid, box = sim.grid, sim.box
    assert (state.grid_nx, state.grid_ny) == (grid.nx, grid.ny)
    # Shapes, finiteness, each disc in exactly one cell and listed there, one event per owner, partners
    # in range: what a loaded state must satisfy too.
    state.check(n, len(grid))
    laws = sim.laws
    falls = np.isfinite(sim.discs.masses) & (state.resting == 0)
    pos = box.wrap(state.positions_at(state.time, laws.gravity if laws.falls else None, falls, laws.drag))
    expected = grid.cells_of(pos)
    tol = 1e-9 * max(grid.lx, grid.ly)
    for i in np.flatnonzero(expected != state.cell).tolist():  # only allowed on a cell boundary, within roundoff
        cx, cy = divmod(int(state.cell[i]), grid.ny)
        x, y = pos[i]
        inside_x = cx * grid.lx - tol <= x <= (cx + 1) * grid.lx + tol or (
            box.periodic and (x < tol or x > box.width - tol)
        )
        inside_y = cy * grid.ly - tol <= y <= (cy + 1) * grid.ly + tol or (
            box.periodic and (y < tol or y > box.height - tol)
        )
        assert inside_x and inside_y, f"disc {i} at {pos[i]} is not in its cell {int(state.cell[i])}"
    now = state.time - state.epoch
    assert (state.queue_time >= now - 1e-12 * max(1.0, state.time)).all(), "an event lies in the past"
    moving = np.isfinite(sim.discs.masses) & (state.velocities != 0).any(axis=1)
    pending = np.zeros(n, dtype=bool)
    pending[state.queue_owner] = True
    idle = moving & ~pending  # a moving disc always has a wall, a crossing or a collision ahead,
    if laws.drag != 0.0 and not laws.falls:  # unless drag stops it first
        idle[:] = False
    assert not idle.any(), f"moving disc {np.flatnonzero(idle)[0]} has no pending event"
    d = sim.discs
    check_fits(Discs(sim.positions, sim.velocities, d.radii, d.masses, d.groups), box, pass_through=sim.pass_through)
    piston = sim.piston
    if piston is not None and n:
        top = sim.positions[:, 1] + d.radii
        assert top.max() <= piston.height + 1e-9 * box.height, f"disc {int(top.argmax())} is above the piston"
