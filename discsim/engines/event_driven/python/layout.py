"""The pure-Python backend's fast internal forms, shared by its parts: records, cell records, kinds.

A disc's state is one record of six float64 ``(x, y, vx, vy, t_ref, radius)`` in a ``bytearray`` read with
one :class:`struct.Struct` call (a neighbour costs one cache line); each cell has one static record (a
tuple, see :func:`~discsim.engines.event_driven.python.predictor.make_predictor`) that its discs point at.
"""

from __future__ import annotations

import math
import struct

import numpy as np

from discsim.engines.event_driven.numbering import TILE
from discsim.events import EventKind
from discsim.physics.sources import boundaries

# A disc's record in the state buffer: x, y, vx, vy, t_ref, radius (float64).
_RECORD = struct.Struct("6d")
_RECORD_BYTES = _RECORD.size
# Positions in a cell's static record (see predictor.make_predictor): the cell's index,
# its slot in its tile, and the ghost copies of it in other tiles.
_CELL_INDEX, _SLOT, _GHOSTS = 9, 10, 11
# Side, in cells, of the square tiles the table of cell members is cut into (see predictor.tile_cells): the
# tiles of the internal numbering. With a ring of ghost cells a tile holds 12 x 12 = 144 slots, so every
# slot index is one of CPython's cached small ints and a 3x3 block reads no memory outside its tile.
_TILE = TILE

INF = math.inf
# Kinds of queued events, as plain ints for the hot loop (one numbering: EventKind).
_COLLISION, _WALL, _CROSSING, _SEGMENT = (
    int(k) for k in (EventKind.COLLISION, EventKind.WALL, EventKind.CROSSING, EventKind.SEGMENT)
)
# Physical events between moves of the internal clock's epoch (at least 16 per disc).
_REBASE_EVENTS = 1 << 18
# Directions of a cell crossing (one numbering: discsim.physics.sources.boundaries).
_PLUS_X, _MINUS_X, _PLUS_Y, _MINUS_Y = boundaries.PLUS_X, boundaries.MINUS_X, boundaries.PLUS_Y, boundaries.MINUS_Y


def pack_records(x, y, vx, vy, t_ref, radius) -> bytearray:
    """The state buffer of per-disc records from ``(N,)`` arrays, one per field."""
    return bytearray(np.column_stack([x, y, vx, vy, t_ref, radius]).astype(np.float64).tobytes())
