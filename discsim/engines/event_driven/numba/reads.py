"""What the compiled backend answers without running the loop: the clock, counters, positions, velocities, the
last event, the queue's size, and its own invariants (a mixin of
:class:`~discsim.engines.event_driven.numba.backend.NumbaBackend`, which holds the arrays these read).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from discsim.events import SENSED
from discsim.physics.dynamics import advance_many
from discsim.physics.sources import piston

__all__ = ["LOG_ROWS", "CompiledReads"]

#: Rows of the buffer the compiled loop writes the event log into, per call (0.1 MB: a streamed run's
#: memory stays flat and small).
LOG_ROWS = 1 << 10


class CompiledReads:
    """The backend's reads, over the arrays :class:`~discsim.engines.event_driven.numba.backend.NumbaBackend`
    builds (``_rec``, ``_ints``, ``_floats``, ``_order`` ...; see :mod:`discsim.engines.event_driven.numba.loop`)."""

    _lp: Any
    scene: Any
    _rec: np.ndarray
    _ints: np.ndarray
    _floats: np.ndarray
    _order: np.ndarray
    _images: np.ndarray
    _rest: np.ndarray
    _rot: np.ndarray
    _count: np.ndarray
    _qt: np.ndarray
    _kept_partner: np.ndarray
    _kept_stamp: np.ndarray
    _cell: np.ndarray
    _head: np.ndarray
    _nxt: np.ndarray
    _qk: np.ndarray
    _qo: np.ndarray
    _qs: np.ndarray
    _bheap: np.ndarray
    _bht: np.ndarray
    _bpos: np.ndarray
    _barg: np.ndarray
    _group: np.ndarray
    _tlast: np.ndarray
    _found: np.ndarray
    _egroup: np.ndarray
    _edges: np.ndarray
    _law_of_motion: Any
    laws: Any
    box: Any
    grid: Any

    # --- cheap reads -----------------------------------------------------------------------
    def _log_rows(self) -> int:
        """Rows of the loop's log buffer: :data:`LOG_ROWS`, and under gravity room for every disc besides (an
        event that wakes a pile logs a ``SET`` record for each disc that falls again)."""
        return LOG_ROWS + (len(self._rec) if self.laws.falls else 0)

    def piston_now(self) -> tuple[float, float, int, float]:
        """The piston's height and velocity now, its impacts so far and its pressure (a piston run only)."""
        from discsim.engines.event_driven.numba import moving  # (compiled: imported with the loop)

        height, velocity, ref_time, hits, pressure = (float(v) for v in moving.numbers(self._edges))
        accel = float(self._edges[len(self._edges) - moving.SLOTS + moving.P_ACCEL])
        since = self.time - float(self._floats[self._lp.F_EPOCH]) - ref_time
        height, velocity = piston.at(height, velocity, accel, since)
        return height, velocity, int(hits), pressure

    @property
    def time(self) -> float:
        return float(self._floats[self._lp.F_TIME])

    @time.setter
    def time(self, value: float) -> None:
        self._floats[self._lp.F_TIME] = value

    @property
    def max_overlap(self) -> float:
        return float(self._floats[self._lp.F_OVERLAP])

    @max_overlap.setter
    def max_overlap(self, value: float) -> None:
        self._floats[self._lp.F_OVERLAP] = value

    @property
    def max_queue(self) -> int:
        return int(self._ints[self._lp.I_MAXQ])

    @property
    def virial(self) -> float:
        """Sum over collisions of ``dp_i . (r_i - r_j)`` since the start (for the pressure)."""
        return float(self._floats[self._lp.F_VIRIAL])

    def counts(self) -> dict[str, int]:
        """``collisions``, ``wall_hits``, ``cell_crossings``, ``stale``, ``predictions`` (and ``rests``, discs
        put to rest, under gravity; ``sensor_events``, enter and leave events, with sensors)."""
        lp, ints = self._lp, self._ints
        counts = {
            "collisions": int(ints[lp.I_COLL]),
            "wall_hits": int(ints[lp.I_WALL]),
            "cell_crossings": int(ints[lp.I_CROSS]),
            "stale": int(ints[lp.I_STALE]),
            "predictions": int(ints[lp.I_PRED]),
        }
        if self.laws.falls:
            counts["rests"] = int(ints[lp.I_RESTS])
        if self.scene.sensors:
            counts["sensor_events"] = int(ints[lp.I_SENSE])
        return counts

    @property
    def dissipated(self) -> float:
        """Kinetic energy lost in collisions (restitution), by discs coming to rest and to drag, since the start
        (drag's over the flights still under way too, up to ``time``)."""
        lost = float(self._floats[self._lp.F_LOST])
        if self.laws.drag == 0.0:
            return lost
        x, y, vx, vy = self._now()
        rank = self._rank()
        rec = self._rec[rank]
        moving = np.isfinite(rec[:, 6])
        m, (x0, y0, vx0, vy0) = rec[moving, 6], rec[moving, :4].T
        gx, gy = self.laws.gravity
        falls = (self._rest[rank] == 0)[moving]
        work = np.where(falls, gx * (x[moving] - x0) + gy * (y[moving] - y0), 0.0)
        kinetic = 0.5 * ((vx0 * vx0 + vy0 * vy0) - (vx[moving] ** 2 + vy[moving] ** 2))
        return lost + float(np.sum(m * (kinetic + work)))

    def turning(self) -> tuple[np.ndarray, np.ndarray]:
        """``(spins, angles)``, each ``(N,)`` at ``time`` in the caller's numbering (new arrays)."""
        rot, rank = self._rot, self._rank()
        angles = rot[:, 2] + rot[:, 0] * (self.time - rot[:, 3])
        return rot[rank, 0].copy(), angles[rank]

    def resting(self) -> np.ndarray:
        """``(N,)`` bool: the discs at rest (under gravity), in the caller's numbering."""
        return self._rest[self._rank()].astype(bool)

    def disc_counts(self) -> np.ndarray:
        """``(N,)`` each disc's collision counter, in the caller's numbering (a new array)."""
        out = np.empty(len(self._order), dtype=np.int64)
        out[self._order] = self._count
        return out

    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, not wrapped."""
        x, y, _, _ = self._now()
        return np.column_stack([x, y]).reshape(-1, 2)

    def _now(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Every disc's ``(x, y, vx, vy)`` at ``time``, in the caller's numbering (the discs that fall under
        gravity advanced with it)."""
        t = self.time - float(self._floats[self._lp.F_EPOCH])
        rank = self._rank()
        rx, ry, vx, vy, tr = self._rec[rank, :5].T
        drag = self.laws.drag
        advance = self._law_of_motion.advance if drag == 0.0 else advance_many
        x, y, vx, vy = advance(rx, ry, vx, vy, t - tr, 0.0, 0.0, drag) if drag else advance(rx, ry, vx, vy, t - tr)
        if self.laws.falls:
            falls = (self._rec[rank, 6] != np.inf) & (self._rest[rank] == 0)
            fx, fy, fvx, fvy = advance(
                rx, ry, self._rec[rank, 2], self._rec[rank, 3], t - tr, *self.laws.gravity, *((drag,) if drag else ())
            )
            x, y, vx, vy = (np.where(falls, f, v) for f, v in ((fx, x), (fy, y), (fvx, vx), (fvy, vy)))
        return x, y, vx, vy

    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time``, each disc followed across the periodic edges."""
        images = self._images[self._rank()].astype(np.float64)
        return self.positions() + images * np.array([self.box.width, self.box.height])

    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time``."""
        _, _, vx, vy = self._now()
        return np.column_stack([vx, vy]).reshape(-1, 2)

    def last_event(self) -> tuple[float, int, int, int] | None:
        """``(time, kind, i, j)`` of the last physical event in the caller's numbering, or None."""
        lp, ints = self._lp, self._ints
        if ints[lp.I_LKIND] < 0:
            return None
        i, j, kind = int(ints[lp.I_LI]), int(ints[lp.I_LJ]), int(ints[lp.I_LKIND])
        order = self._order
        pair = j >= 0 and kind not in SENSED  # a sensor's j is the sensor's index
        return float(self._floats[lp.F_LTIME]), kind, int(order[i]), int(order[j]) if pair else j

    def _rank(self) -> np.ndarray:
        """Internal number of each caller's disc, ``(N,)`` (built when asked: O(N), as every read that needs it)."""
        rank = np.empty_like(self._order)
        rank[self._order] = np.arange(len(self._order))
        return rank

    def nbytes(self) -> int:
        """Bytes of the run state's arrays (per disc, per cell and the queue; not the log buffer)."""
        arrays = (
            self._rec, self._count, self._images, self._kept_partner, self._kept_stamp, self._cell,
            self._head, self._nxt, self._qk, self._qo, self._qs,
            self._qt, self._bheap, self._bht, self._bpos, self._barg, self._order, self._group,
            self._rest, self._tlast, self._egroup,
        )  # fmt: skip
        return sum(a.nbytes for a in arrays)

    def queue_size(self) -> int:
        """Events pending now (at most N)."""
        return int(self._ints[self._lp.I_SIZE])

    def queue_storage(self) -> int:
        """Entries the queue holds: one slot per pending event (no dead entries)."""
        return self.queue_size()

    def _check(self) -> None:
        """Assert the backend's own invariants (each block's earliest event, the heap of blocks, linked cells); O(N)."""
        qt, n = self._qt, len(self._order)
        assert np.isinf(qt[n:]).all() and np.count_nonzero(qt != np.inf) == self.queue_size(), "queue size out of date"
        blocks = qt.reshape(-1, self._lp.BLOCK)
        first = blocks.min(axis=1)
        assert np.array_equal(self._bht[self._bpos], first), "a block's time out of date"
        earliest = np.argmax(blocks == first[:, None], axis=1) + np.arange(len(blocks)) * self._lp.BLOCK
        finite = first != np.inf
        assert np.array_equal(self._barg[finite], earliest[finite]), "a block's earliest disc out of date"
        heap, times = self._bheap, self._bht
        assert np.array_equal(heap[self._bpos], np.arange(len(heap))), "heap positions out of date"
        parent = (np.arange(1, len(heap)) - 1) >> 1
        pt, ct, po, co = times[parent], times[1:], heap[parent], heap[1:]
        ordered = (pt < ct) | ((pt == ct) & (po < co))
        assert ordered.all(), "heap order broken"
        members = np.zeros(len(self._order), dtype=np.int64)
        sizes = np.zeros(len(self.grid), dtype=np.int64)
        self._lp.unlink(self._head, self._nxt, members, sizes)
        assert np.array_equal(np.repeat(np.arange(len(sizes)), sizes), self._cell[members]), "cells out of date"
