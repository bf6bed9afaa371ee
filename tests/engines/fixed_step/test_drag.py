"""Linear drag in the fixed-step engine (PIT): the exact exponential flight at and between the frames, the drag's
loss in ``dissipated``, the trajectory, PIT against PIC under drag, checkpoints, bad input (issue 27, items 4, 5).

Every test runs once per backend (``every_backend``, autouse in this folder's conftest); the two backends give the
same frames bit for bit under drag too (``test_backends.py``).
"""

import math

import numpy as np
import pytest

import discsim as ds
from discsim import _numba
from discsim.errors import CheckpointError, InvalidArgumentError

if _numba.available():
    # Compiled now, while numba is visible (see test_laws.py): the python cases run EventDriven under the laws.
    import discsim.engines.fixed_step.numba.policy

G = 9.81
FRAME_POLICIES = ("resolve", "revert", "separate")


def ball(x, y, vx=0.0, vy=0.0, r=0.5):
    return ds.Discs([[x, y]], [[vx, vy]], radii=r)


def tau(t, gamma):
    return -math.expm1(-gamma * t) / gamma


# --- closed forms at the frames -------------------------------------------------------------------------------
@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_a_sliding_disc_stops_after_v_over_gamma_short_of_the_wall(policy):
    # From x = 1 at 2 under gamma = 0.5: it stops at 1 + 2 / 0.5 = 5, far short of the wall (its centre stops at 9.5).
    gamma, dt = 0.5, 0.1
    sim = ds.FixedStep(ball(1.0, 5.0, 2.0), ds.Box(10.0, 10.0), dt=dt, drag=gamma, policy=policy)
    for k in range(1, 41):
        assert sim.step() == []
        t = k * dt
        assert sim.positions[0] == pytest.approx([1.0 + 2.0 * tau(t, gamma), 5.0], rel=1e-14)
        assert sim.velocities[0] == pytest.approx([2.0 * math.exp(-gamma * t), 0.0], rel=1e-13)
    t = 4.0 + 0.37 * dt  # between frames too: the clock moved past the last frame, the frame grid stays
    sim.run(until=t)
    assert sim.frames == 40
    assert sim.positions[0] == pytest.approx([1.0 + 2.0 * tau(t, gamma), 5.0], rel=1e-14)
    assert sim.velocities[0] == pytest.approx([2.0 * math.exp(-gamma * t), 0.0], rel=1e-13)
    sim.run(until=80.0)
    assert sim.events.size == 0
    assert sim.positions[0] == pytest.approx([5.0, 5.0], rel=1e-14)
    assert sim.velocities[0, 0] == pytest.approx(2.0 * math.exp(-40.0), rel=1e-9)


@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_a_falling_ball_reaches_its_terminal_velocity(policy):
    gamma, dt, vx0 = 4.0, 1.0 / 30.0, 2.0
    box = ds.Box(10.0, 1001.0)
    sim = ds.FixedStep(ball(5.0, 1000.0, vx0), box, dt=dt, gravity=(0.0, -G), drag=gamma, policy=policy)
    for k in range(1, 31):
        sim.step()
        t = k * dt
        v = -G / gamma * (1.0 - math.exp(-gamma * t))  # g tau(t)
        assert sim.velocities[0] == pytest.approx([vx0 * math.exp(-gamma * t), v], rel=1e-13)
        assert 1000.0 - sim.positions[0, 1] == pytest.approx(G / gamma * (t - tau(t, gamma)), rel=1e-12)
    sim.run(until=10.0)
    assert sim.velocities[0] == pytest.approx([vx0 * math.exp(-40.0), -G / gamma], rel=1e-12)
    assert sim.positions[0] == pytest.approx([5.0 + vx0 * tau(10.0, gamma), 1000.0 - G / gamma * (10.0 - 0.25)])


@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_a_wall_hit_comes_within_one_frame_of_the_exact_time(policy):
    # From x = 2 at 8 under gamma = 0.5 the centre reaches 9 (the wall at 9.5) when tau = 7 / 8: exactly at
    # t = -log1p(-gamma 7 / 8) / gamma; PIT answers at the first frame past it, where the exact flight put the disc.
    gamma, dt = 0.5, 1.0 / 30.0
    exact = -math.log1p(-gamma * 7.0 / 8.0) / gamma
    sim = ds.FixedStep(ball(2.0, 5.0, 8.0), ds.Box(9.5, 10.0), dt=dt, drag=gamma, policy=policy)
    sim.run(until=2.0)
    hit = sim.events[0]
    assert hit["j"] == -1 and 0.0 <= hit["time"] - exact < dt
    assert hit["vxi"] == pytest.approx(-8.0 * math.exp(-gamma * hit["time"]), rel=1e-13)
    pic = ds.EventDriven(ball(2.0, 5.0, 8.0), ds.Box(9.5, 10.0), drag=gamma).run(until=2.0)
    assert pic.events["time"][0] == pytest.approx(exact, rel=1e-14)


