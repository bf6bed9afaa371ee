"""Event-chain Monte Carlo (straight ECMC): the :class:`EventChain` engine.

``engine.py`` is the engine (validation, the random starts, the state the driver and checkpoints see);
``loop.py`` the chains, in pure Python, and ``compiled.py`` the same source compiled by numba when it imports.
"""

from discsim.engines.event_chain.engine import EventChain, EventChainState

__all__ = ["EventChain", "EventChainState"]
