"""Adversarial checks of steered segments (issue 28, review 17): a segment steered during a run keeps its earlier
motions (``Segment.steered``, ``Segment.pieces``) through checkpoints, contacts and runs on. Every test runs on
both backends (the directory's conftest)."""

import json
import re

import numpy as np
import pytest

import discsim as ds

BOX = ds.Box(10.0, 10.0)


def steered_run():
    """A paddle fixed at x = 8 (y from 3 to 7) meets a ball from (4, 5) at 1 along x at t = 3.5; at t = 4 the
    paddle is steered at -1 along x."""
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0))
    sim = ds.EventDriven(ds.Discs([[4.0, 5.0]], [[1.0, 0.0]], radii=0.5), BOX, segments=[paddle], record=True)
    sim.run(until=4.0).set_segment_velocity(0, (-1.0, 0.0))
    return sim.run(until=5.0)


def test_a_checkpoint_of_a_steered_run_keeps_where_the_segment_was(tmp_path):
    # The checkpoint kept only the motion the paddle has now: loaded, it was drawn at x = 8.5 at t = 3.5 (its new
    # motion extrapolated back), and the contact at 3.5 read a speed of approach of 2 (the ball at 1 against a
    # paddle at -1) where the paddle stood still.
    sim = steered_run()
    sim.save(tmp_path / "steered.npz")
    back = ds.load(tmp_path / "steered.npz")
    paddle = back.segments[0]
    assert paddle.at(3.5).p0.tolist() == [8.0, 3.0] and paddle.at(4.5).p0.tolist() == [7.5, 3.0]
    assert [(until, piece.velocity.tolist()) for until, piece in paddle.pieces()] == [(4.0, [0.0, 0.0])]
    hit = [c for c in ds.contacts(back) if c.kind == "segment"]
    assert [(c.time, c.speed) for c in hit] == [(c.time, c.speed) for c in ds.contacts(sim) if c.kind == "segment"]
    assert hit[0].time == 3.5 and hit[0].speed == pytest.approx(1.0, rel=1e-12)
    # ... and it runs on as the run it came from, bit for bit.
    back.run(until=8.0)
    sim.run(until=8.0)
    assert np.array_equal(back.positions, sim.positions) and np.array_equal(back.velocities, sim.velocities)
    assert back.segments[0].at(8.0).p0.tolist() == sim.segments[0].at(8.0).p0.tolist()
    back._check()


def test_the_viewer_draws_a_steered_segment_of_a_checkpoint_where_it_was(tmp_path):
    # ds.view of the file loads it: it was refused (the load's 'lies entirely outside the box').
    steered_run().save(tmp_path / "steered.npz")
    page = ds.view(tmp_path / "steered.npz", path=None)
    found = re.search(r'<script type="application/json" id="ds-data">(.*?)</script>', page.html, re.S)
    data = json.loads(found.group(1).replace("<\\/", "</"))
    assert json.dumps(data).count("[[[4.0, 8.0, 3.0, 8.0, 7.0, 0.0, 0.0]]]") == 1  # its segment_past


def test_a_new_run_refuses_a_steered_segment_it_would_move_elsewhere():
    # The paddle fixed at x = 8 until t = 4 (then at -1): a new run moved it on its last motion from t = 0 (at x = 12
    # then), so a ball from x = 5 met it at t = 3.25 at x = 8.75, where at(), the plots and contacts say there was no
    # paddle (and the scene check looked at one place while the run used the other).
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0)).steered(4.0, (-1.0, 0.0))
    ball = ds.Discs([[5.0, 5.0]], [[1.0, 0.0]], radii=0.5)
    for make in (
        lambda: ds.EventDriven(ball, ds.Box(14.0, 10.0), segments=[ds.Segment((1, 1), (1, 2)), paddle]),
        lambda: ds.FixedStep(ball, ds.Box(14.0, 10.0), segments=[ds.Segment((1, 1), (1, 2)), paddle], dt=0.01),
    ):
        with pytest.raises(ds.DiscsimError, match=r"segments\[1\] .* was steered at time 4\.0"):
            make()
    # As it moves from the start, it runs.
    sim = ds.EventDriven(ball, ds.Box(14.0, 10.0), segments=[ds.Segment(paddle.p0, paddle.p1, paddle.velocity)])
    assert sim.step().time == 3.25


@pytest.mark.parametrize(("time", "why"), [(float("nan"), "nan"), (float("inf"), "inf"), (1.0, "1.0"), ("2", "'2'")])
def test_steering_at_a_time_that_is_not_finite_or_before_the_last_steer_is_refused_by_name(time, why):
    # NaN and inf gave "segment p0 must be 2 finite numbers, got [nan, nan]" (and a RuntimeWarning); a time before
    # the last steer gave pieces() out of order.
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0)).steered(2.0, (1.0, 0.0))
    with pytest.raises(ds.DiscsimError, match=rf"steer time must be a finite number, not before .*2\.0.*got {why}"):
        paddle.steered(time, (0.0, 1.0))
    assert [until for until, _ in paddle.steered(2.0, (0.0, 1.0)).pieces()] == [2.0, 2.0]  # twice in one instant
