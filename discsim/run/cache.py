"""The on-disk cache of a sweep: one JSON file per finished task, addressed by what the task computed.

A task's *key* is the SHA-256 of its identity: the task's name, its parameters, its seed and discsim's
version (canonical JSON, sorted keys). Its entry, ``<folder>/<key[:2]>/<key>.json``, holds the identity
beside the result and a ``checksum`` (the SHA-256 of the rest of the entry as canonical JSON), and is
written atomically (a temporary file in the same folder, then ``os.replace``), so a sweep killed at any
moment leaves only whole entries. An entry is served only when it reads back whole and unchanged: one that
cannot be read, whose checksum does not match (a bit flipped on disk, a number changed by hand), that has
no checksum, or that holds another task's identity, is reported (a :class:`~discsim.errors.CacheWarning`
naming the file), never served, and computed again (and overwritten). The checksum finds damage and edits,
not forgery: whoever can write the folder can also write a matching checksum.
The folder's manifest, ``discsim-sweep.json``, names the task whose results it holds:
a folder of another task's results, or one holding files that are no sweep's, is refused before anything
runs, so two studies never mix their numbers.

Only finished tasks are stored: a failure is run again by the next sweep over the same folder.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import tempfile
import warnings
from pathlib import Path

from discsim.errors import CacheWarning, InvalidArgumentError

__all__ = ["MANIFEST", "SweepCache", "checksum", "task_key"]

#: The manifest naming the task a cache folder belongs to.
MANIFEST = "discsim-sweep.json"
#: The layout of the folder; a later layout would refuse (or convert) an older one. (Entries of layout 1
#: had no checksum: they are reported and computed again.)
LAYOUT = 2
#: The field of an entry that holds the SHA-256 of the rest of it.
CHECKSUM = "checksum"


def _canonical(identity: dict) -> str:
    return json.dumps(identity, sort_keys=True, separators=(",", ":"), allow_nan=True)


def checksum(entry: dict) -> str:
    """The hex SHA-256 of an entry without its ``checksum`` field (canonical JSON): what the field must hold.

    Example:
        >>> checksum({"result": {"y": 1.0}}) == checksum({"result": {"y": 1.0}, "checksum": "anything"})
        True
        >>> checksum({"result": {"y": 1.0}}) == checksum({"result": {"y": 2.0}})
        False
    """
    content = {name: value for name, value in entry.items() if name != CHECKSUM}
    return hashlib.sha256(_canonical(content).encode()).hexdigest()


def task_key(task: str, params: dict, seed: int, version: str) -> str:
    """The hex SHA-256 that addresses one task's result.

    Example:
        >>> task_key("m:f", {"a": 1}, 7, "0.1.0") == task_key("m:f", {"a": 1}, 7, "0.1.0")
        True
        >>> task_key("m:f", {"a": 1}, 7, "0.1.0") == task_key("m:f", {"a": 1.5}, 7, "0.1.0")
        False
    """
    identity = {"task": task, "params": params, "seed": int(seed), "version": version}
    return hashlib.sha256(_canonical(identity).encode()).hexdigest()


class SweepCache:
    """A folder of finished tasks' results (see the module docstring).

    Args:
        folder: the cache folder; created when missing.
        task: the sweep's task name (``module:qualname``).
        version: discsim's version (part of every key).

    Raises:
        InvalidArgumentError: if ``folder`` is a file, holds another task's results (its manifest names
            another task), or holds files but no manifest.
    """

    def __init__(self, folder, task: str, version: str):
        self.folder = Path(folder)
        self.task = task
        self.version = version
        self._unchecked = False  # the folder is of layout 1 (entries without checksums)
        self._check_folder()

    def _check_folder(self) -> None:
        folder = self.folder
        if folder.exists() and not folder.is_dir():
            msg = f"cache={str(folder)!r} is a file, not a folder"
            raise InvalidArgumentError(msg)
        manifest = folder / MANIFEST
        if manifest.is_file():
            try:
                owner = json.loads(manifest.read_text())["task"]
            except (OSError, ValueError, KeyError, TypeError) as exc:
                msg = f"cache={str(folder)!r}: its manifest {MANIFEST} cannot be read ({exc})"
                raise InvalidArgumentError(msg) from exc
            if owner != self.task:
                msg = (
                    f"cache={str(folder)!r} holds the results of another sweep's task, {owner!r}, not {self.task!r}: "
                    f"give this sweep a folder of its own"
                )
                raise InvalidArgumentError(msg)
        elif folder.is_dir() and any(folder.iterdir()):
            msg = (
                f"cache={str(folder)!r} holds files but is not a sweep cache (no {MANIFEST}): "
                f"give the sweep an empty or new folder"
            )
            raise InvalidArgumentError(msg)

    def open(self) -> None:
        """Create the folder and its manifest (when a sweep is about to run).

        Raises:
            InvalidArgumentError: naming the folder, if it cannot be created or written.
        """
        manifest = self.folder / MANIFEST
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            layout = json.loads(manifest.read_text()).get("layout") if manifest.is_file() else None
            if layout != LAYOUT:
                self._write(manifest, {"format": "discsim sweep cache", "layout": LAYOUT, "task": self.task})
        except (OSError, ValueError, AttributeError) as exc:
            msg = f"cache={str(self.folder)!r} cannot be created or written: {exc}"
            raise InvalidArgumentError(msg) from exc
        if layout is not None and layout != LAYOUT:  # entries of layout 1 have no checksum: not served
            self._unchecked = True
            msg = (
                f"sweep cache: {str(self.folder)!r} was written by an older discsim, without checksums: its "
                f"entries are not used, their tasks run again and are stored with checksums"
            )
            warnings.warn(msg, CacheWarning, stacklevel=4)  # open <- _run <- sweep <- the caller

    def _path(self, key: str) -> Path:
        return self.folder / key[:2] / f"{key}.json"

    def get(self, params: dict, seed: int) -> dict | None:
        """The stored entry of a finished task (``result``, ``seconds``, ``attempts``), or None.

        None when the task has no entry, and also, with a :class:`~discsim.errors.CacheWarning` naming the
        file, when its entry is damaged or changed (see the module docstring): the task is then run again.
        """
        key = task_key(self.task, params, seed, self.version)
        path = self._path(key)
        try:
            text = path.read_bytes().decode()
        except FileNotFoundError:
            return None
        except (OSError, UnicodeDecodeError) as exc:
            return self._refuse(path, f"cannot be read ({exc})")
        try:
            entry = json.loads(text)
        except ValueError as exc:
            return self._refuse(path, f"cannot be read: it is not whole JSON ({exc})")
        if isinstance(entry, dict) and CHECKSUM not in entry and self._unchecked:
            return None  # an entry of layout 1, which open() reported for the whole folder
        if not isinstance(entry, dict) or not isinstance(entry.get(CHECKSUM), str):
            return self._refuse(path, "has no checksum (damaged, or written by an older discsim)")
        if entry[CHECKSUM] != checksum(entry):
            return self._refuse(path, "does not match its checksum: it was damaged or changed after it was written")
        identity = {"key": key, "task": self.task, "params": params, "seed": int(seed), "version": self.version}
        wrong = [name for name, value in identity.items() if entry.get(name) != value]
        if wrong or not isinstance(entry.get("result"), dict):
            what = f"its {wrong[0]} is {entry.get(wrong[0])!r}, not {identity[wrong[0]]!r}" if wrong else "no result"
            return self._refuse(path, f"holds another task's entry ({what})")
        return entry

    @staticmethod
    def _refuse(path: Path, why: str) -> None:
        msg = f"sweep cache: the entry {str(path)!r} {why}; it is not used, and the task runs again"
        warnings.warn(msg, CacheWarning, stacklevel=5)  # _refuse <- get <- _run <- sweep <- the caller
        return None

    def put(self, params: dict, seed: int, result: dict, seconds: float, attempts: int) -> None:
        """Store a finished task's result (atomically)."""
        key = task_key(self.task, params, seed, self.version)
        entry = {
            "key": key,
            "task": self.task,
            "params": params,
            "seed": int(seed),
            "version": self.version,
            "result": result,
            "seconds": float(seconds) if math.isfinite(seconds) else None,
            "attempts": int(attempts),
        }
        entry[CHECKSUM] = checksum(entry)
        path = self._path(key)
        path.parent.mkdir(parents=True, exist_ok=True)
        self._write(path, entry)

    def __len__(self) -> int:
        """Entries stored (finished tasks of any grid, this task and version or older)."""
        if not self.folder.is_dir():
            return 0
        return sum(1 for entry in self.folder.glob("??/*.json") if not entry.name.startswith("."))  # not a .tmp-

    @staticmethod
    def _write(path: Path, content: dict) -> None:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=".json")
        try:
            with os.fdopen(fd, "w") as f:
                f.write(json.dumps(content, separators=(",", ":"), allow_nan=True))  # results keep their order
                f.flush()
                os.fsync(f.fileno())
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
