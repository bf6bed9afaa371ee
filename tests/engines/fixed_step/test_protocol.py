"""FixedStep on the engine protocol: the driver, checkpoints and exact resume, streamed logs, unwrapped positions."""

from __future__ import annotations

import numpy as np
import pytest

import discsim as ds
from discsim.engines.fixed_step import BROAD_PHASES, POLICIES
from discsim.engines.fixed_step.state import FixedStepState
from discsim.errors import InvalidArgumentError


def walled_scene():
    """60 discs in a walled box with two segments, two groups passing through each other, two obstacles."""
    discs, box = ds.random_gas(60, 0.3, periodic=False, seed=21)
    segments = [ds.Segment((0.2 * box.width, 0.5 * box.height), (0.45 * box.width, 0.55 * box.height))]
    keep = segments[0].distance(discs.positions) > discs.radii * 1.01
    masses = np.where(np.arange(len(discs)) < 2, np.inf, 1.0)[keep]
    velocities = np.where(np.isinf(masses)[:, None], 0.0, discs.velocities[keep])
    discs = ds.Discs(discs.positions[keep], velocities, discs.radii[keep], masses, groups=np.arange(keep.sum()) % 3)
    return discs, box, {"segments": segments, "pass_through": {(1, 2)}}


def periodic_scene():
    discs, box = ds.random_gas(60, 0.35, periodic=True, seed=22)
    return discs, box, {}


SCENES = {"walled": walled_scene, "periodic": periodic_scene}


def build(scene, policy, broad_phase="grid", **kwargs):
    discs, box, options = SCENES[scene]()
    return ds.FixedStep(discs, box, dt=0.05, policy=policy, broad_phase=broad_phase, **options, **kwargs)


def assert_same(a, b):
    """Two engines in the same state, bit for bit: time, frames, counters, overlap, log, positions, velocities."""
    assert a.time == b.time and a.frames == b.frames
    assert a.counts == b.counts and a.max_overlap == b.max_overlap
    assert a.positions.tobytes() == b.positions.tobytes()
    assert a.velocities.tobytes() == b.velocities.tobytes()
    assert a.unwrapped_positions.tobytes() == b.unwrapped_positions.tobytes()
    assert a.events.tobytes() == b.events.tobytes()


# --- the driver's protocol ------------------------------------------------------------------------------------


@pytest.mark.parametrize("policy", POLICIES)
@pytest.mark.parametrize("scene", SCENES)
def test_a_run_cut_in_two_gives_the_same_run(scene, policy):
    whole = build(scene, policy).run(until=3.0)
    halves = build(scene, policy).run(until=1.5).run(until=3.0)
    assert whole.counts["detections"] > 0
    assert_same(whole, halves)
    # The same in chunks served to an observer, and between frames (time 1.01 is not a frame time).
    seen = []
    chunked = build(scene, policy).run(until=1.01, observers=[ds.Callback(lambda s, e: seen.append(len(e)), every=7)])
    chunked.run(until=3.0)
    assert_same(whole, chunked)
    assert sum(seen) == len(build(scene, policy).run(until=1.01).events) and len(seen) == 3  # 20 frames: 7 + 7 + 6


@pytest.mark.parametrize("policy", POLICIES)
def test_the_event_count_is_the_length_of_the_log(policy):
    sim = build("walled", policy)
    for until in (0.5, 1.0, 2.5):
        sim.run(until=until)
        assert sim._event_count() == len(sim.events) == sim.counts["detections"] + sim.counts["wall_hits"]
    assert sim._units() == sim.frames == 50
    assert (sim.events["j"] == -1).sum() == sim.counts["wall_hits"] > 0


def test_frames_and_events_are_two_names_for_the_count():
    a = build("periodic", "resolve").run(frames=12)
    b = build("periodic", "resolve").run(events=12)
    c = build("periodic", "resolve").run(frames=12, events=12.0)
    assert_same(a, b)
    assert_same(a, c)
    with pytest.raises(InvalidArgumentError, match="not both: frames=12 but events=13"):
        a.run(frames=12, events=13)
    with pytest.raises(InvalidArgumentError, match="frames must be a non-negative integer"):
        a.run(frames=-1, events=3)
    with pytest.raises(InvalidArgumentError, match="run\\(\\) needs until=... or frames=..."):
        a.run()
    with pytest.raises(ds.TimeError, match="never ends"):
        a.run(until=np.inf)
    assert a.frames == 12
    assert a.run(until=np.inf, frames=3).frames == 15  # a count bounds it


def test_a_run_stopped_by_the_frame_count_stays_at_the_last_frame():
    sim = build("walled", "resolve").run(until=1.02, frames=10)
    assert sim.frames == 10 and sim.time == sim.frame_time(10)
    sim.run(until=1.02)
    assert sim.frames == 20 and sim.time == 1.02


def test_observers_see_each_frame_and_record_false_keeps_no_log():
    reference = build("walled", "swept").run(frames=30)
    got = []
    sim = build("walled", "swept", record=False).run(frames=30, observers=[lambda s, events: got.append(events)])
    assert len(got) == 1 and got[0].tobytes() == reference.events.tobytes()  # one chunk: 1,000 frames at most
    assert len(sim.events) == 0 and sim.record is False
    per_frame = []
    build("walled", "swept").run(frames=30, observers=[ds.Callback(lambda s, e: per_frame.append(s.frames), every=1)])
    assert per_frame == list(range(1, 31))


