"""Correlation time and the start of equilibrium (discsim.analysis.equilibration), and thermo()'s use of them:
error bars from the statistical inefficiency, since="auto" (Chodera 2016) and ds.EquilibrationWarning."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import discsim as ds
from discsim.analysis.equilibration import (
    detect_equilibration,
    geweke_score,
    statistical_inefficiency,
    trend_score,
)
from discsim.analysis.thermo import VirialBlocks


def ar1(rng: np.random.Generator, t: int, phi: float) -> np.ndarray:
    """A stationary AR(1) series of unit innovations: g = (1 + phi) / (1 - phi) exactly (for T -> inf)."""
    e = rng.normal(size=t)
    x = np.empty(t)
    x[0] = e[0] / math.sqrt(1 - phi * phi)
    for i in range(1, t):
        x[i] = phi * x[i - 1] + e[i]
    return x


@pytest.mark.parametrize("phi", [0.0, 0.5, 0.8])
def test_the_inefficiency_of_an_ar1_series(phi):
    rng = np.random.default_rng(1)
    g = np.mean([statistical_inefficiency(ar1(rng, 20_000, phi)) for _ in range(4)])
    assert g == pytest.approx((1 + phi) / (1 - phi), rel=0.1)


def test_exact_small_cases():
    assert statistical_inefficiency(np.ones(50)) == 1.0  # constant: nothing to correlate
    assert statistical_inefficiency([3.0]) == 1.0
    # Blocks of k equal values of a white series: each block is one sample, g -> k (here 1 + 2 sum (1 - t/k)).
    rng = np.random.default_rng(0)
    g = statistical_inefficiency(np.repeat(rng.normal(size=4000), 8))
    assert g == pytest.approx(8.0, rel=0.05)
    # The sum stops at the first non-positive autocorrelation beyond lag 3: alternating signs give g = 1.
    assert statistical_inefficiency(np.tile([1.0, -1.0], 100)) == 1.0


def test_the_start_of_a_decaying_transient_is_found():
    rng = np.random.default_rng(2)
    hits = []
    for _ in range(5):
        x = ar1(rng, 2000, 0.5) + 6.0 * np.exp(-np.arange(2000) / 100.0)
        found = detect_equilibration(x, nskip=5)
        hits.append(found.t0)
        assert found.n_eff > found.n_eff_all  # skipping the transient buys independent samples
    assert 150 < np.median(hits) < 600  # e-folds of 100 samples: the transient is below noise after 2-5
    stationary = [detect_equilibration(ar1(rng, 1000, 0.5), nskip=5).t0 for _ in range(10)]
    assert np.median(stationary) < 100


def test_geweke_tells_drift_from_noise():
    rng = np.random.default_rng(3)
    scores = [abs(geweke_score(ar1(rng, 1000, 0.5))) for _ in range(50)]
    assert np.mean(np.array(scores) > 3) <= 0.04  # about normal at equilibrium
    assert abs(geweke_score(ar1(rng, 1000, 0.5) + np.linspace(2.0, 0.0, 1000))) > 5


def test_the_trend_score_tells_a_slow_drift_from_correlated_noise():
    rng = np.random.default_rng(8)
    scores = np.array([trend_score(ar1(rng, 64, 0.7)) for _ in range(200)])
    assert np.mean(np.abs(scores) > 5) < 0.02 and 0.5 < np.std(scores) < 2.0  # about normal at equilibrium
    # A structure relaxing slowly: a small steady fall under small noise, as psi6 of a melting lattice.
    assert trend_score(np.linspace(0.70, 0.64, 64) + 0.003 * rng.normal(size=64)) < -5
    assert trend_score([1.0, 2.0]) == 0.0 and trend_score(np.arange(10.0)) == 0.0  # too short; no scatter


def test_pymbar_agrees():
    timeseries = pytest.importorskip("pymbar.timeseries")
    rng = np.random.default_rng(4)
    for _ in range(3):
        x = ar1(rng, 600, 0.9)
        x[:100] += np.linspace(8.0, 0.0, 100)
        assert statistical_inefficiency(x) == pytest.approx(timeseries.statistical_inefficiency(x, fast=False))
        t0, g, n_eff = timeseries.detect_equilibration(x, fast=False)
        found = detect_equilibration(x)
        assert found.t0 == t0 and found.g == pytest.approx(g, rel=1e-5) and found.n_eff == pytest.approx(n_eff, 1e-5)


def blocks_of(z: np.ndarray) -> VirialBlocks:
    """A VirialBlocks whose blocks (width 1) give the series ``z`` (100 discs at kT = 1, 50 collisions each)."""
    _, box = ds.random_gas(100, 0.3, seed=1)
    fine = VirialBlocks(0.0, 1.0, np.ones(100), box, 100.0, temperature=1.0)
    fine.virial = (z - 1.0) * 2.0 * 100 * 1.0  # Z = 1 + W / (2 t N kT), t = 1
    fine.collisions = np.full(len(z), 50, dtype=np.int64)
    fine.end = float(len(z))
    return fine


def test_thermo_error_bars_follow_the_correlation_time():
    rng = np.random.default_rng(5)
    phi, t = 0.9, 1000
    errors, means = [], []
    for _ in range(40):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ds.EquilibrationWarning)
            averages = ds.thermo(blocks_of(5.0 + 0.1 * ar1(rng, t, phi)))
        errors.append(averages.z_err)
        means.append(averages.z)
        assert averages.method == "statistical inefficiency" and averages.blocks == t
    exact = 0.1 * math.sqrt((1 + phi) / (1 - phi) / (1 - phi * phi) / t)  # the standard error of the mean
    assert np.median(errors) == pytest.approx(exact, rel=0.2)
    assert np.std(means) == pytest.approx(exact, rel=0.3)  # and the means scatter by that much
    # Ten fixed batches of 100 samples give about the same here; with g = 19 they are independent enough.
    batched = ds.thermo(blocks_of(5.0 + 0.1 * ar1(rng, t, phi)), blocks=10)
    assert batched.method == "batch means" and batched.blocks == 10


def test_thermo_warns_on_a_drift_and_since_auto_skips_it():
    rng = np.random.default_rng(6)
    z = 5.0 + 0.1 * ar1(rng, 1000, 0.5) - 0.8 * np.exp(-np.arange(1000) / 150.0)  # climbing from 4.2 to 5
    with pytest.warns(ds.EquilibrationWarning, match="still drifts.*since='auto'"):
        early = ds.thermo(blocks_of(z), since=0.0)
    assert early.drifting and early.geweke < -3 and early.z < 4.95
    with warnings.catch_warnings():
        warnings.simplefilter("error", ds.EquilibrationWarning)  # the production part is at equilibrium
        auto = ds.thermo(blocks_of(z), since="auto")
    assert not auto.drifting and auto.since == auto.equilibrium_start == early.equilibrium_start > 200
    assert abs(auto.z - 5.0) < 4 * auto.z_err + 0.01
    sim = ds.EventDriven(*ds.random_gas(50, 0.3, seed=1)).run(until=4.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ds.EquilibrationWarning)  # Z settles at once, the lattice's psi6 does not
        assert ds.compressibility_factor(sim, since="auto") == ds.thermo(sim, since="auto").z > 1


def test_thermo_warns_when_too_short_to_tell():
    rng = np.random.default_rng(7)
    z = 5.0 + 0.1 * ar1(rng, 200, 0.99)  # a correlation time of 200 samples in 200 samples
    with pytest.warns(ds.EquilibrationWarning, match="independent samples"):
        ds.thermo(blocks_of(z))


def test_bad_since_names_auto():
    sim = ds.EventDriven(*ds.random_gas(50, 0.3, seed=1)).run(until=2.0)
    with pytest.raises(ds.TimeError, match='"auto"'):
        ds.thermo(sim, since="later")
    with pytest.raises(ds.InvalidArgumentError, match="blocks must be None or an integer"):
        ds.thermo(sim, blocks=0)


@pytest.mark.slow
def test_the_readme_pattern_at_packing_070_warns():
    # Issue 29: 100 collisions per disc from the lattice at 0.70, averaged from T / 4. Z looks steady (its drift is
    # below a block's noise) but psi6 is still falling from the lattice's: thermo must say so. (N = 2,500 here,
    # 10,000 in benchmarks/equilibration.py, where the since="auto" average warns too.)
    discs, box = ds.random_gas(2500, 0.70, seed=0)
    sim = ds.EventDriven(discs, box).run(events=125_000)
    with pytest.warns(ds.EquilibrationWarning, match="the structure still relaxes"):
        averages = ds.thermo(sim, since=sim.time / 4)
    assert averages.drifting and averages.order[0] > averages.order[-1] > 0.4
