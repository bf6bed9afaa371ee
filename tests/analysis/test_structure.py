"""g(r) and psi6 against numbers anyone can check: the ideal gas, a perfect triangular lattice, brute force,
and the pressure of an equilibrated hard-disc fluid (Z = 1 + 2 eta g(sigma+))."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds


def lattice(nx: int, ny: int, a: float = 1.0):
    """A perfect triangular lattice of spacing ``a`` filling a periodic box exactly (``ny`` even)."""
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    pos = np.column_stack([(i + 0.5 * (j % 2)).ravel() * a, j.ravel() * a * math.sqrt(3) / 2])
    return pos, ds.Box(nx * a, ny * a * math.sqrt(3) / 2, periodic=True)


def brute_distances(pos, box):
    d = box.minimum_image(pos[None, :, :] - pos[:, None, :])
    return np.sqrt((d**2).sum(-1))[np.triu_indices(len(pos), 1)]


@pytest.mark.parametrize("periodic", [True, False])
def test_ideal_gas_gives_one_everywhere(periodic):
    box = ds.Box(20.0, 12.0, periodic=periodic)
    points = np.random.default_rng(1).uniform([0, 0], [20, 12], size=(40, 500, 2))
    g = ds.rdf(points, box, r_max=6.0 if periodic else 11.5, dr=0.5)
    # 40 frames of 500 points: each bin holds thousands of pairs; 3% is several standard errors
    assert np.abs(g.g - 1.0).max() < 0.03
    assert g.frames == 40 and g.n == 500


@settings(max_examples=40, deadline=None)
@given(
    n=st.integers(2, 120),
    width=st.floats(4.0, 30.0),
    height=st.floats(4.0, 30.0),
    periodic=st.booleans(),
    seed=st.integers(0, 2**16),
)
def test_counts_equal_brute_force(n, width, height, periodic, seed):
    box = ds.Box(width, height, periodic=periodic)
    pos = np.random.default_rng(seed).uniform([0, 0], [width, height], size=(n, 2))
    r_max = 0.5 * min(width, height) * 0.99
    result = ds.rdf(pos, box, r_max=r_max, dr=r_max / 17)
    expected = np.histogram(brute_distances(pos, box), result.edges)[0]
    assert (result.counts == expected).all()


def test_pairs_within_a_block_at_a_time(monkeypatch):
    from discsim.analysis import structure

    monkeypatch.setattr(structure, "_PAIR_BLOCK", 50)  # many small blocks: the same pairs
    pos, box = lattice(12, 10)
    pos = pos + np.random.default_rng(2).normal(0, 0.1, pos.shape)
    pos = box.wrap(pos)
    result = ds.rdf(pos, box, r_max=4.0, dr=0.1)
    assert (result.counts == np.histogram(brute_distances(pos, box), result.edges)[0]).all()


def test_lattice_peaks_at_1_sqrt3_2():
    pos, box = lattice(20, 20)
    dr = 0.07  # the shells 1, sqrt(3), 2 fall inside bins, not on their edges
    g = ds.rdf(pos, box, r_max=2.5, dr=dr)
    shells = {1.0: 6, np.sqrt(3): 6, 2.0: 6}  # neighbours per disc at each distance
    expected = np.zeros_like(g.counts)
    for r, neighbours in shells.items():
        expected[int(r / dr)] = len(pos) * neighbours // 2
    assert (g.counts == expected).all()  # every pair at a lattice distance, and nothing between
    assert set(np.flatnonzero(g.g).tolist()) == {int(r / dr) for r in shells}


def test_psi6_of_a_perfect_lattice_is_one():
    pos, box = lattice(16, 12, a=2.0)
    p = ds.psi6(pos, box)
    assert p.order == pytest.approx(1.0, abs=1e-12)
    assert np.allclose(np.abs(p.local), 1.0) and (p.counts == 6).all()
    by_cutoff = ds.psi6(pos, box, cutoff=2.5)
    assert by_cutoff.order == pytest.approx(1.0, abs=1e-12) and (by_cutoff.counts == 6).all()
    # rotated by 5 degrees: |psi6| stays 1, its phase turns by 30 degrees
    turn = math.radians(5.0)
    rot = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    walled = ds.Box(200.0, 200.0)
    centre = pos.mean(axis=0)
    turned = (pos - centre) @ rot.T + 100.0
    inner = ds.psi6(turned, walled)
    deep = np.linalg.norm(turned - 100.0, axis=1) < 8.0  # discs with their whole first shell
    assert np.allclose(inner.local[deep], np.exp(6j * turn))


def test_psi6_of_a_fluid_is_small_and_frames_stack():
    sim = ds.EventDriven(*ds.random_gas(400, 0.4, seed=3)).run(until=8.0)
    f = ds.frames(sim, [6.0, 7.0, 8.0])
    p = ds.psi6(f.positions, f.box)
    assert p.local.shape == (3, 400) and p.order.shape == (3,)
    assert (p.order < 0.2).all()  # a fluid: about 1 / sqrt(N) = 0.05
    assert p.order[0] == pytest.approx(ds.psi6(f.positions[0], f.box).order)


@pytest.fixture(scope="module")
def fluid():
    """An equilibrated hard-disc fluid at packing 0.5 (radius 1): the run, and 41 frames after the lattice melted."""
    sim = ds.EventDriven(*ds.random_gas(1000, 0.5, seed=5)).run(until=24.0)
    return sim, ds.frames(sim, np.arange(4.0, 24.01, 0.5))


def test_contact_value_gives_the_pressure(fluid):
    """Z = 1 + 2 eta g(sigma+) against the run's own virial pressure and Henderson's equation of state."""
    eta, radius = 0.5, 1.0
    sim, f = fluid
    g = ds.rdf(f.positions, f.box, r_max=4.0, dr=0.02)
    contact = g.contact_value(2.0 * radius)
    z_structure = 1.0 + 2.0 * eta * contact
    z_virial = ds.thermo(sim, since=4.0)
    assert z_structure == pytest.approx(z_virial.z, rel=0.02)
    assert z_structure == pytest.approx(float(ds.henderson_z(eta)), rel=0.02)
    assert ds.compressibility_factor(sim, since=4.0) == pytest.approx(z_virial.z)
    assert g.g[g.r < 2.0].max() == 0.0  # hard discs never overlap


@pytest.mark.parametrize("radii", [0.0, 1.0])
def test_the_default_bins_give_the_contact_value(fluid, radii):
    """``ds.rdf(positions, box).contact_value(sigma)`` works as it stands (the default bins were sigma / 8 wide
    and held 2 bins in the fit window), and agrees with fine bins chosen by hand."""
    _, f = fluid
    by_hand = ds.rdf(f.positions, f.box, r_max=4.0, dr=0.02).contact_value(2.0)
    default = ds.rdf(f.positions, f.box, radii=radii)
    assert default.contact_value(2.0) == pytest.approx(by_hand, rel=0.01)
    if radii:  # the disc size given: the contact distance on a bin edge
        assert np.isclose(default.edges, 2.0, rtol=1e-12).any()


@pytest.mark.parametrize("periodic", [True, False])
def test_the_defaults_at_ten_thousand_discs(periodic):
    """N = 10^4 at the density of discs of radius 1 at packing 0.5: the default bins give the contact value
    (an ideal gas: 1), and the default r_max is a few spacings, so the pairs counted (and the time) stay near
    40 a disc per frame (10 spacings counted 157: 9.5 s for 11 frames)."""
    n, sigma = 10_000, 2.0
    side = math.sqrt(n * math.pi / 0.5)
    box = ds.Box(side, side, periodic=periodic)
    points = np.random.default_rng(4).uniform(0, side, size=(3, n, 2))
    g = ds.rdf(points, box)
    assert g.contact_value(sigma) == pytest.approx(1.0, abs=0.1)
    spacing = math.sqrt(box.area / n)
    assert g.edges[-1] <= 5.0 * spacing * (1 + 1e-12)
    assert g.counts.sum() < 40 * n * 3


def test_contact_value_needs_bins_in_the_window():
    pos, box = lattice(10, 10)
    g = ds.rdf(pos, box, r_max=3.0, dr=0.5)
    with pytest.raises(ds.InvalidArgumentError, match="bin"):
        g.contact_value(1.0)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"dr": 6.0}, "larger than half the box"),
        ({"dr": 0.0}, "dr must be a positive"),
        ({"r_max": 5.5}, "beyond half the shorter side"),
        ({"r_max": float("nan")}, "r_max must be a positive"),
    ],
)
def test_rdf_refuses_bad_bins(kwargs, match):
    box = ds.Box(10.0, 12.0, periodic=True)
    pos = np.random.default_rng(0).uniform(0, 10, (20, 2))
    with pytest.raises(ds.InvalidArgumentError, match=match):
        ds.rdf(pos, box, **kwargs)


def test_bad_positions_and_neighbour_counts():
    box = ds.Box(10.0, 10.0, periodic=True)
    with pytest.raises(ds.InvalidArgumentError, match="shape"):
        ds.rdf(np.zeros((5, 3)), box)
    with pytest.raises(ds.InvalidArgumentError, match="two discs"):
        ds.rdf(np.zeros((1, 2)), box)
    with pytest.raises(ds.InvalidArgumentError, match="finite"):
        ds.psi6([[1.0, 1.0], [np.nan, 2.0]], box)
    with pytest.raises(ds.InvalidArgumentError, match="k must be"):
        ds.psi6(np.random.default_rng(0).uniform(0, 10, (5, 2)), box, k=5)
    with pytest.raises(ds.InvalidArgumentError, match="Box"):
        ds.rdf(np.zeros((3, 2)), (10, 10))


def test_plots_return_axes():
    import matplotlib.pyplot as plt

    pos, box = lattice(8, 8)
    assert ds.rdf(pos, box, r_max=3.0, dr=0.1).plot() is not None
    _, ax = plt.subplots()
    assert ds.psi6(pos, box).plot(ax) is ax
    plt.close("all")
