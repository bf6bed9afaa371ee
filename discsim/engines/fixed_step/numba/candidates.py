"""The candidates of a compiled sub-frame: their heap, the contacts answered, the growing buffers.

Shared by :mod:`~discsim.engines.fixed_step.numba.detection` (the frame's first candidates),
:mod:`~discsim.engines.fixed_step.numba.cell_table` and :mod:`~discsim.engines.fixed_step.numba.sub_frame`
(the frame driver), with the constants they agree on: the candidate kinds, the ``counts`` slots of
:func:`~discsim.engines.fixed_step.numba.sub_frame.sub_frames` and the ``st`` slots (the fill levels of one
frame's buffers).

The heap is ordered by ``(time, seq)``, ``seq`` counting the pushes, so that it pops in the order of Python's
``heapq`` of ``(time, seq, ...)`` tuples (:meth:`~discsim.engines.fixed_step.sub_frame.SubFrame.push`). The
functions that run per candidate (``leaf``) take ``_nrt=False`` (no reference counts on their array
arguments) and allocate nothing: their callers make room in the growing buffers first.
"""

from __future__ import annotations

import math

import numpy as np

from discsim._numba import numba
from discsim.engines.fixed_step.numba.kernels import jit

_nb = numba()
if _nb is None:  # pragma: no cover - importable without numba (doctests); the engine needs numba to use it

    def leaf(function):
        return function

else:
    leaf = _nb.njit(cache=True, error_model="numpy", _nrt=False)

#: The compiled sub-frame policies by name: the ``policy`` argument of ``sub_frames``.
SUB_FRAME_CODES = {"bisect": 3, "swept": 4}
BISECT, SWEPT = 3, 4
INF = math.inf
COLLISION, WALL, SEGMENT = 0, 1, 2  # candidate kinds (discsim.events.EventKind's order: no log kind is kept)
#: Slots of the ``counts`` array of ``sub_frames``: the engine's counters of the same names.
C_PAIR_TESTS, C_SEGMENT_TESTS, C_BISECTION_TESTS, C_DETECTIONS, C_WALL_HITS = range(5)
# Slots of ``st``, the fill levels of one frame's buffers.
S_HEAP, S_SEQ, S_DONE, S_FOUND, S_EXT, S_EVENTS, S_STAMP, S_NEAR = range(8)


# --- the candidates' heap, ordered by (time, seq) -----------------------------------------------------------
# ``ht[k]`` the time of entry k; ``hn[k]``: seq, kind, a, b, stamp of a, stamp of b.
@leaf
def _before(ht, hn, x, y):
    return ht[x] < ht[y] or (ht[x] == ht[y] and hn[x, 0] < hn[y, 0])


@leaf
def _swap(ht, hn, x, y):
    ht[x], ht[y] = ht[y], ht[x]
    for c in range(6):
        hn[x, c], hn[y, c] = hn[y, c], hn[x, c]


@leaf
def _push(ht, hn, st, found, version, tc, kind, a, b):
    """``SubFrame.push``: queue a candidate (room made already); a pair goes to ``found`` too."""
    k = st[S_HEAP]
    ht[k] = tc
    hn[k, 0], hn[k, 1], hn[k, 2], hn[k, 3] = st[S_SEQ], kind, a, b
    hn[k, 4], hn[k, 5] = version[a], version[b] if kind == COLLISION else 0
    st[S_SEQ] += 1
    st[S_HEAP] = k + 1
    while k > 0:
        parent = (k - 1) >> 1
        if not _before(ht, hn, k, parent):
            break
        _swap(ht, hn, k, parent)
        k = parent
    if kind == COLLISION:
        m = st[S_FOUND]
        found[m, 0], found[m, 1] = a, b
        st[S_FOUND] = m + 1


@leaf
def _pop(ht, hn, st):
    """Take the first candidate off the heap: ``(time, kind, a, b, stamp_a, stamp_b)``."""
    tc, kind, a, b, sa, sb = ht[0], hn[0, 1], hn[0, 2], hn[0, 3], hn[0, 4], hn[0, 5]
    size = st[S_HEAP] - 1
    st[S_HEAP] = size
    if size > 0:
        _swap(ht, hn, 0, size)
        k = 0
        while 2 * k + 1 < size:
            child = 2 * k + 1
            if child + 1 < size and _before(ht, hn, child + 1, child):
                child += 1
            if not _before(ht, hn, child, k):
                break
            _swap(ht, hn, k, child)
            k = child
    return tc, kind, a, b, sa, sb


# --- contacts answered in the frame (SubFrame.done) -----------------------------------------------------------
@leaf
def _answered_at(done_head, done_next, done_key, done_time, kind, a, b, tc):
    """Whether contact ``(kind, a, b)`` was last answered at ``tc``; then files it as answered at ``tc``."""
    e = done_head[a]
    again = False
    while e >= 0:
        if done_key[e, 0] == kind and done_key[e, 1] == b:
            again = done_time[e] == tc
            break
        e = done_next[e]
    return again


@leaf
def _file_answer(done_head, done_next, done_key, done_time, st, kind, a, b, tc):
    e = st[S_DONE]
    done_next[e] = done_head[a]
    done_key[e, 0], done_key[e, 1] = kind, b
    done_time[e] = tc
    done_head[a] = e
    st[S_DONE] = e + 1


# --- growing buffers -------------------------------------------------------------------------------------------
@jit
def _room_f(a, need):
    """``a`` (1-D float) with room for ``need`` entries (copied into a larger array when short)."""
    if need <= len(a):
        return a
    b = np.empty(max(need, 2 * len(a)))
    for k in range(len(a)):
        b[k] = a[k]
    return b


@jit
def _room_i(a, need):
    """``a`` (1-D int) with room for ``need`` entries."""
    if need <= len(a):
        return a
    b = np.empty(max(need, 2 * len(a)), dtype=np.int64)
    for k in range(len(a)):
        b[k] = a[k]
    return b


@jit
def _room_i2(a, need):
    """``a`` (2-D int) with room for ``need`` rows."""
    if need <= len(a):
        return a
    b = np.empty((max(need, 2 * len(a)), a.shape[1]), dtype=np.int64)
    for k in range(len(a)):
        for c in range(a.shape[1]):
            b[k, c] = a[k, c]
    return b


@jit
def _room_f2(a, need):
    """``a`` (2-D float) with room for ``need`` rows."""
    if need <= len(a):
        return a
    b = np.empty((max(need, 2 * len(a)), a.shape[1]))
    for k in range(len(a)):
        for c in range(a.shape[1]):
            b[k, c] = a[k, c]
    return b


@jit
def _push_growing(heap, found, st, version, tc, kind, a, b):
    """:func:`_push` after making room: returns the heap and ``found``, grown when they were full."""
    ht, hn = heap
    if st[S_HEAP] == len(ht):
        ht, hn = _room_f(ht, st[S_HEAP] + 1), _room_i2(hn, st[S_HEAP] + 1)
    if kind == COLLISION:
        found = _room_i2(found, st[S_FOUND] + 1)
    _push(ht, hn, st, found, version, tc, kind, a, b)
    return (ht, hn), found
