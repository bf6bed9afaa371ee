"""Rough discs that spin in the fixed-step engine (PIT): the rough collision law of the event-driven engine at the
frames, for disc pairs, walls and segments; spins, angles and the rotational energy; checkpoints; ``compare`` under
roughness; bad input (issue 27, items 3 and 5).

Every test runs once per backend (``every_backend``, autouse in this folder's conftest); ``test_backends.py`` pits
the two against each other bit for bit under roughness too. The textbook law is the one of
``tests/engines/event_driven/test_spin.py`` (vectors and cross products), not the library's tangent-basis form.
"""

import math

import numpy as np
import pytest

import discsim as ds
from discsim.errors import InvalidArgumentError

FRAME_POLICIES = ("resolve", "revert", "separate")
POLICIES = (*FRAME_POLICIES, "bisect", "swept")


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def textbook(p1, p2, v1, v2, w1, w2, r1, r2, m1, m2, i1, i2, e, beta):
    """Velocities, spins and the energy lost in a collision of two rough discs along the line ``p1``-``p2``."""
    p1, p2, v1, v2 = (np.asarray(x, dtype=float) for x in (p1, p2, v1, v2))
    n = (p2 - p1) / np.linalg.norm(p2 - p1)
    a1, a2 = r1 * n, -r2 * n  # from each centre to the contact point
    g = (v1 + w1 * np.array([-a1[1], a1[0]])) - (v2 + w2 * np.array([-a2[1], a2[0]]))
    gn = (g @ n) * n
    gt = g - gn
    mass_n = 1.0 / (1.0 / m1 + 1.0 / m2)
    mass_t = 1.0 / (1.0 / m1 + 1.0 / m2 + r1 * r1 / i1 + r2 * r2 / i2)
    impulse = -(1.0 + e) * mass_n * gn - (1.0 + beta) * mass_t * gt  # on disc 1; -impulse on disc 2
    lost = 0.5 * (1.0 - e * e) * mass_n * (g @ n) ** 2 + 0.5 * (1.0 - beta * beta) * mass_t * (gt @ gt)
    return v1 + impulse / m1, v2 - impulse / m2, w1 + _cross(a1, impulse) / i1, w2 + _cross(a2, -impulse) / i2, lost


def pair(p1, p2, v1, v2, w1, w2, r1, r2, m1=1.0, m2=1.0, inertia=None):
    return ds.Discs([p1, p2], [v1, v2], radii=[r1, r2], masses=[m1, m2], spins=[w1, w2], inertia=inertia)


# --- the law at a frame, in closed form -----------------------------------------------------------------------
@pytest.mark.parametrize("policy", POLICIES)
def test_a_head_on_rough_collision_turns_both_discs(policy):
    # As in the event-driven test: disc 1 runs into disc 2, which spins at 3: g_t = 3, J = -2 * 3 / 6 = -1.
    discs = pair([2.0, 5.0], [5.0, 5.0], [1.0, 0.0], [0.0, 0.0], 0.0, 3.0, 1.0, 1.0)
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.25, roughness=1.0, policy=policy).run(frames=5)
    assert sim.counts["detections"] == 1
    assert sim.velocities == pytest.approx(np.array([[0.0, -1.0], [1.0, 1.0]]), abs=1e-15)
    assert sim.spins.tolist() == pytest.approx([-2.0, 1.0])
    assert sim.kinetic_energy() == pytest.approx(0.5 + 0.25 * 9.0)  # 2.75 before and after
    assert abs(sim.dissipated) < 1e-15
    t = float(sim.events["time"][0])  # the response: at the frame, or at the contact inside it
    sim.run(until=2.0)
    assert sim.angles.tolist() == pytest.approx([-2.0 * (2.0 - t), 3.0 * t + 1.0 * (2.0 - t)])


