"""Rigid convex polygons that move and spin: the bodies of a polygon scene, checked once (issue 33, first step).

:class:`Polygons` holds N bodies, each a convex polygon (one shape for all, or one per body) with its centre,
angle, velocity, spin, mass and moment of inertia. A body's vertices live in its own frame, centred on the
polygon's area centroid (its centre of mass, as a uniform plate) and listed counter-clockwise; at angle ``theta``
the world vertices are ``centre + R(theta) v``. :func:`regular_polygon` builds the common shapes,
:func:`plate_inertia` the moment of inertia of a uniform plate, :func:`overlap_depth` the separating-axis test
that the start is checked with (:func:`check_polygons`: inside a walled box, no two bodies overlapping).

No engine runs polygons yet: this module is the model the certified time of impact
(:mod:`discsim.physics.polygons`) and the engines will take.

Example:
    >>> square = regular_polygon(4, 1.0)
    >>> bodies = Polygons(square, [[0.0, 0.0], [3.0, 0.0]], velocities=[[1.0, 0.0], [-1.0, 0.0]], spins=[0.5, 0.0])
    >>> len(bodies), round(float(bodies.inertia[0]), 12)  # m R^2 / 3 for a square of circumradius R
    (2, 0.333333333333)
    >>> bodies.world_vertices(1)[0].round(12).tolist()  # body 1's first vertex: (3, 0) + (1, 0)
    [4.0, 0.0]
"""

from __future__ import annotations

import math

import numpy as np

from discsim.errors import InvalidArgumentError, InvalidDiscsError, OutsideBoxError, OverlapError
from discsim.model import OVERLAP_TOLERANCE, Box, _readonly, _real_array

__all__ = ["Polygons", "check_polygons", "convex_shape", "overlap_depth", "plate_inertia", "regular_polygon"]

#: Relative size below which a turn between two edges counts as none (collinear vertices: a degenerate polygon).
FLAT = 1e-12


def regular_polygon(n: int, circumradius: float, angle: float = 0.0) -> np.ndarray:
    """The ``(n, 2)`` vertices of a regular n-gon of ``circumradius`` centred on the origin, counter-clockwise, the
    first at ``angle`` (radians) from the x axis.

    Raises:
        InvalidArgumentError: ``n`` not an integer >= 3, or a circumradius that is not positive and finite.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 3:
        msg = f"a regular polygon needs an integer n >= 3 vertices, got {n!r}"
        raise InvalidArgumentError(msg)
    if not (isinstance(circumradius, (int, float, np.integer, np.floating)) and 0.0 < circumradius < math.inf):
        msg = f"circumradius must be a positive, finite number, got {circumradius!r}"
        raise InvalidArgumentError(msg)
    phi = float(angle) + 2.0 * np.pi * np.arange(int(n)) / int(n)
    return float(circumradius) * np.column_stack([np.cos(phi), np.sin(phi)])


def _area_terms(v: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Twice the signed area of polygon ``v`` ``(K, 2)``, and each edge's cross term and next vertex."""
    w = np.roll(v, -1, axis=0)
    cross = v[:, 0] * w[:, 1] - w[:, 0] * v[:, 1]
    return float(cross.sum()), cross, w


def convex_shape(name: str, vertices) -> np.ndarray:
    """``vertices`` ``(K, 2)`` checked to be a convex polygon, counter-clockwise, shifted so that its area
    centroid is the origin (a new read-only array).

    Raises:
        InvalidDiscsError: naming ``name`` and what is wrong: not ``(K, 2)`` with ``K >= 3``, not finite, no area,
            a repeated vertex or three in a row on one line (degenerate), a turn the other way (not convex), or
            edges that wind round more than once (a star).
    """
    v = _real_array(name, vertices)
    if v.ndim != 2 or v.shape[1] != 2 or len(v) < 3:
        msg = f"{name} must have shape (K, 2) with K >= 3 vertices, got shape {v.shape}"
        raise InvalidDiscsError(msg)
    if not np.isfinite(v).all():
        msg = f"{name} must be finite, got {v.tolist()}"
        raise InvalidDiscsError(msg)
    twice, _, _ = _area_terms(v)
    if twice < 0.0:
        v = v[::-1].copy()
    edges = np.roll(v, -1, axis=0) - v
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    scale = float(lengths.max())
    if scale == 0.0 or float(lengths.min()) <= FLAT * scale:
        k = int(np.argmin(lengths))
        msg = f"{name} is degenerate: vertex {k} {v[k].tolist()} repeats the next one"
        raise InvalidDiscsError(msg)
    after = np.roll(edges, -1, axis=0)
    turns = edges[:, 0] * after[:, 1] - edges[:, 1] * after[:, 0]  # at each edge's end vertex
    flat = np.abs(turns) <= FLAT * lengths * np.roll(lengths, -1)
    if flat.any():
        k = (int(np.argmax(flat)) + 1) % len(v)
        msg = f"{name} is degenerate: vertex {k} {v[k].tolist()} lies on the line through its neighbours"
        raise InvalidDiscsError(msg)
    if (turns < 0.0).any():
        k = (int(np.argmax(turns < 0.0)) + 1) % len(v)
        msg = f"{name} is not convex: it turns the other way at vertex {k} {v[k].tolist()}"
        raise InvalidDiscsError(msg)
    winding = float(np.sum(np.arctan2(turns, np.einsum("ij,ij->i", edges, after)))) / (2.0 * np.pi)
    if round(winding) != 1:
        msg = f"{name} winds round {round(winding)} times (a star, not a convex polygon): {v.tolist()}"
        raise InvalidDiscsError(msg)
    twice, cross, w = _area_terms(v)
    centroid = np.array([np.sum((v[:, 0] + w[:, 0]) * cross), np.sum((v[:, 1] + w[:, 1]) * cross)]) / (3.0 * twice)
    return _readonly(v - centroid)


