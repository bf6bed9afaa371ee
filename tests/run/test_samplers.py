"""Sampler: exact frames every dt during a run, without a log, equal to those rebuilt from the log."""

from __future__ import annotations

import numpy as np
import pytest

import discsim as ds
from discsim.run import samplers


@pytest.mark.parametrize("periodic", [True, False])
def test_frames_equal_those_from_the_log(monkeypatch, periodic):
    monkeypatch.setattr(samplers, "SAMPLE_CHUNK", 37)  # many chunks, samples inside and across them
    discs, box = ds.random_gas(200, 0.4, periodic=periodic, seed=2)
    recorded = ds.EventDriven(discs, box).run(until=6.0)
    sampler = ds.Sampler(0.3, free_times=True)
    quiet = ds.EventDriven(discs, box, record=False).run(until=6.0, observers=[sampler])
    f = sampler.frames
    assert np.allclose(f.times, np.arange(21) * 0.3)
    exact = ds.frames(recorded, f.times)
    assert np.allclose(f.unwrapped, exact.unwrapped, rtol=0, atol=1e-10)
    assert np.allclose(f.velocities, exact.velocities, rtol=0, atol=1e-12)
    assert np.allclose(f.unwrapped, recorded.trajectory(f.times, unwrapped=True), rtol=0, atol=1e-10)
    # the sampled run is the same run, bit for bit
    assert (quiet.velocities == recorded.velocities).all() and quiet.counts == recorded.counts
    assert len(quiet.events) == 0  # record=False stays so: the chunks were forgotten
    got, want = ds.free_times(sampler), ds.free_times(recorded)
    assert np.array_equal(np.sort(got.times), np.sort(want.times))


def test_several_runs_continue_the_grid_and_fn_sees_each_sample():
    seen = []
    sampler = ds.Sampler(0.25, keep=True, fn=lambda frames: seen.extend(frames.times.tolist()))
    sim = ds.EventDriven(*ds.random_gas(100, 0.3, seed=1), record=False)
    sim.run(until=0.6, observers=[sampler])
    sim.run(until=1.0, observers=[sampler])
    assert sampler.frames.times.tolist() == [0.0, 0.25, 0.5, 0.75, 1.0] == seen
    sim.step()
    with pytest.raises(ds.InvalidArgumentError, match="moved outside"):
        sim.run(until=2.0, observers=[sampler])
    other = ds.EventDriven(*ds.random_gas(100, 0.3, seed=1), record=False)
    with pytest.raises(ds.InvalidArgumentError, match="another engine"):
        other.run(until=1.0, observers=[sampler])


def test_keep_false_holds_no_frames():
    sampler = ds.Sampler(0.5, keep=False)
    ds.EventDriven(*ds.random_gas(50, 0.3, seed=1), record=False).run(until=2.0, observers=[sampler])
    assert sampler.frames is None and sampler.virial_blocks.end == 2.0


def test_analysis_of_sampled_frames_matches_the_log():
    discs, box = ds.random_gas(400, 0.5, seed=3)
    sim = ds.EventDriven(discs, box).run(until=8.0)
    sampler = ds.Sampler(0.5)
    ds.EventDriven(discs, box, record=False).run(until=8.0, observers=[sampler])
    exact = ds.frames(sim, sampler.frames.times)
    a = ds.rdf(sampler.frames.positions[4:], box, r_max=5.0, dr=0.05)
    b = ds.rdf(exact.positions[4:], box, r_max=5.0, dr=0.05)
    assert np.array_equal(a.counts, b.counts)
    assert np.allclose(
        ds.msd(sampler.frames.unwrapped, sampler.frames.times).msd, ds.msd(exact.unwrapped, exact.times).msd
    )


def test_bad_arguments():
    with pytest.raises(ds.InvalidArgumentError, match="dt"):
        ds.Sampler(0.0)
    with pytest.raises(ds.InvalidArgumentError, match="callable"):
        ds.Sampler(1.0, fn=3)


def test_frames_of_a_run_that_recorded_nothing_is_refused():
    sim = ds.EventDriven(*ds.random_gas(30, 0.3, seed=1), record=False).run(until=1.0)
    with pytest.raises(ds.InvalidArgumentError, match="ds.Sampler"):
        ds.frames(sim, [0.5])
    recorded = ds.EventDriven(*ds.random_gas(30, 0.3, seed=1)).run(until=1.0)
    with pytest.raises(ds.TimeError):
        ds.frames(recorded, [1.5])
