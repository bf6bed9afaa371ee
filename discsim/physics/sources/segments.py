"""Fixed segments: when a disc touches one, and how it bounces off.

Example:
    >>> predict(0.0, 5.0, 0.0, -1.0, 1.0, -3.0, 0.0, 3.0, 0.0)
    4.0
    >>> resolve(0.0, 1.0, 1.0, -2.0, -3.0, 0.0, 3.0, 0.0)
    (1.0, 2.0)
"""

from __future__ import annotations

from discsim.physics.dynamics import segment_time_of_impact as predict
from discsim.physics.laws import reflect_off_segment as resolve

__all__ = ["predict", "resolve"]
