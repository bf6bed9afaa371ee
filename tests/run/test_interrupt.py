"""Ctrl-C during a run stops at a whole event (or frame): the engine stays consistent and goes on exactly.

The reproduction of issue 18: a SIGINT sent to the process in the middle of ``run(until=...)``.
"""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

import discsim as ds
from discsim import _numba

ENGINES = {
    "event_driven": lambda: ds.EventDriven(*ds.random_gas(2000, 0.4, seed=1), backend="python"),
    "event_driven-numba": lambda: ds.EventDriven(*ds.random_gas(2000, 0.4, seed=1), backend="numba"),
    "fixed_step": lambda: ds.FixedStep(*ds.random_gas(2000, 0.4, seed=1), dt=0.001, backend="python"),
    "fixed_step-numba": lambda: ds.FixedStep(*ds.random_gas(2000, 0.4, seed=1), dt=0.001, backend="numba"),
}
# Long enough that the interrupt, 0.3 s in, falls inside the run: a few seconds under each backend on a quiet machine.
UNTIL = {"event_driven": 40.0, "event_driven-numba": 2000.0, "fixed_step": 3.0, "fixed_step-numba": 150.0}


def _interrupt_after(seconds: float) -> threading.Timer:
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(ENGINES))
def test_ctrl_c_leaves_a_consistent_engine_that_goes_on_bit_for_bit(name):
    if name.endswith("numba") and not _numba.available():
        pytest.skip("numba is not installed (the fast extra)")
    until = UNTIL[name]
    reference = ENGINES[name]().run(until=until)
    sim = ENGINES[name]()
    timer = _interrupt_after(0.3)
    with pytest.raises(KeyboardInterrupt) as caught:
        sim.run(until=until)
    timer.join()
    assert isinstance(caught.value, ds.Interrupted)
    assert 0.0 < sim.time < until and sim.counts[sim.rate_count] > 0
    if name.startswith("event_driven"):
        sim._check()
        assert len(sim.events) == sim._event_count()
    sim.run(until=until)
    assert sim.time == reference.time
    assert sim.positions.tobytes() == reference.positions.tobytes()
    assert sim.events.tobytes() == reference.events.tobytes()
    assert sim.counts == reference.counts


@pytest.mark.slow  # 8 s: a run of a second or more, interrupted
def test_a_program_handler_of_sigint_still_gets_the_signal(monkeypatch):
    """Deferred to the end of the event, handed to the handler the program installed, and the run goes on."""
    got = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: got.append(signum))
    try:
        sim = ds.EventDriven(*ds.random_gas(500, 0.3, seed=2))
        until = 150.0 if sim.backend == "python" else 15_000.0  # a run of a second or more under either backend
        timer = _interrupt_after(0.2)
        start = time.perf_counter()
        sim.run(until=until)  # no exception: the program's handler took the signal
        assert time.perf_counter() - start > 0.2  # the signal came during the run
        timer.join()
    finally:
        signal.signal(signal.SIGINT, previous)
    assert got == [signal.SIGINT]
    reference = ds.EventDriven(*ds.random_gas(500, 0.3, seed=2)).run(until=until)
    assert sim.time == until and sim.positions.tobytes() == reference.positions.tobytes()  # it went on


def test_off_the_main_thread_runs_are_unaffected():
    result = {}

    def work():
        result["sim"] = ds.EventDriven(*ds.random_gas(100, 0.3, seed=3)).run(until=2.0)

    worker = threading.Thread(target=work)
    worker.start()
    worker.join()
    assert result["sim"].time == 2.0


@pytest.mark.parametrize("how", ["raise KeyboardInterrupt", "SIGINT during a slow callback"])
@pytest.mark.parametrize("where", ["sim.on", "observer"])
def test_ctrl_c_in_a_callback_raises_interrupted_and_the_run_goes_on_exactly(every_backend, how, where):
    """Issue 30, item 12: Ctrl-C in a callback (between two whole events) raised a plain KeyboardInterrupt, not
    ``ds.Interrupted`` as the README says. The engine is consistent there and goes on bit for bit."""
    discs, box = ds.random_gas(40, 0.3, seed=2)
    reference = ds.EventDriven(discs, box).run(until=4.0)
    sim = ds.EventDriven(discs, box)
    calls, timers = [], []

    def slow(s, *_):
        calls.append(s.time)
        if len(calls) == 5:
            if how.startswith("raise"):
                raise KeyboardInterrupt
            timers.append(_interrupt_after(0.05))
            time.sleep(10.0)  # the signal cuts it short

    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt) as caught:
        if where == "sim.on":
            sim.on("collision", slow).run(until=4.0)
        else:
            sim.run(until=4.0, observers=[ds.Callback(slow, every=1)])
    assert time.perf_counter() - start < 5.0
    for timer in timers:
        timer.join()
    assert isinstance(caught.value, ds.Interrupted), type(caught.value)
    assert isinstance(caught.value.__cause__, KeyboardInterrupt)  # the original, kept
    assert sim._broken is None and sim.time == calls[-1] < 4.0
    sim._check()
    sim.run_context.handlers.clear()
    sim.run(until=4.0)
    assert sim.positions.tobytes() == reference.positions.tobytes()
    assert sim.events.tobytes() == reference.events.tobytes()
    assert sim.counts == reference.counts
