"""A piston on top of the box (issue 28, item 2): closed forms, an independent 1D oracle of a disc bouncing under it,
energy, checkpoints, set_piston, both backends bit for bit, a kinematic lid, bad input."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds
from discsim.analysis.isobaric import IsobaricAverages
from discsim.errors import InvalidArgumentError, OutsideBoxError, TimeError, WrongTypeError

BOX = ds.Box(10.0, 10.0)


def ball(x, y, vx=0.0, vy=0.0, r=0.5, m=1.0):
    return ds.Discs([[x, y]], [[vx, vy]], radii=r, masses=m)


def energy(sim):
    """The run's invariant: the discs' kinetic energy, the piston's, and its potential energy F H."""
    p = sim.piston
    return sim.kinetic_energy() + 0.5 * p.mass * p.velocity**2 + p.pressure * sim.box.width * p.height


def test_a_piston_released_over_a_disc_at_rest_falls_onto_it_and_they_bounce_as_two_masses_do():
    # M = 3 under F = 0.3 * 10: a = 1; the gap 5.5 - 0.5 - 1 = 4 closes at sqrt(2 * 4 / 1); at -sqrt(8) it hits m = 1
    # at rest: the disc leaves at 2 M u / (m + M), the piston goes on at (M - m) u / (m + M).
    sim = ds.EventDriven(ball(5.0, 1.0), BOX, piston=ds.Piston(mass=3.0, pressure=0.3, height=5.5))
    event = sim.step()
    u = -math.sqrt(8.0)
    assert (event.kind, event.i, event.j) == ("wall", 0, -1)
    assert event.time == pytest.approx(math.sqrt(8.0), rel=1e-14)
    assert sim.velocities[0] == pytest.approx([0.0, 1.5 * u], rel=1e-14)
    assert sim.piston.velocity == pytest.approx(0.5 * u, rel=1e-14)
    assert sim.piston.height == pytest.approx(1.5, rel=1e-14) and sim.piston.hits == 1
    record = sim.events[-1]  # the log's WALL record carries the piston's height and velocity after
    assert (record["yj"], record["vyj"]) == (sim.piston.height, sim.piston.velocity)
    assert np.isnan(record["xj"]) and np.isnan(record["vxj"])


def _oracle(y, v, r, m, h, u, mass, force, until):
    """An independent 1D event loop of one disc bouncing between the floor and a piston (both of which it meets
    exactly): the list of (time, y, v, h, u) after each impact on the piston."""
    a = force / mass
    t, out = 0.0, []
    while True:
        # the floor: y - r + v s = 0 for v < 0; the piston: (h - r - y) + (u - v) s - a s^2 / 2 = 0, larger root
        floor = (r - y) / v if v < 0 else math.inf
        g, w = h - r - y, u - v
        top = (w + math.sqrt(w * w + 2.0 * a * g)) / a
        s = min(floor, top)
        if t + s > until:
            return out
        t += s
        y, h, u = y + v * s, h + u * s - 0.5 * a * s * s, u - a * s
        if s == floor:
            v = -v
        else:
            v, u = ((m - mass) * v + 2 * mass * u) / (m + mass), ((mass - m) * u + 2 * m * v) / (m + mass)
            out.append((t, y, v, h, u))


def test_a_disc_under_a_piston_bounces_as_an_independent_1d_loop_says_and_the_energy_holds():
    disc = ball(3.0, 2.0, 0.0, 1.3, r=0.5, m=1.0)
    piston = ds.Piston(mass=4.0, pressure=0.2, height=6.0, velocity=0.5)
    sim = ds.EventDriven(disc, BOX, piston=piston).run(until=60.0)
    hits = sim.events[(sim.events["kind"] == int(ds.EventKind.WALL)) & ~np.isnan(sim.events["yj"])]
    expected = np.array(_oracle(2.0, 1.3, 0.5, 1.0, 6.0, 0.5, 4.0, 0.2 * 10.0, 60.0))
    assert len(hits) == len(expected) > 10
    got = np.column_stack([hits["time"], hits["yi"], hits["vyi"], hits["yj"], hits["vyj"]])
    assert got == pytest.approx(expected, rel=1e-9, abs=1e-9)
    assert energy(sim) == pytest.approx(0.5 * 1.3**2 + 0.5 * 4.0 * 0.25 + 2.0 * 6.0, rel=1e-13)


