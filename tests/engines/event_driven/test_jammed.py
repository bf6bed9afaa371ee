"""Jammed starts end (issue 18, part 2): discs wedged against each other or a wall raise JammedError, never hang.

Each jam in ``tests/jams.py`` used to loop for ever at one instant. A watchdog (SIGALRM) turns a hang into a failure.
"""

from __future__ import annotations

import numpy as np
import pytest
from jams import JAMS, wall_and_obstacle, watchdog

import discsim as ds


def _named(message: str, discs: list[int]) -> bool:
    listed = message.split(" are jammed")[0]
    return all(str(d) in listed for d in discs[:20])


@pytest.mark.parametrize("name", sorted(JAMS))
def test_a_jammed_start_is_refused_by_name_and_leaves_a_consistent_engine(name):
    discs, box, jammed = JAMS[name]()
    sim = ds.EventDriven(discs, box)
    with watchdog(), pytest.raises(ds.JammedError, match=r"are jammed at time 0\.0") as caught:
        sim.run(until=1.0)
    assert _named(str(caught.value), jammed)
    assert isinstance(caught.value, ds.DiscsimError)
    assert sim.time == 0.0
    sim._check()  # consistent at the last whole event: not marked broken, and can be saved
    assert sim._broken is None
    sim.state().check(len(discs), len(sim.grid))


@pytest.mark.slow_on_python  # (2 s a case interpreted; the numba cases stay quick)
@pytest.mark.parametrize("name", sorted(JAMS))
def test_a_jam_ends_an_event_count_run_step_and_chunked_runs(name, tmp_path):
    discs, box, _ = JAMS[name]()
    with watchdog():
        with pytest.raises(ds.JammedError):
            ds.EventDriven(discs, box).run(events=10**9)
        sim = ds.EventDriven(discs, box)
        with pytest.raises(ds.JammedError):
            for _ in range(10**7):
                sim.step()
        # The driver's chunks (an observer every 100 events) are smaller than the jam threshold.
        with pytest.raises(ds.JammedError):
            ds.EventDriven(discs, box).run(until=1.0, observers=[ds.Callback(lambda s, e: None, every=100)])
        sim = ds.EventDriven(discs, box, record=False)
        with pytest.raises(ds.JammedError):
            sim.run(until=1.0, checkpoint=tmp_path / "c.dsc", checkpoint_every=1000)
        assert ds.load(tmp_path / "c.dsc").time == 0.0  # the checkpoints before the jam stay readable


def test_a_system_that_jams_during_a_run_is_stopped_at_that_instant():
    """A disc sliding down a wall is knocked, at t = 1.5, into the slot between the wall and an obstacle."""
    u = np.array([np.cos(np.radians(75)), np.sin(np.radians(75))])
    v_a = np.array([0.0, -1.0])
    v_b = v_a - u
    b0 = np.array([0.5, 5.0]) + u - 1.5 * v_b
    discs = ds.Discs([[0.5, 6.5], [1.5, 5.0], b0], [v_a, [0, 0], v_b], 0.5, masses=[1, np.inf, 1])
    sim = ds.EventDriven(discs, ds.Box(10, 10))
    with watchdog(), pytest.raises(ds.JammedError, match=r"discs 0, 1(, 2)? are jammed at time 1\.5"):
        sim.run(until=10.0)
    assert sim.time == pytest.approx(1.5)
    assert sim.events["time"][0] == pytest.approx(1.5)
    sim._check()


def test_finite_cascades_at_one_instant_are_not_jams():
    """A touching row with room at its ends: N (N - 1) / 2 collisions at t = 0 at most, then time moves."""
    n = 120
    x = 5.0 + np.arange(n)
    v = np.column_stack([np.random.default_rng(3).normal(size=n), np.zeros(n)])
    sim = ds.EventDriven(ds.Discs(np.column_stack([x, np.full(n, 5.0)]), v, 0.5), ds.Box(n + 10.0, 10.0))
    with watchdog():
        sim.run(until=1.0)
    at_zero = int((sim.events["time"] == 0.0).sum())
    assert at_zero > 1000  # a real cascade ...
    assert at_zero < sim.jam_events  # ... shorter than the threshold
    assert sim.time == 1.0
    cradle = ds.scenarios.newtons_cradle(5)
    assert ds.EventDriven(cradle.discs, cradle.box).run(until=cradle.until).time == cradle.until


