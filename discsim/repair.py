"""Discs that overlap or cross a wall, moved the least needed to make a state an engine accepts.

A fixed-step run answers overlaps after the fact, so a snapshot of it may hold overlapping pairs and discs
cut by a wall or a segment, which no engine takes as a start (``OverlapError``, ``OutsideBoxError``).
:func:`violations` lists them; :func:`push_apart` moves the discs involved, and only them, the least
needed, leaves every velocity as it is, and reports each move (:class:`Repair`).
:meth:`Engine.from_snapshot <discsim.engines.base.Engine.from_snapshot>` restarts an engine with either.

The moves, each the least for its constraint alone, in the kinetic metric ``sum_i m_i |dr_i|^2`` (which
keeps a pair's centre of mass, and never moves an obstacle):

- a pair overlapping by ``delta`` along its unit line of centres ``u`` (from ``i`` to ``j``): disc ``i``
  moves ``-delta m_j / (m_i + m_j) u`` and disc ``j`` moves ``+delta m_i / (m_i + m_j) u`` (equal masses:
  ``delta / 2`` each; an obstacle stays and the other disc moves ``delta``), the split of the fixed-step
  ``"separate"`` policy; coincident centres are parted along ``+x``;
- a disc cut by a wall: along the wall's normal until it touches the wall;
- a disc cut by a segment: along the normal from the segment's nearest point, on the side of the segment
  its centre is on, until it touches the segment.

When constraints couple (a chain of overlaps, a disc pressed into a wall by another), the moves are made
in turn, sweep after sweep (projected Gauss-Seidel, as position-based dynamics does), pairs in the order
``(i, j)``, then segments, then walls, until no pair overlaps by more than :data:`STOP` of its contact
distance (a tenth of what the engines accept) and no disc crosses a wall or a segment. The result is a
valid state near the least-move one; for one pair or one wall cut on its own it is exactly that one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from discsim.cells import neighbour_pairs
from discsim.errors import InvalidArgumentError, OutsideBoxError, OverlapError, WrongTypeError
from discsim.model import OVERLAP_TOLERANCE, Box, Discs, minimum_image_1d, normalize_pass_through
from discsim.scene import check_segments, filter_table

__all__ = ["REPAIRS", "STOP", "Repair", "Violations", "push_apart", "restart_scene", "violations"]

#: :func:`push_apart` stops when no pair overlaps by more than this fraction of its contact distance.
STOP = 0.1 * OVERLAP_TOLERANCE
#: Sweeps :func:`push_apart` makes at most before it gives up.
MAX_SWEEPS = 10_000
#: Discs a message names at most.
NAMED = 10


@dataclass(frozen=True)
class Violations:
    """What keeps discs from being a valid start: overlapping pairs and discs cut by a wall or a segment.

    Attributes:
        pairs: ``(P, 2)`` int, the overlapping pairs ``(i, j)``, ``i < j``, deepest first.
        depths: ``(P,)`` how deep each pair overlaps (contact distance less distance; length).
        cut: ``(K,)`` int, the discs cut by a wall or a segment (or outside a walled box), deepest first.
        cut_depths: ``(K,)`` how far each reaches past the wall or into the segment (length).
    """

    pairs: np.ndarray
    depths: np.ndarray
    cut: np.ndarray
    cut_depths: np.ndarray

    def __bool__(self) -> bool:
        return bool(len(self.pairs) or len(self.cut))

    def describe(self) -> str:
        """One sentence naming the discs (the deepest :data:`NAMED` of each kind) and the depths."""
        parts = []
        if len(self.pairs):
            named = ", ".join(
                f"{i} and {j} by {d:.6g}" for (i, j), d in zip(self.pairs[:NAMED].tolist(), self.depths.tolist())
            )
            more = f", ... ({len(self.pairs)} pairs)" if len(self.pairs) > NAMED else ""
            parts.append(f"discs {named}{more} overlap")
        if len(self.cut):
            named = ", ".join(f"{i} by {d:.6g}" for i, d in zip(self.cut[:NAMED].tolist(), self.cut_depths.tolist()))
            more = f", ... ({len(self.cut)} discs)" if len(self.cut) > NAMED else ""
            parts.append(f"discs {named}{more} are cut by a wall or a segment")
        return "; ".join(parts)


def violations(discs: Discs, box: Box, *, segments=(), pass_through=(), tolerance: float = OVERLAP_TOLERANCE):
    """The overlaps and wall or segment cuts the engines refuse, every one of them.

    Pairs overlapping by more than ``tolerance`` of their contact distance (pairs of groups that pass
    through each other excepted), discs cut by a wall by more than ``tolerance`` of their radius, and
    discs nearer a segment than ``(1 - tolerance)`` radii: what :func:`discsim.scene.check_fits` refuses,
    listed instead of the first one raised. O(N) with a cell grid.

    Returns:
        :class:`Violations` (false when there are none).

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[1.0, 1.0], [2.5, 1.0], [5.5, 1.0]], [[0.0, 0.0]] * 3, radii=1.0)
        >>> found = violations(discs, ds.Box(6.0, 3.0))
        >>> found.pairs.tolist(), found.depths.tolist(), found.cut.tolist(), found.cut_depths.tolist()
        ([[0, 1]], [0.5], [2], [0.5])
    """
    discs, box, segments, pass_through = _checked(discs, box, segments, pass_through)
    return _violations(np.array(discs.positions), discs, box, segments, pass_through, tolerance)


@dataclass(frozen=True)
class Repair:
    """What :func:`push_apart` did.

    Attributes:
        discs: the discs where they were moved to (velocities, radii, masses and groups as given).
        displacements: ``(N, 2)`` each disc's move, new less old position (minimum image when periodic;
            length units); zero for the discs left where they were.
        found: the :class:`Violations` of the discs given: the pairs overlapping by more than
            :data:`STOP` of their contact distance and the discs crossing a wall at all or a segment by
            more than :data:`STOP` of their radius (what was repaired).
        sweeps: passes over the constraints (0 when nothing needed a move).
    """

    discs: Discs
    displacements: np.ndarray
    found: Violations
    sweeps: int

    @property
    def distances(self) -> np.ndarray:
        """``(N,)`` how far each disc moved (length)."""
        return np.hypot(self.displacements[:, 0], self.displacements[:, 1])

    @property
    def moved(self) -> np.ndarray:
        """``(K,)`` int, the discs that moved, in order."""
        return np.flatnonzero(self.distances > 0.0)

    def __str__(self) -> str:
        moved = self.moved
        if not len(moved):
            return "nothing to repair: no disc moved"
        far = int(moved[np.argmax(self.distances[moved])])
        return (
            f"moved {len(moved)} discs (the farthest, disc {far}, by {self.distances[far]:.6g}) in {self.sweeps} "
            f"sweep(s): {len(self.found.pairs)} overlapping pair(s), {len(self.found.cut)} disc(s) cut by a wall "
            "or a segment"
        )


def push_apart(discs: Discs, box: Box, *, segments=(), pass_through=()) -> Repair:
    """Move the discs that overlap or cross a wall or a segment the least needed; velocities unchanged.

    The moves and their order are in the module docstring: for one overlapping pair, disc ``i`` moves
    ``delta m_j / (m_i + m_j)`` along the line of centres (away from ``j``) and ``j`` the rest; for one
    disc cut by a wall, it moves along the normal until it touches. Discs that need no move stay exactly
    where they were, and discs already valid come back unchanged (``sweeps == 0``).

    Args:
        discs: the discs, e.g. ``sim.snapshot()`` of a fixed-step run.
        box: their box. segments: fixed :class:`~discsim.model.Segment` walls (walled box).
        pass_through: pairs of group labels whose discs pass through each other (never pushed apart).

    Returns:
        :class:`Repair`: the discs moved, each disc's displacement, what was found, the sweeps made.

    Raises:
        WrongTypeError: if ``discs``, ``box`` or a segment is of the wrong type.
        OverlapError: if two obstacles (infinite mass) overlap, or no valid state was reached in
            :data:`MAX_SWEEPS` sweeps (too many discs for the box), naming the discs.
        OutsideBoxError: if an obstacle is cut by a wall or a segment, a disc is wider than the box, or a
            disc's centre lies on a segment (no side to push it to), naming the disc.

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[2.0, 2.0], [3.5, 2.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0, masses=[1.0, 3.0])
        >>> done = push_apart(discs, ds.Box(8.0, 4.0))  # overlapping by 0.5: the light disc moves 3/4 of it
        >>> done.displacements.tolist(), done.discs.velocities.tolist()
        ([[-0.375, 0.0], [0.125, 0.0]], [[1.0, 0.0], [-1.0, 0.0]])
    """
    discs, box, segments, pass_through = _checked(discs, box, segments, pass_through)
    start = np.array(discs.positions)
    found = _violations(start, discs, box, segments, pass_through, STOP, walls_only_past=True)
    pos = start.copy()
    n = len(discs)
    if not found:
        return Repair(discs, np.zeros((n, 2)), found, 0)
    radii = discs.radii
    moving = np.isfinite(discs.masses)
    _refuse_fixed(found, moving, radii, box)
    pairs = _Pairs(discs, box, pass_through)
    sweeps = 0
    while True:
        if sweeps == MAX_SWEEPS:
            left = _violations(pos, discs, box, segments, pass_through, STOP, walls_only_past=True)
            msg = (
                f"push_apart found no valid state in {MAX_SWEEPS} sweeps (too many discs for the box?): "
                f"{left.describe()}"
            )
            raise OverlapError(msg)
        sweeps += 1
        pairs.sweep(pos)
        _off_segments(pos, radii, moving, segments)
        if box.periodic:
            pos = box.wrap(pos)
        else:
            _inside_walls(pos, radii, moving, box)
        if not _violations(pos, discs, box, segments, pass_through, STOP, walls_only_past=True):
            break
    moved = box.minimum_image(pos - start)
    still = (moved == 0.0).all(axis=1)
    pos[still] = start[still]  # a disc never moved keeps its position to the bit (wrap may have touched it)
    return Repair(discs.replace(positions=pos), moved, found, sweeps)


# --- the parts -----------------------------------------------------------------------------------------------
def _checked(discs, box, segments, pass_through):
    if not isinstance(discs, Discs):
        msg = f"discs must be a discsim.Discs, got {type(discs).__name__}"
        raise WrongTypeError(msg)
    if not isinstance(box, Box):
        msg = f"box must be a discsim.Box, got {type(box).__name__}"
        raise WrongTypeError(msg)
    return discs, box, check_segments(segments, box), normalize_pass_through(pass_through)


def _candidate_pairs(pos, discs, box, pass_through, reach):
    """Pairs ``i < j`` nearer than ``reach`` plus their contact distance (``(i, j, contact)``), filter obeyed."""
    radii = discs.radii
    if len(radii) < 2:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, np.zeros(0)
    i, j, d = neighbour_pairs(box.wrap(pos), 2.0 * float(radii.max()) + reach, box)
    i, j = np.minimum(i, j), np.maximum(i, j)
    contact = radii[i] + radii[j]
    keep = np.hypot(d[:, 0], d[:, 1]) < contact + reach
    if pass_through:
        group, blocked = filter_table(discs.groups, pass_through)
        keep &= ~blocked[group[i], group[j]]
    i, j, contact = i[keep], j[keep], contact[keep]
    order = np.lexsort((j, i))
    return i[order], j[order], contact[order]


def _violations(pos, discs, box, segments, pass_through, tolerance, walls_only_past=False) -> Violations:
    radii = discs.radii
    i, j, contact = _candidate_pairs(pos, discs, box, pass_through, 0.0)
    d = box.minimum_image(pos[j] - pos[i])
    depth = contact - np.hypot(d[:, 0], d[:, 1])
    bad = depth > tolerance * contact
    order = np.argsort(-depth[bad], kind="stable")
    pairs = np.column_stack([i[bad], j[bad]])[order].reshape(-1, 2)
    reach = np.zeros(len(radii))
    if not box.periodic and len(radii):
        slack = 0.0 if walls_only_past else tolerance * radii
        past = np.maximum(radii[:, None] - pos, pos + radii[:, None] - box.size).max(axis=1)
        reach = np.where(past > slack, past, 0.0)
    for segment in segments:
        into = radii - segment.distance(pos) if len(radii) else np.zeros(0)
        reach = np.maximum(reach, np.where(into > tolerance * radii, into, 0.0))
    cut = np.flatnonzero(reach > 0.0)
    cut = cut[np.argsort(-reach[cut], kind="stable")]
    return Violations(pairs, depth[bad][order], cut, reach[cut])


def _refuse_fixed(found: Violations, moving, radii, box) -> None:
    """Raise on what no move can repair: two overlapping obstacles, an obstacle cut, a disc wider than the box."""
    for (i, j), depth in zip(found.pairs.tolist(), found.depths.tolist()):
        if not (moving[i] or moving[j]):
            msg = f"discs {i} and {j} are both obstacles (infinite mass) and overlap by {depth:.6g}: neither can move"
            raise OverlapError(msg)
    for i, depth in zip(found.cut.tolist(), found.cut_depths.tolist()):
        if not moving[i]:
            msg = f"disc {i} is an obstacle (infinite mass) cut by a wall or a segment by {depth:.6g}: it cannot move"
            raise OutsideBoxError(msg)
        if not box.periodic and 2.0 * radii[i] > min(box.width, box.height):
            msg = f"disc {i} of radius {radii[i]:g} is wider than the box {box.width:g} x {box.height:g}"
            raise OutsideBoxError(msg)


class _Pairs:
    """The candidate pairs (a Verlet list with a skin of half the largest radius) and one sweep over them."""

    def __init__(self, discs: Discs, box: Box, pass_through):
        self.discs, self.box, self.pass_through = discs, box, pass_through
        self.skin = 0.5 * float(discs.radii.max())
        masses = discs.masses
        self.inverse = np.where(np.isfinite(masses), 1.0 / masses, 0.0)  # obstacles: 0, they never move
        self.listed_at: np.ndarray | None = None  # the positions when the candidate pairs were listed

    def sweep(self, pos: np.ndarray) -> None:
        """Push every overlapping pair apart in the order ``(i, j)``, each seeing the moves before it."""
        box = self.box
        if self.listed_at is None or np.abs(box.minimum_image(pos - self.listed_at)).max() > 0.5 * self.skin:
            self.i, self.j, self.contact = _candidate_pairs(pos, self.discs, box, self.pass_through, self.skin)
            self.listed_at = pos.copy()
        i, j, contact = self.i, self.j, self.contact
        d = box.minimum_image(pos[j] - pos[i])
        over = np.flatnonzero(np.hypot(d[:, 0], d[:, 1]) < contact * (1.0 - 0.1 * STOP))
        periodic, width, height = box.periodic, box.width, box.height
        inverse = self.inverse
        for k in over.tolist():
            a, b, sigma = int(i[k]), int(j[k]), float(contact[k])
            xa, ya = pos[a].tolist()
            xb, yb = pos[b].tolist()
            dx, dy = xb - xa, yb - ya
            if periodic:
                dx, dy = minimum_image_1d(dx, width), minimum_image_1d(dy, height)
            dist = math.hypot(dx, dy)
            depth = sigma - dist
            if depth <= 0.0:  # parted by an earlier push in this sweep
                continue
            ux, uy = (dx / dist, dy / dist) if dist > 0.0 else (1.0, 0.0)
            wa, wb = inverse[a], inverse[b]
            share_a, share_b = wa / (wa + wb), wb / (wa + wb)
            pos[a] = (xa - share_a * depth * ux, ya - share_a * depth * uy)
            pos[b] = (xb + share_b * depth * ux, yb + share_b * depth * uy)


def _off_segments(pos, radii, moving, segments) -> None:
    for k, segment in enumerate(segments):
        cut = np.flatnonzero((segment.distance(pos) < radii) & moving)
        for i in cut.tolist():
            p = pos[i]
            e = segment.p1 - segment.p0
            u = min(max(float((p - segment.p0) @ e / (e @ e)), 0.0), 1.0)
            nearest = segment.p0 + u * e
            normal = p - nearest
            dist = float(np.hypot(*normal))
            if dist == 0.0:
                msg = f"disc {i} at {p.tolist()} has its centre on segment {k} {segment!r}: no side to push it to"
                raise OutsideBoxError(msg)
            pos[i] = nearest + normal * (radii[i] / dist)


def _inside_walls(pos, radii, moving, box: Box) -> None:
    for axis, size in ((0, box.width), (1, box.height)):
        column = pos[:, axis]
        pos[:, axis] = np.where(moving, np.clip(column, radii, size - radii), column)


# --- restarting an engine -----------------------------------------------------------------------------------------
#: What :meth:`Engine.from_snapshot <discsim.engines.base.Engine.from_snapshot>` does with discs that overlap
#: or cross a wall or a segment.
REPAIRS = ("refuse", "push")


def restart_scene(source, box, segments, pass_through, repair: str):
    """``(discs, box, segments, pass_through, report)`` to build an engine from ``source``, repaired or refused.

    ``source``: an engine (its snapshot, box, segments and filter; ``box`` None or its own,
    ``segments`` and ``pass_through`` None) or :class:`~discsim.model.Discs` (with ``box``).
    ``report``: the :class:`Repair` with ``repair="push"``, None with ``"refuse"``.
    See :meth:`Engine.from_snapshot <discsim.engines.base.Engine.from_snapshot>` for the errors.
    """
    if not isinstance(repair, str) or repair not in REPAIRS:
        msg = f"repair must be one of {list(REPAIRS)}, got {repair!r}"
        raise InvalidArgumentError(msg)
    if isinstance(source, Discs):
        if box is None:
            msg = "from_snapshot of Discs needs their box: from_snapshot(discs, box, ...)"
            raise InvalidArgumentError(msg)
        discs, segments, pass_through = source, segments or (), pass_through or ()
        where = "the discs given"
    elif all(hasattr(source, name) for name in ("snapshot", "box", "segments", "pass_through", "time")):
        if box is not None and box != source.box:
            msg = f"box {box!r} is not the engine's own {source.box!r}: a snapshot restarts in its own box"
            raise InvalidArgumentError(msg)
        for name, value in (("segments", segments), ("pass_through", pass_through)):
            if value is not None:
                msg = f"{name} come from the engine a snapshot is taken of; got {name}={value!r} as well"
                raise InvalidArgumentError(msg)
        discs, box, segments, pass_through = source.snapshot(), source.box, source.segments, source.pass_through
        where = f"the snapshot of {type(source).__name__} at time {source.time!r}"
    else:
        msg = f"from_snapshot needs an engine or discsim.Discs, got {type(source).__name__}"
        raise WrongTypeError(msg)
    discs, box, segments, pass_through = _checked(discs, box, segments, pass_through)
    if repair == "push":
        report = push_apart(discs, box, segments=segments, pass_through=pass_through)
        return report.discs, box, segments, pass_through, report
    found = violations(discs, box, segments=segments, pass_through=pass_through)
    if found:
        msg = (
            f"{where} is not a valid start: {found.describe()} (depths in length units); "
            "from_snapshot(..., repair='push') moves them apart the least needed"
        )
        raise (OverlapError if len(found.pairs) else OutsideBoxError)(msg)
    return discs, box, segments, pass_through, None
