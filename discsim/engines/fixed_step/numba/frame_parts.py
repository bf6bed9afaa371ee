"""The parts the compiled frames share (:mod:`~discsim.engines.fixed_step.numba.kernels`, ``detection``,
``sub_frame``, ``verlet``): the ``jit`` they are compiled with and the scalar parts of
:mod:`discsim.engines.fixed_step.parts` and :mod:`discsim.physics.laws`, compiled from their very source, so that the
compiled frames do the Python frames' arithmetic bit for bit.
"""

from __future__ import annotations

from discsim._compiled import compile_from_source
from discsim._numba import numba
from discsim.engines.fixed_step import parts
from discsim.model import image_step, minimum_image_1d
from discsim.physics import laws

__all__ = ["jit"]

_nb = numba()
if _nb is None:  # pragma: no cover - the engine imports this module only when numba imports

    def jit(function):
        return function

else:
    # error_model="numpy": no zero check on every division; the frame divides only by numbers it has
    # tested (or that cannot vanish), as the Python frame does.
    jit = _nb.njit(cache=True, error_model="numpy")

# The frame's own parts (discsim.engines.fixed_step.parts, and the image count of discsim.model), compiled from
# their source: the Python frames call the same functions.
_parts = compile_from_source(
    (
        minimum_image_1d,
        image_step,
        parts.wrap,
        parts.nearest_image,
        parts.box_image,
        parts.impulse_virial,
        parts.separate_pair,
        parts.push_off_segment,
        parts.restitution,
        parts.kinetic_loss,
        laws.reflect,
        laws.closest_point_on_segment,
        laws.reflect_off_segment,
        laws.rough_impulse,
        parts.spin_loss,
        parts.rough_pair,
        parts._rough_bounce,
        parts.wall_bounce,
        parts.segment_bounce,
        parts.moving_segment_bounce,
    ),
    jit,
)
_separate_pair = _parts[parts.separate_pair]
_push_off_segment = _parts[parts.push_off_segment]
_image_step = _parts[image_step]
_wrap = _parts[parts.wrap]
_nearest_image = _parts[parts.nearest_image]  # the rule as the Python frames' scalar loops compute it
_image = _parts[parts.box_image]  # as Box.minimum_image computes it on arrays (a zero as +0.0)
_impulse_virial = _parts[parts.impulse_virial]
_restitution = _parts[parts.restitution]
_kinetic_loss = _parts[parts.kinetic_loss]
_spin_loss = _parts[parts.spin_loss]
_rough_pair = _parts[parts.rough_pair]
_wall_bounce = _parts[parts.wall_bounce]
_segment_bounce = _parts[parts.segment_bounce]
_moving_segment_bounce = _parts[parts.moving_segment_bounce]
