"""Segments moving at a constant velocity in the fixed-step engine (issue 28, item 1): tested where they are at the
frame's time, the bounce in the segment's frame (restitution, the energy taken in that frame), the refusals by
name."""

import re

import numpy as np
import pytest

import discsim as ds
from discsim.errors import InvalidArgumentError
from discsim.events import WALL

BOX = ds.Box(10.0, 10.0)
MOVING_POLICIES = ("resolve", "revert", "separate")


def ball(x, y, vx=0.0, vy=0.0, r=0.5):
    return ds.Discs([[x, y]], [[vx, vy]], radii=r)


@pytest.mark.parametrize("policy", MOVING_POLICIES)
@pytest.mark.parametrize("e", [1.0, 0.6])
def test_a_paddle_hits_a_disc_at_rest_and_sends_it_off_in_its_frame(policy, e):
    # The paddle x = 8 - t meets the disc's edge (x = 2.5) at t = 5.5: the first frame past it (dt = 0.25) is at
    # t = 5.75, where the paddle is at 2.25. In its frame the disc comes at +1 and leaves at -e: -1 - e in the box
    # (2u - v at e = 1, u = -1, v = 0).
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0), velocity=(-1.0, 0.0))
    sim = ds.FixedStep(ball(2.0, 5.0), BOX, dt=0.25, segments=[paddle], restitution=e, policy=policy)
    sim.run(until=5.5)
    assert sim.counts["wall_hits"] == 0 and sim.velocities.tolist() == [[0.0, 0.0]]
    events = sim.step()
    assert [(ev.kind, ev.i, ev.time) for ev in events] == [("wall", 0, 5.75)]
    assert sim.velocities.tolist() == [[-1.0 - e, 0.0]]
    # The energy the bounce took, in the paddle's frame: none at e = 1 (the paddle did work on the disc).
    assert sim.dissipated == pytest.approx(0.5 * sim.discs.masses[0] * (1.0 - e * e), abs=1e-14)
    x = sim.positions[0, 0]
    if policy == "separate":  # pushed out along the normal until it touches the paddle where it is at the frame
        assert x == pytest.approx(8.0 - 5.75 - 0.5, abs=1e-14)
    else:  # left where it was found ("revert": where it was at the previous frame, the same place)
        assert x == 2.0
    assert sim.counts["segment_tests"] == sim.counts["frames"]


@pytest.mark.parametrize("policy", MOVING_POLICIES)
def test_a_disc_is_tested_against_the_segment_where_it_is_at_the_frame(policy):
    # The segment y = 1 + 2 t (x in [3, 7]) rises under a disc at (5, 5) falling at 1: their gap closes at 3 per
    # unit of time, from 3.5: contact at t = 7/6. At dt = 0.25 the frame at 1.0 is clear (the centre 1 above the
    # segment), the frame at 1.25 cuts (0.25 above). A test against the segment's time-0 place would see nothing.
    lift = ds.Segment((3.0, 1.0), (7.0, 1.0), velocity=(0.0, 2.0))
    sim = ds.FixedStep(ball(5.0, 5.0, 0.0, -1.0), BOX, dt=0.25, segments=[lift], policy=policy).run(until=1.0)
    assert sim.counts["wall_hits"] == 0
    sim.run(until=1.25)
    assert sim.counts["wall_hits"] == 1
    assert sim.velocities.tolist() == [[0.0, 5.0]]  # -1 - 2 = -3 relative, reflected: +3, +2 back


def test_a_disc_moving_away_slower_than_the_paddle_comes_is_hit_in_the_paddles_frame():
    # The disc moves away from the paddle (-1) slower than it comes (-3): in the paddle's frame it approaches (+2),
    # so it bounces (to -3 - 2 = -5, e = 1); in the box's frame it moved away, which a fixed wall's test would
    # take for receding. The frame at 0.8 finds the disc 0.4 from the paddle.
    paddle = ds.Segment((6.0, 3.0), (6.0, 7.0), velocity=(-3.0, 0.0))
    sim = ds.FixedStep(ball(4.0, 5.0, -1.0, 0.0), BOX, dt=0.1, segments=[paddle], policy="resolve").run(until=1.0)
    assert sim.counts["wall_hits"] == 1
    assert sim.velocities.tolist() == [[-5.0, 0.0]]


@pytest.mark.parametrize("policy", MOVING_POLICIES)
def test_a_run_with_a_still_paddle_is_the_fixed_segments_run(policy):
    discs = ds.Discs([[2.0, 5.0], [5.0, 2.0]], [[3.0, 0.5], [0.4, 2.5]], radii=0.5)
    runs = [
        ds.FixedStep(discs, BOX, dt=0.1, policy=policy, segments=[segment], restitution=0.8).run(until=6.0)
        for segment in (ds.Segment((7.0, 2.0), (7.5, 8.0)), ds.Segment((7.0, 2.0), (7.5, 8.0), velocity=(0.0, 0.0)))
    ]
    assert runs[0].counts["wall_hits"] > 1
    assert runs[0].positions.tobytes() == runs[1].positions.tobytes()
    assert runs[0].velocities.tobytes() == runs[1].velocities.tobytes()
    assert runs[0].dissipated == runs[1].dissipated