def plate_inertia(vertices: np.ndarray, mass: float) -> float:
    """The moment of inertia about its centroid of a uniform plate of ``mass`` shaped as ``vertices`` ``(K, 2)``
    (convex, counter-clockwise, centred on its centroid, as :func:`convex_shape` gives them): ``m J / A`` with
    ``J = sum (x_k y_k+1 - x_k+1 y_k)(x_k^2 + x_k x_k+1 + x_k+1^2 + y_k^2 + y_k y_k+1 + y_k+1^2) / 12`` the polar
    second moment of the area ``A``; ``inf`` for an infinite mass."""
    if mass == math.inf:
        return math.inf
    twice, cross, w = _area_terms(vertices)
    x, y = vertices[:, 0], vertices[:, 1]
    polar = float(np.sum(cross * (x * x + x * w[:, 0] + w[:, 0] ** 2 + y * y + y * w[:, 1] + w[:, 1] ** 2))) / 12.0
    return float(mass) * polar / (0.5 * twice)


def _one_shape(vertices) -> bool:
    """Whether ``vertices`` is one shape (rows of numbers) rather than one shape per body (rows of rows)."""
    try:
        return bool(np.ndim(vertices[0][0]) == 0)
    except (TypeError, IndexError, KeyError):
        return True


def _per_body(name: str, value, n: int, shape: tuple[int, ...]) -> np.ndarray:
    """``value`` as a finite float array ``(n, *shape)`` (a scalar, or one entry per body, broadcast)."""
    a = _real_array(name, value)
    try:
        out = np.broadcast_to(a, (n, *shape)).copy()
    except ValueError:
        msg = f"{name} must be a number or have shape {(n, *shape)}, got shape {a.shape}"
        raise InvalidDiscsError(msg) from None
    return out


class Polygons:
    """N rigid convex polygons: their shapes, where they are and how they move.

    Args:
        vertices: one shape for all ``(K, 2)``, or one per body: a sequence of N arrays ``(K_i, 2)`` (length, in
            the body's frame). Each is checked convex (:func:`convex_shape`), made counter-clockwise and shifted
            so that its area centroid is the body's centre.
        positions: ``(N, 2)`` the centres (centroids) at time 0 (length).
        angles: ``(N,)`` or a number: each body's angle at time 0 (radians; 0: its vertices as given).
        velocities: ``(N, 2)`` or a number (length / time).
        spins: ``(N,)`` or a number: angular velocities (radians / time, counter-clockwise).
        masses: ``(N,)`` or a number, > 0; ``inf`` for an obstacle (it never moves).
        inertia: ``(N,)`` or a number, > 0: moments of inertia about the centres (mass length^2); None: each a
            uniform plate's (:func:`plate_inertia`; ``inf`` for an obstacle).

    Attributes:
        vertices (tuple): N read-only arrays ``(K_i, 2)``, centred and counter-clockwise (one array shared by all
            bodies when one shape was given).
        positions, velocities ((N, 2) float64), angles, spins, masses, inertia ((N,) float64): as given or computed.
        circumradii ((N,) float64): each body's largest distance from its centre to a vertex.

    Raises:
        InvalidDiscsError: a shape that is not a convex polygon (naming the body and the vertex), arrays of the
            wrong shape or not finite, masses or inertia that are not positive.
    """

    __slots__ = ("angles", "circumradii", "inertia", "masses", "positions", "spins", "velocities", "vertices")

    def __init__(self, vertices, positions, angles=0.0, velocities=0.0, spins=0.0, masses=1.0, inertia=None):
        pos = _real_array("positions", positions)
        if pos.ndim != 2 or pos.shape[1] != 2:
            msg = f"positions must have shape (N, 2), got shape {pos.shape}"
            raise InvalidDiscsError(msg)
        n = len(pos)
        one = _one_shape(vertices)
        if one:
            shape = convex_shape("vertices", vertices)
            shapes = (shape,) * n
        else:
            if len(vertices) != n:
                msg = f"vertices must be one (K, 2) shape or one per body ({n}), got {len(vertices)} shapes"
                raise InvalidDiscsError(msg)
            shapes = tuple(convex_shape(f"vertices of body {i}", v) for i, v in enumerate(vertices))
        fields = {
            "positions": pos,
            "angles": _per_body("angles", angles, n, ()),
            "velocities": _per_body("velocities", velocities, n, (2,)),
            "spins": _per_body("spins", spins, n, ()),
        }
        for name, a in fields.items():
            if not np.isfinite(a).all():
                k = int(np.argmax(~np.isfinite(a.reshape(n, -1)).all(axis=1)))
                msg = f"{name} of body {k} must be finite, got {a[k].tolist()}"
                raise InvalidDiscsError(msg)
        mass = _per_body("masses", masses, n, ())
        bad = ~(mass > 0.0) | np.isnan(mass)
        if bad.any():
            k = int(np.argmax(bad))
            msg = f"masses must be > 0 (inf for an obstacle): body {k} has {float(mass[k])!r}"
            raise InvalidDiscsError(msg)
        if inertia is None:
            moment = np.array([plate_inertia(shapes[i], float(mass[i])) for i in range(n)])
        else:
            moment = _per_body("inertia", inertia, n, ())
            bad = ~(moment > 0.0) | np.isnan(moment)
            if bad.any():
                k = int(np.argmax(bad))
                msg = f"inertia must be > 0: body {k} has {float(moment[k])!r}"
                raise InvalidDiscsError(msg)
        self.vertices = shapes
        self.positions = _readonly(pos)
        self.angles = _readonly(fields["angles"])
        self.velocities = _readonly(fields["velocities"])
        self.spins = _readonly(fields["spins"])
        self.masses = _readonly(mass)
        self.inertia = _readonly(moment)
        self.circumradii = _readonly(np.array([float(np.hypot(*s.T).max()) for s in shapes]))

    def __len__(self) -> int:
        return len(self.positions)

    def world_vertices(self, i: int, time: float = 0.0) -> np.ndarray:
        """Body ``i``'s vertices ``(K_i, 2)`` in the world at ``time`` (free flight: centre ``p + v t``, angle
        ``theta + w t``)."""
        theta = float(self.angles[i] + self.spins[i] * time)
        c, s = math.cos(theta), math.sin(theta)
        v = self.vertices[i]
        centre = self.positions[i] + self.velocities[i] * time
        return np.column_stack([centre[0] + c * v[:, 0] - s * v[:, 1], centre[1] + s * v[:, 0] + c * v[:, 1]])

    def __repr__(self) -> str:
        sides = sorted({len(v) for v in self.vertices})
        return f"Polygons(n={len(self)}, vertices per body={sides if len(sides) > 1 else sides[0] if sides else 0})"


