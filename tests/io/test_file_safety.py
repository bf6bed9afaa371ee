"""GSD and XYZ files under failure and damage (issue 30, items 2 and 4): a failed write leaves the old file as
it was, and every read returns exactly what was written or raises a DiscsimError naming the file."""

from __future__ import annotations

import contextlib
import importlib
import resource
import signal

import numpy as np
import pytest

import discsim as ds
import discsim.io.gsd as gsd_module


def _have_gsd() -> bool:
    try:
        importlib.import_module("gsd.hoomd")
    except ImportError:
        return False
    return True


needs_gsd = pytest.mark.skipif(not _have_gsd(), reason="needs the gsd package (the io extra)")


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


# --- item 4: every read returns what was written or names what is wrong -------------------------
def _same(a: ds.Frames, b: ds.Frames) -> bool:
    fields = ("times", "positions", "unwrapped", "velocities", "radii", "masses", "groups")
    return a.box == b.box and all(np.array_equal(getattr(a, f), getattr(b, f)) for f in fields)


@pytest.mark.parametrize("kind", KINDS)
def test_single_bit_flips_read_back_equal_or_raise_a_discsim_error(tmp_path, kind):
    path, damaged = tmp_path / f"good.{kind}", tmp_path / f"damaged.{kind}"
    _write(kind, path, _frames())
    data, written = path.read_bytes(), _read(kind, path)
    rng = np.random.default_rng(30)
    outcomes = {"equal": 0, "refused": 0}
    for bit in rng.integers(0, 8 * len(data), size=300).tolist():
        flipped = bytearray(data)
        flipped[bit // 8] ^= 1 << (bit % 8)
        damaged.write_bytes(bytes(flipped))
        try:
            back = _read(kind, damaged)
        except ds.DiscsimError as exc:
            assert str(damaged) in str(exc)
            outcomes["refused"] += 1
        else:
            assert _same(back, written), f"bit {bit} (byte {bit // 8}) reads back changed, silently"
            outcomes["equal"] += 1
    assert outcomes["refused"] > 50  # the flips land in the data, and are found


@pytest.mark.parametrize("kind", KINDS)
def test_a_file_without_discs_reads_back(tmp_path, kind):
    frames = _frames(0)
    back = _read(kind, _write(kind, tmp_path / f"empty.{kind}", frames))
    assert _same(back, frames) and back.positions.shape == (3, 0, 2)


def test_an_xyz_file_edited_by_hand_is_refused_by_its_checksum(tmp_path):
    path = ds.write_xyz(tmp_path / "run.xyz", _frames())
    lines = path.read_text().splitlines()
    row = lines[3].split()
    row[1] = repr(float(row[1]) + 1e-9)
    lines[3] = " ".join(row)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ds.InvalidArgumentError, match=r"frame 0 \(from line 1\) does not match its checksum"):
        ds.read_xyz(path)
    lines[1] = lines[1][: lines[1].index(" discsim_sha256=")]  # no checksum: taken as another tool's file
    path.write_text("\n".join(lines) + "\n")
    assert ds.read_xyz(path).positions[0, 1, 0] == float(row[1])


def test_garbage_in_an_xyz_file_is_named(tmp_path):
    path = ds.write_xyz(tmp_path / "run.xyz", _frames())
    good = path.read_bytes()
    path.write_bytes(good + b"\x00\xff\xfe binary tail")
    with pytest.raises(ds.InvalidArgumentError, match=rf"{path.name} is not a text file .*byte {len(good) + 1}"):
        ds.read_xyz(path)
    path.write_bytes(good + b"some trailing words\n")
    with pytest.raises(ds.InvalidArgumentError, match="should count the discs of frame 3"):
        ds.read_xyz(path)
    path.write_bytes(good.replace(b"Time=0.5", b"Time=0.5x", 1))
    with pytest.raises(ds.InvalidArgumentError, match="frame 1 .*does not match its checksum"):
        ds.read_xyz(path)


