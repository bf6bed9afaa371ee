"""The event-driven engine on cases with exact answers, and its public protocol."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds


def _two(p1, v1, p2, v2, r=(1.0, 1.0), m=(1.0, 1.0), box=(20.0, 20.0)):
    discs = ds.Discs([p1, p2], [v1, v2], list(r), list(m))
    return ds.EventDriven(discs, ds.Box(*box))


def test_head_on_unequal_masses():
    m1, m2, u = 3.0, 1.0, 2.0
    sim = _two([5.0, 10.0], [u, 0.0], [12.0, 10.0], [0.0, 0.0], m=(m1, m2))
    event = sim.step()
    assert event.kind == "collision" and {event.i, event.j} == {0, 1}
    assert event.time == pytest.approx(5.0 / u, rel=1e-15)  # gap 7 - 2 closes at speed 2
    v = sim.velocities
    assert v[:, 0] == pytest.approx([(m1 - m2) * u / (m1 + m2), 2 * m1 * u / (m1 + m2)], rel=1e-15)
    assert np.all(v[:, 1] == 0.0)
    assert sim.positions[1, 0] - sim.positions[0, 0] == pytest.approx(2.0, rel=1e-15)


@pytest.mark.parametrize("offset", [0.3, 1.0, 1.7])
def test_equal_masses_oblique_leave_at_right_angles(offset):
    sim = _two([3.0, 10.0], [1.5, 0.0], [10.0, 10.0 + offset], [0.0, 0.0])
    sim.step()
    v1, v2 = sim.velocities
    assert np.dot(v1, v2) == pytest.approx(0.0, abs=1e-14)
    assert np.hypot(*v1) ** 2 + np.hypot(*v2) ** 2 == pytest.approx(1.5**2, rel=1e-14)
    # the struck disc leaves along the line of centres at contact
    d = sim.positions[1] - sim.positions[0]
    assert d[0] * v2[1] - d[1] * v2[0] == pytest.approx(0.0, abs=1e-13)


def _unfold(x0, v, t, lo, hi):
    """Closed-form position of a point bouncing between lo and hi: fold the free path."""
    span = hi - lo
    s = np.mod(x0 - lo + v * t, 2 * span)
    return lo + np.where(s > span, 2 * span - s, s)


def test_single_disc_in_a_box_follows_the_unfolded_path():
    r, w, h = 0.5, 7.0, 3.0
    p0, v0 = np.array([2.0, 1.0]), np.array([3.1, 1.7])
    sim = ds.EventDriven(ds.Discs([p0], [v0], r), ds.Box(w, h))
    times = np.linspace(0.0, 40.0, 401)
    sim.run(until=times[-1])
    expect_x = _unfold(p0[0], v0[0], times, r, w - r)
    expect_y = _unfold(p0[1], v0[1], times, r, h - r)
    path = sim.trajectory(times)[:, 0, :]
    assert path[:, 0] == pytest.approx(expect_x, abs=1e-11)
    assert path[:, 1] == pytest.approx(expect_y, abs=1e-11)
    # wall hits: the number of times each coordinate reached a wall
    hits_x = math.floor((p0[0] - r + v0[0] * 40.0) / (w - 2 * r))
    hits_y = math.floor((p0[1] - r + v0[1] * 40.0) / (h - 2 * r))
    assert sim.counts["wall_hits"] == hits_x + hits_y
    assert sim.counts["collisions"] == 0
    assert sim.positions[0] == pytest.approx([expect_x[-1], expect_y[-1]], abs=1e-11)


@pytest.mark.parametrize("n", [3, 5, 8])
def test_newtons_cradle_passes_momentum_down_the_line(n):
    r = 1.0
    pos = [[2.0, 5.0]] + [[6.0 + 2 * r * k, 5.0] for k in range(n - 1)]
    vel = [[1.0, 0.0]] + [[0.0, 0.0]] * (n - 1)
    sim = ds.EventDriven(ds.Discs(pos, vel, r), ds.Box(6.0 + 2 * r * n + 10.0, 10.0))
    sim.run(until=4.0)  # the striker arrives at t = 2; the far disc has not reached the wall yet
    v = sim.velocities
    assert sim.counts["collisions"] == n - 1
    assert v[-1] == pytest.approx([1.0, 0.0], abs=1e-12)
    assert np.abs(v[:-1]).max() < 1e-12
    assert sim.momentum() == pytest.approx([1.0, 0.0], abs=1e-12)


@pytest.mark.parametrize("angle", [0.0, 0.4, -1.1])
def test_infinite_mass_obstacle_reflects_like_a_mirror(angle):
    n = np.array([math.cos(angle), math.sin(angle)])
    obstacle = np.array([10.0, 10.0])
    v0 = np.array([2.0, 0.7])
    # start the disc so that it touches the obstacle at t = 1 at contact direction n
    contact = obstacle - 3.0 * n
    start = contact - v0
    assert np.dot(v0, n) > 0  # approaching for each angle above
    discs = ds.Discs([start, obstacle], [v0, [0.0, 0.0]], [1.0, 2.0], [1.0, np.inf])
    sim = ds.EventDriven(discs, ds.Box(20.0, 20.0))
    event = sim.step()
    assert event.time == pytest.approx(1.0, rel=1e-12)
    mirrored = v0 - 2 * np.dot(v0, n) * n
    assert sim.velocities[0] == pytest.approx(mirrored, abs=1e-13)
    assert np.all(sim.velocities[1] == 0.0)
    sim.run(until=5.0)
    assert sim.positions[1] == pytest.approx(obstacle, abs=0)  # never moves


def test_run_until_sets_time_and_run_events_counts_physical_events():
    discs, box = ds.random_gas(100, 0.3, seed=5)
    sim = ds.EventDriven(discs, box).run(until=3.0)
    assert sim.time == 3.0
    n0 = sim.counts["collisions"] + sim.counts["wall_hits"]
    sim.run(events=250)
    assert sim.counts["collisions"] + sim.counts["wall_hits"] == n0 + 250
    assert sim.time == sim.events["time"][-1]
    assert sim.run(until=sim.time) is sim  # until == now is a no-op
    with pytest.raises(ds.TimeError, match="before the current time"):
        sim.run(until=1.0)
    with pytest.raises(ValueError, match="until"):
        sim.run()


def test_step_returns_events_in_time_order_and_none_when_nothing_moves():
    discs, box = ds.random_gas(50, 0.3, seed=2)
    sim = ds.EventDriven(discs, box)
    times = [sim.step().time for _ in range(100)]
    assert times == sorted(times)
    still = ds.EventDriven(ds.Discs([[1.0, 1.0]], [[0.0, 0.0]], 0.5), ds.Box(4, 4))
    assert still.step() is None


def test_same_input_gives_the_same_events_bit_for_bit():
    discs, box = ds.random_gas(300, 0.5, seed=11)
    a = ds.EventDriven(discs, box).run(until=5.0)
    b = ds.EventDriven(discs, box).run(until=5.0)
    assert a.events.tobytes() == b.events.tobytes()
    assert np.array_equal(a.positions, b.positions)


@pytest.mark.parametrize("queue", ["calendar", "sorted", "heap"])
def test_stopping_halfway_changes_nothing(queue):
    discs, box = ds.random_gas(300, 0.5, seed=12, periodic=False)
    whole = ds.EventDriven(discs, box, queue=queue).run(until=6.0)
    halves = ds.EventDriven(discs, box, queue=queue).run(until=3.0).run(until=6.0)
    assert whole.events.tobytes() == halves.events.tobytes()
    assert np.array_equal(whole.positions, halves.positions)
    assert np.array_equal(whole.velocities, halves.velocities)


def test_all_queues_give_the_same_events():
    discs, box = ds.random_gas(200, 0.4, seed=13)
    a = ds.EventDriven(discs, box, queue="sorted").run(until=4.0)
    for queue in ("heap", "calendar"):
        b = ds.EventDriven(discs, box, queue=queue).run(until=4.0)
        assert a.events.tobytes() == b.events.tobytes(), queue


@pytest.mark.slow_on_python
def test_calendar_queue_matches_the_sorted_queue_over_many_laps_and_epoch_moves():
    """Long enough for the calendar to wrap its ring many times and re-bin, with the epoch moved often."""
    discs, box = ds.random_gas(1500, 0.3, seed=14)
    runs = []
    for queue in ("sorted", "calendar"):
        sim = ds.EventDriven(discs, box, queue=queue, record=False)
        sim._backend._rebase_every = 3001  # forces shift_times on the queue every 3001 physical events
        sim.run(events=40_000)
        runs.append(sim)
    a, b = runs
    assert a.counts == b.counts and a.time == b.time
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.velocities, b.velocities)
    assert b.max_queue <= 1500 and b.queue_size <= b.queue_storage <= 3 * 1500 + 64
    assert a.queue_storage == a.queue_size  # the SortedList removes replaced events at once


def test_trajectory_reproduces_the_engine_state_at_any_time():
    discs, box = ds.random_gas(80, 0.4, seed=3)
    sim = ds.EventDriven(discs, box)
    checkpoints = [0.0, 0.7, 1.3, 2.9, 4.0]
    snapshots = []
    for t in checkpoints:
        sim.run(until=t)
        snapshots.append(sim.positions)
    rebuilt = sim.trajectory(checkpoints)
    assert rebuilt.shape == (len(checkpoints), 80, 2)
    for got, want in zip(rebuilt, snapshots):
        assert np.abs(box.displacement(got, want)).max() < 1e-9
    with pytest.raises(ds.TimeError, match="outside the simulated span"):
        sim.trajectory([5.0])


def test_event_log_records_state_after_each_event():
    sim = _two([5.0, 10.0], [2.0, 0.0], [12.0, 10.0], [0.0, 0.0], m=(3.0, 1.0))
    sim.run(until=10.0)
    ev = sim.events
    assert ev["kind"][0] == 0 and (ev["i"][0], ev["j"][0]) in {(0, 1), (1, 0)}
    first = ev[0]
    assert first["time"] == pytest.approx(2.5)
    vel = {int(first["i"]): first["vxi"], int(first["j"]): first["vxj"]}
    assert vel[0] == pytest.approx(1.0) and vel[1] == pytest.approx(3.0)
    walls = ev[ev["kind"] == 1]
    assert len(walls) == sim.counts["wall_hits"] and np.all(walls["j"] == -1)


def test_recording_off_keeps_no_log():
    discs, box = ds.random_gas(100, 0.3, seed=1)
    sim = ds.EventDriven(discs, box, record=False).run(until=3.0)
    assert len(sim.events) == 0 and sim.counts["collisions"] > 0
    with pytest.raises(ValueError, match="record=True"):
        sim.trajectory([1.0])


def test_queue_holds_at_most_one_event_per_disc():
    discs, box = ds.random_gas(500, 0.6, seed=4)
    sim = ds.EventDriven(discs, box, record=False).run(events=20_000)
    assert sim.max_queue <= 500
    sim._check()


def test_energy_and_momentum_are_conserved_to_roundoff():
    discs, box = ds.random_gas(400, 0.5, seed=6)
    sim = ds.EventDriven(discs, box, record=False)
    e0, p0 = sim.kinetic_energy(), sim.momentum()
    sim.run(events=20_000)
    assert abs(sim.kinetic_energy() - e0) / e0 < 1e-12
    assert np.abs(sim.momentum() - p0).max() < 1e-10


def test_progress_bar_runs(capsys):
    discs, box = ds.random_gas(100, 0.3, seed=1)
    a = ds.EventDriven(discs, box).run(until=2.0, progress=True)
    b = ds.EventDriven(discs, box).run(until=2.0)
    assert a.events.tobytes() == b.events.tobytes()
    assert a.time == b.time == 2.0
    c = ds.EventDriven(discs, box).run(events=500, progress=True)
    assert c.counts["collisions"] + c.counts["wall_hits"] == 500


def test_trajectory_keeps_the_later_state_when_a_disc_changes_twice_at_one_time():
    # A cradle of touching discs: the middle disc is hit and passes the momentum on at the same instant.
    pos = [[2.0, 5.0], [6.0, 5.0], [8.0, 5.0]]
    sim = ds.EventDriven(ds.Discs(pos, [[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]], 1.0), ds.Box(30.0, 10.0)).run(until=5.0)
    ev = sim.events
    assert ev["time"][0] == ev["time"][1] == 2.0  # disc 1 is struck and strikes at t = 2
    path = sim.trajectory([4.0, 5.0])
    assert path[:, 1, 0] == pytest.approx([6.0, 6.0])  # the middle disc stays put
    assert path[:, 2, 0] == pytest.approx([10.0, 11.0])


def test_moving_the_clock_epoch_keeps_the_physics_and_determinism():
    from oracle import next_event

    # Rebase the internal clock every 7 physical events instead of every 2^18.
    discs, box = ds.random_gas(40, 0.5, seed=9, periodic=False)
    often = ds.EventDriven(discs, box)
    often._backend._rebase_every = 7
    just_collided = set()
    for _ in range(300):  # the oracle, from the engine's state, agrees event by event
        t0 = often.time
        dt, kind, i, j = next_event(often.positions, often.velocities, discs.radii, discs.masses, box, just_collided)
        event = often.step()
        assert event.time == pytest.approx(t0 + dt, rel=1e-9, abs=1e-9)
        assert (event.kind, {event.i, event.j}) == (kind, {i, j})
        just_collided = {frozenset((i, j))} if kind == "collision" else set()
    often._check()
    assert often.state().epoch > 0.5 * often.time > 0  # the epoch did move
    # splitting a run does not move the epoch differently
    whole = ds.EventDriven(discs, box)
    whole._backend._rebase_every = 37
    whole.run(until=20.0)
    halves = ds.EventDriven(discs, box)
    halves._backend._rebase_every = 37
    halves.run(until=7.3).run(until=20.0)
    assert whole.time == halves.time == 20.0
    assert halves.events.tobytes() == whole.events.tobytes()
    assert np.array_equal(halves.positions, whole.positions)
    # the trajectory still rebuilds the state from absolute times, and energy is kept
    assert np.abs(whole.trajectory([20.0])[0] - whole.positions).max() < 1e-9
    assert abs(whole.kinetic_energy() / discs.kinetic_energy() - 1) < 1e-12


def test_restoring_state_across_epoch_moves_is_bit_for_bit():
    discs, box = ds.random_gas(50, 0.4, seed=10)
    a = ds.EventDriven(discs, box)
    a._backend._rebase_every = 11
    a.run(until=3.0)
    b = ds.EventDriven._restore(a.scene, a._settings(), a.state(), a.events, a.start_time)
    b._backend._rebase_every = 11
    a.run(until=9.0)
    b.run(until=9.0)
    assert a.state().epoch > 0 and a.state().epoch == b.state().epoch
    assert a.events.tobytes() == b.events.tobytes()
    assert np.array_equal(a.positions, b.positions)


def test_run_leaves_the_garbage_collector_as_it_found_it():
    """The hot loop pauses the cyclic GC; it must restore it, on and off, after errors too."""
    import gc

    discs, box = ds.random_gas(100, 0.3, seed=15)
    was = gc.isenabled()
    try:
        gc.enable()
        sim = ds.EventDriven(discs, box).run(events=500)
        assert gc.isenabled()
        gc.disable()
        sim.run(events=500)
        assert not gc.isenabled()
        gc.enable()
        sim.step()
        assert gc.isenabled()
        with pytest.raises(ds.TimeError):
            sim.run(until=sim.time - 1.0)
        assert gc.isenabled()
    finally:
        (gc.enable if was else gc.disable)()


# --- the tiled table of cell members ---------------------------------------------------------
@pytest.mark.parametrize("periodic", [True, False])
@pytest.mark.parametrize("shape", [(3, 3), (4, 7), (10, 10), (11, 23), (25, 9)])
def test_tiles_give_every_cell_its_3x3_block(periodic, shape):
    """Each cell's getter, applied to its tile, returns the members of the grid's 3x3 block, in order."""
    from discsim.cells import CellGrid
    from discsim.engines.event_driven.python.predictor import _TILE
    from discsim.engines.event_driven.python.predictor import tile_cells as _tile_cells

    nx, ny = shape
    grid = CellGrid(ds.Box(float(nx), float(ny), periodic=periodic), 1.0)
    assert (grid.nx, grid.ny) == shape
    members = [(c, c + 1000) if c % 3 else (c,) for c in range(len(grid))]  # a distinct tuple per cell
    blocks, tiles, slots, ghosts = _tile_cells(grid, members, periodic)
    for c, near in enumerate(grid.neighbours):
        assert blocks[c](tiles[c]) == tuple(members[c2] if c2 >= 0 else () for c2 in near)
        assert tiles[c][slots[c]] is members[c]
        assert all(tile[slot] is members[c] for tile, slot in ghosts[c])
    # Every slot a getter reads is the cell's own slot, a ghost copy, or empty beyond a wall.
    copies = sum(1 + len(g) for g in ghosts)
    assert copies == sum(sum(1 for m in tile if m) for tile in {id(t): t for t in tiles}.values())
    assert max(len(tile) for tile in tiles) == (_TILE + 2) ** 2


def test_cell_crossings_keep_ghost_copies_in_step():
    """After many crossings in a box of several tiles, every ghost copy is the cell's own tuple (``_check``)."""
    from discsim.engines.event_driven.python.layout import _TILE

    discs, box = ds.random_gas(1500, 0.3, periodic=True, seed=4)
    sim = ds.EventDriven(discs, box, record=False)
    assert sim.grid.nx > 2 * _TILE
    sim.run(events=30_000)
    assert sim.counts["cell_crossings"] > 30_000
    sim._check()


