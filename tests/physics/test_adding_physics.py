"""The worked example of docs/adding-physics.md: a new law of motion, compiled into the event loop, no loop edited.

The toy law is a uniform wind: every disc drifts at ``(WIND, 0)`` on top of its own velocity. It changes free
flight along x and nothing else: a pair's relative motion, and so its time of impact and its collision, are
those of free flight. A periodic gas in the wind is therefore the same gas, without wind, seen from a frame
moving at ``-WIND`` (Galilean invariance): the same collisions and cell crossings at the same times, between the
same discs. The test runs both through the compiled loop, one built over the wind law by
``variants.with_physics``, the other the usual one with every velocity plus the wind.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

import discsim as ds
from discsim._numba import available
from discsim.events import EventLog
from discsim.physics import dynamics
from discsim.scene import Scene

needs_numba = pytest.mark.skipif(not available(), reason="the compiled loop needs numba")

WIND = 0.75  # length / time, along x


# --8<-- [start:law]
def advance(x, y, vx, vy, dt, ax=0.0, ay=0.0, drag=0.0):
    """Free flight plus the wind: the centre drifts at (vx + WIND, vy); the disc's own velocity is unchanged.
    (A law takes the disc's acceleration, then the drag, last, as free flight does; this toy runs without
    either.)"""
    return x + (vx + WIND) * dt, y + vy * dt, vx, vy


def exit_x(x, vx, lo, hi, a=0.0, drag=0.0):
    """Time to leave the slab lo <= x <= hi when moving at vx + WIND along x (the side: 1 up, -1 down)."""
    v = vx + WIND
    if v > 0.0:
        return (hi - x) / v, 1
    if v < 0.0:
        return (lo - x) / v, -1
    return math.inf, 0


#: The law of motion: the five functions of discsim.physics.dynamics. Along y, between two discs, and (in this
#: toy, which the test runs without segments) against segments, motion is free flight's.
wind = SimpleNamespace(
    advance=advance,
    exit_x=exit_x,
    exit_y=dynamics.exit_y,
    pair_time_of_impact=dynamics.pair_time_of_impact,
    segment_time_of_impact=dynamics.segment_time_of_impact,
)
# --8<-- [end:law]


def _run(discs, box, events, law_of_motion=None, collision_law=None, segments=(), interpreted=False):
    """The compiled loop over the given laws (or the same loop interpreted), its first ``events`` physical events:
    the backend and its log."""
    from discsim.engines.event_driven.engine import EventDriven
    from discsim.engines.event_driven.numba.backend import NumbaBackend

    scene = Scene(discs, box, segments)
    grid = EventDriven.cell_grid(discs.radii, box)
    backend = NumbaBackend(
        scene, grid, "calendar", law_of_motion=law_of_motion, collision_law=collision_law, interpreted=interpreted
    )
    backend.start()
    log = EventLog()
    backend.advance(math.inf, events, log)
    return backend, log.to_array()


def _by_pair(log):
    """The log's collisions with each pair's lower-numbered disc first: which disc of a pair owns its event
    depends on which was predicted first, and roundoff may turn that either way."""
    rows = log.copy()
    swap = rows["i"] > rows["j"]
    for a, b in (("i", "j"), ("xi", "xj"), ("yi", "yj"), ("vxi", "vxj"), ("vyi", "vyj")):
        rows[a][swap], rows[b][swap] = log[b][swap], log[a][swap]
    return rows


@pytest.mark.slow  # compiles the event loop anew (about a minute on 2 cores)
@needs_numba
def test_a_gas_in_a_wind_is_the_same_gas_seen_from_a_moving_frame():
    discs, box = ds.random_gas(300, 0.35, periodic=True, seed=4)
    boosted = discs.replace(velocities=discs.velocities + np.array([WIND, 0.0]))
    windy, log = _run(discs, box, 1500, law_of_motion=wind)
    still, reference = _run(boosted, box, 1500)
    log, reference = _by_pair(log), _by_pair(reference)
    assert len(log) == len(reference) == 1500
    # The same collisions, in the same order, at the same times (roundoff apart: the wind is added on every
    # flight instead of once into the velocities).
    np.testing.assert_array_equal(log["i"], reference["i"])
    np.testing.assert_array_equal(log["j"], reference["j"])
    np.testing.assert_allclose(log["time"], reference["time"], rtol=1e-9, atol=1e-9)
    # The centres at contact are the same; the velocities logged are the discs' own: the reference's less the
    # wind along x.
    for name in ("xi", "yi", "xj", "yj", "vyi", "vyj"):
        np.testing.assert_allclose(log[name], reference[name], atol=1e-8)
    np.testing.assert_allclose(log["vxi"] + WIND, reference["vxi"], atol=1e-8)
    np.testing.assert_allclose(log["vxj"] + WIND, reference["vxj"], atol=1e-8)
    # The motion through space is the same: as many cell crossings, the same centres at the end.
    assert windy.counts()["cell_crossings"] == still.counts()["cell_crossings"]
    np.testing.assert_allclose(windy.positions(), still.positions(), atol=1e-8)


@needs_numba
def test_every_function_that_reaches_a_part_is_rebuilt():
    # with_physics swaps parts by name in the functions of PHYSICAL: a function of the loop that calls a part,
    # itself or through another function, and is not in that list would keep free flight.
    from discsim.engines.event_driven.numba import loop
    from discsim.physics.compiled import _NAMES

    functions = {
        name: f.py_func
        for name, f in vars(loop).items()
        if hasattr(f, "py_func") and f.py_func.__module__ == loop.__name__  # the loop's own, not the parts
    }
    calls = {name: set(f.__code__.co_names) for name, f in functions.items()}
    reaching = {name for name, names in calls.items() if names & set(_NAMES)}
    while True:
        more = {name for name, names in calls.items() if names & reaching} - reaching
        if not more:
            break
        reaching |= more
    assert reaching == set(loop.PHYSICAL)


@pytest.mark.slow  # compiles the event loop anew (once for the three scenes)
@needs_numba
def test_the_loop_compiled_over_free_flight_and_the_elastic_law_is_the_usual_loop_bit_for_bit():
    # with_physics over the free-flight and elastic modules themselves: the same events, to the last bit, in a
    # walled box with segments, in a periodic box (crossings through the edges, the minimum image), and after a
    # change of course (set_disc).
    from discsim.physics import laws

    gas, walls = ds.random_gas(200, 0.4, periodic=False, seed=2)
    wall = ds.Segment([0.25 * walls.width, 0.5 * walls.height], [0.75 * walls.width, 0.6 * walls.height])
    clear = wall.distance(gas.positions) > gas.radii * 1.001  # the discs the segment does not cut
    walled = ds.Discs(gas.positions[clear], gas.velocities[clear], gas.radii[clear])
    periodic = ds.random_gas(300, 0.4, periodic=True, seed=3)
    for discs, box, segments in ((walled, walls, [wall]), (*periodic, [])):
        rebuilt, log = _run(discs, box, 1000, law_of_motion=dynamics, collision_law=laws, segments=segments)
        usual, reference = _run(discs, box, 1000, segments=segments)
        assert not segments or usual.counts()["wall_hits"] > 0
        assert log.tobytes() == reference.tobytes()
        for backend in (rebuilt, usual):
            backend.set_disc(7, 0.5, -1.25)
        logs = []
        for backend in (rebuilt, usual):
            more = EventLog()
            backend.advance(math.inf, 500, more)
            logs.append(more.to_array().tobytes())
        assert logs[0] == logs[1]
        assert rebuilt.positions().tobytes() == usual.positions().tobytes()


@pytest.mark.slow  # compiles the event loop anew
@needs_numba
def test_a_law_in_which_no_pair_ever_meets_gives_no_collision():
    # Every part the loop calls comes from the law: discs that never meet (a toy pair time of impact) only
    # cross cells and hit walls.
    never = SimpleNamespace(**{name: getattr(dynamics, name) for name in ("advance", "exit_x", "exit_y")})
    never.pair_time_of_impact = _never
    never.segment_time_of_impact = dynamics.segment_time_of_impact
    discs, box = ds.random_gas(200, 0.4, periodic=False, seed=1)
    backend, log = _run(discs, box, 300, law_of_motion=never)
    assert len(log) == 300 and backend.counts()["collisions"] == 0 and backend.counts()["wall_hits"] == 300


def _never(dx, dy, dvx, dvy, sigma, dax=0.0, day=0.0, drag=0.0):
    """A pair time of impact for discs that pass through each other (the relative acceleration last, as every
    law's)."""
    return math.inf


def test_the_interpreted_loop_over_free_flight_is_the_pure_python_backend_bit_for_bit():
    # The loop the compiled backend compiles, run by the interpreter (no numba needed): with free flight and the
    # elastic law, the pure-Python backend's events to the last bit, in a walled box and a periodic one.
    from discsim.engines.event_driven.python import PythonBackend

    for periodic, seed in ((False, 5), (True, 6)):
        discs, box = ds.random_gas(120, 0.4, periodic=periodic, seed=seed)
        interpreted, log = _run(discs, box, 600, interpreted=True)
        assert interpreted.name == "python"
        scene = Scene(discs, box)
        from discsim.engines.event_driven.engine import EventDriven

        usual = PythonBackend(scene, EventDriven.cell_grid(discs.radii, box), "calendar")
        usual.start()
        reference = EventLog()
        usual.advance(math.inf, 600, reference)
        assert log.tobytes() == reference.to_array().tobytes()
        assert interpreted.positions().tobytes() == usual.positions().tobytes()


def test_the_interpreted_loop_runs_a_new_law_as_the_compiled_one_would():
    # The wind law in the interpreter: the Galilean check of the compiled test above, with no numba needed.
    discs, box = ds.random_gas(150, 0.35, periodic=True, seed=4)
    boosted = discs.replace(velocities=discs.velocities + np.array([WIND, 0.0]))
    windy, log = _run(discs, box, 400, law_of_motion=wind, interpreted=True)
    still, reference = _run(boosted, box, 400, interpreted=True)
    log, reference = _by_pair(log), _by_pair(reference)
    np.testing.assert_array_equal(log["i"], reference["i"])
    np.testing.assert_allclose(log["time"], reference["time"], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(log["vxi"] + WIND, reference["vxi"], atol=1e-8)
    np.testing.assert_allclose(windy.positions(), still.positions(), atol=1e-8)


@needs_numba
@pytest.mark.slow  # compiles the event loop anew
def test_the_interpreted_loop_gives_the_compiled_loops_events_bit_for_bit_under_a_new_law():
    discs, box = ds.random_gas(150, 0.35, periodic=True, seed=8)
    _, compiled = _run(discs, box, 400, law_of_motion=wind)
    _, interpreted = _run(discs, box, 400, law_of_motion=wind, interpreted=True)
    assert compiled.tobytes() == interpreted.tobytes()


@pytest.mark.parametrize("parts", [{"law_of_motion": wind}, {"collision_law": SimpleNamespace()}])
def test_a_law_of_ones_own_under_other_laws_is_refused_naming_both(parts):
    from discsim.engines.event_driven.engine import EventDriven
    from discsim.engines.event_driven.numba.backend import NumbaBackend
    from discsim.errors import InvalidArgumentError
    from discsim.laws import Laws

    discs, box = ds.random_gas(10, 0.2, seed=1)
    scene, grid = Scene(discs, box), EventDriven.cell_grid(discs.radii, box)
    name = next(iter(parts))
    with pytest.raises(InvalidArgumentError, match=rf"{name}=SimpleNamespace.*default laws.*gravity=\(0.0, -9.81\)"):
        NumbaBackend(scene, grid, "calendar", laws=Laws.build(gravity=(0.0, -9.81)), interpreted=True, **parts)
