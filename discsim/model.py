"""Validated input state: :class:`Discs` (struct of arrays) and :class:`Box`.

Both classes check their input once, at construction, and are immutable
afterwards; engines copy what they need and trust it. Checks that need both
(inside the box, no overlaps) live in :class:`discsim.scene.Scene`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from discsim.errors import InvalidArgumentError, InvalidDiscsError, UnitsError

__all__ = [
    "LENGTH_RANGE",
    "MASS_RANGE",
    "RESOLUTION",
    "SPEED_RANGE",
    "Box",
    "Discs",
    "Segment",
    "frame_count",
    "image_step",
    "image_steps",
    "kinetic_energy",
    "minimum_image_1d",
    "momentum",
    "normalize_pass_through",
    "polygon",
    "rotational_energy",
]

#: Relative tolerance on the contact distance below which two discs count as overlapping.
OVERLAP_TOLERANCE = 1e-9

# The supported units (issue 18, part 3). The time of impact squares lengths, speeds and length times
# speed (``|dr|^2``, ``|dv|^2``, ``(dr . dv)^2``, ``|dv|^2 |dr|^2``); each must stay a normal float
# (2.2e-308 to 1.8e308) with room to spare, or discs pass through each other unseen. Lengths and speeds
# within 1e-50 to 1e50 keep every such square and product within 1e-232 to 1e200, and times of impact
# (length / speed) within 1e-100 to 1e100; masses within 1e-100 to 1e100 keep energies and impulses
# (mass times speed squared) within 1e-200 to 1e200. Everything in SI units lies well inside.
#: Radii, box sides and |position| (length units): each within this range (positions may also be 0).
LENGTH_RANGE = (1e-50, 1e50)
#: The speed |v| of each moving disc (length per time unit): 0, or within this range.
SPEED_RANGE = (1e-50, 1e50)
#: Each finite mass (mass units); ``numpy.inf`` (an obstacle) is allowed too.
MASS_RANGE = (1e-100, 1e100)
#: The smallest radius must be at least this fraction of the box's longer side: positions near the far
#: side are resolved to 2.2e-16 of the box, and the contact geometry to about 1e-6 of a radius then.
RESOLUTION = 1e-10


def _check_range(what: str, values: np.ndarray, name: str, zero: bool = False, upper_only: bool = False) -> None:
    """Raise :class:`UnitsError` naming the first disc whose ``values`` lie outside the range ``name``.

    ``zero``: 0 is allowed too. ``upper_only``: only the upper bound applies.
    """
    lo, hi = globals()[name]
    bad = values > hi
    if not upper_only:
        bad |= (values < lo) & ((values != 0.0) if zero else True)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        span = f"at most {hi:g}" if upper_only else f"[{lo:g}, {hi:g}]" + (" or 0" if zero else "")
        msg = (
            f"disc {i} has {what} {float(values[i])!r}, outside the range discsim supports ({span}; "
            f"discsim.model.{name}): express it in other units"
        )
        raise UnitsError(msg)


def _readonly(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _real_array(name: str, value, error=InvalidDiscsError) -> np.ndarray:
    """``value`` as a fresh float64 array, refusing what numpy would turn into numbers by guessing.

    Complex numbers (numpy drops the imaginary part with only a warning), strings, bools, ``None`` and other
    objects, and ragged lists raise ``error`` naming ``name`` and the value.
    """
    try:
        raw = np.asarray(value, dtype=object if isinstance(value, (str, bytes)) else None)
    except (TypeError, ValueError) as exc:  # ragged
        msg = f"{name} must be an array of real numbers, got a ragged {_short(value)}"
        raise error(msg) from exc
    if raw.dtype.kind == "O":
        real = (int, float, np.integer, np.floating)
        bad = [x for x in raw.reshape(-1).tolist() if not isinstance(x, real) or isinstance(x, bool)]
        if bad:
            msg = f"{name} must be real numbers, got {_short(bad[0])} in {_short(value)}"
            raise error(msg)
    elif raw.dtype.kind not in "iuf":
        kind = {"c": "complex numbers", "b": "booleans", "U": "strings", "S": "bytes"}.get(raw.dtype.kind, raw.dtype)
        msg = f"{name} must be real numbers, got {kind}: {_short(value)}"
        raise error(msg)
    return np.array(raw, dtype=np.float64)


def _as_float_array(name: str, value, shape: tuple[int, ...]) -> np.ndarray:
    """Return ``value`` as a fresh float64 array of ``shape`` (scalars broadcast)."""
    array = _real_array(name, value)
    if array.ndim == 0 and len(shape) == 1:
        return np.full(shape, float(array))
    if array.shape != shape:
        msg = f"{name} must have shape {shape}, got shape {array.shape}"
        raise InvalidDiscsError(msg)
    return array


def _first_bad(mask: np.ndarray) -> int:
    return int(np.flatnonzero(mask.reshape(len(mask), -1).any(axis=1))[0])


class Discs:
    """A set of N discs as a struct of arrays, validated once.

    Args:
        positions: ``(N, 2)`` centres, in length units.
        velocities: ``(N, 2)`` velocities, in length per time unit.
        radii: ``(N,)`` radii, or one scalar for all; positive and finite.
        masses: ``(N,)`` masses, or one scalar for all; positive; ``numpy.inf``
            makes a fixed obstacle, whose velocity must be zero.
        groups: ``(N,)`` integer collision-group labels (default all 0), used by
            collision filters.
        spins: ``(N,)`` angular velocities (radians per time unit, counter-clockwise positive), or one
            scalar for all; finite; default zeros. They change only at collisions of rough discs
            (``EventDriven(roughness=)``, ``docs/laws.md``).
        inertia: ``(N,)`` moments of inertia (mass times length^2), or one scalar for all; positive;
            default that of a uniform disc, ``m r^2 / 2`` (``numpy.inf`` for an obstacle, which must have
            ``numpy.inf``); ``numpy.inf`` for a disc of finite mass: a rough disc that cannot turn.

    Attributes are read-only float64 arrays of the shapes above.

    Raises:
        InvalidDiscsError: on a wrong shape, a NaN or infinite position,
            velocity or spin, a non-positive radius, mass or inertia, a moving
            obstacle or an obstacle of finite inertia; the message names the
            argument, the first offending disc and its value.

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[1.0, 1.0], [3.0, 1.0]], [[1.0, 0.0], [0.0, 0.0]], radii=0.5)
        >>> len(discs), discs.radii.tolist()
        (2, [0.5, 0.5])
    """

    def __init__(self, positions, velocities, radii, masses=1.0, groups=None, spins=None, inertia=None):
        pos = _real_array("positions", positions)
        if pos.ndim != 2 or pos.shape[1] != 2:
            msg = f"positions must have shape (N, 2), got shape {pos.shape}"
            raise InvalidDiscsError(msg)
        n = pos.shape[0]
        vel = _as_float_array("velocities", velocities, (n, 2))
        rad = _as_float_array("radii", radii, (n,))
        mass = _as_float_array("masses", masses, (n,))
        for name, arr in (("position", pos), ("velocity", vel)):
            bad = ~np.isfinite(arr)
            if bad.any():
                i = _first_bad(bad)
                msg = f"disc {i} has a non-finite {name} {arr[i].tolist()}"
                raise InvalidDiscsError(msg)
        bad = ~(np.isfinite(rad) & (rad > 0))
        if bad.any():
            i = _first_bad(bad)
            msg = f"disc {i} has radius {float(rad[i])!r}; radii must be positive and finite"
            raise InvalidDiscsError(msg)
        bad = ~(mass > 0)  # also catches NaN
        if bad.any():
            i = _first_bad(bad)
            msg = f"disc {i} has mass {float(mass[i])!r}; masses must be positive (numpy.inf for an obstacle)"
            raise InvalidDiscsError(msg)
        _check_range("radius", rad, "LENGTH_RANGE")
        _check_range("coordinate", np.abs(pos).max(axis=1) if n else np.zeros(0), "LENGTH_RANGE", upper_only=True)
        _check_range("speed", np.hypot(vel[:, 0], vel[:, 1]), "SPEED_RANGE", zero=True)
        _check_range("mass", np.where(np.isinf(mass), 1.0, mass), "MASS_RANGE")
        moving_obstacle = np.isinf(mass) & (vel != 0).any(axis=1)
        if moving_obstacle.any():
            i = _first_bad(moving_obstacle)
            msg = f"disc {i} has infinite mass but velocity {vel[i].tolist()}; obstacles must be at rest"
            raise InvalidDiscsError(msg)
        if groups is None:
            grp = np.zeros(n, dtype=np.int64)
        else:
            try:
                grp = np.array(groups)
            except (TypeError, ValueError) as exc:
                msg = f"groups must be ({n},) integers, got {_short(groups)}"
                raise InvalidDiscsError(msg) from exc
            if grp.ndim == 0:
                grp = np.full(n, grp)
            if grp.shape != (n,) or not np.issubdtype(grp.dtype, np.integer) or grp.dtype == np.bool_:
                msg = f"groups must be ({n},) integers, got shape {grp.shape} dtype {grp.dtype}: {_short(groups)}"
                raise InvalidDiscsError(msg)
            if grp.dtype == np.uint64 and (grp > np.iinfo(np.int64).max).any():  # they would wrap to negatives
                i = int(np.flatnonzero(grp > np.iinfo(np.int64).max)[0])
                msg = f"disc {i} has group label {int(grp[i])}, above the largest label 2**63 - 1"
                raise InvalidDiscsError(msg)
            grp = grp.astype(np.int64)
        spin, moment = _rotation(n, spins, inertia, rad, mass)
        self.positions = _readonly(pos)
        self.velocities = _readonly(vel)
        self.radii = _readonly(rad)
        self.masses = _readonly(mass)
        self.groups = _readonly(grp)
        self.spins = _readonly(spin)
        self.inertia = _readonly(moment)

    def __len__(self) -> int:
        return len(self.radii)

    def __repr__(self) -> str:
        if len(self) == 0:
            return "Discs(n=0)"
        return f"Discs(n={len(self)}, radii in [{self.radii.min():g}, {self.radii.max():g}])"

    def replace(self, positions=None, velocities=None, spins=None) -> Discs:
        """Return new validated discs with other positions, velocities and/or spins (the same inertia)."""
        return Discs(
            self.positions if positions is None else positions,
            self.velocities if velocities is None else velocities,
            self.radii,
            self.masses,
            self.groups,
            self.spins if spins is None else spins,
            self.inertia,
        )

    def rotational_energy(self) -> float:
        """Total rotational kinetic energy ``sum(I w^2 / 2)`` (discs of infinite inertia contribute zero)."""
        return rotational_energy(self.spins, self.inertia)

    def kinetic_energy(self) -> float:
        """Total kinetic energy ``sum(m v^2 / 2)`` (obstacles contribute zero)."""
        return kinetic_energy(self.velocities, self.masses)

    def momentum(self) -> np.ndarray:
        """Total momentum ``(2,)`` of the moving discs (obstacles excluded)."""
        return momentum(self.velocities, self.masses)


def _rotation(n: int, spins, inertia, radii: np.ndarray, masses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``spins`` and ``inertia`` of ``Discs`` checked, as ``(N,)`` float arrays (defaults filled in)."""
    spin = np.zeros(n) if spins is None else _as_float_array("spins", spins, (n,))
    bad = ~np.isfinite(spin)
    if bad.any():
        i = _first_bad(bad)
        msg = f"spins: disc {i} has a non-finite spin {float(spin[i])!r}"
        raise InvalidDiscsError(msg)
    if inertia is None:
        return spin, 0.5 * masses * radii * radii  # inf for an obstacle
    moment = _as_float_array("inertia", inertia, (n,))
    bad = ~(moment > 0)  # also catches NaN
    if bad.any():
        i = _first_bad(bad)
        msg = f"inertia: disc {i} has inertia {float(moment[i])!r}; moments of inertia must be positive"
        raise InvalidDiscsError(msg)
    bad = np.isinf(masses) & np.isfinite(moment)
    if bad.any():
        i = _first_bad(bad)
        msg = f"inertia: disc {i} is an obstacle (mass inf) but has inertia {float(moment[i])!r}; it must be inf"
        raise InvalidDiscsError(msg)
    return spin, moment


