"""Rough discs that spin in the event-driven engine: the textbook law at the contact point, energy, momentum and
angular momentum, smooth discs bit for bit, equipartition, checkpoints, bad input (issue 27, item 3).

The textbook law here is written with vectors and cross products (contact arms, ``w z x a``), apart from the
library's tangent-basis form in :func:`discsim.physics.laws.rough_impulse`.
"""

import math

import numpy as np
import pytest

import discsim as ds
from discsim.errors import InvalidArgumentError, InvalidDiscsError
from discsim.physics.laws import collide_rough


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _turn(w, a):
    """The velocity ``w z x a`` of the point at arm ``a`` of a disc spinning at ``w``."""
    return w * np.array([-a[1], a[0]])


def textbook(p1, p2, v1, v2, w1, w2, r1, r2, m1, m2, i1, i2, e, beta):
    """Velocities and spins after a collision of two rough discs at contact (disc 2 may be an obstacle: inf)."""
    p1, p2, v1, v2 = (np.asarray(x, dtype=float) for x in (p1, p2, v1, v2))
    n = (p2 - p1) / np.linalg.norm(p2 - p1)
    a1, a2 = r1 * n, -r2 * n  # from each centre to the contact point
    g = (v1 + _turn(w1, a1)) - (v2 + _turn(w2, a2))  # contact point of 1 relative to that of 2
    gn = (g @ n) * n
    gt = g - gn
    mass_n = 1.0 / (1.0 / m1 + 1.0 / m2)
    mass_t = 1.0 / (1.0 / m1 + 1.0 / m2 + r1 * r1 / i1 + r2 * r2 / i2)
    impulse = -(1.0 + e) * mass_n * gn - (1.0 + beta) * mass_t * gt  # on disc 1; -impulse on disc 2
    return (
        v1 + impulse / m1,
        v2 - impulse / m2,
        w1 + _cross(a1, impulse) / i1,
        w2 + _cross(a2, -impulse) / i2,
        0.5 * (1.0 - e * e) * mass_n * (g @ n) ** 2 + 0.5 * (1.0 - beta * beta) * mass_t * (gt @ gt),
    )


def pair(p1, p2, v1, v2, w1, w2, r1, r2, m1=1.0, m2=1.0, inertia=None):
    return ds.Discs([p1, p2], [v1, v2], radii=[r1, r2], masses=[m1, m2], spins=[w1, w2], inertia=inertia)


def first_collision(discs, box, **laws):
    sim = ds.EventDriven(discs, box, **laws)
    event = sim.step()
    assert event.kind == "collision"
    row = sim.events[-1]
    return sim, event, np.array([row["xi"], row["yi"]]), np.array([row["xj"], row["yj"]])


# --- the law, in closed form ------------------------------------------------------------------------------
def test_the_rough_law_is_the_textbook_one():
    rng = np.random.default_rng(3)
    for _ in range(200):
        p2 = rng.normal(size=2)
        v1, v2 = rng.normal(size=2), rng.normal(size=2)
        w1, w2, r1, r2 = rng.normal(), rng.normal(), rng.uniform(0.2, 2), rng.uniform(0.2, 2)
        m1, m2 = rng.uniform(0.1, 3, size=2)
        i1, i2 = rng.uniform(0.05, 1.0) * m1 * r1 * r1, rng.uniform(0.05, 1.0) * m2 * r2 * r2
        e, beta = rng.uniform(0, 1), rng.uniform(-1, 1)
        u1, u2, s1, s2, _ = textbook((0, 0), p2, v1, v2, w1, w2, r1, r2, m1, m2, i1, i2, e, beta)
        got = collide_rough(*p2, *v1, *v2, w1, w2, r1, r2, m1, m2, i1, i2, e, beta)
        assert got == pytest.approx([*u1, *u2, s1, s2], rel=1e-12, abs=1e-12)


