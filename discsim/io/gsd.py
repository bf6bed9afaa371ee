"""GSD files (the format of HOOMD-blue, read by OVITO, freud and MDAnalysis): write and read discsim frames.

Needs the ``gsd`` package (``pip install discsim[io]``), imported when a function is called.

The layout, in HOOMD's schema (``gsd.hoomd``), one GSD frame per sample time:

- ``configuration.box = [W, H, 0, 0, 0, 0]`` and ``configuration.dimensions = 2`` (HOOMD's 2D convention:
  ``Lz = 0``; a file with ``Lz = 1`` and ``dimensions = 2`` reads too); ``configuration.step`` is the frame's
  index.
- ``particles.position``: HOOMD centres its box on the origin, discsim's is ``[0, W] x [0, H]``: discsim writes
  ``(x - W / 2, y - H / 2, 0)`` and reads back ``x + W / 2``. ``particles.image``: the periodic images crossed
  since the run's start (HOOMD's unwrapped position is ``position + image * L``), so unwrapped paths survive.
- ``particles.velocity`` ``(vx, vy, 0)``, ``particles.diameter`` ``2 r``, ``particles.mass`` (``inf`` for an
  obstacle), ``particles.types`` the group labels as strings and ``particles.typeid`` each disc's group.
- ``log/discsim/time``: the simulated time (float64); ``log/discsim/periodic``: 1 for a periodic box, 0 for
  walls (HOOMD has no walled box; other readers see a periodic one). ``log/discsim/sha256``: the SHA-256 of what
  :func:`read_gsd` takes from the frame and the frame's place in the file (32 bytes; see below).

GSD itself keeps no checksums: a damaged byte in a GSD file's data reads back as another number. discsim writes
a checksum with each frame, and :func:`read_gsd` refuses a frame that does not match it; it also checks the
file's index against the file's size before anything is allocated. A GSD file written by another tool (or with
its checksum entries removed) cannot be checked that way: it is read as it stands.

GSD stores these in single precision (float32), as HOOMD does: positions come back to about ``1e-7 L``.
"""

from __future__ import annotations

import hashlib
import struct
from pathlib import Path

import numpy as np

from discsim.analysis.frames import Frames
from discsim.errors import DiscsimError, InvalidArgumentError
from discsim.io.container import replacing
from discsim.model import Box, image_steps

#: The log entry that holds each frame's SHA-256 (``log/discsim/sha256``, 32 bytes), checked by :func:`read_gsd`.
CHECKSUM = "discsim/sha256"

__all__ = ["append_frames", "open_gsd", "read_gsd", "require_gsd", "write_gsd"]


def require_gsd():
    """The ``gsd.hoomd`` module.

    Raises:
        ModuleNotFoundError: naming the extra that installs it.
    """
    try:
        import gsd.hoomd
    except ModuleNotFoundError as exc:
        msg = "GSD files need the gsd package: pip install 'discsim[io]' (or pip install gsd)"
        raise ModuleNotFoundError(msg) from exc
    return gsd.hoomd


def open_gsd(path, mode: str):
    """``gsd.hoomd.open(path, mode)`` (``"w"`` to create, ``"a"`` to append)."""
    return require_gsd().open(str(path), mode)


def _gsd_frame(frames: Frames, k: int, step: int):
    hoomd = require_gsd()
    box = frames.box
    size = np.array([box.width, box.height])
    n = frames.n
    frame = hoomd.Frame()
    frame.configuration.box = [box.width, box.height, 0.0, 0.0, 0.0, 0.0]
    frame.configuration.dimensions = 2
    frame.configuration.step = int(step)
    position = np.zeros((n, 3))
    position[:, :2] = frames.positions[k] - 0.5 * size
    image = np.zeros((n, 3), dtype=np.int32)
    if box.periodic:
        image[:, :2] = image_steps(frames.unwrapped[k], frames.positions[k], size).astype(np.int32)
    velocity = np.zeros((n, 3))
    velocity[:, :2] = frames.velocities[k]
    labels = np.unique(frames.groups)
    frame.particles.N = n
    frame.particles.position = position.astype(np.float32)
    frame.particles.image = image
    frame.particles.velocity = velocity.astype(np.float32)
    frame.particles.diameter = (2.0 * frames.radii).astype(np.float32)
    frame.particles.mass = frames.masses.astype(np.float32)
    frame.particles.types = [str(g) for g in labels.tolist()] or ["0"]  # gsd needs a type, even for no disc
    frame.particles.typeid = np.searchsorted(labels, frames.groups).astype(np.uint32)
    frame.log["discsim/time"] = np.array([frames.times[k]], dtype=np.float64)
    frame.log["discsim/periodic"] = np.array([int(box.periodic)], dtype=np.uint8)
    frame.log[CHECKSUM] = _frame_digest(frame, step)
    return frame


