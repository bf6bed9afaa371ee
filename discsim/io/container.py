"""Files on disk: checksummed state files written atomically, and chunked record streams.

This module knows nothing of discs or engines. A *state file* holds one JSON
document (``meta``) and named numpy arrays. A *record stream* holds a header
(the same: JSON and arrays) followed by chunks of records of one structured
dtype, appended while a run goes on, so that memory stays flat.

Layout (integers little-endian)::

    file  = magic (16 bytes) | format version (uint32) | block [| block ...]
    block = body length (uint64) | body | SHA-256 of the body (32 bytes)
    body  = JSON length (uint64) | JSON (UTF-8) | the arrays' bytes, in the order listed

The JSON is ``{"meta": ..., "arrays": [{"name": ..., "descr": ..., "shape": ...}, ...]}``
with ``descr`` numpy's dtype description (:mod:`numpy.lib.format`). A state
file has exactly one block; a record stream has a header block and then one
block per chunk, each checked by its own checksum. Floats in the JSON are
written with ``repr``, which reads back to the same bits.

Safety: no pickle anywhere. Arrays of Python objects are refused when
written, and a file can describe only plain numbers and JSON, so reading a
file never runs code from it.

Crash safety: :func:`write_state` (like every file discsim replaces, through
:func:`replacing`) writes to a temporary file in the same folder, syncs it and
renames it over the target (``os.replace``), so a crash
leaves either the old file or the new one, never half a file. A stream is
appended in whole chunks; whoever resumes it truncates it back to a length it
recorded (:meth:`RecordWriter.reopen`).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import struct
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.lib import format as npformat

from discsim.errors import CheckpointError

__all__ = [
    "EVENTS_MAGIC",
    "FORMAT_VERSION",
    "STATE_MAGIC",
    "RecordStream",
    "RecordWriter",
    "iter_stream",
    "read_state",
    "read_stream",
    "replacing",
    "stream_extent",
    "stream_index",
    "write_state",
]

#: Version of both layouts; a file of another version is refused.
FORMAT_VERSION = 1
#: First 16 bytes of a state file (checkpoint) and of a record stream (event log).
STATE_MAGIC = b"\x89DISCSIM-STATE\r\n"
EVENTS_MAGIC = b"\x89DISCSIM-EVENT\r\n"

_PREFIX = struct.Struct("<16sI")  # magic, version
_LENGTH = struct.Struct("<Q")
_DIGEST = 32  # SHA-256
#: A JSON document larger than this is taken for damage rather than read.
_MAX_JSON = 1 << 28


# --- blocks ----------------------------------------------------------------------------------
def _json_default(value):
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    if isinstance(value, np.bool_):
        return bool(value)
    msg = f"cannot store a {type(value).__name__} in a discsim file (only numbers, strings, lists, dicts)"
    raise TypeError(msg)


def _encode_block(meta: dict, arrays: dict[str, np.ndarray]) -> bytes:
    specs, buffers = [], []
    for name, value in arrays.items():
        array = np.ascontiguousarray(value)
        if array.dtype.hasobject:
            msg = f"array {name!r} holds Python objects; discsim files hold plain numbers only"
            raise TypeError(msg)
        specs.append({"name": name, "descr": npformat.dtype_to_descr(array.dtype), "shape": list(array.shape)})
        buffers.append(array.tobytes())
    text = json.dumps({"meta": meta, "arrays": specs}, default=_json_default, separators=(",", ":"))
    head = text.encode("utf-8")
    body = b"".join([_LENGTH.pack(len(head)), head, *buffers])
    return _LENGTH.pack(len(body)) + body + hashlib.sha256(body).digest()


def _decode_body(body: bytes, where: str) -> tuple[dict, dict[str, np.ndarray]]:
    """Meta and arrays of a block body whose checksum has been verified."""
    try:
        (json_len,) = _LENGTH.unpack_from(body, 0)
        if json_len > len(body) - _LENGTH.size:
            raise ValueError("JSON length beyond the block")
        doc = json.loads(body[_LENGTH.size : _LENGTH.size + json_len].decode("utf-8"))
        meta, specs = doc["meta"], doc["arrays"]
        arrays, offset = {}, _LENGTH.size + json_len
        for spec in specs:
            dtype = npformat.descr_to_dtype(spec["descr"])
            if dtype.hasobject:
                raise ValueError("an array of Python objects")
            shape = tuple(int(k) for k in spec["shape"])
            nbytes = dtype.itemsize * int(np.prod(shape, dtype=np.int64))
            if offset + nbytes > len(body):
                raise ValueError(f"array {spec['name']!r} runs past the block")
            count = nbytes // dtype.itemsize if dtype.itemsize else 0
            flat = np.frombuffer(body, dtype=dtype, count=count, offset=offset)
            arrays[spec["name"]] = flat.reshape(shape).copy()
            offset += nbytes
        if offset != len(body):
            raise ValueError(f"{len(body) - offset} unexplained bytes")
    except (ValueError, KeyError, TypeError, struct.error, UnicodeDecodeError) as exc:
        # The checksum matched, so the writer itself produced this: not a discsim file.
        msg = f"{where}: unreadable contents ({exc}); not written by this version of discsim"
        raise CheckpointError(msg) from exc
    return meta, arrays


def _read_block(handle, where: str, size: int) -> tuple[dict, dict[str, np.ndarray], int] | None:
    """Read one block at the handle's position; None at a clean end of file.

    Returns ``(meta, arrays, end offset)``. Raises CheckpointError on a
    truncated or corrupted block. ``size`` is the file's length in bytes.
    """
    start = handle.tell()
    if start == size:
        return None
    raw = handle.read(_LENGTH.size)
    if len(raw) < _LENGTH.size:
        msg = f"{where}: truncated at byte {start} (an incomplete block header)"
        raise _Truncated(msg, start)
    (body_len,) = _LENGTH.unpack(raw)
    end = start + _LENGTH.size + body_len + _DIGEST
    if end > size:
        msg = (
            f"{where}: truncated at byte {size} (a block starting at byte {start} needs {end - start} bytes; "
            f"or its length field is corrupted)"
        )
        raise _Truncated(msg, start)
    body = handle.read(body_len)
    digest = handle.read(_DIGEST)
    if hashlib.sha256(body).digest() != digest:
        msg = f"{where}: checksum mismatch in the block at bytes {start}..{end} (the file is corrupted)"
        raise CheckpointError(msg)
    meta, arrays = _decode_body(body, where)
    return meta, arrays, end


class _Truncated(CheckpointError):
    """A block runs past the end of the file; ``offset`` is where that block starts."""

    def __init__(self, message: str, offset: int):
        super().__init__(message)
        self.offset = offset


def _check_prefix(handle, path, magic: bytes, what: str) -> None:
    raw = handle.read(_PREFIX.size)
    if len(raw) < _PREFIX.size:
        msg = f"{path}: truncated ({len(raw)} bytes), not a complete discsim {what}"
        raise CheckpointError(msg)
    found, version = _PREFIX.unpack(raw)
    if found != magic:
        msg = f"{path}: not a discsim {what} (wrong leading bytes {found[:16]!r})"
        raise CheckpointError(msg)
    if version != FORMAT_VERSION:
        msg = (
            f"{path}: format version {version}, but this discsim reads version {FORMAT_VERSION} "
            "(written by an incompatible discsim, or damaged)"
        )
        raise CheckpointError(msg)


def _fsync_folder(folder: Path) -> None:
    """Make a rename durable (POSIX); a no-op where folders cannot be opened."""
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


# --- state files -------------------------------------------------------------------------------
def write_state(path, meta: dict, arrays: dict[str, np.ndarray]) -> Path:
    """Write a checksummed state file atomically (temporary file, fsync, ``os.replace``).

    Args:
        path: the file to write; its folder must exist. An existing file is
            replaced only once the new one is complete on disk.
        meta: JSON-able dict (numbers, strings, None, lists, dicts; numpy
            scalars are converted). Floats read back bit for bit.
        arrays: named numpy arrays of plain (non-object) dtypes.

    Returns:
        The path written.

    Raises:
        TypeError: if ``meta`` or ``arrays`` hold something other than plain data.
        FileNotFoundError: naming ``path``, if its folder does not exist.

    Example:
        >>> import os, tempfile, numpy as np
        >>> path = os.path.join(tempfile.mkdtemp(), "state.bin")
        >>> _ = write_state(path, {"time": 0.1}, {"x": np.arange(3.0)})
        >>> meta, arrays = read_state(path)
        >>> meta["time"], arrays["x"].tolist()
        (0.1, [0.0, 1.0, 2.0])
    """
    data = _PREFIX.pack(STATE_MAGIC, FORMAT_VERSION) + _encode_block(meta, arrays)
    with replacing(path) as tmp, open(tmp, "wb") as handle:
        handle.write(data)
    return Path(path)


@contextlib.contextmanager
def replacing(path) -> Iterator[Path]:
    """Replace the file ``path`` atomically: write to the temporary path this yields, in the same folder.

    When the block ends without an error, the temporary file is synced to the disk and renamed over ``path``
    (``os.replace``); on any error (a full disk, an exception midway) it is removed and ``path`` is left as it
    was: the old file, or none. The new file gets the permissions of a newly created one.

    Raises:
        FileNotFoundError: naming ``path``, if its folder does not exist (before anything is written).

    Example:
        >>> import os, tempfile
        >>> path = os.path.join(tempfile.mkdtemp(), "notes.txt")
        >>> with replacing(path) as tmp:
        ...     _ = tmp.write_text("new")
        >>> open(path).read(), os.listdir(os.path.dirname(path))
        ('new', ['notes.txt'])
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        msg = f"cannot write {str(path)!r}: no folder {str(folder)!r}"
        raise FileNotFoundError(msg)
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes it private (0600)
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    _fsync_folder(folder)


