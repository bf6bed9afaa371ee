"""The functions of :mod:`.loop`, compiled by numba: imported only when numba imports (``discsim._numba``).

The very source of :mod:`.loop` is compiled, not a copy: :func:`discsim._compiled.compile_from_source` rebuilds
each function over its globals with its callees (the law of motion's :func:`~discsim.physics.dynamics.advance`
among them) already compiled, then jits it with ``discsim._compiled.jit``, as the event-driven numba backend is
(``_nrt=False``: no reference counting of the array arguments of calls between compiled functions).
The first process compiles (a few seconds) and caches the machine code in ``__pycache__``.
"""

from __future__ import annotations

from discsim._compiled import compile_from_source, jit
from discsim.engines.compress import loop

_compiled = compile_from_source([getattr(loop, name) for name in loop.ORDER], jit)

#: The compiled epoch and time of impact.
run_epoch = _compiled[loop.run_epoch]
growing_time_of_impact = _compiled[loop.growing_time_of_impact]