def test_a_head_on_rough_collision_turns_both_discs():
    # Disc 1 runs into disc 2, which spins at 3: g_t = 3, J = -(1 + 1) 3 / (1 + 1 + 2 + 2) = -1.
    discs = pair([2.0, 5.0], [5.0, 5.0], [1.0, 0.0], [0.0, 0.0], 0.0, 3.0, 1.0, 1.0)
    sim, event, _, _ = first_collision(discs, ds.Box(10.0, 10.0), roughness=1.0)
    assert event.time == 1.0
    assert sim.velocities == pytest.approx(np.array([[0.0, -1.0], [1.0, 1.0]]), abs=1e-15)
    assert sim.spins.tolist() == pytest.approx([-2.0, 1.0])
    assert sim.kinetic_energy() == pytest.approx(0.5 + 0.25 * 9.0)  # 2.75 before and after
    sim.run(until=2.0)
    assert sim.angles.tolist() == pytest.approx([-2.0, 4.0])  # 0 + -2 * 1, 3 * 1 + 1 * 1


@pytest.mark.parametrize("e, beta", [(1.0, 1.0), (1.0, -1.0), (0.8, 0.4), (1.0, 0.0), (0.5, -0.3), (0.9, 1.0)])
def test_an_oblique_rough_collision_follows_the_textbook(e, beta):
    p1, p2, v1, v2 = [3.0, 5.0], [6.0, 5.8], [2.0, 0.3], [-0.5, 0.1]
    w1, w2, r1, r2, m1, m2 = 1.5, -0.7, 1.0, 1.4, 1.0, 2.5
    inertia = [0.3, 0.5 * m2 * r2 * r2]
    discs = pair(p1, p2, v1, v2, w1, w2, r1, r2, m1, m2, inertia)
    sim, _, c1, c2 = first_collision(discs, ds.Box(12.0, 10.0), restitution=e, roughness=beta)
    u1, u2, s1, s2, lost = textbook(c1, c2, v1, v2, w1, w2, r1, r2, m1, m2, inertia[0], inertia[1], e, beta)
    assert sim.velocities == pytest.approx(np.array([u1, u2]), rel=1e-12, abs=1e-14)
    assert sim.spins == pytest.approx([s1, s2], rel=1e-12, abs=1e-14)
    before = 0.5 * (m1 * np.dot(v1, v1) + m2 * np.dot(v2, v2) + inertia[0] * w1 * w1 + inertia[1] * w2 * w2)
    assert before - sim.kinetic_energy() == pytest.approx(lost, rel=1e-9, abs=1e-13)
    assert sim.dissipated == pytest.approx(lost, rel=1e-9, abs=1e-13)
    if beta == -1.0:  # smooth: the spins never change, and no spin is logged
        assert sim.spins.tolist() == [w1, w2] and len(sim.spin_events) == 0
    else:
        assert sim.spin_events[["i", "j"]].tolist() == [(0, 1)]
        assert [sim.spin_events["wi"][0], sim.spin_events["wj"][0]] == sim.spins.tolist()


