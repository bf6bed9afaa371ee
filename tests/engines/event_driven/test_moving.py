"""Segments moving at a constant velocity in the event-driven engine (issue 28, item 1): closed forms, the bounce in
the segment's frame (Galilean invariance), restitution, checkpoints, queries and edits where the segment is now,
both backends bit for bit, bad input."""

import math
import re

import numpy as np
import pytest

import discsim as ds
from discsim.errors import InvalidArgumentError, InvalidDiscsError, OutsideBoxError

BOX = ds.Box(10.0, 10.0)


def ball(x, y, vx=0.0, vy=0.0, r=0.5):
    return ds.Discs([[x, y]], [[vx, vy]], radii=r)


@pytest.mark.parametrize("e", [1.0, 0.6])
def test_a_paddle_hits_a_disc_at_rest_at_the_exact_time_and_sends_it_off(e):
    # The paddle x = 8 - t meets the disc's edge at x = 2.5 at t = 5.5; in its frame the disc comes at +1 and
    # leaves at -e: in the box at -1 - e.
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0), velocity=(-1.0, 0.0))
    sim = ds.EventDriven(ball(2.0, 5.0), BOX, segments=[paddle], restitution=e)
    event = sim.step()
    assert (event.kind, event.i) == ("wall", 0)
    assert event.time == pytest.approx(5.5, rel=1e-14)
    assert sim.velocities[0] == pytest.approx([-1.0 - e, 0.0], rel=1e-14)
    # The energy the bounce took is counted in the paddle's frame: e = 1 takes none (the paddle did work).
    assert sim.dissipated == pytest.approx(0.5 * sim.discs.masses[0] * (1.0 - e * e), abs=1e-14)
    # Back off the left wall, it meets the paddle again where both are then.
    event = sim.step()
    assert event.time == pytest.approx(5.5 + 1.5 / (1.0 + e), rel=1e-13)
    event = sim.step()
    v = 1.0 + e
    t_wall = 5.5 + 1.5 / v
    t_meet = t_wall + (8.0 - t_wall - 1.0) / (e * v + 1.0)  # its edge 0.5 + e v dt + 0.5 (the wall: e) meets 8 - t
    assert event.time == pytest.approx(t_meet, rel=1e-13)


def test_a_disc_catches_up_with_a_receding_segment():
    # The segment x = 5 + 0.5 t recedes; the disc at 2 at speed 2: its edge 2.5 + 2 t meets it at t = 5 / 3.
    wall = ds.Segment((5.0, 0.0), (5.0, 10.0), velocity=(0.5, 0.0))
    sim = ds.EventDriven(ball(2.0, 5.0, 2.0), BOX, segments=[wall])
    event = sim.step()
    assert event.time == pytest.approx(2.5 / 1.5, rel=1e-14)
    assert sim.velocities[0] == pytest.approx([-1.0, 0.0], rel=1e-14)  # 2 u - v


def test_a_bounce_off_a_moving_end_point_is_the_fixed_one_seen_from_a_moving_frame():
    # In the segment's frame the segment is fixed and the disc moves at v - u: the same contact time, and the
    # velocity after differs by u (a glancing hit on the end point, far from the walls).
    u = np.array([-0.5, 0.1])
    p0, p1 = np.array([5.0, 2.0]), np.array([5.0, 5.0])
    x, v = np.array([3.5, 5.3]), np.array([1.0, 0.0])
    moving = ds.EventDriven(ball(*x, *v, r=0.4), BOX, segments=[ds.Segment(p0, p1, velocity=u)])
    fixed = ds.EventDriven(ball(*x, *(v - u), r=0.4), BOX, segments=[ds.Segment(p0, p1)])
    a, b = moving.step(), fixed.step()
    assert a.time == pytest.approx(b.time, rel=1e-12)
    assert moving.velocities[0] == pytest.approx(fixed.velocities[0] + u, rel=1e-12)
    assert moving.positions[0] == pytest.approx(fixed.positions[0] + u * a.time, rel=1e-12)
    assert not np.allclose(moving.velocities[0], v)  # it did bounce (off the end point: a slanted normal)


def test_a_gas_pushed_by_a_piston_wall_heats_up():
    # A segment across the box closing at speed 0.2: every bounce off it adds energy to the gas.
    gas, box = ds.random_gas(40, 0.2, seed=6, periodic=False)
    w, h = box.width, box.height
    low = gas.positions[:, 1] + gas.radii < 0.9 * h
    discs = ds.Discs(gas.positions[low], gas.velocities[low], radii=gas.radii[low])
    lid = ds.Segment((-1.0, 0.98 * h), (w + 1.0, 0.98 * h), velocity=(0.0, -0.02 * h))
    sim = ds.EventDriven(discs, box, segments=[lid])
    e0 = sim.energy()
    sim.run(until=10.0)
    assert sim.counts["wall_hits"] > 10
    assert sim.energy() > e0 * 1.01
    assert (sim.positions[:, 1] + discs.radii <= 0.98 * h - 0.2 * h + 1e-9).all()  # all below the lid now
    sim._check()


