"""Adversarial checks of steered segments (issue 28, review 17): a segment steered during a run keeps its earlier
motions (``Segment.steered``, ``Segment.pieces``) through checkpoints, contacts and runs on. Every test runs on
both backends (the directory's conftest)."""

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
