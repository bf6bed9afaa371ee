"""The event-driven Z against an independent canonical Monte Carlo (benchmarks/canonical_mc.py) at small N.

An event-driven run in a periodic box samples the microcanonical ensemble at fixed momentum (2N - 2 degrees of
freedom); thermo() must give the canonical Z at every N (issue 29). At N = 20 the reading kT = K / N was
too high by (Z - 1) / (N - 1), about 0.15 here, many error bars; the canonical reading agrees with the
Monte Carlo, whose only tie to discsim is its starting lattice.
"""

from __future__ import annotations

import importlib.util
import math
import sys

import pytest
from paths import BENCHMARKS

import discsim as ds
from discsim._numba import available as numba_available


@pytest.fixture(scope="module")
def canonical_mc():
    spec = importlib.util.spec_from_file_location("canonical_mc", BENCHMARKS / "canonical_mc.py")
    module = importlib.util.module_from_spec(spec)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(sys.modules, "canonical_mc", module)
        spec.loader.exec_module(module)
        yield module


@pytest.mark.slow
@pytest.mark.skipif(not numba_available(), reason="the Monte Carlo is compiled by numba")
def test_event_driven_z_is_the_canonical_one_at_n_20(canonical_mc):
    n, packing = 20, 0.5
    mc = canonical_mc.canonical_z(n, packing, sweeps=200_000, warmup=5000, blocks=40, seed=3)
    md = canonical_mc.event_driven_z(n, packing, collisions_per_disc=60_000, seed=3)
    sigma = math.hypot(mc["z_err"], md["z_md_err"])
    assert mc["z_err"] < 0.03 and md["z_md_err"] < 0.02
    assert abs(md["z_md"] - mc["z"]) < 4 * sigma  # canonical: agrees
    assert md["z_naive"] - mc["z"] > 4 * math.hypot(mc["z_err"], md["z_naive_err"])  # kT = K / N: too high


@pytest.mark.slow  # (24 s: numba compiles the Monte Carlo)
def test_the_quick_mode_writes_its_csv(canonical_mc, tmp_path):
    if not numba_available():
        pytest.skip("the Monte Carlo is compiled by numba")
    assert canonical_mc.main(["--quick", "--results", str(tmp_path)]) == 0
    lines = (tmp_path / "canonical_mc_quick.csv").read_text().splitlines()
    assert lines[0].startswith("n,packing,z,z_err") and len(lines) == 2


@pytest.mark.slow  # (4 s)
def test_thermo_z_is_independent_of_the_reading_of_kt_at_large_n():
    # The correction is (Z - 1) / (N - 1): at N = 2000 it is below the error of a short run, as before.
    sim = ds.EventDriven(*ds.random_gas(2000, 0.3, seed=0)).run(until=4.0)
    t = ds.thermo(sim, since=2.0)
    assert t.temperature == pytest.approx(2000 / 1999, rel=1e-12)
    assert abs(t.z - ds.henderson_z(0.3)) < 4 * t.z_err + 0.01
