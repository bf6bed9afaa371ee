"""Adversarial checks of the kinematic crush detection (issue 28, review 17): runs that no crush would stop must
not be refused. Every test runs on both backends (the directory's conftest); every run is bounded with events=."""

import math

import numpy as np
import pytest

import discsim as ds
from discsim.errors import JammedError


@pytest.mark.slow_on_python  # (3 s interpreted)
def test_a_lid_over_ghost_discs_that_pass_through_each_other_is_not_bounded_by_their_area():
    # 30 discs of radius 0.5 that pass through each other take no room from one another: under a lid from 9 at -1
    # they fit until the lid is at their diameter 1 (t = 8). The area bound (their area over the box's width,
    # 2.356, reached at t = 6.64) said "crushed" and stopped the run at t = 5.1 (the first look).
    rng = np.random.default_rng(0)
    n = 30
    positions = np.column_stack([rng.uniform(0.6, 9.4, n), rng.uniform(0.6, 6.0, n)])
    discs = ds.Discs(positions, rng.normal(0.0, 100.0, (n, 2)), radii=0.5, groups=np.zeros(n, int))
    lid = ds.Piston(mass=math.inf, pressure=0.0, height=9.0, velocity=-1.0)
    sim = ds.EventDriven(discs, ds.Box(10.0, 10.0), piston=lid, pass_through={(0, 0)})
    sim.run(until=7.5, events=2_000_000)
    assert sim.time == 7.5 and sim.piston.height == pytest.approx(1.5)
    sim._check()
    with pytest.raises(JammedError, match="crushes disc"):  # past the diameter: crushed (the bound that holds)
        sim.run(until=9.0, events=2_000_000)


@pytest.mark.slow  # (8 s interpreted, 3 s compiled: 400,000 events)
def test_a_lid_a_callback_steers_up_half_way_to_the_crush_does_not_stop_a_busy_gas():
    # 20 fast discs under a lid from 28.07 at -1: their area would be reached at t = 25.56, but a callback turns the
    # lid up at half that time. The run was refused at t = 4.43.
    discs, _ = ds.random_gas(20, 0.1, seed=1, periodic=False)
    box = ds.Box(float(discs.positions[:, 0].max()) + 1.0, 100.0)
    top = float((discs.positions[:, 1] + discs.radii).max()) + 3.0
    discs = ds.Discs(discs.positions, discs.velocities * 300.0, radii=discs.radii)
    sim = ds.EventDriven(discs, box, piston=ds.Piston(mass=math.inf, pressure=0.0, height=top, velocity=-1.0))
    turn = (top - float(np.sum(math.pi * discs.radii**2)) / box.width) / 2.0
    sim.on("wall", lambda sim, _: sim.set_piston(velocity=1.0) if sim.time > turn and sim.piston.velocity < 0 else None)
    sim.run(until=2.0 * turn + 1.0, events=400_000)
    assert sim.time == 2.0 * turn + 1.0 and sim.piston.velocity == 1.0


def row_squeeze():
    """Three discs in a row at rest, y = 5, x = 1, 3, 5, and the paddle x = 8 - t pushing them into the wall x = 0:
    no single disc is caught for certain (each has neighbours), so only the backstop can stop it before t = 5."""
    paddle = ds.Segment((8.0, 4.0), (8.0, 6.0), velocity=(-1.0, 0.0))
    discs = ds.Discs([[1.0, 5.0], [3.0, 5.0], [5.0, 5.0]], np.zeros((3, 2)), radii=0.5)
    sim = ds.EventDriven(discs, ds.Box(10.0, 10.0), segments=[paddle])
    sim.squeeze_speedup, sim.jam_events = 100.0, 1_000  # (the backstop sooner, looking every 650 events)
    return sim


def test_the_backstop_stops_a_row_of_discs_squeezed_by_a_paddle():
    sim = row_squeeze()
    with pytest.raises(JammedError, match="100 times the speed scale"):
        sim.run(until=20.0, events=3_000)
    assert sim.time < 5.0
    sim._check()


def test_the_backstop_stops_a_squeeze_whose_callback_steers_the_paddle_at_each_contact():
    sim = row_squeeze()
    sim.on("segment", lambda sim, _: sim.set_segment_velocity(0, (-1.0, 0.0)))  # (a paddle AI: the same velocity)
    with pytest.raises(JammedError, match="100 times the speed scale"):
        sim.run(until=20.0, events=3_000)  # (now: returns at the event limit, the fastest disc at ~700)
