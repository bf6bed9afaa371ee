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


def compress(discs, box, steps, duration, settle, mass=10.0):
    """Quadruple the pressure on a dilute gas in ``steps`` equal ratios over ``duration``: the averages before and
    after (each over ``settle`` time units, the first tenth skipped), and the energy ``K + M U^2 / 2 + P_f A`` the
    gas and piston hold from the moment the pressure first changes (conserved from then on for one step)."""
    kinetic = 0.5 * float(np.sum(discs.masses * np.sum(discs.velocities**2, axis=1)))
    p0 = ds.henderson_z(0.005) * kinetic / box.area
    piston = ds.Piston(mass=mass, pressure=p0, height=box.height)
    sim = ds.EventDriven(discs, ds.Box(box.width, 3 * box.height), piston=piston).run(until=settle)
    before = ds.thermo(sim, since=settle / 10)
    pressures = p0 * 4.0 ** (np.arange(1, steps + 1) / steps)
    now = sim.piston
    energy = sim.kinetic_energy() + 0.5 * mass * now.velocity**2 + pressures[-1] * box.width * now.height
    for p in pressures:
        sim.set_piston(pressure=p)
        sim.run(until=sim.time + duration / steps)
    end = sim.time
    sim.run(until=end + settle)
    return before, ds.thermo(sim, since=end + settle / 10), energy


def test_a_slow_compression_follows_the_adiabat_and_a_sudden_one_heats_more():
    discs, box = ds.random_gas(200, 0.005, seed=7, periodic=False)
    before, slow, _ = compress(discs, box, 400, 20000.0, 10000.0)
    # The adiabat of a 2D ideal gas: P A^2 = const, so at 4 P the area halves and kT doubles.
    assert slow.temperature / before.temperature == pytest.approx(2.0, rel=0.03)
    assert slow.area / before.area == pytest.approx(0.5, rel=0.04)
    assert slow.pressure * slow.area**2 / (before.pressure * before.area**2) == pytest.approx(1.0, rel=0.06)
    # At once: the final pressure P_f does the work P_f (A_i - A_f) on the gas, so (first law, ideal gas: P_f A_f =
    # N kT_f, K = N kT, the piston's kinetic energy kT / 2) N kT_f (2 + 1 / (2N)) = K_i + M U_i^2 / 2 + P_f A_i, from
    # the moment of the jump: on average over where the piston was then, kT_f = 2.5 kT_i and A_f = 0.625 A_i.
    before, sudden, energy = compress(discs, box, 1, 1.0, 20000.0)
    n = len(discs)
    assert sudden.temperature == pytest.approx(energy / (2 * n + 0.5), rel=0.02)
    assert sudden.temperature / before.temperature == pytest.approx(2.5, rel=0.08)
    assert sudden.area / before.area == pytest.approx(0.625, rel=0.08)
    assert sudden.temperature > 1.15 * slow.temperature
