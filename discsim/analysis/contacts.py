"""Contact data of every collision and wall hit, derived from the event log: stored at no cost when nobody asks.

Each log record holds the state of its discs just after the event; the state just before is each disc's
previous record (or the start). From the two, :func:`contacts` computes, for every physical event at once
(vectorized, O(E log E)): the contact point, the unit normal, the impulse and the normal relative speed.

Conventions: the normal ``n`` points from disc ``i`` towards what it hit (disc ``j``, a wall or a segment);
disc ``i`` receives the impulse ``-J n`` and disc ``j`` receives ``+J n`` (``J >= 0``, momentum units);
``speed`` is the normal speed of approach just before, ``(v_i - v_j) . n`` (or ``v_i . n`` at a wall). For
an elastic contact ``J = 2 mu speed`` with the reduced mass ``mu = m_i m_j / (m_i + m_j)`` (``m_i`` at a wall
or an obstacle).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from discsim.errors import InvalidArgumentError
from discsim.events import COLLISION, WALL, disc_partners
from discsim.trajectory import log_start

__all__ = ["Contact", "Contacts", "contact_of_record", "contacts", "contacts_of"]

#: ``Contacts.surface`` of the four walls of the box (segments are numbered 0, 1, ...).
LEFT, RIGHT, BOTTOM, TOP = -1, -2, -3, -4


class Contact(NamedTuple):
    """One contact, as a callback of ``sim.on(...)`` receives it.

    Attributes:
        time: when. kind: ``"collision"``, ``"wall"`` or ``"segment"``. i, j: the discs (``j = -1`` at a wall).
        point: ``(2,)`` contact point. normal: ``(2,)`` unit normal from ``i`` to what it hit.
        impulse: ``J >= 0`` (``i`` receives ``-J n``). speed: normal speed of approach before the contact.
        surface: the segment's index, or -1 to -4 for the left, right, bottom and top wall (-5: a disc).
    """

    time: float
    kind: str
    i: int
    j: int
    point: np.ndarray
    normal: np.ndarray
    impulse: float
    speed: float
    surface: int


@dataclass(frozen=True)
class Contacts:
    """The contacts of a log, one row per collision or wall hit (arrays of length ``E``).

    Attributes:
        index: each contact's row in the log, ``(E,)``.
        time: as in the log, ``(E,)``.
        kind: ``"collision"``, ``"wall"`` or ``"segment"`` (strings), ``(E,)``.
        i: as in the log, ``(E,)``.
        j: as in the log, ``(E,)``.
        point: contact points, ``(E, 2)``.
        normal: unit normals, ``(E, 2)``.
        impulse: ``(E,)``.
        speed: normal approach speeds, ``(E,)``.
        surface: ``(E,)`` int, as in :class:`Contact`.
    """

    index: np.ndarray
    time: np.ndarray
    kind: np.ndarray
    i: np.ndarray
    j: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    impulse: np.ndarray
    speed: np.ndarray
    surface: np.ndarray

    def __len__(self) -> int:
        return len(self.index)

    def __getitem__(self, k: int) -> Contact:
        return Contact(
            float(self.time[k]),
            str(self.kind[k]),
            int(self.i[k]),
            int(self.j[k]),
            self.point[k].copy(),
            self.normal[k].copy(),
            float(self.impulse[k]),
            float(self.speed[k]),
            int(self.surface[k]),
        )


def contacts(source, discs=None, box=None, segments=()) -> Contacts:
    """The contacts of a run: from an engine (its log in memory), or from a log with its ``discs`` and ``box``.

    Discs are named as in the log, by id (``sim.ids``; the index unless discs were removed).

    Args:
        source: an engine built with ``record=True``, or a structured array of
            :data:`~discsim.events.EVENT_DTYPE` (the log from the start of ``discs``).
        discs: the discs where the log starts (with ``source`` a log).
        box, segments: the box and segment walls (with ``source`` a log).

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
        >>> c = ds.contacts(ds.EventDriven(discs, ds.Box(10.0, 10.0)).run(until=2.5))
        >>> c.kind[0], (int(c.i[0]), int(c.j[0])), c.point[0].tolist(), c.normal[0].tolist()
        ('collision', (1, 0), [5.0, 5.0], [-1.0, 0.0])
        >>> float(c.impulse[0]), float(c.speed[0])
        (2.0, 2.0)
    """
    ids = None
    if hasattr(source, "events") and hasattr(source, "discs"):
        box, segments, events = source.box, source.segments, source.events
        context = getattr(source, "run_context", None)
        discs, ids = (source.discs, None) if context is None else context.log_origin(source.discs)
    else:
        events = np.asarray(source)
        if discs is None or box is None:
            msg = "contacts(events, discs, box): give the discs where the log starts and the box"
            raise InvalidArgumentError(msg)
    _, velocities, radii, masses, _ = log_start(events, discs, ids)  # by disc id (add_discs, remove_discs)
    return contacts_of(events, velocities, masses, radii, box, segments)


def contacts_of(events, velocities, masses, radii, box, segments=()) -> Contacts:
    """:func:`contacts` of ``events`` given every disc's ``velocities`` ``(N, 2)`` before the first record."""
    n_ev = len(events)
    pair = np.flatnonzero(disc_partners(events))
    disc = np.concatenate([events["i"], events["j"][pair]]).astype(np.int64)
    row = np.concatenate([np.arange(n_ev), pair])
    after = np.concatenate(
        [
            np.column_stack([events["vxi"], events["vyi"]]),
            np.column_stack([events["vxj"][pair], events["vyj"][pair]]),
        ]
    ).reshape(-1, 2)
    order = np.lexsort((row, disc))  # by disc, then log order
    before = np.empty_like(after)
    same = np.zeros(len(order), dtype=bool)
    same[1:] = disc[order][1:] == disc[order][:-1]
    before[order] = np.where(same[:, None], np.roll(after[order], 1, axis=0), np.asarray(velocities)[disc[order]])
    n_i = n_ev
    vi_before, vj_before = before[:n_i], np.full((n_ev, 2), np.nan)
    vj_before[pair] = before[n_i:]
    physical = np.flatnonzero((events["kind"] == COLLISION) | (events["kind"] == WALL))
    ev = events[physical]
    i, j = ev["i"].astype(np.int64), ev["j"].astype(np.int64)
    ri = np.column_stack([ev["xi"], ev["yi"]]).reshape(-1, 2)
    vi, vi0 = np.column_stack([ev["vxi"], ev["vyi"]]).reshape(-1, 2), vi_before[physical]
    normal = np.full((len(ev), 2), np.nan)
    impulse = np.full(len(ev), np.nan)
    speed = np.full(len(ev), np.nan)
    surface = np.full(len(ev), -5, dtype=np.int64)
    kind = np.full(len(ev), "collision", dtype=object)
    masses, radii = np.asarray(masses, dtype=float), np.asarray(radii, dtype=float)
    coll = ev["kind"] == COLLISION
    if coll.any():
        c = np.flatnonzero(coll)
        rj = np.column_stack([ev["xj"][c], ev["yj"][c]])
        d = box.minimum_image(rj - ri[c])
        nrm = d / np.hypot(d[:, 0], d[:, 1])[:, None]
        vj, vj0 = np.column_stack([ev["vxj"][c], ev["vyj"][c]]), vj_before[physical][c]
        mi, mj = masses[i[c]], masses[j[c]]
        ji = -mi * np.einsum("ij,ij->i", vi[c] - vi0[c], nrm)
        jj = mj * np.einsum("ij,ij->i", vj - vj0, nrm)
        normal[c] = nrm
        impulse[c] = np.where(np.isfinite(mi), ji, jj)
        speed[c] = np.einsum("ij,ij->i", vi0[c] - vj0, nrm)
    walls = np.flatnonzero(~coll)
    if len(walls):
        dv = vi[walls] - vi0[walls]
        size = np.hypot(dv[:, 0], dv[:, 1])
        nrm = -dv / np.where(size > 0, size, np.nan)[:, None]
        normal[walls] = nrm
        impulse[walls] = masses[i[walls]] * size
        speed[walls] = np.einsum("ij,ij->i", vi0[walls], nrm)
        p, r = ri[walls], radii[i[walls]]
        gaps = [p[:, 0] - r, box.width - r - p[:, 0], p[:, 1] - r, box.height - r - p[:, 1]]
        when = ev["time"][walls][:, None]
        motions = [_segment_then(seg, p, when[:, 0]) for seg in segments]  # (a moving one where it was then)
        gaps += [distance - r for distance, _ in motions]
        nearest = np.argmin(np.abs(np.column_stack(gaps)), axis=1)
        surface[walls] = np.where(nearest < 4, -1 - nearest, nearest - 4)
        kind[walls] = np.where(nearest < 4, "wall", "segment")
        for s, (_, velocity) in enumerate(motions):  # a moving segment's speed of approach is in its frame
            hit = nearest == 4 + s
            if hit.any():
                speed[walls[hit]] -= np.einsum("ij,ij->i", nrm[hit], velocity[hit])
        piston = walls[np.isfinite(ev["yj"][walls])]  # a piston's impact (its height and velocity after in yj, vyj)
        surface[piston], kind[piston] = TOP, "wall"
        speed[piston] = ev["vyj"][piston] - ev["vyi"][piston]  # (elastic: approached as fast as they part)
    point = ri + normal * radii[i][:, None]
    if box.periodic:
        point = box.wrap(point)
    return Contacts(physical, ev["time"].copy(), kind, i, j, point, normal, impulse, speed, surface)


