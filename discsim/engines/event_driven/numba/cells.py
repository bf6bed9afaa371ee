"""The compiled loop's cells: singly linked lists of discs in the order they entered (as the Python backend's
tuples), built from and unpacked into the state's members and sizes."""

from __future__ import annotations

from discsim._compiled import jit

__all__ = ["link", "unlink"]


@jit
def link(members, sizes, head, nxt):
    """Build the cells' linked lists from ``members`` (internal numbers, cell by cell) and ``sizes``."""
    k = 0
    for c in range(sizes.shape[0]):
        previous = -1
        head[c] = -1
        for _ in range(sizes[c]):
            j = members[k]
            k += 1
            nxt[j] = -1
            if previous < 0:
                head[c] = j
            else:
                nxt[previous] = j
            previous = j


@jit
def unlink(head, nxt, members, sizes):
    """The cells' members in order (internal numbers), cell by cell, and each cell's size."""
    k = 0
    for c in range(head.shape[0]):
        j = head[c]
        n = 0
        while j >= 0:
            members[k] = j
            k += 1
            n += 1
            j = nxt[j]
        sizes[c] = n


# Cells are singly linked lists in the order their discs entered (as the Python backend's tuples): a cell
# holds a disc or two, so walking it to leave or to join costs less than a second link per disc and a tail
# per cell would in memory.
@jit
def _leave(i, c, head, nxt):
    j = head[c]
    if j == i:
        head[c] = nxt[i]
        return
    while nxt[j] != i:
        j = nxt[j]
    nxt[j] = nxt[i]


@jit
def _enter(i, c, head, nxt):
    nxt[i] = -1
    j = head[c]
    if j < 0:
        head[c] = i
        return
    while nxt[j] >= 0:
        j = nxt[j]
    nxt[j] = i
