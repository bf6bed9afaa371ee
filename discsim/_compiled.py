"""Building blocks of the compiled loops: the ``jit`` and ``inline`` they share, ``prefetch``, and
:func:`compile_from_source`, which compiles plain Python functions (the physics parts) from their very source.

Imported only by compiled modules (``engines/*/numba/``), which are imported when a ``backend="numba"`` engine
is built. Without numba (or with ``DISCSIM_NO_NUMBA=1``) it still imports: ``jit`` returns the plain function
and ``prefetch`` does nothing, so that doctest collection and the pure-Python path never need numba.
"""

from __future__ import annotations

import functools
import hashlib
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from types import FunctionType
from typing import Any, cast

from discsim._numba import numba

__all__ = ["compile_from_source", "inline", "interpret", "jit", "prefetch"]

#: What every compiled function of discsim may compile into itself, besides its own folder's modules (the
#: physics parts, the minimum image, the queue's heap, the event kinds, this module): paths under the package.
DEPENDENCIES = ("physics", "model.py", "laws.py", "queue.py", "events.py", "_compiled.py")
_PACKAGE = Path(__file__).resolve().parent


def source_stamp(py_file) -> bytes:
    """The stamp numba's cache keeps for a compiled function of ``py_file``: a hash of its folder's modules and of
    :data:`DEPENDENCIES`.

    numba checks a cached function against its own source file only, yet the loops compile the physics parts
    into themselves (``inline``): with numba's own stamp, an edit of ``physics/dynamics.py`` would leave every
    cached loop running the old law. Installed copies never change, so their cache stays valid; a developer's
    edit of a part recompiles what depends on it.
    """
    folder = Path(py_file).resolve().parent
    files = sorted({*folder.glob("*.py"), *(p for d in DEPENDENCIES for p in _files(_PACKAGE / d))})
    return _hash_files(tuple((str(path), path.stat().st_mtime_ns, path.stat().st_size) for path in files))


@functools.lru_cache(maxsize=64)
def _hash_files(files: tuple[tuple[str, int, int], ...]) -> bytes:
    """A hash of the files' names (under the package) and contents; memoized on their times and sizes, so the
    many compiled functions of one process read each file once."""
    digest = hashlib.sha256()
    for name, _, _ in files:
        path = Path(name)
        digest.update(str(path.relative_to(_PACKAGE) if path.is_relative_to(_PACKAGE) else path).encode())
        digest.update(path.read_bytes())
    return digest.digest()


def _files(path: Path) -> list[Path]:
    if path.is_dir():
        return sorted(path.rglob("*.py"))
    return [path] if path.exists() else []


def _install_cache_stamp(nb) -> None:
    """Make numba stamp the cached functions of discsim's own files with :func:`source_stamp` (both where numba
    puts its cache by default and under ``NUMBA_CACHE_DIR``); functions of other files keep numba's stamp.

    Uses numba's cache locators (``numba.core.caching``); with a numba whose locators differ, nothing is
    changed and numba's own stamp applies.
    """
    try:
        from numba.core import caching

        bases = (caching.UserProvidedCacheLocator, caching.InTreeCacheLocator)
        locators = caching.CacheImpl._locator_classes
    except (ImportError, AttributeError):
        return

    def stamped(base):
        class Locator(base):
            @classmethod
            def from_function(cls, py_func, py_file):
                if not Path(py_file).resolve().is_relative_to(_PACKAGE):
                    return None
                return super().from_function(py_func, py_file)

            def get_source_stamp(self):
                return source_stamp(self._py_file)

        Locator.__name__ = Locator.__qualname__ = f"Discsim{base.__name__}"
        return Locator

    if not any(k.__name__.startswith("Discsim") for k in locators):
        locators[:0] = [stamped(base) for base in bases]


_nb = numba()
if _nb is None:

    def jit(function):
        return function

    def prefetch(array, offset):
        """Without numba: nothing to fetch."""

    inline = jit