def contact_of_record(rec, i: int, j: int, before_i, before_j, masses, radii, box, segments=()) -> Contact:
    """The :class:`Contact` of one collision or wall record ``rec`` (a row of :data:`~discsim.events.EVENT_DTYPE`),
    in plain floats: the floats :func:`contacts_of` gives for it, without its arrays (what a callback run after
    every event needs: about a tenth of the time).

    Args:
        rec: the record; ``i``, ``j``: its discs as indices now (``j = -1`` at a wall).
        before_i, before_j: ``(vx, vy)`` of ``i`` and ``j`` just before (``before_j`` unused at a wall).
        masses, radii: ``(N,)``. box, segments: the scene's.
    """
    t, xi, yi, vxi, vyi = float(rec["time"]), float(rec["xi"]), float(rec["yi"]), float(rec["vxi"]), float(rec["vyi"])
    vxi0, vyi0 = float(before_i[0]), float(before_i[1])
    ri, mi = float(radii[i]), float(masses[i])
    if int(rec["kind"]) == COLLISION:
        dx, dy = float(rec["xj"]) - xi, float(rec["yj"]) - yi
        if box.periodic:
            dx -= box.width * round(dx / box.width)
            dy -= box.height * round(dy / box.height)
        h = math.hypot(dx, dy)
        nx, ny = dx / h, dy / h
        vxj, vyj, vxj0, vyj0 = float(rec["vxj"]), float(rec["vyj"]), float(before_j[0]), float(before_j[1])
        if math.isfinite(mi):
            impulse = -mi * ((vxi - vxi0) * nx + (vyi - vyi0) * ny)
        else:
            impulse = float(masses[j]) * ((vxj - vxj0) * nx + (vyj - vyj0) * ny)
        speed = (vxi0 - vxj0) * nx + (vyi0 - vyj0) * ny
        kind, surface = "collision", -5
    else:
        dvx, dvy = vxi - vxi0, vyi - vyi0
        size = math.hypot(dvx, dvy)
        scale = size if size > 0 else math.nan
        nx, ny = -dvx / scale, -dvy / scale
        impulse = mi * size
        speed = vxi0 * nx + vyi0 * ny
        gaps = [xi - ri, box.width - ri - xi, yi - ri, box.height - ri - yi]
        then = [seg.at(t) for seg in segments]  # (a moving one where it was then, as it moved then)
        gaps += [float(seg.distance(np.array([[xi, yi]]))[0]) - ri for seg in then]
        nearest = min(range(len(gaps)), key=lambda k: abs(gaps[k]))
        kind, surface = ("wall", -1 - nearest) if nearest < 4 else ("segment", nearest - 4)
        if nearest >= 4:  # its speed of approach in the segment's frame
            u = then[nearest - 4].velocity
            speed -= nx * float(u[0]) + ny * float(u[1])
        if math.isfinite(float(rec["yj"])):  # a piston's impact (its height and velocity after in yj, vyj)
            kind, surface, speed = "wall", TOP, float(rec["vyj"]) - vyi  # (elastic: approached as fast as they part)
    px, py = xi + nx * ri, yi + ny * ri
    if box.periodic:
        px, py = (float(v) for v in box.wrap(np.array([px, py])))
    return Contact(t, kind, i, j, np.array([px, py]), np.array([nx, ny]), impulse, speed, surface)


def _segment_then(segment, points: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(distances (K,), velocities (K, 2))``: from each of ``points`` ``(K, 2)`` to ``segment`` where it was at
    each of ``times`` ``(K,)``, and its velocity then (the motion in force then, for one :meth:`Segment.steered`)."""
    distances, velocities = np.empty(len(points)), np.empty((len(points), 2))
    start = -np.inf
    for until, piece in [*segment.pieces(), (np.inf, segment)]:
        now = (times > start) & (times <= until)  # (a hit at the instant of a steer: the motion it steered)
        distances[now] = piece.distance(points[now] - piece.velocity * times[now, None])
        velocities[now] = piece.velocity
        start = until
    return distances, velocities
