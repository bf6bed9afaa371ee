"""Kinematic walls closing on a disc (a paddle against a wall, a lid over the floor): the run stops with a
JammedError that names the disc, the walls and the exact time they crush it, instead of creeping towards that time
for ever (infinitely many bounces come before it). Every test runs on both backends (the directory's conftest)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds
from discsim.engines.event_driven.squeeze import lid_crush, squeeze
from discsim.errors import JammedError

BOX = ds.Box(10.0, 10.0)


def paddle_run(vy=0.0, gravity=None, others=()):
    """The paddle x = 8 - t, from y = 4 to 6, meets a disc of radius 0.5 resting at (5, 5) against the wall x = 0
    at t = 7 (the gap between them is then its diameter)."""
    paddle = ds.Segment((8.0, 4.0), (8.0, 6.0), velocity=(-1.0, 0.0))
    discs = ds.Discs([[5.0, 5.0], *others], [[0.0, vy]] + [[0.0, 0.0]] * len(others), radii=0.5)
    return ds.EventDriven(discs, BOX, segments=[paddle], gravity=gravity)


@pytest.mark.slow_on_python
def test_a_paddle_squeezing_a_disc_against_a_wall_raises_at_the_crush_time_naming_them():
    sim = paddle_run()
    bound = 3 * (sim.jam_events + sim.jam_events_per_disc)  # (before the fix: never ended)
    with pytest.raises(JammedError) as caught:
        sim.run(until=20.0, events=bound)
    text = str(caught.value)
    assert "segments[0] (kinematic) and the box's left wall crush disc 0 (radius 0.5)" in text
    assert "at time 7.0" in text
    assert 6.99 < sim.time < 7.0  # consistent at its last whole event, short of the crush
    sim._check()
    assert abs(sim.velocities[0, 0]) > 1000.0  # (it gains 2 at each return from the paddle)
    # Steering the paddle back lets the run go on (the disc gives back what it gained as the gap widens).
    sim.set_segment_velocity(0, (1.0, 0.0))
    until = sim.time + 1.0
    sim.run(until=until)
    assert sim.time == until and 0.5 <= sim.positions[0, 0] <= 8.0 - 7.0 + 1.0 - 0.5
    sim._check()


def test_a_run_that_stops_before_the_crush_is_not_refused():
    sim = paddle_run().run(until=6.9)
    # The paddle meets the disc at t = 2.5 (at rest: it leaves at 2), the wall returns it, and so on: the n-th
    # return from the wall comes at speed 2n, the disc sent back from x = 0.5 at each.
    assert sim.counts["wall_hits"] > 20 and 0.5 <= sim.positions[0, 0] <= 8.0 - 6.9 - 0.5


def test_a_disc_that_slides_out_of_the_paddle_s_span_before_the_crush_is_not_refused():
    # At 0.2 along y it passes the paddle's end y = 6 (less its margin) at t = 5, before the crush at 7.
    sim = paddle_run(vy=0.2).run(until=20.0)
    assert sim.time == 20.0 and sim.counts["wall_hits"] > 2


def test_a_falling_disc_leaves_a_short_paddle_and_a_tall_one_crushes_it():
    # Under gravity 0.01 down, the disc falls 0.245 by t = 7: it stays within a paddle from y = 4 to 6 (crushed),
    # but gravity 0.1 takes it below y = 4 by t = 4.5 (let go).
    with pytest.raises(JammedError, match="at time 7.0"):
        paddle_run(gravity=(0.0, -0.01)).run(until=20.0)
    sim = paddle_run(gravity=(0.0, -0.1)).run(until=12.0)
    assert sim.time == 12.0


def test_a_disc_near_the_squeezed_one_makes_the_crush_uncertain():
    # A second disc on the far side of the wall's corridor could knock the first out: no certain crush from
    # squeeze() (the function alone, at the start: the paddle 2.5 from the disc).
    positions = np.array([[5.0, 5.0], [5.0, 7.0]])
    velocities = np.array([[0.0, 0.0], [0.0, -0.1]])
    paddle = [ds.Segment((8.0, 4.0), (8.0, 6.0), velocity=(-1.0, 0.0))]
    alone = squeeze(BOX, paddle, None, positions[:1], velocities[:1], np.array([0.5]), (0.0, 0.0), 0, math.inf)
    assert alone is not None and alone.after == 7.0
    radii = np.array([0.5, 0.5])
    assert squeeze(BOX, paddle, None, positions, velocities, radii, (0.0, 0.0), 0, math.inf) is None
    assert squeeze(BOX, paddle, None, positions[:1], velocities[:1], radii[:1], (0.0, 0.0), 0, 6.5) is None  # later


def test_a_paddle_against_a_parallel_fixed_segment_crushes_at_the_closed_form_time():
    # A fixed segment x = 2 (y from 0 to 10) and the paddle x = 8 - 0.5 t: the gap reaches 1 at t = 10.
    paddle = ds.Segment((8.0, 4.0), (8.0, 6.0), velocity=(-0.5, 0.0))
    fence = ds.Segment((2.0, 0.5), (2.0, 9.5))
    sim = ds.EventDriven(ds.Discs([[5.0, 5.0]], [[0.3, 0.0]], radii=0.5), BOX, segments=[fence, paddle])
    with pytest.raises(JammedError, match=r"segments\[1\] \(kinematic\) and segments\[0\] crush disc 0.*at time 10.0"):
        sim.run(until=30.0)


def lid_run():
    lid = ds.Piston(mass=math.inf, pressure=0.0, height=8.0, velocity=-1.0)  # reaches the diameter 1 at t = 7
    return ds.EventDriven(ds.Discs([[5.0, 2.0]], [[0.0, 1.0]], radii=0.5), BOX, piston=lid)


@pytest.mark.slow_on_python
def test_a_lid_closing_on_a_disc_stops_the_run_short_of_the_crush():
    sim = lid_run()
    with pytest.raises(JammedError, match=r"the kinematic lid reaches height 1.0 and crushes disc 0 .* at time 7.0"):
        sim.run(until=7.5)
    assert 6.9 < sim.time < 7.0
    sim._check()
    sim.set_piston(velocity=0.5)  # going up again: the run goes on
    sim.run(until=sim.time + 1.0)


def test_a_lid_steered_up_by_a_callback_before_the_crush_runs_on():
    # The crush it was headed for at t = 7 never comes: the check looks at the lid as the callback left it.
    sim = lid_run()
    sim.on("wall", lambda sim, contact: sim.set_piston(velocity=1.0) if sim.time > 5.0 else None)
    sim.run(until=12.0)
    assert sim.time == 12.0 and sim.piston.velocity == 1.0
    sim = lid_run().run(until=6.5)  # short of it: runs
    assert sim.piston.height == pytest.approx(1.5)


def test_a_lid_over_many_discs_is_bounded_by_their_area():
    # 30 discs of radius 0.5 in a box 10 wide need a height of at least 30 pi 0.25 / 10 = 2.356 (more than their
    # diameter): the lid from 9 at 0.5 down reaches it at t = 13.29.
    found = lid_crush(np.full(30, 0.5), 10.0, 9.0, -0.5)
    assert found.after == pytest.approx((9.0 - 30 * math.pi * 0.25 / 10.0) / 0.5, rel=1e-15)
    assert "the discs (their area" in found.what
    assert lid_crush(np.full(30, 0.5), 10.0, 9.0, 0.0) is None  # standing still: never
    discs, _ = ds.random_gas(30, 0.2, seed=1, periodic=False)
    box = ds.Box(float(discs.positions[:, 0].max()) + 1.0, 100.0)
    top = float((discs.positions[:, 1] + discs.radii).max()) + 1.0
    sim = ds.EventDriven(discs, box, piston=ds.Piston(mass=math.inf, pressure=0.0, height=top, velocity=-1.0))
    crush = float(np.sum(math.pi * discs.radii**2)) / box.width
    with pytest.raises(JammedError, match="crushes the discs"):
        sim.run(until=top - crush + 1e-9)
    assert sim.time < top - crush


@pytest.mark.slow_on_python
@settings(max_examples=15, deadline=None)
@given(
    u=st.floats(0.1, 3.0),
    x0=st.floats(1.0, 6.0),
    r=st.floats(0.1, 0.8),
    ahead=st.floats(0.1, 3.0),
    flip=st.booleans(),
    swap=st.booleans(),
)
def test_the_crush_time_is_the_closed_form_whichever_wall_and_axis(u, x0, r, ahead, flip, swap):
    # A paddle at x0 + r + ahead moving at -u towards a disc at rest against the wall x = 0 (mirrored by flip, x and
    # y swapped by swap): the gap between them reaches 2 r at (x0 + r + ahead - 2 r) / u.
    def place(x, y, point=True):
        x = (10.0 - x if point else -x) if flip else x
        return (y, x) if swap else (x, y)

    xp = x0 + r + ahead
    velocity = place(-u, 0.0, point=False)
    paddle = ds.Segment(place(xp, 3.0), place(xp, 7.0), velocity=velocity)
    sim = ds.EventDriven(ds.Discs([place(x0, 5.0)], [[0.0, 0.0]], radii=r), BOX, segments=[paddle])
    crush = (xp - 2.0 * r) / u
    with pytest.raises(JammedError) as caught:
        sim.run(until=crush + 1.0, events=3 * (sim.jam_events + sim.jam_events_per_disc))
    said = float(str(caught.value).split(" at time ")[1].split(":")[0])
    assert said == pytest.approx(crush, rel=1e-9) and sim.time < said


@pytest.mark.slow_on_python
def test_a_row_of_discs_squeezed_by_a_paddle_stops_once_a_disc_is_far_faster_than_the_run_allows():
    # Three discs in a row: each next to others, so no certain single-disc crush is proved; the backstop (a disc
    # squeeze_speedup times faster than the energy and the walls' speeds allow) stops the run short of t = 5.
    paddle = ds.Segment((8.0, 4.0), (8.0, 6.0), velocity=(-1.0, 0.0))
    discs = ds.Discs([[1.0, 5.0], [3.0, 5.0], [5.0, 5.0]], np.zeros((3, 2)), radii=0.5)
    sim = ds.EventDriven(discs, BOX, segments=[paddle])
    with pytest.raises(JammedError, match=r"disc \d moves at .*10000 times the speed scale of the run \(1:"):
        sim.run(until=20.0)
    assert 4.99 < sim.time < 5.0
    assert np.hypot(*sim.velocities.T).max() > 1e4
    sim._check()


def test_a_paddle_that_batters_a_ball_a_few_times_is_no_squeeze():
    # A pong rally: the paddle x = 8 - t sends a ball back towards the far wall at each meeting, then is steered
    # away; the ball gains 2 per hit, far below the backstop.
    paddle = ds.Segment((8.0, 0.5), (8.0, 9.5), velocity=(-0.2, 0.0))
    sim = ds.EventDriven(ds.Discs([[4.0, 5.0]], [[1.0, 0.0]], radii=0.5), BOX, segments=[paddle])
    sim.run(until=15.0)
    sim.set_segment_velocity(0, (0.0, 0.0))
    sim.run(until=30.0)
    assert sim.time == 30.0 and 1.0 < np.hypot(*sim.velocities[0]) < 10.0
