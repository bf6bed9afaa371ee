"""The scene an engine is given: discs, box, segment walls and the collision filter, validated once.

:class:`Scene` checks everything that needs more than one input (every disc inside the box and clear of the
segments, no overlaps, a well-formed filter) and holds the one definition of the collision filter that every
engine and every check uses (:meth:`Scene.passes`).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from discsim.cells import neighbour_pair_chunks
from discsim.errors import InvalidArgumentError, OutsideBoxError, OverlapError, UnitsError, WrongTypeError
from discsim.model import OVERLAP_TOLERANCE, RESOLUTION, Box, Discs, Segment, normalize_pass_through
from discsim.piston import Piston
from discsim.sensors import check_sensors

__all__ = ["Scene", "check_added", "check_fits", "check_scene", "filter_table"]


def filter_table(groups: np.ndarray, pass_through: frozenset) -> tuple[np.ndarray, np.ndarray]:
    """The collision filter as a table: ``(group, blocked)``.

    ``group`` ``(N,)`` gives each disc's group as an index ``0..G-1`` (its rank
    among the distinct labels); ``blocked`` ``(G, G)`` bool is True where two
    groups pass through each other (``pass_through``: sorted label pairs).

    Example:
        >>> group, blocked = filter_table(np.array([5, 7, 5]), frozenset({(5, 7)}))
        >>> group.tolist(), blocked.tolist()
        ([0, 1, 0], [[False, True], [True, False]])
    """
    labels = np.unique(groups)
    group = np.searchsorted(labels, groups).astype(np.int64)
    names = labels.tolist()
    blocked = np.array([[(min(g, h), max(g, h)) in pass_through for h in names] for g in names], dtype=bool)
    return group, blocked.reshape(len(names), len(names))


def check_fits(
    discs: Discs,
    box: Box,
    tolerance: float = OVERLAP_TOLERANCE,
    segments=(),
    pass_through=frozenset(),
    *,
    new_from: int = 0,
) -> None:
    """Raise if a disc is outside ``box``, cut by a wall or a segment, or overlaps another.

    Overlaps deeper than ``tolerance`` times the contact distance are errors;
    touching discs are allowed, and so are overlaps between groups that pass
    through each other (``pass_through``: sorted group pairs). O(N) with a cell grid.
    With ``new_from`` > 0 only the discs from that index on are checked (against every disc), and the
    messages call them new: the discs before are an engine's own (a fixed-step run may hold overlaps).

    Raises:
        OutsideBoxError: naming the disc, its position and radius (and the segment).
        OverlapError: naming the deepest overlapping pair and the depth (of the first piece of candidate
            pairs, :func:`~discsim.cells.neighbour_pair_chunks`, that holds an overlap: memory stays
            O(N + 2^20) however the discs crowd).
    """
    pos, rad = discs.positions, discs.radii
    if len(discs) <= new_from:
        return
    new = "new disc" if new_from else "disc"
    size = box.size
    if box.periodic:
        bad = ((pos < 0) | (pos >= size)).any(axis=1)
        what = "outside the periodic box [0, width) x [0, height)"
    else:
        slack = tolerance * rad[:, None]
        bad = ((pos - rad[:, None] < -slack) | (pos + rad[:, None] > size + slack)).any(axis=1)
        what = "outside the box or cut by a wall"
    bad[:new_from] = False
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        msg = f"{new} {i} at {pos[i].tolist()} with radius {rad[i]:g} is {what} (box {box.width:g} x {box.height:g})"
        raise OutsideBoxError(msg)
    for k, segment in enumerate(segments):
        cut = segment.distance(pos) < rad * (1.0 - tolerance)
        cut[:new_from] = False
        if cut.any():
            i = int(np.flatnonzero(cut)[0])
            msg = f"{new} {i} at {pos[i].tolist()} with radius {rad[i]:g} is cut by segment {k} {segment!r}"
            raise OutsideBoxError(msg)
    # The candidate pairs in pieces of bounded memory (10^5 discs at one spot make 5 10^9 of them), each
    # piece checked as it comes: the first piece holding an overlap names its deepest one.
    table = filter_table(discs.groups, pass_through) if pass_through else None
    for i, j, d in neighbour_pair_chunks(pos, 2.0 * float(rad.max()), box):
        if new_from:
            keep = np.maximum(i, j) >= new_from
            i, j, d = i[keep], j[keep], d[keep]
        if table is not None:
            group, blocked = table
            keep = ~blocked[group[i], group[j]]
            i, j, d = i[keep], j[keep], d[keep]
        contact = rad[i] + rad[j]
        dist = np.hypot(d[:, 0], d[:, 1])
        depth = contact - dist
        bad = depth > tolerance * contact
        if bad.any():
            k = int(np.argmax(np.where(bad, depth / contact, -np.inf)))
            a, b = min(int(i[k]), int(j[k])), max(int(i[k]), int(j[k]))
            which = f"{new} {b} at {pos[b].tolist()} would overlap {'new ' if a >= new_from else ''}disc {a}"
            msg = (
                f"{which if new_from else f'discs {a} and {b} overlap'} by {depth[k]:.6g} "
                f"(distance {dist[k]:.6g}, contact distance {contact[k]:.6g})"
            )
            raise OverlapError(msg)


def check_added(discs: Discs, box: Box, new_from: int, segments=(), pass_through=frozenset()) -> None:
    """Refuse the discs from index ``new_from`` on (being added to an engine's) as :class:`Scene` refuses discs.

    Their radii must resolve in the box (``RESOLUTION``), and each must fit: in the box, clear of the walls,
    the segments, every disc before it and every other new one (:func:`check_fits` with ``new_from``).
    Messages name each new disc by the index it would get.

    Raises:
        UnitsError: a new radius does not resolve in the box.
        OutsideBoxError: a new disc is outside the box or cut by a wall or segment.
        OverlapError: a new disc overlaps another disc.
    """
    radii = discs.radii[new_from:]
    if len(radii):
        smallest, longest = float(radii.min()), max(box.width, box.height)
        if smallest < RESOLUTION * longest:
            i = new_from + int(np.argmin(radii))
            msg = (
                f"new disc {i} has radius {smallest!r}, below {RESOLUTION:g} of the box's longer side {longest!r}: "
                "positions near the far side would not resolve its contacts (discsim.model.RESOLUTION)"
            )
            raise UnitsError(msg)
    check_fits(discs, box, segments=segments, pass_through=pass_through, new_from=new_from)


def check_segments(segments, box: Box) -> tuple[Segment, ...]:
    """``segments`` as a tuple, each a :class:`~discsim.model.Segment`, in a box with walls.

    Raises:
        WrongTypeError: naming the first that is not a ``Segment``.
        InvalidArgumentError: if there are segments and the box is periodic.
    """
    segments = tuple(segments)
    for k, segment in enumerate(segments):
        if not isinstance(segment, Segment):
            msg = f"segments[{k}] must be a discsim.Segment, got {type(segment).__name__} {segment!r}"
            raise WrongTypeError(msg)
    if segments and box.periodic:
        msg = "segments need a box with walls (periodic=False)"
        raise InvalidArgumentError(msg)
    return segments


def check_unsteered(segments) -> tuple:
    """``segments`` as a tuple, for a new run: refused if one was steered (:meth:`~discsim.model.Segment.steered`,
    ``set_segment_velocity``), since a new run would move it on its last motion from the start, not where it was.

    Raises:
        InvalidArgumentError: naming the first steered segment and when it was steered.
    """
    segments = tuple(segments)
    for k, segment in enumerate(segments):
        pieces = segment.pieces() if isinstance(segment, Segment) else []
        if pieces:
            msg = (
                f"segments[{k}] {segment!r} was steered at time {pieces[-1][0]!r} (set_segment_velocity): a new run "
                "would move it on its last motion from the start, not where it was; give ds.Segment(p0, p1, "
                "velocity) as it moves from the start"
            )
            raise InvalidArgumentError(msg)
    return segments


def check_scene(discs: Discs, box: Box, segments=(), pass_through=()) -> tuple[tuple[Segment, ...], frozenset]:
    """Validate what an engine is given: segments, the collision filter, and :func:`check_fits`.

    Returns:
        ``(segments, pass_through)`` as a tuple of segments and a frozenset of sorted group pairs.

    Raises:
        WrongTypeError: if a segment is not a :class:`~discsim.model.Segment`.
        UnitsError: if the smallest radius is below ``RESOLUTION`` of the box's longer side.
        ValueError: if segments are given with a periodic box.
        OutsideBoxError, OverlapError: from :func:`check_fits`.
    """
    segments = check_segments(segments, box)
    for k, segment in enumerate(segments):
        if not _crosses_box(segment.at(0.0), box):  # (a steered one where it was: not its new motion run back)
            msg = f"segments[{k}] {segment!r} lies entirely outside the box {box.width:g} x {box.height:g}"
            raise InvalidArgumentError(msg)
    if len(discs):
        smallest, longest = float(discs.radii.min()), max(box.width, box.height)
        if smallest < RESOLUTION * longest:
            i = int(np.argmin(discs.radii))
            msg = (
                f"disc {i} has radius {smallest!r}, below {RESOLUTION:g} of the box's longer side {longest!r}: "
                "positions near the far side would not resolve its contacts (discsim.model.RESOLUTION)"
            )
            raise UnitsError(msg)
    pass_through = normalize_pass_through(pass_through)
    labels = np.unique(discs.groups).tolist()
    unknown = sorted({g for pair in pass_through for g in pair} - set(labels))
    if unknown:
        msg = f"pass_through names group label(s) {unknown} that no disc has (groups: {labels[:20]})"
        warnings.warn(msg, UserWarning, stacklevel=4)
    check_fits(discs, box, segments=[segment.at(0.0) for segment in segments], pass_through=pass_through)
    return segments, pass_through


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _crosses_box(segment: Segment, box: Box) -> bool:
    """True if ``segment`` meets the box's rectangle (its ends may both lie outside)."""
    p0, p1 = segment.p0, segment.p1
    lo, hi = 0.0, 1.0  # Liang-Barsky clipping of p0 + s (p1 - p0), s in [0, 1]
    for axis, size in ((0, box.width), (1, box.height)):
        d = p1[axis] - p0[axis]
        for q, e in ((p0[axis], -d), (size - p0[axis], d)):
            if e == 0.0:
                if q < 0.0:
                    return False
            elif e < 0.0:
                lo = max(lo, q / e)
            else:
                hi = min(hi, q / e)
    return lo <= hi


class Scene:
    """What an engine simulates, validated once: discs, box, segment walls and the collision filter.

    Args:
        discs: the :class:`~discsim.model.Discs`.
        box: the :class:`~discsim.model.Box`.
        segments: fixed :class:`~discsim.model.Segment` walls (walled boxes only).
        pass_through: pairs of group labels whose discs pass through each other.
        sensors: :class:`~discsim.sensors.Sensor` regions and trip wires (none by default); in a periodic box
            every one must lie inside the box.
        piston: a :class:`~discsim.piston.Piston` as the top wall of a walled box (None: none); every disc's top
            ``y + r`` at most its height, which is at most the box's.
        check: False for the scene of discs an engine already holds (``add_discs`` checks the new ones with
            :func:`check_added`): ``segments`` and ``pass_through`` as a scene holds them, no check at all.

    Attributes:
        discs, box: as given. segments (tuple[Segment, ...]), sensors (tuple[Sensor, ...]), piston: as given.
        pass_through (frozenset[tuple[int, int]]): sorted group pairs.
        group ((N,) int64): each disc's group as an index into ``blocked``.
        blocked ((G, G) bool): True where two groups pass through each other.

    Raises:
        WrongTypeError: if ``discs``, ``box`` or a segment is of the wrong type.
        InvalidArgumentError: if segments are given with a periodic box.
        InvalidDiscsError: on a malformed ``pass_through``.
        OutsideBoxError, OverlapError: if the discs do not fit (see :func:`check_fits`).

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[1.0, 1.0], [1.5, 1.0]], [[0.0, 0.0], [0.0, 0.0]], 0.5, groups=[1, 1])
        >>> scene = Scene(discs, ds.Box(4.0, 2.0), pass_through=[(1, 1)])
        >>> scene.passes(np.array([0]), np.array([1])).tolist()
        [True]
    """

    def __init__(
        self, discs: Discs, box: Box, segments=(), pass_through=(), *, sensors=(), piston=None, check: bool = True
    ):
        self.piston = piston
        if not check:  # the discs, segments and filter of an engine's own scene, validated when they came in
            self.segments, self.pass_through = tuple(segments), frozenset(pass_through)
            self.sensors = tuple(sensors)
            self.discs, self.box = discs, box
            self.group, self.blocked = filter_table(discs.groups, self.pass_through)
            return
        if not isinstance(discs, Discs):
            msg = f"discs must be a discsim.Discs, got {type(discs).__name__} {_short(discs)}"
            raise WrongTypeError(msg)
        if not isinstance(box, Box):
            msg = f"box must be a discsim.Box, got {type(box).__name__} {_short(box)}"
            raise WrongTypeError(msg)
        self.segments, self.pass_through = check_scene(discs, box, segments, pass_through)
        self.sensors = check_sensors(sensors)
        if box.periodic:
            for k, sensor in enumerate(self.sensors):
                x0, y0, x1, y1 = sensor.bounds()
                if not (0.0 <= x0 and x1 <= box.width and 0.0 <= y0 and y1 <= box.height):
                    why = (
                        "a trip wire's part beyond the edge would never be crossed: the discs wrap"
                        if sensor.shape == "line"
                        else "a region across its edge would be entered without a crossing"
                    )
                    size = f"{box.width:g} x {box.height:g}"
                    msg = f"sensors[{k}] {sensor!r} must lie inside the periodic box {size} ({why})"
                    raise InvalidArgumentError(msg)
        self.discs = discs
        self.box = box
        if piston is not None:
            _check_piston(piston, discs, box)
        self.group, self.blocked = filter_table(discs.groups, self.pass_through)

    def but(self, discs: Discs | None = None, segments: tuple | None = None) -> Scene:
        """This scene with other ``discs`` or ``segments`` (None: these), everything else kept, nothing checked:
        for the discs and segments an engine already holds."""
        return Scene(
            self.discs if discs is None else discs,
            self.box,
            self.segments if segments is None else segments,
            self.pass_through,
            sensors=self.sensors,
            piston=self.piston,
            check=False,
        )

    @property
    def piston_height(self) -> float:
        """The piston's height at time 0 (the box's height when it was given none); nan without a piston."""
        if self.piston is None:
            return math.nan
        return self.box.height if self.piston.height is None else self.piston.height

    @property
    def moving(self) -> bool:
        """True when some segment moves."""
        return any(segment.moving for segment in self.segments)

    @property
    def filtering(self) -> bool:
        """True when some groups pass through each other."""
        return bool(self.pass_through)

    def passes(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """``(P,)`` bool: True where discs ``i[k]`` and ``j[k]`` pass through each other."""
        return self.blocked[self.group[i], self.group[j]]

    def __len__(self) -> int:
        return len(self.discs)


def _check_piston(piston, discs: Discs, box: Box) -> None:
    """Refuse a piston that is not a :class:`~discsim.piston.Piston`, in a periodic box, above the box or below a
    disc's top, naming the disc."""
    if not isinstance(piston, Piston):
        msg = f"piston must be a discsim.Piston, got {type(piston).__name__} {_short(piston)}"
        raise WrongTypeError(msg)
    if box.periodic:
        msg = "a piston is the top wall of a walled box; this box is periodic"
        raise InvalidArgumentError(msg)
    height = box.height if piston.height is None else piston.height
    if height > box.height:
        msg = f"piston height {height!r} is above the box's height {box.height!r}"
        raise InvalidArgumentError(msg)
    tops = discs.positions[:, 1] + discs.radii if len(discs) else np.zeros(0)
    if (tops > height).any():
        k = int(np.argmax(tops))
        msg = f"disc {k}'s top y + r = {float(tops[k])!r} is above the piston's height {height!r}"
        raise OutsideBoxError(msg)
