"""sim.on("collision" | "wall" | "segment", fn) (issue 19, part 2): callbacks that may change the run."""

from __future__ import annotations

import numpy as np
import pytest

import discsim as ds
from discsim.events import SET


def test_a_game_scores_and_stops_each_hit_target(every_backend):
    # A striker (0) at the bottom, three targets on its line; each hit target is stopped dead and scored.
    discs = ds.Discs([[5.0, 1.0], [5.0, 4.0], [5.0, 6.5], [5.0, 9.0]], [[0.0, 1.0], [0, 0], [0, 0], [0, 0]], 0.5)
    sim = ds.EventDriven(discs, ds.Box(10.0, 10.0))
    score, seen = [], []

    def hit(sim, contact):
        seen.append((contact.time, sim.time, sim.velocities.copy()))
        target = contact.j if contact.i == 0 else contact.i
        score.append(target)
        sim.set_velocities([target], [[0.0, 0.0]])

    sim.on("collision", hit).run(until=30.0)
    sim._check()
    assert score[:1] == [1]
    assert all(t == now for t, now, _ in seen)  # each callback sees the state right after its event
    assert (sim.events["kind"] == SET).sum() == len(score)
    # The log stays exact: positions rebuilt after every change match a replay of the recorded log.
    times = np.linspace(0.0, 30.0, 31)
    path = sim.trajectory(times)
    np.testing.assert_allclose(path[-1], sim.positions, atol=1e-9)


def test_callbacks_change_nothing_when_they_only_look(every_backend):
    discs, box = ds.random_gas(100, 0.3, periodic=False, seed=4)
    plain = ds.EventDriven(discs, box).run(until=2.0)
    kinds = []
    watched = ds.EventDriven(discs, box)
    watched.on("collision", lambda sim, c: kinds.append(c.kind)).on("wall", lambda sim, c: kinds.append(c.kind))
    watched.run(until=2.0)
    assert plain.events.tobytes() == watched.events.tobytes()
    assert len(kinds) == len(plain.events)
    c = ds.contacts(plain)
    assert kinds == c.kind.tolist()


def test_contact_data_in_the_callback_match_contacts(every_backend):
    discs, box = ds.random_gas(60, 0.3, periodic=True, seed=5)
    got = []
    sim = ds.EventDriven(discs, box).on("collision", lambda sim, c: got.append(c)).run(until=1.0)
    c = ds.contacts(sim)
    assert len(got) == len(c)
    np.testing.assert_array_equal([g.impulse for g in got], c.impulse)
    np.testing.assert_array_equal([g.normal for g in got], c.normal)


def test_segment_callback_and_fixed_step(every_backend):
    seg = ds.Segment([6.0, 0.0], [6.0, 10.0])
    discs = ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], radii=0.5)
    hits = []
    ds.EventDriven(discs, ds.Box(10.0, 10.0), segments=[seg]).on("segment", lambda s, c: hits.append(c.time)).run(
        until=5.0
    )
    assert hits == [3.5]
    walls = []
    pit = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.25)
    pit.on("wall", lambda s, c: (walls.append(c.surface), s.apply_impulse([0], [0.0, 1.0]))).run(until=20.0)
    assert walls[:2] == [-2, -4]  # right wall, then (pushed up by 1) the top before the left


@pytest.mark.parametrize("kind", ["collisions", "crossing", "set", 3, None])
def test_unknown_kinds_are_refused(kind):
    sim = ds.EventDriven(*ds.random_gas(10, 0.2, seed=1))
    with pytest.raises(ds.InvalidArgumentError, match=repr(kind)):
        sim.on(kind, print)
    with pytest.raises(ds.InvalidArgumentError, match="callable"):
        sim.on("wall", 3)


NESTED = {
    "run(events=3)": lambda sim: sim.run(events=3),
    "run(until=)": lambda sim: sim.run(until=sim.time + 1.0),
    "step()": lambda sim: sim.step(),
}


