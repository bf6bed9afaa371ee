"""GSD and XYZ files under failure and damage (issue 30, items 2 and 4): a failed write leaves the old file as
it was, and every read returns exactly what was written or raises a DiscsimError naming the file."""

from __future__ import annotations

import contextlib
import importlib.util
import resource
import signal

import numpy as np
import pytest

import discsim as ds
import discsim.io.gsd as gsd_module

needs_gsd = pytest.mark.skipif(importlib.util.find_spec("gsd") is None, reason="the gsd package (io extra)")


def _frames(n: int = 6, times=(0.0, 0.5, 1.0)) -> ds.Frames:
    if n:
        discs, box = ds.random_gas(n, 0.2, seed=4)
    else:
        discs, box = ds.Discs(np.zeros((0, 2)), np.zeros((0, 2)), 1.0), ds.Box(10.0, 8.0)
    return ds.frames(ds.EventDriven(discs, box).run(until=max(times)), list(times))


def _write(kind: str, path, source):
    return (ds.write_gsd if kind == "gsd" else ds.write_xyz)(path, source)


def _read(kind: str, path) -> ds.Frames:
    return (ds.read_gsd if kind == "gsd" else ds.read_xyz)(path)


KINDS = [pytest.param("gsd", marks=needs_gsd), "xyz"]


@contextlib.contextmanager
def _disk_full_after(size: int):
    """Writes that pass byte ``size`` of a file fail with EFBIG, as on a full disk (the process file size limit)."""
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    previous = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (size, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
        signal.signal(signal.SIGXFSZ, previous)


# --- item 2: a failed write leaves the old file -------------------------------------------------
@pytest.mark.parametrize("kind", KINDS)
def test_a_write_that_fills_the_disk_midway_leaves_the_old_file(tmp_path, kind):
    path = tmp_path / f"run.{kind}"
    _write(kind, path, _frames(4, (0.0,)))
    old = path.read_bytes()
    with pytest.raises(OSError), _disk_full_after(len(old) + 200):
        _write(kind, path, _frames(40, (0.0, 0.5, 1.0, 1.5)))  # several times as long
    assert path.read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]  # no temporary file left
    assert _read(kind, path).n == 4


@needs_gsd
def test_an_exception_midway_through_write_gsd_leaves_the_old_file(tmp_path, monkeypatch):
    path = tmp_path / "run.gsd"
    ds.write_gsd(path, _frames())
    old = path.read_bytes()
    frame_of = gsd_module._gsd_frame

    def fail_at_frame_one(frames, k, step):
        if k == 1:
            raise RuntimeError("midway")
        return frame_of(frames, k, step)

    monkeypatch.setattr(gsd_module, "_gsd_frame", fail_at_frame_one)
    with pytest.raises(RuntimeError, match="midway"):
        ds.write_gsd(path, _frames(8))
    assert path.read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.gsd"]
