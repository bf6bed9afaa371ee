"""ds.EventChain (straight ECMC): exact sampling, no overlap, the pressure, both backends, runs and checkpoints."""

from __future__ import annotations

import math

import numpy as np
import pytest

import discsim as ds
from discsim import _numba
from discsim.cells import neighbour_pairs

needs_numba = pytest.mark.skipif(not _numba.available(), reason="numba is not installed or is hidden")
BACKENDS = ["python", pytest.param("numba", marks=needs_numba)]


def _min_gap(sim) -> float:
    """The smallest (distance / contact distance) over all pairs now."""
    pos, radii = sim.positions, sim.discs.radii
    i, j, d = neighbour_pairs(pos, 2.0 * float(radii.max()) * 1.01, sim.box)
    return float(np.min(np.hypot(d[:, 0], d[:, 1]) / (radii[i] + radii[j]))) if len(i) else math.inf


def _samples(sim, count, every=1):
    """The positions after every ``every`` chains, ``count`` times: ``(count, N, 2)``."""
    out = np.empty((count, len(sim.discs), 2))
    for k in range(count):
        sim.run(chains=every)
        out[k] = sim.positions
    return out


@pytest.mark.parametrize("backend", BACKENDS)
def test_two_discs_are_sampled_uniformly(backend):
    """Two discs of contact distance 1 in a periodic 3.2 x 3.2 box: their separation is uniform over the box
    less the disc of radius 1 (every configuration has the same weight), so P(|r| < rho) is
    pi (rho^2 - 1) / (L^2 - pi) for rho <= L / 2."""
    box = ds.Box(3.2, 3.2, periodic=True)
    sim = ds.EventChain(ds.Discs([[0.5, 0.5], [2.0, 2.0]], [[0, 0], [0, 0]], 0.5), box, seed=11, backend=backend)
    pos = _samples(sim, 12_000)
    r = box.minimum_image(pos[:, 1] - pos[:, 0])
    rho = np.hypot(r[:, 0], r[:, 1])
    assert rho.min() >= 1.0 - 1e-12
    free = box.area - math.pi
    for edge in (1.1, 1.25, 1.4, 1.55):
        p = math.pi * (edge**2 - 1.0) / free
        seen = np.mean(rho < edge)
        assert abs(seen - p) < 5.0 * math.sqrt(p * (1 - p) / len(rho)), (edge, seen, p)
    # and every direction alike: the quadrants of the separation
    quadrant = np.mean((r[:, 0] > 0) & (r[:, 1] > 0))
    assert abs(quadrant - 0.25) < 5.0 * math.sqrt(0.25 * 0.75 / len(rho))


def test_three_discs_are_sampled_as_rejection_sampling_samples_them():
    """Three discs of two sizes: the distribution of the closest pair's distance against an independent sampler
    (uniform positions, overlapping draws rejected), by their histograms."""
    box = ds.Box(3.5, 3.5, periodic=True)
    radii = np.array([0.5, 0.5, 0.3])
    discs = ds.Discs([[0.6, 0.6], [2.0, 0.7], [1.2, 2.4]], np.zeros((3, 2)), radii)
    sim = ds.EventChain(discs, box, seed=3, backend="python", chain_length=1.3)
    pos = _samples(sim, 10_000)

    def closest(p):
        best = np.full(len(p), np.inf)
        for a, b in ((0, 1), (0, 2), (1, 2)):
            d = box.minimum_image(p[:, b] - p[:, a])
            best = np.minimum(best, np.hypot(d[:, 0], d[:, 1]) - radii[a] - radii[b])
        return best

    rng = np.random.default_rng(5)
    draws = rng.uniform(0, 3.5, size=(200_000, 3, 2))
    gaps = closest(draws)
    reference = gaps[gaps >= 0.0]
    ours = closest(pos)
    assert ours.min() >= -1e-12
    edges = np.array([0.0, 0.1, 0.2, 0.4, 0.7, 2.0])
    expected = np.histogram(reference, edges)[0] / len(reference)
    seen = np.histogram(ours, edges)[0] / len(ours)
    sigma = np.sqrt(expected * (1 - expected) / len(ours))
    assert np.all(np.abs(seen - expected) < 5.0 * sigma + 0.003), (seen, expected)


