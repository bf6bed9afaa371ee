"""Building blocks of the compiled loops: the ``jit`` they share, ``prefetch``, and the compiled segment kernels.

Imported only by compiled modules (``engines/*/numba/``), which are imported when a ``backend="numba"`` engine
is built. Without numba (or with ``DISCSIM_NO_NUMBA=1``) it still imports: ``jit`` returns the plain function
and ``prefetch`` does nothing, so that doctest collection and the pure-Python path never need numba.
"""

from __future__ import annotations

import math

from discsim import kernels
from discsim._numba import numba

__all__ = ["inline", "jit", "prefetch", "reflect_off_segment", "segment_time_of_impact", "time_of_impact"]

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


INF = math.inf

#: :func:`discsim.kernels.time_of_impact`, compiled (the one definition of the time of impact).
time_of_impact = jit(kernels.time_of_impact)


@jit
def segment_time_of_impact(px, py, vx, vy, radius, ax, ay, bx, by):
    """:func:`discsim.kernels.segment_time_of_impact`, compiled (the same float operations in the same order)."""
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    best = INF
    length = math.sqrt(length2)
    nx, ny = -ey / length, ex / length
    s = (px - ax) * nx + (py - ay) * ny
    vn = vx * nx + vy * ny
    if s < 0.0:
        s, vn = -s, -vn
    if vn < 0.0:
        t = (s - radius) / -vn if s > radius else 0.0
        u = ((px + vx * t - ax) * ex + (py + vy * t - ay) * ey) / length2
        if 0.0 <= u <= 1.0:
            best = t
    t = time_of_impact(ax - px, ay - py, -vx, -vy, radius)
    if t < best:
        best = t
    t = time_of_impact(bx - px, by - py, -vx, -vy, radius)
    if t < best:
        best = t
    return best


@jit
def reflect_off_segment(px, py, vx, vy, ax, ay, bx, by):
    """:func:`discsim.kernels.reflect_off_segment`, compiled."""
    ex, ey = bx - ax, by - ay
    u = ((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey)
    u = min(max(u, 0.0), 1.0)
    qx, qy = ax + u * ex, ay + u * ey
    nx, ny = px - qx, py - qy
    k = 2.0 * (vx * nx + vy * ny) / (nx * nx + ny * ny)
    return vx - k * nx, vy - k * ny