@pytest.mark.parametrize(
    ("laws", "named"),
    [({"gravity": (0.0, -1.0)}, "gravity"), ({"drag": 0.5}, "drag"), ({"roughness": 0.5}, "roughness")],
)
def test_a_moving_segment_under_gravity_drag_or_roughness_is_refused_by_name(laws, named):
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0), velocity=(-1.0, 0.0))
    with pytest.raises(InvalidArgumentError, match=rf"segments\[1\] .*moves.*{named}"):
        ds.FixedStep(ball(2.0, 5.0), BOX, segments=[ds.Segment((1, 1), (2, 1)), paddle], **laws)


@pytest.mark.parametrize("policy", ["bisect", "swept"])
def test_a_moving_segment_with_a_policy_that_cannot_answer_it_is_refused_by_name(policy):
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0), velocity=(-1.0, 0.0))
    with pytest.raises(InvalidArgumentError, match=rf"segments\[0\] .*moves: policy {re.escape(repr(policy))}"):
        ds.FixedStep(ball(2.0, 5.0), BOX, segments=[paddle], policy=policy)
    # A fixed segment is fine with every policy.
    ds.FixedStep(ball(2.0, 5.0), BOX, segments=[ds.Segment((8.0, 3.0), (8.0, 7.0))], policy=policy)


def test_energy_and_momentum_bookkeeping_of_a_paddle_bounce_at_e_below_one():
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0), velocity=(-2.0, 1e-300 * 0.0))
    sim = ds.FixedStep(ball(2.0, 5.0, 1.0), BOX, dt=0.1, segments=[paddle], restitution=0.5).run(until=2.2)
    assert sim.counts["wall_hits"] == 1
    assert np.allclose(sim.velocities, [[-2.0 - 0.5 * 3.0, 0.0]], rtol=0, atol=1e-14)
    assert sim.dissipated == pytest.approx(0.5 * sim.discs.masses[0] * 9.0 * (1 - 0.25), rel=1e-14)


def test_the_paddle_tunnel_case_pic_bounces_at_the_closed_form_time_and_pit_tunnels_at_its_default_rate():
    case = ds.scenarios.paddle_tunnel()
    assert case.name in [c.name for c in ds.scenarios.law_cases()]
    (paddle,) = case.laws["segments"]
    (x_d, _), (v_d, _), r = case.discs.positions[0], case.discs.velocities[0], case.discs.radii[0]
    x_p, v_p = paddle.p0[0], paddle.velocity[0]
    t_c = (x_p - x_d - r) / (v_d - v_p)  # the docstring's closed form: 0.41
    assert t_c == pytest.approx(0.41, rel=1e-14)
    pic = ds.EventDriven(case.discs, case.box, **case.laws).run(until=case.until)
    assert pic.events["kind"].tolist() == [WALL]
    assert pic.events["time"][0] == pytest.approx(t_c, rel=1e-14)
    assert pic.events["vxi"][0] == pytest.approx(-(v_d - 2 * v_p), rel=1e-14)  # -(speed + 2 paddle_speed) = -40
    assert pic.positions[0, 0] < paddle.at(case.until).p0[0]  # back on its own side
    for policy in MOVING_POLICIES:  # the default rate: the frames straddle the crossing, the disc flies through
        pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=policy, **case.laws)
        pit.run(until=case.until)
        assert pit.counts["wall_hits"] == 0
        assert pit.positions[0, 0] == pytest.approx(x_d + v_d * case.until) and pit.positions[0, 0] > x_p + v_p * 0.6
        report = ds.compare(pic, pit)
        assert (report.truth_wall_hits, report.approx_wall_hits) == (1, 0)
    # Fast enough frames catch it, late by less than a frame, with the exact bounce.
    pit = ds.FixedStep(case.discs, case.box, frame_rate=150.0, policy="resolve", **case.laws).run(until=case.until)
    assert pit.counts["wall_hits"] == 1
    assert t_c < pit.events["time"][0] < t_c + 1.0 / 150.0
    assert pit.velocities.tolist() == [[-40.0, 0.0]]


def test_a_run_with_a_paddle_continues_from_a_checkpoint_bit_for_bit(tmp_path):
    # The checkpoint keeps the segment's ends at time 0 and its velocity: the copy finds it where the run would.
    discs = ds.Discs([[2.0, 5.0], [4.0, 2.0], [3.0, 8.0]], [[1.0, 0.3], [0.5, 1.0], [2.0, -0.5]], radii=0.5)
    options = {"dt": 0.1, "segments": [ds.Segment((8.0, 1.0), (8.5, 9.0), velocity=(-0.4, 0.0))], "restitution": 0.9}
    whole = ds.FixedStep(discs, BOX, **options).run(frames=100)
    half = ds.FixedStep(discs, BOX, **options).run(frames=50)
    copy = ds.load(half.save(tmp_path / "half.dsc"))
    assert copy.scene.segments[0].velocity.tolist() == [-0.4, 0.0]
    copy.run(frames=50)
    assert whole.counts["wall_hits"] > 3
    assert copy.events.tobytes() == whole.events.tobytes()
    assert copy.positions.tobytes() == whole.positions.tobytes() and copy.dissipated == whole.dissipated
