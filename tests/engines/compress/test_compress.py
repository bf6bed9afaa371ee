"""ds.compress (Lubachevsky-Stillinger): time of impact, bookkeeping, no overlaps, targets, jams, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds
from discsim import _numba
from discsim.engines.compress import DENSEST_PACKING, engine, loop
from discsim.scene import check_fits

needs_numba = pytest.mark.skipif(not _numba.available(), reason="numba is not installed or is hidden")
BACKENDS = ["python", pytest.param("numba", marks=needs_numba)]


def _brute_force(dx, dy, dvx, dvy, s, sp, horizon):
    """The first t in [0, horizon] with |dr + dv t| = s + sp t, by a fine scan and bisection (inf if none)."""

    def f(t):
        return math.hypot(dx + dvx * t, dy + dvy * t) - (s + sp * t)

    ts = np.linspace(0.0, horizon, 20001)
    values = np.hypot(dx + dvx * ts, dy + dvy * ts) - (s + sp * ts)
    below = np.flatnonzero(values <= 0.0)
    if len(below) == 0:
        return math.inf
    k = below[0]
    if k == 0:
        return 0.0
    lo, hi = ts[k - 1], ts[k]
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) > 0 else (lo, mid)
    return hi


coord = st.floats(-10.0, 10.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(dx=coord, dy=coord, dvx=coord, dvy=coord, s=st.floats(0.1, 3.0), sp=st.floats(0.0, 2.0))
def test_growing_time_of_impact_matches_a_brute_force_root(dx, dy, dvx, dvy, s, sp):
    if math.hypot(dx, dy) < s * (1 + 1e-6):
        return  # the kernel's input: discs apart
    horizon = 50.0
    t = loop.growing_time_of_impact(dx, dy, dvx, dvy, s, sp)
    truth = _brute_force(dx, dy, dvx, dvy, s, sp, horizon)
    if truth == math.inf:  # no crossing; the kernel may still find a tangent touch the scan stepped over
        if t < horizon * (1 - 1e-3):
            assert math.hypot(dx + dvx * t, dy + dvy * t) == pytest.approx(s + sp * t, rel=1e-6)
    else:
        assert t == pytest.approx(truth, rel=1e-6, abs=1e-6)
        assert math.hypot(dx + dvx * t, dy + dvy * t) == pytest.approx(s + sp * t, rel=1e-9)


@needs_numba
def test_the_compiled_time_of_impact_is_the_same_function():
    from discsim.engines.compress import compiled

    rng = np.random.default_rng(3)
    for args in rng.uniform(-5, 5, size=(200, 6)):
        args[4], args[5] = abs(args[4]), abs(args[5])
        assert compiled.growing_time_of_impact(*args) == loop.growing_time_of_impact(*args)


def test_a_head_on_pair_separates_faster_than_it_grows():
    # two discs of radius 1 at distance 4, closing at 2 (each at 1), contact distance growing at sp = 2 g
    positions = np.array([[8.0, 10.0], [12.0, 10.0]])
    velocities = np.array([[1.0, 0.0], [-1.0, 0.0]])
    g = 0.1
    box = ds.Box(20.0, 20.0, periodic=True)
    _, vel, t, stats = engine.epoch(positions, velocities, np.ones(2), np.ones(2), box, (3, 3), g, 1.0, 1, "python")
    assert stats["collisions"] == 1
    contact = 2.0 / (2.0 + 2.0 * g)  # 4 - 2 t = 2 (1 + g t)
    assert t == pytest.approx(contact, rel=1e-12)
    sp = 2.0 * g
    assert vel[1, 0] - vel[0, 0] == pytest.approx(2 * sp + 2.0, rel=1e-12)  # vn' = 2 sp - vn, vn = -2
    assert vel.sum(axis=0) == pytest.approx([0.0, 0.0], abs=1e-15)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("periodic", [pytest.param(True, marks=pytest.mark.slow), False])  # periodic: 3 s
def test_bookkeeping_and_no_overlaps_along_the_way(backend, periodic):
    discs, box = ds.random_gas(120, 0.5, periodic=periodic, seed=2, radii=[1.0, 1.4])
    pos, vel, radii, masses = discs.positions, discs.velocities, discs.radii.copy(), discs.masses
    shape = (3, 3) if periodic else (4, 4)
    for _ in range(30):
        p0 = vel.sum(axis=0)
        e0 = 0.5 * float(np.sum(vel**2))
        g = 0.05
        pos, vel, t, _ = engine.epoch(pos, vel, radii, masses, box, shape, g, 1e9, 200, backend)
        radii = radii * (1.0 + g * t)
        if periodic:
            pos = box.wrap(pos)
            assert vel.sum(axis=0) == pytest.approx(p0, abs=1e-9)  # pair impulses conserve momentum
        assert 0.5 * float(np.sum(vel**2)) >= e0  # each collision adds energy: 2 mu (sp - vn) sp > 0
        check_fits(ds.Discs(pos, vel, radii), box, tolerance=1e-9)  # never an overlap
        vel = vel * math.sqrt(e0 / (0.5 * float(np.sum(vel**2))))
    assert math.pi * float(np.sum(radii**2)) / box.area > 0.6


def test_both_backends_give_the_same_compression():
    if not _numba.available():
        pytest.skip("numba is not installed or is hidden")
    gas, box = ds.random_gas(100, 0.3, seed=1)
    a, ra = ds.compress(gas, box, 0.6, backend="python")
    b, rb = ds.compress(gas, box, 0.6, backend="numba")
    assert ra.collisions == rb.collisions
    np.testing.assert_array_equal(a.positions, b.positions)


@pytest.mark.parametrize("periodic", [True, False])
def test_monodisperse_reaches_085(periodic):
    n = 200 if periodic else 500
    if not periodic and not _numba.available():
        pytest.skip("260,000 collisions: numba only (about 17 s in pure Python)")
    gas, box = ds.random_gas(n, 0.3, periodic=periodic, seed=1)
    dense, report = ds.compress(gas, box, packing_fraction=0.85, growth_rate=0.01)
    assert report.reached and not report.jammed and report.reason == "reached"
    assert report.packing_fraction == pytest.approx(0.85, rel=1e-9)
    assert 0 < report.collisions_to(0.8, n) < report.collisions_to(0.85, n) <= report.collisions / n
    ds.EventDriven(dense, box)  # passes the engine's validation
    np.testing.assert_array_equal(dense.masses, gas.masses)
    assert dense.kinetic_energy() == pytest.approx(n, rel=1e-12)  # kT = 1


@pytest.mark.parametrize("periodic", [True, False])
def test_a_binary_mixture_reaches_080(periodic):
    gas, box = ds.random_gas(300, 0.5, periodic=periodic, seed=1, radii=[1.0, 1.4], fractions=[0.5, 0.5])
    dense, report = ds.compress(gas, box, packing_fraction=0.80, growth_rate=0.01)
    assert report.reached, report
    assert report.packing_fraction == pytest.approx(0.80, rel=1e-9)
    assert sorted(set(np.round(dense.radii / dense.radii.min(), 9))) == [1.0, 1.4]  # the ratio stays
    ds.EventDriven(dense, box)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_jam_stops_and_says_so(backend):
    gas, box = ds.random_gas(150, 0.5, periodic=False, seed=1, radii=[1.0, 1.4])
    dense, report = ds.compress(gas, box, packing_fraction=0.9, growth_rate=0.1, backend=backend)
    assert report.jammed and not report.reached and report.reason == "jammed"
    assert 0.75 < report.packing_fraction < 0.9
    assert report.z > 1e5
    assert "JAMMED" in str(report)
    ds.EventDriven(dense, box)  # still a valid start


def test_the_collision_budget_stops_the_run():
    gas, box = ds.random_gas(100, 0.3, seed=1)
    dense, report = ds.compress(gas, box, 0.8, max_collisions=1000, backend="python")
    assert report.reason == "max_collisions" and report.collisions == 1000 and not report.jammed
    assert 0.3 < report.packing_fraction < 0.8
    ds.EventDriven(dense, box)


def test_progress_bar_runs(capsys):
    gas, box = ds.random_gas(50, 0.3, seed=1, periodic=False)
    _, report = ds.compress(gas, box, 0.5, progress=True, backend="python")
    assert report.reached


def test_seed_draws_new_velocities():
    gas, box = ds.random_gas(60, 0.3, seed=1)
    a, _ = ds.compress(gas, box, 0.4, seed=5, backend="python")
    b, _ = ds.compress(gas, box, 0.4, seed=5, backend="python")
    np.testing.assert_array_equal(a.positions, b.positions)
    assert a.kinetic_energy() == pytest.approx(60.0)


@pytest.mark.parametrize(
    ("kwargs", "error", "words"),
    [
        ({"packing_fraction": 0.91}, ds.PackingError, "0.91"),
        ({"packing_fraction": DENSEST_PACKING}, ds.PackingError, "pi / (2 sqrt 3)"),
        ({"packing_fraction": float("nan")}, ds.PackingError, "nan"),
        ({"packing_fraction": 0.2}, ds.PackingError, "0.2"),
        ({"packing_fraction": "0.8"}, ds.PackingError, "'0.8'"),
        ({"packing_fraction": 0.8, "growth_rate": 0.0}, ds.InvalidArgumentError, "growth_rate"),
        ({"packing_fraction": 0.8, "growth_rate": -1.0}, ds.InvalidArgumentError, "-1.0"),
        ({"packing_fraction": 0.8, "growth_rate": math.inf}, ds.InvalidArgumentError, "inf"),
        ({"packing_fraction": 0.8, "growth_rate": math.nan}, ds.InvalidArgumentError, "nan"),
        ({"packing_fraction": 0.8, "temperature": 0}, ds.InvalidArgumentError, "temperature"),
        ({"packing_fraction": 0.8, "max_collisions": 0}, ds.InvalidArgumentError, "max_collisions"),
        ({"packing_fraction": 0.8, "backend": "gpu"}, ds.InvalidArgumentError, "gpu"),
    ],
)
def test_bad_input_is_refused_by_name(kwargs, error, words):
    gas, box = ds.random_gas(60, 0.3, seed=1)
    with pytest.raises(error, match=None) as info:
        ds.compress(gas, box, **kwargs)
    assert words in str(info.value)
    assert isinstance(info.value, ds.DiscsimError)


def test_bad_discs_are_refused():
    box = ds.Box(10.0, 10.0)
    with pytest.raises(ds.InvalidArgumentError, match="mass"):
        ds.compress(ds.Discs([[2, 2], [6, 6]], [[1, 0], [0, 0]], 1.0, [1.0, np.inf]), box, 0.5)
    with pytest.raises(ds.OverlapError):
        ds.compress(ds.Discs([[2, 2], [2.5, 2]], [[1, 0], [0, 0]], 1.0), box, 0.5)
    with pytest.raises(ds.WrongTypeError):
        ds.compress("discs", box, 0.5)
    with pytest.raises(ds.BoxTooSmallError):  # a periodic box under 3 final diameters
        ds.compress(ds.Discs([[2, 2]], [[1, 0]], 0.5), ds.Box(10.0, 10.0, periodic=True), 0.8)
