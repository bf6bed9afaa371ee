"""random_gas(radii=...): species with fractions, one radius per disc, a size distribution; bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

import discsim as ds


def _packing(discs, box):
    return math.pi * float(np.sum(discs.radii**2)) / box.area


@pytest.mark.parametrize("periodic", [True, False])
def test_species_with_fractions(periodic):
    discs, box = ds.random_gas(101, 0.5, periodic=periodic, seed=3, radii=[1.0, 1.4], fractions=[0.3, 0.7])
    counts = np.bincount(discs.groups)
    assert counts.tolist() == [30, 71]
    np.testing.assert_array_equal(discs.radii, np.array([1.0, 1.4])[discs.groups])
    assert _packing(discs, box) == pytest.approx(0.5, rel=1e-12)
    assert discs.kinetic_energy() == pytest.approx(101.0)
    ds.EventDriven(discs, box)  # no overlaps, inside the box


def test_equal_shares_by_default_and_seeded():
    a, _ = ds.random_gas(100, 0.4, seed=1, radii=[1.0, 1.4])
    b, _ = ds.random_gas(100, 0.4, seed=1, radii=[1.0, 1.4])
    assert np.bincount(a.groups).tolist() == [50, 50]
    np.testing.assert_array_equal(a.positions, b.positions)


def test_one_radius_per_disc_and_a_distribution():
    radii = np.linspace(0.8, 1.2, 50)
    discs, box = ds.random_gas(50, 0.4, seed=1, radii=radii, periodic=False)
    np.testing.assert_array_equal(discs.radii, radii)
    ds.EventDriven(discs, box)
    discs, box = ds.random_gas(80, 0.4, seed=1, radii=lambda rng, n: rng.uniform(0.8, 1.2, n))
    assert 0.8 <= discs.radii.min() and discs.radii.max() <= 1.2 and len(set(discs.radii)) == 80
    assert _packing(discs, box) == pytest.approx(0.4, rel=1e-12)
    ds.EventDriven(discs, box)


def test_without_radii_nothing_changes():
    a, _ = ds.random_gas(100, 0.3, seed=1)
    assert set(a.radii) == {1.0} and set(a.groups) == {0}


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"radii": [1.0, -1.0]}, "-1.0"),
        ({"radii": [1.0, math.nan]}, "nan"),
        ({"radii": "big"}, "big"),
        ({"radii": [1.0, 1.4], "fractions": [0.5]}, "fractions"),
        ({"radii": [1.0, 1.4], "fractions": [0.0, 0.0]}, "fractions"),
        ({"radii": lambda rng, n: np.ones(3)}, "shape"),
    ],
)
def test_bad_radii_are_refused_by_name(kwargs, words):
    with pytest.raises(ds.InvalidArgumentError) as info:
        ds.random_gas(40, 0.3, seed=1, **kwargs)
    assert words in str(info.value)
