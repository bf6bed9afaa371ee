"""The in-memory event log (issue 18, part 6b): compact arrays, about 89 bytes an event, and cheap appends."""

from __future__ import annotations

import random
import tracemalloc

import numpy as np
import pytest

import discsim as ds
from discsim.events import EVENT_DTYPE, EventLog


def _row(k: int) -> tuple:
    return (k * 0.5, 0, k % 97, k % 89 + 100, *(k + 0.25 * m for m in range(8)))


def test_the_log_holds_about_one_record_of_89_bytes_per_event():
    """It held 360 bytes an event (a list of tuples of floats) and ``events`` built a further copy."""
    n = 130_000  # blocks of 1024, 1024, 2048, ..., 65536 rows hold 131,072
    tracemalloc.start()
    try:
        log = EventLog()
        before = tracemalloc.get_traced_memory()[0]
        for k in range(n):
            log.collision(k * 0.5, k % 97, k + 100, k + 0.25, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0)
        held = (tracemalloc.get_traced_memory()[0] - before) / n
        array = log.to_array()
        again = log.to_array()
        after = (tracemalloc.get_traced_memory()[0] - before) / n
    finally:
        tracemalloc.stop()
    assert EVENT_DTYPE.itemsize == 89
    assert held < 89 * 1.3, held  # rows in blocks, one block partly filled, a thousand pending tuples
    assert after < 89 * 1.3 * 1.1, after  # to_array joined the blocks in their place: no second copy kept
    assert not array.flags.writeable and np.shares_memory(array, again)
    assert array["i"][:3].tolist() == [0, 1, 2] and len(array) == n


@pytest.mark.slow
def test_the_log_behaves_as_a_list_of_records():
    """collision, wall, extend, since, clear, len and to_array against a plain list, at random."""
    rng = random.Random(1)
    ref: list[tuple] = []
    log = EventLog()
    held, held_copy = log.to_array(), log.to_array().copy()
    for step in range(5_000):
        r = rng.random()
        if r < 0.45:
            row = _row(step)
            log.collision(row[0], row[2], row[3], *row[4:])
            ref.append(row)
        elif r < 0.9:
            log.wall(step * 1.0, step, 1.0, 2.0, 3.0, 4.0)
            ref.append((step * 1.0, 1, step, -1, 1.0, 2.0, 3.0, 4.0, *[np.nan] * 4))
        elif r < 0.95:
            records = np.zeros(rng.randrange(0, 5_000), EVENT_DTYPE)
            records["time"], records["i"] = step, np.arange(len(records))
            log.extend(records)
            ref.extend(tuple(x) for x in records.tolist())
        elif r < 0.97:
            assert held.tobytes() == held_copy.tobytes()  # arrays handed out never change
            held, held_copy = log.to_array(), log.to_array().copy()
            assert held.tobytes() == np.array(ref, dtype=EVENT_DTYPE).tobytes()
        elif r < 0.99:
            start = rng.randrange(0, len(ref) + 2)
            assert log.since(start).tobytes() == np.array(ref[start:], dtype=EVENT_DTYPE).tobytes()
        elif r < 0.992:
            log.clear()
            ref.clear()
        assert len(log) == len(ref)
    assert log.to_array().tobytes() == np.array(ref, dtype=EVENT_DTYPE).tobytes()
    assert held.tobytes() == held_copy.tobytes()


def test_extend_of_a_structured_array_is_one_byte_copy():
    """A compiled backend appends chunks of records: a million rows in well under a second (was ~0.9 s)."""
    import time

    chunk = np.zeros(16_384, EVENT_DTYPE)
    chunk["time"] = np.arange(len(chunk))
    log = EventLog()
    start = time.process_time()
    for _ in range(61):
        log.extend(chunk)
    assert time.process_time() - start < 0.5
    assert (log.to_array()["time"].reshape(61, -1) == chunk["time"]).all()


def test_an_engine_log_is_read_only_and_matches_a_fresh_run():
    discs, box = ds.random_gas(50, 0.3, seed=4)
    sim = ds.EventDriven(discs, box).run(until=5.0)
    events = sim.events
    assert not events.flags.writeable
    sim.run(until=10.0)
    assert sim.events[: len(events)].tobytes() == events.tobytes()
    assert ds.EventDriven(discs, box).run(until=10.0).events.tobytes() == sim.events.tobytes()