@pytest.mark.parametrize("backend", BACKENDS)
def test_no_disc_ever_overlaps_and_the_discs_stay_in_the_box(backend):
    discs, box = ds.random_gas(300, 0.6, seed=2, radii=[0.5, 0.7])
    sim = ds.EventChain(discs, box, seed=4, backend=backend)
    for _ in range(5):
        sim.run(chains=400)
        assert _min_gap(sim) >= 1.0 - 1e-12
        assert ((sim.positions >= 0) & (sim.positions < box.size)).all()
    counts = sim.counts
    assert counts["chains"] == 2000 and counts["lifts"] > 2000 and counts["cell_crossings"] > 0
    moved = sim.unwrapped_positions - discs.positions
    np.testing.assert_allclose(box.wrap(sim.unwrapped_positions), sim.positions, atol=1e-9)
    assert (moved >= -1e-9).all()  # chains go along +x and +y only


@needs_numba
def test_both_backends_run_the_same_chains_bit_for_bit():
    discs, box = ds.random_gas(200, 0.6, seed=5, radii=[0.5, 0.6])
    a = ds.EventChain(discs, box, seed=9, backend="python").run(chains=3000)
    b = ds.EventChain(discs, box, seed=9, backend="numba").run(chains=3000)
    assert a.positions.tobytes() == b.positions.tobytes() and a.counts == b.counts
    assert a.compressibility_factor() == b.compressibility_factor()


def test_a_run_cut_into_calls_and_checkpoints_gives_the_same_chains(tmp_path):
    discs, box = ds.random_gas(120, 0.5, seed=6)
    whole = ds.EventChain(discs, box, seed=3, backend="python").run(chains=9000)
    cut = ds.EventChain(discs, box, seed=3, backend="python")
    for k in (1, 4095, 3, 1000):
        cut.run(chains=k)
    path = tmp_path / "ecmc.dsc"
    cut.run(chains=1900, checkpoint=path, checkpoint_every=700)
    loaded = ds.load(path)
    assert isinstance(loaded, ds.EventChain) and loaded.counts == cut.counts and loaded.seed == 3
    loaded.run(chains=2001)  # 9,000 in all
    assert loaded.positions.tobytes() == whole.positions.tobytes()
    assert loaded.compressibility_factor() == whole.compressibility_factor()
    assert ds.resume(path).counts["chains"] == 6999  # the checkpointed run asked for 1,900 and did them


def test_the_pressure_of_a_dilute_gas_is_the_virial_series():
    discs, box = ds.random_gas(200, 0.1, seed=8)
    sim = ds.EventChain(discs, box, seed=1, backend="auto").run(chains=20_000)
    assert sim.compressibility_factor() == pytest.approx(ds.virial_z(0.1), rel=0.01)
    assert sim.pressure() == pytest.approx(sim.compressibility_factor() * 200 / box.area)


@pytest.mark.slow
def test_the_pressure_of_a_dense_liquid_is_the_event_driven_one():
    discs, box = ds.random_gas(400, 0.6, seed=3)
    mc = ds.EventChain(discs, box, seed=2).run(chains=20_000)  # melt the lattice
    start = mc.counts, mc._state.separation
    mc.run(chains=200_000)
    z_mc = 1.0 + (mc._state.separation - start[1]) / ((mc.counts["chains"] - start[0]["chains"]) * mc.chain_length)
    md = ds.EventDriven(discs, box, record=True).run(until=20.0)
    z_md = ds.thermo(md, since=5.0).z
    assert z_mc == pytest.approx(z_md, rel=0.02)
    assert z_mc == pytest.approx(ds.henderson_z(0.6), rel=0.03)