def test_a_rough_disc_bounces_off_a_wall_and_an_obstacle_as_off_an_infinite_mass():
    # Onto the floor at 45 degrees, without spin, perfectly rough: I = m r^2 / 2, J = -2 g_t / (1 + 2) with
    # g_t = vx - r w ... written out by the textbook against a wall of infinite mass and inertia.
    r, v = 1.0, np.array([1.0, -1.0])
    sim = ds.EventDriven(ds.Discs([[5.0, 3.0]], [v], radii=r), ds.Box(10.0, 10.0), roughness=1.0)
    sim.step()
    centre = sim.positions[0]
    u, _, w, _, _ = textbook(centre, centre - [0.0, r], v, [0, 0], 0.0, 0.0, r, 0.0, 1.0, math.inf, 0.5, math.inf, 1, 1)
    assert sim.velocities[0] == pytest.approx(u, rel=1e-13) and sim.spins[0] == pytest.approx(w, rel=1e-13)
    # g_t = 1, J = -2 / 3: it goes on slower, turning clockwise, its contact point's sliding reversed.
    assert u == pytest.approx([1.0 / 3.0, 1.0]) and w == pytest.approx(-4.0 / 3.0)
    assert sim.kinetic_energy() == pytest.approx(1.0, rel=1e-13)
    # An obstacle (infinite mass and inertia, spinning at 2): the same law, and it neither moves nor turns.
    discs = pair([2.0, 5.0], [5.0, 5.6], [1.0, 0.0], [0.0, 0.0], 0.0, 2.0, 1.0, 1.0, 1.0, math.inf)
    sim, _, c1, c2 = first_collision(discs, ds.Box(10.0, 10.0), restitution=0.7, roughness=0.5)
    u1, _, s1, _, _ = textbook(c1, c2, [1.0, 0.0], [0, 0], 0.0, 2.0, 1.0, 1.0, 1.0, math.inf, 0.5, math.inf, 0.7, 0.5)
    assert sim.velocities[0] == pytest.approx(u1, rel=1e-12) and sim.spins[0] == pytest.approx(s1, rel=1e-12)
    assert sim.velocities[1].tolist() == [0.0, 0.0] and sim.spins[1] == 2.0


def test_a_rough_disc_bounces_off_a_segment_as_off_a_wall():
    # The same disc as above, onto a horizontal segment at y = 4 instead of the floor: the same law.
    r, v = 1.0, np.array([1.0, -1.0])
    floor = ds.Segment((0.0, 4.0), (10.0, 4.0))
    sim = ds.EventDriven(ds.Discs([[5.0, 7.0]], [v], radii=r), ds.Box(10.0, 10.0), segments=[floor], roughness=1.0)
    assert sim.step().kind == "wall"
    assert sim.positions[0][1] == pytest.approx(5.0)
    assert sim.velocities[0] == pytest.approx([1.0 / 3.0, 1.0], rel=1e-13)
    assert sim.spins[0] == pytest.approx(-4.0 / 3.0, rel=1e-13)


# --- invariants ---------------------------------------------------------------------------------------------
def test_momentum_and_angular_momentum_about_the_contact_are_conserved_per_collision():
    rng = np.random.default_rng(5)
    for _ in range(20):
        r1, r2 = rng.uniform(0.5, 1.5, size=2)
        m1, m2 = rng.uniform(0.5, 3.0, size=2)
        w1, w2 = rng.normal(scale=2.0, size=2)
        angle = rng.uniform(-0.5, 0.5)
        p1 = np.array([4.0, 6.0])
        p2 = p1 + (r1 + r2 + 1.0) * np.array([math.cos(angle), math.sin(angle)])
        v1 = 2.0 * (p2 - p1) / np.linalg.norm(p2 - p1) + rng.normal(scale=0.3, size=2)
        v2 = rng.normal(scale=0.3, size=2)
        beta, e = rng.uniform(-1, 1), rng.uniform(0.3, 1.0)
        discs = pair(p1, p2, v1, v2, w1, w2, r1, r2, m1, m2)
        sim, _, c1, c2 = first_collision(discs, ds.Box(14.0, 12.0), restitution=e, roughness=beta)
        contact = c1 + r1 * (c2 - c1) / np.linalg.norm(c2 - c1)
        i1, i2 = discs.inertia

        def angular(vs, ws, c1=c1, c2=c2, contact=contact, m1=m1, m2=m2, i1=i1, i2=i2):
            return m1 * _cross(c1 - contact, vs[0]) + i1 * ws[0] + m2 * _cross(c2 - contact, vs[1]) + i2 * ws[1]

        assert m1 * sim.velocities[0] + m2 * sim.velocities[1] == pytest.approx(m1 * v1 + m2 * v2, rel=1e-12)
        assert angular(sim.velocities, sim.spins) == pytest.approx(angular([v1, v2], [w1, w2]), rel=1e-11, abs=1e-12)


