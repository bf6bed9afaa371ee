"""An engine's run bookkeeping lives in ``engine.run_context`` (engines/context.py)."""

from __future__ import annotations

import numpy as np
import pytest

import discsim as ds
from discsim.engines.context import RunContext


def _pair(engine: str = "EventDriven", **options):
    discs = ds.Discs([[2.0, 5.0], [5.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [0.0, 0.0], [-1.0, 0.0]], 0.5)
    return getattr(ds, engine)(discs, ds.Box(10.0, 10.0), **options)


def test_a_new_context_holds_nothing_yet():
    context = RunContext(3)
    assert len(context.log) == 0 and not context.recording and not context.streamed
    assert context.run_id is None and context.stream is None and context.ids is None
    assert context.next_id == 3 and context.origin is None and context.structure == 0 and context.handlers == {}
    first = context.ensure_run_id()
    assert len(first) == 32 and context.ensure_run_id() == first == context.run_id


def test_set_ids_keeps_none_while_the_ids_are_the_indices():
    context = RunContext(3)
    discs = ds.Discs([[1.0, 1.0]], [[0.0, 0.0]], 0.5)
    context.set_ids(np.arange(3), 5, (discs, None))
    assert context.ids is None and context.next_id == 5 and context.log_origin(discs)[0] is discs
    context.set_ids(np.array([0, 2, 7]), 8, (discs, None))
    assert context.ids.tolist() == [0, 2, 7] and not context.ids.flags.writeable and context.log.ids is context.ids


@pytest.mark.parametrize("engine", ["EventDriven", "FixedStep"])
def test_the_engine_keeps_its_bookkeeping_in_its_context(engine, tmp_path):
    sim = _pair(engine)
    context = sim.run_context
    assert context.log_origin(sim.discs) == (sim.discs, None)
    sim.on("collision", lambda sim, contact: None)
    assert list(context.handlers) == ["collision"]
    first = sim.discs
    sim.remove_discs([1])
    assert context.structure == 1 and context.ids.tolist() == [0, 2] and sim.ids.tolist() == [0, 2]
    assert context.next_id == 3 and context.origin[0] is first
    sim.run(until=2.0, record_to=tmp_path / "events.dse", checkpoint=tmp_path / "state.dsc")
    assert context.streamed and context.stream["path"] == str((tmp_path / "events.dse").absolute())
    assert context.run_id == context.stream["run_id"] and not context.recording
    copy = ds.load(tmp_path / "state.dsc")
    assert copy.run_context.run_id == context.run_id
    assert {k: copy.run_context.stream[k] for k in ("path", "run_id", "base")} == {
        k: context.stream[k] for k in ("path", "run_id", "base")
    }
    assert copy.ids.tolist() == [0, 2] and copy.run_context.next_id == 3 and copy.run_context.structure == 0
    with pytest.raises(ds.InvalidArgumentError, match="streamed its event log"):
        copy.events  # noqa: B018


def test_the_driver_records_for_its_observers_only_during_the_run():
    sim = _pair(record=False)
    seen = []

    def look(engine, events):
        seen.append(engine.run_context.recording)

    sim.run(until=1.0, observers=[look])
    assert seen and all(seen) and not sim.run_context.recording and len(sim.run_context.log) == 0
