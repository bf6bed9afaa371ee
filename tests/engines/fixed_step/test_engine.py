"""FixedStep (PIT): exact small cases, invariants, validation, policies and broad phases."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds
from discsim.engines.fixed_step import broad_phase
from discsim.errors import BoxTooSmallError, OutsideBoxError, OverlapError, TimeError
from discsim.events import Event

POLICIES = ["resolve", "revert", "separate"]


def pair(dx=6.0, speed=1.0, offset=0.0, radius=1.0, masses=1.0):
    """Two discs on y = 5 approaching head-on (or with an offset in y) in a 10 x 10 box."""
    x0 = 5.0 - dx / 2.0
    discs = ds.Discs([[x0, 5.0], [x0 + dx, 5.0 + offset]], [[speed, 0.0], [-speed, 0.0]], radii=radius, masses=masses)
    return discs, ds.Box(10.0, 10.0)


def gas_with_obstacles(seed, n=60, packing=0.2, periodic=False, obstacles=6):
    discs, box = ds.random_gas(n, packing, periodic=periodic, seed=seed)
    masses = np.ones(n)
    velocities = np.array(discs.velocities)
    masses[:obstacles] = np.inf
    velocities[:obstacles] = 0.0
    return ds.Discs(discs.positions, velocities, discs.radii, masses), box


def assert_logs_equal(a, b):
    assert a.dtype == b.dtype and a.shape == b.shape
    for name in a.dtype.names:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


# --- exact small cases ---------------------------------------------------------------------------------


@pytest.mark.parametrize("policy", POLICIES)
def test_head_on_equal_masses_swaps_velocities_one_frame_late(policy):
    # Gap 4 closed at relative speed 2: contact at t = 2; frames every 0.3 -> detection at t = 2.1.
    discs, box = pair()
    sim = ds.FixedStep(discs, box, dt=0.3, policy=policy).run(until=2.4)
    assert sim.counts["detections"] == 1
    (event,) = sim.events
    assert event["time"] == pytest.approx(2.1)
    np.testing.assert_allclose(sim.velocities, [[-1.0, 0.0], [1.0, 0.0]], atol=1e-15)
    # Overlap at detection: distance 6 - 2 * 2.1 = 1.8 against contact 2.
    assert sim.max_overlap == pytest.approx(0.1)
    after = np.array([[event["xi"], event["yi"]], [event["xj"], event["yj"]]])
    expected = {
        "resolve": [[4.1, 5.0], [5.9, 5.0]],  # left where found
        "revert": [[3.8, 5.0], [6.2, 5.0]],  # put back to the frame at t = 1.8
        "separate": [[4.0, 5.0], [6.0, 5.0]],  # pushed apart to touch, equal shares
    }[policy]
    np.testing.assert_allclose(after, expected, atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(
    m1=st.floats(0.1, 10.0),
    m2=st.one_of(st.floats(0.1, 10.0), st.just(math.inf)),
    policy=st.sampled_from(POLICIES),
)
def test_head_on_unequal_masses_matches_the_closed_form(m1, m2, policy):
    case = ds.head_on(m1, m2)
    sim = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=policy).run(until=case.until)
    if math.isinf(m2):
        u1, u2 = -1.0, 0.0
    else:
        u1, u2 = (m1 - m2) / (m1 + m2), 2.0 * m1 / (m1 + m2)
    np.testing.assert_allclose(sim.velocities, [[u1, 0.0], [u2, 0.0]], atol=1e-12)
    assert sim.counts["detections"] == 1


@pytest.mark.parametrize("policy", POLICIES)
def test_wall_reflection_and_position_response(policy):
    # Disc of radius 1 at x = 8.5 moving right at 2 in a 10-wide box: crosses x = 9 at t = 0.25.
    discs = ds.Discs([[8.5, 5.0]], [[2.0, 1.0]], radii=1.0)
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.4, policy=policy)
    events = sim.step()
    assert events == [Event(0.4, "wall", 0, -1)]
    np.testing.assert_array_equal(sim.velocities, [[-2.0, 1.0]])
    expected = {"resolve": [9.3, 5.4], "revert": [8.5, 5.0], "separate": [9.0, 5.4]}[policy]
    np.testing.assert_allclose(sim.positions[0], expected, atol=1e-12)
    assert sim.counts["wall_hits"] == 1


@pytest.mark.parametrize("policy", POLICIES)
def test_separate_leaves_the_pair_touching_and_revert_at_the_previous_frame(policy):
    discs, box = pair(offset=0.8)
    sim = ds.FixedStep(discs, box, dt=0.25, policy=policy)
    previous = None
    while not sim.counts["detections"]:
        previous = sim.positions
        sim.step()
    now = sim.positions
    gap = float(np.hypot(*(now[1] - now[0])))
    if policy == "separate":
        assert gap == pytest.approx(2.0, abs=1e-12)
    elif policy == "revert":
        np.testing.assert_array_equal(now, previous)
    else:
        assert gap < 2.0
    # Elastic response: kinetic energy and momentum unchanged.
    assert sim.kinetic_energy() == pytest.approx(discs.kinetic_energy(), rel=1e-14)
    np.testing.assert_allclose(sim.momentum(), discs.momentum(), atol=1e-14)


def test_newtons_cradle_passes_the_momentum_one_frame_at_a_time():
    case = ds.newtons_cradle(5)
    sim = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    ev = sim.events
    # Each link k - (k + 1) is first found one frame after the previous one. (Roundoff in the
    # impulse can leave a 1e-16 velocity that makes a resting pair "collide" again later.)
    first = [float(ev["time"][(ev["i"] == k) & (ev["j"] == k + 1)].min()) for k in range(4)]
    np.testing.assert_allclose(first, [2.1, 2.2, 2.3, 2.4], atol=1e-12)
    np.testing.assert_allclose(sim.velocities, [[0, 0]] * 4 + [[1, 0]], atol=1e-12)


def test_a_small_fast_disc_tunnels_through_another():
    # The failure PIT is known for: 3 units per frame against a contact distance of 0.4.
    case = ds.scenarios.missed_collision()
    sim = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    assert sim.counts["detections"] == 0 and len(sim.events) == 0
    assert sim.counts["pair_tests"] == 0  # the grid never even put them in adjacent cells at a frame
    np.testing.assert_array_equal(sim.velocities, case.discs.velocities)


# --- invariants ------------------------------------------------------------------------------------------


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), packing=st.floats(0.1, 0.45), rate=st.sampled_from([5.0, 20.0, 60.0]))
def test_resolve_conserves_momentum_and_energy_in_a_periodic_gas(seed, packing, rate):
    discs, box = ds.random_gas(80, packing, periodic=True, seed=seed)
    sim = ds.FixedStep(discs, box, frame_rate=rate, policy="resolve").run(until=2.0)
    assert sim.counts["detections"] > 0
    np.testing.assert_allclose(sim.momentum(), discs.momentum(), atol=1e-11)
    assert sim.kinetic_energy() == pytest.approx(discs.kinetic_energy(), rel=1e-12)
    pos = sim.positions
    assert ((pos >= 0) & (pos < box.size)).all()  # wrapped


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 10_000), policy=st.sampled_from(POLICIES), periodic=st.booleans())
def test_infinite_mass_discs_never_move(seed, policy, periodic):
    discs, box = gas_with_obstacles(seed, periodic=periodic)
    sim = ds.FixedStep(discs, box, frame_rate=4.0, policy=policy)
    fixed = discs.positions[:6]
    for _ in range(25):
        sim.step()
        np.testing.assert_array_equal(sim.positions[:6], fixed)
        np.testing.assert_array_equal(sim.velocities[:6], 0.0)
    hit_obstacle = (sim.events["j"] >= 0) & (sim.events["i"] < 6)
    assert hit_obstacle.any()  # the obstacles were hit, and still did not move
    path = sim.trajectory(np.linspace(0.0, sim.time, 17))
    np.testing.assert_array_equal(path[:, :6], np.broadcast_to(fixed, (17, 6, 2)))


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 10_000), policy=st.sampled_from(POLICIES), periodic=st.booleans())
def test_all_pairs_and_grid_give_identical_runs(seed, policy, periodic):
    discs, box = ds.random_gas(70, 0.35, periodic=periodic, seed=seed)
    grid = ds.FixedStep(discs, box, frame_rate=8.0, policy=policy, broad_phase="grid").run(frames=20)
    brute = ds.FixedStep(discs, box, frame_rate=8.0, policy=policy, broad_phase="all-pairs").run(frames=20)
    assert grid.counts["detections"] > 0
    assert_logs_equal(grid.events, brute.events)
    np.testing.assert_array_equal(grid.positions, brute.positions)
    np.testing.assert_array_equal(grid.velocities, brute.velocities)
    assert grid.max_overlap == brute.max_overlap
    assert brute.counts["pair_tests"] == 20 * 70 * 69 // 2
    assert grid.counts["pair_tests"] < brute.counts["pair_tests"]


def test_all_pairs_in_blocks_gives_the_same_run(monkeypatch):
    discs, box = ds.random_gas(90, 0.4, seed=3)
    whole = ds.FixedStep(discs, box, frame_rate=6.0, broad_phase="all-pairs").run(frames=10)
    monkeypatch.setattr(broad_phase, "_ALL_PAIRS_BLOCK", 500)  # about 6 rows per block
    blocks = ds.FixedStep(discs, box, frame_rate=6.0, broad_phase="all-pairs").run(frames=10)
    assert_logs_equal(whole.events, blocks.events)
    assert whole.counts == blocks.counts


@pytest.mark.parametrize("policy", POLICIES)
@pytest.mark.parametrize("periodic", [False, True])
def test_trajectory_reproduces_every_frame_exactly(policy, periodic):
    discs, box = ds.random_gas(50, 0.3, periodic=periodic, seed=11)
    sim = ds.FixedStep(discs, box, frame_rate=5.0, policy=policy)
    frames = [sim.positions]
    logged = []
    for _ in range(15):
        logged.extend(sim.step())
        frames.append(sim.positions)
    path = sim.trajectory(sim.frame_times())
    np.testing.assert_allclose(path, np.array(frames), atol=1e-12, rtol=0)
    # step() returned exactly what the log holds, in order.
    ev = sim.events
    kinds = {0: "collision", 1: "wall"}
    assert logged == [Event(float(e["time"]), kinds[int(e["kind"])], int(e["i"]), int(e["j"])) for e in ev]
    assert sim.counts["detections"] + sim.counts["wall_hits"] == len(ev) > 0


def test_run_until_between_frames_drifts_and_keeps_the_frame_grid():
    discs, box = pair(dx=8.0, speed=0.5)
    sim = ds.FixedStep(discs, box, frame_rate=4.0).run(until=1.1)
    assert sim.frames == 4 and sim.time == 1.1
    np.testing.assert_allclose(sim.positions[:, 0], [1.0 + 0.55, 9.0 - 0.55])
    sim.step()
    assert sim.frames == 5 and sim.time == 1.25
    np.testing.assert_allclose(sim.positions[:, 0], [1.625, 8.375])
    sim.run(until=3.0)
    assert sim.frames == 12 and sim.time == 3.0
    assert sim.run(frames=3) is sim and sim.frames == 15 and sim.time == pytest.approx(3.75)


def test_record_false_keeps_no_log():
    discs, box = pair()
    sim = ds.FixedStep(discs, box, frame_rate=10.0, record=False).run(until=3.0)
    assert sim.counts["detections"] == 1 and len(sim.events) == 0
    with pytest.raises(ValueError, match="record=True"):
        sim.trajectory([1.0])


def test_dt_and_frame_rate_are_two_names_for_one_thing():
    discs, box = pair()
    a = ds.FixedStep(discs, box, frame_rate=8.0)
    b = ds.FixedStep(discs, box, dt=0.125)
    c = ds.FixedStep(discs, box, frame_rate=8.0, dt=0.125)
    assert a.dt == b.dt == c.dt == 0.125 and a.frame_rate == b.frame_rate == 8.0
    assert ds.FixedStep(discs, box).frame_rate == 30.0


def test_run_with_progress_bar(capsys):
    discs, box = pair()
    sim = ds.FixedStep(discs, box, frame_rate=10.0).run(until=3.0, progress=True)
    assert sim.frames == 30 and sim.counts["detections"] == 1


# --- validation: bad input raises and changes nothing ------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"frame_rate": 0.0}, "frame_rate must be a positive, finite number, got 0.0"),
        ({"frame_rate": -30}, "got -30"),
        ({"frame_rate": float("nan")}, "got nan"),
        ({"frame_rate": float("inf")}, "got inf"),
        ({"frame_rate": "fast"}, "got 'fast'"),
        ({"frame_rate": True}, "got True"),
        ({"dt": 0.0}, "dt must be a positive, finite number"),
        ({"dt": -0.1}, "got -0.1"),
        ({"frame_rate": 10.0, "dt": 0.2}, "not both"),
        ({"policy": "bounce"}, "policy must be one of"),
        ({"broad_phase": "octree"}, "broad_phase must be one of"),
    ],
)
def test_bad_parameters_raise_a_clear_value_error(kwargs, match):
    discs, box = pair()
    with pytest.raises(ValueError, match=match):
        ds.FixedStep(discs, box, **kwargs)


def test_bad_discs_raise_like_event_driven():
    overlapping = ds.Discs([[3.0, 5.0], [4.0, 5.0], [8.0, 5.0]], np.zeros((3, 2)), radii=1.0)
    with pytest.raises(OverlapError, match="discs 0 and 1 overlap"):
        ds.FixedStep(overlapping, ds.Box(10.0, 10.0))
    outside = ds.Discs([[3.0, 5.0], [9.5, 5.0]], np.zeros((2, 2)), radii=1.0)
    with pytest.raises(OutsideBoxError, match="disc 1"):
        ds.FixedStep(outside, ds.Box(10.0, 10.0))
    tiny = ds.Discs([[1.0, 1.0]], [[1.0, 0.0]], radii=1.0)
    with pytest.raises(BoxTooSmallError):
        ds.FixedStep(tiny, ds.Box(4.0, 4.0, periodic=True))
    with pytest.raises(TypeError, match=r"discsim\.Discs"):
        ds.FixedStep(np.zeros((2, 2)), ds.Box(10.0, 10.0))


def snapshot(sim):
    return (sim.time, sim.frames, dict(sim.counts), sim.positions, sim.velocities, sim.events, sim.max_overlap)


def assert_unchanged(before, after):
    assert before[:3] == after[:3] and before[6] == after[6]
    np.testing.assert_array_equal(before[3], after[3])
    np.testing.assert_array_equal(before[4], after[4])
    assert_logs_equal(before[5], after[5])


@pytest.mark.parametrize(
    ("kwargs", "error"),
    [
        ({"until": 1.0}, TimeError),
        ({"until": float("nan")}, TimeError),
        ({"until": "later"}, TimeError),
        ({"frames": -1}, ValueError),
        ({"frames": 2.5}, ValueError),
        ({"until": 10.0, "frames": -3}, ValueError),
        ({}, ValueError),
        ({"until": float("inf")}, ValueError),
    ],
)
def test_bad_run_arguments_raise_before_any_state_changes(kwargs, error):
    discs, box = pair()
    sim = ds.FixedStep(discs, box, frame_rate=10.0).run(until=2.5)
    before = snapshot(sim)
    with pytest.raises(error):
        sim.run(**kwargs)
    assert_unchanged(before, snapshot(sim))
    sim.run(until=3.0)  # still usable
    assert sim.frames == 30


def test_trajectory_outside_the_simulated_span_raises():
    discs, box = pair()
    sim = ds.FixedStep(discs, box, frame_rate=10.0).run(until=1.0)
    with pytest.raises(TimeError, match="outside the simulated span"):
        sim.trajectory([1.5])
