"""What moves on its own in the compiled event loop (:mod:`~discsim.engines.event_driven.numba.loop`): the piston
(the loop of the laws only) and the clock's rebase, which moving segments and the piston follow.

The piston is the top wall of a walled box as a body of mass ``M`` under a constant force (:class:`discsim.Piston`).
Its numbers are the last :data:`SLOTS` of the loop's ``edges`` (after the cells' edges and the laws'), present only
when there is a piston: its mass, its fall's acceleration ``F / M``, its height and velocity at the internal time
``P_T`` (its last impact, or the start), the impacts so far (the stamp that tells a disc's predicted contact is
stale) and the pressure (``F`` is the pressure times the box's width). Impacts only ever push it up, so a contact
predicted before one can only come later (:mod:`discsim.physics.sources.piston`): the loop drops it when it comes
up, as a stale collision.
"""

from __future__ import annotations

import numpy as np

from discsim._compiled import jit
from discsim.engines.event_driven.numba.blocks import reblock
from discsim.engines.event_driven.numba.sensing import place_segments
from discsim.engines.event_driven.numba.support import KEPT, VX, VY, M, T, X, Y
from discsim.events import EventKind
from discsim.physics.compiled import advance, piston_at, piston_bounce, piston_contact

__all__ = [
    "P_ACCEL",
    "P_H",
    "P_HITS",
    "P_MASS",
    "P_PRESSURE",
    "P_T",
    "P_U",
    "SLOTS",
    "hit",
    "now",
    "numbers",
    "put",
    "rebase",
    "time",
]

#: Slots of the piston's numbers, from ``edges.shape[0] - SLOTS``.
P_MASS, P_ACCEL, P_H, P_U, P_T, P_HITS, P_PRESSURE = range(7)
SLOTS = 7
WALL = int(EventKind.WALL)


@jit
def now(t, edges):
    """The piston's height and velocity at internal time ``t``."""
    p = edges.shape[0] - SLOTS
    return piston_at(edges[p + P_H], edges[p + P_U], edges[p + P_ACCEL], t - edges[p + P_T])


@jit
def time(y, vy, ay, r, t, edges):
    """Time from ``t`` until a disc at height ``y`` moving at ``vy`` with the acceleration ``ay`` (gravity, or 0;
    radius ``r``) meets the piston's path as it is now (``inf``: never): the gap falls at the piston's acceleration
    plus the disc's."""
    h, u = now(t, edges)
    return piston_contact(y, vy, r, h, u, edges[edges.shape[0] - SLOTS + P_ACCEL] + ay)


@jit
def hit(i, t, epoch, ax, ay, recording, logged, rec, edges, order, ev_t, ev_kind, ev_i, ev_j, ev_f):
    """Disc ``i`` (flying with the acceleration ``ax``, ``ay`` until now) meets the piston at ``t``: both bounce
    (momentum exchanged along y), the piston's path starts afresh from there and its impacts count one more; the
    disc's record holds its new flight. Logged (when ``recording``, in row ``logged``) as a ``WALL`` record whose
    ``yj`` and ``vyj`` are the piston's height and velocity after."""
    p = edges.shape[0] - SLOTS
    xi, yi, vxi, vyi = advance(rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], t - rec[i, T], ax, ay, 0.0)
    h, u = now(t, edges)
    vyi, u = piston_bounce(rec[i, M], vyi, edges[p + P_MASS], u)
    edges[p + P_H], edges[p + P_U], edges[p + P_T] = h, u, t
    edges[p + P_HITS] += 1.0
    rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], rec[i, T] = xi, yi, vxi, vyi, t
    if recording:
        ev_t[logged] = t + epoch
        ev_kind[logged] = WALL
        ev_i[logged] = order[i]
        ev_j[logged] = -1
        ev_f[logged, 0], ev_f[logged, 1], ev_f[logged, 2], ev_f[logged, 3] = xi, yi, vxi, vyi
        ev_f[logged, 4], ev_f[logged, 5], ev_f[logged, 6], ev_f[logged, 7] = np.nan, h, np.nan, u


@jit
def rebase(shift, epoch, rec, qt, bheap, bht, bpos, barg, seg, edges, laws_end):
    """Move the internal clock's origin from ``epoch`` forward by ``shift``, as the Python backend's ``_rebase`` (the
    caller adds ``shift`` to its epoch): a moving segment's row holds where it is at the new origin (from where it
    was at time 0: the same at every rebase), and the piston's path (numbers after ``laws_end``, if any) counts
    from it."""
    place_segments(seg, epoch + shift)
    if edges.shape[0] > laws_end:
        edges[edges.shape[0] - SLOTS + P_T] -= shift
    for i in range(rec.shape[0]):
        rec[i, T] -= shift
        rec[i, KEPT] = rec[i, KEPT] - shift
    for i in range(qt.shape[0]):
        qt[i] = qt[i] - shift  # inf stays inf
    reblock(qt, bheap, bht, bpos, barg)  # the shift may round two times to one: order them anew


def put(edges: np.ndarray, mass: float, numbers: np.ndarray, width: float, gy: float = 0.0) -> None:
    """Write a state's piston numbers (height, velocity, internal reference time, impacts, pressure:
    :attr:`~discsim.engines.event_driven.state.EventDrivenState.piston`) into ``edges``' last slots, for a piston of
    ``mass`` in a box ``width`` wide under gravity ``gy`` along y (its fall's acceleration
    ``pressure * width / mass - gy``, 0 for a kinematic lid)."""
    height, velocity, ref_time, hits, pressure = (float(v) for v in numbers)
    p = edges.shape[0] - SLOTS
    edges[p + P_MASS] = mass
    edges[p + P_ACCEL] = 0.0 if mass == np.inf else pressure * width / mass - gy
    edges[p + P_H], edges[p + P_U], edges[p + P_T], edges[p + P_HITS], edges[p + P_PRESSURE] = (
        height, velocity, ref_time, hits, pressure,
    )  # fmt: skip


def numbers(edges: np.ndarray) -> np.ndarray:
    """The piston's numbers in ``edges``, as a state holds them (:func:`put`'s ``numbers``)."""
    p = edges.shape[0] - SLOTS
    return edges[[p + P_H, p + P_U, p + P_T, p + P_HITS, p + P_PRESSURE]].copy()