def rotational_energy(spins: np.ndarray, inertia: np.ndarray) -> float:
    """Sum of ``I w^2 / 2`` over discs of finite inertia."""
    finite = np.isfinite(inertia)
    return float(0.5 * np.dot(inertia[finite], spins[finite] ** 2))


def kinetic_energy(velocities: np.ndarray, masses: np.ndarray) -> float:
    """Sum of ``m v^2 / 2`` over discs of finite mass."""
    finite = np.isfinite(masses)
    v2 = np.einsum("ij,ij->i", velocities[finite], velocities[finite])
    return float(0.5 * np.dot(masses[finite], v2))


def momentum(velocities: np.ndarray, masses: np.ndarray) -> np.ndarray:
    """Sum of ``m v`` over discs of finite mass, shape ``(2,)``."""
    finite = np.isfinite(masses)
    return masses[finite] @ velocities[finite]


@dataclass(frozen=True)
class Box:
    """The rectangle ``[0, width] x [0, height]`` that holds the discs.

    Args:
        width: extent in x (length units), positive and finite.
        height: extent in y (length units), positive and finite.
        periodic: if True the box wraps in x and y (minimum image); otherwise
            its four sides are reflecting walls.

    Example:
        >>> Box(10.0, 5.0).area
        50.0
    """

    width: float
    height: float
    periodic: bool = False

    def __post_init__(self):
        for name in ("width", "height"):
            given = getattr(self, name)
            if isinstance(given, (bool, np.bool_)) or not isinstance(given, (int, float, np.integer, np.floating)):
                msg = f"box {name} must be a number, got {given!r}"  # float("10") would take a string
                raise InvalidArgumentError(msg)
            value = float(given)
            if not (math.isfinite(value) and value > 0):
                msg = f"box {name} must be positive and finite, got {given!r}"
                raise InvalidArgumentError(msg)
            lo, hi = LENGTH_RANGE
            if not lo <= value <= hi:
                msg = (
                    f"box {name} {value!r} is outside the supported lengths [{lo:g}, {hi:g}] "
                    "(discsim.model.LENGTH_RANGE): express it in other units"
                )
                raise UnitsError(msg)
            object.__setattr__(self, name, value)
        flag = self.periodic
        if not (isinstance(flag, (bool, np.bool_)) or (isinstance(flag, (int, np.integer)) and flag in (0, 1))):
            # bool("no") would be True
            msg = f"box periodic must be True or False, got {self.periodic!r}"
            raise InvalidArgumentError(msg)
        object.__setattr__(self, "periodic", bool(self.periodic))

    def as_dict(self) -> dict:
        """``{"width", "height", "periodic"}``, as files store a box; ``Box(**d)`` reads it back.

        Example:
            >>> Box(**Box(3.0, 2.0, periodic=True).as_dict()) == Box(3.0, 2.0, periodic=True)
            True
        """
        return {"width": self.width, "height": self.height, "periodic": self.periodic}

    @property
    def area(self) -> float:
        """Area ``width * height``."""
        return self.width * self.height

    @property
    def size(self) -> np.ndarray:
        """``(2,)`` array ``[width, height]``."""
        return np.array([self.width, self.height])

    def wrap(self, positions: np.ndarray) -> np.ndarray:
        """Map positions into the box when periodic; return them unchanged otherwise."""
        if not self.periodic:
            return positions
        size = self.size
        wrapped = np.mod(positions, size)
        return np.where(wrapped >= size, 0.0, wrapped)  # mod of a tiny negative number rounds up to the size

    def displacement(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``b - a``, with the minimum-image convention when periodic.

        Example:
            >>> Box(10.0, 10.0, periodic=True).displacement([9.0, 1.0], [1.0, 2.0]).tolist()
            [2.0, 1.0]
        """
        return self.minimum_image(np.asarray(b, dtype=float) - np.asarray(a, dtype=float))

    def minimum_image(self, d: np.ndarray) -> np.ndarray:
        """Displacements ``d`` ``(..., 2)`` mapped to their nearest periodic image (unchanged with walls).

        The one minimum-image rule: ``d - size * round(d / size)``, element by
        element (:func:`minimum_image_1d` is the same rule on one float, for the loops).
        """
        if not self.periodic:
            return d
        size = self.size
        return d - size * np.round(d / size)


def minimum_image_1d(d: float, length: float) -> float:
    """One coordinate ``d`` of a displacement mapped to its nearest periodic image in a box ``length`` wide.

    The rule of :meth:`Box.minimum_image` on one float, for the loops (numba compiles this very function into
    the compiled ones): ``round`` rounds halves to even, as ``numpy.round`` does. It keeps the sign of a zero
    (``-0.0`` stays ``-0.0``; the array form gives ``+0.0`` there), as the Python loop always did.

    Example:
        >>> minimum_image_1d(9.0, 10.0), minimum_image_1d(-6.0, 10.0)
        (-1.0, 4.0)
    """
    return d - length * round(d / length)


def image_step(flown: float, wrapped: float, length: float) -> int:
    """Whole box lengths between a coordinate ``flown`` along a path and ``wrapped``, the same point mapped
    into a periodic box ``length`` long: what the point's image count gains (rounds halves to even).

    One float each (numba compiles this very function into the compiled frames); :func:`image_steps` on arrays.

    Example:
        >>> image_step(12.5, 2.5, 10.0), image_step(-0.5, 9.5, 10.0)
        (1, -1)
    """
    return round((flown - wrapped) / length)


def image_steps(flown: np.ndarray, wrapped: np.ndarray, size: np.ndarray) -> np.ndarray:
    """:func:`image_step` on arrays: ``(..., 2)`` float whole box lengths (``size``, ``(2,)``) between points
    ``flown`` and ``wrapped`` (NaN where either is NaN).

    Example:
        >>> image_steps(np.array([[12.5, -0.5]]), np.array([[2.5, 9.5]]), np.array([10.0, 10.0])).tolist()
        [[1.0, -1.0]]
    """
    return np.round((flown - wrapped) / size)


def frame_count(start: float, end: float, dt: float) -> int:
    """The number of whole frame intervals ``dt`` from ``start`` to ``end`` (times), allowing for the roundoff
    of ``k * dt``: a relative slack of 1e-12 and an absolute one of 1e-9 frames.

    Example:
        >>> frame_count(0.0, 0.3, 0.1), frame_count(1.0, 1.25, 0.1)
        (3, 2)
    """
    return math.floor((end - start) / dt * (1 + 1e-12) + 1e-9)


class Segment:
    """A line-segment wall from ``p0`` to ``p1`` (both sides reflect), fixed or moving at a constant velocity.

    Segments build polygonal tables (a triangle, a stadium's straight sides)
    inside a walled box. Discs bounce off the face and off the end points. A segment given a ``velocity`` is
    kinematic (a paddle, a pusher, a conveyor's edge): it moves at that velocity for ever, whatever hits it,
    and a disc bounces off it in its own frame (``EventDriven``, under gravity with elastic bounces only; ``FixedStep``
    at its frames, under the default laws or restitution).

    Args:
        p0, p1: end points ``(2,)`` in length units at time 0; finite and distinct.
        velocity: ``(2,)`` the segment's velocity (length / time; finite); default ``(0, 0)``: fixed.

    Example:
        >>> Segment((0, 0), (3, 4)).length
        5.0
        >>> Segment((0, 0), (0, 1), velocity=(2, 0)).at(1.5)
        Segment([3.0, 0.0], [3.0, 1.0], velocity=[2.0, 0.0])
    """

    __slots__ = ("_before", "p0", "p1", "velocity")

    def __init__(self, p0, p1, velocity=(0.0, 0.0)):
        a = _real_array("segment p0", p0)
        b = _real_array("segment p1", p1)
        v = _real_array("segment velocity", velocity)
        for name, p in (("p0", a), ("p1", b), ("velocity", v)):
            if p.shape != (2,) or not np.isfinite(p).all():
                msg = f"segment {name} must be 2 finite numbers, got {p.tolist()}"
                raise InvalidDiscsError(msg)
        if np.array_equal(a, b):
            msg = f"segment end points must differ, got {a.tolist()} twice"
            raise InvalidDiscsError(msg)
        self.p0 = _readonly(a)
        self.p1 = _readonly(b)
        self.velocity = _readonly(v + 0.0)  # (-0.0 -> 0.0)
        self._before: tuple[float, Segment] | None = None  # (time steered, the segment until then)

    @property
    def moving(self) -> bool:
        """Whether the segment has a velocity."""
        return bool(self.velocity.any())

    def at(self, time: float) -> Segment:
        """The segment where it is at ``time`` (itself if it does not move; before a :meth:`steered` time, where
        it was then)."""
        if self._before is not None and time < self._before[0]:
            return self._before[1].at(time)
        if not self.moving:
            return self
        shift = self.velocity * float(time)
        return Segment(self.p0 + shift, self.p1 + shift, self.velocity)

    def steered(self, time: float, velocity) -> Segment:
        """This segment from ``time`` on at ``velocity`` ``(2,)``, from where it is then; before ``time``, :meth:`at`
        still gives where this one was (a paddle the player steers, drawn where it was at every time).

        Example:
            >>> paddle = Segment((0, 0), (0, 1)).steered(2.0, (1.0, 0.0))
            >>> paddle.at(1.0).p0.tolist(), paddle.at(3.0).p0.tolist()
            ([0.0, 0.0], [1.0, 0.0])

        Raises:
            InvalidDiscsError: on a velocity that is not 2 finite numbers, or a ``time`` that is not finite or comes
                before the segment's last steer.
        """
        v = _real_array("segment velocity", velocity)
        if v.shape != (2,) or not np.isfinite(v).all():
            msg = f"segment velocity must be 2 finite numbers, got {v.tolist()}"
            raise InvalidDiscsError(msg)
        last = -math.inf if self._before is None else self._before[0]
        if not (isinstance(time, (int, float, np.integer, np.floating)) and last <= float(time) < math.inf):
            msg = f"segment steer time must be a finite number, not before its last steer ({last!r}), got {time!r}"
            raise InvalidDiscsError(msg)
        here, time = self.at(time), float(time)
        moved = Segment(here.p0 - v * time, here.p1 - v * time, v)  # where it is at ``time``, at time ``time``
        moved._before = (time, self)
        return moved

    def pieces(self) -> list[tuple[float, Segment]]:
        """``[(until, segment), ...]``: the motions this segment had before each :meth:`steered` time, earliest
        first (each ``segment`` without history: where it was is ``segment.at(t)`` for ``t < until``); ``[]`` if
        it was never steered."""
        out, seg = [], self
        while seg._before is not None:
            until, seg = seg._before
            plain = Segment(seg.p0, seg.p1, seg.velocity)
            out.append((until, plain))
        return out[::-1]

    @property
    def length(self) -> float:
        """Length of the segment."""
        return float(np.hypot(*(self.p1 - self.p0)))

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Distance ``(N,)`` from each of ``points`` ``(N, 2)`` to the segment."""
        points = np.atleast_2d(points)
        e = self.p1 - self.p0
        u = np.clip((points - self.p0) @ e / (e @ e), 0.0, 1.0)
        nearest = self.p0 + u[:, None] * e
        return np.hypot(*(points - nearest).T)

    def __repr__(self) -> str:
        if self.moving:
            return f"Segment({self.p0.tolist()}, {self.p1.tolist()}, velocity={self.velocity.tolist()})"
        return f"Segment({self.p0.tolist()}, {self.p1.tolist()})"


def polygon(vertices) -> list[Segment]:
    """The closed chain of segments through ``vertices`` ``(K, 2)``.

    Example:
        >>> len(polygon([(1, 1), (9, 1), (5, 8)]))
        3
    """
    v = _real_array("polygon vertices", vertices)
    if v.ndim != 2 or v.shape[1] != 2 or len(v) < 2:
        msg = f"polygon vertices must have shape (K, 2) with K >= 2, got shape {v.shape}: {_short(vertices)}"
        raise InvalidDiscsError(msg)
    return [Segment(v[k], v[(k + 1) % len(v)]) for k in range(len(v))]


def normalize_pass_through(pairs) -> frozenset:
    """Validate a collision filter: pairs of group labels whose discs pass through each other.

    Returns a frozenset of sorted ``(g1, g2)`` tuples.

    Example:
        >>> sorted(normalize_pass_through([(2, 1), (3, 3)]))
        [(1, 2), (3, 3)]
    """
    out = set()
    if isinstance(pairs, (str, bytes)) or not (pairs is None or hasattr(pairs, "__iter__")):
        msg = f"pass_through must be a collection of pairs of group labels, got {_short(pairs)}"
        raise InvalidDiscsError(msg)
    for pair in pairs or ():
        try:
            g1, g2 = pair
        except (TypeError, ValueError) as exc:
            msg = f"pass_through must hold pairs of group labels, got {pair!r}"
            raise InvalidDiscsError(msg) from exc
        for g in (g1, g2):
            whole = isinstance(g, (int, np.integer)) or (isinstance(g, (float, np.floating)) and float(g).is_integer())
            if isinstance(g, (bool, np.bool_)) or not whole:
                msg = f"pass_through group labels must be integers, got {g!r} in {pair!r}"
                raise InvalidDiscsError(msg)
        out.add((min(int(g1), int(g2)), max(int(g1), int(g2))))
    return frozenset(out)
