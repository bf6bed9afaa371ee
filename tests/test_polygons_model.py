"""The polygon bodies (discsim.polygons, issue 33's model): shapes checked convex and centred, the inertia of a
uniform plate against closed forms, the separating-axis overlap, and bad input refused by name."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds
from discsim.errors import InvalidArgumentError, InvalidDiscsError, OutsideBoxError, OverlapError
from discsim.polygons import Polygons, check_polygons, convex_shape, overlap_depth, plate_inertia, regular_polygon


@pytest.mark.parametrize("n", [3, 4, 5, 6, 12])
def test_a_regular_polygon_s_plate_inertia_is_the_closed_form(n):
    # A regular n-gon of circumradius R: I = m R^2 (1 + 2 cos^2(pi / n)) / 6.
    v = convex_shape("v", regular_polygon(n, 2.0, angle=0.3))
    assert plate_inertia(v, 3.0) == pytest.approx(3.0 * 4.0 * (1.0 + 2.0 * math.cos(math.pi / n) ** 2) / 6.0, rel=1e-13)


def test_a_rectangle_and_a_triangle_have_their_closed_form_inertia_about_the_centroid():
    rectangle = convex_shape("r", [[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [0.0, 1.0]])
    assert plate_inertia(rectangle, 2.0) == pytest.approx(2.0 * (16.0 + 1.0) / 12.0, rel=1e-14)  # m (a^2 + b^2) / 12
    triangle = convex_shape("t", [[0.0, 0.0], [3.0, 0.0], [0.0, 4.0]])  # sides 3, 4, 5
    assert plate_inertia(triangle, 1.0) == pytest.approx((9.0 + 16.0 + 25.0) / 36.0, rel=1e-14)  # m (a^2+b^2+c^2) / 36
    assert np.allclose(triangle.mean(axis=0), 0.0)  # a triangle's centroid is its vertices' mean
    assert plate_inertia(triangle, math.inf) == math.inf


def test_a_clockwise_off_centre_shape_is_turned_counter_clockwise_and_centred():
    v = convex_shape("v", [[1.0, 1.0], [1.0, 3.0], [5.0, 3.0], [5.0, 1.0]])  # clockwise, centred on (3, 2)
    assert v.tolist() == [[2.0, -1.0], [2.0, 1.0], [-2.0, 1.0], [-2.0, -1.0]]
    assert not v.flags.writeable


@pytest.mark.parametrize(
    ("vertices", "words"),
    [
        ([[0, 0], [1, 0]], r"shape \(K, 2\) with K >= 3"),
        ([[0, 0], [1, 0], [math.nan, 1]], "must be finite"),
        ([[0, 0], [1, 0], [1, 0], [0, 1]], "vertex 1 .* repeats the next one"),
        ([[0, 0], [1, 0], [2, 0], [0, 1]], "vertex 1 .* lies on the line through its neighbours"),
        ([[0, 0], [2, 0], [1, 0.5], [1, 2]], "not convex: it turns the other way at vertex 2"),
        (regular_polygon(5, 1.0)[[0, 2, 4, 1, 3]], "winds round 2 times"),
        ([[0, 0], [1, 1], [2, 2]], "lies on the line"),
        ("abc", "real numbers"),
    ],
)
def test_a_shape_that_is_not_a_convex_polygon_is_refused_naming_the_vertex(vertices, words):
    with pytest.raises(InvalidDiscsError, match=words):
        Polygons(vertices, [[5.0, 5.0]])


def test_bodies_take_one_shape_or_one_each_and_refuse_bad_arrays_naming_the_body():
    square, hexagon = regular_polygon(4, 1.0), regular_polygon(6, 0.5)
    bodies = Polygons([square, hexagon], [[2.0, 2.0], [5.0, 2.0]], angles=[0.0, 0.1], masses=[1.0, math.inf])
    assert [len(v) for v in bodies.vertices] == [4, 6] and bodies.circumradii.tolist() == pytest.approx([1.0, 0.5])
    assert bodies.inertia[1] == math.inf and repr(bodies) == "Polygons(n=2, vertices per body=[4, 6])"
    with pytest.raises(InvalidDiscsError, match="vertices of body 1 is not convex"):
        Polygons([square, [[0, 0], [2, 0], [1, 0.5], [1, 2]]], [[2.0, 2.0], [5.0, 2.0]])
    with pytest.raises(InvalidDiscsError, match=r"one per body \(2\), got 3"):
        Polygons([square, square, square], [[2.0, 2.0], [5.0, 2.0]])
    with pytest.raises(InvalidDiscsError, match="spins of body 1 must be finite"):
        Polygons(square, [[2.0, 2.0], [5.0, 2.0]], spins=[0.0, math.inf])
    with pytest.raises(InvalidDiscsError, match="masses must be > 0 .* body 0 has -1.0"):
        Polygons(square, [[2.0, 2.0], [5.0, 2.0]], masses=[-1.0, 1.0])
    with pytest.raises(InvalidDiscsError, match="inertia must be > 0: body 1 has 0.0"):
        Polygons(square, [[2.0, 2.0], [5.0, 2.0]], inertia=[1.0, 0.0])
    with pytest.raises(InvalidDiscsError, match=r"velocities must be a number or have shape \(2, 2\)"):
        Polygons(square, [[2.0, 2.0], [5.0, 2.0]], velocities=[1.0, 2.0, 3.0])
    with pytest.raises(InvalidArgumentError, match="n >= 3"):
        regular_polygon(2, 1.0)


def test_world_vertices_follow_the_free_flight_and_the_spin():
    bodies = Polygons(regular_polygon(4, 1.0), [[1.0, 2.0]], angles=0.25, velocities=[[0.5, 0.0]], spins=1.0)
    theta = 0.25 + 1.0 * 2.0
    assert bodies.world_vertices(0, 2.0)[0].tolist() == pytest.approx([2.0 + math.cos(theta), 2.0 + math.sin(theta)])


def test_the_separating_axis_depth_of_two_squares():
    a = regular_polygon(4, math.sqrt(2.0), angle=math.pi / 4)  # the square [-1, 1]^2
    assert overlap_depth(a, a + np.array([1.5, 0.0])) == pytest.approx(0.5)
    assert overlap_depth(a, a + np.array([2.0, 0.0])) == pytest.approx(0.0, abs=1e-15)  # touching
    assert overlap_depth(a, a + np.array([3.0, 0.5])) == pytest.approx(-1.0)  # a gap of 1 along x
    turned = regular_polygon(4, math.sqrt(2.0))  # a diamond, its corners sqrt(2) from its centre: one 0.1 deep
    assert overlap_depth(a, turned + np.array([1.0 + math.sqrt(2.0) - 0.1, 0.0])) == pytest.approx(0.1)


@settings(max_examples=200, deadline=None)
@given(
    n=st.integers(3, 8), m=st.integers(3, 8), angle=st.floats(0.0, 6.3), other=st.floats(0.0, 6.3),
    x=st.floats(-3.0, 3.0), y=st.floats(-3.0, 3.0),
)  # fmt: skip
def test_overlap_agrees_with_points_of_one_inside_the_other(n, m, angle, other, x, y):
    # Two convex polygons overlap (by more than roundoff) exactly when some point of one lies inside the other:
    # checked on a fine sampling of their edges.
    a, b = regular_polygon(n, 1.0, angle), regular_polygon(m, 1.2, other) + np.array([x, y])

    def inside(points, poly):
        edges = np.roll(poly, -1, axis=0) - poly
        rel = points[:, None, :] - poly[None, :, :]
        return (edges[None, :, 0] * rel[..., 1] - edges[None, :, 1] * rel[..., 0] > 1e-9).all(axis=1)

    def rim(poly, k=200):
        s = np.linspace(0.0, 1.0, k, endpoint=False)[:, None]
        return np.concatenate([p + s * (q - p) for p, q in zip(poly, np.roll(poly, -1, axis=0), strict=True)])

    depth = overlap_depth(a, b)
    seen = inside(rim(a), b).any() or inside(rim(b), a).any()
    if abs(depth) > 1e-2:
        assert (depth > 0.0) == seen


def test_a_start_outside_the_box_or_with_overlaps_is_refused_naming_the_bodies():
    square = regular_polygon(4, 1.0)
    box = ds.Box(10.0, 10.0)
    check_polygons(Polygons(square, [[2.0, 2.0], [4.0, 2.0]]), box)  # corners 1 apart: fine
    with pytest.raises(OutsideBoxError, match="body 1 at"):
        check_polygons(Polygons(square, [[2.0, 2.0], [9.5, 2.0]]), box)
    with pytest.raises(OverlapError, match="bodies 0 and 1 overlap"):
        check_polygons(Polygons(square, [[2.0, 2.0], [3.5, 2.0]], angles=[0.0, 0.3]), box)
    periodic = ds.Box(10.0, 10.0, periodic=True)
    with pytest.raises(OverlapError, match="bodies 0 and 1 overlap"):  # across the edge x = 0
        check_polygons(Polygons(square, [[0.3, 5.0], [9.2, 5.0]]), periodic)
    check_polygons(Polygons(square, [[0.3, 5.0], [7.0, 5.0]]), periodic)
