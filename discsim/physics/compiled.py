"""The physics parts compiled by numba from their very source, for the compiled loops.

Each is ``inline``: compiled into every compiled loop that calls it (a call between compiled functions passes
each array argument as a struct, and the parts are called once per candidate or event), so a loop that calls
:func:`advance` runs the same machine code as one that wrote ``x + vx * dt`` itself. Imported only by the
compiled modules (``engines/*/numba/``); without numba the names are the plain Python functions.
"""

from __future__ import annotations

from discsim import model
from discsim._compiled import compile_from_source, inline
from discsim.physics import dynamics, laws
from discsim.physics.sources import boundaries, pairs

__all__ = [
    "advance",
    "closest_point_on_segment",
    "collide",
    "cross",
    "exit_x",
    "exit_y",
    "minimum_image_1d",
    "pair_predict",
    "pair_resolve",
    "pair_time_of_impact",
    "predict_x",
    "predict_y",
    "reflect",
    "reflect_off_segment",
    "segment_time_of_impact",
    "wall_time",
]

_parts = compile_from_source(
    [
        model.minimum_image_1d,
        dynamics.advance,
        dynamics.exit_x,
        dynamics.exit_y,
        dynamics.pair_time_of_impact,
        dynamics.segment_time_of_impact,
        laws.collide,
        laws.reflect,
        laws.closest_point_on_segment,
        laws.reflect_off_segment,
        pairs.predict,
        pairs.resolve,
        boundaries.predict_x,
        boundaries.predict_y,
        boundaries.cross,
        boundaries.wall_time,
    ],
    inline,
)
minimum_image_1d = _parts[model.minimum_image_1d]
advance = _parts[dynamics.advance]
exit_x = _parts[dynamics.exit_x]
exit_y = _parts[dynamics.exit_y]
pair_time_of_impact = _parts[dynamics.pair_time_of_impact]
segment_time_of_impact = _parts[dynamics.segment_time_of_impact]
collide = _parts[laws.collide]
reflect = _parts[laws.reflect]
reflect_off_segment = _parts[laws.reflect_off_segment]
closest_point_on_segment = _parts[laws.closest_point_on_segment]
pair_predict = _parts[pairs.predict]
pair_resolve = _parts[pairs.resolve]
predict_x = _parts[boundaries.predict_x]
predict_y = _parts[boundaries.predict_y]
cross = _parts[boundaries.cross]
wall_time = _parts[boundaries.wall_time]
