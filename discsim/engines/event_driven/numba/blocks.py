"""The compiled loop's event queue: each disc's pending time, and a binary heap of blocks of discs.

Imported by :mod:`discsim.engines.event_driven.numba.loop` (its functions are compiled into the loop's); see that
module for the arrays. Counters live in the loop's ``ints`` (the queue's size in slot ``I_SIZE``).
"""

from __future__ import annotations

import math

from discsim._compiled import inline, jit
from discsim.queue import sift_down, sift_up

__all__ = ["BLOCK", "BLOCK_SHIFT", "I_SIZE", "discard", "push", "reblock"]

INF = math.inf
#: The slot of the loop's ``ints`` that holds the number of pending events (the loop's ``I_SIZE``).
I_SIZE = 7


# --- the queue: each disc's pending time, and a binary heap of blocks of discs ----------------------------
# ``qt[owner]`` is the owner's pending time (inf: none). The discs are cut into blocks of ``BLOCK`` consecutive
# numbers; ``barg[b]`` is block b's earliest owner (the lowest number among equal times) and the heap orders the
# blocks by that owner's ``(time, owner)``: ``bheap[k]`` is the block at position k, ``bht[k]`` its time and
# ``bpos[b]`` its position. Blocks hold consecutive numbers, so ordering equal times by block orders them by
# owner: the heap pops the earliest ``(time, owner)``, as every queue of the Python backend. A heap of owners
# moved (and re-indexed) a random owner per level, about twenty levels at N = 10^6, each a cache miss (a quarter
# of the loop's time there); a disc's new time here rescans its block (16 times in a row, with selects: which is
# earlier is a coin toss) and sifts a heap 16 times smaller, which stays in cache. Blocks of 16 against the heap
# of owners: 1.17x at N = 10^6, 1.12x at 10^4 (blocks of 8 and 32 did less).
BLOCK_SHIFT = 4
BLOCK = 1 << BLOCK_SHIFT
_sift_up = jit(sift_up)
_sift_down = jit(sift_down)


@jit
def _earliest(b, qt):
    """Block ``b``'s earliest ``(time, owner)``: the lowest owner among equal times (inf and the block's first
    owner when it has no event)."""
    base = b << BLOCK_SHIFT
    best = qt[base]
    owner = base
    for o in range(base + 1, base + BLOCK):
        t = qt[o]
        owner = o if t < best else owner
        best = t if t < best else best
    return best, owner


@jit
def _moved(b, t, owner, bheap, bht, bpos, barg):
    """Block ``b``'s earliest event is now ``owner``'s at ``t``: restore the heap."""
    k = bpos[b]
    old = bht[k]
    bht[k] = t
    barg[b] = owner
    if t < old:
        _sift_up(k, bheap, bht, bpos)
    elif t > old:
        _sift_down(k, bheap.shape[0], bheap, bht, bpos)


@inline
def push(owner, t, kind, other, stamp, qt, bheap, bht, bpos, barg, qk, qo, qs, ints):
    """Schedule ``owner``'s event at ``t`` (finite), replacing its pending one.

    The loop leaves a popped event in place until its owner is predicted again, so that the new
    event replaces it with one update instead of a removal and an insertion.
    """
    qk[owner] = kind
    qo[owner] = other
    qs[owner] = stamp
    if qt[owner] == INF:
        ints[I_SIZE] += 1
    qt[owner] = t
    b = owner >> BLOCK_SHIFT
    first = bht[bpos[b]]
    if t < first or (t == first and owner < barg[b]):
        _moved(b, t, owner, bheap, bht, bpos, barg)
    elif barg[b] == owner:  # the block's earliest event moved later: find the new earliest
        first, o = _earliest(b, qt)
        _moved(b, first, o, bheap, bht, bpos, barg)


@jit
def discard(owner, qt, bheap, bht, bpos, barg, ints):
    """Drop ``owner``'s pending event, if any."""
    if qt[owner] != INF:
        qt[owner] = INF
        ints[I_SIZE] -= 1
        b = owner >> BLOCK_SHIFT
        if barg[b] == owner:
            first, o = _earliest(b, qt)
            _moved(b, first, o, bheap, bht, bpos, barg)


@jit
def reblock(qt, bheap, bht, bpos, barg):
    """Find every block's earliest event and build the heap of blocks (at the start, and after every time moved)."""
    n_blocks = bheap.shape[0]
    for b in range(n_blocks):
        bheap[b] = b
        bpos[b] = b
        bht[b], barg[b] = _earliest(b, qt)
    for k in range((n_blocks >> 1) - 1, -1, -1):
        _sift_down(k, n_blocks, bheap, bht, bpos)
