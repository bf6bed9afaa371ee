"""Extended XYZ files (ASE's conventions): a plain-text fallback that ASE, OVITO and many tools read.

Each frame is a count line, a comment line of ``key=value`` pairs, and one line per disc (the comment line
is one line in the file; it is cut here)::

    1
    Lattice="10.0 0.0 0.0 0.0 8.0 0.0 0.0 0.0 0.0"
        Properties=species:S:1:pos:R:3:radius:R:1:velo:R:3:mass:R:1:group:I:1 pbc="T T F" Time=0.5
    H 1.0 2.0 0.0 0.5 0.1 -0.2 0.0 1.0 0

- ``Lattice``: the cell vectors ``(W, 0, 0), (0, H, 0), (0, 0, 0)`` (a 2D cell: zero third vector); discsim's box
  ``[0, W] x [0, H]`` is the cell itself (no shift: XYZ cells start at the origin).
- ``pbc="T T F"`` for a periodic box, ``"F F F"`` for walls. ``Time``: the simulated time.
- Columns: ``species`` (an element symbol per group, ``H``, ``He``, ``Li``, ... in the order of the sorted
  group labels, so that ASE can build its ``Atoms``; the label itself is the ``group`` column), ``pos``
  (z = 0), ``radius``, ``velo`` (z = 0), ``mass`` (``inf`` for an obstacle) and ``group``.

The comment line ends with ``discsim_sha256=...``: the SHA-256 (hex) of the frame's lines without it. XYZ has
no checksum of its own, so a damaged digit would read back as another number: :func:`read_xyz` refuses a frame
that does not match the checksum discsim wrote; a file from another tool (no such key) is read as it stands.

Numbers are written with ``repr`` (17 significant digits), so a file reads back exactly. Unwrapped positions
are not stored: a file read back has ``unwrapped`` equal to ``positions``.
"""

from __future__ import annotations

import hashlib
import re
import shlex
from os import PathLike
from pathlib import Path

import numpy as np

from discsim.analysis.frames import Frames
from discsim.errors import DiscsimError, InvalidArgumentError
from discsim.io.container import replacing
from discsim.model import Box

__all__ = ["read_xyz", "write_xyz"]

#: Placeholder species for the groups, so that ASE can build Atoms (the group label is its own column).
SYMBOLS = "H He Li Be B C N O F Ne Na Mg Al Si P S Cl Ar K Ca Sc Ti V Cr Mn Fe Co Ni Cu Zn Ga Ge As Se Br Kr".split()
PROPERTIES = "species:S:1:pos:R:3:radius:R:1:velo:R:3:mass:R:1:group:I:1"
#: The columns read as numbers: a file that declares one of them text (type S) is refused.
_NUMBERS = ("pos", "radius", "velo", "mass", "group")
#: The key of each frame's checksum, written last on its comment line: the SHA-256 (hex) of the frame's lines
#: without it. read_xyz checks it where present; other tools keep it as an info string.
CHECKSUM = "discsim_sha256"
_CHECKSUM_AT_END = re.compile(rf"\s+{CHECKSUM}=(\S*)\s*$")


