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