# --- the internal numbering of large systems -------------------------------------------------
def test_the_internal_numbering_is_invisible(monkeypatch):
    """A large system numbered tile by tile inside gives the caller the same positions, events and ids."""
    from discsim.engines.event_driven import numbering
    from discsim.engines.event_driven.numbering import RENUMBER_MIN as _RENUMBER_MIN

    gas, box = ds.random_gas(_RENUMBER_MIN + 904, 0.3, periodic=True, seed=5)
    n = len(gas)
    shuffled = np.random.default_rng(2).permutation(n)  # neighbours far apart in the caller's numbering
    masses = np.linspace(1.0, 2.0, n)  # unequal, so that a mix-up of masses would show
    discs = ds.Discs(gas.positions[shuffled], gas.velocities[shuffled], gas.radii, masses)
    sim = ds.EventDriven(discs, box)
    order = sim.state().order
    assert not np.array_equal(order, np.arange(n)) and sorted(order.tolist()) == list(range(n))
    assert np.abs(np.diff(order)).mean() > n / 10  # far from the identity on a shuffled input
    assert np.array_equal(sim.positions, discs.positions) and np.array_equal(sim.velocities, discs.velocities)
    monkeypatch.setattr(numbering, "RENUMBER_MIN", 10 * n)
    plain = ds.EventDriven(discs, box)  # the caller's numbering inside too
    assert np.array_equal(plain.state().order, np.arange(n))
    first = [sim.step() for _ in range(2000)]
    second = [plain.step() for _ in range(2000)]
    for a, b in zip(first, second):
        assert (a.kind, {a.i, a.j}) == (b.kind, {b.i, b.j})
        assert a.time == pytest.approx(b.time, rel=1e-12)
    assert np.allclose(sim.positions, plain.positions, rtol=0, atol=1e-9)
    assert np.allclose(sim.velocities, plain.velocities, rtol=0, atol=1e-9)
    assert sim.kinetic_energy() == pytest.approx(plain.kinetic_energy(), rel=1e-12)
    log = sim.events
    assert set(log["i"][log["kind"] == 0].tolist()) <= set(range(n))
    assert np.abs(sim.trajectory([sim.time])[0] - sim.positions).max() < 1e-9
    sim._check()


