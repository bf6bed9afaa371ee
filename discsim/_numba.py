"""numba, when it is installed and not hidden: the one place that imports it.

The compiled backends (``backend="numba"``) need numba, from the ``fast`` extra
(``pip install "discsim[fast]"``). ``backend="auto"`` takes it when it imports.
Setting the environment variable ``DISCSIM_NO_NUMBA=1`` hides it, so that the
pure-Python path can be tested on a machine that has numba.
"""

from __future__ import annotations

import os

from discsim.errors import InvalidArgumentError

__all__ = ["HIDE_VARIABLE", "available", "numba", "resolve_backend"]

#: The environment variable that hides numba from discsim (any value but "", "0").
HIDE_VARIABLE = "DISCSIM_NO_NUMBA"

_module = None
_tried = False


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
    """True when the compiled backends can run."""
    return numba() is not None


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
