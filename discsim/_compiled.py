"""Building blocks of the compiled loops: the ``jit`` and ``inline`` they share, ``prefetch``, and
:func:`compile_from_source`, which compiles plain Python functions (the physics parts) from their very source.

Imported only by compiled modules (``engines/*/numba/``), which are imported when a ``backend="numba"`` engine
is built. Without numba (or with ``DISCSIM_NO_NUMBA=1``) it still imports: ``jit`` returns the plain function
and ``prefetch`` does nothing, so that doctest collection and the pure-Python path never need numba.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from types import FunctionType
from typing import Any, cast

from discsim._numba import numba

__all__ = ["compile_from_source", "inline", "jit", "prefetch"]

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
        A dict from each given function to its compiled version (to itself, or its replacement, without
        numba: then nothing is compiled and the callers keep their own globals).
    """
    replace = replace or {}
    if _nb is None:
        return {function: replace.get(function, function) for function in functions}
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