# --- the frames follow the event-driven engine's flights ----------------------------------------------------------
@pytest.mark.parametrize("gravity", [None, (0.4, -G)])
@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_the_frames_are_where_event_driven_puts_the_discs_between_events(policy, gravity):
    discs = ds.Discs(
        [[2.0, 30.0], [6.0, 26.0], [10.0, 22.0], [14.0, 34.0]],
        [[3.0, 1.0], [-2.0, 2.5], [0.5, -4.0], [-1.0, 0.0]],
        radii=[0.5, 0.7, 0.4, 0.6],
        masses=[1.0, 2.0, 0.5, 1.5],
    )
    box, dt = ds.Box(16.0, 40.0), 0.02
    pic = ds.EventDriven(discs, box, gravity=gravity, drag=0.8, restitution=0.7).run(until=6.0)
    first = float(pic.events["time"][0]) if len(pic.events) else 6.0
    assert first > 0.5
    pit = ds.FixedStep(discs, box, dt=dt, gravity=gravity, drag=0.8, restitution=0.7, policy=policy)
    at_frames = []
    while pit.time + dt < first:
        assert pit.step() == []
        at_frames.append(pit.positions)
    assert len(at_frames) > 20
    np.testing.assert_allclose(np.array(at_frames), pic.trajectory(pit.frame_times()[1:]), rtol=1e-14, atol=1e-13)


@pytest.mark.parametrize("policy", FRAME_POLICIES)
@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize("gravity", [None, (0.7, -G)])
def test_the_trajectory_under_drag_follows_the_frames_between_responses(policy, periodic, gravity):
    discs = ds.Discs([[3.0, 4.0], [6.0, 2.5], [4.5, 1.2]], [[6.0, 3.0], [-3.0, 9.0], [1.5, 0.0]], radii=0.5)
    box = ds.Box(9.0, 9.0, periodic=periodic)
    if periodic and gravity is not None:
        gravity = (0.7, 0.0)  # sideways: nothing to land on in a periodic box
    sim = ds.FixedStep(discs, box, dt=0.05, gravity=gravity, drag=0.6, restitution=0.8, policy=policy)
    seen = [sim.positions]
    for _ in range(60):
        sim.step()
        seen.append(sim.positions)
    assert len(sim.events) > (0 if periodic else 3)
    rebuilt = sim.trajectory(sim.frame_times())
    np.testing.assert_allclose(rebuilt, np.array(seen), rtol=0.0, atol=1e-12)
    t = sim.time + 0.013
    sim.run(until=t)
    np.testing.assert_allclose(sim.trajectory([t])[0], sim.positions, rtol=0.0, atol=1e-12)


# --- energy: what the drag takes ---------------------------------------------------------------------------------
@pytest.mark.parametrize("gravity", [None, (0.3, -G)])
def test_energy_plus_dissipated_is_constant_under_drag_with_resolve(gravity):
    """``"resolve"`` neither moves a disc nor changes energy beyond its collision law: what it and the drag take is
    all of the loss, at the frames, between them and across an edit."""
    discs, box = ds.random_gas(30, 0.3, periodic=False, seed=5)
    sim = ds.FixedStep(discs, box, dt=0.02, gravity=gravity, drag=0.5, restitution=0.9)
    e0 = sim.energy()
    sim.run(frames=150)
    assert sim.counts["detections"] > 10 and sim.counts["wall_hits"] > 10
    assert sim.dissipated > 0.2 * e0
    assert sim.energy() + sim.dissipated == pytest.approx(e0, rel=1e-12)
    sim.run(until=sim.time + 0.007)  # between frames: the flights under way count too
    assert sim.time != sim.frame_times()[-1]
    assert sim.energy() + sim.dissipated == pytest.approx(e0, rel=1e-12)
    lost = sim.dissipated
    sim.set_velocities([0, 1], np.zeros((2, 2)))  # an edit between frames ends two flights: their loss stays counted
    assert sim.dissipated == pytest.approx(lost, rel=1e-14)
    e1 = sim.energy() + sim.dissipated
    sim.run(frames=20)
    assert sim.energy() + sim.dissipated == pytest.approx(e1, rel=1e-12)


