"""ds.Compression: compression as an engine run by the driver (epochs, progress, observers, checkpoints, Ctrl-C)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import discsim as ds
from discsim import _numba
from discsim.engines.compress.engine import Compression

needs_numba = pytest.mark.skipif(not _numba.available(), reason="numba is not installed or is hidden")
BACKENDS = ["python", pytest.param("numba", marks=needs_numba)]


def _same(a: ds.Discs, b: ds.Discs) -> bool:
    return all(np.array_equal(getattr(a, k), getattr(b, k)) for k in ("positions", "velocities", "radii"))


def _setup(periodic=True):
    gas, box = ds.random_gas(80, 0.3, seed=7, periodic=periodic)
    return gas, box, 0.72


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("periodic", [True, False])
def test_run_to_the_end_is_compress_and_epochs_at_a_time_change_nothing(backend, periodic):
    gas, box, target = _setup(periodic)
    dense, report = ds.compress(gas, box, target, seed=3, backend=backend)
    whole = Compression(gas, box, target, seed=3, backend=backend).run()
    assert whole.finished and whole.report.reason == "reached" == report.reason
    assert _same(whole.snapshot(), dense)
    assert whole.counts == {"collisions": report.collisions, "wall_events": report.wall_events, "epochs": report.epochs}
    assert np.array_equal(whole.report.history["packing"], report.history["packing"])
    pieces = Compression(gas, box, target, seed=3, backend=backend)
    steps = 0
    while not pieces.finished:
        pieces.run(epochs=3) if steps % 2 else pieces.step()
        steps += 1
    assert _same(pieces.snapshot(), dense) and pieces.time == whole.time
    assert pieces.run(epochs=5).counts["epochs"] == report.epochs  # nothing left to do
    assert pieces.report.reason == "reached"


def test_the_state_between_epochs_is_a_valid_start_and_unwrapped_positions_follow_the_discs():
    gas, box, target = _setup()
    c = Compression(gas, box, target, seed=3, backend="python").run(epochs=4)
    assert c.report.reason == "running" and not c.finished and c.counts["epochs"] == 4
    assert 0.3 < c.report.packing_fraction < target
    ds.EventDriven(c.snapshot(), box)  # no overlap: the snapshot shrinks what roundoff left inside
    assert np.allclose(box.wrap(c.unwrapped_positions), c.positions, rtol=0, atol=1e-9)
    assert np.isclose(c.kinetic_energy(), len(gas) * 1.0)  # velocities at kT = 1
    assert "so far" in str(c.report)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_checkpointed_compression_resumes_bit_for_bit(backend, tmp_path):
    gas, box, target = _setup(periodic=False)
    whole = Compression(gas, box, target, seed=3, backend=backend).run()
    path = tmp_path / "compress.dsc"
    part = Compression(gas, box, target, seed=3, backend=backend)
    part.run(epochs=7, checkpoint=path, checkpoint_every=2)
    assert ds.checkpoint_info(path)["run"]["events"] == 7
    loaded = ds.load(path)
    assert isinstance(loaded, Compression) and loaded.counts == part.counts and loaded.time == part.time
    assert _same(loaded.snapshot(), part.snapshot())
    resumed = ds.resume(path)  # the run asked for 7 epochs and did them: finished
    assert resumed.counts["epochs"] == 7
    assert _same(loaded.run().snapshot(), whole.snapshot())
    assert loaded.report.history.tolist()[-1][:2] == whole.report.history.tolist()[-1][:2]
    # a run to the end, checkpointed, stopped by an exception half-way, then resumed
    path2 = tmp_path / "to_end.dsc"
    stopped = Compression(gas, box, target, seed=3, backend=backend)

    def stop_at_ten(engine, events):
        if engine.counts["epochs"] >= 10:
            raise RuntimeError("stop")

    with pytest.raises(RuntimeError):
        stopped.run(checkpoint=path2, checkpoint_every=5, observers=[stop_at_ten])
    assert ds.checkpoint_info(path2)["run"]["finished"] is False
    assert _same(ds.resume(path2).snapshot(), whole.snapshot())


def test_progress_shows_the_way_to_the_target_and_observers_see_every_epoch(capsys):
    gas, box, target = _setup()
    seen = []
    c = Compression(gas, box, target, seed=3, backend="python")
    c.run(progress=True, observers=[lambda engine, events: seen.append(engine.counts["epochs"])])
    assert sorted(set(seen)) == list(range(1, c.counts["epochs"] + 1))  # and once more as the run ends
    err = capsys.readouterr().err
    assert "100" in err and "%" in err


@pytest.mark.parametrize("backend", BACKENDS)
def test_ctrl_c_stops_after_the_epoch_under_way_and_the_compression_goes_on_exactly(backend, monkeypatch):
    gas, box, target = _setup()
    whole = Compression(gas, box, target, seed=3, backend=backend).run()
    c = Compression(gas, box, target, seed=3, backend=backend)
    epoch = Compression._epoch

    def interrupted_epoch(self):
        if self.counts["epochs"] == 3:
            os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C in the middle of the fourth epoch
        epoch(self)

    monkeypatch.setattr(Compression, "_epoch", interrupted_epoch)
    with pytest.raises(ds.Interrupted):
        c.run()
    assert c.counts["epochs"] == 4  # the fourth finished, nothing more
    monkeypatch.setattr(Compression, "_epoch", epoch)
    assert _same(c.run().snapshot(), whole.snapshot())


def test_what_a_compression_cannot_do_is_refused_and_changes_nothing(tmp_path):
    gas, box, target = _setup()
    c = Compression(gas, box, target, seed=3, backend="python").run(epochs=2)
    before = c.state()
    for call, words in [
        (lambda: c.run(until=5.0), "runs by epochs"),
        (lambda: c.run(record_to=tmp_path / "log.dse"), "no event log"),
        (lambda: c.run(epochs=2, events=3), "not both"),
        (lambda: c.run(epochs=-1), "epochs"),
        (lambda: c.set_velocities([0], [[1.0, 0.0]]), "cannot set velocities"),
        (lambda: c.apply_impulse([0], [1.0, 0.0]), "cannot apply impulses"),
        (lambda: c.set_positions([0], [[1.0, 1.0]]), "cannot set positions"),
        (lambda: c.add_discs(ds.Discs([[1.0, 1.0]], [[0.0, 0.0]], 0.1)), "cannot add discs"),
        (lambda: c.remove_discs([0]), "cannot remove discs"),
        (lambda: c.on("collision", print), "cannot follow events"),
        (lambda: c.trajectory([0.0]), "cannot give trajectories"),
    ]:
        with pytest.raises(ds.DiscsimError, match=words):
            call()
    after = c.state()
    assert all(np.array_equal(getattr(before, k), getattr(after, k)) for k in ("positions", "velocities", "radii"))
    assert after.epochs == 2 and not c.run_context.handlers


def test_a_target_at_which_a_disc_spans_a_walled_box_is_refused():
    one = ds.Discs([[3.0, 0.5]], [[1.0, 0.0]], 0.5)  # spans the channel already
    with pytest.raises(ds.PackingError, match=r"disc 0 would grow to a diameter of 1\.12838, not less than"):
        Compression(one, ds.Box(10, 1), 0.1)
    two = ds.Discs([[3.0, 0.5], [6.0, 0.5]], [[1.0, 0.0], [0.0, 1.0]], [0.3, 0.2])
    with pytest.raises(ds.PackingError, match="disc 0 would grow"):
        ds.compress(two, ds.Box(10, 1), 0.12)


def test_discs_wedged_across_a_channel_end_the_compression_as_a_jam():
    """Issue 30, item 6: these never returned (max_collisions and, under numba, Ctrl-C ignored); now each ends.

    Run in a child process with a time limit, so that a regression fails instead of hanging the suite.
    """
    script = textwrap.dedent(
        """
        import discsim as ds
        from discsim import _numba
        backends = ["python"] + (["numba"] if _numba.available() else [])
        cases = [
            (ds.Discs([[3, 0.25], [3, 0.75]], [[1, 0], [-1, 0]], 0.25), 0.05),  # a touching column
            (ds.Discs([[3, 0.25], [3, 0.75]], [[0, 0.1], [0, -0.1]], 0.2), 0.0475),  # will wedge
        ]
        for backend in backends:
            for discs, target in cases:
                _, report = ds.compress(discs, ds.Box(10, 1), target, max_collisions=100000, backend=backend)
                print(backend, report.reason, report.packing_fraction < target)
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120, env={**os.environ}
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.split("\n")
    assert [line.split()[1:] for line in lines if line] == [["jammed", "True"]] * (len([x for x in lines if x]))
    assert len([x for x in lines if x]) in (2, 4)
