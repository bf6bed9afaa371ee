"""random_gas(..., start="random"): a disordered start by compression from a dilute random configuration,
beside the lattice (the default, unchanged)."""

from __future__ import annotations

import numpy as np
import pytest

import discsim as ds


@pytest.mark.parametrize("periodic", [True, False])
def test_a_random_start_is_disordered_at_the_packing_asked(periodic):
    discs, box = ds.random_gas(300, 0.6, periodic=periodic, seed=4, start="random")
    lattice, same_box = ds.random_gas(300, 0.6, periodic=periodic, seed=4)
    assert box == same_box and len(discs) == 300
    assert np.allclose(discs.radii, 1.0, rtol=1e-9, atol=0)
    assert ds.analysis.thermo.packing_fraction(discs.radii, box.area) == pytest.approx(0.6, rel=1e-8)
    assert discs.kinetic_energy() == pytest.approx(300.0, rel=1e-12)
    assert np.abs(discs.momentum()).max() < 1e-10
    assert ds.psi6(discs.positions, box).order < 0.2 < ds.psi6(lattice.positions, box).order  # no crystal
    sim = ds.EventDriven(discs, box).run(events=3000)  # no overlap: the engine accepts and runs it
    assert sim.max_overlap < 1e-9


def test_seeded_and_polydisperse():
    a, _ = ds.random_gas(120, 0.5, seed=7, start="random", radii=[1.0, 1.4])
    b, _ = ds.random_gas(120, 0.5, seed=7, start="random", radii=[1.0, 1.4])
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.velocities, b.velocities)
    assert set(np.round(a.radii / a.radii.min(), 9)) == {1.0, 1.4} and a.groups is not None
    dilute, _ = ds.random_gas(50, 0.05, seed=1, start="random")  # below the dilute packing: no compression
    assert np.array_equal(dilute.radii, np.ones(50))


def test_the_lattice_stays_the_default():
    a, box_a = ds.random_gas(100, 0.5, seed=3)
    b, box_b = ds.random_gas(100, 0.5, seed=3, start="lattice")
    assert box_a == box_b and np.array_equal(a.positions, b.positions) and np.array_equal(a.velocities, b.velocities)


@pytest.mark.parametrize("start", ["crystal", None, 1])
def test_an_unknown_start_is_refused_by_name(start):
    with pytest.raises(ds.InvalidArgumentError, match="start must be"):
        ds.random_gas(100, 0.5, start=start)