def test_a_gas_under_a_piston_keeps_its_energy_and_every_disc_below_it():
    discs, _ = ds.random_gas(40, 0.2, seed=3, periodic=False)
    box = ds.Box(discs.positions[:, 0].max() + 2.0, 200.0)  # tall enough for the energy bound
    top = float((discs.positions[:, 1] + discs.radii).max()) + 0.5
    sim = ds.EventDriven(discs, box, piston=ds.Piston(mass=20.0, pressure=0.5, height=top))
    e0 = energy(sim)
    for until in np.linspace(1.0, 20.0, 5):
        sim.run(until=until)
        assert energy(sim) == pytest.approx(e0, rel=1e-12)
        assert (sim.positions[:, 1] + sim.discs.radii <= sim.piston.height * (1 + 1e-12)).all()
    assert sim.piston.hits > 20 and sim.counts["stale"] > 0  # contacts dropped after another disc hit it first
    sim._check()


def test_a_piston_run_resumes_from_a_checkpoint_bit_for_bit_and_both_backends_agree(every_backend, tmp_path):
    discs, _ = ds.random_gas(20, 0.2, seed=4, periodic=False)
    box = ds.Box(discs.positions[:, 0].max() + 2.0, 100.0)
    piston = ds.Piston(mass=5.0, pressure=0.4, height=float((discs.positions[:, 1] + discs.radii).max()) + 1.0)
    whole = ds.EventDriven(discs, box, piston=piston).run(until=8.0)
    assert whole.backend == every_backend
    half = ds.EventDriven(discs, box, piston=piston).run(until=4.0)
    half.save(tmp_path / "half.npz")
    resumed = ds.load(tmp_path / "half.npz")
    assert resumed.scene.piston == piston
    resumed.run(until=8.0)
    assert resumed.events.tobytes() == whole.events.tobytes()
    assert resumed.piston.height == whole.piston.height
    if every_backend == "numba":
        python = ds.EventDriven(discs, box, piston=piston, backend="python").run(until=8.0)
        assert python.events.tobytes() == whole.events.tobytes()


def test_set_piston_pushes_harder_from_now_on():
    sim = ds.EventDriven(ball(5.0, 1.0, 0.0, 2.0), BOX, piston=ds.Piston(mass=2.0, pressure=0.1, height=4.0))
    sim.run(until=5.0)
    sim.set_piston(pressure=0.4)
    assert sim.piston.pressure == 0.4
    e0 = energy(sim)
    sim.run(until=30.0)
    assert energy(sim) == pytest.approx(e0, rel=1e-12)
    sim.set_piston(velocity=0.0)
    assert sim.piston.velocity == 0.0


def test_a_kinematic_lid_closes_on_a_disc_at_its_speed():
    # The lid y = 8 - t; the disc rises at 1 from y = 2 (top 2.5): they meet at t = 2.75, the disc leaves at 2u - v.
    lid = ds.Piston(mass=math.inf, pressure=0.0, height=8.0, velocity=-1.0)
    sim = ds.EventDriven(ball(5.0, 2.0, 0.0, 1.0), BOX, piston=lid)
    event = sim.step()
    assert event.time == pytest.approx(2.75, rel=1e-14)
    assert sim.velocities[0] == pytest.approx([0.0, -3.0], rel=1e-14)
    assert sim.piston.velocity == -1.0 and sim.piston.height == pytest.approx(5.25, rel=1e-14)