def read_state(path) -> tuple[dict, dict[str, np.ndarray]]:
    """Read and verify a file written by :func:`write_state`.

    Returns:
        ``(meta, arrays)``: the JSON dict and the named arrays (fresh, writable).

    Raises:
        FileNotFoundError: if there is no such file.
        CheckpointError: if the file is truncated, corrupted (checksum), not a
            discsim state file, or of another format version.
    """
    path = Path(path)
    size = path.stat().st_size
    with open(path, "rb") as handle:
        _check_prefix(handle, path, STATE_MAGIC, "state file")
        block = _read_block(handle, str(path), size)
        if block is None:
            msg = f"{path}: truncated (no data after the header)"
            raise CheckpointError(msg)
        meta, arrays, end = block
    if end != size:
        msg = f"{path}: {size - end} unexpected bytes after the data (damaged or not a state file)"
        raise CheckpointError(msg)
    return meta, arrays


# --- record streams ----------------------------------------------------------------------------
@dataclass
class RecordStream:
    """A record stream read back by :func:`read_stream`.

    Attributes:
        meta: the header's JSON dict. arrays: the header's named arrays.
        records: ``(R,)`` every record, in the order written, of ``dtype``.
        chunks: number of chunks read. end: byte offset after the last chunk read.
        last: the JSON dict of the last chunk read (empty when there is none).
    """

    meta: dict
    arrays: dict[str, np.ndarray]
    records: np.ndarray
    chunks: int
    end: int
    last: dict