@pytest.mark.parametrize("policy", POLICIES)
@pytest.mark.parametrize(("e", "beta"), [(1.0, 1.0), (0.8, 0.4), (1.0, 0.0), (0.5, -0.3), (1.0, -1.0)])
def test_an_oblique_rough_collision_follows_the_textbook_along_the_line_of_its_impulse(policy, e, beta):
    p1, p2, v1, v2 = [3.0, 5.0], [6.0, 5.8], [2.0, 0.3], [-0.5, 0.1]
    w1, w2, r1, r2, m1, m2 = 1.5, -0.7, 1.0, 1.4, 1.0, 2.5
    inertia = [0.3, 0.5 * m2 * r2 * r2]
    discs = pair(p1, p2, v1, v2, w1, w2, r1, r2, m1, m2, inertia)
    sim = ds.FixedStep(discs, ds.Box(12.0, 10.0), dt=0.1, restitution=e, roughness=beta, policy=policy)
    sim.run(frames=4)
    assert sim.counts["detections"] == 1 and sim.counts["wall_hits"] == 0
    row = sim.events[0]  # where the policy left the discs: the impulse acts along their line of centres
    c1, c2 = [row["xi"], row["yi"]], [row["xj"], row["yj"]]
    u1, u2, s1, s2, lost = textbook(c1, c2, v1, v2, w1, w2, r1, r2, m1, m2, inertia[0], inertia[1], e, beta)
    assert sim.velocities == pytest.approx(np.array([u1, u2]), rel=1e-12, abs=1e-14)
    assert sim.spins == pytest.approx([s1, s2], rel=1e-12, abs=1e-14)
    before = 0.5 * (m1 * np.dot(v1, v1) + m2 * np.dot(v2, v2) + inertia[0] * w1 * w1 + inertia[1] * w2 * w2)
    assert before - sim.kinetic_energy() == pytest.approx(lost, rel=1e-9, abs=1e-13)
    assert sim.dissipated == pytest.approx(lost, rel=1e-9, abs=1e-13)
    if beta == -1.0:  # smooth: the spins never change
        assert sim.spins.tolist() == [w1, w2]


@pytest.mark.parametrize("policy", POLICIES)
def test_a_rough_disc_bounces_off_a_wall_a_segment_and_an_obstacle_as_off_an_infinite_mass(policy):
    # Onto the floor (disc 0) and onto a horizontal segment (disc 1) at 45 degrees, without spin, perfectly rough:
    # g_t = 1, J = -2 / 3 (the event-driven engine's numbers): it goes on slower, turning clockwise.
    floor = ds.Segment((10.0, 4.0), (20.0, 4.0))
    discs = ds.Discs([[5.0, 3.0], [15.0, 7.0]], [[1.0, -1.0], [1.0, -1.0]], radii=1.0)
    sim = ds.FixedStep(discs, ds.Box(20.0, 10.0), dt=0.25, segments=[floor], roughness=1.0, policy=policy)
    sim.run(frames=10)
    assert sim.counts["wall_hits"] == 2 and sim.counts["detections"] == 0
    assert sim.velocities == pytest.approx(np.array([[1.0 / 3.0, 1.0], [1.0 / 3.0, 1.0]]), rel=1e-13)
    assert sim.spins == pytest.approx([-4.0 / 3.0, -4.0 / 3.0], rel=1e-13)
    assert sim.kinetic_energy() == pytest.approx(2.0, rel=1e-13)
    # A disc of finite mass and an obstacle (infinite mass and inertia, spinning at 2), head on along x: the
    # same law; the obstacle neither moves nor turns.
    discs = pair([2.0, 5.0], [5.0, 5.0], [1.0, 0.0], [0.0, 0.0], 0.0, 2.0, 1.0, 1.0, 1.0, math.inf)
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.25, restitution=0.7, roughness=0.5, policy=policy)
    sim.run(frames=5)
    inf = math.inf
    u1, _, s1, _, _ = textbook([2, 5], [5, 5], [1, 0], [0, 0], 0.0, 2.0, 1.0, 1.0, 1.0, inf, 0.5, inf, 0.7, 0.5)
    assert sim.velocities[0] == pytest.approx(u1, rel=1e-12) and sim.spins[0] == pytest.approx(s1, rel=1e-12)
    assert sim.velocities[1].tolist() == [0.0, 0.0] and sim.spins[1] == 2.0


