"""What a compression did: :class:`CompressionReport`, and the bounds every compression shares."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["DENSEST_PACKING", "HISTORY", "CompressionReport"]

#: The densest packing of equal discs in the plane, the triangular lattice: pi / (2 sqrt 3) = 0.9069.
DENSEST_PACKING = math.pi / (2.0 * math.sqrt(3.0))
#: One row per thermostat epoch: packing, collisions so far, seconds so far, Z, simulated time.
HISTORY = np.dtype([("packing", "f8"), ("collisions", "i8"), ("seconds", "f8"), ("z", "f8"), ("time", "f8")])


@dataclass(frozen=True)
class CompressionReport:
    """What :func:`compress` did.

    Attributes:
        packing_fraction: the packing reached (after the final shrink, if any).
        target: the packing asked for.
        reached: True when the target was reached (to within the final shrink).
        jammed: True when the compression stopped because the pressure diverged below the target.
        reason: ``"reached"``, ``"jammed"`` or ``"max_collisions"``; ``"running"`` for the report of a
            :class:`~discsim.engines.compress.engine.Compression` that has not finished.
        collisions: disc-disc collisions in all. wall_events: disc-wall collisions.
        time: simulated time of the compression. seconds: wall-clock time.
        z: the reduced pressure ``PA / NkT`` (collision virial) of the last epoch; it diverges at jamming.
        epochs: thermostat epochs run. shrink: the factor the radii were scaled by at the end (1.0: none).
        backend: ``"python"`` or ``"numba"``.
        history: one row per epoch: packing, collisions so far, seconds so far, Z, simulated time.
    """

    packing_fraction: float
    target: float
    reached: bool
    jammed: bool
    reason: str
    collisions: int
    wall_events: int
    time: float
    seconds: float
    z: float
    epochs: int
    shrink: float
    backend: str
    history: np.ndarray

    def collisions_to(self, packing: float, n: int) -> float:
        """Collisions per disc (``n`` discs) spent to reach ``packing``, interpolated between epochs (nan if never)."""
        h = self.history
        if len(h) == 0 or h["packing"][-1] < packing * (1.0 - 1e-9):
            return math.nan
        k = int(np.searchsorted(h["packing"], packing * (1.0 - 1e-9)))
        if k == 0:
            return float(h["collisions"][0]) / n
        p0, p1 = h["packing"][k - 1], h["packing"][k]
        c0, c1 = h["collisions"][k - 1], h["collisions"][k]
        w = (packing - p0) / (p1 - p0) if p1 > p0 else 1.0
        return float(c0 + w * (c1 - c0)) / n

    def __str__(self) -> str:
        what = {
            "reached": "reached",
            "jammed": "JAMMED below",
            "max_collisions": "ran out of collisions (max_collisions) below",
            "running": "so far, on the way to",
        }[self.reason]
        return (
            f"packing {self.packing_fraction:.6f} ({what} the target {self.target:g}) after {self.collisions:,} "
            f"collisions, simulated time {self.time:.6g}, {self.seconds:.3g} s ({self.backend}), Z = {self.z:.4g}"
        )