def gas(n=36, packing=0.3, seed=4, spin=1.0, periodic=True):
    discs, box = ds.random_gas(n, packing, periodic=periodic, seed=seed)
    spins = np.random.default_rng(seed).normal(scale=spin, size=n)
    return ds.Discs(discs.positions, discs.velocities, discs.radii, spins=spins), box


@pytest.mark.parametrize("beta", [1.0, -1.0])
def test_energy_is_conserved_at_roughness_plus_and_minus_one(beta):
    for periodic in (True, False):
        discs, box = gas(periodic=periodic)
        sim = ds.EventDriven(discs, box, roughness=beta)
        start = sim.kinetic_energy()
        assert start == pytest.approx(discs.kinetic_energy() + discs.rotational_energy())
        sim.run(events=1500)
        assert sim.kinetic_energy() == pytest.approx(start, rel=1e-12)
        assert abs(sim.dissipated) < 1e-12 * start


def test_energy_lost_otherwise_is_the_sum_of_the_closed_forms():
    discs, box = gas(seed=6)
    sim = ds.EventDriven(discs, box, roughness=0.3)
    start = sim.kinetic_energy()
    sim.run(events=400)
    assert sim.kinetic_energy() < start
    assert start - sim.kinetic_energy() == pytest.approx(sim.dissipated, rel=1e-10)


def test_smooth_discs_give_the_elastic_events_bit_for_bit():
    discs, box = gas(seed=2)
    plain = ds.EventDriven(ds.Discs(discs.positions, discs.velocities, discs.radii), box).run(events=500)
    smooth = ds.EventDriven(discs, box, roughness=-1.0).run(events=500)
    assert np.array_equal(plain.events, smooth.events)
    assert smooth.laws.default and smooth.spins.tolist() == discs.spins.tolist()
    assert smooth.angles == pytest.approx(discs.spins * smooth.time, rel=1e-15)
    assert len(smooth.spin_events) == 0
    # Under other laws too: the loop that reads them, at roughness -1, is the loop without roughness.
    lossy = ds.EventDriven(discs, box, restitution=0.9, roughness=-1.0).run(events=500)
    assert np.array_equal(ds.EventDriven(discs, box, restitution=0.9).run(events=500).events, lossy.events)


def test_the_spin_log_follows_the_event_log():
    discs, box = gas(seed=8, periodic=False)  # walls too
    sim = ds.EventDriven(discs, box, roughness=0.6).run(events=300)
    spins, events = sim.spin_events, sim.events
    physical = events[np.isin(events["kind"], [0, 1])]
    assert len(spins) == len(physical) == 300
    assert np.array_equal(spins["time"], physical["time"]) and np.array_equal(spins["i"], physical["i"])
    walls = physical["j"] < 0
    assert np.isnan(spins["wj"][walls]).all() and not np.isnan(spins["wj"][~walls]).any()
    last = {}
    for row in spins:
        last[int(row["i"])] = row["wi"]
        if row["j"] >= 0:
            last[int(row["j"])] = row["wj"]
    assert all(sim.spins[k] == w for k, w in last.items())
    assert sim.trajectory([sim.time])[0] == pytest.approx(sim.positions, rel=1e-12)  # spin moves no centre


def test_a_rough_run_s_frames_carry_each_disc_s_spin_and_angle():
    discs, box = gas(seed=8, periodic=False)
    sim = ds.EventDriven(discs, box, roughness=0.6).run(events=200)
    half = ds.EventDriven(discs, box, roughness=0.6).run(until=sim.time / 2)
    f = ds.frames(sim, [0.0, sim.time / 2, sim.time])
    assert (f.angles[0] == 0.0).all()  # angles count from the start (its wall hits at t = 0 done: their spins)
    assert f.spins[1].tolist() == half.spins.tolist() and f.spins[2].tolist() == sim.spins.tolist()
    assert f.angles[1] == pytest.approx(half.angles, rel=1e-12, abs=1e-12)
    assert f.angles[2] == pytest.approx(sim.angles, rel=1e-12, abs=1e-12)
    assert f.discs(1).spins.tolist() == half.spins.tolist()


