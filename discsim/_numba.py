"""numba, when it is installed and not hidden: the one place that imports it.

The compiled backends (``backend="numba"``) need numba, from the ``fast`` extra
(``pip install "discsim[fast]"``). ``backend="auto"`` takes it when it imports (the event-driven engine once
a run is long enough to pay for loading it: :func:`auto_plan`).
Setting the environment variable ``DISCSIM_NO_NUMBA=1`` hides it, so that the
pure-Python path can be tested on a machine that has numba.
"""

from __future__ import annotations

import importlib.util
import os

from discsim.errors import InvalidArgumentError

__all__ = [
    "AUTO_NUMBA_DISCS",
    "AUTO_PYTHON_EVENTS",
    "HIDE_VARIABLE",
    "auto_plan",
    "available",
    "installed",
    "mark_loaded",
    "numba",
    "resolve_backend",
]

#: The environment variable that hides numba from discsim (any value but "", "0").
HIDE_VARIABLE = "DISCSIM_NO_NUMBA"
#: ``EventDriven(backend="auto")`` runs its first this many physical events in pure Python and then takes the
#: compiled loop (the same events bit for bit), so a short run does not pay for importing numba and loading the
#: compiled loop from its cache (about 1 s, against about 0.5 s for this many events in Python at N = 10^3).
AUTO_PYTHON_EVENTS = 20_000
#: ... unless it has at least this many discs: then the compiled loop from the start (predicting every disc at
#: the start costs about as much in Python as loading the compiled loop).
AUTO_NUMBA_DISCS = 20_000

_module = None
_tried = False
_loaded = False  # an event-driven engine of this process has run the compiled loop: "auto" takes it at once


def numba():
    """The numba module, or None if it is not installed or hidden by ``DISCSIM_NO_NUMBA``."""
    global _module, _tried
    if not _tried:
        _tried = True
        if os.environ.get(HIDE_VARIABLE, "") in ("", "0"):
            try:
                import numba as module
            except ImportError:
                module = None
            _module = module
    return _module


def available() -> bool:
    """True when the compiled backends can run (imports numba)."""
    return numba() is not None


def installed() -> bool:
    """True when numba is installed and not hidden, found without importing it (importing takes a while)."""
    if _tried:
        return _module is not None
    if os.environ.get(HIDE_VARIABLE, "") not in ("", "0"):
        return False
    try:
        return importlib.util.find_spec("numba") is not None
    except (ImportError, ValueError):
        return False


def auto_plan(n: int) -> tuple[str, int | None]:
    """What ``EventDriven(backend="auto")`` runs for ``n`` discs: ``(backend, events)``.

    ``("python", k)``: the pure-Python loop for the first ``k`` physical events, then the compiled one
    (:data:`AUTO_PYTHON_EVENTS`); ``("numba", None)``: the compiled loop from the start, for
    :data:`AUTO_NUMBA_DISCS` discs or more, or once this process has loaded it (:func:`mark_loaded`), or when
    ``k`` is 0; ``("python", None)`` for good when numba is not installed or hidden.
    """
    if not installed():
        return "python", None
    if _loaded or n >= AUTO_NUMBA_DISCS or AUTO_PYTHON_EVENTS <= 0:
        return ("numba", None) if available() else ("python", None)
    return "python", AUTO_PYTHON_EVENTS


def mark_loaded() -> None:
    """Note that this process has loaded the compiled event loop: later ``"auto"`` engines take it at once."""
    global _loaded
    _loaded = True


def resolve_backend(backend, names, what: str) -> str:
    """The backend to run for the argument ``backend``: ``"auto"`` picks numba when it imports.

    Args:
        backend: the user's argument: ``"auto"``, ``"python"`` or ``"numba"``.
        names: the backends the engine has.
        what: the engine's name, for messages.

    Raises:
        InvalidArgumentError: an unknown backend, or ``"numba"`` without numba (naming the extra to install).
    """
    if not isinstance(backend, str) or (backend != "auto" and backend not in names):
        msg = f"{what} backend must be 'auto' or one of {sorted(names)}, got {backend!r}"
        raise InvalidArgumentError(msg)
    if backend == "auto":
        return "numba" if "numba" in names and available() else "python"
    if backend == "numba" and not available():
        hidden = os.environ.get(HIDE_VARIABLE, "") not in ("", "0")
        why = f"numba is hidden by {HIDE_VARIABLE}" if hidden else "numba is not installed"
        msg = f"backend='numba' needs numba, but {why}: pip install \"discsim[fast]\" (or use backend='auto')"
        raise InvalidArgumentError(msg)
    return backend
