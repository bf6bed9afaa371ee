"""Long runs: invariants hold over 10^5 collisions; the pressure matches the hard-disc equation of state."""

import numpy as np
import pytest

import discsim as ds
from discsim.cells import neighbour_pairs


def _deepest_overlap(sim):
    pos, rad = sim.positions, sim.discs.radii
    i, j, d = neighbour_pairs(pos, 2 * rad.max(), sim.box)
    contact = rad[i] + rad[j]
    return float(np.max((contact - np.hypot(d[:, 0], d[:, 1])) / contact, initial=0.0))


@pytest.mark.slow
def test_hundred_thousand_collisions_at_packing_fraction_0_7():
    n = 1000
    discs, box = ds.random_gas(n, 0.7, seed=21)
    sim = ds.EventDriven(discs, box, record=False)
    e0, p0 = sim.kinetic_energy(), sim.momentum()
    deepest = 0.0
    while sim.counts["collisions"] < 100_000:
        sim.run(events=10_000)
        deepest = max(deepest, _deepest_overlap(sim))
        assert sim.queue_size <= n
    assert abs(sim.kinetic_energy() / e0 - 1) < 1e-12
    assert np.abs(sim.momentum() - p0).max() < 1e-9
    assert deepest < 1e-9
    assert sim.max_overlap < 1e-9
    assert sim.max_queue <= n  # one pending event per disc at most: O(N) over any horizon
    sim._check()


@pytest.mark.slow
@pytest.mark.parametrize("phi", [0.2, 0.3, 0.4, 0.5])
def test_pressure_matches_henderson_equation_of_state(phi):
    n = 2000
    discs, box = ds.random_gas(n, phi, seed=1)
    melted = ds.EventDriven(discs, box, record=False).run(events=20 * n)
    sim = ds.EventDriven(melted.snapshot(), box, record=False).run(events=50 * n)
    z = ds.compressibility_factor(sim)
    assert z == pytest.approx(float(ds.henderson_z(phi)), rel=0.01)


def test_ideal_gas_limit_of_the_pressure():
    # Very dilute: Z -> 1 (P A = N kT).
    discs, box = ds.random_gas(400, 0.01, seed=2)
    sim = ds.EventDriven(discs, box, record=False).run(events=20_000)
    assert ds.compressibility_factor(sim) == pytest.approx(float(ds.henderson_z(0.01)), rel=0.01)


@pytest.mark.slow
def test_collision_rate_matches_enskog():
    n, phi = 2000, 0.3
    discs, box = ds.random_gas(n, phi, seed=3)
    melted = ds.EventDriven(discs, box, record=False).run(events=20 * n)
    sim = ds.EventDriven(melted.snapshot(), box, record=False).run(events=30 * n)
    kT = sim.kinetic_energy() / n
    rate = 2 * sim.counts["collisions"] / (n * sim.time)
    assert rate == pytest.approx(float(ds.enskog_collision_rate(phi, radius=1.0, kT=kT)), rel=0.03)
