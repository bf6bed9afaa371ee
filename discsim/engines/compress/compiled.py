"""The functions of :mod:`.loop`, compiled by numba: imported only when numba imports (``discsim._numba``).

The very source of :mod:`.loop` is compiled, not a copy: each function is rebuilt over one shared table of
globals in which its callees are already the compiled ones, then jitted with
``njit(cache=True, nogil=True, error_model="numpy", _nrt=False)`` as the event-driven numba backend is
(``_nrt=False``: no reference counting of the array arguments of calls between compiled functions).
The first process compiles (a few seconds) and caches the machine code in ``__pycache__``.
"""

from __future__ import annotations

import types

from discsim._numba import numba
from discsim.engines.compress import loop

_nb = numba()
if _nb is None:  # importable without numba (doctest collection); compress() uses it only when numba imports

    def _jit(function):
        return function

else:
    _jit = _nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
_globals = dict(vars(loop))
for _name in loop.ORDER:
    _source = getattr(loop, _name)
    _function = types.FunctionType(_source.__code__, _globals, _name, _source.__defaults__)
    _function.__qualname__ = _source.__qualname__
    _function.__module__ = __name__
    _globals[_name] = _jit(_function)

#: The compiled epoch and time of impact.
run_epoch = _globals["run_epoch"]
growing_time_of_impact = _globals["growing_time_of_impact"]
