"""The functions of :mod:`.loop`, compiled by numba from their very source (imported only when numba imports)."""

from __future__ import annotations

from discsim._compiled import compile_from_source, jit
from discsim.engines.event_chain import loop

_compiled = compile_from_source([getattr(loop, name) for name in loop.ORDER], jit)

#: The compiled chains.
run_chains = _compiled[loop.run_chains]
