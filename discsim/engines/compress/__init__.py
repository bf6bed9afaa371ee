"""Compression by growing discs (Lubachevsky-Stillinger): the :class:`Compression` engine and :func:`compress`.

``engine.py`` is the engine (validation, the thermostat epochs, the state the driver and checkpoints see)
and :func:`compress`, its one-call form; ``report.py`` the :class:`CompressionReport`; ``epoch.py`` one
epoch and the final shrink; ``loop.py`` the event loop of one epoch, in pure Python, and ``compiled.py``
the same source compiled by numba when it imports.
"""

from discsim.engines.compress.engine import Compression, compress
from discsim.engines.compress.report import DENSEST_PACKING, CompressionReport

__all__ = ["DENSEST_PACKING", "Compression", "CompressionReport", "compress"]