def test_small_systems_keep_the_callers_numbering():
    discs, box = ds.random_gas(500, 0.3, seed=2)
    sim = ds.EventDriven(discs, box)
    assert np.array_equal(sim.state().order, np.arange(500))


# --- runs with no time limit end when nothing can ever happen again -----------------------------------


@pytest.mark.parametrize(
    ("positions", "velocities"),
    [
        ([[5.0, 5.0]], [[1.0, 0.3]]),  # one disc on a torus: nothing to hit
        ([[2.0, 5.0], [6.0, 5.0]], [[1.0, 0.0], [1.0, 0.0]]),  # drifting alike
        ([[2.0, 2.0], [6.0, 6.0]], [[1.0, 0.0], [2.0, 0.0]]),  # two lanes along x, 4 apart
        ([[2.0, 2.0], [6.0, 6.0]], [[0.0, -1.0], [0.0, 0.5]]),  # two lanes along y
    ],
)
def test_step_returns_none_in_a_periodic_box_where_nothing_can_meet(positions, velocities):
    sim = ds.EventDriven(ds.Discs(positions, velocities, 0.5), ds.Box(10.0, 10.0, periodic=True))
    assert sim.step() is None
    assert sim.time == 0.0  # the cell crossings it went through changed nothing
    sim.run(events=5)
    assert sim.counts["collisions"] == 0 and sim.time == 0.0
    sim.run(until=123.0)  # and the run goes on exactly
    expected = ds.Box(10.0, 10.0, periodic=True).wrap(np.array(positions) + 123.0 * np.array(velocities))
    np.testing.assert_allclose(sim.positions, expected, atol=1e-12)