@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_a_rough_disc_in_a_corner_is_not_sent_back_into_the_floor(policy):
    # At the frame (t = 0.6) the disc is past the left wall and the floor, both approached. The left wall's rough
    # bounce comes first: n = (-1, 0), g_t = 0.1 + r w = 2.1, J = -2 * 2.1 / 3 = -1.4: it leaves at (1, 1.3), spin
    # -0.8, already moving away from the floor, which must not reflect it back down.
    disc = ds.Discs([[1.5, 1.05]], [[-1.0, -0.1]], radii=1.0, spins=[2.0])
    sim = ds.FixedStep(disc, ds.Box(10.0, 10.0), dt=0.6, roughness=1.0, policy=policy).run(frames=1)
    assert sim.counts["wall_hits"] == 1
    assert sim.velocities[0] == pytest.approx([1.0, 1.3], rel=1e-14)
    assert sim.spins[0] == pytest.approx(-0.8, rel=1e-14)
    assert sim.kinetic_energy() == pytest.approx(0.5 * 1.01 + 0.25 * 4.0, rel=1e-14)


# --- energy along a run ------------------------------------------------------------------------------------
def gas(n=40, packing=0.2, seed=4, periodic=True):
    discs, box = ds.random_gas(n, packing, periodic=periodic, seed=seed)
    spins = np.random.default_rng(seed).normal(size=n)
    return ds.Discs(discs.positions, discs.velocities, discs.radii, spins=spins), box


@pytest.mark.parametrize("beta", [1.0, -1.0])
@pytest.mark.parametrize("periodic", [True, False])
def test_energy_is_conserved_at_roughness_plus_and_minus_one_where_pit_resolves_every_contact(beta, periodic):
    # Small frames in a dilute gas: compare() finds no collision of the exact run missed by the frames.
    discs, box = gas(periodic=periodic)
    pit = ds.FixedStep(discs, box, dt=0.002, roughness=beta).run(until=3.0)
    pic = ds.EventDriven(discs, box, roughness=beta).run(until=3.0)
    report = ds.compare(pic, pit)
    assert report.truth_collisions > 20 and report.missed == 0 and report.spurious == 0
    start = discs.kinetic_energy() + discs.rotational_energy()
    assert pit.kinetic_energy() == pytest.approx(start, rel=1e-12)
    assert abs(pit.dissipated) < 1e-12 * start
    assert report.approx_energy_error == pytest.approx(0.0, abs=1e-12)
    if beta == -1.0:
        assert pit.spins.tolist() == discs.spins.tolist()
        assert pit.angles == pytest.approx(discs.spins * pit.time, rel=1e-14)
    else:
        assert not np.array_equal(pit.spins, discs.spins)


def test_the_energy_lost_otherwise_is_what_dissipated_counts():
    discs, box = gas(seed=6, periodic=False)
    sim = ds.FixedStep(discs, box, dt=0.01, restitution=0.9, roughness=0.3).run(until=3.0)
    start = discs.kinetic_energy() + discs.rotational_energy()
    assert sim.counts["detections"] + sim.counts["wall_hits"] > 30
    assert sim.kinetic_energy() < start
    assert start - sim.kinetic_energy() == pytest.approx(sim.dissipated, rel=1e-10)


def test_smooth_discs_give_the_frames_of_the_default_laws_bit_for_bit():
    discs, box = gas(seed=2)
    plain = ds.FixedStep(discs, box, dt=0.01).run(frames=200)
    smooth = ds.FixedStep(discs, box, dt=0.01, roughness=-1.0).run(frames=200)
    assert plain.events.tobytes() == smooth.events.tobytes() and plain.counts["detections"] > 0
    assert smooth.spins.tolist() == discs.spins.tolist()
    assert smooth.kinetic_energy() == pytest.approx(discs.kinetic_energy() + discs.rotational_energy())
    snap = smooth.snapshot()
    assert snap.spins.tolist() == discs.spins.tolist() and snap.inertia.tolist() == discs.inertia.tolist()