def test_the_threshold_is_a_setting():
    discs, box, _ = wall_and_obstacle()
    sim = ds.EventDriven(discs, box)
    sim.jam_events, sim.jam_events_per_disc = 50, 0
    with watchdog(), pytest.raises(ds.JammedError, match="made 50 collisions and wall hits"):
        sim.run(until=1.0)
    assert sim.counts["collisions"] + sim.counts["wall_hits"] == 50


# --- issue 30, items 7 and 10 ----------------------------------------------------------------------------------
def _energy_and_momentum(sim):
    return sim.kinetic_energy(), sim.momentum()


@pytest.mark.parametrize("chunks", [None, 100], ids=["one call", "observer every 100 events"])
def test_an_unbounded_cascade_creeping_towards_an_instant_is_a_jam(chunks):
    """Item 7: a light disc squeezed between a wall and a disc 10^200 times heavier gains twice the heavy one's
    speed at each bounce: some 10^100 bounces while the clock creeps towards t = 5 without reaching it (numba ran
    out of memory after 15 million collisions, Python never returned). The clock never stood still, so the jam
    guard reset at every chunk; now events that come faster than ``jam_time`` of the time scale count too."""
    discs = ds.Discs([[2, 5], [8, 5]], [[1, 0], [-1, 0]], 1, [1e100, 1e-100])
    sim = ds.EventDriven(discs, ds.Box(10, 10), record=False)
    if sim.backend == "python":  # the same guard, sooner: 4 10^4 events instead of 1.2 10^6
        sim.jam_events, sim.jam_events_per_disc, sim.jam_time = 1000, 0, 1e-6
    before = _energy_and_momentum(sim)
    with watchdog(120), pytest.raises(ds.JammedError, match=r"discs 0, 1 are jammed at time 4\.9999") as caught:
        if chunks is None:
            sim.run(until=5.0)
        else:  # the driver's chunks, far below the threshold: the guard's mark carries over
            sim.run(until=5.0, observers=[ds.Callback(lambda s, e: None, every=chunks)])
    assert "while the clock moved by" in str(caught.value)
    assert 4.9999 < sim.time < 5.0 and sim.counts["collisions"] > 10**4
    assert sim._broken is None  # consistent at its last whole event
    sim._check()
    sim.state().check(2, len(sim.grid))
    energy, momentum = _energy_and_momentum(sim)
    assert energy == pytest.approx(before[0], rel=1e-12)
    np.testing.assert_allclose(momentum, before[1], rtol=1e-12)


@pytest.mark.slow_on_python
def test_a_finite_cascade_of_a_large_mass_ratio_is_not_a_jam():
    """Mass ratio 10^10: pi / 2 10^5 bounces squeeze the light disc, then the heavy one turns back (Galperin's
    billiard); those bounces come slower than ``jam_time``, and the run ends."""
    discs = ds.Discs([[2, 5], [8, 5]], [[1, 0], [-1, 0]], 1, [1e5, 1e-5])
    sim = ds.EventDriven(discs, ds.Box(10, 10), record=False)
    with watchdog(120):
        sim.run(until=8.0)
    assert sim.time == 8.0
    assert sim.counts["collisions"] == pytest.approx(np.pi / 2 * 1e5, rel=1e-3)
    assert sim.velocities[0, 0] == pytest.approx(-1.0, abs=1e-6)  # turned back


