"""Gravity, restitution and the TC model in the fixed-step engine (PIT): the exact parabola at the frames, energy,
the collision law with restitution at a frame, per-group restitution, checkpoints, bad input (issue 27, item 5).

Every test runs once per backend (``every_backend``, autouse in this folder's conftest); the two backends give the
same frames bit for bit under the laws too (``test_backends.py``).
"""

import math

import numpy as np
import pytest

import discsim as ds
from discsim import _numba
from discsim.errors import CheckpointError, InvalidArgumentError

if _numba.available():
    # Compiled now, while numba is visible: the python case of the bouncing ball runs EventDriven under the laws,
    # whose interpreted loop imports the compiled physics parts, and would import them with numba hidden (plain
    # functions that the compiled frame of the numba case then cannot call).
    import discsim.engines.fixed_step.numba.policy

G = 9.81
FRAME_POLICIES = ("resolve", "revert", "separate")


def ball(x, y, vx=0.0, vy=0.0, r=1.0, group=0):
    return ds.Discs([[x, y]], [[vx, vy]], radii=r, groups=[group])


# --- gravity: the exact parabola at the frames -----------------------------------------------------------------
@pytest.mark.parametrize("policy", FRAME_POLICIES)
@pytest.mark.parametrize("gravity", [(0.0, -G), (1.5, -4.0)])
def test_a_projectile_is_on_the_exact_parabola_at_every_frame(policy, gravity):
    x0, y0, vx, vy, dt = 3.0, 6.0, 1.3, 2.0, 1.0 / 60.0
    sim = ds.FixedStep(ball(x0, y0, vx, vy), ds.Box(20.0, 20.0), dt=dt, gravity=gravity, policy=policy)
    gx, gy = gravity
    for k in range(1, 61):
        assert sim.step() == []
        t = k * dt
        assert sim.time == t
        assert sim.positions[0] == pytest.approx(
            [x0 + vx * t + gx * t * t / 2, y0 + vy * t + gy * t * t / 2], rel=1e-13
        )
        assert sim.velocities[0] == pytest.approx([vx + gx * t, vy + gy * t], rel=1e-13, abs=1e-13)
    # Between frames too (the clock moved past the last frame: the frame grid stays).
    t = 1.0 + 0.3 * dt
    sim.run(until=t)
    assert sim.frames == 60
    assert sim.positions[0] == pytest.approx([x0 + vx * t + gx * t * t / 2, y0 + vy * t + gy * t * t / 2], rel=1e-13)
    assert sim.velocities[0] == pytest.approx([vx + gx * t, vy + gy * t], rel=1e-13)


@pytest.mark.parametrize("policy", FRAME_POLICIES)
@pytest.mark.parametrize("periodic", [False, True])
def test_the_trajectory_under_gravity_follows_the_parabolas_between_responses(policy, periodic):
    discs = ds.Discs([[3.0, 4.0], [6.0, 2.5], [4.5, 1.2]], [[2.0, 1.0], [-1.0, 3.0], [0.5, 0.0]], radii=0.5)
    box = ds.Box(9.0, 9.0, periodic=periodic)
    sim = ds.FixedStep(discs, box, dt=0.05, gravity=(0.7, -G), restitution=0.8, policy=policy)
    seen = [sim.positions]
    for _ in range(60):
        sim.step()
        seen.append(sim.positions)
    assert sim.counts["wall_hits"] + sim.counts["detections"] >= (1 if periodic else 4)
    rebuilt = sim.trajectory(sim.frame_times())
    assert rebuilt == pytest.approx(np.array(seen), rel=1e-12, abs=1e-12)
    between = sim.frame_times()[:-1] + 0.02
    moved = ds.FixedStep(discs, box, dt=0.05, gravity=(0.7, -G), restitution=0.8, policy=policy)
    for k, t in enumerate(between.tolist()):
        moved.run(until=t)
        assert sim.trajectory([t])[0] == pytest.approx(moved.positions, rel=1e-12, abs=1e-12), k
        moved.run(frames=1)


def test_obstacles_stay_put_under_gravity():
    discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[0.0, 0.0], [0.0, 0.0]], radii=0.5, masses=[1.0, math.inf])
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.1, gravity=(0.0, -G)).run(frames=5)
    assert sim.positions[1].tolist() == [8.0, 5.0] and sim.velocities[1].tolist() == [0.0, 0.0]
    assert sim.positions[0][1] == pytest.approx(5.0 - G * 0.25 / 2, rel=1e-13)


