"""A piston's physics against closed forms and against the fixed-volume run (issue 28, item 2): the equation of state
sampled at fixed pressure agrees with the one at fixed volume; a slow compression of a dilute elastic gas follows the
adiabat P A^2 = const (2D, gamma = 2) and a sudden one heats more, as the first law says for a constant external
pressure."""

import math

import numpy as np
import pytest

import discsim as ds

pytestmark = pytest.mark.slow


def top_wall_z(sim, since):
    """``Z = P A / K`` at fixed volume, ``P`` the momentum the discs give the box's top wall per unit time and
    length (every top-wall bounce gives ``2 m |vy|``), with a batch-means error bar."""
    ev = sim.events
    r, height = sim.discs.radii, sim.box.height
    top = (ev["kind"] == int(ds.EventKind.WALL)) & (ev["yi"] > height - r[ev["i"]] - 1e-9) & (ev["vyi"] < 0)
    hits = ev[top & (ev["time"] > since)]
    impulse = 2.0 * np.abs(hits["vyi"]) * sim.discs.masses[hits["i"]]
    edges = np.linspace(since, sim.time, 41)
    per_block = np.bincount(np.searchsorted(edges, hits["time"]) - 1, weights=impulse, minlength=40)[:40]
    scale = height / sim.kinetic_energy()  # Z = P w H / K with P = impulse / (w dt)
    z_blocks = per_block / np.diff(edges) * scale
    return impulse.sum() / (sim.time - since) * scale, z_blocks.std(ddof=1) / math.sqrt(len(z_blocks))


def test_the_equation_of_state_at_fixed_pressure_is_the_one_at_fixed_volume():
    # 100 discs at packing about 0.34: the piston's run gives <A>; the box of that area, its top wall fixed, gives
    # the pressure on it. Both count the whole box's area (walls and all), so both Z carry the same surface term.
    discs, box = ds.random_gas(100, 0.35, seed=5, periodic=False)
    pressure = 0.2677
    piston = ds.Piston(mass=25.0, pressure=pressure, height=box.height)
    at_p = ds.EventDriven(discs, ds.Box(box.width, 4 * box.height), piston=piston).run(until=3000.0)
    averages = ds.thermo(at_p, since=20.0)
    at_v = ds.EventDriven(discs, ds.Box(box.width, averages.area / box.width)).run(until=3000.0)
    z_v, z_v_err = top_wall_z(at_v, 20.0)
    assert averages.z == pytest.approx(z_v, abs=3.0 * math.hypot(averages.z_err, z_v_err))
    assert averages.z_err < 0.03 and z_v_err < 0.02


def compress(discs, box, steps, duration, mass=10.0):
    """Quadruple the pressure on a dilute gas in ``steps`` equal ratios over ``duration``; the averages before and
    after (each over 3,000 time units, the first 100 skipped)."""
    kinetic = 0.5 * float(np.sum(discs.masses * np.sum(discs.velocities**2, axis=1)))
    p0 = ds.henderson_z(0.005) * kinetic / box.area
    piston = ds.Piston(mass=mass, pressure=p0, height=box.height)
    sim = ds.EventDriven(discs, ds.Box(box.width, 3 * box.height), piston=piston).run(until=3000.0)
    before = ds.thermo(sim, since=100.0)
    for p in p0 * 4.0 ** (np.arange(1, steps + 1) / steps):
        sim.set_piston(pressure=p)
        sim.run(until=sim.time + duration / steps)
    end = sim.time
    sim.run(until=end + 3000.0)
    return before, ds.thermo(sim, since=end + 100.0)


def test_a_slow_compression_follows_the_adiabat_and_a_sudden_one_heats_more():
    discs, box = ds.random_gas(200, 0.005, seed=7, periodic=False)
    before, slow = compress(discs, box, 400, 20000.0)
    # The adiabat of a 2D ideal gas: P A^2 = const, so at 4 P the area halves and kT doubles.
    assert slow.temperature / before.temperature == pytest.approx(2.0, rel=0.05)
    assert slow.area / before.area == pytest.approx(0.5, rel=0.05)
    assert slow.pressure * slow.area**2 / (before.pressure * before.area**2) == pytest.approx(1.0, rel=0.08)
    # At once: the first law with the constant external pressure P_f, N kT_f - N kT_i = P_f (A_i - A_f) and
    # P_f A_f = N kT_f, gives kT_f = kT_i (1 + P_f / P_i) / 2 = 2.5 kT_i and A_f = 0.625 A_i: more heat, less squeeze.
    before, sudden = compress(discs, box, 1, 1.0)
    assert sudden.temperature / before.temperature == pytest.approx(2.5, rel=0.05)
    assert sudden.area / before.area == pytest.approx(0.625, rel=0.05)
    assert sudden.temperature > 1.15 * slow.temperature