def test_a_run_by_events_stops_after_the_last_collision_that_can_happen():
    # Discs 0 and 1 share a lane and meet over and over; disc 2 drifts in a lane of its own.
    discs = ds.Discs([[2.0, 2.0], [6.0, 2.5], [5.0, 7.0]], [[1.0, 0.0], [2.0, 0.0], [1.5, 0.0]], 0.5)
    sim = ds.EventDriven(discs, ds.Box(10.0, 10.0, periodic=True)).run(events=20)
    assert sim.counts["collisions"] == 20
    # Crossing lanes: the relative motion runs along x + y = 9 (mod 10), which passes 0.71 from a lattice point.
    lone = ds.Discs([[2.0, 2.0], [8.0, 5.0]], [[1.0, 0.0], [0.0, 1.0]], 0.5)
    assert ds.EventDriven(lone, ds.Box(10.0, 10.0, periodic=True)).run(events=1).counts["collisions"] == 1


def test_step_by_step_equals_one_run_when_a_run_ends_early():
    discs = ds.Discs([[2.0, 2.0], [6.0, 6.0]], [[1.0, 0.0], [2.0, 0.0]], 0.5)
    box = ds.Box(10.0, 10.0, periodic=True)
    stepped = ds.EventDriven(discs, box)
    while stepped.step() is not None:
        pass
    whole = ds.EventDriven(discs, box).run(events=10)
    assert stepped.time == whole.time and stepped.counts == whole.counts


