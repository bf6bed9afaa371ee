"""A run's bookkeeping: :class:`RunContext`, the one object an engine carries for the run it belongs to.

It holds what goes on from one ``run()`` call to the next and into files: the event log kept in memory,
whether the driver records for its observers meanwhile, which run this is (``run_id``) and where its log
was streamed, the disc ids (after ``add_discs`` / ``remove_discs``) and the discs where the log starts, and
the ``sim.on(...)`` callbacks. :mod:`discsim.run` (the driver and its observers), :mod:`discsim.io` and
:mod:`discsim.analysis` read and change it through ``engine.run_context`` and never through the engine's
private attributes.

It lives beside the engines, not in ``run/``, because an engine exists (and is edited, saved, loaded)
before any run and must hold one from its constructor on; the engine itself only reads ``log``,
``recording``, ``serving``, ``streamed`` and the ids, and changes the ids when the user adds or removes discs.
"""

from __future__ import annotations

import uuid

import numpy as np

from discsim.events import EventLog
from discsim.model import Discs

__all__ = ["LookOnly", "RunContext"]


class LookOnly:
    """A ``sim.on(kind, fn, changes=False)`` callback: ``fn`` only looks, so the run need not stop after each event.

    Calls ``fn`` as given; the driver's callback observer (:class:`discsim.run.handlers.EventHandlers`) tells it
    from a callback that may change the simulation by this type.
    """

    __slots__ = ("fn",)

    def __init__(self, fn):
        self.fn = fn

    def __call__(self, sim, contact):
        return self.fn(sim, contact)

    def __repr__(self) -> str:
        return f"LookOnly({getattr(self.fn, '__qualname__', self.fn)!r})"


class RunContext:
    """The bookkeeping of the run an engine belongs to (see the module docstring).

    Attributes:
        log (EventLog): the records kept in memory: the engine's loop fills it while ``record`` or
            ``recording`` is on; the driver hands chunks of it to observers, a stream takes it to disk.
            One object for the engine's life (its loops hold it as ``_log``): cleared, never replaced.
        recording (bool): the driver records for its observers now, whatever the engine's ``record`` says.
        run_id (str | None): identifies the run in its checkpoints and its streamed log (None until one
            is written: :meth:`ensure_run_id`).
        stream (dict | None): where the log went on disk (``path``, ``run_id``, ``base``, ``records``,
            ``end``, maybe ``write_error``); None while the log is in memory only.
        ids ((N,) int64 array | None): each disc's id; None while the ids are the indices.
        next_id (int): the id the next disc added gets.
        origin (tuple[Discs, array | None] | None): ``(discs, ids)`` where the log starts, once the discs
            changed (the engine's ``discs`` are then today's); None: the engine's ``discs`` and their indices.
        structure (int): ``add_discs`` / ``remove_discs`` calls so far (observers notice the disc set changed).
        handlers (dict[str, list]): the ``sim.on(kind, fn)`` callbacks by kind, in the order given (those given
            with ``changes=False`` wrapped in :class:`LookOnly`).
        serving (bool): the driver is between two chunks of a run, serving its observers and callbacks; the
            engine refuses ``step()`` and ``run()`` meanwhile (a callback may change discs, not advance them).
    """

    def __init__(self, n: int):
        self.log = EventLog()
        self.recording = False
        self.run_id: str | None = None
        self.stream: dict | None = None
        self.ids: np.ndarray | None = None
        self.next_id = int(n)
        self.origin: tuple[Discs, np.ndarray | None] | None = None
        self.structure = 0
        self.handlers: dict[str, list] = {}
        self.serving = False

    @property
    def streamed(self) -> bool:
        """True once the run's log went to a file (``run(record_to=...)``): the engine keeps no whole log."""
        return self.stream is not None

    def ensure_run_id(self) -> str:
        """The run's id, made (a random hex string) the first time it is asked for."""
        if self.run_id is None:
            self.run_id = uuid.uuid4().hex
        return self.run_id

    def log_origin(self, discs: Discs) -> tuple[Discs, np.ndarray | None]:
        """``(discs, ids)`` where the log starts: ``origin``, or the engine's ``discs`` (ids None: their indices)
        while they never changed."""
        return (discs, None) if self.origin is None else self.origin

    def set_ids(self, ids: np.ndarray, next_id: int, origin: tuple[Discs, np.ndarray | None]) -> None:
        """Take each disc's ``ids`` ``(N,)``, the ``next_id`` and the ``origin`` of the log (the log's records
        so far are named by the old ids: it must be flushed first)."""
        identity = bool(np.array_equal(ids, np.arange(len(ids))))
        self.ids = None if identity else readonly_ids(ids)
        self.next_id = int(next_id)
        self.origin = origin
        self.log.ids = self.ids


def readonly_ids(ids: np.ndarray) -> np.ndarray:
    """``ids`` as a new read-only int64 array."""
    out = np.array(ids, dtype=np.int64)
    out.flags.writeable = False
    return out
