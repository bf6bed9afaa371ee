"""MSD, diffusion, VACF and free times against exact free flight, Enskog's dilute gas and the log itself."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import discsim as ds

finite = st.floats(-5.0, 5.0, allow_nan=False)


@settings(max_examples=50, deadline=None)
@given(
    v=arrays(np.float64, st.tuples(st.integers(1, 6), st.just(2)), elements=finite),
    steps=st.integers(2, 40),
    dt=st.floats(0.01, 3.0),
)
def test_msd_of_free_flight_is_v2_t2(v, steps, dt):
    t = dt * np.arange(steps)
    path = 3.0 + v[None, :, :] * t[:, None, None]
    m = ds.msd(path, t)
    expected = (v**2).sum(axis=1).mean() * m.lags**2
    assert np.allclose(m.msd, expected, rtol=1e-9, atol=1e-9 * (1 + expected.max()))


def test_msd_follows_a_disc_across_the_periodic_edges():
    discs = ds.Discs([[1.0, 1.0]], [[3.0, -1.25]], radii=0.5)
    sim = ds.EventDriven(discs, ds.Box(4.0, 4.0, periodic=True)).run(until=10.0)  # crosses the edges 9 times
    f = ds.frames(sim, np.arange(0.0, 10.01, 0.5))
    m = ds.msd(f.unwrapped, f.times)
    assert np.allclose(m.msd, (9.0 + 1.5625) * m.lags**2)
    assert np.allclose(ds.vacf(f.velocities, f.times).c, 10.5625)


def test_dilute_gas_diffuses_as_enskog_says():
    eta = 0.05
    sim = ds.EventDriven(*ds.random_gas(2000, eta, seed=3)).run(until=120.0)
    f = ds.frames(sim, np.arange(0.0, 120.01, 1.0))
    m = ds.msd(f.unwrapped, f.times)
    d_enskog = float(ds.enskog_diffusion(eta))  # 8.18 for discs of radius 1: mean free time 8.2
    assert m.diffusion((20.0, 60.0)) == pytest.approx(d_enskog, rel=0.1)
    c = ds.vacf(f.velocities, f.times)
    assert c.c[0] == pytest.approx(2.0)  # <|v|^2> = 2 kT / m
    assert c.normalized[0] == 1.0
    assert c.diffusion() == pytest.approx(d_enskog, rel=0.15)


def test_free_times_match_the_log_and_enskog():
    sim = ds.EventDriven(*ds.random_gas(500, 0.2, seed=4)).run(until=60.0)
    events = sim.events
    ft = ds.free_times(sim)
    collisions = events[events["kind"] == 0]
    involved = np.unique(np.concatenate([collisions["i"], collisions["j"]]))
    # each disc's k collisions bound k - 1 free times
    assert len(ft.times) == 2 * len(collisions) - len(involved)
    assert (ft.times >= 0).all()
    # one disc by hand
    mine = np.sort(collisions["time"][(collisions["i"] == 7) | (collisions["j"] == 7)])
    assert np.allclose(np.sort(ft.times[ft.discs == 7]), np.sort(np.diff(mine)))
    rate = float(ds.enskog_collision_rate(0.2))  # mean free time 0.98; the run is 60 of them
    assert ft.mean * rate == pytest.approx(1.0, rel=0.06)
    late = ds.free_times(sim, since=10.0)
    assert len(late.times) < len(ft.times)
    with_walls = ds.free_times(events, walls=True)
    assert len(with_walls.times) == len(ds.free_times(events).times)  # periodic: no walls
    density, edges = ft.histogram(20)
    assert np.sum(density * np.diff(edges)) == pytest.approx(1.0)


def test_free_times_with_walls_count_wall_hits():
    sim = ds.EventDriven(*ds.random_gas(100, 0.1, periodic=False, seed=2)).run(until=20.0)
    assert len(ds.free_times(sim, walls=True).times) > len(ds.free_times(sim).times)


def test_bad_series_and_windows():
    t = np.array([0.0, 1.0, 3.0])
    with pytest.raises(ds.InvalidArgumentError, match="evenly spaced"):
        ds.msd(np.zeros((3, 2, 2)), t)
    with pytest.raises(ds.InvalidArgumentError, match="shape"):
        ds.msd(np.zeros((3, 2)), np.arange(3.0))
    with pytest.raises(ds.InvalidArgumentError, match="times must have shape"):
        ds.vacf(np.zeros((3, 2, 2)), np.arange(4.0))
    m = ds.msd(np.zeros((4, 2, 2)), np.arange(4.0))
    with pytest.raises(ds.InvalidArgumentError, match="window"):
        m.diffusion((10.0, 20.0))
    sim = ds.EventDriven(*ds.random_gas(30, 0.3, seed=1), record=False).run(until=1.0)
    with pytest.raises(ds.InvalidArgumentError, match="record=False"):
        ds.free_times(sim)
    with pytest.raises(ds.InvalidArgumentError, match="free_times=True"):
        ds.free_times(ds.Sampler(1.0))


def test_plots_return_axes():
    import matplotlib.pyplot as plt

    t = np.arange(5.0)
    path = np.ones((5, 3, 2)) * t[:, None, None]
    assert ds.msd(path, t).plot() is not None
    assert ds.vacf(path, t).plot() is not None
    sim = ds.EventDriven(*ds.random_gas(100, 0.3, seed=1)).run(until=5.0)
    assert ds.free_times(sim).plot() is not None
    plt.close("all")