def test_energy_is_conserved_under_gravity_while_nothing_collides():
    rng = np.random.default_rng(5)
    positions = np.array([[10.0 + 10.0 * i, 150.0 + 10.0 * j] for i in range(4) for j in range(4)])
    velocities = rng.normal(0.0, 0.5, (16, 2))
    discs = ds.Discs(positions, velocities, radii=1.0, masses=rng.uniform(0.5, 2.0, 16))
    sim = ds.FixedStep(discs, ds.Box(60.0, 200.0), dt=0.02, gravity=(0.0, -G), restitution=0.5)
    e0 = sim.energy()
    assert e0 == pytest.approx(sim.kinetic_energy() + G * float(np.sum(discs.masses * positions[:, 1])))
    for _ in range(10):
        sim.run(frames=10)
        assert sim.energy() == pytest.approx(e0, rel=1e-13)
    assert sim.counts["detections"] == sim.counts["wall_hits"] == 0 and sim.dissipated == 0.0
    assert sim.potential_energy() < G * float(np.sum(discs.masses * positions[:, 1]))  # they fell


@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_an_elastic_ball_on_a_floor_keeps_its_energy_only_where_the_policy_moves_nothing(policy):
    # PIT answers the floor at the first frame below it. "resolve" reverses the velocity there: kinetic and
    # potential energy are both kept. "revert" (back to the frame before) and "separate" (lifted onto the floor)
    # raise the ball and keep its speed: each bounce adds energy.
    sim = ds.FixedStep(ball(5.0, 5.0), ds.Box(10.0, 10.0), frame_rate=30.0, gravity=(0.0, -G), policy=policy)
    e0 = sim.energy()
    sim.run(until=10.0)
    assert sim.counts["wall_hits"] == 5 and sim.dissipated == 0.0
    if policy == "resolve":
        assert sim.energy() == pytest.approx(e0, rel=1e-14)
    else:
        assert sim.energy() > 1.2 * e0


# --- restitution at a frame ------------------------------------------------------------------------------------
@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_a_head_on_collision_at_a_frame_takes_the_closed_form(policy, e):
    m1, m2, v1, v2 = 1.0, 3.0, 2.0, -1.0
    discs = ds.Discs([[2.0, 5.0], [6.2, 5.0]], [[v1, 0.0], [v2, 0.0]], radii=1.0, masses=[m1, m2])
    sim = ds.FixedStep(discs, ds.Box(12.0, 10.0), dt=0.25, restitution=e, policy=policy)
    sim.run(frames=3)  # 3 dt = 0.75 apart less: 4.2 - 3 * 0.75 = 1.95 < 2 at frame 3
    assert sim.counts["detections"] == 1
    u1 = v1 - (1 + e) * m2 / (m1 + m2) * (v1 - v2)
    u2 = v2 + (1 + e) * m1 / (m1 + m2) * (v1 - v2)
    assert sim.velocities[:, 0] == pytest.approx([u1, u2], rel=1e-14, abs=1e-14)
    assert sim.velocities[:, 1].tolist() == [0.0, 0.0]
    assert float(np.sum(discs.masses * sim.velocities[:, 0])) == pytest.approx(m1 * v1 + m2 * v2)  # momentum
    lost = 0.5 * m1 * m2 / (m1 + m2) * (1 - e * e) * (v1 - v2) ** 2
    assert sim.dissipated == pytest.approx(lost, rel=1e-14)
    assert sim.kinetic_energy() + sim.dissipated == pytest.approx(0.5 * (m1 * v1 * v1 + m2 * v2 * v2), rel=1e-14)


@pytest.mark.parametrize("policy", ("resolve", "separate", "bisect", "swept"))
def test_a_wall_and_a_segment_bounce_take_the_restitution(policy):
    segment = ds.Segment((6.0, 0.5), (6.0, 4.5))
    discs = ds.Discs([[8.0, 2.5], [1.6, 7.0]], [[-1.0, 0.0], [-1.0, 0.0]], radii=0.5)
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.25, restitution=0.6, segments=[segment], policy=policy)
    sim.run(frames=8)
    assert sim.counts["wall_hits"] == 2
    assert sim.velocities == pytest.approx(np.array([[0.6, 0.0], [0.6, 0.0]]), rel=1e-15, abs=1e-15)
    assert sim.dissipated == pytest.approx(2 * 0.5 * (1 - 0.36))