@pytest.mark.slow
def test_the_structure_of_a_dense_liquid_is_the_event_driven_one():
    """g(r) of EventChain and EventDriven at N = 400, packing 0.6: the same canonical structure (both melted from
    the lattice, 30 frames each), bin by bin (a tenth of a diameter wide) to within 0.08 and the same contact
    value to 2% (halves of one run differ by about half that)."""
    discs, box = ds.random_gas(400, 0.6, seed=7)
    sigma = 2.0 * float(discs.radii[0])
    mc = ds.EventChain(discs, box, seed=5).run(chains=20_000)
    mc_frames = np.array([mc.run(chains=2_000).positions for _ in range(30)])
    md = ds.EventDriven(discs, box, record=False).run(until=10.0)
    md_frames = np.array([md.run(until=10.0 + 0.5 * (k + 1)).positions for k in range(30)])
    coarse = [ds.rdf(f, box, r_max=3.0 * sigma, dr=sigma / 10) for f in (mc_frames, md_frames)]
    assert np.max(np.abs(coarse[0].g - coarse[1].g)) < 0.08
    g_mc, g_md = (ds.rdf(f, box, r_max=3.0 * sigma, dr=sigma / 40) for f in (mc_frames, md_frames))
    assert g_mc.contact_value(sigma) == pytest.approx(g_md.contact_value(sigma), rel=0.02)


@pytest.mark.parametrize("backend", [pytest.param("python", marks=pytest.mark.slow), BACKENDS[1]])  # python: 12 s
def test_the_lift_log_holds_every_lift_and_changes_nothing(backend, tmp_path):
    discs, box = ds.random_gas(150, 0.7, seed=4)
    ell = 3.0 * box.width  # long chains: hundreds of lifts each, past the first batch's room (64): it runs again
    plain = ds.EventChain(discs, box, seed=6, backend=backend, chain_length=ell).run(chains=3000)
    logged = ds.EventChain(discs, box, seed=6, backend=backend, chain_length=ell, record_lifts=True)
    logged.run(chains=1000).run(chains=2000)
    assert logged.positions.tobytes() == plain.positions.tobytes() and logged.counts == plain.counts
    lifts = logged.lifts
    assert len(lifts) == logged.counts["lifts"] > 100 * 3000
    assert lifts["separation"].sum() == pytest.approx(logged.state().separation, rel=1e-12)
    assert np.all(np.diff(lifts["chain"]) >= 0) and np.array_equal(lifts["direction"], lifts["chain"] % 2)
    same = lifts["chain"][1:] == lifts["chain"][:-1]
    assert np.array_equal(lifts["i"][1:][same], lifts["j"][:-1][same])  # the disc that took over stops next
    assert np.all((lifts["separation"] > 0) & (lifts["separation"] <= 2.0 * discs.radii.max() + 1e-12))
    with pytest.raises(ds.InvalidArgumentError, match="record_lifts=True"):
        _ = plain.lifts
    path = tmp_path / "ecmc.dsc"
    logged.save(path)
    assert ds.load(path).lifts.tobytes() == lifts.tobytes()


@needs_numba
def test_both_backends_log_the_same_lifts():
    discs, box = ds.random_gas(100, 0.6, seed=2)
    a, b = (ds.EventChain(discs, box, seed=1, backend=k, record_lifts=True) for k in ("python", "numba"))
    a.run(chains=500), b.run(chains=500)
    assert a.lifts.tobytes() == b.lifts.tobytes()


@pytest.mark.parametrize(
    ("make", "words"),
    [
        (lambda d, b: ds.EventChain(d, ds.Box(b.width, b.height)), "periodic box only"),
        (lambda d, b: ds.EventChain(d, b, chain_length=0.0), "chain_length must be a positive, finite length"),
        (lambda d, b: ds.EventChain(d, b, chain_length=float("nan")), "chain_length"),
        (lambda d, b: ds.EventChain(d, b, seed=-1), "seed must be a non-negative integer"),
        (lambda d, b: ds.EventChain(d, b).run(until=3.0), "no physical time"),
        (lambda d, b: ds.EventChain(d, b).run(), "chains"),
        (lambda d, b: ds.EventChain(d, b).run(chains=3, record_to="x.dse"), "no event log"),
        (lambda d, b: ds.EventChain(d, b).set_positions([0], [[1.0, 1.0]]), "cannot set positions"),
        (lambda d, b: ds.EventChain(d, b).trajectory([0.0]), "cannot give trajectories"),
        (lambda d, b: ds.EventChain(d, b).compressibility_factor(), "at least one chain"),
    ],
)
def test_bad_input_is_refused_by_name(make, words):
    discs, box = ds.random_gas(30, 0.3, seed=1)
    with pytest.raises(ds.DiscsimError, match=words):
        make(discs, box)