def overlap_depth(a: np.ndarray, b: np.ndarray) -> float:
    """How deep convex polygons ``a`` ``(K, 2)`` and ``b`` ``(L, 2)`` (world vertices, counter-clockwise) overlap:
    the least, over the edge normals of both (the separating-axis theorem), of the overlap of their shadows on it;
    <= 0 when they are apart or touch (then minus the widest gap)."""
    depth = math.inf
    for p, q in ((a, b), (b, a)):
        edges = np.roll(p, -1, axis=0) - p
        normals = np.column_stack([edges[:, 1], -edges[:, 0]]) / np.hypot(edges[:, 0], edges[:, 1])[:, None]
        sp, sq = p @ normals.T, q @ normals.T  # (K, E), (L, E): the shadows on each outward normal
        depth = min(depth, float(np.min(np.minimum(sp.max(axis=0) - sq.min(axis=0), sq.max(axis=0) - sp.min(axis=0)))))
    return depth


def check_polygons(bodies: Polygons, box: Box) -> None:
    """Refuse, naming the bodies, a start with a body outside a walled box (a vertex beyond a wall, by more than
    ``OVERLAP_TOLERANCE`` of its circumradius) or two bodies overlapping (deeper than that of the smaller);
    pairs are looked at only where their circumcircles meet (the minimum image in a periodic box).

    Raises:
        OutsideBoxError, OverlapError: naming the body (or both) and where.
    """
    n = len(bodies)
    world = [bodies.world_vertices(i) for i in range(n)]
    if not box.periodic:
        for i, v in enumerate(world):
            slack = OVERLAP_TOLERANCE * float(bodies.circumradii[i])
            if v.min() < -slack or (v[:, 0] > box.width + slack).any() or (v[:, 1] > box.height + slack).any():
                msg = (
                    f"body {i} at {bodies.positions[i].tolist()} reaches outside the box {box.width:g} x {box.height:g}"
                )
                raise OutsideBoxError(msg)
    centres, radii = bodies.positions, bodies.circumradii
    for i in range(n - 1):
        gap = box.minimum_image(centres[i + 1 :] - centres[i])
        near = np.flatnonzero(np.hypot(gap[:, 0], gap[:, 1]) < radii[i + 1 :] + radii[i])
        for k in near.tolist():
            j = i + 1 + k
            other = world[i] + (centres[j] - gap[k] - centres[i])  # body i's image next to body j
            if overlap_depth(other, world[j]) > OVERLAP_TOLERANCE * float(min(radii[i], radii[j])):
                msg = f"bodies {i} and {j} overlap at the start (centres {centres[i].tolist()}, {centres[j].tolist()})"
                raise OverlapError(msg)