@pytest.mark.slow
def test_a_rough_elastic_gas_shares_its_energy_equally_among_its_degrees_of_freedom():
    # beta = 1, I = m r^2 / 2: one rotational and two translational degrees of freedom per disc, so the
    # rotational energy settles at half the translational one. Starts without spin.
    discs, box = ds.random_gas(100, 0.25, seed=12)
    sim = ds.EventDriven(discs, box, roughness=1.0).run(events=3000)
    ratios = []
    for _ in range(40):
        sim.run(events=250)
        rotational = 0.5 * float(np.sum(sim.discs.inertia * sim.spins**2))
        ratios.append(rotational / (sim.kinetic_energy() - rotational))
    assert np.mean(ratios) == pytest.approx(0.5, abs=0.04)


# --- state, checkpoints, bad input ----------------------------------------------------------------------------
def _free_spot(sim, radius, seed=0):
    rng, box = np.random.default_rng(seed), sim.box
    while True:
        p = rng.uniform(radius, [box.width - radius, box.height - radius])
        d = box.minimum_image(sim.positions - p)
        if (np.hypot(d[:, 0], d[:, 1]) > (sim.discs.radii + radius) * 1.01).all():
            return p


@pytest.mark.parametrize("roughness", [0.5, -1.0])
def test_added_discs_keep_their_spins_and_every_disc_its_inertia(roughness, tmp_path):
    discs, box = gas(seed=3, periodic=False)
    n = len(discs)
    inertia = np.linspace(0.2, 0.6, n)
    discs = ds.Discs(discs.positions, discs.velocities, discs.radii, spins=discs.spins, inertia=inertia)
    sim = ds.EventDriven(discs, box, roughness=roughness).run(events=50)
    spins, angles = sim.spins.copy(), sim.angles.copy()
    new = ds.Discs([_free_spot(sim, 0.3)], [[0.0, 0.0]], radii=0.3, spins=[2.5], inertia=[0.01])
    (k,) = sim.add_discs(new)
    assert sim.spins.tolist() == [*spins.tolist(), 2.5] and sim.angles.tolist() == [*angles.tolist(), 0.0]
    assert sim.discs.inertia.tolist() == [*inertia.tolist(), 0.01] and sim.snapshot().spins[k] == 2.5
    loaded = ds.load(sim.save(tmp_path / "added.dsc"))  # and through a checkpoint
    assert loaded.spins.tolist() == sim.spins.tolist() and loaded.angles.tolist() == sim.angles.tolist()
    assert loaded.discs.inertia.tolist() == sim.discs.inertia.tolist()
    sim.remove_discs([0])
    assert sim.discs.inertia.tolist() == [*inertia[1:].tolist(), 0.01] and sim.spins[-1] == 2.5
    assert sim.spins[:-1].tolist() == spins[1:].tolist()


def test_a_rough_run_continues_from_a_checkpoint_bit_for_bit(tmp_path):
    discs, box = gas(seed=9)
    inertia = np.linspace(0.2, 0.6, len(discs))
    discs = ds.Discs(discs.positions, discs.velocities, discs.radii, spins=discs.spins, inertia=inertia)
    whole = ds.EventDriven(discs, box, roughness=0.5, restitution=0.95).run(events=600)
    half = ds.EventDriven(discs, box, roughness=0.5, restitution=0.95).run(events=300)
    half.save(tmp_path / "half.dsc")
    loaded = ds.load(tmp_path / "half.dsc")
    assert loaded.laws.roughness == 0.5 and loaded.discs.inertia.tolist() == inertia.tolist()
    assert loaded.spins.tolist() == half.spins.tolist() and loaded.angles.tolist() == half.angles.tolist()
    resumed = loaded.run(events=300)
    assert np.array_equal(resumed.events[-300:], whole.events[-300:])
    assert resumed.spins.tolist() == whole.spins.tolist()
    assert resumed.angles == pytest.approx(whole.angles, rel=1e-12, abs=1e-12)


