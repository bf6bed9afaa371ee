"""The laws a run uses, as the user chose them: gravity, restitution (with the TC model), rest and roughness,
validated once.

:class:`Laws` is what every engine takes from its ``gravity=``, ``restitution=``, ``tc=``, ``rest_speed=``,
``roughness=`` and ``drag=`` keywords: it checks them (a :class:`~discsim.errors.DiscsimError` naming the argument
and its value, before anything changes), stores them in a run's settings and checkpoints, and gives the compiled loops
their numbers as one small float array (:meth:`Laws.array`) and one table (:meth:`Laws.table`). The defaults are
today's physics, free flight and elastic, smooth collisions, bit for bit (:attr:`Laws.default`).

Example:
    >>> laws = Laws.build(gravity=(0.0, -9.81), restitution=0.8)
    >>> laws.gravity, laws.default
    ((0.0, -9.81), False)
    >>> Laws.build().default
    True
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from discsim.errors import InvalidArgumentError, UnitsError

__all__ = ["LAW_SLOTS", "Laws"]

#: Slots of :meth:`Laws.array`: gravity along x and y, the rest speed, the TC time, whether the restitution
#: depends on the pair of groups (1.0) or is one number (0.0), that number, and the roughness (tangential
#: restitution) beta, and the drag gamma.
GX, GY, REST_SPEED, TC, PER_GROUP, E, BETA, DRAG = range(8)
LAW_SLOTS = 8
#: The default rest speed, as a bounce height: a disc that would bounce less high than this fraction of the
#: smallest radius comes to rest (see :class:`Laws`).
REST_HEIGHT = 1e-3
#: A drag (1 / time) other than 0 lies within this range: the inverse of the times of impact the supported units
#: keep (``discsim.model``), so ``gamma t`` stays a normal float (a subnormal one has lost its digits).
DRAG_RANGE = (1e-100, 1e100)


def _number(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        msg = f"{name} must be a number, got {value!r}"
        raise InvalidArgumentError(msg)
    return float(value)


def _coefficient(name: str, value) -> float:
    e = _number(name, value)
    if not 0.0 <= e <= 1.0:
        msg = f"{name} must lie in [0, 1], got {value!r}"
        raise InvalidArgumentError(msg)
    return e


@dataclass(frozen=True)
class Laws:
    """The laws of one run (build it with :meth:`build`, which checks every value).

    Attributes:
        gravity: ``(gx, gy)``, the uniform acceleration of every disc of finite mass (length / time^2);
            ``(0.0, 0.0)``: none.
        restitution: the normal coefficient of restitution ``e`` in [0, 1] of every collision (1: elastic), or
            a dict from sorted pairs of group labels (``discs.groups``) to ``e``; pairs it does not name are
            elastic, and a disc's bounce off a wall or a segment uses its group's pair with itself.
        tc: the TC model's time (Luding & McNamara 1998): a collision within ``tc`` of either disc's previous
            collision is elastic, the guard against inelastic collapse; 0: none.
        rest_speed: under gravity, a disc whose speed away from a support (a wall, a segment, an obstacle or a
            disc at rest) after an impact is below this comes to rest there (velocity zero, gravity off) until
            something hits it harder (see ``docs/laws.md``); None: the speed of a bounce
            :data:`REST_HEIGHT` times the smallest radius high.
        roughness: the tangential coefficient of restitution ``beta`` in [-1, 1] of every collision and bounce:
            -1, smooth (frictionless: spins never change, today's physics bit for bit); +1, perfectly rough
            (the tangential relative velocity of the contact points reverses, energy conserved); between, the
            tangential relative velocity is scaled by ``-beta`` (:func:`discsim.physics.laws.rough_impulse`).
        drag: the linear drag ``gamma`` >= 0 of every disc of finite mass (1 / time): a force ``-m gamma v``, so
            that between events a velocity relaxes as ``e^(-gamma t)`` towards the terminal velocity
            ``g / gamma`` (:mod:`discsim.physics.damped`); 0: none.
    """

    gravity: tuple[float, float] = (0.0, 0.0)
    restitution: float | dict = 1.0
    tc: float = 0.0
    rest_speed: float | None = None
    roughness: float = -1.0
    drag: float = 0.0
    _pairs: tuple = field(default=(), repr=False)

    @classmethod
    def build(cls, gravity=None, restitution=1.0, tc=0.0, rest_speed=None, roughness=-1.0, drag=0.0) -> Laws:
        """Check the keywords as the engines take them and build the laws.

        Raises:
            InvalidArgumentError: naming the argument and value: gravity not a pair of finite numbers, a
                restitution outside [0, 1] (or a malformed dict), a negative or non-finite ``tc`` or
                ``rest_speed``, a roughness outside [-1, 1], a negative or non-finite drag.
            UnitsError: a drag other than 0 outside :data:`DRAG_RANGE`.
        """
        if gravity is None:
            g = (0.0, 0.0)
        else:
            try:
                pair = tuple(gravity)
            except TypeError:
                pair = ()
            if len(pair) != 2 or not all(math.isfinite(_number("gravity", v)) for v in pair):
                msg = f"gravity must be None or a pair (gx, gy) of finite numbers, got {gravity!r}"
                raise InvalidArgumentError(msg)
            g = (float(pair[0]), float(pair[1]))
        pairs: tuple = ()
        if isinstance(restitution, dict) and not restitution:
            restitution = 1.0  # no pair named: every pair elastic
        if isinstance(restitution, dict):
            checked = {}
            for key, value in restitution.items():
                try:
                    a, b = key
                    labels = (int(a), int(b))
                except (TypeError, ValueError):
                    labels = None
                if labels is None or labels != tuple(key):
                    msg = f"restitution keys must be pairs of group labels (integers), got {key!r}"
                    raise InvalidArgumentError(msg)
                checked[(min(labels), max(labels))] = _coefficient(f"restitution[{key!r}]", value)
            e: float | dict = checked
            pairs = tuple(sorted(checked.items()))
        else:
            e = _coefficient("restitution", restitution)
        tc = _number("tc", tc)
        if not (math.isfinite(tc) and tc >= 0.0):
            msg = f"tc must be a finite number >= 0, got {tc!r}"
            raise InvalidArgumentError(msg)
        if rest_speed is not None:
            rest_speed = _number("rest_speed", rest_speed)
            if not (math.isfinite(rest_speed) and rest_speed > 0.0):  # 0: a disc on a floor would bounce for ever
                msg = f"rest_speed must be None or a positive, finite number, got {rest_speed!r}"
                raise InvalidArgumentError(msg)
        beta = _number("roughness", roughness)
        if not -1.0 <= beta <= 1.0:
            msg = f"roughness must lie in [-1, 1] (-1: smooth, +1: perfectly rough), got {roughness!r}"
            raise InvalidArgumentError(msg)
        gamma = _number("drag", drag)
        if not (math.isfinite(gamma) and gamma >= 0.0):
            msg = f"drag must be a finite number >= 0 (1 / time), got {drag!r}"
            raise InvalidArgumentError(msg)
        if gamma != 0.0 and not DRAG_RANGE[0] <= gamma <= DRAG_RANGE[1]:
            lo, hi = DRAG_RANGE
            msg = (
                f"drag {drag!r} lies outside the range discsim supports ([{lo:g}, {hi:g}] or 0; "
                "discsim.laws.DRAG_RANGE): express it in other units"
            )
            raise UnitsError(msg)
        return cls(g, e, tc, rest_speed, beta, gamma, pairs)

    @property
    def default(self) -> bool:
        """True for free flight and elastic collisions: today's physics, bit for bit."""
        plain = self.gravity == (0.0, 0.0) and not self._pairs and self.restitution == 1.0
        return plain and not self.rough and self.drag == 0.0

    @property
    def rough(self) -> bool:
        """True when collisions turn the discs (``roughness`` above -1)."""
        return self.roughness != -1.0

    @property
    def falls(self) -> bool:
        """True under gravity."""
        return self.gravity != (0.0, 0.0)

    def settings(self) -> dict:
        """The laws as a run's settings store them (plain JSON: pairs of groups as ``"a,b"`` keys)."""
        e = {f"{a},{b}": v for (a, b), v in self._pairs} if self._pairs else self.restitution
        out = {"gravity": list(self.gravity), "restitution": e, "tc": self.tc, "rest_speed": self.rest_speed}
        if self.rough:
            out["roughness"] = self.roughness
        if self.drag != 0.0:
            out["drag"] = self.drag
        return out

    @classmethod
    def from_settings(cls, settings: dict) -> Laws:
        """The laws stored by :meth:`settings` (absent: the defaults, as every run before the laws)."""
        e = settings.get("restitution", 1.0)
        if isinstance(e, dict):
            e = {tuple(int(v) for v in key.split(",")): value for key, value in e.items()}
        gravity = settings.get("gravity")
        return cls.build(
            gravity,
            e,
            settings.get("tc", 0.0),
            settings.get("rest_speed"),
            settings.get("roughness", -1.0),
            settings.get("drag", 0.0),
        )

    def checked(self, scene) -> Laws:
        """These laws, checked against a :class:`~discsim.scene.Scene` (its discs' groups and its box), as an
        engine's constructor checks them (raises as :meth:`check_scene`)."""
        self.check_scene(scene.discs.groups, scene.box)
        return self

    def check_scene(self, groups: np.ndarray, box) -> None:
        """Check the laws against the discs' ``groups`` ``(N,)`` and the ``box``, as an engine's constructor does.

        Raises:
            InvalidArgumentError: a restitution pair naming a group label that no disc has (naming the pair).
            UnitsError: gravity so strong that a fall across the box (its longer side ``L``) would reach a speed,
                ``sqrt(2 |g| L)``, beyond the largest that discsim resolves (:data:`discsim.model.SPEED_RANGE`).
        """
        from discsim.errors import UnitsError
        from discsim.model import SPEED_RANGE

        labels = sorted({int(g) for g in np.unique(groups)})
        for (a, b), _ in self._pairs:
            missing = [g for g in (a, b) if g not in labels]
            if missing:
                msg = (
                    f"restitution names the pair {(a, b)!r}, but no disc has group {missing[0]} (groups: {labels[:20]})"
                )
                raise InvalidArgumentError(msg)
        if self.falls:
            longest = max(float(box.width), float(box.height))
            speed = math.sqrt(2.0 * math.hypot(*self.gravity) * longest)  # inf if |g| L overflows
            if not speed <= SPEED_RANGE[1]:
                msg = (
                    f"gravity {self.gravity!r} is too strong for the box {float(box.width):g} x {float(box.height):g}: "
                    f"a fall across it would reach speed {speed:.3g}, beyond the largest discsim resolves "
                    f"({SPEED_RANGE[1]:g}; discsim.model.SPEED_RANGE)"
                )
                raise UnitsError(msg)

    def rest_speed_for(self, radii: np.ndarray) -> float:
        """The rest speed a run of discs of ``radii`` uses (0 without gravity)."""
        if not self.falls:
            return 0.0
        if self.rest_speed is not None:
            return self.rest_speed
        r = float(np.min(radii)) if len(radii) else 1.0
        return math.sqrt(2.0 * math.hypot(*self.gravity) * REST_HEIGHT * r)

    def array(self, radii: np.ndarray) -> np.ndarray:
        """The numbers the compiled loops read, ``(LAW_SLOTS,)`` float64 (see the slot names above)."""
        out = np.zeros(LAW_SLOTS)
        out[GX], out[GY] = self.gravity
        out[REST_SPEED] = self.rest_speed_for(radii)
        out[TC] = self.tc
        out[PER_GROUP] = 1.0 if self._pairs else 0.0
        out[E] = 1.0 if self._pairs else float(self.restitution)  # type: ignore[arg-type]
        out[BETA] = self.roughness
        out[DRAG] = self.drag
        return out

    def table(self, labels: np.ndarray) -> np.ndarray:
        """``(G, G)`` restitution between the groups ``labels`` (sorted distinct labels; as
        :func:`discsim.scene.filter_table` numbers them); all ones for a single number (unused then)."""
        g = len(labels)
        out = np.ones((max(g, 1), max(g, 1)))
        lookup = dict(self._pairs)
        names = [int(v) for v in labels]
        for a, la in enumerate(names):
            for b, lb in enumerate(names):
                out[a, b] = lookup.get((min(la, lb), max(la, lb)), 1.0)
        return out
