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


def test_saving_inside_an_observer_keeps_the_engines_own_record_setting(make, tmp_path):
    """The driver records for its observers without touching ``record``: a save mid-run is faithful."""
    path = tmp_path / "mid.dsc"
    sim = make(record=False)
    seen = []
    sim.run(until=2.0, observers=[ds.Callback(lambda s, e: (seen.append(s.record), s.save(path)), every=50)])
    assert seen and not any(seen)
    copy = ds.load(path)
    assert not copy.record and len(copy.events) == 0
    with pytest.raises(ds.InvalidArgumentError, match="record=True"):
        copy.trajectory([copy.time])


def test_an_infinite_until_with_a_count_is_a_count(make):
    sim = make()
    sim.run(until=np.inf, **_limit(sim, 5))
    assert np.isfinite(sim.time) and np.isfinite(sim.positions).all()
    discs = ds.Discs([[2.0, 2.0], [2.0, 7.0]], [[1.0, 0.0], [1.0, 0.0]], radii=0.5)  # never meet
    lonely = ds.EventDriven(discs, ds.Box(10.0, 10.0, periodic=True)).run(until=np.inf, events=5)
    assert lonely.time == 0.0 and np.isfinite(lonely.positions).all()


def test_built_in_observers_passed_by_hand_are_linked_and_resumable(make, tmp_path):
    ck, lg = tmp_path / "c.dsc", tmp_path / "e.dse"
    reference = make(record=False).run(until=2.0)

    class Stop(Exception):
        pass

    def stop_late(sim, events):
        if sim.time > 1.2:
            raise Stop

    sim = make(record=False)
    with pytest.raises(Stop):
        sim.run(until=2.0, observers=[ds.Callback(stop_late, every=20), ds.Checkpointer(ck, 25), ds.EventStream(lg)])
    assert ds.checkpoint_info(ck)["run"]["checkpoint_every"] == 25
    resumed = ds.resume(ck)
    assert resumed.positions.tobytes() == reference.positions.tobytes() and resumed.time == reference.time
    log = ds.read_events(lg)
    assert len(log.events) == resumed._event_count()


def test_a_failing_observer_keeps_the_streamed_events_of_finished_chunks(make, tmp_path):
    lg = tmp_path / "e.dse"
    calls = []

    def third_call_fails(sim, events):
        calls.append(len(events))
        if len(calls) == 3:
            raise RuntimeError("boom")

    sim = make(record=False)
    with pytest.raises(RuntimeError):
        sim.run(until=5.0, record_to=lg, observers=[ds.Callback(third_call_fails, every=10)])
    assert len(ds.read_events(lg).events) == sim._event_count() == sum(calls)
    sim.run(until=5.0, record_to=lg)  # the log goes on
    plain = make().run(until=5.0)
    assert ds.read_events(lg).events.tobytes() == plain.events.tobytes()


def test_a_failing_observer_start_leaves_no_trace(make, tmp_path):
    class Bad(Observer):
        def start(self, engine, plan):
            raise RuntimeError("no")

    sim = make().run(until=1.0)
    lg, ck = tmp_path / "e.dse", tmp_path / "c.dsc"
    with pytest.raises(RuntimeError):
        sim.run(until=2.0, record_to=lg, checkpoint=ck, observers=[Bad()])
    assert not lg.exists() and not ck.exists()
    assert len(sim.events) and sim.time == 1.0  # still in memory, nothing ran


def test_resuming_without_the_runs_log_is_refused(tmp_path):
    ck, lg = tmp_path / "c.dsc", tmp_path / "e.dse"
    sim = ds.EventDriven(*ds.random_gas(60, 0.3, seed=1), record=False)
    sim.run(until=1.0, record_to=lg, checkpoint=ck)
    lg.rename(tmp_path / "moved.dse")
    with pytest.raises(ds.CheckpointError, match="event log is missing"):
        ds.load(ck).run(until=2.0, record_to=lg)


def test_observers_may_not_advance_the_engine(make):
    sim = make()
    with pytest.raises(ds.InvalidArgumentError, match="advance the engine"):
        sim.run(until=2.0, observers=[ds.Callback(lambda s, e: s.step(), every=5)])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"until": True}, "until must be a number"),
        ({"until": "2"}, "until must be a number"),
        ({"until": 1.0, "checkpoint_every": -3}, "checkpoint_every must be a positive integer"),
        ({"until": 1.0, "observers": print}, "observers must be a list"),
        ({"until": 1.0, "record_to": "no/such/folder/e.dse"}, "record_to"),
    ],
)
def test_bad_run_arguments_are_named(make, kwargs, match):
    sim = make()
    with pytest.raises((ds.DiscsimError, FileNotFoundError), match=match):
        sim.run(**kwargs)
    assert sim.time == 0.0


def test_an_exception_inside_the_loop_marks_the_engine_unusable(make, monkeypatch):
    sim = make()
    if sim.unit == "events":
        backend = sim._backend

        def interrupted(*args, **kwargs):
            raise KeyboardInterrupt

        monkeypatch.setattr(backend, "advance", interrupted)
    else:

        def interrupted(*args, **kwargs):
            raise KeyboardInterrupt

        monkeypatch.setattr(sim._policy, "frame", interrupted)
        if hasattr(sim._policy, "frames"):  # the compiled frame does many frames a call
            monkeypatch.setattr(sim._policy, "frames", interrupted)
    with pytest.raises(KeyboardInterrupt):
        sim.run(until=1.0)
    monkeypatch.undo()
    with pytest.raises(ds.DiscsimError, match="interrupted inside its event loop"):
        sim.run(until=2.0)
    with pytest.raises(ds.DiscsimError, match="ds.resume"):
        sim.save("never.dsc")