def test_a_checkpoint_carries_the_spin_log_so_frames_and_the_viewer_still_turn(tmp_path):
    discs, box = gas(seed=9)
    sim = ds.EventDriven(discs, box, roughness=0.5).run(events=100)
    loaded = ds.load(sim.save(tmp_path / "rough.dsc"))
    assert np.array_equal(loaded.spin_events, sim.spin_events) and len(loaded.spin_events) == 100
    times = [sim.time / 2, sim.time]
    assert np.array_equal(ds.frames(loaded, times).angles, ds.frames(sim, times).angles)
    assert '"turning":null' not in ds.view(loaded, path=None).html
    whole = ds.EventDriven(discs, box, roughness=0.5).run(events=150)
    assert np.array_equal(loaded.run(events=50).spin_events, whole.spin_events)
    # A run that records nothing keeps no spin log, nor does its checkpoint.
    quiet = ds.EventDriven(discs, box, roughness=0.5, record=False).run(events=20)
    assert len(ds.load(quiet.save(tmp_path / "quiet.dsc")).spin_events) == 0


def test_a_state_from_before_spins_reads_with_spins_zero():
    discs, box = ds.random_gas(9, 0.3, seed=1)
    scalars, arrays = ds.EventDriven(discs, box).state().to_arrays()
    old = {k: v for k, v in arrays.items() if k not in ("spins", "angles")}
    state = ds.EventDrivenState.from_arrays(scalars, old, 2)
    assert state.spins.tolist() == [0.0] * 9 and state.angles.tolist() == [0.0] * 9


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"spins": [1.0, 2.0, 3.0]}, "spins"),
        ({"spins": [1.0, math.nan]}, "spins"),
        ({"spins": [[1.0, 2.0]]}, "spins"),
        ({"spins": ["fast", 1.0]}, "spins"),
        ({"inertia": [-1.0, 1.0]}, "inertia"),
        ({"inertia": [0.0, 1.0]}, "inertia"),
        ({"inertia": [1.0]}, "inertia"),
        ({"masses": [1.0, math.inf], "inertia": [1.0, 1.0]}, "inertia"),
    ],
)
def test_bad_spins_and_inertia_are_refused_naming_the_argument(kwargs, name):
    with pytest.raises(InvalidDiscsError, match=name):
        ds.Discs([[2.0, 2.0], [6.0, 2.0]], [[0.0, 0.0], [0.0, 0.0]], radii=1.0, **kwargs)


@pytest.mark.parametrize("beta", [1.5, -1.01, math.nan, "rough", True])
def test_bad_roughness_is_refused_naming_the_argument(beta):
    with pytest.raises(InvalidArgumentError, match="roughness"):
        ds.EventDriven(ds.Discs([[2.0, 2.0]], [[1.0, 0.0]], radii=1.0), ds.Box(10.0, 10.0), roughness=beta)


def test_discs_keep_their_old_calls_and_default_turning():
    discs = ds.Discs([[2.0, 2.0], [6.0, 2.0]], [[1.0, 0.0], [0.0, 0.0]], 1.0, [2.0, math.inf], [0, 1])
    assert discs.spins.tolist() == [0.0, 0.0] and discs.inertia.tolist() == [1.0, math.inf]
    assert discs.rotational_energy() == 0.0
    moved = discs.replace(velocities=[[2.0, 0.0], [0.0, 0.0]])
    assert moved.inertia.tolist() == [1.0, math.inf] and moved.spins.tolist() == [0.0, 0.0]
