"""Event logs read chunk by chunk (ds.iter_events): the same records and positions as the whole log, bit for bit,
without ever loading the whole file (trajectory_from_events, frames and view of a streamed log)."""

from __future__ import annotations

import numpy as np
import pytest

import discsim as ds
from discsim.io import container
from discsim.trajectory import LastRecords, replay


def _streamed(tmp_path, *, periodic=True, until=6.0, chunk=40, edit=False):
    """A gas streamed in chunks of ``chunk`` events (many chunks), and the same run kept in memory."""
    discs, box = ds.random_gas(60, 0.3, periodic=periodic, seed=5)
    path = tmp_path / "events.dse"
    runs = []
    for record_to in (path, None):
        sim = ds.EventDriven(discs, box, record=record_to is None)
        sim.stream_chunk = chunk
        if edit:  # discs leave and come: ADD and REMOVE records, ids
            sim.run(until=until / 3, record_to=record_to)
            sim.remove_discs([3, 7])
            sim.add_discs(ds.Discs(_free_spot(sim, 0.3), [[0.7, 0.2]], 0.3))
            sim.run(until=2 * until / 3, record_to=record_to)
            sim.remove_discs([0])
        sim.run(until=until, record_to=record_to)
        runs.append(sim)
    return path, runs[1]


def _free_spot(sim, radius):
    """A place ``(1, 2)`` for a disc of ``radius``, clear of every disc of ``sim`` and of the walls."""
    rng, box = np.random.default_rng(0), sim.box
    while True:
        p = rng.uniform(radius, [box.width - radius, box.height - radius])
        d = box.minimum_image(sim.positions - p)
        if (np.hypot(d[:, 0], d[:, 1]) > (sim.discs.radii + radius) * 1.01).all():
            return p[None]


def _forbid_whole_reads(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the whole log was read into memory")

    monkeypatch.setattr(container, "read_stream", refuse)
    monkeypatch.setattr(ds.io.streams, "read_stream", refuse)


@pytest.mark.parametrize("edit", [False, True])
def test_the_chunks_hold_the_log_and_each_replays_exactly_from_its_before_state(tmp_path, edit):
    path, _ = _streamed(tmp_path, edit=edit)
    whole = ds.read_events(path)
    log = ds.iter_events(path, chunk=10)
    assert (log.records, log.end_time, log.start_time) == (len(whole.events), whole.end_time, 0.0)
    chunks = list(log)
    assert len(chunks) > 10 and max(len(c.records) for c in chunks) <= 10
    assert np.concatenate([c.records for c in chunks]).tobytes() == whole.events.tobytes()
    assert [c.first for c in chunks] == np.cumsum([0] + [len(c.records) for c in chunks[:-1]]).tolist()
    for c in chunks[::3]:  # a chunk and where the log stood before it give the positions in its span
        t = np.linspace(c.records["time"][0], c.records["time"][-1], 4)
        mine = replay([c.records], c.before, t, log.box)
        expected = whole.trajectory(t)
        assert mine.tobytes() == expected[:, : mine.shape[1]].tobytes()
        assert np.isnan(expected[:, mine.shape[1] :]).all()  # discs added later
    late = list(ds.iter_events(path, start=4.0))
    assert late[0].records["time"][0] >= 4.0
    assert np.concatenate([c.records for c in late]).tobytes() == whole.events[whole.events["time"] >= 4.0].tobytes()


@pytest.mark.parametrize("unwrapped", [False, True])
@pytest.mark.parametrize("edit", [False, True])
def test_trajectory_from_events_reads_chunk_by_chunk_and_gives_the_same_bits(tmp_path, monkeypatch, unwrapped, edit):
    path, memory = _streamed(tmp_path, edit=edit)
    times = [5.9, 0.0, 0.37, 2.0, 2.0 + 1e-9, 4.2, 6.0]
    expected = memory.trajectory(times, unwrapped=unwrapped)
    _forbid_whole_reads(monkeypatch)
    got = ds.trajectory_from_events(path, times, unwrapped=unwrapped)
    assert got.shape == expected.shape and got.tobytes() == expected.tobytes()


def test_frames_of_a_streamed_log_read_it_chunk_by_chunk_and_match_the_log_in_memory(tmp_path, monkeypatch):
    path, memory = _streamed(tmp_path, periodic=True)
    times = np.linspace(0.0, 6.0, 13)
    expected = ds.frames(memory, times)
    _forbid_whole_reads(monkeypatch)
    got = ds.frames(path, times)
    for name in ("positions", "unwrapped", "velocities"):
        assert getattr(got, name).tobytes() == getattr(expected, name).tobytes(), name


def test_the_before_state_of_a_walled_log_with_ties_matches_the_whole_log(tmp_path):
    case = ds.newtons_cradle(5)  # chains of contacts at one time: ties in time, kept in log order
    path = tmp_path / "cradle.dse"
    sim = ds.EventDriven(case.discs, case.box, record=False)
    sim.stream_chunk = 1
    sim.run(until=case.until, record_to=path)
    whole = ds.read_events(path)
    origin = LastRecords.at_start(whole.discs, whole.start_time)
    times = np.unique(np.concatenate([whole.events["time"], np.linspace(0, whole.end_time, 9)]))
    chunked = replay((c.records for c in ds.iter_events(path, chunk=1)), origin, times, whole.box)
    assert chunked.tobytes() == whole.trajectory(times).tobytes()


def test_a_bad_chunk_size_or_start_is_refused_by_name(tmp_path):
    path, _ = _streamed(tmp_path, until=0.5)
    for bad in (0, -3, 2.5, True):
        with pytest.raises(ds.InvalidArgumentError, match="chunk must be a positive integer"):
            ds.iter_events(path, chunk=bad)
    for bad in (float("nan"), float("inf"), "1.0"):
        with pytest.raises(ds.InvalidArgumentError, match="start must be a finite time"):
            ds.iter_events(path, start=bad)