def _open_stream(handle, path, size: int) -> tuple[dict, dict[str, np.ndarray], np.dtype, int]:
    _check_prefix(handle, path, EVENTS_MAGIC, "record stream")
    header = _read_block(handle, str(path), size)
    if header is None:
        msg = f"{path}: truncated (no header after the leading bytes)"
        raise CheckpointError(msg)
    meta, arrays, end = header
    try:
        dtype = npformat.descr_to_dtype(meta["record_descr"])
        user = meta["header"]
    except (KeyError, TypeError, ValueError) as exc:
        msg = f"{path}: the header does not describe a record stream ({exc})"
        raise CheckpointError(msg) from exc
    return user, arrays, dtype, end


def iter_stream(path, *, partial: bool = False) -> Iterator[tuple[dict, dict, np.ndarray, int]]:
    """Walk a record stream chunk by chunk without holding it all in memory.

    Yields ``(header meta, header arrays, no records, end of header)`` first, then
    ``(chunk meta, {}, records, end offset)`` for each chunk, checking every
    checksum and that the chunks follow one another.

    Args:
        path: the stream file.
        partial: stop quietly before an incomplete last chunk (a run killed
            while writing) instead of raising. Corruption is refused either way.

    Raises:
        CheckpointError: truncated (unless ``partial``) or corrupted file,
            wrong format version, chunks out of order or of the wrong dtype.
    """
    path = Path(path)
    size = path.stat().st_size
    with open(path, "rb") as handle:
        user, header_arrays, dtype, end = _open_stream(handle, path, size)
        yield user, header_arrays, np.zeros(0, dtype=dtype), end
        expected = 0
        while True:
            try:
                block = _read_block(handle, str(path), size)
            except _Truncated:
                if partial:
                    return
                raise
            if block is None:
                return
            meta, arrays, end = block
            records = arrays.get("records")
            if records is None or records.dtype != dtype or records.ndim != 1:
                msg = f"{path}: the chunk ending at byte {end} does not hold records of the stream's dtype"
                raise CheckpointError(msg)
            if meta.get("first") != expected or meta.get("count") != len(records):
                msg = (
                    f"{path}: the chunk ending at byte {end} starts at record {meta.get('first')}, "
                    f"expected {expected} (chunks missing or out of order)"
                )
                raise CheckpointError(msg)
            expected += len(records)
            yield meta, {}, records, end