def _row_sorting_its_velocities(m: int):
    """A touching row of ``m`` discs with room at its ends, x velocities falling along it: every pair once
    out of order, so ``m (m - 1) / 2`` collisions at t = 0, then the row flies apart."""
    x = 10.0 + np.arange(m)
    v = np.column_stack([np.linspace(1.0, -1.0, m), np.zeros(m)])
    return ds.Discs(np.column_stack([x, np.full(m, 5.0)]), v, 0.5), ds.Box(m + 20.0, 10.0)


def _square_lattice_with_room(n: int):
    """An exactly touching ``n x n`` square lattice (packing pi / 4 inside it) in a walled box twice as wide, each
    row's x velocities and each column's y velocities falling along it: ``n^2 (n - 1)`` collisions at t = 0."""
    k = np.arange(n)
    r, c = np.meshgrid(k, k, indexing="ij")
    pts = np.column_stack([(n / 2 + c + 0.5).ravel(), (n / 2 + r + 0.5).ravel()])
    fall = np.linspace(1.0, -1.0, n)
    v = np.column_stack([fall[c.ravel()], fall[r.ravel()]]) * np.random.default_rng(2).uniform(0.5, 1.0, (1, 2))
    return ds.Discs(pts, v, 0.5), ds.Box(2.0 * n, 2.0 * n)


@pytest.mark.parametrize(
    ("scene", "threshold", "at_zero"),
    [
        # a row of 400 (79 800 collisions) against the default threshold 10 000 + 100 N = 50 000
        (lambda: _row_sorting_its_velocities(400), None, 400 * 399 // 2),
        # Item 10: a square lattice of 30 x 30 (26 100) against a threshold of 10 000 + 10 N = 19 000 (the
        # default's 10 000 + 100 N falls short from 110 x 110 on: 1.3 million against 1.2 million)
        (lambda: _square_lattice_with_room(30), 10, 30 * 30 * 29),
    ],
    ids=["row", "square lattice"],
)
def test_a_touching_start_with_room_is_a_finite_cascade_not_a_jam(scene, threshold, at_zero):
    """Item 10: the jam threshold grew as N, while the finite cascade of a touching start grows as N^2 (a row) or
    N^1.5 (a square lattice): long ones were refused. Now the threshold leaves room for the cascade of the
    touching cluster (M discs, e contacts deep from the last event's: M e events)."""
    discs, box = scene()
    sim = ds.EventDriven(discs, box)
    if threshold is not None:
        sim.jam_events_per_disc = threshold
    before = _energy_and_momentum(sim)
    with watchdog(120):
        sim.run(until=0.5)
    assert sim.time == 0.5
    assert int((sim.events["time"] == 0.0).sum()) == at_zero  # the whole cascade, at t = 0
    assert sim.counts["wall_hits"] == 0
    sim._check()
    energy, momentum = _energy_and_momentum(sim)
    assert energy == pytest.approx(before[0], rel=1e-12)
    np.testing.assert_allclose(momentum, before[1], atol=1e-12 * len(discs))
    # The cascade sorted each row's x velocities (and each column's y velocities): no pair approaches now.
    assert sorted(sim.velocities[:, 0].tolist()) == pytest.approx(sorted(discs.velocities[:, 0].tolist()), abs=1e-12)


def test_a_touching_square_lattice_whose_rows_and_columns_slide_is_no_jam():
    """The other side of item 10's periodic lattice (a jam, in ``jams.py``): velocities that slide whole rows
    along x and whole columns along y part no contact, and the lattice shears apart."""
    n = 6
    pts = np.array([[c + 0.5, r + 0.5] for r in range(n) for c in range(n)])
    rng = np.random.default_rng(4)
    rows, cols = rng.normal(size=n), rng.normal(size=n)
    v = np.array([[rows[r], cols[c]] for r in range(n) for c in range(n)])
    sim = ds.EventDriven(ds.Discs(pts, v, 0.5), ds.Box(n, n, periodic=True))
    with watchdog():
        sim.run(until=0.05)
    assert sim.time == 0.05
    sim._check()
