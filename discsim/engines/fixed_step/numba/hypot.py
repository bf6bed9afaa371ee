"""CPython's ``math.hypot``, compiled: the compiled frames' distance, so that they agree with the Python frames to
the last bit (the C library's ``hypot`` differs from CPython's in the last bit now and then).

Moved out of :mod:`~discsim.engines.fixed_step.numba.kernels` (which imports it from here) to keep that module
under the size limit of ``tests/test_architecture.py``.
"""

from __future__ import annotations

import math

from discsim._numba import numba

__all__ = ["cpython_hypot"]

_nb = numba()
if _nb is None:  # pragma: no cover - the engine imports this module only when numba imports

    def jit(function):
        return function

else:
    jit = _nb.njit(cache=True, error_model="numpy")  # as kernels' jit

_DBL_MIN = 2.2250738585072014e-308
_VELTKAMP = 134217729.0  # 2 ** 27 + 1


@jit
def cpython_hypot(x, y):
    """``math.hypot(x, y)`` as CPython 3.10 and 3.11 compute it (Veltkamp splitting, differential correction).

    Example:
        >>> cpython_hypot(3.0, 4.0)
        5.0
    """
    x, y = abs(x), abs(y)
    top = 0.0  # the largest, NaN skipped: hypot(inf, nan) is inf
    if x > top:
        top = x
    if y > top:
        top = y
    if math.isinf(top):
        return top
    if math.isnan(x) or math.isnan(y):
        return math.nan
    if top == 0.0:
        return top
    _, top_e = math.frexp(top)
    if top_e < -1023:  # subnormal: 2 ** -top_e would overflow
        return _DBL_MIN * cpython_hypot(x / _DBL_MIN, y / _DBL_MIN)
    scale = math.ldexp(1.0, -top_e)
    csum, frac1, frac2, frac3 = 1.0, 0.0, 0.0, 0.0
    for v in (x, y):
        v = v * scale
        t = v * _VELTKAMP
        hi = t - (t - v)
        lo = v - hi
        w = hi * hi
        old = csum
        csum += w
        frac1 += (old - csum) + w
        w = 2.0 * hi * lo
        old = csum
        csum += w
        frac2 += (old - csum) + w
        frac3 += lo * lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2 + frac3))
    t = h * _VELTKAMP
    hi = t - (t - h)
    lo = h - hi
    w = -hi * hi
    old = csum
    csum += w
    frac1 += (old - csum) + w
    w = -2.0 * hi * lo
    old = csum
    csum += w
    frac2 += (old - csum) + w
    w = -lo * lo
    old = csum
    csum += w
    frac3 += (old - csum) + w
    w = csum - 1.0 + (frac1 + frac2 + frac3)
    return (h + w / (2.0 * h)) / scale