@pytest.mark.parametrize("nested", sorted(NESTED))
@pytest.mark.parametrize("how", ["sim.on", "observer"])
def test_a_callback_that_advances_the_engine_is_refused_before_anything_changes(every_backend, nested, how):
    """Issue 30, item 9: ``sim.run(events=3)`` in a ``sim.on`` callback served the same callbacks again, down to a
    RecursionError that left the engine marked broken; in an observer it (and ``step()``) ran before the driver
    noticed. Now each is refused at once: nothing changes, and the run goes on exactly."""
    discs, box = ds.random_gas(30, 0.3, seed=3)
    reference = ds.EventDriven(discs, box).run(until=5.0)
    sim = ds.EventDriven(discs, box)
    seen = []

    def advance(s, *_):
        seen.append((s.time, s.counts, s.positions.tobytes()))
        NESTED[nested](s)

    with pytest.raises(ds.InvalidArgumentError, match=r"step\(\) or run\(\) inside a run is refused"):
        if how == "sim.on":
            sim.on("collision", advance).run(until=5.0)
        else:
            sim.run(until=5.0, observers=[ds.Callback(advance, every=1)])
    assert len(seen) == 1 and sim._broken is None
    time, counts, positions = seen[0]
    assert (sim.time, sim.counts, sim.positions.tobytes()) == (time, counts, positions)  # nothing changed
    sim._check()
    sim.run_context.handlers.clear()
    sim.run(until=5.0)
    assert sim.positions.tobytes() == reference.positions.tobytes()
    assert sim.events.tobytes() == reference.events.tobytes()


# --- callbacks that only look: changes=False (issue 28, item 5) ------------------------------------------------
def _contacts_seen(sim, until, changes):
    seen = []
    sim.on("collision", lambda s, c: seen.append(c), changes=changes)
    sim.on("wall", lambda s, c: seen.append(c), changes=changes)
    sim.run(until=until)
    return seen


def test_look_only_callbacks_see_every_contact_of_the_exact_ones_and_change_nothing(every_backend):
    discs, box = ds.random_gas(120, 0.35, periodic=False, seed=6)
    plain = ds.EventDriven(discs, box, record=False).run(until=3.0)
    exact = _contacts_seen(ds.EventDriven(discs, box, record=False), 3.0, changes=True)
    looking = ds.EventDriven(discs, box, record=False)
    seen = _contacts_seen(looking, 3.0, changes=False)
    assert len(seen) == len(exact) == plain.counts["collisions"] + plain.counts["wall_hits"] > 100
    for a, b in zip(seen, exact):
        assert (a.time, a.kind, a.i, a.j, a.surface) == (b.time, b.kind, b.i, b.j, b.surface)
        np.testing.assert_allclose(a.point, b.point, rtol=0, atol=1e-12)
        assert a.impulse == pytest.approx(b.impulse, rel=1e-12) and a.speed == pytest.approx(b.speed, rel=1e-12)
    assert looking.positions.tobytes() == plain.positions.tobytes()


def test_look_only_callbacks_run_in_chunks_and_exact_ones_stop_at_every_event(every_backend):
    discs, box = ds.random_gas(200, 0.3, seed=2)
    chunks = []
    sim = ds.EventDriven(discs, box, record=False)
    sim.on("collision", lambda s, c: chunks.append(s.time), changes=False).run(events=3000)
    assert len(chunks) == 3000 and len(set(chunks)) <= 2  # the chunks' ends, not the events' times
    both = ds.EventDriven(discs, box, record=False)
    order = []
    both.on("collision", lambda s, c: order.append(("look", s.time == c.time)), changes=False)
    both.on("collision", lambda s, c: order.append(("exact", s.time == c.time)))
    both.run(events=50)
    assert order == [("look", True), ("exact", True)] * 50  # with an exact one, every event stops the run


def test_a_look_only_callback_that_changes_the_run_is_refused_by_name(every_backend):
    discs, box = ds.random_gas(60, 0.3, seed=3)
    sim = ds.EventDriven(discs, box)

    def push(sim, contact):
        sim.apply_impulse([contact.i], [0.0, 1.0])

    sim.on("collision", push, changes=False)
    with pytest.raises(ds.InvalidArgumentError, match=r"sim.on\('collision', .*push, changes=False\) changed"):
        sim.run(events=500)
    sim._check()


def test_changes_takes_true_or_false():
    sim = ds.EventDriven(ds.Discs([[2.0, 2.0]], [[1.0, 0.0]], 0.5), ds.Box(10, 5))
    with pytest.raises(ds.InvalidArgumentError, match="changes=...\\) takes True or False, got 'no'"):
        sim.on("wall", print, changes="no")
    assert not sim.run_context.handlers
