"""Long runs (issue 6): save/load, periodic checkpoints and exact resume, streamed event logs, damaged files.

Bit-for-bit means bytes: ``events.tobytes()``, ``positions.tobytes()``, counters and
every float the engine keeps must be identical to a run that never stopped.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

import discsim as ds
import discsim.io.container as dio
from discsim import _numba
from discsim.errors import CheckpointError


# --- helpers ---------------------------------------------------------------------------
def _mixed_table():
    """Discs below and above a segment wall, obstacles, and two groups that pass through each other."""
    rng = np.random.default_rng(11)
    centres = [(x, y) for x in np.arange(2.5, 28.0, 3.0) for y in (*np.arange(2.5, 13.0, 3.0), 18.0, 21.0, 24.5)]
    n = len(centres)
    velocities = rng.normal(size=(n, 2))
    masses = rng.uniform(0.5, 2.0, size=n)
    masses[::7] = np.inf
    velocities[::7] = 0.0
    groups = np.arange(n) % 2
    discs = ds.Discs(centres, velocities, radii=1.0, masses=masses, groups=groups)
    segment = ds.Segment((1.0, 15.5), (29.0, 15.5))
    return ds.EventDriven(discs, ds.Box(30.0, 30.0), segments=[segment], pass_through={(1, 1)})


def _assert_same(a, b):
    """Same state, bit for bit, and the same observable history."""
    assert a.time == b.time
    assert a.positions.tobytes() == b.positions.tobytes()
    assert a.velocities.tobytes() == b.velocities.tobytes()
    assert a.counts == b.counts
    assert a.max_overlap == b.max_overlap
    assert a.max_queue == b.max_queue
    assert a.state().virial == b.state().virial
    if a.time > 0:
        assert a.pressure() == b.pressure()


def _state_bytes(sim) -> bytes:
    """Every array of the engine's internal state, as bytes (clocks, cells, queue...)."""
    scalars, arrays = sim.state().to_arrays()
    return repr(sorted(scalars.items())).encode() + b"".join(v.tobytes() for _, v in sorted(arrays.items()))


# --- save / load -----------------------------------------------------------------------
@pytest.mark.parametrize("queue", ["calendar", "sorted", "heap"])
@pytest.mark.parametrize("periodic", [True, False])
def test_save_load_continues_bit_for_bit(tmp_path, queue, periodic):
    discs, box = ds.random_gas(150, 0.5, periodic=periodic, seed=3)
    a = ds.EventDriven(discs, box, queue=queue).run(events=1500)
    path = a.save(tmp_path / "sim.dsc")
    b = ds.load(path)
    assert b.queue_kind == queue and b.box == box
    assert _state_bytes(a) == _state_bytes(b)
    b._check()
    a.run(events=3000)
    b.run(events=3000)
    assert a.events.tobytes() == b.events.tobytes()  # including the 1500 events before the save
    assert len(a.events) == 4500
    _assert_same(a, b)
    a.run(until=a.time + 1.0)
    b.run(until=b.time + 1.0)
    _assert_same(a, b)
    assert [p.name for p in tmp_path.iterdir()] == ["sim.dsc"]  # no temporary file left behind


def test_save_load_with_segments_obstacles_and_filters(tmp_path):
    a = _mixed_table().run(events=400)
    b = ds.load(a.save(tmp_path / "table.dsc"))
    assert len(b.segments) == 1 and b.pass_through == a.pass_through
    assert b.discs.groups.tolist() == a.discs.groups.tolist()
    assert np.isinf(b.discs.masses[::7]).all()
    a.run(events=800)
    b.run(events=800)
    assert a.events.tobytes() == b.events.tobytes()
    _assert_same(a, b)