# --- compare, checkpoints, editing, bad input -------------------------------------------------------------------
def test_compare_runs_under_roughness_and_counts_the_rotational_energy():
    discs, box = gas(seed=5)
    pic = ds.EventDriven(discs, box, restitution=0.9, roughness=0.5).run(until=1.5)
    pit = ds.FixedStep(discs, box, dt=0.01, restitution=0.9, roughness=0.5).run(until=1.5)
    report = ds.compare(pic, pit)
    assert report.matched > 10
    # Both runs lose energy by their laws only: energy() + dissipated keeps its start (the spins' energy counted).
    assert report.truth_energy_error == pytest.approx(0.0, abs=1e-12)
    assert report.approx_energy_error == pytest.approx(0.0, abs=1e-12)
    assert report.truth_energy_change < 0.0 and report.approx_energy_change < 0.0
    spun = ds.Discs(discs.positions, discs.velocities, discs.radii, spins=discs.spins + 1.0)
    with pytest.raises(InvalidArgumentError, match="disc 0 has spins"):
        ds.compare(pic, ds.FixedStep(spun, box, dt=0.01, roughness=0.5).run(until=1.5))


@pytest.mark.parametrize("policy", ("resolve", "swept"))
def test_a_rough_run_continues_from_a_checkpoint_bit_for_bit(tmp_path, policy):
    discs, box = gas(seed=7, periodic=False)
    laws = {"restitution": 0.9, "roughness": 0.4}
    whole = ds.FixedStep(discs, box, dt=0.02, policy=policy, **laws).run(frames=120)
    half = ds.FixedStep(discs, box, dt=0.02, policy=policy, **laws).run(frames=60)
    copy = ds.load(half.save(tmp_path / "half.dsc"))
    assert copy.laws == half.laws and copy.laws.roughness == 0.4
    assert copy.spins.tobytes() == half.spins.tobytes() and copy.angles.tobytes() == half.angles.tobytes()
    copy.run(frames=60)
    assert copy.events.tobytes() == whole.events.tobytes()
    assert copy.spins.tobytes() == whole.spins.tobytes()
    assert copy.angles == pytest.approx(whole.angles, rel=1e-13, abs=1e-13)
    assert copy.dissipated == whole.dissipated and copy.kinetic_energy() == whole.kinetic_energy()


def test_a_state_from_before_the_spins_reads_with_the_discs_still():
    sim = ds.FixedStep(*ds.random_gas(10, 0.2, seed=1), dt=0.05).run(frames=5)
    scalars, arrays = sim.state().to_arrays()
    del arrays["spins"], arrays["angles"]
    old = ds.FixedStepState.from_arrays(scalars, arrays, 3)
    assert old.spins.tolist() == [0.0] * 10 and old.angles.tolist() == [0.0] * 10


def test_added_discs_bring_their_spins_and_removed_ones_take_theirs():
    discs, box = gas(n=10, seed=3, periodic=False)
    sim = ds.FixedStep(discs, box, dt=0.02, roughness=1.0).run(frames=50)
    spins = sim.spins
    sim.remove_discs([0])
    assert sim.spins.tolist() == spins[1:].tolist()
    new = ds.Discs([[0.5 * box.width, 0.5 * box.height]], [[0.0, 0.0]], radii=0.01, spins=[4.0])
    sim.add_discs(new)
    assert sim.spins.tolist() == [*spins[1:].tolist(), 4.0]
    sim.run(frames=10)


@pytest.mark.parametrize("roughness", [1.5, -1.01, math.nan, "rough", True])
def test_a_bad_roughness_is_refused_naming_it(roughness):
    with pytest.raises(InvalidArgumentError, match="roughness"):
        ds.FixedStep(*ds.random_gas(5, 0.2, seed=1), roughness=roughness)