@pytest.mark.parametrize("policy", ("resolve", "revert", "bisect", "swept"))
def test_restitution_per_pair_of_groups(policy):
    # Two head-on pairs at the same time: groups (0, 1) at e = 0.25, groups (1, 1) not named: elastic;
    # disc 4 (group 2) bounces off the left wall with its group's pair with itself, (2, 2): e = 0.5.
    positions = [[2.0, 2.0], [6.2, 2.0], [2.0, 6.0], [6.2, 6.0], [1.2, 9.0]]
    velocities = [[2.0, 0.0], [-2.0, 0.0], [2.0, 0.0], [-2.0, 0.0], [-2.0, 0.0]]
    discs = ds.Discs(positions, velocities, radii=[1.0, 1.0, 1.0, 1.0, 0.5], groups=[0, 1, 1, 1, 2])
    e = {(1, 0): 0.25, (2, 2): 0.5}
    sim = ds.FixedStep(discs, ds.Box(12.0, 12.0), dt=0.25, restitution=e, policy=policy).run(frames=3)
    assert sim.counts["detections"] == 2 and sim.counts["wall_hits"] == 1
    assert sim.velocities[:, 0] == pytest.approx([-0.5, 0.5, -2.0, 2.0, 1.0], rel=1e-14)
    assert sim.dissipated == pytest.approx(0.5 * 0.5 * (1 - 0.25**2) * 16 + 0.5 * (4 - 1), rel=1e-14)


def test_the_tc_model_makes_a_response_soon_after_another_elastic():
    # Disc 0 bounces off the wall at frame 1, then meets disc 1 at frame 3: within tc = 1 of the bounce the
    # collision is elastic (equal masses swap velocities); without the TC model it is not.
    discs = ds.Discs([[1.1, 5.0], [3.8, 5.0]], [[-1.0, 0.0], [-1.0, 0.0]], radii=1.0)
    runs = {
        tc: ds.FixedStep(discs, ds.Box(20.0, 10.0), dt=0.25, restitution=0.5, tc=tc).run(frames=3) for tc in (0.0, 1.0)
    }
    for sim in runs.values():
        assert sim.counts["wall_hits"] == 1 and sim.counts["detections"] == 1
    assert runs[1.0].velocities[:, 0].tolist() == [-1.0, 0.5]  # equal masses, elastic: swapped
    assert runs[0.0].velocities[:, 0] == pytest.approx([0.5 - 0.75 * 1.5, -1.0 + 0.75 * 1.5])
    assert runs[1.0].state().last_collision.tolist() == [0.75, 0.75]
    assert runs[0.0].state().last_collision.tolist() == [-math.inf, -math.inf]  # no TC model: no clocks


# --- the defaults, checkpoints, bad input ---------------------------------------------------------------------
def test_the_defaults_store_no_laws_and_are_elastic():
    discs, box = ds.random_gas(40, 0.3, periodic=False, seed=3)
    sim = ds.FixedStep(discs, box, dt=0.05).run(frames=40)
    assert "laws" not in sim._settings()
    assert sim.laws.default and sim.dissipated == 0.0 and sim.potential_energy() == 0.0
    assert sim.energy() == sim.kinetic_energy()
    explicit = ds.FixedStep(discs, box, dt=0.05, gravity=None, restitution=1.0, tc=0.0).run(frames=40)
    assert explicit.events.tobytes() == sim.events.tobytes()


@pytest.mark.parametrize("policy", ("resolve", "separate", "swept"))
def test_a_run_under_the_laws_continues_from_a_checkpoint_bit_for_bit(tmp_path, policy):
    discs, box = ds.random_gas(60, 0.35, periodic=False, seed=7)
    laws = {"restitution": {(0, 0): 0.8}, "tc": 0.05}
    if policy != "swept":
        laws["gravity"] = (0.5, -G)
    whole = ds.FixedStep(discs, box, dt=0.02, policy=policy, **laws).run(frames=120)
    half = ds.FixedStep(discs, box, dt=0.02, policy=policy, **laws).run(frames=60)
    copy = ds.load(half.save(tmp_path / "half.dsc"))
    assert copy.laws == half.laws and copy.dissipated == half.dissipated > 0.0
    copy.run(frames=60)
    assert copy.events.tobytes() == whole.events.tobytes()
    a, b = copy.state(), whole.state()
    for name in ("ref_positions", "velocities", "ref_times", "last_collision"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name
    assert copy.dissipated == whole.dissipated and copy.energy() == whole.energy()


def test_a_state_from_before_the_laws_reads_with_their_defaults():
    sim = ds.FixedStep(*ds.random_gas(10, 0.2, seed=1), dt=0.05).run(frames=5)
    scalars, arrays = sim.state().to_arrays()
    del scalars["dissipated"], arrays["last_collision"]
    old = ds.FixedStepState.from_arrays(scalars, arrays, 2)
    assert old.dissipated == 0.0 and old.last_collision.tolist() == [-math.inf] * 10


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"restitution": 1.5}, "restitution"),
        ({"restitution": -0.1}, "restitution"),
        ({"restitution": "elastic"}, "restitution"),
        ({"restitution": {(0, 1): 2.0}}, "restitution"),
        ({"restitution": {"ab": 0.5}}, "restitution"),
        ({"gravity": (0.0, math.nan)}, "gravity"),
        ({"gravity": (1.0,)}, "gravity"),
        ({"gravity": "down"}, "gravity"),
        ({"tc": -1.0}, "tc"),
        ({"tc": math.inf}, "tc"),
        ({"rest_speed": -1.0}, "rest_speed"),
    ],
)
def test_bad_laws_are_refused_naming_the_argument(kwargs, name):
    with pytest.raises(InvalidArgumentError, match=name):
        ds.FixedStep(ball(5.0, 5.0), ds.Box(10.0, 10.0), **kwargs)