def _never_again_pairwise(sim) -> bool:
    """The proof of "no pair can ever meet" pair by pair, O(N^2): the oracle of the grouped one."""
    box, scene = sim.box, sim.scene
    pos, vel, radii = sim.positions, sim.velocities, sim.discs.radii
    for i in range(len(pos) - 1):
        j = np.arange(i + 1, len(pos))
        dv = vel[j] - vel[i]
        gap = box.displacement(pos[i], pos[j])
        reach = (radii[i] + radii[j]) * (1.0 + 1e-9) + 1e-12 * box.size.max()
        never = (dv == 0.0).all(axis=1) | scene.passes(np.full(len(j), i), j)
        never |= (dv[:, 0] == 0.0) & (np.abs(gap[:, 0]) > reach)
        never |= (dv[:, 1] == 0.0) & (np.abs(gap[:, 1]) > reach)
        if not never.all():
            return False
    return True


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    n=st.integers(2, 12),
    lanes=st.sampled_from(["alike", "x", "y", "mixed", "signed zeros"]),
    filtered=st.booleans(),
)
def test_the_grouped_never_again_proof_agrees_with_the_pairwise_one(seed, n, lanes, filtered):
    rng = np.random.default_rng(seed)
    side = 4.0 * max(n, 3)
    positions = np.column_stack([np.arange(n) * 4.0 + 2.0, rng.uniform(0.0, side, n)])
    if rng.random() < 0.5:
        positions = positions[:, ::-1].copy()
    speeds = rng.choice([-1.0, 0.0, 1.0, 2.0], size=n)
    velocities = {
        "alike": np.tile([0.3, -0.7], (n, 1)),
        "x": np.column_stack([speeds, np.zeros(n)]),
        "y": np.column_stack([np.zeros(n), speeds]),
        "mixed": np.column_stack([speeds, rng.choice([0.0, 1.0], size=n)]),
        "signed zeros": np.column_stack([np.where(rng.random(n) < 0.5, -0.0, 0.0), np.ones(n)]),
    }[lanes]
    discs = ds.Discs(positions, velocities, radii=rng.uniform(0.2, 1.5, n), groups=rng.integers(0, 2, n))
    sim = ds.EventDriven(discs, ds.Box(side, side, periodic=True), pass_through={(0, 1)} if filtered else ())
    assert sim._never_again() == _never_again_pairwise(sim)