def test_bad_pistons_are_refused_by_name_before_anything_runs():
    disc = ball(5.0, 1.0)
    with pytest.raises(InvalidArgumentError, match="mass"):
        ds.Piston(mass=0.0, pressure=1.0)
    with pytest.raises(InvalidArgumentError, match="pressure"):
        ds.Piston(mass=1.0, pressure=0.0)
    with pytest.raises(InvalidArgumentError, match="kinematic"):
        ds.Piston(mass=math.inf, pressure=1.0)
    with pytest.raises(WrongTypeError, match="piston"):
        ds.EventDriven(disc, BOX, piston="heavy")
    with pytest.raises(InvalidArgumentError, match="periodic"):
        ds.EventDriven(disc, ds.Box(10.0, 10.0, periodic=True), piston=ds.Piston(1.0, 1.0))
    with pytest.raises(OutsideBoxError, match="disc 0"):
        ds.EventDriven(disc, BOX, piston=ds.Piston(1.0, 1.0, height=1.2))
    with pytest.raises(InvalidArgumentError, match="above the box"):
        ds.EventDriven(ball(5.0, 1.0, 0.0, 5.0), BOX, piston=ds.Piston(1.0, 0.01, height=5.0))
    with pytest.raises(InvalidArgumentError, match="restitution=0.5"):
        ds.EventDriven(disc, BOX, piston=ds.Piston(1.0, 1.0), restitution=0.5)
    with pytest.raises(InvalidArgumentError, match="gravity"):
        ds.EventDriven(disc, BOX, piston=ds.Piston(1.0, 1.0), gravity=(0.5, -1.0))
    with pytest.raises(InvalidArgumentError, match="obstacle"):
        ds.EventDriven(ball(5.0, 1.0, m=math.inf), BOX, piston=ds.Piston(1.0, 1.0))
    sim = ds.EventDriven(ball(5.0, 1.0, 0.0, 1.0), BOX, piston=ds.Piston(1.0, 1.0, height=5.0))
    with pytest.raises(InvalidArgumentError, match="above the box"):
        sim.set_piston(pressure=1e-6)
    with pytest.raises(InvalidArgumentError, match="needs a piston"):
        ds.EventDriven(disc, BOX).set_piston(pressure=1.0)
    assert sim.piston.pressure == 1.0 and sim.time == 0.0


def test_thermo_of_a_piston_run_averages_the_area_it_sampled_and_says_the_pressure():
    discs, _ = ds.random_gas(30, 0.3, seed=6, periodic=False)
    box = ds.Box(discs.positions[:, 0].max() + 1.5, 120.0)
    top = float((discs.positions[:, 1] + discs.radii).max()) + 0.5
    sim = ds.EventDriven(discs, box, piston=ds.Piston(mass=8.0, pressure=0.3, height=top))
    sim.run(until=5.0)
    heights, kinetic = [], []
    for t in np.linspace(5.0, 40.0, 7001)[1:]:  # a dense sample of the piston's height and the discs' energy
        sim.run(until=t)
        heights.append(sim.piston.height)
        kinetic.append(sim.kinetic_energy())
    averages = ds.thermo(sim, since=5.0)
    assert isinstance(averages, IsobaricAverages) and averages.pressure == 0.3
    assert averages.area == pytest.approx(box.width * np.mean(heights), rel=5e-4)
    assert averages.energy == pytest.approx(np.mean(kinetic), rel=5e-4)
    assert averages.z == pytest.approx(0.3 * averages.area / averages.energy, rel=1e-12)
    assert averages.packing == pytest.approx(np.pi * np.sum(discs.radii**2) / averages.area, rel=1e-12)
    assert 0 < averages.area_err < 0.05 * averages.area
    sim.set_piston(pressure=0.5)
    sim.run(until=50.0)
    with pytest.raises(TimeError, match="last change"):
        ds.thermo(sim, since=30.0)
    assert ds.thermo(sim).pressure == 0.5


