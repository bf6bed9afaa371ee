"""Spatial queries at the current time (sim.disc_at, nearest, within, ray_cast), against brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds
from discsim import _numba

needs_numba = pytest.mark.skipif(not _numba.available(), reason="numba is not installed or is hidden")
ENGINES = [
    ("EventDriven", "python"),
    pytest.param(("EventDriven", "numba"), marks=needs_numba),
    ("FixedStep", "python"),
]


def _engine(kind, backend, discs, box, **options):
    cls = ds.EventDriven if kind == "EventDriven" else ds.FixedStep
    return cls(discs, box, backend=backend, **options)


# --- brute force: every disc, every image ---------------------------------------------------------------
def _edge(points, positions, radii, box):
    d = positions[None, :, :] - points[:, None, :]
    d = box.minimum_image(d)
    return np.hypot(d[..., 0], d[..., 1]) - radii[None, :]


def _brute_disc_at(points, positions, radii, box):
    edge = _edge(points, positions, radii, box)
    centre = edge + radii[None, :]
    centre = np.where(edge <= 0, centre, np.inf)
    j = np.argmin(centre, axis=1)
    return np.where(np.isfinite(centre[np.arange(len(points)), j]), j, -1)


def _brute_ray(origin, direction, positions, radii, box, segments, max_t):
    """(kind, index, t) by the plain quadratic for each disc image near the ray, each wall and segment."""
    best = (math.inf, "none", -1)
    images = [(0.0, 0.0)]
    if box.periodic:
        reach = max_t * math.hypot(*direction) + 2 * max(box.width, box.height)
        kx, ky = int(reach / box.width) + 1, int(reach / box.height) + 1
        images = [(a * box.width, b * box.height) for a in range(-kx, kx + 1) for b in range(-ky, ky + 1)]
    a = direction @ direction
    for j, (c, r) in enumerate(zip(positions, radii)):
        for sx, sy in images:
            rel = c + np.array([sx, sy]) - origin
            b = direction @ rel
            cc = rel @ rel - r * r
            if cc <= 0:
                t = 0.0
            else:
                disc = b * b - a * cc
                if b <= 0 or disc < 0:
                    continue
                t = (b - math.sqrt(disc)) / a
            if t <= max_t and t < best[0]:
                best = (t, "disc", j)
    if not box.periodic:
        for side, (axis, wall) in enumerate(((0, 0.0), (0, box.width), (1, 0.0), (1, box.height))):
            if direction[axis] != 0:
                t = (wall - origin[axis]) / direction[axis]
                if t >= 0 and t < best[0]:
                    best = (t, "wall", side)
    for s, seg in enumerate(segments):
        m = np.column_stack([direction, seg.p0 - seg.p1])
        if abs(np.linalg.det(m)) < 1e-300:
            continue
        t, u = np.linalg.solve(m, seg.p0 - origin)
        if t >= 0 and 0 <= u <= 1 and t <= max_t and t < best[0]:
            best = (t, "segment", s)
    return best


def _scene(periodic, seed, n=150, phi=0.35):
    discs, box = ds.random_gas(n, phi, periodic=periodic, seed=seed, radii=[0.5, 1.0])
    return discs, box


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("periodic", [True, False])
def test_point_queries_match_brute_force(engine, periodic):
    discs, box = _scene(periodic, seed=3)
    sim = _engine(*engine, discs, box).run(until=2.0)
    pos, radii = sim.positions, sim.discs.radii
    rng = np.random.default_rng(1)
    points = rng.uniform(-1.0, 1.0, size=(400, 2)) * 0.1 + rng.uniform(0, 1, size=(400, 2)) * box.size
    points[:40] = pos[:40] + rng.normal(scale=0.3, size=(40, 2))  # near and on discs
    if periodic:
        points[40:60] += box.size  # any point: wrapped
    assert np.array_equal(sim.disc_at(points), _brute_disc_at(box.wrap(points), pos, radii, box))
    index, distance = sim.nearest(points)
    edge = _edge(box.wrap(points) if periodic else points, pos, radii, box)
    assert np.array_equal(index, np.argmin(edge, axis=1))
    np.testing.assert_allclose(distance, edge.min(axis=1), rtol=0, atol=1e-12)
    for point, reach in ((points[0], 0.0), (points[1], 0.7), (points[2], 3.0), (points[3], 40.0)):
        expected = np.flatnonzero(_edge(box.wrap(point[None]), pos, radii, box)[0] <= reach)
        assert sim.within(point, reach).tolist() == expected.tolist()


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    periodic=st.booleans(),
    n=st.integers(8, 40),
    points=st.lists(st.tuples(st.floats(-2, 22), st.floats(-2, 22)), min_size=1, max_size=20),
)
def test_point_queries_of_any_gas_match_brute_force(seed, periodic, n, points):
    discs, box = ds.random_gas(n, 0.2, periodic=periodic, seed=seed, radii=[0.3, 1.1])
    sim = ds.EventDriven(discs, box, backend="python")
    pts = np.array(points) * box.size / 20.0
    wrapped = box.wrap(pts) if periodic else pts
    assert np.array_equal(sim.disc_at(pts), _brute_disc_at(wrapped, discs.positions, discs.radii, box))
    index, distance = sim.nearest(pts)
    edge = _edge(wrapped, discs.positions, discs.radii, box)
    assert np.array_equal(index, np.argmin(edge, axis=1))
    np.testing.assert_allclose(distance, edge.min(axis=1), rtol=0, atol=1e-12)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("periodic", [True, False])
def test_rays_match_brute_force(engine, periodic):
    discs, box = _scene(periodic, seed=5, n=60, phi=0.2)
    segments = [] if periodic else [ds.Segment([0.1 * box.width, 0.5], [0.1 * box.width, 0.9 * box.height])]
    keep = np.ones(len(discs), dtype=bool)
    if segments:
        keep = segments[0].distance(discs.positions) > discs.radii * 1.01
    discs = ds.Discs(discs.positions[keep], discs.velocities[keep], discs.radii[keep])
    sim = _engine(*engine, discs, box, segments=segments).run(until=1.0)
    rng = np.random.default_rng(2)
    origins = rng.uniform(0.02, 0.98, size=(60, 2)) * box.size
    directions = rng.normal(size=(60, 2)) * rng.uniform(0.2, 3.0, size=(60, 1))
    max_distance = 2.5 * max(box.width, box.height)
    hits = sim.ray_cast(origins, directions, max_distance=max_distance)
    for k in range(len(origins)):
        t, kind, index = _brute_ray(
            origins[k], directions[k], sim.positions, sim.discs.radii, box, segments,
            max_distance / np.hypot(*directions[k]),
        )  # fmt: skip
        assert (hits.kind[k], hits.index[k]) == (kind, index), k
        if kind != "none":
            assert math.isclose(hits.t[k], t, rel_tol=1e-9, abs_tol=1e-12)
            expected = origins[k] + t * directions[k]
            np.testing.assert_allclose(hits.point[k], box.wrap(expected) if periodic else expected, atol=1e-9)
    one = sim.ray_cast(origins[0], directions[0], max_distance=max_distance)
    assert (one.kind, one.index, one.t) == (hits.kind[0], hits.index[0], hits.t[0])


def test_rays_by_hand():
    discs = ds.Discs([[6.0, 2.0], [6.0, 4.0]], [[0.0, 0.0], [0.0, 0.0]], [1.0, 0.5])
    sim = ds.EventDriven(discs, ds.Box(10, 5), segments=[ds.Segment([2.0, 3.0], [4.0, 3.0])])
    hit = sim.ray_cast([1.0, 2.0], [1.0, 0.0])
    assert (hit.kind, hit.index, hit.t) == ("disc", 0, 4.0)
    hit = sim.ray_cast([6.0, 2.5], [0.0, 1.0])  # starts inside disc 0
    assert (hit.kind, hit.index, hit.t) == ("disc", 0, 0.0)
    hit = sim.ray_cast([3.0, 1.0], [0.0, 4.0])  # the segment at y = 3, t in units of |direction|
    assert (hit.kind, hit.index, hit.t) == ("segment", 0, 0.5)
    hit = sim.ray_cast([9.0, 1.0], [0.0, -2.0])
    assert (hit.kind, hit.index, hit.t, hit.point.tolist()) == ("wall", 2, 0.5, [9.0, 0.0])
    assert sim.ray_cast([1.0, 2.0], [1.0, 0.0], max_distance=3.0).kind == "none"
    # periodic: a ray leaving through the right edge meets the disc's image on the left
    torus = ds.EventDriven(ds.Discs([[1.0, 2.5]], [[0.0, 0.0]], 0.5), ds.Box(10, 5, periodic=True))
    hit = torus.ray_cast([8.0, 2.5], [1.0, 0.0])
    assert (hit.kind, hit.index, hit.t, hit.point.tolist()) == ("disc", 0, 2.5, [0.5, 2.5])
    assert torus.ray_cast([8.0, 0.1], [1.0, 0.0]).kind == "none"  # along a row the disc misses


def test_overlapping_discs_of_a_fixed_step_run_give_the_nearest_centre():
    discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=1.25).run(until=2.5)  # the pair found 1 apart
    left, right = sim.positions[:, 0]
    assert right - left == pytest.approx(1.0)
    assert sim.disc_at([left + 0.4, 5.0]) == 0 and sim.disc_at([right - 0.4, 5.0]) == 1


def test_queries_follow_the_engine_after_a_run_and_a_change():
    discs = ds.Discs([[2.0, 2.0], [7.0, 2.0]], [[1.0, 0.0], [0.0, 0.0]], 0.5)
    sim = ds.EventDriven(discs, ds.Box(10, 5))
    assert sim.disc_at([2.0, 2.0]) == 0
    sim.run(until=1.0)
    assert sim.disc_at([2.0, 2.0]) == -1 and sim.disc_at([3.0, 2.0]) == 0
    sim.set_positions([1], [[3.0, 4.0]])  # same time, a changed disc
    assert sim.disc_at([3.0, 4.0]) == 1
    sim.remove_discs([0])
    assert sim.disc_at([3.0, 4.0]) == 0 and sim.nearest([3.0, 2.0])[0] == 0


def test_a_compression_is_queried_with_the_radii_it_has_grown_to():
    gas, box = ds.random_gas(60, 0.3, seed=1)
    c = ds.Compression(gas, box, 0.6, backend="python").run(epochs=3)
    point = c.positions[0] + [0.99 * c.radii[0], 0.0]
    assert c.radii[0] > gas.radii[0] * 1.01 and c.disc_at(point) == 0


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda s: s.disc_at([np.nan, 1.0]), r"points\[0\] = \[nan, 1.0\] is not finite"),
        (lambda s: s.disc_at([[1.0, 2.0, 3.0]]), "shape"),
        (lambda s: s.disc_at(["1", "2"]), "real numbers"),
        (lambda s: s.nearest([1j, 2.0]), "complex"),
        (lambda s: s.within([[1.0, 1.0], [2.0, 2.0]], 1.0), "one point"),
        (lambda s: s.within([1.0, 1.0], -1.0), "distance must be a finite number >= 0, got -1.0"),
        (lambda s: s.within([1.0, 1.0], math.inf), "distance"),
        (lambda s: s.ray_cast([1.0, 1.0], [0.0, 0.0]), "zero length"),
        (lambda s: s.ray_cast([11.0, 1.0], [1.0, 0.0]), r"origin\[0\] = \[11.0, 1.0\] is outside the walled box"),
        (lambda s: s.ray_cast([1.0, 1.0], [1.0, 0.0], max_distance=0.0), "max_distance"),
        (lambda s: s.ray_cast([[1.0, 1.0]] * 3, [[1.0, 0.0]] * 2), "same number of rays"),
    ],
)
def test_bad_queries_are_refused_by_name(call, words):
    sim = ds.EventDriven(ds.Discs([[2.0, 2.0]], [[1.0, 0.0]], 0.5), ds.Box(10, 5))
    with pytest.raises(ds.InvalidArgumentError, match=words):
        call(sim)
    assert sim.time == 0.0


def test_a_periodic_ray_needs_a_finite_reach():
    torus = ds.EventDriven(ds.Discs([[1.0, 2.5]], [[0.0, 0.0]], 0.5), ds.Box(10, 5, periodic=True))
    with pytest.raises(ds.InvalidArgumentError, match="finite in a periodic box"):
        torus.ray_cast([8.0, 0.1], [1.0, 0.0], max_distance=math.inf)
