"""Ctrl-C during an engine's loop, deferred to the end of the event (or frame) under way.

Python raises ``KeyboardInterrupt`` between any two bytecodes, which inside an event loop can fall half-way
through an event (one disc moved, its partner not yet). :func:`deferred_interrupt` lets the loop see the
interrupt as a flag it checks once per event, stop at a whole event, and write its state back; then
:func:`deferred_interrupt` raises :class:`~discsim.errors.Interrupted` (a ``KeyboardInterrupt``), or hands
the signal to whatever handler the program had installed.
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager

from discsim.errors import Interrupted

__all__ = ["deferred_interrupt", "interrupted_outside_the_loop"]


@contextmanager
def deferred_interrupt():
    """Within the block, SIGINT only sets ``flag[0]``; after the block, it acts as it would have.

    Yields:
        ``flag``, a one-item list the loop checks (``if flag[0]: break``).

    Off the main thread (where handlers cannot be installed) the flag never rises and Ctrl-C acts at once.
    """
    flag = [False]
    previous = None
    if threading.current_thread() is threading.main_thread():

        def note(signum, frame):
            flag[0] = True

        try:
            previous = signal.signal(signal.SIGINT, note)
        except ValueError:  # not the main interpreter
            previous = None
    try:
        yield flag
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    if flag[0]:
        if previous is signal.default_int_handler or previous == signal.SIG_DFL:
            msg = "interrupted (Ctrl-C) after the last whole event; the engine is consistent and can go on"
            raise Interrupted(msg)
        if callable(previous):
            previous(signal.SIGINT, None)


def interrupted_outside_the_loop() -> Interrupted:
    """The :class:`~discsim.errors.Interrupted` for a plain ``KeyboardInterrupt`` raised between two whole events,
    outside the engine's loop: in an observer or a ``sim.on`` callback (Ctrl-C during a slow one, or the callback's
    own ``raise KeyboardInterrupt``). The engine is consistent there; the caller raises it ``from`` the original.
    """
    msg = (
        "interrupted (Ctrl-C) in an observer or callback, after the last whole event; the engine is consistent "
        "and can go on"
    )
    return Interrupted(msg)