def test_moving_segments_survive_checkpoints_and_give_both_backends_the_same_events(every_backend, tmp_path):
    discs, box = ds.random_gas(30, 0.05, seed=2, periodic=False)
    x = 0.3 * box.width
    clear = np.abs(discs.positions[:, 0] - x) > discs.radii + 1e-6  # none cut by the paddle at the start
    discs = ds.Discs(discs.positions[clear], discs.velocities[clear], radii=discs.radii[clear])
    paddle = ds.Segment((x, 0.2), (x, 0.6 * box.height), velocity=(0.05, 0.0))
    whole = ds.EventDriven(discs, box, segments=[paddle]).run(until=6.0)
    assert whole.backend == every_backend
    half = ds.EventDriven(discs, box, segments=[paddle]).run(until=3.0)
    half.save(tmp_path / "half.npz")
    resumed = ds.load(tmp_path / "half.npz")
    assert resumed.segments[0].velocity.tolist() == [0.05, 0.0]
    resumed.run(until=6.0)
    assert resumed.events.tobytes() == whole.events.tobytes()
    if every_backend == "numba":
        python = ds.EventDriven(discs, box, segments=[paddle], backend="python").run(until=6.0)
        assert python.events.tobytes() == whole.events.tobytes()


def test_queries_and_added_discs_see_the_segment_where_it_is_now():
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0), velocity=(-1.0, 0.0))
    sim = ds.EventDriven(ball(1.0, 9.0), BOX, segments=[paddle]).run(until=4.0)  # the paddle is at x = 4 now
    hit = sim.ray_cast([0.5, 5.0], [1.0, 0.0])
    assert (hit.kind, hit.index) == ("segment", 0)
    assert hit.point == pytest.approx([4.0, 5.0])
    with pytest.raises(OutsideBoxError, match="segment 0"):
        sim.add_discs(ball(4.2, 5.0))
    assert len(sim.add_discs(ball(8.0, 5.0))) == 1  # where the paddle was at the start: free now


@pytest.mark.parametrize(
    "make, error, words",
    [
        (lambda: ds.Segment((0, 0), (1, 1), velocity=(float("nan"), 0.0)), InvalidDiscsError, "velocity"),
        (
            lambda: ds.EventDriven(ball(2, 2), BOX, segments=[ds.Segment((5, 0), (5, 9), (1, 0))], gravity=(0, -1)),
            InvalidArgumentError,
            "segments[0]",
        ),
        (
            lambda: ds.FixedStep(ball(2, 2), BOX, segments=[ds.Segment((5, 0), (5, 9), (1, 0))], policy="bisect"),
            InvalidArgumentError,
            "segments[0] Segment([5.0, 0.0], [5.0, 9.0], velocity=[1.0, 0.0]) moves: policy 'bisect'",
        ),
        (
            lambda: ds.EventDriven(ball(5.2, 2), BOX, segments=[ds.Segment((5, 0), (5, 9), (1, 0))]),
            OutsideBoxError,
            "segment",
        ),
    ],
)
def test_bad_moving_segments_are_refused_by_name(make, error, words):
    with pytest.raises(error, match=re.escape(words)):
        make()


def test_a_fixed_segment_is_unchanged():
    s = ds.Segment((0.0, 0.0), (1.0, 0.0))
    assert not s.moving and s.at(5.0) is s and repr(s) == "Segment([0.0, 0.0], [1.0, 0.0])"
    assert math.isclose(ds.Segment((0, 0), (0, 1), velocity=(2, 0)).at(1.5).p0[0], 3.0)


def test_a_paddle_steered_mid_run_stays_where_it_is_and_moves_on_at_its_new_velocity(tmp_path):
    # Fixed at x = 8 until t = 2, then sweeping left at 2: it meets the disc's edge (x = 2.5) at 2 + 5.5 / 2.
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0))
    sim = ds.EventDriven(ball(2.0, 5.0), BOX, segments=[paddle]).run(until=2.0)
    assert sim.backend in ("python", "numba")
    sim.set_segment_velocity(0, (-2.0, 0.0))
    assert sim.segments[0].at(2.0).p0 == pytest.approx([8.0, 3.0])
    event = sim.step()
    assert event.time == pytest.approx(2.0 + 5.5 / 2.0, rel=1e-14)
    assert sim.velocities[0] == pytest.approx([-4.0, 0.0], rel=1e-14)
    sim.set_segment_velocity(0, (0.0, 0.0))  # stopped where it is: x = 8 - 2 * (t - 2)
    sim.run(until=6.0)
    assert sim.segments[0].at(6.0).p0 == pytest.approx([8.0 - 2.0 * (4.75 - 2.0), 3.0])  # where it stopped
    sim.save(tmp_path / "steered.npz")
    assert ds.load(tmp_path / "steered.npz").segments[0].velocity.tolist() == [0.0, 0.0]


def test_steering_a_segment_is_refused_by_name_and_changes_nothing():
    sim = ds.EventDriven(ball(2.0, 5.0), BOX, segments=[ds.Segment((8.0, 3.0), (8.0, 7.0))], gravity=(0.0, -1.0))
    with pytest.raises(InvalidArgumentError, match="segments\\[0\\]"):
        sim.set_segment_velocity(0, (1.0, 0.0))
    assert not sim.segments[0].moving
    with pytest.raises(InvalidArgumentError, match="segment index 3"):
        sim.set_segment_velocity(3, (1.0, 0.0))
    with pytest.raises(InvalidArgumentError, match="velocity"):
        sim.set_segment_velocity(0, (float("inf"), 0.0))
    with pytest.raises(InvalidArgumentError, match="FixedStep cannot change a segment"):
        ds.FixedStep(ball(2.0, 5.0), BOX, segments=[ds.Segment((8.0, 3.0), (8.0, 7.0))]).set_segment_velocity(0, (1, 0))