# --- PIT against PIC under drag -------------------------------------------------------------------------------
@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_the_terminal_fall_case_compares_pit_with_pic_under_drag(policy):
    case = ds.scenarios.terminal_fall()
    assert [c.name for c in ds.scenarios.law_cases()][:2] == ["bouncing_ball", "terminal_fall"]
    g, gamma = -case.laws["gravity"][1], case.laws["drag"]
    h0 = float(case.discs.positions[0, 1] - case.discs.radii[0])
    pic = ds.EventDriven(case.discs, case.box, **case.laws).run(until=case.until)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=policy, **case.laws)
    pit.run(until=case.until)
    # PIC: the floor at the time the drop at (almost) terminal velocity reaches h0.
    hit = float(pic.events["time"][0])
    assert g / gamma * (hit - tau(hit, gamma)) == pytest.approx(h0, rel=1e-13)
    assert pic.events["vyi"][0] == pytest.approx(case.laws["restitution"] * g / gamma * -math.expm1(-gamma * hit))
    report = ds.compare(pic, pit)
    assert report.truth_wall_hits == len(pic.events) >= 3
    # PIT: on the same exact flight until then, it answers the first bounce at the first frame past the floor.
    assert 0.0 < report.wall_delays[0] < case.dt
    assert report.wall_matches[0][1] == pytest.approx(hit, rel=1e-15)
    assert abs(report.truth_energy_error) < 1e-12
    if policy == "resolve":  # drag and restitution take all that it loses
        assert abs(report.approx_energy_error) < 1e-12
    else:  # "revert" and "separate" lift the ball at each bounce
        assert report.approx_energy_error > 1e-3
    assert pit.dissipated > 0.9 * pic.dissipated
    assert "energy error" in str(report)


# --- checkpoints, the default, bad input --------------------------------------------------------------------------
@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_a_run_under_drag_continues_from_a_checkpoint_bit_for_bit(tmp_path, policy):
    discs, box = ds.random_gas(40, 0.35, periodic=False, seed=7)
    laws = {"gravity": (0.5, -G), "drag": 0.9, "restitution": 0.8}
    whole = ds.FixedStep(discs, box, dt=0.02, policy=policy, **laws).run(frames=100)
    half = ds.FixedStep(discs, box, dt=0.02, policy=policy, **laws).run(frames=50)
    copy = ds.load(half.save(tmp_path / "half.dsc"))
    assert copy.laws.drag == 0.9 and copy.laws == half.laws and copy.dissipated == half.dissipated > 0.0
    copy.run(frames=50)
    assert copy.events.tobytes() == whole.events.tobytes()
    a, b = copy.state(), whole.state()
    for name in ("ref_positions", "velocities", "ref_times", "frame_positions"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name
    assert copy.dissipated == whole.dissipated and copy.energy() == whole.energy()


def test_a_checkpoint_with_a_bad_drag_is_refused():
    sim = ds.FixedStep(ball(5.0, 5.0, 1.0), ds.Box(10.0, 10.0), drag=0.5).run(frames=3)
    settings = {**sim._settings(), "laws": {**sim.laws.settings(), "drag": -2.0}}
    with pytest.raises(CheckpointError, match="drag must be"):
        ds.FixedStep._restore(sim.scene, settings, sim.state(), sim.events, 0.0)


@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_drag_zero_gives_todays_frames_bit_for_bit(policy):
    discs, box = ds.random_gas(40, 0.3, periodic=False, seed=3)
    runs = [
        ds.FixedStep(discs, box, dt=0.05, gravity=(0.0, -1.0), restitution=0.9, policy=policy, **extra).run(frames=60)
        for extra in ({}, {"drag": 0.0})
    ]
    assert runs[0].events.tobytes() == runs[1].events.tobytes()
    assert runs[0].state().velocities.tobytes() == runs[1].state().velocities.tobytes()
    assert runs[0].dissipated == runs[1].dissipated
    plain = ds.FixedStep(discs, box, dt=0.05, drag=0.0).run(frames=10)
    assert "laws" not in plain._settings()


@pytest.mark.parametrize("drag", [-0.1, math.nan, math.inf, "thick", True])
def test_bad_drag_is_refused_naming_it(drag):
    with pytest.raises(InvalidArgumentError, match="drag"):
        ds.FixedStep(ball(5.0, 5.0), ds.Box(10.0, 10.0), drag=drag)


@pytest.mark.parametrize("policy", ("bisect", "swept"))
def test_drag_with_a_sub_frame_policy_is_refused_by_name(policy):
    with pytest.raises(InvalidArgumentError, match=rf"drag=0\.5 needs a policy .*{policy!r}"):
        ds.FixedStep(ball(5.0, 5.0), ds.Box(10.0, 10.0), drag=0.5, policy=policy)
