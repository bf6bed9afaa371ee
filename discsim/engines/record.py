"""What every engine reads from its event log: the log kept in memory and what is rebuilt from it.

Numbers from the records only, so that an engine restoring an old checkpoint (``FixedStep``'s version 1
state) and the analyses above (:mod:`discsim.analysis.thermo`) share one definition.
"""

from __future__ import annotations

import numpy as np

from discsim.events import COLLISION

__all__ = ["collision_virials"]


def collision_virials(events: np.ndarray, masses: np.ndarray, box) -> tuple[np.ndarray, np.ndarray]:
    """``(times, W)`` of the disc-disc collisions in ``events``: each collision's virial ``dp_i . (r_i - r_j)``.

    From the state after the collision only: with ``mu`` the reduced mass (the finite one for an obstacle),
    ``W = 2 mu (u_i - u_j) . (r_i - r_j)``, ``u`` the velocities after and ``r_i - r_j`` the minimum image.
    Summed over a run, this is the engine's own virial (``pressure()``) to roundoff.

    Args:
        events: structured array ``(E,)`` of :data:`~discsim.events.EVENT_DTYPE`.
        masses: ``(N,)`` the discs' masses. box: the box.

    Returns:
        ``(C,)`` times and ``(C,)`` virials (energy units) of the ``C`` collisions.
    """
    rows = events[events["kind"] == COLLISION]
    mi = masses[rows["i"]]
    mj = masses[rows["j"]]
    with np.errstate(invalid="ignore"):
        mu = np.where(np.isinf(mj), mi, np.where(np.isinf(mi), mj, mi * mj / (mi + mj)))
    d = box.minimum_image(np.column_stack([rows["xi"] - rows["xj"], rows["yi"] - rows["yj"]]))
    w = 2.0 * mu * ((rows["vxi"] - rows["vxj"]) * d[:, 0] + (rows["vyi"] - rows["vyj"]) * d[:, 1])
    return rows["time"].astype(float), w