def test_save_without_record_and_before_any_event(tmp_path):
    discs, box = ds.random_gas(80, 0.4, seed=5)
    fresh = ds.EventDriven(discs, box, record=False)
    loaded = ds.load(fresh.save(tmp_path / "fresh.dsc"))
    assert loaded.record is False and loaded.time == 0.0
    fresh.run(until=3.0)
    loaded.run(until=3.0)
    _assert_same(fresh, loaded)
    assert len(loaded.events) == 0


def test_save_replaces_atomically_and_a_failed_save_leaves_the_old_file(tmp_path, monkeypatch):
    discs, box = ds.random_gas(60, 0.3, seed=1)
    sim = ds.EventDriven(discs, box).run(until=1.0)
    path = sim.save(tmp_path / "sim.dsc")
    before = path.read_bytes()
    sim.run(until=2.0)

    def broken_replace(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(dio.os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full"):
        sim.save(path)
    monkeypatch.undo()
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["sim.dsc"]
    sim.save(path)  # replacing an existing file is what save() does
    assert ds.checkpoint_info(path)["time"] == 2.0


def test_state_files_hold_no_pickle(tmp_path):
    with pytest.raises(TypeError, match="Python objects"):
        dio.write_state(tmp_path / "x", {}, {"bad": np.array([object()])})
    with pytest.raises(TypeError, match="cannot store"):
        dio.write_state(tmp_path / "x", {"bad": object()}, {})
    assert list(tmp_path.iterdir()) == []


# --- damaged checkpoints ---------------------------------------------------------------
@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    discs, box = ds.random_gas(40, 0.4, seed=2)
    path = tmp_path_factory.mktemp("saved") / "sim.dsc"
    ds.EventDriven(discs, box).run(events=100).save(path)
    return path.read_bytes()


def test_truncated_checkpoints_are_refused(tmp_path, saved):
    path = tmp_path / "cut.dsc"
    for length in (0, 5, 16, 20, 27, 40, len(saved) // 2, len(saved) - 33, len(saved) - 1):
        path.write_bytes(saved[:length])
        with pytest.raises(CheckpointError, match="truncated|not a discsim"):
            ds.load(path)
    path.write_bytes(saved + b"\0")
    with pytest.raises(CheckpointError, match="unexpected bytes"):
        ds.load(path)


def test_every_flipped_byte_region_is_detected(tmp_path, saved):
    path = tmp_path / "flipped.dsc"
    offsets = sorted({*range(0, 40), *range(40, len(saved), max(1, len(saved) // 97)), len(saved) - 1})
    for offset in offsets:
        damaged = bytearray(saved)
        damaged[offset] ^= 0x10
        path.write_bytes(bytes(damaged))
        with pytest.raises(CheckpointError):
            ds.load(path)
    path.write_bytes(saved)
    ds.load(path)  # the undamaged file still loads


def test_a_checkpoint_of_another_format_version_is_refused(tmp_path, monkeypatch):
    discs, box = ds.random_gas(30, 0.3, seed=0)
    monkeypatch.setattr(dio, "FORMAT_VERSION", 2)
    path = ds.EventDriven(discs, box).save(tmp_path / "future.dsc")
    monkeypatch.undo()
    with pytest.raises(CheckpointError, match="format version 2, but this discsim reads version 1"):
        ds.load(path)


def test_a_state_file_that_is_not_a_checkpoint_is_refused(tmp_path):
    path = dio.write_state(tmp_path / "other.dsc", {"engine": "Teleporter"}, {})
    with pytest.raises(CheckpointError, match="not a discsim checkpoint"):
        ds.load(path)
    (tmp_path / "text.dsc").write_text("hello")
    with pytest.raises(CheckpointError, match="not a discsim state file|truncated"):
        ds.load(tmp_path / "text.dsc")


# --- periodic checkpoints and resume -------------------------------------------------------
def test_run_refuses_a_foreign_or_damaged_checkpoint_and_changes_nothing(tmp_path, saved):
    discs, box = ds.random_gas(50, 0.3, seed=4)
    sim = ds.EventDriven(discs, box, record=False)
    foreign = tmp_path / "foreign.dsc"
    foreign.write_bytes(saved)
    with pytest.raises(CheckpointError, match="another run"):
        sim.run(until=1.0, checkpoint=foreign, record_to=tmp_path / "events.dse")
    damaged = tmp_path / "damaged.dsc"
    damaged.write_bytes(saved[:-10])
    with pytest.raises(CheckpointError, match="truncated"):
        sim.run(until=1.0, checkpoint=damaged)
    assert foreign.read_bytes() == saved and damaged.read_bytes() == saved[:-10]
    assert not (tmp_path / "events.dse").exists()
    assert sim.time == 0.0 and sim.counts["collisions"] == 0
    with pytest.raises(FileNotFoundError, match="no folder"):
        sim.run(until=1.0, checkpoint=tmp_path / "missing" / "c.dsc")
    with pytest.raises(ValueError, match="two different files"):
        sim.run(until=1.0, checkpoint=tmp_path / "same", record_to=tmp_path / "same")
    assert not (tmp_path / "same").exists()


@pytest.mark.parametrize("every", [0, -3, 2.5, True])
def test_checkpoint_every_must_be_a_positive_integer(tmp_path, every):
    discs, box = ds.random_gas(20, 0.3, seed=0)
    sim = ds.EventDriven(discs, box)
    with pytest.raises(ValueError, match="checkpoint_every"):
        sim.run(until=1.0, checkpoint=tmp_path / "c.dsc", checkpoint_every=every)
    with pytest.raises(ValueError, match="needs checkpoint"):
        sim.run(until=1.0, checkpoint_every=10)
    assert list(tmp_path.iterdir()) == [] and sim.time == 0.0


def test_periodic_checkpoints_are_taken_every_k_events_and_at_the_end(tmp_path, monkeypatch):
    discs, box = ds.random_gas(100, 0.5, seed=8)
    sim = ds.EventDriven(discs, box, record=False)
    taken = []
    from discsim.run import observers

    original = observers.write_checkpoint

    def spy(engine, path, *, run, record):
        taken.append((engine._units(), run["finished"]))
        original(engine, path, run=run, record=record)

    monkeypatch.setattr(observers, "write_checkpoint", spy)
    sim.run(events=2500, checkpoint=tmp_path / "c.dsc", checkpoint_every=1000)
    assert taken == [(0, False), (1000, False), (2000, False), (2500, True)]
    info = ds.checkpoint_info(tmp_path / "c.dsc")
    assert info["run"]["finished"] and info["counts"] == {k: sim.counts[k] for k in info["counts"]}


class _Crash(Exception):
    """Stands for the process dying: the engine object is abandoned."""


def _crash_after(monkeypatch, flushes: int, garbage: bytes = b""):
    """Make the ``flushes``-th write to the streamed log append ``garbage`` (half a chunk) and die."""
    calls = {"n": 0}
    from discsim.run.observers import EventStream

    original = EventStream.flush

    def flaky(self, engine):
        calls["n"] += 1
        if calls["n"] == flushes:
            self._writer._handle.write(garbage)
            self._writer._handle.flush()
            raise _Crash
        original(self, engine)

    monkeypatch.setattr(EventStream, "flush", flaky)


@pytest.mark.parametrize("record", [True, False])
@pytest.mark.parametrize("limit", ["until", "events"])
def test_a_crashed_run_resumes_to_the_same_end_bit_for_bit(tmp_path, monkeypatch, record, limit):
    discs, box = ds.random_gas(120, 0.55, seed=9)
    goal = {"until": 25.0} if limit == "until" else {"events": 7000}
    reference = ds.EventDriven(discs, box, record=record)
    reference.stream_chunk = 700
    reference.run(**goal, record_to=tmp_path / "ref.dse")

    sim = ds.EventDriven(discs, box, record=record)
    sim.stream_chunk = 700
    log, state = tmp_path / "events.dse", tmp_path / "state.dsc"
    _crash_after(monkeypatch, flushes=9, garbage=b"\x07" * 500)
    with pytest.raises(_Crash):
        sim.run(**goal, record_to=log, checkpoint=state, checkpoint_every=1500)
    monkeypatch.undo()
    info = ds.checkpoint_info(state)
    assert not info["run"]["finished"] and 0 < info["stream"]["records"] < log.stat().st_size / 89
    with pytest.raises(CheckpointError, match="truncated"):
        ds.read_events(log)  # half a chunk at the end

    resumed = ds.resume(state)
    resumed.stream_chunk = 700
    _assert_same(reference, resumed)
    expected, got = ds.read_events(tmp_path / "ref.dse"), ds.read_events(log)
    assert expected.events.tobytes() == got.events.tobytes()
    assert got.end_time == reference.time and got.start_time == 0.0
    assert ds.checkpoint_info(state)["run"]["finished"]
    assert ds.resume(state).positions.tobytes() == reference.positions.tobytes()  # finished: nothing to do


def test_resume_refuses_a_damaged_log_and_leaves_it_untouched(tmp_path, monkeypatch):
    discs, box = ds.random_gas(100, 0.5, seed=12)
    sim = ds.EventDriven(discs, box, record=False)
    sim.stream_chunk = 500
    log, state = tmp_path / "events.dse", tmp_path / "state.dsc"
    _crash_after(monkeypatch, flushes=6)
    with pytest.raises(_Crash):
        sim.run(events=5000, record_to=log, checkpoint=state, checkpoint_every=1200)
    monkeypatch.undo()
    end = ds.checkpoint_info(state)["stream"]["end"]
    data = bytearray(log.read_bytes())
    data[end - 100] ^= 0xFF  # inside the last chunk the checkpoint saw
    log.write_bytes(bytes(data))
    with pytest.raises(CheckpointError, match="checksum"):
        ds.resume(state)
    assert log.read_bytes() == bytes(data)
    log.write_bytes(bytes(data[: end - 1]))
    with pytest.raises(CheckpointError, match="truncated"):
        ds.resume(state)
    with pytest.raises(CheckpointError, match="save\\(\\)"):
        ds.resume(ds.EventDriven(discs, box).save(tmp_path / "plain.dsc"))


_KILLED_RUN = """
import os, signal
import discsim as ds
discs, box = ds.random_gas(300, 0.6, seed=7)
sim = ds.EventDriven(discs, box, record=False)
# SIGKILL from inside, between two checkpoints (every 3000 events), whatever the backend's speed.
kill = ds.Callback(lambda sim, events: sim.counts["collisions"] >= {kill_at} and os.kill(os.getpid(), signal.SIGKILL),
                   every=700)
sim.run(events={events}, record_to={log!r}, checkpoint={state!r}, checkpoint_every=3000, observers=[kill])
"""


@pytest.mark.parametrize("backend", ["python", "numba"])
def test_a_run_killed_with_sigkill_resumes_to_the_same_end(tmp_path, backend):
    if backend == "numba" and not _numba.available():
        pytest.skip("numba is not installed (the fast extra)")
    events = 80_000
    log, state = tmp_path / "events.dse", tmp_path / "state.dsc"
    code = _KILLED_RUN.format(events=events, kill_at=41_000, log=str(log), state=str(state))
    env = {**os.environ, "DISCSIM_NO_NUMBA": "1" if backend == "python" else ""}
    process = subprocess.Popen([sys.executable, "-c", code], stderr=subprocess.PIPE, env=env)
    try:
        _, stderr = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == -signal.SIGKILL, stderr.decode()
    info = ds.checkpoint_info(state)
    assert not info["run"]["finished"] and info["counts"]["collisions"] < events

    resumed = ds.resume(state)
    discs, box = ds.random_gas(300, 0.6, seed=7)
    reference = ds.EventDriven(discs, box, record=False).run(events=events, record_to=tmp_path / "ref.dse")
    _assert_same(reference, resumed)
    assert ds.read_events(log).events.tobytes() == ds.read_events(tmp_path / "ref.dse").events.tobytes()


# --- streamed event logs ---------------------------------------------------------------------
def test_streamed_log_equals_the_in_memory_log(tmp_path):
    discs, box = ds.random_gas(90, 0.45, periodic=False, seed=6)
    memory = ds.EventDriven(discs, box).run(until=4.0)
    streamed = ds.EventDriven(discs, box, record=False)
    streamed.stream_chunk = 300
    streamed.run(until=2.5, record_to=tmp_path / "events.dse", progress=True)
    streamed.run(until=4.0, record_to=tmp_path / "events.dse")  # a second call continues the file
    _assert_same(memory, streamed)
    log = ds.read_events(tmp_path / "events.dse")
    assert log.events.tobytes() == memory.events.tobytes()
    assert (log.start_time, log.end_time, log.box) == (0.0, 4.0, box)
    assert log.discs.positions.tobytes() == discs.positions.tobytes()
    times = np.linspace(0.0, 4.0, 9)
    assert ds.trajectory_from_events(tmp_path / "events.dse", times).tobytes() == memory.trajectory(times).tobytes()
    assert ds.trajectory_from_events(log, [4.0])[0].tobytes() == memory.positions.tobytes()
    with pytest.raises(ds.TimeError, match="outside the logged span"):
        log.trajectory([4.5])
    for refused in (lambda: streamed.events, lambda: streamed.trajectory([1.0])):
        with pytest.raises(ValueError, match="read_events"):
            refused()


def test_a_recorded_engine_streams_its_earlier_events_too(tmp_path):
    discs, box = ds.random_gas(60, 0.4, seed=3)
    memory = ds.EventDriven(discs, box).run(until=3.0)
    sim = ds.EventDriven(discs, box).run(until=1.0)  # record=True: these events are in memory
    sim.run(until=3.0, record_to=tmp_path / "events.dse")
    assert ds.read_events(tmp_path / "events.dse").events.tobytes() == memory.events.tobytes()


def test_a_new_log_started_mid_run_begins_with_a_snapshot(tmp_path):
    discs, box = ds.random_gas(60, 0.4, seed=3)
    memory = ds.EventDriven(discs, box).run(until=3.0)
    sim = ds.EventDriven(discs, box, record=False).run(until=1.0)
    sim.run(until=3.0, record_to=tmp_path / "late.dse")
    log = ds.read_events(tmp_path / "late.dse")
    assert log.start_time == 1.0
    assert np.array_equal(log.events, memory.events[memory.events["time"] > 1.0])
    assert np.allclose(log.trajectory([1.0, 2.0, 3.0]), memory.trajectory([1.0, 2.0, 3.0]), rtol=0, atol=1e-12)


def test_streaming_refuses_foreign_files_and_gaps_without_touching_them(tmp_path):
    discs, box = ds.random_gas(50, 0.4, seed=1)
    other = tmp_path / "other.dse"
    ds.EventDriven(discs, box).run(until=0.5, record_to=other)
    before = other.read_bytes()
    sim = ds.EventDriven(discs, box, record=False)
    with pytest.raises(CheckpointError, match="will not overwrite"):
        sim.run(until=1.0, record_to=other)
    assert sim.time == 0.0
    log = tmp_path / "events.dse"
    sim.run(until=1.0, record_to=log)
    with pytest.raises(CheckpointError, match="another run"):  # a foreign log at the path this run used
        os.replace(log, tmp_path / "mine.dse")
        os.replace(other, log)
        sim.run(until=2.0, record_to=log)
    assert log.read_bytes() == before and sim.time == 1.0
    os.replace(tmp_path / "mine.dse", log)
    sim.run(until=2.0)  # record=False and no record_to: these events reach no log
    size = log.stat().st_size
    with pytest.raises(CheckpointError, match="events before the engine"):
        sim.run(until=3.0, record_to=log)
    assert log.stat().st_size == size and sim.time == 2.0


def test_damaged_logs_are_refused(tmp_path, monkeypatch):
    discs, box = ds.random_gas(80, 0.5, seed=2)
    sim = ds.EventDriven(discs, box, record=False)
    sim.stream_chunk = 400
    path = tmp_path / "events.dse"
    sim.run(events=1900, record_to=path)  # 4 chunks of 400, then 300
    data = path.read_bytes()
    complete = ds.read_events(path)
    assert len(complete.events) == 1900
    cut = tmp_path / "cut.dse"
    cut.write_bytes(data[:-50])
    with pytest.raises(CheckpointError, match="truncated"):
        ds.read_events(cut)
    partial = ds.read_events(cut, partial=True)
    assert len(partial.events) == 1600 and partial.events.tobytes() == complete.events[:1600].tobytes()
    for offset in (3, 17, 200, len(data) // 2, len(data) - 5):
        damaged = bytearray(data)
        damaged[offset] ^= 0x01
        path.write_bytes(bytes(damaged))
        with pytest.raises(CheckpointError):
            ds.read_events(path, partial=True)
    monkeypatch.setattr(dio, "FORMAT_VERSION", 7)
    ds.EventDriven(discs, box).run(until=0.1, record_to=tmp_path / "v7.dse")
    monkeypatch.undo()
    with pytest.raises(CheckpointError, match="format version 7"):
        ds.read_events(tmp_path / "v7.dse")
    saved = ds.EventDriven(discs, box).save(tmp_path / "state.dsc")
    with pytest.raises(CheckpointError, match="not a discsim record stream"):
        ds.read_events(saved)


def test_streaming_keeps_memory_flat(tmp_path):
    """Peak traced memory of a streamed run does not grow with its length; in memory it does."""
    discs, box = ds.random_gas(100, 0.5, seed=1)

    def peak(sim, **run) -> float:
        tracemalloc.start()
        try:
            base = tracemalloc.get_traced_memory()[0]
            sim.run(**run)
            return (tracemalloc.get_traced_memory()[1] - base) / 1e6
        finally:
            tracemalloc.stop()

    short, long = (ds.EventDriven(discs, box, record=False) for _ in range(2))
    short.stream_chunk = long.stream_chunk = 250
    short_mb = peak(short, events=1500, record_to=tmp_path / "short.dse")
    long_mb = peak(long, events=6000, record_to=tmp_path / "long.dse")
    memory_short_mb = peak(ds.EventDriven(discs, box), events=1500)
    memory_mb = peak(ds.EventDriven(discs, box), events=6000)
    assert long_mb < 1.0 and long_mb < short_mb + 0.25, (short_mb, long_mb)
    in_memory = 6000 * ds.EVENT_DTYPE.itemsize / 1e6  # the log's rows: 89 bytes an event
    grown = memory_mb - memory_short_mb  # 4500 more events kept in memory
    assert memory_mb > in_memory and grown > 0.75 * 4500 * ds.EVENT_DTYPE.itemsize / 1e6, (memory_mb, grown)
    assert long_mb - short_mb < 0.25 * grown, (short_mb, long_mb, grown)  # streamed: flat
    assert len(ds.read_events(tmp_path / "long.dse").events) == 6000


def test_the_log_on_disk_costs_about_89_bytes_per_event(tmp_path):
    discs, box = ds.random_gas(100, 0.5, seed=1)
    path = tmp_path / "events.dse"
    ds.EventDriven(discs, box, record=False).run(events=20_000, record_to=path)
    per_event = path.stat().st_size / 20_000
    assert ds.EVENT_DTYPE.itemsize == 89
    assert 89 <= per_event < 89.5, per_event


def test_record_streams_refuse_what_they_cannot_hold(tmp_path):
    dtype = np.dtype([("t", "f8")])
    path = tmp_path / "s.bin"
    with dio.RecordWriter.create(path, dtype, {}, {}) as writer:
        with pytest.raises(TypeError, match="must be"):
            writer.append(np.zeros(3, dtype=[("t", "f4")]))
        writer.append(np.zeros(3, dtype=dtype), {"time": 1.0})
    with pytest.raises(CheckpointError, match="already exists"):
        dio.RecordWriter.create(path, dtype, {}, {})
    stream = dio.read_stream(path)
    assert stream.chunks == 1 and stream.last["time"] == 1.0 and Path(path).stat().st_size == stream.end


def test_save_load_of_a_renumbered_system_continues_bit_for_bit(tmp_path):
    """Large systems are numbered internally tile by tile; a checkpoint keeps that numbering."""
    from discsim.engines.event_driven.numbering import RENUMBER_MIN as _RENUMBER_MIN

    discs, box = ds.random_gas(_RENUMBER_MIN + 500, 0.3, periodic=False, seed=8)
    shuffled = np.random.default_rng(1).permutation(len(discs))
    discs = ds.Discs(discs.positions[shuffled], discs.velocities[shuffled], discs.radii, discs.masses)
    a = ds.EventDriven(discs, box).run(events=3000)
    assert not np.array_equal(a.state().order, np.arange(len(discs)))  # the internal numbering is not the caller's
    b = ds.load(a.save(tmp_path / "big.dsc"))
    assert _state_bytes(a) == _state_bytes(b)
    a.run(events=3000)
    b.run(events=3000)
    assert a.events.tobytes() == b.events.tobytes()
    _assert_same(a, b)


def test_saving_into_a_missing_folder_names_the_path_given(tmp_path):
    sim = ds.EventDriven(*ds.random_gas(20, 0.3, seed=1))
    target = tmp_path / "no" / "such" / "sim.dsc"
    with pytest.raises(FileNotFoundError, match=r"cannot write .*sim\.dsc.*no folder"):
        sim.save(target)
    assert not (tmp_path / "no").exists()


@pytest.mark.parametrize(
    ("field", "damage", "named"),
    [
        ("state.ref_positions", lambda a: a[:-1], "ref_positions"),
        ("state.cell_members", lambda a: np.where(a == a.max(), 10**6, a), "cell_members"),
        ("state.order", lambda a: np.zeros_like(a), "order"),
        ("state.queue_time", lambda a: np.where(np.arange(len(a)) == 0, np.nan, a), "queue_time"),
        ("state.queue_owner", lambda a: a + 10**6, "queue_owner"),
        ("state.cell", lambda a: (a + 1) % a.max(), "cell"),
    ],
)
def test_a_crafted_checkpoint_with_a_valid_checksum_is_refused_by_name(tmp_path, field, damage, named):
    """Arrays that do not fit together are refused when loading, not later in the loop (issue 18, part 4)."""
    path = tmp_path / "sim.dsc"
    ds.EventDriven(*ds.random_gas(60, 0.4, seed=2)).run(events=300).save(path)
    meta, arrays = dio.read_state(path)
    arrays[field] = damage(arrays[field])
    dio.write_state(path, meta, arrays)  # a fresh, valid checksum over the damaged arrays
    with pytest.raises(CheckpointError, match=named):
        ds.load(path)


def test_a_crafted_checkpoint_with_a_nan_time_is_refused(tmp_path):
    path = tmp_path / "sim.dsc"
    ds.EventDriven(*ds.random_gas(60, 0.4, seed=2)).run(events=300).save(path)
    meta, arrays = dio.read_state(path)
    meta["state"]["time"] = float("nan")
    dio.write_state(path, meta, arrays)
    with pytest.raises(CheckpointError, match="time"):
        ds.load(path)
