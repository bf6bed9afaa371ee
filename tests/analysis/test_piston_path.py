"""The piston's knots read back from a run's log (discsim.analysis.piston_path): its height at any time against
``sim.piston`` sampled while the run goes on, across set_piston, and bad input."""

import numpy as np
import pytest

import discsim as ds
from discsim.analysis.piston_path import piston_path
from discsim.errors import InvalidArgumentError


def _gas(n=8, seed=2):
    discs, _ = ds.random_gas(n, 0.15, seed=seed, periodic=False)
    box = ds.Box(discs.positions[:, 0].max() + 1.5, 80.0)
    return discs, box


def _top(discs):
    return float((discs.positions[:, 1] + discs.radii).max()) + 3.0


def _sampled(sim, times, changes=None):
    """``sim.piston.height`` at each of ``times`` (the run stopped there); ``changes``: {time: pressure}."""
    changes = changes or {}
    out = []
    for t in times:
        sim.run(until=float(t))
        out.append(sim.piston.height)
        if float(t) in changes:
            sim.set_piston(pressure=changes[float(t)])
    return np.array(out)


def test_the_knots_start_at_the_scene_s_piston_hold_every_impact_and_give_the_height_the_run_had():
    discs, box = _gas()
    piston = ds.Piston(mass=5.0, pressure=0.4, height=_top(discs), velocity=-0.2)
    sim = ds.EventDriven(discs, box, piston=piston)
    times = np.linspace(0.37, 14.8, 40)
    heights = _sampled(sim, times)
    path = piston_path(sim)
    hits = sim.events[(sim.events["kind"] == int(ds.EventKind.WALL)) & np.isfinite(sim.events["yj"])]
    assert sim.piston.hits == len(hits) > 10
    assert (path.times[0], path.heights[0], path.velocities[0]) == (0.0, piston.height, -0.2)
    assert np.array_equal(path.times[1:-1], hits["time"]) and np.array_equal(path.heights[1:-1], hits["yj"])
    assert (path.times[-1], path.heights[-1], path.velocities[-1]) == (sim.time, sim.piston.height, sim.piston.velocity)
    assert path.accel == pytest.approx(np.full(len(path.accel), 0.4 * box.width / 5.0), rel=1e-14)
    assert path.height(times) == pytest.approx(heights, rel=1e-12)
    assert path.height(times.reshape(4, 10)).shape == (4, 10)


def test_a_pressure_changed_mid_run_is_followed_and_only_the_pieces_that_held_a_change_are_approximate():
    discs, box = _gas(seed=5)
    sim = ds.EventDriven(discs, box, piston=ds.Piston(mass=5.0, pressure=0.4, height=_top(discs)))
    times = np.linspace(0.31, 18.6, 60)
    changes = {float(times[19]): 0.8, float(times[39]): 1.2}
    heights = _sampled(sim, times, changes)
    path = piston_path(sim)
    per = box.width / 5.0
    pieces = np.searchsorted(path.times, times, side="right") - 1
    broken = np.searchsorted(path.times, list(changes), side="right") - 1
    exact = ~np.isin(pieces, broken) | np.isin(times, path.times)
    assert exact.sum() >= 45
    assert path.height(times[exact]) == pytest.approx(heights[exact], rel=1e-12)
    # each piece's acceleration is a pressure's (the middle one, never given, read from its pieces' ends), but the
    # two that held a change (joined end to end)
    pressures = np.array([0.4, 0.8, 1.2]) * per
    nearest = np.abs(np.delete(path.accel, broken)[:, None] - pressures).argmin(axis=1)
    assert np.delete(path.accel, broken) == pytest.approx(pressures[nearest], rel=1e-9)
    assert set(nearest.tolist()) == {0, 1, 2} and not np.isclose(path.accel[broken][:, None], pressures).any()
    ends = path.heights[broken + 1]
    assert path.height(path.times[broken + 1] - 1e-15) == pytest.approx(ends, rel=1e-9)


def test_under_gravity_the_piston_falls_with_its_weight_too():
    discs, box = _gas(seed=7)
    g = 0.3
    sim = ds.EventDriven(discs, box, piston=ds.Piston(mass=5.0, pressure=0.4, height=_top(discs)), gravity=(0.0, -g))
    times = np.linspace(0.29, 11.6, 40)
    heights = _sampled(sim, times)
    path = piston_path(sim)
    assert sim.piston.hits > 5 and path.accel == pytest.approx(
        np.full(len(path.accel), 0.4 * box.width / 5.0 + g), rel=1e-14
    )
    assert path.height(times) == pytest.approx(heights, rel=1e-12)


def test_a_run_without_a_piston_or_a_log_is_refused_by_name():
    discs, box = _gas()
    with pytest.raises(InvalidArgumentError, match="needs a run with a piston"):
        piston_path(ds.EventDriven(discs, box).run(until=1.0))
    unrecorded = ds.EventDriven(
        discs, box, piston=ds.Piston(mass=5.0, pressure=0.4, height=_top(discs)), record=False
    ).run(until=1.0)
    with pytest.raises(InvalidArgumentError, match="record"):
        piston_path(unrecorded)
