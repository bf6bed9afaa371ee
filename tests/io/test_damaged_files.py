"""Files under damage and full disks (issue 18, part 4): a damaged log is never appended to, a full disk ends
the command line with one clear line, and a later run names the real reason for the missing events."""

from __future__ import annotations

import errno

import numpy as np
import pytest

import discsim as ds
from discsim.cli import RUN_FILES, main
from discsim.io.container import RecordWriter


class Crash(Exception):
    pass


def _crash_after(time: float):
    def fn(sim, events):
        if sim.time > time:
            raise Crash

    return ds.Callback(fn, every=50)


def _logged_run(tmp_path, until=8.0):
    """A run to ``until`` streaming its log in chunks of 100 events, checkpointed every 150, that crashes at t = 4."""
    sim = ds.EventDriven(*ds.random_gas(60, 0.4, seed=5), record=False)
    sim.stream_chunk = 100
    log, state = tmp_path / "events.dse", tmp_path / "state.dsc"
    with pytest.raises(Crash):
        sim.run(until=until, record_to=log, checkpoint=state, checkpoint_every=150, observers=[_crash_after(4.0)])
    return sim, log, state


def _damage_first_chunk(log) -> None:
    """Flip one byte inside the first chunk of records (after the header)."""
    walk = list(ds.io.container.iter_stream(log))
    header_end, first_end = walk[0][3], walk[1][3]
    data = bytearray(log.read_bytes())
    data[(header_end + first_end) // 2] ^= 0xFF
    log.write_bytes(bytes(data))


def test_resuming_onto_a_log_with_a_damaged_early_chunk_is_refused_and_leaves_it_untouched(tmp_path):
    _, log, state = _logged_run(tmp_path)
    assert len(ds.read_events(log).events) > 200  # several chunks
    _damage_first_chunk(log)
    damaged = log.read_bytes()
    with pytest.raises(ds.CheckpointError, match=r"damaged before byte \d+.*checksum mismatch.*0 records before byte"):
        ds.resume(state)
    assert log.read_bytes() == damaged  # nothing appended, nothing cut
    again = ds.load(state)
    with pytest.raises(ds.CheckpointError, match="damaged"):
        again.run(until=8.0, record_to=log)
    assert log.read_bytes() == damaged
    again.run(until=8.0, record_to=tmp_path / "new.dse")  # a new file goes on from the checkpoint
    assert again.time == 8.0


def test_an_intact_log_still_resumes(tmp_path):
    _, log, state = _logged_run(tmp_path)
    resumed = ds.resume(state)
    straight = ds.EventDriven(*ds.random_gas(60, 0.4, seed=5)).run(until=8.0)
    assert ds.read_events(log).events.tobytes() == straight.events.tobytes()
    assert resumed.time == 8.0


def _full_disk_after(monkeypatch, chunks: int):
    """Make RecordWriter.append fail with ENOSPC after ``chunks`` chunks."""
    real = RecordWriter.append
    calls = {"n": 0}

    def append(self, records, meta=None):
        calls["n"] += 1
        if calls["n"] > chunks:
            raise OSError(errno.ENOSPC, "No space left on device", str(self.path))
        return real(self, records, meta)

    monkeypatch.setattr(RecordWriter, "append", append)


def test_a_full_disk_ends_the_command_line_with_one_clear_line(tmp_path, monkeypatch, capsys):
    out = tmp_path / "run"
    args = ["run", "--n", "150", "--packing", "0.4", "--until", "10", "--seed", "2", "--out", str(out)]
    args += ["--checkpoint-every", "1500", "--no-progress"]
    _full_disk_after(monkeypatch, chunks=2)
    assert main(args) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert "No space left on device" in err and "--resume" in err and str(out) in err
    info = ds.checkpoint_info(out / RUN_FILES["checkpoint"])  # the last checkpoint is whole
    assert not info["run"]["finished"]
    monkeypatch.undo()
    assert main([*args, "--resume"]) == 0  # room again: the run goes on to its end
    straight = tmp_path / "straight"
    assert main([*args[:-4], str(straight), "--checkpoint-every", "1500", "--no-progress"]) == 0
    a, b = ds.load(out / RUN_FILES["checkpoint"]), ds.load(straight / RUN_FILES["checkpoint"])
    assert a.positions.tobytes() == b.positions.tobytes() and a.counts == b.counts
    ea, eb = ds.read_events(out / RUN_FILES["events"]), ds.read_events(straight / RUN_FILES["events"])
    assert ea.events.tobytes() == eb.events.tobytes()


def test_after_a_failed_write_the_missing_events_are_explained(tmp_path, monkeypatch):
    sim = ds.EventDriven(*ds.random_gas(60, 0.4, seed=5), record=False)
    sim.stream_chunk = 100
    log = tmp_path / "events.dse"
    _full_disk_after(monkeypatch, chunks=1)
    with pytest.raises(OSError, match="No space left"):
        sim.run(until=4.0, record_to=log)
    monkeypatch.undo()
    before = sim.state()
    with pytest.raises(
        ds.CheckpointError, match=r"stops \d+ events before the engine \(writing them failed: OSError"
    ) as c:
        sim.run(until=8.0, record_to=log)
    assert "ran without record_to" not in str(c.value)
    after = sim.state()
    assert np.array_equal(before.ref_positions, after.ref_positions) and before.time == after.time