# --- the checkpoint's protocol --------------------------------------------------------------------------------


def test_the_state_is_arrays_and_scalars_and_a_copy():
    sim = build("periodic", "resolve").run(frames=20)
    state = sim.state()
    assert isinstance(state, FixedStepState) and state.counts == sim.counts
    scalars, arrays = state.to_arrays()
    assert all(isinstance(v, (int, float)) for v in scalars.values())
    assert arrays["images"].dtype == np.int64 and arrays["images"].shape == (60, 2)
    assert arrays["list_positions"].shape == (60, 2) and len(arrays["list_i"]) > 0
    again = FixedStepState.from_arrays(scalars, arrays, FixedStepState.VERSION)
    assert again.to_arrays()[0] == scalars
    state.velocities[:] = 0.0
    assert np.abs(sim.velocities).sum() > 0
    fresh = build("periodic", "bisect").state()
    assert fresh.list_positions.shape == (0, 2) and fresh.frames == 0 and fresh.time == 0.0


@pytest.mark.parametrize("broad_phase", BROAD_PHASES)
@pytest.mark.parametrize("policy", POLICIES)
@pytest.mark.parametrize("scene", SCENES)
def test_save_and_load_continue_bit_for_bit(tmp_path, scene, policy, broad_phase):
    reference = build(scene, policy, broad_phase).run(until=2.0)
    sim = build(scene, policy, broad_phase).run(until=0.83)  # between two frames
    path = sim.save(tmp_path / "sim.dsc")
    loaded = ds.load(path)
    assert_same(sim, loaded)
    assert loaded.policy == policy and loaded.broad_phase == broad_phase and loaded.dt == sim.dt
    for engine in (sim, loaded):
        engine.run(until=2.0)
    assert reference.counts["detections"] > 0
    assert_same(reference, loaded)
    assert_same(sim, loaded)


def test_the_verlet_list_is_saved_with_the_state(tmp_path):
    # A slow gas: the list outlives many frames, so a list lost on loading would be rebuilt early.
    discs, box = ds.random_gas(80, 0.4, periodic=True, seed=25, temperature=0.05)
    sim = ds.FixedStep(discs, box, dt=0.05).run(frames=9)
    loaded = ds.load(sim.save(tmp_path / "sim.dsc"))
    builds = sim.counts["list_builds"]
    for _ in range(12):
        sim.step()
        loaded.step()
        assert loaded.counts == sim.counts
    assert sim.counts["list_builds"] - builds in (1, 2)  # rebuilt at the same frames, not at every one
    assert_same(sim, loaded)


@pytest.mark.parametrize("kwargs", [{"frame_rate": 30.0}, {"dt": 0.1}, {"frame_rate": 7.0, "dt": 1 / 7.0}])
def test_frame_times_come_out_the_same_after_a_load(tmp_path, kwargs):
    discs, box, _ = periodic_scene()
    reference = ds.FixedStep(discs, box, **kwargs).run(frames=150)
    sim = ds.FixedStep(discs, box, **kwargs).run(frames=61)
    loaded = ds.load(sim.save(tmp_path / "sim.dsc")).run(frames=89)
    assert loaded.frame_times().tobytes() == reference.frame_times().tobytes()
    assert_same(reference, loaded)


@pytest.mark.parametrize("policy", POLICIES)
@pytest.mark.parametrize("streamed", [False, True])
def test_an_interrupted_run_resumes_to_the_same_end(tmp_path, policy, streamed):
    scene = "walled" if policy in ("revert", "bisect") else "periodic"
    goal = {"until": 3.0}
    reference = build(scene, policy, record=not streamed)
    reference.stream_chunk = 50
    reference.run(**goal, record_to=tmp_path / "ref.dse" if streamed else None)

    class Crash(Exception):
        pass

    def crash(sim, events):
        if sim.frames >= 37:
            raise Crash

    sim = build(scene, policy, record=not streamed)
    sim.stream_chunk = 50
    state, log = tmp_path / "state.dsc", tmp_path / "events.dse"
    with pytest.raises(Crash):
        sim.run(
            **goal,
            observers=[ds.Callback(crash, every=1)],
            checkpoint=state,
            checkpoint_every=15,
            record_to=log if streamed else None,
        )
    info = ds.checkpoint_info(state)
    assert info["engine"] == "FixedStep" and not info["run"]["finished"]
    assert info["counts"]["frames"] == 30 and info["run"]["until"] == 3.0

    resumed = ds.resume(state)
    assert ds.checkpoint_info(state)["run"]["finished"]
    assert resumed.time == reference.time and resumed.frames == reference.frames == 60
    assert resumed.counts == reference.counts and resumed.max_overlap == reference.max_overlap
    assert resumed.positions.tobytes() == reference.positions.tobytes()
    assert resumed.velocities.tobytes() == reference.velocities.tobytes()
    if streamed:
        assert ds.read_events(log).events.tobytes() == ds.read_events(tmp_path / "ref.dse").events.tobytes()
    else:
        assert resumed.events.tobytes() == reference.events.tobytes()


