"""Adding and removing discs mid-run (issue 19, part 1): sim.add_discs, sim.remove_discs, ids, the log's records.

Claims tested here: indices shift down like ``np.delete`` while ids stay; an event-driven run after a change
is, event for event and bit for bit, a fresh engine built from ``sim.snapshot()`` (its times shifted by the
time of the change); both backends give the same log; the log (in memory, streamed, checkpointed) rebuilds
every disc's path with NaN where it was not there; callbacks may remove discs; bad input changes nothing.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import discsim as ds
from discsim import _numba
from discsim.events import ADD, REMOVE, added_discs

FIELDS = ("xi", "yi", "vxi", "vyi", "xj", "yj", "vxj", "vyj")

ENGINES = {
    "pic": lambda discs, box, **kw: ds.EventDriven(discs, box, **kw),
    "pit": lambda discs, box, **kw: ds.FixedStep(discs, box, dt=0.01, **kw),
}


def _gas(n=120, periodic=True, seed=3):
    return ds.random_gas(n, 0.3, periodic=periodic, seed=seed)


def _free_spots(sim, radius, k, seed=0):
    """``k`` places for discs of ``radius``, clear of every disc of ``sim``, of the walls and of each other."""
    rng, box, spots = np.random.default_rng(seed), sim.box, []
    while len(spots) < k:
        p = rng.uniform(radius, [box.width - radius, box.height - radius])
        d = box.minimum_image(np.vstack([sim.positions, *spots, np.zeros((0, 2))]) - p)
        reach = np.concatenate([sim.discs.radii, np.full(len(spots), radius)]) + radius
        if (np.hypot(d[:, 0], d[:, 1]) > reach * 1.01).all():
            spots.append(p)
    return np.array(spots)


def _same(a, b):
    """Two logs equal field by field, bit for bit (NaN equal to NaN)."""
    fields = ("time", "kind", "i", "j", *FIELDS)
    return len(a) == len(b) and all(np.array_equal(a[f], b[f], equal_nan=True) for f in fields)


# --- the API -----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("engine", ENGINES)
def test_added_discs_get_the_next_indices_and_collide(every_backend, engine):
    sim = ENGINES[engine](ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], 1.0), ds.Box(10.0, 10.0)).run(until=1.0)
    new = sim.add_discs(ds.Discs([[8.0, 5.0], [5.0, 9.0]], [[-1.0, 0.0], [0.0, 0.0]], [1.0, 0.5], masses=[1.0, 3.0]))
    assert new.tolist() == [1, 2] and sim.ids.tolist() == [0, 1, 2]
    np.testing.assert_array_equal(sim.discs.masses, [1.0, 1.0, 3.0])
    sim.run(until=3.0)
    assert sim.counts.get("collisions", sim.counts.get("detections")) == 1
    np.testing.assert_allclose(sim.velocities[:2], [[-1.0, 0.0], [1.0, 0.0]])
    added = sim.events[sim.events["kind"] == ADD]
    assert added["i"].tolist() == [1, 2] and added["time"].tolist() == [1.0, 1.0]


@pytest.mark.parametrize("engine", ENGINES)
def test_removal_shifts_indices_down_and_ids_stay(every_backend, engine):
    discs, box = _gas(40, periodic=False)
    sim = ENGINES[engine](discs, box).run(until=0.5)
    before = sim.positions.copy()
    sim.remove_discs([3, 0])
    np.testing.assert_array_equal(sim.positions, np.delete(before, [0, 3], axis=0))
    assert sim.ids.tolist() == np.delete(np.arange(40), [0, 3]).tolist()
    assert sim.add_discs(ds.Discs(_free_spots(sim, 0.2, 1), [[0.0, 1.0]], 0.2)).tolist() == [38]
    assert sim.ids[-1] == 40  # a new id, never one of a removed disc
    removed = sim.events[sim.events["kind"] == REMOVE]
    assert removed["i"].tolist() == [0, 3] and np.isnan(removed["xi"]).all()
    np.testing.assert_array_equal(np.column_stack([removed["xj"], removed["yj"]]), before[[0, 3]])
    with pytest.raises(ds.InvalidArgumentError, match="does not exist"):
        sim.remove_discs([39])
    assert sim.ids.flags.writeable is False


def test_nothing_to_add_or_remove_changes_nothing(every_backend):
    discs, box = _gas(30)
    sim = ds.EventDriven(discs, box).run(until=0.5)
    log = sim.events.copy()
    assert sim.add_discs(ds.Discs(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))).shape == (0,)
    sim.remove_discs([])
    assert sim._origin is None and sim.events.tobytes() == log.tobytes()


@pytest.mark.parametrize("engine", ENGINES)
def test_removing_every_disc_and_adding_again(every_backend, engine):
    discs, box = _gas(20)
    sim = ENGINES[engine](discs, box).run(until=0.3)
    sim.remove_discs(np.arange(20)).run(until=0.6)
    assert sim.positions.shape == (0, 2)
    sim.add_discs(ds.Discs([[1.0, 1.0]], [[1.0, 0.5]], 0.5)).tolist()
    sim.run(until=1.0)
    assert sim.ids.tolist() == [20]
    np.testing.assert_allclose(sim.trajectory([1.0])[0, 20], sim.positions[0], atol=1e-12)


def test_a_disc_too_large_for_the_periodic_grid_is_refused_and_nothing_changes(every_backend):
    sim = ds.EventDriven(ds.Discs([[1.0, 1.0]], [[1.0, 0.0]], 0.2), ds.Box(6.0, 6.0, periodic=True)).run(until=0.5)
    state = sim.state()
    with pytest.raises(ds.BoxTooSmallError):
        sim.add_discs(ds.Discs([[4.0, 4.0]], [[0.0, 0.0]], 1.5))  # 3 cells of 3.0 do not fit in 6.0
    assert len(sim.discs) == 1 and sim.state().ref_positions.tobytes() == state.ref_positions.tobytes()
    assert len(sim.events) == 0


def test_groups_that_pass_through_may_be_added_overlapping(every_backend):
    discs = ds.Discs([[2.0, 2.0]], [[0.0, 0.0]], 0.5, groups=[1])
    sim = ds.EventDriven(discs, ds.Box(10, 10), pass_through=[(1, 2)])
    sim.add_discs(ds.Discs([[2.5, 2.0], [7.0, 7.0]], [[1.0, 0.0], [0.0, 0.0]], 0.5, groups=[2, 2**62]))
    with pytest.raises(ds.OverlapError, match="new disc 3 at"):
        sim.add_discs(ds.Discs([[7.5, 7.0]], [[0.0, 0.0]], 0.5, groups=[1]))
    sim.run(until=3.0)
    sim._check()
    ids, _, _, _, radii, _, groups = added_discs(sim.events)
    assert ids.tolist() == [1, 2] and radii.tolist() == [0.5, 0.5]
    assert groups.tolist() == [2, 2**62]  # the label's 64 bits, exactly


@pytest.mark.parametrize("engine", ENGINES)
def test_adding_a_crowd_of_overlapping_discs_is_an_overlap_error_in_bounded_memory(every_backend, engine):
    """Issue 30, item 8: 10^5 discs at one spot made 5 10^9 candidate pairs at once (numpy's MemoryError,
    37 GiB asked for); the check now goes through them in pieces and stops at the first overlap."""
    import tracemalloc

    sim = ENGINES[engine](ds.Discs([[1.0, 1.0]], [[0.0, 0.0]], 0.01), ds.Box(10.0, 10.0))
    n = 10**5
    crowd = ds.Discs(np.full((n, 2), 5.0), np.zeros((n, 2)), 0.01)
    tracemalloc.start()
    try:
        with pytest.raises(ds.OverlapError, match=r"new disc 2 at \[5\.0, 5\.0\] would overlap new disc 1 by 0\.02"):
            sim.add_discs(crowd)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 400e6  # pieces of 2^20 pairs: about 100 MB
    assert len(sim.discs) == 1  # nothing changed
    sim.run(until=1.0)


# --- exactness ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("periodic", [True, False])
def test_after_a_change_the_run_is_a_fresh_engine_from_the_snapshot(every_backend, periodic):
    """The brute-force check: rebuild an engine from the discs as they are after each change, run both."""
    discs, box = _gas(150, periodic=periodic)
    sim = ds.EventDriven(discs, box).run(until=1.0)
    for change in range(3):
        if change == 1:
            spots = _free_spots(sim, 0.3, 4, seed=change)
            velocities = [[0.5, -0.2], [0.5, -0.2], [-1.0, 0.1], [0.0, 0.0]]
            sim.add_discs(ds.Discs(spots, velocities, 0.3, masses=[1.0, 2.0, 0.5, np.inf]))
        else:
            sim.remove_discs([5 + change, 40, 77])
        snapshot, t0, mark = sim.snapshot(), sim.time, len(sim.events)
        sim.run(events=400)
        sim._check()
        fresh = ds.EventDriven(snapshot, box).run(events=400)
        after, alone = sim.events[mark:], fresh.events
        assert len(after) == len(alone) == 400
        assert np.array_equal(after["time"], alone["time"] + t0)  # the fresh run's clock starts at 0
        assert np.array_equal(after["i"], sim.ids[alone["i"]])
        pair = alone["j"] >= 0
        assert np.array_equal(after["j"][pair], sim.ids[alone["j"][pair]])
        assert all(np.array_equal(after[f], alone[f], equal_nan=True) for f in FIELDS)
        assert sim.velocities.tobytes() == fresh.velocities.tobytes()


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("periodic", [True, False])
def test_trajectory_follows_every_disc_with_nan_where_it_was_not(every_backend, engine, periodic):
    discs, box = _gas(60, periodic=periodic)
    sim = ENGINES[engine](discs, box).run(until=0.5)
    gone = sim.positions[[7, 20]].copy()
    sim.remove_discs([7, 20]).run(until=1.0)
    spots = _free_spots(sim, 0.25, 2)
    sim.add_discs(ds.Discs(spots, [[1.0, 0.0], [0.0, -1.0]], 0.25))
    sim.run(until=2.0)
    assert sim.ids[-2:].tolist() == [60, 61]
    paths = sim.trajectory([0.25, 0.5, 0.75, 1.0, 2.0])
    assert paths.shape == (5, 62, 2)
    assert np.isnan(paths[:, 60:]).sum() == 3 * 2 * 2  # new discs: NaN before t = 1, there at it
    # Removed at 0.5: NaN from then on (an event at a time counts as done then, for every kind of record).
    assert not np.isnan(paths[0, [7, 20]]).any() and np.isnan(paths[1:, [7, 20]]).all()
    np.testing.assert_allclose(sim.trajectory([0.5 - 1e-9])[0, [7, 20]], gone, atol=1e-8)
    np.testing.assert_array_equal(paths[3, 60:], spots)
    np.testing.assert_allclose(paths[-1, sim.ids], sim.positions, atol=1e-9)
    unwrapped = sim.trajectory([2.0], unwrapped=True)[0]
    np.testing.assert_allclose(unwrapped[sim.ids], sim.unwrapped_positions, atol=1e-9)


@pytest.mark.skipif(not _numba.available(), reason="numba is not installed or is hidden (the fast extra)")
@pytest.mark.parametrize("engine", ENGINES)
def test_both_backends_give_the_same_log_bit_for_bit(engine):
    logs = []
    for backend in ("python", "numba"):
        discs, box = _gas(200)
        sim = ENGINES[engine](discs, box, backend=backend).run(until=0.7)
        sim.remove_discs([3, 150])
        sim.run(until=1.2)
        sim.add_discs(ds.Discs(_free_spots(sim, 0.2, 3), [[1.0, 0.0], [0.0, 2.0], [-1.0, -1.0]], 0.2))
        sim.run(until=2.0)
        logs.append((sim.events.copy(), sim.positions.tobytes(), sim.ids.tolist()))
    assert _same(logs[0][0], logs[1][0]) and logs[0][1:] == logs[1][1:]


# --- files -------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("engine", ENGINES)
def test_save_and_load_across_changes_continue_bit_for_bit(every_backend, engine, tmp_path):
    discs, box = _gas(80)
    sim = ENGINES[engine](discs, box).run(until=0.5)
    sim.remove_discs([1, 2, 60])
    sim.add_discs(ds.Discs(_free_spots(sim, 0.2, 2), [[0.5, 0.0], [0.0, 0.5]], 0.2))
    copy = ds.load(sim.save(tmp_path / "sim.dsc"))
    assert copy.ids.tolist() == sim.ids.tolist() and copy._next_id == sim._next_id == 82
    for engine_ in (sim, copy):
        engine_.run(until=1.0)
        engine_.remove_discs([0])
        engine_.run(until=1.5)
    assert _same(copy.events, sim.events) and copy.positions.tobytes() == sim.positions.tobytes()
    np.testing.assert_array_equal(copy.trajectory([0.4, 1.2]), sim.trajectory([0.4, 1.2]))


def test_a_run_killed_after_a_callback_removed_discs_resumes_bit_for_bit(every_backend, tmp_path):
    def shoot(sim, contact):  # each wall hit of disc 0 removes the last disc
        if contact.i == 0 and len(sim.discs) > 5:
            sim.remove_discs([len(sim.discs) - 1])

    discs, box = _gas(40, periodic=False)
    whole = ds.EventDriven(discs, box, record=False).on("wall", shoot)
    whole.run(until=4.0, checkpoint=tmp_path / "whole.dsc", record_to=tmp_path / "whole.dse")
    cut = ds.EventDriven(discs, box, record=False).on("wall", shoot)
    cut.run(until=2.0, checkpoint=tmp_path / "cut.dsc", record_to=tmp_path / "cut.dse")
    assert len(cut.discs) < 40
    resumed = ds.load(tmp_path / "cut.dsc").on("wall", shoot)
    resumed.run(until=4.0, record_to=tmp_path / "cut.dse")
    assert resumed.positions.tobytes() == whole.positions.tobytes() and resumed.ids.tolist() == whole.ids.tolist()
    a, b = ds.read_events(tmp_path / "whole.dse"), ds.read_events(tmp_path / "cut.dse")
    assert _same(a.events, b.events)
    np.testing.assert_array_equal(a.trajectory([1.0, 3.0]), ds.trajectory_from_events(tmp_path / "cut.dse", [1.0, 3.0]))


def test_a_log_streamed_after_a_change_names_the_discs_by_id(every_backend, tmp_path):
    discs, box = _gas(50)
    sim = ds.EventDriven(discs, box, record=False).run(until=0.5)
    sim.remove_discs([0, 10])
    kept = ds.EventDriven(discs, box).run(until=0.5).remove_discs([0, 10])
    kept.run(until=1.5)
    sim.run(until=1.5, record_to=tmp_path / "events.dse")  # the file starts here, at the discs there now
    log = ds.read_events(tmp_path / "events.dse")
    assert log.ids.tolist() == sim.ids.tolist() and log.start_time == 0.5
    paths = log.trajectory([0.5, 1.5])
    assert np.isnan(paths[:, [0, 10]]).all()
    np.testing.assert_allclose(paths, kept.trajectory([0.5, 1.5]), atol=1e-9)  # from the snapshot: to roundoff
    assert _same(log.events, kept.events[kept.events["time"] > 0.5])


# --- callbacks and consumers -------------------------------------------------------------------------------
@pytest.mark.parametrize("engine", ENGINES)
def test_a_callback_removes_each_target_a_bullet_hits(every_backend, engine):
    """A game: disc 0 flies through a row of targets (groups 1); each target hit scores and is removed."""
    targets = [[3.0 + 2.0 * k, 5.0] for k in range(5)]
    heavy = [1e6] + [1.0] * 5  # the bullet barely slows down
    discs = ds.Discs([[1.0, 5.0], *targets], [[3.0, 0.0]] + [[0.0, 0.0]] * 5, 0.4, heavy, groups=[0] + [1] * 5)
    sim = ENGINES[engine](discs, ds.Box(14.0, 10.0))
    score, hit = [], []

    def on_hit(sim, contact):
        target = contact.j if sim.discs.groups[contact.j] == 1 else contact.i
        if sim.discs.groups[target] == 1:
            score.append(float(contact.time))
            hit.append(int(sim.ids[target]))
            sim.remove_discs([target])
            if engine == "pic":
                sim._check()

    sim.on("collision", on_hit).run(until=4.0)
    assert hit == [1, 2, 3, 4, 5] and len(sim.discs) == 1
    np.testing.assert_allclose(score, [(2.0 * k + 1.2) / 3.0 for k in range(5)], atol=0.02 if engine == "pit" else 1e-4)
    assert sim.velocities[0, 1] == 0.0 and sim.velocities[0, 0] > 2.99  # the bullet flies on
    removed = sim.events[sim.events["kind"] == REMOVE]
    contacts = ds.contacts(sim)  # named by id, as the log names them
    assert removed["i"].tolist() == hit and np.maximum(contacts.i, contacts.j).tolist() == hit
    assert np.isnan(sim.trajectory([4.0])[0, 1:]).all()


def test_consumers_of_a_fixed_set_of_discs_refuse_a_changed_run(every_backend, tmp_path):
    discs, box = _gas(30)
    sim = ds.EventDriven(discs, box).run(until=0.5)
    sim.remove_discs([4])
    sim.run(until=1.0)
    with pytest.raises(ds.InvalidArgumentError, match="fixed set of discs"):
        ds.frames(sim, [0.5, 1.0])
    with pytest.raises(ds.InvalidArgumentError, match="added or removed"):
        ds.compare(sim, ds.FixedStep(discs, box, dt=0.01).run(until=1.0))
    sampler = ds.Sampler(dt=0.25)
    other = ds.EventDriven(discs, box, record=False).run(until=0.5, observers=[sampler])
    other.remove_discs([0])
    with pytest.raises(ds.InvalidArgumentError, match="Sampler follows a fixed set of discs"):
        other.run(until=1.0, observers=[sampler])
    removing = ds.EventDriven(discs, box, record=False).on("collision", lambda s, c: s.remove_discs([c.j]))
    with pytest.raises(ds.InvalidArgumentError, match="Sampler follows a fixed set of discs"):
        removing.run(until=2.0, observers=[ds.Sampler(dt=0.25)])


# --- property: random sequences keep every invariant --------------------------------------------------------
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    st.lists(
        st.tuples(st.sampled_from(["add", "remove", "run"]), st.integers(0, 10**6), st.floats(0.05, 0.4)),
        min_size=1,
        max_size=8,
    ),
    st.booleans(),
)
def test_random_additions_and_removals_keep_every_invariant(every_backend, actions, periodic):
    discs, box = _gas(30, periodic=periodic, seed=5)
    sim = ds.EventDriven(discs, box)
    alive = list(range(30))  # the id of each disc there, by index (np.delete's rule)
    for what, seed, amount in actions:
        rng = np.random.default_rng(seed)
        if what == "add":
            k = int(rng.integers(1, 4))
            spots = _free_spots(sim, amount / 2, k, seed=seed)
            velocities = rng.normal(size=(k, 2))
            first = sim._next_id
            new = sim.add_discs(ds.Discs(spots, velocities, amount / 2))
            assert new.tolist() == list(range(len(alive), len(alive) + k))
            alive += list(range(first, first + k))
        elif what == "remove" and alive:
            idx = rng.choice(len(alive), size=int(rng.integers(1, min(4, len(alive)) + 1)), replace=False)
            sim.remove_discs(idx)
            alive = [d for k, d in enumerate(alive) if k not in set(idx.tolist())]
        else:
            sim.run(until=sim.time + amount)
        sim._check()
        assert sim.ids.tolist() == alive
    path = sim.trajectory([sim.time])[0]
    np.testing.assert_allclose(path[sim.ids], sim.positions, atol=1e-9)
    assert np.isnan(path[np.setdiff1d(np.arange(len(path)), sim.ids)]).all()