@settings(max_examples=12, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    n=st.integers(1, 12),
    mass=st.floats(0.05, 50.0),
    pressure=st.floats(0.01, 2.0),
    velocity=st.floats(-3.0, 3.0),
)
def test_any_small_gas_under_any_piston_keeps_its_energy_and_stays_below_it(seed, n, mass, pressure, velocity):
    rng = np.random.default_rng(seed)
    discs = ds.Discs(
        np.column_stack([1.0 + 8.0 * (np.arange(n) % 4) / 3.0, 1.0 + 1.2 * (np.arange(n) // 4)]),
        rng.normal(size=(n, 2)),
        radii=0.5,
        masses=rng.uniform(0.5, 2.0, n),
    )
    start = energy_of(discs, mass, pressure, 10.0, 6.0, velocity)
    box = ds.Box(10.0, max(6.0 + start / (pressure * 10.0), 7.0) * 1.01)  # above the energy bound
    sim = ds.EventDriven(discs, box, piston=ds.Piston(mass, pressure, height=6.0, velocity=velocity))
    sim.run(events=300)
    assert energy(sim) == pytest.approx(start, rel=1e-10)
    sim._check()


def energy_of(discs, mass, pressure, width, height, velocity):
    """The energy above the floor's potential: the discs' kinetic energy, the piston's, and F H."""
    kinetic = 0.5 * float(np.sum(discs.masses * np.sum(discs.velocities**2, axis=1)))
    return kinetic + 0.5 * mass * velocity**2 + pressure * width * height


def test_thermo_of_a_piston_run_reads_a_streamed_log_as_the_one_in_memory(tmp_path):
    discs, _ = ds.random_gas(20, 0.3, seed=8, periodic=False)
    box = ds.Box(discs.positions[:, 0].max() + 1.5, 100.0)
    piston = ds.Piston(mass=5.0, pressure=0.3, height=float((discs.positions[:, 1] + discs.radii).max()) + 0.5)
    kept = ds.EventDriven(discs, box, piston=piston).run(until=30.0)
    streamed = ds.EventDriven(discs, box, piston=piston, record=False).run(until=30.0, record_to=tmp_path / "run")
    a, b = ds.thermo(kept, since=3.0), ds.thermo(streamed, since=3.0)
    assert (a.area, a.energy, a.z, a.hits) == (b.area, b.energy, b.z, b.hits)
    with pytest.raises(InvalidArgumentError, match="record"):
        ds.thermo(ds.EventDriven(discs, box, piston=piston, record=False).run(until=5.0))


def test_a_heavy_piston_over_one_disc_oscillates_at_the_adiabatic_frequency():
    # One disc (m = 1) bouncing at v between the floor and a piston M = 100 under F = 1: it pushes with m v^2 / L on
    # average (L = H - 2r, the centre's run), so the piston sits where m v^2 = F L, here L = 4 at v = 2. Slow
    # against the bounces, the disc is a 1D gas (gamma = 3: v L constant), F L^3 constant under slow moves, so the
    # piston oscillates at omega^2 = 3 F / (M L): a period of 2 pi sqrt(M L / 3 F) = 72.55.
    r, length, force, mass = 0.5, 4.0, 1.0, 100.0
    piston = ds.Piston(mass=mass, pressure=force / 10.0, height=length + 2 * r, velocity=0.02)
    sim = ds.EventDriven(ball(5.0, r, 0.0, 2.0, r=r), ds.Box(10.0, 20.0), piston=piston)
    times = np.arange(0.0, 800.0, 0.25)
    heights = []
    for t in times:
        sim.run(until=t)
        heights.append(sim.piston.height)
    h = np.asarray(heights) - np.mean(heights)
    ups = times[1:][(h[:-1] < 0) & (h[1:] >= 0)]  # the piston's upward passes through its mean height
    period = float(np.median(np.diff(ups)))
    assert period == pytest.approx(2 * math.pi * math.sqrt(mass * length / (3 * force)), rel=0.02)


def test_under_gravity_a_piston_with_its_weight_falls_onto_a_disc_at_rest_and_wakes_it():
    # g = 1 down; M = 2 under P w = 2: it falls at 2 / 2 + 1 = 2 from 5.5 onto the disc resting on the floor (top at
    # 1): sqrt(2 * 4.5 / 2); at -2 t it hits m = 1 at rest, which leaves at 2 M u / (m + M), the piston at u / 3.
    sim = ds.EventDriven(ball(5.0, 0.5), BOX, piston=ds.Piston(mass=2.0, pressure=0.2, height=5.5), gravity=(0, -1))
    sim.run(until=0.5)
    assert sim.resting[0]
    event = sim.step()
    t = math.sqrt(4.5)
    assert (event.kind, event.time) == ("wall", pytest.approx(t, rel=1e-13))
    assert sim.velocities[0] == pytest.approx([0.0, 4.0 / 3.0 * -2.0 * t], rel=1e-13)
    assert sim.piston.velocity == pytest.approx(-2.0 * t / 3.0, rel=1e-13) and not sim.resting[0]


def test_under_gravity_a_gas_under_a_piston_keeps_its_energy_with_both_weights():
    discs, _ = ds.random_gas(30, 0.2, seed=9, periodic=False)
    box = ds.Box(discs.positions[:, 0].max() + 1.5, 150.0)
    top = float((discs.positions[:, 1] + discs.radii).max()) + 0.5
    g, piston = 0.05, ds.Piston(mass=6.0, pressure=0.2, height=top)
    sim = ds.EventDriven(discs, box, piston=piston, gravity=(0.0, -g))

    def total():
        p = sim.piston
        weights = g * float(np.sum(sim.discs.masses * sim.positions[:, 1]))
        return sim.kinetic_energy() + weights + 0.5 * p.mass * p.velocity**2 + (0.2 * box.width + 6.0 * g) * p.height

    e0 = total()
    sim.run(until=40.0)
    assert total() == pytest.approx(e0, rel=1e-11) and sim.piston.hits > 10
    sim._check()
    with pytest.raises(InvalidArgumentError, match="gravity"):
        ds.thermo(sim)