def _frame_digest(frame, index: int) -> np.ndarray:
    """``(32,)`` uint8: the SHA-256 of what :func:`read_gsd` takes from ``frame``, the frame ``index`` of its file.

    The index is part of it, so that a frame whose chunks went missing (GSD then repeats frame 0's) is caught.
    """
    config, particles, log = frame.configuration, frame.particles, frame.log
    digest = hashlib.sha256()
    numbers = (index, int(config.dimensions), int(particles.N), list(particles.types))
    digest.update(repr(numbers).encode())
    for value, dtype in (
        (config.box, "<f4"),
        (particles.position, "<f4"),
        (particles.image, "<i4"),
        (particles.velocity, "<f4"),
        (particles.diameter, "<f4"),
        (particles.mass, "<f4"),
        (particles.typeid, "<u4"),
        (log.get("discsim/time", ()), "<f8"),
        (log.get("discsim/periodic", ()), "u1"),
    ):
        array = np.ascontiguousarray(value, dtype=dtype)
        digest.update(repr(array.shape).encode())
        digest.update(array.tobytes())
    return np.frombuffer(digest.digest(), dtype=np.uint8).copy()


def append_frames(handle, frames: Frames, written: int = 0) -> int:
    """Append every frame of ``frames`` to an open GSD file; return the frames it then holds (``written`` before)."""
    for k in range(len(frames)):
        handle.append(_gsd_frame(frames, k, written))
        written += 1
    return written


def _as_frames(source, times=None) -> Frames:
    if isinstance(source, Frames):
        if times is not None:
            msg = "times= selects times of a run; a Frames is written whole"
            raise InvalidArgumentError(msg)
        return source
    if hasattr(source, "snapshot") and hasattr(source, "box"):
        if times is None:
            return Frames.from_discs(source.snapshot(), source.box, source.time, source.unwrapped_positions)
        from discsim.analysis.frames import frames

        return frames(source, times)
    msg = f"expected a Frames or an engine, got {type(source).__name__}"
    raise InvalidArgumentError(msg)


def write_gsd(path, source, times=None) -> Path:
    """Write discs to a GSD file (created, or replaced), one GSD frame per time.

    Args:
        path: the file.
        source: a :class:`~discsim.analysis.frames.Frames` (from :func:`discsim.frames`, a
            :class:`discsim.Sampler` or a reader), or an engine: its state now, or at ``times`` (rebuilt
            from its event log).
        times: with an engine, the simulated times to write.

    Returns:
        The path written, as a :class:`~pathlib.Path`.

    Raises:
        ModuleNotFoundError: without the ``gsd`` package.
        InvalidArgumentError: on another ``source``, or ``times`` with a Frames.

    Example:
        >>> import os, tempfile, discsim as ds
        >>> sim = ds.EventDriven(*ds.random_gas(30, 0.3, seed=1)).run(until=1.0)
        >>> path = ds.write_gsd(os.path.join(tempfile.mkdtemp(), "gas.gsd"), sim, times=[0.0, 0.5, 1.0])
        >>> back = ds.read_gsd(path)
        >>> back.times.tolist(), bool(abs(back.positions - ds.frames(sim, [0.0, 0.5, 1.0]).positions).max() < 1e-5)
        ([0.0, 0.5, 1.0], True)
    """
    frames = _as_frames(source, times)
    path = Path(path)
    require_gsd()
    with replacing(path) as tmp, open_gsd(tmp, "w") as handle:
        append_frames(handle, frames)
    return path


def read_gsd(path) -> Frames:
    """Read a GSD file of 2D discs (written by discsim, HOOMD-blue or another tool) as Frames.

    Positions move from HOOMD's centred box back to ``[0, W] x [0, H]``; radii are half the diameters of the
    first frame, groups the type names when they are integers (else the type ids). Unwrapped positions use
    ``particles.image``; times come from ``log/discsim/time`` (else the step); the box is periodic unless
    ``log/discsim/periodic`` says walls.

    Raises:
        ModuleNotFoundError: without the ``gsd`` package.
        FileNotFoundError: if there is no such file.
        InvalidArgumentError: naming the file, if it is not a GSD file of HOOMD's schema, holds no frame, holds
            3D data (``dimensions = 3`` or a nonzero z), a tilted box, or frames whose number of discs changes;
            or if it is damaged: an index that points past its end, a number of particles that frame 0's
            positions do not bear out, a frame that does not match the checksum discsim wrote with it, chunks
            gsd cannot read.
    """
    hoomd = require_gsd()
    path = Path(path)
    if not path.is_file():
        msg = f"no GSD file at {str(path)!r}"
        raise FileNotFoundError(msg)
    _check_layout(path)
    try:
        _check_counts(path)
        handle = hoomd.open(str(path), "r")
    except DiscsimError:
        raise
    except Exception as exc:  # gsd raises RuntimeError, OSError or ValueError on a foreign file
        msg = f"{path} is not a GSD file of HOOMD's schema ({type(exc).__name__}: {exc})"
        raise InvalidArgumentError(msg) from exc
    try:
        with handle:
            return _read_frames(handle, path)
    except DiscsimError:
        raise
    except Exception as exc:  # what gsd and numpy raise on damaged chunks: RuntimeError, KeyError, ValueError, ...
        msg = f"{path} is damaged: its frames cannot be read ({type(exc).__name__}: {exc})"
        raise InvalidArgumentError(msg) from exc