@needs_gsd
def test_a_gsd_file_given_to_read_xyz_is_named(tmp_path):
    path = ds.write_gsd(tmp_path / "run.gsd", _frames())
    with pytest.raises(ds.InvalidArgumentError, match="run.gsd is not a text file"):
        ds.read_xyz(path)


@needs_gsd
def test_a_huge_size_in_a_gsd_index_is_refused_before_allocating(tmp_path):
    path = ds.write_gsd(tmp_path / "run.gsd", _frames())
    data = bytearray(path.read_bytes())
    index_at = int.from_bytes(data[8:16], "little")
    data[index_at + 8 : index_at + 16] = (1 << 50).to_bytes(8, "little")  # the first chunk's N: 2^50 rows
    path.write_bytes(bytes(data))
    with pytest.raises(ds.InvalidArgumentError, match=r"run.gsd is damaged: an index entry .* 1125899906842624 x"):
        ds.read_gsd(path)


@needs_gsd
def test_a_gsd_frame_changed_in_place_is_refused_by_its_checksum(tmp_path):
    import gsd.fl

    path = ds.write_gsd(tmp_path / "run.gsd", _frames())
    with gsd.fl.open(str(path), "r") as handle:
        position = handle.read_chunk(frame=1, name="particles/position")
    data = path.read_bytes()
    at = data.index(position.tobytes())
    changed = position.copy()
    changed[2, 0] += 0.25  # a plausible value: nothing but the checksum can tell
    path.write_bytes(data[:at] + changed.tobytes() + data[at + changed.nbytes :])
    with pytest.raises(ds.InvalidArgumentError, match="frame 1 does not match its checksum"):
        ds.read_gsd(path)


@pytest.mark.parametrize("kind", ["checkpoint", "events"])
def test_single_bit_flips_of_a_checkpoint_or_event_log_are_refused(tmp_path, kind):
    """The container files were already safe (a SHA-256 per block); this keeps them so, beside GSD and XYZ."""
    sim = ds.EventDriven(*ds.random_gas(6, 0.2, seed=4), record=False)
    sim.run(until=2.0, record_to=tmp_path / "events.dse", checkpoint=tmp_path / "state.dsc")
    path = tmp_path / ("state.dsc" if kind == "checkpoint" else "events.dse")
    read = ds.load if kind == "checkpoint" else ds.read_events
    data, damaged = path.read_bytes(), tmp_path / f"damaged{path.suffix}"
    rng = np.random.default_rng(31)
    for bit in rng.integers(0, 8 * len(data), size=300).tolist():
        flipped = bytearray(data)
        flipped[bit // 8] ^= 1 << (bit % 8)
        damaged.write_bytes(bytes(flipped))
        with pytest.raises(ds.DiscsimError, match=str(damaged)):
            read(damaged)


@needs_gsd
def test_a_huge_number_of_particles_in_a_gsd_file_is_refused_before_allocating(tmp_path):
    path = ds.write_gsd(tmp_path / "run.gsd", _frames())
    data = path.read_bytes()
    index_at = int.from_bytes(data[8:16], "little")
    entry = [("frame", "<u8"), ("N", "<u8"), ("location", "<i8"), ("M", "<u4"), ("id", "<u2"), ("type", "u1")]
    index = np.frombuffer(data, dtype=np.dtype([*entry, ("flags", "u1")]), count=20, offset=index_at)  # gsd.h
    uint32_scalars = index[(index["frame"] == 0) & (index["type"] == 3) & (index["N"] == 1)]
    at = int(uint32_scalars["location"][0])  # frame 0's only uint32 scalar: particles/N
    assert int.from_bytes(data[at : at + 4], "little") == 6
    huge = (6 + 2**25).to_bytes(4, "little")  # gsd would fill 33 million default rows per array
    path.write_bytes(data[:at] + huge + data[at + 4 :])
    with pytest.raises(
        ds.InvalidArgumentError, match="frame 0 declares 33554438 particles but holds the positions of 6"
    ):
        ds.read_gsd(path)