else:
    from llvmlite import ir
    from numba.core import cgutils, types
    from numba.extending import intrinsic

    _install_cache_stamp(_nb)
    # Cached on disk; no reference counts on array arguments (they cost 30% of the event loop's time);
    # error_model="numpy": a division by zero gives inf or nan instead of a check on every division (the
    # loops divide only by numbers they have tested, as the Python code does).
    jit = _nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
    #: ``jit`` for a function compiled into each of its callers (numba's own inlining): a call between compiled
    #: functions passes every array argument as a struct of seven words, which a hot loop pays on every event.
    inline = _nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False, inline="always")

    @intrinsic
    def prefetch(typingctx, array, offset):
        """Ask the CPU for the cache line holding element ``offset`` (flat, C order) of ``array``; no effect on
        results. The event loop's next disc is known only when the queue pops it, so at large N each of its
        records would wait for memory in turn; asking early lets the fetches overlap the work before."""
        if not isinstance(array, types.Array) or not isinstance(offset, types.Integer):
            return None

        def codegen(context, builder, signature, args):
            data = context.make_array(signature.args[0])(context, builder, args[0]).data
            byte = ir.IntType(8).as_pointer()
            i32 = ir.IntType(32)
            kind = ir.FunctionType(ir.VoidType(), [byte, i32, i32, i32])
            fetch = cgutils.get_or_insert_function(builder.module, kind, "llvm.prefetch.p0")
            address = builder.bitcast(builder.gep(data, [args[1]]), byte)
            builder.call(fetch, [address, i32(0), i32(3), i32(1)])  # a read, kept in every cache level, data
            return context.get_dummy_value()

        return types.void(array, offset), codegen


def interpret(function):
    """A ``decorate`` for :func:`compile_from_source` that compiles nothing: the functions are only rebuilt over
    their replacements, and run in the interpreter (the pure-Python backend's loop over other physics)."""
    return function


def compile_from_source(
    functions: Iterable[Callable[..., Any]],
    decorate: Callable[[FunctionType], Callable[..., Any]],
    replace: Mapping[Callable[..., Any], Callable[..., Any]] | None = None,
) -> dict[Callable[..., Any], Callable[..., Any]]:
    """Compile plain Python functions with ``decorate`` (``jit`` or ``inline``), from their very source.

    Each function is rebuilt over a copy of its own module's globals in which every function compiled before it
    (matched by identity, not by name) is replaced by its compiled version, so that a compiled function calls
    compiled callees. Pass callees before their callers.

    ``replace`` swaps parts: ``{free_flight.advance: my_law.advance}`` compiles ``my_law.advance`` in the place
    of ``free_flight.advance``, and every function that called the one now calls the other. That is how a loop
    is compiled over another law of motion or collision law without an edit.

    Args:
        functions: plain Python functions, callees first.
        decorate: what compiles one function (``jit``, ``inline``, or numba's ``njit`` with options).
        replace: a dict from listed functions to the functions that stand in for them (None: none).

    Returns:
        A dict from each given function to its compiled version (without numba, or with ``decorate``
        :func:`interpret`, the function rebuilt over the replacements but not compiled; with neither numba
        nor replacements, the function itself).
    """
    replace = replace or {}
    if _nb is None and not replace:
        return {function: function for function in functions}
    compiled: dict[Callable[..., Any], Callable[..., Any]] = {}
    for function in functions:
        source = cast(FunctionType, replace.get(function, function))  # plain Python functions, as documented
        table = dict(source.__globals__)
        for name, value in table.items():
            if isinstance(value, FunctionType):
                value = replace.get(value, value)
                if value in compiled:
                    table[name] = compiled[value]
        rebuilt = FunctionType(source.__code__, table, source.__name__, source.__defaults__, source.__closure__)
        rebuilt.__qualname__ = source.__qualname__
        rebuilt.__module__ = source.__module__
        rebuilt.__doc__ = source.__doc__
        compiled[function] = compiled[source] = decorate(rebuilt)
    return compiled