def stream_index(path, *, partial: bool = False) -> tuple[dict, dict[str, np.ndarray], list[dict]]:
    """The header of a record stream and the JSON of each chunk, without reading the records.

    Follows the blocks' length fields and reads each chunk's JSON only (a few hundred bytes a chunk, so a
    large file is indexed in milliseconds); the checksums are checked later, by whoever reads the chunks
    (:func:`iter_stream`). Each chunk's dict is what was stored with it (``first``, ``count``, and e.g. the
    ``time`` of an event log), plus ``offset``, where its block starts.

    Raises:
        CheckpointError: see :func:`iter_stream` (a damaged header, or a block past the end of the file
            unless ``partial``).
    """
    path = Path(path)
    size = path.stat().st_size
    chunks: list[dict] = []
    with open(path, "rb") as handle:
        user, arrays, _, position = _open_stream(handle, path, size)
        while position < size:
            handle.seek(position)
            head = handle.read(2 * _LENGTH.size)
            if len(head) < 2 * _LENGTH.size:
                body_len = json_len = size  # an incomplete block header
            else:
                body_len, json_len = _LENGTH.unpack_from(head, 0)[0], _LENGTH.unpack_from(head, _LENGTH.size)[0]
            end = position + _LENGTH.size + body_len + _DIGEST
            if end > size or json_len > min(body_len, _MAX_JSON):
                if partial:
                    break
                msg = f"{path}: truncated at byte {size} (a block starting at byte {position} runs past the end)"
                raise CheckpointError(msg)
            try:
                meta = json.loads(handle.read(json_len).decode("utf-8"))["meta"]
            except (ValueError, KeyError, TypeError, UnicodeDecodeError) as exc:
                msg = f"{path}: unreadable chunk at byte {position} ({exc}; the file is corrupted)"
                raise CheckpointError(msg) from exc
            chunks.append({**meta, "offset": position})
            position = end
    return user, arrays, chunks


def read_stream(path, *, partial: bool = False) -> RecordStream:
    """Read and verify a whole record stream written by :class:`RecordWriter`.

    Args:
        path: the stream file.
        partial: accept an incomplete last chunk (see :func:`iter_stream`).

    Returns:
        A :class:`RecordStream` with every record concatenated.

    Raises:
        FileNotFoundError: if there is no such file.
        CheckpointError: see :func:`iter_stream`.

    Example:
        >>> import os, tempfile, numpy as np
        >>> path = os.path.join(tempfile.mkdtemp(), "log.bin")
        >>> dtype = np.dtype([("t", "f8"), ("i", "i8")])
        >>> writer = RecordWriter.create(path, dtype, {"n": 2}, {})
        >>> writer.append(np.array([(0.5, 1), (0.7, 0)], dtype=dtype)); writer.close()
        >>> stream = read_stream(path)
        >>> stream.meta, stream.records["i"].tolist(), stream.chunks
        ({'n': 2}, [1, 0], 1)
    """
    walk = iter_stream(path, partial=partial)
    meta, arrays, empty, end = next(walk)
    pieces: list[np.ndarray] = [empty]
    last: dict = {}
    for last, _, records, end in walk:  # noqa: B007 (last and end are used after the loop)
        pieces.append(records)
    records = np.concatenate(pieces)
    return RecordStream(meta, arrays, records, len(pieces) - 1, end, last)