def test_resume_continues_a_frame_count(tmp_path):
    reference = build("walled", "separate").run(frames=47)
    sim = build("walled", "separate")
    state = tmp_path / "state.dsc"

    def stop(sim, events):
        if sim.frames == 20:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sim.run(frames=47, checkpoint=state, checkpoint_every=10, observers=[ds.Callback(stop, every=5)])
    assert ds.checkpoint_info(state)["run"]["events"] == 47
    assert_same(reference, ds.resume(state))


# --- streamed logs --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("policy", POLICIES)
@pytest.mark.parametrize("record", [False, True])
def test_a_streamed_log_equals_the_log_in_memory(tmp_path, policy, record):
    in_memory = build("walled", policy).run(until=2.0)
    sim = build("walled", policy, record=record)
    sim.stream_chunk = 40
    path = tmp_path / "events.dse"
    sim.run(until=1.0, record_to=path).run(until=2.0, record_to=path)
    log = ds.read_events(path)
    assert len(in_memory.events) > 40
    assert log.events.tobytes() == in_memory.events.tobytes()
    assert log.end_time == 2.0 and log.start_time == 0.0
    assert sim.positions.tobytes() == in_memory.positions.tobytes()
    with pytest.raises(InvalidArgumentError, match="streamed"):
        _ = sim.events
    np.testing.assert_allclose(ds.trajectory_from_events(path, [2.0])[0], sim.positions, atol=1e-12)


# --- unwrapped positions --------------------------------------------------------------------------------------


@pytest.mark.parametrize("policy", POLICIES)
def test_unwrapped_positions_follow_the_discs_across_the_edges(policy):
    discs, box = ds.random_gas(40, 0.3, periodic=True, seed=23, temperature=4.0)
    sim = ds.FixedStep(discs, box, dt=0.05, policy=policy).run(until=12.34)  # between frames
    unwrapped = sim.unwrapped_positions
    size = box.size
    crossed = (np.floor(unwrapped / size) != 0).any(axis=1)
    assert crossed.sum() >= 10 and sim.state().images.any()  # discs left the box, and collided after
    assert sim.counts["detections"] > 50
    from_log = sim.trajectory([sim.time], unwrapped=True)[0]
    np.testing.assert_allclose(from_log, unwrapped, rtol=1e-9, atol=1e-9 * size.max())
    wrapped = box.wrap(unwrapped)
    assert ((wrapped >= 0) & (wrapped < size)).all()
    np.testing.assert_allclose(box.displacement(sim.positions, wrapped), 0.0, atol=1e-9 * size.max())
    if policy in ("resolve", "bisect", "swept"):  # positions stay continuous: the centre of mass drifts uniformly
        drift = (unwrapped - discs.positions).mean(axis=0)
        np.testing.assert_allclose(drift, discs.momentum() / len(discs) * sim.time, atol=1e-9)
    # At a frame too.
    sim.step()
    np.testing.assert_allclose(
        sim.trajectory([sim.time], unwrapped=True)[0], sim.unwrapped_positions, rtol=1e-9, atol=1e-9 * size.max()
    )


def test_unwrapped_positions_of_free_discs_are_exact():
    discs = ds.Discs([[0.5, 0.5], [2.5, 3.0]], [[3.0, -1.25], [-0.5, 0.0]], 0.25)
    sim = ds.FixedStep(discs, ds.Box(4.0, 4.0, periodic=True), dt=0.25).run(until=10.0)
    assert sim.counts["detections"] == 0
    np.testing.assert_allclose(sim.unwrapped_positions, [[30.5, -12.0], [-2.5, 3.0]], rtol=0, atol=1e-12)
    np.testing.assert_allclose(sim.positions, [[2.5, 0.0], [1.5, 3.0]], rtol=0, atol=1e-12)


def test_unwrapped_positions_survive_a_load(tmp_path):
    discs, box = ds.random_gas(40, 0.3, periodic=True, seed=24, temperature=4.0)
    reference = ds.FixedStep(discs, box, dt=0.05, policy="swept").run(until=8.0)
    sim = ds.FixedStep(discs, box, dt=0.05, policy="swept").run(until=4.0)
    loaded = ds.load(sim.save(tmp_path / "sim.dsc")).run(until=8.0)
    assert np.abs(loaded.state().images).max() >= 1
    assert loaded.unwrapped_positions.tobytes() == reference.unwrapped_positions.tobytes()


@pytest.mark.parametrize("policy", POLICIES)
def test_in_a_walled_box_unwrapped_positions_are_the_positions(policy):
    discs, box, options = walled_scene()
    sim = ds.FixedStep(discs, box, dt=0.05, policy=policy, **options).run(until=2.01)
    assert sim.unwrapped_positions.tobytes() == sim.positions.tobytes()
    assert not sim.state().images.any()
    np.testing.assert_allclose(sim.trajectory([sim.time], unwrapped=True)[0], sim.positions, atol=1e-12)
