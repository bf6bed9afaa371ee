"""The one run driver and its observers (discsim.run): chunks change nothing, observers see every event once."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import discsim as ds
from discsim.run.observers import Observer

ENGINES = {
    "event_driven": lambda record=True: ds.EventDriven(*ds.random_gas(120, 0.4, seed=3), record=record),
    "fixed_step": lambda record=True: ds.FixedStep(*ds.random_gas(120, 0.4, seed=3), dt=0.01, record=record),
}


def _limit(sim, count: int) -> dict:
    return {"frames" if sim.unit == "frames" else "events": count}


@pytest.fixture(params=sorted(ENGINES))
def make(request):
    return ENGINES[request.param]


@pytest.mark.parametrize("every", [1, 7, 1000])
def test_callbacks_see_every_event_once_and_change_nothing(make, every):
    plain = make().run(until=2.0)
    seen, times = [], []

    def callback(sim, events):
        seen.append(events)
        times.append(sim.time)

    watched = make().run(until=2.0, observers=[ds.Callback(callback, every=every)])
    assert watched.events.tobytes() == plain.events.tobytes()
    assert watched.positions.tobytes() == plain.positions.tobytes() and watched.time == plain.time
    assert np.concatenate(seen).tobytes() == plain.events.tobytes()
    assert times == sorted(times) and times[-1] == 2.0
    if every == 1 and watched.unit == "events":
        assert all(len(chunk) <= 1 for chunk in seen)


def test_a_plain_callable_is_an_observer_and_record_false_keeps_no_log(make):
    reference = make().run(until=1.5)
    chunks = []
    sim = make(record=False).run(until=1.5, observers=[lambda sim, events: chunks.append(events)])
    assert len(sim.events) == 0 and not sim.record  # recorded for the observer only, then dropped
    assert np.concatenate(chunks).tobytes() == reference.events.tobytes()


def test_an_observer_sees_the_run_plan_and_the_end(make):
    calls = []

    class Spy(Observer):
        def start(self, engine, plan):
            calls.append(("start", plan.until, plan.limit, plan.unit))

        def finish(self, engine, completed):
            calls.append(("finish", completed))

    sim = make()
    sim.run(until=1.0, observers=[Spy()])
    sim.run(observers=[Spy()], **_limit(sim, 5))
    assert calls == [("start", 1.0, None, sim.unit), ("finish", True), ("start", None, 5, sim.unit), ("finish", True)]


def test_an_exception_in_an_observer_leaves_the_engine_usable_and_record_restored(make):
    class Boom(Exception):
        pass

    def explode(sim, events):
        if sim.time > 0.5:
            raise Boom

    sim = make(record=False)
    with pytest.raises(Boom):
        sim.run(until=2.0, observers=[ds.Callback(explode, every=3)])
    assert sim.record is False
    t = sim.time
    assert 0.5 < t < 2.0
    sim.run(until=2.0)  # it goes on from where the observer stopped it
    assert sim.time == 2.0


def test_bad_observers_and_limits_are_refused_before_anything_runs(make):
    sim = make()
    with pytest.raises(ds.InvalidArgumentError, match=r"observers\[0\]"):
        sim.run(until=1.0, observers=[42])
    with pytest.raises(ds.InvalidArgumentError, match="every must be a positive integer"):
        ds.Callback(print, every=0)
    with pytest.raises(ds.InvalidArgumentError, match="needs until"):
        sim.run()
    with pytest.raises(ds.TimeError, match="never ends"):
        sim.run(until=np.inf)
    assert sim.time == 0.0


def test_ds_plot_is_imported_lazily():
    code = "import sys, discsim as ds; assert 'matplotlib' not in sys.modules; ds.plot.plot_state; print('ok')"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "ok"
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        ds.nothing  # noqa: B018
