"""thermo(): the virial from the log equals the engine's own, the canonical Z at kT = K / (N - 1), block
averages with since=, and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import discsim as ds


@pytest.mark.filterwarnings("ignore::discsim.EquilibrationWarning")  # from t = 0 the lattice melts: it warns
@pytest.mark.parametrize("periodic", [True, False])
def test_from_the_start_equals_the_engine_pressure(periodic):
    sim = ds.EventDriven(*ds.random_gas(300, 0.45, periodic=periodic, seed=2)).run(until=5.0)
    t = ds.thermo(sim, blocks=10)
    # K = 300 and zero momentum: a periodic box has 2N - 2 degrees of freedom, walls 2N.
    assert t.temperature == pytest.approx(300 / 299 if periodic else 1.0, rel=1e-12)
    # The canonical P is the engine's mechanical one plus kT / A where momentum is conserved (issue 29).
    shift = t.temperature / sim.box.area if periodic else 0.0
    assert t.pressure == pytest.approx(sim.pressure() + shift, rel=1e-12)
    assert t.z == pytest.approx(ds.compressibility_factor(sim), rel=1e-12)
    assert t.z == pytest.approx(t.pressure * sim.box.area / (300 * t.temperature), rel=1e-12)
    assert t.collisions == sim.counts["collisions"]
    assert t.collision_rate == pytest.approx(2 * sim.counts["collisions"] / (300 * 5.0))
    assert t.since == 0.0 and t.until == 5.0 and t.blocks == 10 and t.method == "batch means"
    assert len(t.z_blocks) == 10 and np.allclose(np.diff(t.edges), 0.5)
    default = ds.thermo(sim)
    assert default.method == "statistical inefficiency" and default.z == pytest.approx(t.z, rel=1e-12)
    assert len(default.z_blocks) == default.blocks and default.inefficiency >= 1.0


def test_z_is_the_canonical_one_on_exact_small_cases():
    # Two discs in a periodic box, one collision each way per crossing: the virial of each collision is
    # known in closed form, so Z = 1 + W / (2 t N kT) with kT = K / (N - 1) = K can be checked by hand.
    discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], [1.0, 1.0], [1.0, 1.0])
    box = ds.Box(10.0, 10.0, periodic=True)
    sim = ds.EventDriven(discs, box).run(until=10.0)
    # Head-on at relative speed 2: each collision gives W = 2 mu v_rel . d = 2 * 0.5 * 2 * 2 = 4.
    collisions = sim.counts["collisions"]
    assert collisions == 3  # at t = 2, 5, 8: a gap of 4 closes first, then one of 6 round the box
    k = sim.kinetic_energy()
    z = 1.0 + 4.0 * collisions / (2.0 * 10.0 * 2 * k)  # kT = K / (N - 1) = K; kT = K / N gave 1 + 2 (z - 1)
    assert ds.compressibility_factor(sim) == pytest.approx(z, rel=1e-12)
    assert ds.analysis.thermo.kinetic_temperature(sim) == pytest.approx(k, rel=1e-12)
    assert ds.thermo(sim, blocks=2).z == pytest.approx(z, rel=1e-12)
    # Moving together (momentum 2 m u), only the motion relative to the centre of mass is heat.
    moving = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.5, 0.0], [-0.5, 0.0]], [1.0, 1.0], [1.0, 1.0])
    sim = ds.EventDriven(moving, box)
    assert ds.analysis.thermo.kinetic_temperature(sim) == pytest.approx(1.0, rel=1e-12)  # (1.25 - 0.25) / 1
    # Walls, or an obstacle, break momentum conservation: 2N degrees of freedom, kT = K / N.
    walled = ds.EventDriven(discs, ds.Box(10.0, 10.0, periodic=False))
    assert ds.analysis.thermo.kinetic_temperature(walled) == pytest.approx(0.5, rel=1e-12)


def test_since_skips_the_melting_and_meets_henderson():
    sim = ds.EventDriven(*ds.random_gas(1000, 0.5, seed=0)).run(until=20.0)
    late = ds.thermo(sim, since=4.0, blocks=8)
    assert late.since == 4.0 and late.blocks == 8
    assert abs(late.z - ds.henderson_z(0.5)) < 4 * late.z_err + 0.01 * ds.henderson_z(0.5)
    assert late.z_err > 0 and late.collision_rate_err > 0
    assert late.collision_rate == pytest.approx(float(ds.enskog_collision_rate(0.5)), rel=0.03)
    assert "batch means over 8 blocks" in str(late)


def test_a_streamed_log_is_read_chunk_by_chunk(tmp_path):
    discs, box = ds.random_gas(200, 0.4, seed=6)
    memory = ds.EventDriven(discs, box).run(until=6.0)
    streamed = ds.EventDriven(discs, box, record=False)
    streamed.stream_chunk = 500  # many chunks on disk
    streamed.run(until=6.0, record_to=tmp_path / "events.dse")
    a, b = ds.thermo(memory, since=1.5), ds.thermo(streamed, since=1.5)
    assert b.z == pytest.approx(a.z, rel=1e-12) and b.z_err == pytest.approx(a.z_err, rel=1e-9)
    c = ds.thermo(tmp_path / "events.dse", since=1.5)
    assert c.z == pytest.approx(a.z, rel=1e-12)


@pytest.mark.filterwarnings("ignore::discsim.EquilibrationWarning")  # thermo(sampler) from t = 0
def test_a_sampler_gathers_the_same_virial():
    discs, box = ds.random_gas(300, 0.4, seed=1)
    sim = ds.EventDriven(discs, box).run(until=5.0)
    sampler = ds.Sampler(0.5)
    ds.EventDriven(discs, box, record=False).run(until=5.0, observers=[sampler])
    a, b = ds.thermo(sim, since=1.0), ds.thermo(sampler, since=1.0)
    assert b.z == pytest.approx(a.z, rel=1e-12) and b.collisions == a.collisions
    assert ds.thermo(sampler).pressure == pytest.approx(ds.thermo(sim).pressure, rel=1e-12)
    assert ds.thermo(sampler).temperature == pytest.approx(300 / 299, rel=1e-12)
    rounded = ds.thermo(sampler, since=1.01)  # up to the next block of dt / 8
    assert rounded.since == pytest.approx(1.0625)


@pytest.mark.parametrize("since", [-1.0, 5.0, 7.0, float("nan"), "2"])
def test_since_outside_the_run_is_refused(since):
    sim = ds.EventDriven(*ds.random_gas(50, 0.3, seed=1)).run(until=5.0)
    with pytest.raises(ds.TimeError, match="since"):
        ds.thermo(sim, since=since)
    with pytest.raises(ds.TimeError, match="since"):
        ds.compressibility_factor(sim, since=since)


def test_bad_sources_and_blocks():
    sim = ds.EventDriven(*ds.random_gas(50, 0.3, seed=1), record=False).run(until=2.0)
    with pytest.raises(ds.InvalidArgumentError, match="record=False"):
        ds.thermo(sim)
    with pytest.raises(ds.InvalidArgumentError, match="record=False"):
        ds.compressibility_factor(sim, since=1.0)
    assert ds.compressibility_factor(sim) > 1  # from the start needs no log
    with pytest.raises(ds.InvalidArgumentError, match="blocks"):
        ds.thermo(sim, blocks=1)
    case = ds.scenarios.head_on(1.0, 1.0)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=30).run(until=1.0)
    assert ds.thermo(pit).pressure == pytest.approx(pit.pressure(), rel=1e-12)  # FixedStep has one (issue 19)
    with pytest.raises(ds.InvalidArgumentError, match="not observed"):
        ds.thermo(ds.Sampler(1.0))
    short = ds.Sampler(1.0)
    ds.EventDriven(*ds.random_gas(50, 0.3, seed=1), record=False).run(until=1.0, observers=[short])
    with pytest.raises(ds.InvalidArgumentError, match="fewer than blocks"):
        ds.thermo(short, blocks=10)


def test_plot_returns_axes():
    import matplotlib.pyplot as plt

    sim = ds.EventDriven(*ds.random_gas(100, 0.3, seed=1)).run(until=3.0)
    assert ds.thermo(sim, since=1.0).plot() is not None
    plt.close("all")


def test_a_melting_lattice_warns_through_its_structure():
    # From t = 0 the lattice's psi6 falls from 0.8 to the fluid's 0.05: the structure relaxes, and thermo says so.
    sim = ds.EventDriven(*ds.random_gas(300, 0.45, seed=2)).run(until=5.0)
    with pytest.warns(ds.EquilibrationWarning, match="the structure still relaxes: the global psi6"):
        early = ds.thermo(sim)
    assert early.drifting and early.order[0] > 0.5 > 0.2 > early.order[-1] and len(early.order) == 64
    late = ds.thermo(sim, since=2.0)  # melted: no warning (pytest's filterwarnings turns none into errors here)
    assert not late.drifting and late.order.max() < 0.2


def test_a_run_whose_discs_changed_is_averaged_since_the_last_change(every_backend, tmp_path):
    """Issue 31, item 1: thermo refused any run that added or removed discs. It now averages the span since the
    last change, where the discs are today's: the same numbers, bit for bit, as a fresh engine from that state."""
    import warnings

    discs, box = ds.random_gas(200, 0.4, seed=2)
    sim = ds.EventDriven(discs, box).run(until=1.0)
    where = sim.positions[0]
    sim.remove_discs([0, 5])
    sim.add_discs(ds.Discs([where], [[0.3, -0.2]], discs.radii[0]))  # where disc 0 was: a free spot
    sim.run(until=1.5)
    sim.remove_discs([7])
    state = sim.snapshot()
    sim.run(until=9.0)
    fresh = ds.EventDriven(state, box).run(until=7.5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ds.EquilibrationWarning)
        ours, theirs = ds.thermo(sim), ds.thermo(fresh)
        later = ds.thermo(sim, since=4.0)
    assert ours.since == 1.5 and later.since == 4.0
    assert (ours.z, ours.z_err, ours.collisions) == (theirs.z, theirs.z_err, theirs.collisions)
    with pytest.raises(ds.TimeError, match=r"since=1.2 is before the last change of the discs .* at time 1.5"):
        ds.thermo(sim, since=1.2)
    streamed = ds.EventDriven(discs, box, record=False)
    streamed.run(until=1.0, record_to=tmp_path / "log.dse")
    streamed.remove_discs([3])
    streamed.run(until=6.0, record_to=tmp_path / "log.dse")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ds.EquilibrationWarning)
        assert ds.thermo(streamed).since == 1.0