def stream_extent(path) -> tuple[int, int, dict]:
    """How far a record stream's whole blocks reach, read from their lengths and each chunk's JSON only.

    No records are read and no checksum is checked, so this is cheap on a log of any size: use it to say where
    a file cut short (or damaged) stops; :func:`iter_stream` verifies.

    Returns:
        ``(end, records, last)``: the byte after the last whole block (the file's size when none is cut), the
        records in the whole chunks, and the JSON dict of the last whole chunk (empty when there is none).

    Raises:
        FileNotFoundError: if there is no such file.
    """
    path = Path(path)
    size = path.stat().st_size
    end, records = 0, 0
    last: dict = {}
    with open(path, "rb") as handle:
        if len(handle.read(_PREFIX.size)) < _PREFIX.size:
            return end, records, last
        end = _PREFIX.size
        header = True
        while end + _LENGTH.size <= size:
            handle.seek(end)
            (body_len,) = _LENGTH.unpack(handle.read(_LENGTH.size))
            block_end = end + _LENGTH.size + body_len + _DIGEST
            if block_end > size:
                break
            if not header:
                raw = handle.read(min(body_len, _LENGTH.size))
                json_len = _LENGTH.unpack(raw)[0] if len(raw) == _LENGTH.size else body_len
                if json_len > min(body_len - _LENGTH.size, _MAX_JSON):
                    break
                try:
                    meta = json.loads(handle.read(json_len).decode("utf-8"))["meta"]
                    count = int(meta["count"])
                except (ValueError, KeyError, TypeError):
                    break
                records, last = records + count, meta
            header, end = False, block_end
    return end, records, last


def _verify_chunks(handle, path: Path, dtype: np.dtype, position: int, end: int, records: int) -> None:
    """Check every chunk from byte ``position`` (after the header) to ``end``: checksums, order, ``records`` in all.

    Raises:
        CheckpointError: naming the first damaged chunk and how many records before it are intact.
    """
    expected, start = 0, position
    handle.seek(position)
    while position < end:
        try:
            block = _read_block(handle, str(path), end)
        except CheckpointError as exc:
            msg = (
                f"{path}: damaged before byte {end}, where the checkpoint says the log ends: {exc}. The "
                f"{expected} records before byte {position} are intact. Nothing was appended; stream to a new file "
                "(record_to=another path) to go on"
            )
            raise CheckpointError(msg) from exc
        if block is None:
            break
        meta, arrays, position = block
        got = arrays.get("records")
        if got is None or got.dtype != dtype or got.ndim != 1 or meta.get("first") != expected:
            msg = f"{path}: the chunk ending at byte {position} does not follow the one before it (damaged log)"
            raise CheckpointError(msg)
        expected += len(got)
    if expected != records:
        msg = f"{path}: holds {expected} records up to byte {end}, but the checkpoint saw {records} (damaged log)"
        raise CheckpointError(msg)
    handle.seek(start)  # where the caller left it