def _read_frames(handle, path: Path) -> Frames:
    if len(handle) == 0:
        msg = f"{path} holds no frame"
        raise InvalidArgumentError(msg)
    first = handle[0]
    checked = CHECKSUM in first.log or f"log/{CHECKSUM}" in handle.file.find_matching_chunk_names("log/")
    box = _read_box(first, path)
    n = int(first.particles.N)
    size = np.array([box.width, box.height])
    types = list(first.particles.types)
    names = [int(t) if t.lstrip("-").isdigit() else None for t in types]
    typeid = np.asarray(first.particles.typeid, dtype=np.int64)
    if typeid.shape != (n,) or np.any((typeid < 0) | (typeid >= len(types))):
        msg = f"{path}: frame 0's particles.typeid do not name its {len(types)} types"
        raise InvalidArgumentError(msg)
    groups = np.array([names[t] for t in typeid], dtype=np.int64) if None not in names else typeid.copy()
    radii = 0.5 * np.asarray(first.particles.diameter, dtype=float)
    masses = np.asarray(first.particles.mass, dtype=float)
    times, positions, unwrapped, velocities = [], [], [], []
    for k, frame in enumerate(handle):
        if checked:
            _verify(frame, k, path)
        if int(frame.particles.N) != n:
            msg = f"{path}: frame {k} holds {int(frame.particles.N)} particles, frame 0 holds {n}"
            raise InvalidArgumentError(msg)
        if _read_box(frame, path) != box:
            msg = f"{path}: the box of frame {k} differs from frame 0's; discsim frames share one box"
            raise InvalidArgumentError(msg)
        pos = np.asarray(frame.particles.position, dtype=float).reshape(n, 3)
        if np.any(pos[:, 2] != 0.0):
            msg = f"{path} holds 3D data: frame {k} has particles off the plane z = 0"
            raise InvalidArgumentError(msg)
        xy = pos[:, :2] + 0.5 * size
        image = np.asarray(frame.particles.image, dtype=float).reshape(n, 3)[:, :2]
        log = frame.log
        step = float(frame.configuration.step)
        time = float(np.asarray(log["discsim/time"]).ravel()[0]) if "discsim/time" in log else step
        times.append(time)
        positions.append(box.wrap(xy))
        unwrapped.append(xy + image * size)
        velocities.append(np.asarray(frame.particles.velocity, dtype=float).reshape(n, 3)[:, :2])
    shape = (len(times), n, 2)
    return Frames(
        np.array(times),
        np.array(positions).reshape(shape),
        np.array(unwrapped).reshape(shape),
        np.array(velocities).reshape(shape),
        box,
        radii.reshape(n),
        masses.reshape(n),
        groups,
    )


def _verify(frame, k: int, path: Path) -> None:
    """Check frame ``k`` against the checksum discsim wrote with it."""
    stored = frame.log.get(CHECKSUM)
    if stored is None:
        msg = f"{path} is damaged: frame {k} has lost the checksum ({CHECKSUM}) that discsim writes with each frame"
        raise InvalidArgumentError(msg)
    if not np.array_equal(np.asarray(stored).ravel(), _frame_digest(frame, k)):
        msg = f"{path} is damaged: frame {k} does not match its checksum ({CHECKSUM}); it reads back changed"
        raise InvalidArgumentError(msg)


#: GSD's file header (``struct gsd_header`` of gsd.h): magic, index location and entries, name list location
#: and entries, schema version, GSD version, application, schema, reserved.
_HEADER = struct.Struct("<QQQQQII64s64s80s")
_MAGIC = 0x65DF65DF65DF65DF
#: One index entry (``struct gsd_index_entry``): where a chunk of a frame lies, its N x M values and their type.
_INDEX = np.dtype(
    [("frame", "<u8"), ("N", "<u8"), ("location", "<i8"), ("M", "<u4"), ("id", "<u2"), ("type", "u1"), ("flags", "u1")]
)
_NAME_SIZE = 64
#: Bytes of one value of each GSD type (uint8 ... double, character).
_TYPE_SIZES = np.array([0, 1, 2, 4, 8, 1, 2, 4, 8, 4, 8, 1], dtype=np.float64)


