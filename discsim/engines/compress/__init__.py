"""Compression by growing discs (Lubachevsky-Stillinger): :func:`compress` and its :class:`CompressionReport`.

``engine.py`` validates, runs the thermostat epochs and checks the result; ``loop.py`` is the event loop of
one epoch, in pure Python, and ``compiled.py`` the same source compiled by numba when it imports.
"""

from discsim.engines.compress.engine import DENSEST_PACKING, CompressionReport, compress

__all__ = ["DENSEST_PACKING", "CompressionReport", "compress"]
