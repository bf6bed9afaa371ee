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
  walls (HOOMD has no walled box; other readers see a periodic one).

GSD stores these in single precision (float32), as HOOMD does: positions come back to about ``1e-7 L``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from discsim.analysis.frames import Frames
from discsim.errors import InvalidArgumentError
from discsim.io.container import replacing
from discsim.model import Box, image_steps

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
    frame.particles.types = [str(g) for g in labels.tolist()]
    frame.particles.typeid = np.searchsorted(labels, frames.groups).astype(np.uint32)
    frame.log["discsim/time"] = np.array([frames.times[k]], dtype=np.float64)
    frame.log["discsim/periodic"] = np.array([int(box.periodic)], dtype=np.uint8)
    return frame


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
        InvalidArgumentError: if the file is not a GSD file of HOOMD's schema, holds no frame, holds 3D data
            (``dimensions = 3`` or a nonzero z), a tilted box, or frames whose number of discs changes.
    """
    hoomd = require_gsd()
    path = Path(path)
    if not path.is_file():
        msg = f"no GSD file at {str(path)!r}"
        raise FileNotFoundError(msg)
    try:
        handle = hoomd.open(str(path), "r")
    except Exception as exc:  # gsd raises RuntimeError, OSError or ValueError on a foreign file
        msg = f"{path} is not a GSD file of HOOMD's schema ({type(exc).__name__}: {exc})"
        raise InvalidArgumentError(msg) from exc
    with handle:
        if len(handle) == 0:
            msg = f"{path} holds no frame"
            raise InvalidArgumentError(msg)
        first = handle[0]
        box = _read_box(first, path)
        n = int(first.particles.N)
        size = np.array([box.width, box.height])
        types = list(first.particles.types)
        names = [int(t) if t.lstrip("-").isdigit() else None for t in types]
        typeid = np.asarray(first.particles.typeid, dtype=np.int64)
        groups = np.array([names[t] for t in typeid]) if None not in names else typeid.copy()
        radii = 0.5 * np.asarray(first.particles.diameter, dtype=float)
        masses = np.asarray(first.particles.mass, dtype=float)
        times, positions, unwrapped, velocities = [], [], [], []
        for k, frame in enumerate(handle):
            if int(frame.particles.N) != n:
                msg = f"{path}: frame {k} holds {int(frame.particles.N)} particles, frame 0 holds {n}"
                raise InvalidArgumentError(msg)
            if _read_box(frame, path) != box:
                msg = f"{path}: the box of frame {k} differs from frame 0's; discsim frames share one box"
                raise InvalidArgumentError(msg)
            pos = np.asarray(frame.particles.position, dtype=float)
            if np.any(pos[:, 2] != 0.0):
                msg = f"{path} holds 3D data: frame {k} has particles off the plane z = 0"
                raise InvalidArgumentError(msg)
            xy = pos[:, :2] + 0.5 * size
            image = np.asarray(frame.particles.image, dtype=float)[:, :2]
            log = frame.log
            time = (
                float(np.asarray(log["discsim/time"]).ravel()[0])
                if "discsim/time" in log
                else float(frame.configuration.step)
            )
            times.append(time)
            positions.append(box.wrap(xy))
            unwrapped.append(xy + image * size)
            velocities.append(np.asarray(frame.particles.velocity, dtype=float)[:, :2])
    return Frames(
        np.array(times),
        np.array(positions),
        np.array(unwrapped),
        np.array(velocities),
        box,
        radii,
        masses,
        groups,
    )


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