class RecordWriter:
    """Appends chunks of records to a stream file; see the module docstring for the layout.

    Create a new stream with :meth:`create` or continue one with :meth:`reopen`.
    Each :meth:`append` writes one checksummed chunk and flushes it to the
    operating system; :meth:`sync` also forces it to the disk (call it before
    writing a checkpoint that refers to the stream).

    Attributes:
        path (Path): the file. dtype: the records' dtype.
        records (int): records in the file so far. end (int): bytes in the file so far.
    """

    def __init__(self, handle, path: Path, dtype: np.dtype, records: int, end: int):
        self._handle = handle
        self.path = path
        self.dtype = dtype
        self.records = records
        self.end = end

    @classmethod
    def create(cls, path, dtype, meta: dict, arrays: dict[str, np.ndarray]) -> RecordWriter:
        """Start a new stream at ``path`` with a header (``meta``, ``arrays``); never overwrites.

        Raises:
            CheckpointError: if ``path`` already exists.
        """
        path = Path(path)
        dtype = np.dtype(dtype)
        block = _encode_block({"record_descr": npformat.dtype_to_descr(dtype), "header": meta}, arrays)
        try:
            handle = open(path, "xb")
        except FileExistsError as exc:
            msg = f"{path} already exists; discsim will not overwrite it (choose another path or remove it)"
            raise CheckpointError(msg) from exc
        data = _PREFIX.pack(EVENTS_MAGIC, FORMAT_VERSION) + block
        handle.write(data)
        handle.flush()
        return cls(handle, path, dtype, 0, len(data))

    @classmethod
    def reopen(cls, path, records: int, end: int, expect: dict | None = None, verify: bool = True) -> RecordWriter:
        """Continue a stream known to hold ``records`` records in its first ``end`` bytes.

        Checks the header against ``expect`` (items its JSON dict must hold),
        that chunk boundaries lead exactly to byte ``end``, and that every chunk
        up to there is intact (its checksum), follows the one before and that
        they end at record ``records`` (``verify=False``: only the last chunk, for
        a file verified a moment ago); only then cuts off whatever follows
        (chunks written after the checkpoint that recorded ``records`` and
        ``end``, possibly half a chunk from a killed run). Appending after a
        damaged chunk would make the whole file unreadable.

        Raises:
            FileNotFoundError: if the file is missing.
            CheckpointError: if the header is not the expected one, or the file
                is shorter than ``end``, damaged up to ``end``, or does not hold
                ``records`` records there. The file is left untouched.
        """
        path = Path(path)
        size = path.stat().st_size
        handle = open(path, "r+b")
        try:
            user, _, dtype, position = _open_stream(handle, path, size)
            for key, value in (expect or {}).items():
                if not isinstance(user, dict) or user.get(key) != value:
                    found = user.get(key) if isinstance(user, dict) else None
                    msg = f"{path}: belongs to another run ({key} is {found!r}, expected {value!r})"
                    raise CheckpointError(msg)
            if size < end:
                msg = f"{path}: truncated: holds {size} bytes but the checkpoint saw {end}"
                raise CheckpointError(msg)
            if verify:
                _verify_chunks(handle, path, dtype, position, end, records)
            last_start = None
            while position < end:  # follow the length fields to the last chunk
                raw = handle.read(_LENGTH.size)
                if len(raw) < _LENGTH.size:
                    break
                (body_len,) = _LENGTH.unpack(raw)
                last_start = position
                position += _LENGTH.size + body_len + _DIGEST
                handle.seek(position)
            if position != end:
                msg = f"{path}: no chunk ends at byte {end}, where the checkpoint says the log ends (damaged log)"
                raise CheckpointError(msg)
            if last_start is None:
                if records != 0:
                    msg = f"{path}: holds no chunk but the checkpoint saw {records} records"
                    raise CheckpointError(msg)
            else:
                handle.seek(last_start)
                block = _read_block(handle, str(path), size)
                assert block is not None  # not the end of the file: last_start < end <= size
                meta, chunk, _ = block
                got = chunk.get("records")
                if got is None or got.dtype != dtype or meta.get("first", -1) + len(got) != records:
                    msg = f"{path}: the chunk ending at byte {end} does not end at record {records} (damaged log)"
                    raise CheckpointError(msg)
            handle.seek(end)
            handle.truncate(end)
            handle.flush()
        except BaseException:
            handle.close()
            raise
        return cls(handle, path, dtype, records, end)

    def append(self, records: np.ndarray, meta: dict | None = None) -> None:
        """Write ``records`` (``(R,)`` of the stream's dtype, possibly empty) as one chunk.

        ``meta`` (JSON-able) is stored with the chunk, next to its ``first``
        record number and ``count``.
        """
        if records.dtype != self.dtype or records.ndim != 1:
            msg = f"records must be (R,) of {self.dtype}, got shape {records.shape} of {records.dtype}"
            raise TypeError(msg)
        data = _encode_block({**(meta or {}), "first": self.records, "count": len(records)}, {"records": records})
        self._handle.write(data)
        self._handle.flush()
        self.records += len(records)
        self.end += len(data)

    def sync(self) -> None:
        """Force what was appended onto the disk (``os.fsync``)."""
        self._handle.flush()
        os.fsync(self._handle.fileno())

    def close(self) -> None:
        """Flush and close the file (idempotent)."""
        if not self._handle.closed:
            self._handle.flush()
            self._handle.close()

    def __enter__(self) -> RecordWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