@pytest.mark.parametrize("policy", ("bisect", "swept"))
def test_gravity_with_a_sub_frame_policy_is_refused_by_name(policy):
    with pytest.raises(InvalidArgumentError, match=rf"gravity=\(0\.0, -9\.81\) needs a policy .*{policy!r}"):
        ds.FixedStep(ball(5.0, 5.0), ds.Box(10.0, 10.0), gravity=(0.0, -G), policy=policy)


def test_rest_speed_is_accepted_and_changes_nothing():
    runs = [
        ds.FixedStep(ball(5.0, 5.0), ds.Box(10.0, 10.0), gravity=(0.0, -G), restitution=0.7, rest_speed=speed).run(
            until=3.0
        )
        for speed in (None, 0.5)
    ]
    assert runs[0].events.tobytes() == runs[1].events.tobytes()


def test_pressure_under_gravity_is_refused_with_a_reason():
    sim = ds.FixedStep(ball(5.0, 5.0), ds.Box(10.0, 10.0), gravity=(0.0, -G)).run(frames=3)
    with pytest.raises(InvalidArgumentError, match="under gravity"):
        sim.pressure()


def test_a_checkpoint_with_unreadable_laws_is_refused(tmp_path):
    sim = ds.FixedStep(ball(5.0, 5.0), ds.Box(10.0, 10.0), restitution=0.5).run(frames=3)
    settings = {**sim._settings(), "laws": {**sim.laws.settings(), "restitution": 7.0}}
    with pytest.raises(CheckpointError, match="restitution must lie in"):
        ds.FixedStep._restore(sim.scene, settings, sim.state(), sim.events, 0.0)


# --- the study's case under the laws: a ball bouncing to rest, PIT against PIC ----------------------------------
@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_the_bouncing_ball_case_shows_what_stepping_costs(policy):
    case = ds.scenarios.bouncing_ball()
    assert ds.scenarios.law_cases()[0].name == case.name
    assert hash(case) != hash(ds.scenarios.delay())  # hashable, as the cases were before they had laws
    e, g = case.laws["restitution"], -case.laws["gravity"][1]
    h0 = float(case.discs.positions[0, 1] - case.discs.radii[0])
    pic = ds.EventDriven(case.discs, case.box, **case.laws).run(until=case.until)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=policy, **case.laws)
    pit.run(until=case.until)
    # PIC: the bounces of the geometric series, then rest on the floor.
    hits = pic.events["time"]
    v1 = math.sqrt(2.0 * g * h0)
    k = np.arange(len(hits) - 1)
    assert hits == pytest.approx(np.concatenate([[v1 / g], v1 / g + np.cumsum(2.0 * e ** (k + 1) * v1 / g)]), rel=1e-10)
    assert pic.resting.tolist() == [True]
    report = ds.compare(pic, pit)
    assert report.truth_wall_hits == len(hits) > 15
    # PIT answers the first bounce at the first frame below the floor: late by less than a frame.
    assert 0.0 < report.wall_delays[0] < case.dt
    assert report.wall_matches[0][1] == pytest.approx(v1 / g, rel=1e-12)
    # Its bounce times and heights drift from the series; it does not come to rest but keeps hitting the floor.
    assert len(report.wall_matches) >= 3 and abs(report.max_wall_delay) > 0.25 * case.dt
    assert np.all(report.rebound_errors != 0.0) and abs(report.max_rebound_error) > 0.05
    assert report.spurious_wall_hits and max(t for _, _, t in report.spurious_wall_hits) > hits[-1]
    assert abs(pit.velocities[0, 1]) > 0.01 or pit.positions[0, 1] != 0.5
    # Energy: PIC loses exactly what its collision law and the rest take; PIT's "resolve" keeps energy and
    # dissipation in balance but dissipates more than PIC (it bounces from below the floor); "revert" and
    # "separate" lift the ball at each bounce and gain energy.
    assert abs(report.truth_energy_error) < 1e-12
    if policy == "resolve":
        assert abs(report.approx_energy_error) < 1e-12 and pit.dissipated > 1.005 * pic.dissipated
    else:
        assert report.approx_energy_error > 0.1
    text = str(report)
    assert "wall hits        matched" in text and "rebound height error" in text and "energy error" in text
