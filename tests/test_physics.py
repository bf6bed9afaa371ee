"""The physics parts (discsim.physics): exact values, and the compiled parts equal to the Python ones bit for bit.

The compiled loops call the parts compiled by numba from the same source (discsim.physics.compiled); the Python
backend's hot loop inlines them for speed. The engine suites hold both backends to the same events bit for bit;
here each part is held to exact values and its compiled form to its Python form.
"""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from discsim import Box, kernels
from discsim._numba import available
from discsim.events import EventKind
from discsim.model import minimum_image_1d
from discsim.physics import dynamics, laws
from discsim.physics.sources import boundaries, pairs, segments
from discsim.physics.sources.boundaries import MINUS_X, MINUS_Y, PLUS_X, PLUS_Y

needs_numba = pytest.mark.skipif(not available(), reason="numba is not installed or hidden")
coordinate = st.floats(-20.0, 20.0, allow_nan=False, allow_subnormal=False)
speed = st.floats(-5.0, 5.0, allow_nan=False, allow_subnormal=False)
radius = st.floats(0.01, 3.0)
WALL, CROSSING = int(EventKind.WALL), int(EventKind.CROSSING)


def test_advance_is_free_flight():
    assert dynamics.advance(1.0, 2.0, 0.5, -1.0, 2.0) == (2.0, 0.0, 0.5, -1.0)
    assert dynamics.advance(1.0, 2.0, 0.5, -1.0, -2.0) == (0.0, 4.0, 0.5, -1.0)  # back along the path


def test_exit_times_and_sides():
    assert dynamics.exit_x(5.0, 2.0, 1.0, 9.0) == (2.0, 1)
    assert dynamics.exit_x(5.0, -4.0, 1.0, 9.0) == (1.0, -1)
    assert dynamics.exit_y(5.0, 0.0, 1.0, 9.0) == (math.inf, 0)
    assert dynamics.exit_x(10.0, 1.0, 1.0, 9.0) == (-1.0, 1)  # already past: negative, the caller clamps


def test_boundaries_choose_a_wall_in_an_edge_cell_and_a_crossing_elsewhere():
    # A disc of radius 1 at x = 5 moving at +2 in a cell [4, 6] of a box 10 wide.
    assert boundaries.predict_x(5.0, 2.0, 1.0, 4.0, 6.0, 10.0, False, False) == (0.5, CROSSING, PLUS_X)
    assert boundaries.predict_x(5.0, 2.0, 1.0, 4.0, 6.0, 10.0, False, True) == (2.0, WALL, 0)  # rim at 9
    assert boundaries.predict_x(5.0, -2.0, 1.0, 4.0, 6.0, 10.0, True, False) == (2.0, WALL, 0)  # rim at 1
    assert boundaries.predict_x(5.0, -2.0, 1.0, 4.0, 6.0, 10.0, False, False) == (0.5, CROSSING, MINUS_X)
    assert boundaries.predict_y(5.0, 2.0, 1.0, 4.0, 6.0, 10.0, False, True) == (2.0, WALL, 1)
    assert boundaries.predict_y(5.0, -1.0, 1.0, 4.0, 6.0, 10.0, False, False) == (1.0, CROSSING, MINUS_Y)
    assert boundaries.predict_y(5.0, 0.0, 1.0, 4.0, 6.0, 10.0, True, True) == (math.inf, CROSSING, 0)


@pytest.mark.parametrize(
    ("direction", "back"), [(PLUS_X, MINUS_X), (MINUS_X, PLUS_X), (PLUS_Y, MINUS_Y), (MINUS_Y, PLUS_Y)]
)
def test_a_crossing_and_its_reverse_return_to_the_cell_and_image(direction, back):
    nx, ny = 3, 4
    for cx in range(nx):
        for cy in range(ny):
            x1, y1, wx, wy = boundaries.cross(cx, cy, direction, nx, ny)
            assert 0 <= x1 < nx and 0 <= y1 < ny
            assert abs(x1 - cx) in (1, nx - 1) if direction in (PLUS_X, MINUS_X) else abs(y1 - cy) in (1, ny - 1)
            x2, y2, wx2, wy2 = boundaries.cross(x1, y1, back, nx, ny)
            assert (x2, y2, wx + wx2, wy + wy2) == (cx, cy, 0, 0)
            wrapped = (wx, wy) != (0, 0)
            at_edge = {PLUS_X: cx == nx - 1, MINUS_X: cx == 0, PLUS_Y: cy == ny - 1, MINUS_Y: cy == 0}[direction]
            assert wrapped == at_edge


@given(coordinate, st.floats(0.5, 50.0))
def test_the_scalar_minimum_image_is_the_box_rule(d, length):
    box = Box(length, length, periodic=True)
    assert minimum_image_1d(d, length) == box.minimum_image(np.array([d, d]))[0]


def test_the_scalar_minimum_image_keeps_the_sign_of_a_zero_as_the_loops_always_did():
    # Python's round(-0.0) is the int 0: -0.0 - L * 0 stays -0.0 (the Python backend's old inline formula did
    # the same; numpy's round gives -0.0 and so +0.0 in Box.minimum_image, which no loop uses).
    assert _bits(minimum_image_1d(-0.0, 10.0)) == _bits(-0.0)
    assert minimum_image_1d(5.0, 10.0) == 5.0 and minimum_image_1d(15.0, 10.0) == -5.0  # halves to even