def write_xyz(path, source, times=None) -> Path:
    """Write discs to an extended XYZ file (created, or replaced), one XYZ frame per time.

    Args:
        path: the file.
        source: a :class:`~discsim.analysis.frames.Frames`, or an engine: its state now, or at ``times``.
        times: with an engine, the simulated times to write (rebuilt from its event log).

    Returns:
        The path written.

    Raises:
        InvalidArgumentError: on another source, or more groups than placeholder species (36).

    Example:
        >>> import os, tempfile, discsim as ds
        >>> sim = ds.EventDriven(*ds.random_gas(20, 0.3, seed=1)).run(until=1.0)
        >>> path = ds.write_xyz(os.path.join(tempfile.mkdtemp(), "gas.xyz"), sim, times=[0.0, 1.0])
        >>> back = ds.read_xyz(path)
        >>> bool((back.positions == ds.frames(sim, [0.0, 1.0]).positions).all()), back.box == sim.box
        (True, True)
    """
    from discsim.io.gsd import _as_frames

    frames = _as_frames(source, times)
    labels = np.unique(frames.groups)
    if len(labels) > len(SYMBOLS):
        msg = f"write_xyz names at most {len(SYMBOLS)} groups with species, got {len(labels)}"
        raise InvalidArgumentError(msg)
    species = [SYMBOLS[k] for k in np.searchsorted(labels, frames.groups).tolist()]
    box = frames.box
    lattice = f"{box.width!r} 0.0 0.0 0.0 {box.height!r} 0.0 0.0 0.0 0.0"
    pbc = "T T F" if box.periodic else "F F F"
    radii = frames.radii.tolist()
    masses = frames.masses.tolist()
    groups = frames.groups.tolist()
    lines = []
    for k in range(len(frames)):
        comment = f'Lattice="{lattice}" Properties={PROPERTIES} pbc="{pbc}" Time={float(frames.times[k])!r}'
        pos, vel = frames.positions[k].tolist(), frames.velocities[k].tolist()
        rows = [
            f"{species[d]} {pos[d][0]!r} {pos[d][1]!r} 0.0 {radii[d]!r} {vel[d][0]!r} {vel[d][1]!r} 0.0 "
            f"{masses[d]!r} {groups[d]}"
            for d in range(frames.n)
        ]
        count = str(frames.n)
        lines += [count, f"{comment} {CHECKSUM}={_digest(count, comment, rows)}", *rows]
    path = Path(path)
    with replacing(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n")
    return path


def _parse_comment(line: str, path: Path, frame: int) -> dict[str, str]:
    try:
        words = shlex.split(line)
    except ValueError as exc:
        msg = f"{path}: frame {frame}'s comment line is not key=value pairs ({exc})"
        raise InvalidArgumentError(msg) from exc
    out = {}
    for word in words:
        key, sep, value = word.partition("=")
        if sep:
            out[key.lower()] = value
    return out


def read_xyz(path: str | PathLike[str]) -> Frames:
    """Read an extended XYZ file of discs (as :func:`write_xyz` writes) as Frames.

    Needs ``Lattice`` (a rectangle in the xy plane) and ``Properties`` with ``pos``; ``radius`` (default 0.5),
    ``velo`` (default 0), ``mass`` (default 1) and ``group`` (default: the species, numbered in sorted order)
    are read when present. ``pbc`` decides the box (default periodic).

    Raises:
        FileNotFoundError: if there is no such file.
        InvalidArgumentError: naming the file, if it is not extended XYZ as above (or not text), holds 3D data
            (a nonzero z, or a cell with a third vector), its frames differ in the number of discs or the box,
            or a frame does not match the checksum discsim wrote with it (the file is damaged).
    """
    path = Path(path)
    if not path.is_file():
        msg = f"no XYZ file at {str(path)!r}"
        raise FileNotFoundError(msg)
    data = path.read_bytes()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        msg = f"{path} is not a text file (XYZ): byte {exc.start}, on line {line}, is not UTF-8 text"
        raise InvalidArgumentError(msg) from exc
    try:
        return _read_lines(text.splitlines(), path)
    except DiscsimError:
        raise
    except (ValueError, TypeError, IndexError, KeyError, OverflowError) as exc:  # a value no check above named
        msg = f"{path}: unreadable as extended XYZ ({type(exc).__name__}: {exc})"
        raise InvalidArgumentError(msg) from exc


def _digest(count: str, comment: str, rows: list[str]) -> str:
    """The SHA-256 (hex) of a frame's lines, its comment line without the checksum."""
    return hashlib.sha256("\n".join([count, comment, *rows]).encode()).hexdigest()


def _verify(lines: list[str], at: int, n: int, path: Path, frame: int) -> str:
    """Frame ``frame``'s comment line (at line ``at + 1``) without its checksum, once the frame matches it."""
    comment = lines[at + 1]
    found = _CHECKSUM_AT_END.search(comment)
    if found is None:  # written by another tool (or an older discsim): nothing to check
        return comment
    comment = comment[: found.start()]
    if found.group(1).lower() != _digest(lines[at], comment, lines[at + 2 : at + 2 + n]):
        msg = f"{path} is damaged: frame {frame} (from line {at + 1}) does not match its checksum ({CHECKSUM})"
        raise InvalidArgumentError(msg)
    return comment


def _read_lines(lines: list[str], path: Path) -> Frames:
    at, frame = 0, 0
    times: list[float] = []
    positions: list[np.ndarray] = []
    velocities: list[np.ndarray] = []
    first: tuple[Box, np.ndarray, np.ndarray, np.ndarray] | None = None  # frame 0's box, radii, masses, groups
    while at < len(lines):
        if not lines[at].strip():
            at += 1
            continue
        try:
            n = int(lines[at])
        except ValueError:
            n = -1
        if n < 0:
            msg = f"{path}: line {at + 1} should count the discs of frame {frame}, got {lines[at][:40]!r}"
            raise InvalidArgumentError(msg)
        if at + 2 + n > len(lines):
            msg = f"{path}: frame {frame} announces {n} discs but the file ends first"
            raise InvalidArgumentError(msg)
        info = _parse_comment(_verify(lines, at, n, path, frame), path, frame)
        frame_box = _box(info, path, frame)
        columns = _columns(info, path, frame)
        rows = [lines[at + 2 + d].split() for d in range(n)]
        width = sum(count for _, _, count in columns)
        if any(len(row) != width for row in rows):
            msg = f"{path}: frame {frame} has lines without the {width} columns its Properties name"
            raise InvalidArgumentError(msg)
        table: dict[str, np.ndarray] = {}  # (n, count) floats, or strings for a column of type S
        start = 0
        for name, kind, count in columns:
            values = [row[start : start + count] for row in rows]
            if kind == "S":
                if name in _NUMBERS:
                    msg = f"{path}: frame {frame}: column {name} is declared text (S); it must hold numbers"
                    raise InvalidArgumentError(msg)
                table[name] = np.array(values, dtype=str).reshape(n, count)
            else:
                try:
                    table[name] = np.array(values, dtype=float).reshape(n, count)
                except ValueError as exc:
                    msg = f"{path}: frame {frame}: column {name} holds values that are not numbers"
                    raise InvalidArgumentError(msg) from exc
            start += count
        if "pos" not in table:
            msg = f"{path}: frame {frame}'s Properties hold no pos column"
            raise InvalidArgumentError(msg)
        pos = table["pos"]
        if pos.shape[1] > 2 and np.any(pos[:, 2] != 0.0):
            msg = f"{path} holds 3D data: frame {frame} has discs off the plane z = 0"
            raise InvalidArgumentError(msg)
        if first is None:
            radii = table["radius"][:, 0] if "radius" in table else np.full(n, 0.5)
            masses = table["mass"][:, 0] if "mass" in table else np.ones(n)
            if "group" in table:
                labels = table["group"][:, 0]
                if not np.all((np.abs(labels) < 2.0**62) & (labels == np.round(labels))):
                    msg = f"{path}: frame {frame}: column group holds values that are not integers"
                    raise InvalidArgumentError(msg)
                groups = labels.astype(np.int64)
            elif "species" in table:
                names = [v[0] for v in table["species"]]
                groups = np.unique(names, return_inverse=True)[1].reshape(-1)
            else:
                groups = np.zeros(n, dtype=np.int64)
            first = (frame_box, radii, masses, groups)
        elif frame_box != first[0] or n != len(first[1]):
            msg = f"{path}: frame {frame} differs from frame 0 in its box or its number of discs"
            raise InvalidArgumentError(msg)
        try:
            times.append(float(info.get("time", frame)))
        except ValueError as exc:
            msg = f"{path}: frame {frame}'s Time is not a number: {info['time'][:40]!r}"
            raise InvalidArgumentError(msg) from exc
        positions.append(first[0].wrap(pos[:, :2]))
        velocities.append(table["velo"][:, :2] if "velo" in table else np.zeros((n, 2)))
        at += 2 + n
        frame += 1
    if first is None:
        msg = f"{path} holds no frame"
        raise InvalidArgumentError(msg)
    box, radii, masses, groups = first
    wrapped = np.array(positions)
    return Frames(np.array(times), wrapped, wrapped.copy(), np.array(velocities), box, radii, masses, groups)


def _box(info: dict[str, str], path: Path, frame: int) -> Box:
    if "lattice" not in info:
        msg = f'{path}: frame {frame} has no Lattice="..." (not extended XYZ, or no cell)'
        raise InvalidArgumentError(msg)
    try:
        cell = np.array(info["lattice"].split(), dtype=float).reshape(3, 3)
    except ValueError as exc:
        msg = f"{path}: frame {frame}'s Lattice is not 9 numbers: {info['lattice']!r}"
        raise InvalidArgumentError(msg) from exc
    if cell[2].any() or cell[0, 1:].any() or cell[1, [0, 2]].any():
        msg = (
            f"{path}: frame {frame}'s Lattice {info['lattice']!r} is not a 2D rectangle "
            "(W 0 0  0 H 0  0 0 0): 3D data or a tilted cell"
        )
        raise InvalidArgumentError(msg)
    pbc = info.get("pbc", "T T F").split()
    return Box(float(cell[0, 0]), float(cell[1, 1]), periodic=bool(pbc) and pbc[0].upper().startswith("T"))


def _columns(info: dict[str, str], path: Path, frame: int) -> list[tuple[str, str, int]]:
    spec = info.get("properties", "species:S:1:pos:R:3").split(":")
    if len(spec) % 3:
        msg = f"{path}: frame {frame}'s Properties {':'.join(spec)!r} are not name:type:count triples"
        raise InvalidArgumentError(msg)
    try:
        return [(spec[k].lower(), spec[k + 1].upper(), int(spec[k + 2])) for k in range(0, len(spec), 3)]
    except ValueError as exc:
        msg = f"{path}: frame {frame}'s Properties have a count that is not an integer"
        raise InvalidArgumentError(msg) from exc