def _check_counts(path: Path) -> None:
    """Refuse a number of particles that the file's positions do not bear out, before gsd fills arrays that long.

    discsim frames share their discs: every ``particles/N`` must equal frame 0's, which holds their positions.
    """
    import gsd.fl

    with gsd.fl.open(str(path), "r") as handle:
        if handle.nframes == 0:
            return
        n = int(handle.read_chunk(0, "particles/N")[0]) if handle.chunk_exists(0, "particles/N") else 0
        has_rows = handle.chunk_exists(0, "particles/position")
        rows = len(handle.read_chunk(0, "particles/position")) if has_rows else 0
        if rows != n:
            msg = f"{path}: frame 0 declares {n} particles but holds the positions of {rows}"
            raise InvalidArgumentError(msg)
        for k in range(1, handle.nframes):
            if handle.chunk_exists(k, "particles/N") and int(handle.read_chunk(k, "particles/N")[0]) != n:
                msg = f"{path}: frame {k} holds {int(handle.read_chunk(k, 'particles/N')[0])} particles, frame 0 {n}"
                raise InvalidArgumentError(msg)


def _check_layout(path: Path) -> None:
    """Refuse a GSD file whose header or index point past its end, before gsd allocates what they claim.

    A damaged size field would otherwise make gsd allocate up to petabytes.
    """
    size = path.stat().st_size
    with open(path, "rb") as handle:
        raw = handle.read(_HEADER.size)
        if len(raw) < _HEADER.size or _HEADER.unpack(raw)[0] != _MAGIC:
            msg = f"{path} is not a GSD file (no GSD header: {size} bytes, wrong leading bytes)"
            raise InvalidArgumentError(msg)
        _, index_at, index_count, names_at, names_count, *_ = _HEADER.unpack(raw)
        for what, at, count, width in (
            ("index", index_at, index_count, _INDEX.itemsize),
            ("name list", names_at, names_count, _NAME_SIZE),
        ):
            if at < _HEADER.size or at + count * width > size:
                msg = (
                    f"{path} is damaged: its {what} ({count} entries at byte {at}) lies outside the file ({size} bytes)"
                )
                raise InvalidArgumentError(msg)
        handle.seek(index_at)
        index = np.frombuffer(handle.read(index_count * _INDEX.itemsize), dtype=_INDEX)
    used = index[index["location"] != 0]
    kinds = used["type"].astype(np.int64)
    bad_type = (kinds < 1) | (kinds >= len(_TYPE_SIZES))
    nbytes = used["N"].astype(np.float64) * used["M"].astype(np.float64) * _TYPE_SIZES[np.where(bad_type, 0, kinds)]
    location = used["location"]
    bad = bad_type | (location < _HEADER.size) | (location + nbytes > size)
    bad[1:] |= used["frame"][1:] < used["frame"][:-1]
    if len(used) and int(used["frame"][-1]) >= len(used):  # every frame holds a chunk, at least its step
        msg = f"{path} is damaged: its index names frame {int(used['frame'][-1])} but holds {len(used)} chunks"
        raise InvalidArgumentError(msg)
    if bad.any():
        entry = used[np.flatnonzero(bad)[0]]
        msg = (
            f"{path} is damaged: an index entry of frame {int(entry['frame'])} claims {int(entry['N'])} x "
            f"{int(entry['M'])} values of type {int(entry['type'])} at byte {int(entry['location'])}, which the "
            f"file ({size} bytes) cannot hold, or is out of order"
        )
        raise InvalidArgumentError(msg)


def _read_box(frame, path) -> Box:
    dims = int(frame.configuration.dimensions)
    lx, ly, lz, xy, xz, yz = (float(v) for v in frame.configuration.box)
    if dims != 2:
        msg = f"{path} holds 3D data (configuration.dimensions = {dims}, Lz = {lz}); discsim reads 2D files only"
        raise InvalidArgumentError(msg)
    if xy or xz or yz:
        msg = f"{path} has a tilted box (xy, xz, yz = {xy}, {xz}, {yz}); discsim boxes are rectangles"
        raise InvalidArgumentError(msg)
    periodic = True
    if "discsim/periodic" in frame.log:
        periodic = bool(np.asarray(frame.log["discsim/periodic"]).ravel()[0])
    return Box(lx, ly, periodic=periodic)