def _bits(x) -> bytes:
    """The float's 8 bytes: ``==`` cannot tell -0.0 from 0.0, and bit for bit means both."""
    return struct.pack("<d", x)


def _same(a, b) -> bool:
    """Bit for bit, element by element (floats, ints, or tuples of them)."""
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) or isinstance(b, float):
        return _bits(float(a)) == _bits(float(b)) and type(a) is type(b)
    return a == b


@given(coordinate, coordinate, speed, speed, speed, speed, radius, radius, st.floats(0.0, 3.0))
def test_pair_predict_is_free_flight_then_the_time_of_impact(x, y, vxj, vyj, vxi, vyi, ri, rj, dtj):
    xj, yj = x + 0.5, y - 0.25
    expected = kernels.time_of_impact(xj + vxj * dtj - x, yj + vyj * dtj - y, vxj - vxi, vyj - vyi, ri + rj)
    assert pairs.predict(xj, yj, vxj, vyj, dtj, rj, -x, -y, vxi, vyi, ri) == expected


@given(coordinate, coordinate, speed, speed, radius)
def test_the_time_of_impact_matches_the_branchy_textbook_root(dx, dy, dvx, dvy, sigma):
    # The form the loops compile (one min() test) against the textbook's branches.
    b = dx * dvx + dy * dvy
    c = dx * dx + dy * dy - sigma * sigma
    a = dvx * dvx + dvy * dvy
    if b >= 0.0:
        expected = math.inf
    elif c <= 0.0:
        expected = 0.0
    elif b * b - a * c <= 0.0:
        expected = math.inf
    else:
        expected = c / (-b + math.sqrt(b * b - a * c))
    assert dynamics.pair_time_of_impact(dx, dy, dvx, dvy, sigma) == expected


def test_pair_resolve_takes_the_minimum_image():
    # Discs at x = 0.5 and x = 9.5 of a periodic box 10 wide touch across the edge: the line of centres is -1.
    dx, dy, uxi, uyi, uxj, uyj = pairs.resolve(0.5, 5.0, -1.0, 0.0, 1.0, 9.5, 5.0, 1.0, 0.0, 1.0, 10.0, 10.0, True)
    assert (dx, dy) == (-1.0, 0.0)
    assert (uxi, uyi, uxj, uyj) == (1.0, 0.0, -1.0, 0.0)


def test_laws_reflect_and_segments_are_the_kernels():
    assert laws.reflect(1.0, 2.0, 0) == (-1.0, 2.0) and laws.reflect(1.0, 2.0, 1) == (1.0, -2.0)
    assert segments.predict is dynamics.segment_time_of_impact is kernels.segment_time_of_impact
    assert segments.resolve is laws.reflect_off_segment is kernels.reflect_off_segment
    assert kernels.resolve_collision is laws.collide and kernels.time_of_impact is dynamics.pair_time_of_impact


@needs_numba
@settings(max_examples=300, deadline=None)
@given(coordinate, coordinate, speed, speed, speed, speed, radius, radius, st.floats(0.0, 3.0), st.booleans())
def test_the_compiled_parts_equal_the_python_parts_bit_for_bit(x, y, vxj, vyj, vxi, vyi, ri, rj, dtj, periodic):
    from discsim.physics import compiled

    assert _same(compiled.advance(x, y, vxi, vyi, dtj), dynamics.advance(x, y, vxi, vyi, dtj))
    for lo, hi in ((x - 1.0, x + 2.0), (x + 0.5, x - 0.5)):
        assert _same(compiled.exit_x(x, vxi, lo, hi), dynamics.exit_x(x, vxi, lo, hi))
        assert _same(compiled.exit_y(y, vyi, lo, hi), dynamics.exit_y(y, vyi, lo, hi))
        for walls in ((False, False), (True, False), (False, True), (True, True)):
            got = compiled.predict_x(x, vxi, ri, lo, hi, 40.0, *walls)
            assert _same(got, boundaries.predict_x(x, vxi, ri, lo, hi, 40.0, *walls))
            got = compiled.predict_y(y, vyi, ri, lo, hi, 40.0, *walls)
            assert _same(got, boundaries.predict_y(y, vyi, ri, lo, hi, 40.0, *walls))
    args = (x + 1.0, y - 0.5, vxj, vyj, dtj, rj, -x, -y, vxi, vyi, ri)
    assert _same(compiled.pair_predict(*args), pairs.predict(*args))
    dx, dy = x + 2.5 * ri, y - 0.3 * rj
    assert _same(compiled.pair_time_of_impact(dx, dy, vxj, vyj, ri), dynamics.pair_time_of_impact(dx, dy, vxj, vyj, ri))
    state = (x, y, vxi, vyi, 1.0, x + ri + rj, y + 0.1, vxj, vyj, 2.5, 30.0, 20.0, periodic)
    assert _same(compiled.pair_resolve(*state), pairs.resolve(*state))
    for d in (dx, -dx, 0.0, -0.0, 3.5, -3.5, 10.5):
        assert _same(compiled.minimum_image_1d(d, 7.0), minimum_image_1d(d, 7.0))
    assert _same(compiled.reflect(vxi, vyi, 0), laws.reflect(vxi, vyi, 0))
    assert _same(compiled.wall_time(x, vxi, ri, 40.0), boundaries.wall_time(x, vxi, ri, 40.0))
    for direction in (PLUS_X, MINUS_X, PLUS_Y, MINUS_Y):
        assert compiled.cross(2, 0, direction, 3, 4) == boundaries.cross(2, 0, direction, 3, 4)
