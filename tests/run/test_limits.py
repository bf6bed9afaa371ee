"""One spelling of "no limit" past the public edge: the engine gets a float stop time (inf: none) and an int
count (None: none), whatever the user wrote, with or without observers."""

from __future__ import annotations

import math

import numpy as np
import pytest

import discsim as ds
from discsim.run.driver import run_limits

SPELLINGS = [
    ({"until": 2.0}, (2.0, None)),
    ({"until": 2}, (2.0, None)),
    ({"events": 5}, (math.inf, 5)),
    ({"until": None, "events": 5.0}, (math.inf, 5)),
    ({"until": math.inf, "events": 5}, (math.inf, 5)),
    ({"until": np.inf, "events": np.int64(5)}, (math.inf, 5)),
    ({"until": 2.0, "events": 5}, (2.0, 5)),
]


@pytest.mark.parametrize(("asked", "expected"), SPELLINGS)
def test_run_limits_has_one_spelling(asked, expected):
    stop, limit = run_limits(asked.get("until"), asked.get("events"), 0.0, "events")
    assert (stop, limit) == expected
    assert type(stop) is float and (limit is None or type(limit) is int)


@pytest.mark.parametrize("engine", ["EventDriven", "FixedStep"])
@pytest.mark.parametrize("observed", [False, True])
@pytest.mark.parametrize(("asked", "expected"), SPELLINGS)
def test_the_engine_gets_the_one_spelling(engine, observed, asked, expected, monkeypatch):
    discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], 1.0)
    sim = getattr(ds, engine)(discs, ds.Box(10.0, 10.0))
    calls = []
    advance = sim._advance

    def spy(until, limit):
        calls.append((until, limit))
        return advance(until, limit)

    monkeypatch.setattr(sim, "_advance", spy)
    plans = []

    class Plan(ds.Observer):
        def start(self, engine, plan):
            plans.append(plan)

    sim.run(**asked, observers=[Plan()] if observed else [])
    stop, limit = expected
    assert calls and all(until == stop and type(until) is float for until, _ in calls)
    counts = [k for _, k in calls]
    assert all(k is None or type(k) is int for k in counts)
    if limit is not None:
        assert None not in counts
    elif not observed:
        assert counts == [None]  # one call of the engine's loop
    if observed:
        (plan,) = plans
        assert plan.until == (None if stop == math.inf else stop) and plan.limit == limit
        assert plan.stop == stop


def test_no_limit_at_all_is_refused_in_every_spelling():
    sim = ds.EventDriven(ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], 1.0), ds.Box(10.0, 10.0))
    with pytest.raises(ds.InvalidArgumentError, match="needs until"):
        sim.run(until=None, events=None)
    with pytest.raises(ds.TimeError, match="never ends"):
        sim.run(until=math.inf)
    with pytest.raises(ds.InvalidArgumentError, match="non-negative integer"):
        sim.run(events=-1)  # -1 is no spelling of "no limit" in the public API
    with pytest.raises(ds.InvalidArgumentError, match="non-negative integer"):
        sim.run(events=math.inf)
    assert sim.time == 0.0


def test_a_fixed_step_engine_asked_for_no_limit_refuses():
    sim = ds.FixedStep(ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], 1.0), ds.Box(10.0, 10.0))
    with pytest.raises(ds.InvalidArgumentError, match="finite until or a frame count"):
        sim._advance(math.inf, None)
    assert sim._advance(math.inf, 3) == 3 and sim.frames == 3
    assert sim._advance(0.2, None) == 3 and sim.frames == 6  # frames 4, 5, 6 at 0.133, 0.167, 0.2
