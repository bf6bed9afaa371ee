"""The physics parts compiled by numba from their very source, for the compiled loops.

Each is ``jit``: compiled once, on its own, and called by the compiled loops. The parts take and return
scalars only, so LLVM inlines them into their callers, and the loops run as fast as when they wrote
``x + vx * dt`` themselves (1.02x at N = 10^3 and 10^4 against the loop before the parts). numba's own
inlining (``inline="always"``, which the loops use for functions taking many arrays) re-types a function at
every call site: over the parts it made the first compile of the event loop 1.77x longer (32.7 s against
18.5 s); compiled on their own, 15.2 s. Imported only by the compiled modules (``engines/*/numba/``); without
numba the names are the plain Python functions.
"""

from __future__ import annotations

from discsim import model
from discsim._compiled import compile_from_source, interpret, jit
from discsim._numba import numba
from discsim.physics import damped, dynamics, laws, roots
from discsim.physics.sources import boundaries, pairs, piston, sensors

__all__ = [
    "DYNAMICS",
    "LAWS",
    "advance",
    "closest_point_on_segment",
    "collide",
    "compile_parts",
    "cross",
    "exit_x",
    "exit_y",
    "minimum_image_1d",
    "pair_predict",
    "pair_resolve",
    "pair_time_of_impact",
    "piston_at",
    "piston_bounce",
    "piston_contact",
    "predict_x",
    "predict_y",
    "reflect",
    "reflect_off_segment",
    "rough_impulse",
    "segment_time_of_impact",
    "sensor_contains",
    "sensor_on_wire",
    "sensor_predict",
    "wall_time",
]

#: The functions a law of motion defines (:mod:`discsim.physics.dynamics` is the model), and a collision law
#: (:mod:`discsim.physics.laws`).
DYNAMICS = ("advance", "exit_x", "exit_y", "pair_time_of_impact", "segment_time_of_impact")
LAWS = ("collide", "reflect", "closest_point_on_segment", "reflect_off_segment")
#: Every part, callees before callers.
_SOURCES = (
    model.minimum_image_1d,
    *roots.PARTS,
    *damped.PARTS,
    *(getattr(dynamics, name) for name in DYNAMICS if name != "segment_time_of_impact"),
    dynamics._falling_segment_time,
    dynamics.segment_time_of_impact,
    *(getattr(laws, name) for name in LAWS),
    laws.rough_impulse,
    pairs.predict,
    pairs.resolve,
    boundaries.predict_x,
    boundaries.predict_y,
    boundaries.cross,
    boundaries.wall_time,
    *sensors.PARTS,
    *piston.PARTS,
)
#: The names the compiled loops import, and the source of each.
_NAMES = {
    "minimum_image_1d": model.minimum_image_1d,
    **{name: getattr(dynamics, name) for name in DYNAMICS},
    **{name: getattr(laws, name) for name in LAWS},
    "rough_impulse": laws.rough_impulse,
    "pair_predict": pairs.predict,
    "pair_resolve": pairs.resolve,
    "predict_x": boundaries.predict_x,
    "predict_y": boundaries.predict_y,
    "cross": boundaries.cross,
    "wall_time": boundaries.wall_time,
    "sensor_predict": sensors.predict,
    "sensor_contains": sensors.contains,
    "sensor_on_wire": sensors.on_wire,
    "piston_at": piston.at,
    "piston_contact": piston.contact_time,
    "piston_bounce": piston.bounce,
}


def compile_parts(law_of_motion=None, collision_law=None, *, interpreted: bool = False) -> dict:
    """Every part compiled (``jit``), over another law of motion or collision law if given.

    Args:
        law_of_motion: a module (or any object) with the functions :data:`DYNAMICS` names, with the
            signatures of :mod:`discsim.physics.dynamics`; None: free flight.
        collision_law: likewise with the functions :data:`LAWS` names (:mod:`discsim.physics.laws`); None:
            elastic and frictionless.
        interpreted: rebuild the parts over the laws but compile nothing (they run in the interpreter).

    Returns:
        A dict from the names the compiled loops use (``advance``, ``pair_predict``, ``predict_x`` ...) to the
        compiled parts.
    """
    replace = {}
    if law_of_motion is not None:
        replace.update({getattr(dynamics, name): getattr(law_of_motion, name) for name in DYNAMICS})
    if collision_law is not None:
        replace.update({getattr(laws, name): getattr(collision_law, name) for name in LAWS})
    decorate = interpret if interpreted else jit
    nb = numba()
    if replace and nb is not None and not interpreted:
        # Not cached on disk: numba would file these under the very names of the free-flight parts (its cache
        # knows a function by its source file and name, not by the parts compiled into it).
        decorate = nb.njit(cache=False, nogil=True, error_model="numpy", _nrt=False)
    compiled = compile_from_source(_SOURCES, decorate, replace)
    return {name: compiled[source] for name, source in _NAMES.items()}


_parts = compile_parts()
minimum_image_1d = _parts["minimum_image_1d"]
advance = _parts["advance"]
exit_x = _parts["exit_x"]
exit_y = _parts["exit_y"]
pair_time_of_impact = _parts["pair_time_of_impact"]
segment_time_of_impact = _parts["segment_time_of_impact"]
collide = _parts["collide"]
reflect = _parts["reflect"]
closest_point_on_segment = _parts["closest_point_on_segment"]
reflect_off_segment = _parts["reflect_off_segment"]
rough_impulse = _parts["rough_impulse"]
pair_predict = _parts["pair_predict"]
pair_resolve = _parts["pair_resolve"]
predict_x = _parts["predict_x"]
predict_y = _parts["predict_y"]
cross = _parts["cross"]
wall_time = _parts["wall_time"]
sensor_predict = _parts["sensor_predict"]
sensor_contains = _parts["sensor_contains"]
sensor_on_wire = _parts["sensor_on_wire"]
piston_at = _parts["piston_at"]
piston_contact = _parts["piston_contact"]
piston_bounce = _parts["piston_bounce"]
