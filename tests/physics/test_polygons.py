"""Rotating convex polygons (discsim.physics.polygons): closed forms, brute force, the compiled parts.

The issue's thin spinning bar, a square spinning in place against a wall and two squares head-on, with and
without spin, against their closed forms; random pairs of polygons turning up to three turns per unit time against
a brute force (the separating-axis gap sampled finely in time, its first sign change bisected): no contact
missed, the same times; the compiled parts (numba, from the same source) equal the Python ones bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from discsim._numba import available
from discsim.errors import InvalidArgumentError
from discsim.physics import polygons
from discsim.physics.polygons import (
    check_polygon,
    polygon_contact,
    polygon_separation,
    polygon_time_of_impact,
    polygon_wall_time,
    world_vertices,
)

needs_numba = pytest.mark.skipif(not available(), reason="numba is not installed or hidden")


def rectangle(width: float, height: float) -> np.ndarray:
    w, h = 0.5 * width, 0.5 * height
    return np.array([[-w, -h], [w, -h], [w, h], [-w, h]])


SQUARE = rectangle(1.0, 1.0)
BAR = rectangle(1.0, 0.02)
BOX = rectangle(0.04, 0.04)
#: The issue's study case: the bar about its centre at 0.6 rad per unit time from angle 0; the box at radius
#: 0.4 at the angle the bar has at t = 0.5 (0.3 rad), its sides along and across the bar there.
BAR_CASE = (BAR, 0.0, 0.0, 0.0, 0.0, 0.0, 0.6, BOX, 0.4 * math.cos(0.3), 0.4 * math.sin(0.3), 0.3, 0.0, 0.0, 0.0)


# --- closed forms ---------------------------------------------------------------------------------------------
def test_the_thin_spinning_bar_meets_the_small_box_at_0_3686():
    # The box's inner corner (0.38 along the bar's line at 0.3 rad, 0.02 behind it) meets the bar's leading
    # side (0.01 off its axis) when the bar has turned 0.3 - atan(0.02 / 0.38) - asin(0.01 / |corner|).
    exact = (0.3 - math.atan(0.02 / 0.38) - math.asin(0.01 / math.hypot(0.38, 0.02))) / 0.6
    assert round(exact, 4) == 0.3686
    t, px, py, nx, ny = polygon_time_of_impact(*BAR_CASE, 10.0)
    assert t == pytest.approx(exact, rel=4e-16, abs=0.0)
    corner = (0.38 * math.cos(0.3) + 0.02 * math.sin(0.3), 0.38 * math.sin(0.3) - 0.02 * math.cos(0.3))
    assert (px, py) == pytest.approx(corner, abs=1e-15)
    turned = 0.6 * t  # the normal is the bar's side's, from the bar to the box
    assert (nx, ny) == pytest.approx((-math.sin(turned), math.cos(turned)), abs=1e-15)


def test_time_stepping_steps_through_the_bar_case_that_the_search_finds():
    """The issue's PIT frames: one step (t = 1) and three see no overlap, two and four see it at 0.5."""

    def overlap(t):
        bar, cx, cy, angle, _, _, w, box, bx, by, b_angle = BAR_CASE[:11]
        return polygon_separation(bar, cx, cy, angle + w * t, box, bx, by, b_angle) <= 0.0

    assert not overlap(0.0) and not overlap(1.0) and not overlap(1 / 3) and not overlap(2 / 3)
    assert overlap(0.5) and not overlap(0.25)


def test_a_square_spinning_in_place_reaches_a_wall_with_a_corner():
    # Half side 0.5, corners at radius r = sqrt(0.5); the wall x = 0.6 (normal -x towards the square); spin
    # 2 rad / time from angle 0: the corner at -pi/4 reaches x = 0.6 at angle -acos(0.6 / r).
    r = math.sqrt(0.5)
    for w in (2.0, 17.0):
        exact = (math.pi / 4 - math.acos(0.6 / r)) / w
        t, px, py, nx, ny = polygon_wall_time(SQUARE, 0.0, 0.0, 0.0, 0.0, 0.0, w, 0.6, 0.0, -1.0, 0.0, 5.0)
        assert t == pytest.approx(exact, rel=1e-15)
        assert (px, py, nx, ny) == pytest.approx((0.6, -math.sqrt(r * r - 0.36), -1.0, 0.0), abs=1e-15)
    # Spinning the other way, the corner at +pi/4 comes down to it; slower than it needs: no contact by then.
    t = polygon_wall_time(SQUARE, 0.0, 0.0, 0.0, 0.0, 0.0, -2.0, 0.6, 0.0, -1.0, 0.0, 5.0)[0]
    assert t == pytest.approx((math.pi / 4 - math.acos(0.6 / r)) / 2.0, rel=1e-15)
    assert polygon_wall_time(SQUARE, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.6, 0.0, -1.0, 0.0, 0.05)[0] == math.inf
    # Far enough, never.
    assert polygon_wall_time(SQUARE, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.8, 0.0, -1.0, 0.0, 50.0)[0] == math.inf


def test_a_square_falling_flat_on_a_wall_touches_at_its_sides_midpoint():
    t, px, py, nx, ny = polygon_wall_time(SQUARE, 0.3, 2.0, 0.0, 0.7, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 9.0)
    assert (t, px, py, nx, ny) == (1.5, 0.3 + 0.7 * 1.5, 0.0, 0.0, 1.0)


def test_two_squares_head_on_without_spin_touch_side_on_side_at_the_midpoint():
    # Gap 2 closing at speed 2: t = 1; the sides share the segment x = 1.5, y in [-0.5 + 0.25, 0.5].
    t, px, py, nx, ny = polygon_time_of_impact(
        SQUARE, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, SQUARE, 3.0, 0.25, 0.0, -1.0, 0.0, 0.0, 10.0
    )
    assert t == pytest.approx(1.0, rel=2e-16)
    assert (px, py, nx, ny) == pytest.approx((1.5, 0.125, 1.0, 0.0), abs=1e-15)
    # Exchanging the two: the same time and point, the normal reversed (from A to B).
    swapped = polygon_time_of_impact(SQUARE, 3.0, 0.25, 0.0, -1.0, 0.0, 0.0, SQUARE, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 9.0)
    assert swapped[0] == t and swapped[1:] == pytest.approx((1.5, 0.125, -1.0, 0.0), abs=1e-15)


def test_two_squares_head_on_with_spin_touch_corner_first():
    # B still at x = 3, A at speed 1 spinning at w: a corner of A at radius r = sqrt(0.5) and angle
    # phi = -pi/4 + w t reaches B's side x = 2.5 when t + r cos(phi) = 2.5 (solved here by bisection in
    # 50-digit-free floats: the function rises through the root).
    r = math.sqrt(0.5)
    for w in (0.5, 3.0, -3.0):

        def corner_gap(t, w=w):
            best = max(r * math.cos(math.pi / 4 + k * math.pi / 2 + w * t) for k in range(4))
            return t + best - 2.5

        lo, hi = 0.0, 2.0
        while True:  # the first crossing: the gap rises monotonically for these spins before contact
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                break
            lo, hi = (mid, hi) if corner_gap(mid) < 0.0 else (lo, mid)
        t, px, _, nx, ny = polygon_time_of_impact(
            SQUARE, 0.0, 0.0, 0.0, 1.0, 0.0, w, SQUARE, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 10.0
        )
        assert t == pytest.approx(hi, abs=1e-14)
        assert px == pytest.approx(2.5, abs=1e-14) and (nx, ny) == (1.0, 0.0)


def test_polygons_touching_at_the_start_or_never_meeting():
    assert polygon_time_of_impact(SQUARE, 0.0, 0.0, 0.0, 0, 0, 0, SQUARE, 0.9, 0.0, 0.0, 0, 0, 0, 5.0)[0] == 0.0
    assert polygon_time_of_impact(SQUARE, 0.0, 0.0, 0.0, 0, 0, 0, SQUARE, 1.0, 0.0, 0.0, 0, 0, 0, 5.0)[0] == 0.0
    never = polygon_time_of_impact(SQUARE, 0.0, 0.0, 0.0, 0, 0, 0, SQUARE, 3.0, 0.0, 0.0, 0, 1, 0, 5.0)
    assert never[0] == math.inf and all(math.isnan(v) for v in never[1:])
    # Spinning in place side by side, 0.1 apart from corner to corner: never within reach (r + r < 1.5).
    assert polygon_time_of_impact(SQUARE, 0, 0, 0, 0, 0, 5.0, SQUARE, 1.5, 0, 0, 0, 0, -5.0, 50.0)[0] == math.inf
    # Closer, they catch: corner meets corner or side.
    assert polygon_time_of_impact(SQUARE, 0, 0, 0, 0, 0, 5.0, SQUARE, 1.3, 0, 0, 0, 0, -5.0, 50.0)[0] < 1.0


def test_the_edge_on_edge_rule_is_the_midpoint_of_the_shared_segment():
    # Both orders and a rotated frame give the same point.
    assert polygon_contact(SQUARE, 0.0, 0.0, 0.0, SQUARE, 1.0, 0.25, 0.0) == (0.5, 0.125, 1.0, 0.0)
    assert polygon_contact(SQUARE, 1.0, 0.25, 0.0, SQUARE, 0.0, 0.0, 0.0) == (0.5, 0.125, -1.0, 0.0)
    small = rectangle(0.2, 0.2)  # a small square flat on a big one's side: the small side's midpoint
    px, py, nx, ny = polygon_contact(SQUARE, 0.0, 0.0, 0.0, small, 0.6, -0.3, 0.0)
    assert (px, py, nx, ny) == pytest.approx((0.5, -0.3, 1.0, 0.0), abs=1e-15)
    a = 0.7  # the whole picture turned by a: the point and normal turn with it
    c, s = math.cos(a), math.sin(a)
    got = polygon_contact(SQUARE, 0.0, 0.0, a, small, 0.6 * c + 0.3 * s, 0.6 * s - 0.3 * c, a)
    assert got == pytest.approx((0.5 * c + 0.3 * s, 0.5 * s - 0.3 * c, c, s), abs=1e-14)


def test_world_vertices_and_the_check_at_the_boundary():
    got = world_vertices(SQUARE, 1.0, 2.0, 0.0, 1.0, 0.0, math.pi / 2, 1.0)
    assert got == pytest.approx(np.array([[2.5, 1.5], [2.5, 2.5], [1.5, 2.5], [1.5, 1.5]]))
    assert check_polygon(SQUARE.tolist()).shape == (4, 2)
    with pytest.raises(InvalidArgumentError, match=r"vertices must be a \(K, 2\) array.*\(2, 2\)"):
        check_polygon([[0, 0], [1, 0]])
    with pytest.raises(InvalidArgumentError, match="shape must be finite"):
        check_polygon([[0, 0], [1, 0], [np.nan, 1]], "shape")
    with pytest.raises(InvalidArgumentError, match="counter-clockwise; vertex 1"):
        check_polygon(SQUARE[::-1])
    with pytest.raises(InvalidArgumentError, match=r"vertex 2 \(\[0.5, 0.5\]\)"):  # a dent (not convex)
        check_polygon([[0, 0], [1, 0], [0.5, 0.5], [1, 1], [0, 1]])


# --- brute force ----------------------------------------------------------------------------------------------
def _random_polygon(rng) -> np.ndarray:
    n = int(rng.integers(3, 9))
    while True:
        angles = np.sort(rng.uniform(0.0, 2 * np.pi, n))
        radii = rng.uniform(0.15, 0.6) * rng.uniform(0.7, 1.0, n)
        p = np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)
        try:
            return check_polygon(p - p.mean(axis=0))
        except InvalidArgumentError:
            continue


def _random_pair(rng):
    """Two disjoint random polygons heading roughly at each other, each spinning up to 3 turns per unit time."""
    while True:
        va, vb = _random_polygon(rng), _random_polygon(rng)
        a = (*rng.uniform(-0.5, 0.5, 2), rng.uniform(-np.pi, np.pi))
        b = (*rng.uniform(0.5, 2.0, 2), rng.uniform(-np.pi, np.pi))
        if polygon_separation(va, *a, vb, *b) > 0.0:
            break
    aim = np.array(b[:2]) - np.array(a[:2])
    va_ = aim * rng.uniform(0.0, 1.5) + rng.normal(0.0, 0.3, 2)
    spins = rng.uniform(-6 * np.pi, 6 * np.pi, 2)
    return (va, *a, *va_, spins[0], vb, *b, *rng.normal(0.0, 0.3, 2), spins[1])


def _gaps(args, times: np.ndarray) -> np.ndarray:
    """The separating-axis gap of the pair at each time, vectorised over times."""
    va, cax, cay, ta, vax, vay, wa, vb, cbx, cby, tb, vbx, vby, wb = args

    def world(v, cx, cy, th, vx, vy, w):
        ang = th + w * times[:, None]
        c, s = np.cos(ang), np.sin(ang)
        x = cx + vx * times[:, None] + c * v[:, 0] - s * v[:, 1]
        y = cy + vy * times[:, None] + s * v[:, 0] + c * v[:, 1]
        return np.stack([x, y], axis=2)  # (T, K, 2)

    def one_way(p, q):  # q's edges against p's vertices
        e = np.roll(q, -1, axis=1) - q
        n = np.stack([e[..., 1], -e[..., 0]], axis=2) / np.linalg.norm(e, axis=2)[..., None]
        h = np.einsum("tjd,tjid->tji", n, p[:, None, :, :] - q[:, :, None, :])
        return h.min(axis=2).max(axis=1)

    a, b = world(va, cax, cay, ta, vax, vay, wa), world(vb, cbx, cby, tb, vbx, vby, wb)
    return np.maximum(one_way(a, b), one_way(b, a))


def brute_force_contact(args, horizon: float, samples: int) -> float:
    """The first sampled time at which the pair overlaps, bisected back to the sign change of the gap."""
    times = np.linspace(0.0, horizon, samples + 1)
    gaps = _gaps(args, times)
    inside = np.flatnonzero(gaps <= 0.0)
    if not inside.size:
        return math.inf
    k = int(inside[0])
    lo, hi = float(times[k - 1]), float(times[k])
    while True:
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            return hi
        if _gaps(args, np.array([mid]))[0] <= 0.0:
            hi = mid
        else:
            lo = mid


def _check_against_brute_force(toi, seed: int, pairs: int, samples: int) -> dict:
    rng = np.random.default_rng(seed)
    horizon = 2.0
    seen = {"contacts": 0, "both": 0, "brute_missed": 0}
    for _ in range(pairs):
        args = _random_pair(rng)
        t = toi(*args, horizon)[0]
        brute = brute_force_contact(args, horizon, samples)
        assert t <= brute + 1e-9, (args, t, brute)  # never missed, never late
        if t < math.inf:
            seen["contacts"] += 1
            if brute < math.inf:
                seen["both"] += 1
            if abs(t - brute) > 1e-9:  # a contact the sampling stepped over: they do touch at t
                assert abs(_gaps(args, np.array([t]))[0]) < 1e-12, (args, t, brute)
                seen["brute_missed"] += 1
    return seen


@pytest.fixture(scope="module")
def compiled():
    if not available():
        return {"toi": polygon_time_of_impact, "wall": polygon_wall_time}
    from discsim._compiled import compile_from_source, jit

    parts = compile_from_source(polygons.PARTS, jit)
    return {"toi": parts[polygon_time_of_impact], "wall": parts[polygon_wall_time]}


@pytest.mark.slow  # (4 s, and numba compiling the parts; the closed forms above run quick)
def test_random_pairs_against_brute_force_quick(compiled):
    seen = _check_against_brute_force(compiled["toi"], seed=1, pairs=60, samples=10_000)
    assert seen["contacts"] > 15 and seen["both"] >= seen["contacts"] - 1


@pytest.mark.slow
def test_random_pairs_against_brute_force_thousands(compiled):
    seen = _check_against_brute_force(compiled["toi"], seed=2, pairs=2000, samples=20_000)
    assert seen["contacts"] > 800 and seen["both"] >= seen["contacts"] - 20


@pytest.mark.slow
def test_random_polygons_against_walls_with_brute_force(compiled):
    rng = np.random.default_rng(3)
    for _ in range(100):
        v = _random_polygon(rng)
        cx, cy, th = 0.0, rng.uniform(0.7, 1.5), rng.uniform(-np.pi, np.pi)
        vx, vy, w = rng.normal(0.0, 0.5), rng.uniform(-1.0, 0.2), rng.uniform(-6 * np.pi, 6 * np.pi)
        t, _, py, nx, ny = compiled["wall"](v, cx, cy, th, vx, vy, w, 0.0, 0.0, 0.0, 1.0, 2.0)
        times = np.linspace(0.0, 2.0, 40_001)
        lowest = np.array([world_vertices(v, cx, cy, th, vx, vy, w, s)[:, 1].min() for s in times[::40]])
        first = times[::40][np.argmax(lowest <= 0.0)] if (lowest <= 0.0).any() else math.inf
        assert t <= first + 1e-9
        if t < math.inf:
            assert world_vertices(v, cx, cy, th, vx, vy, w, t)[:, 1].min() == pytest.approx(0.0, abs=1e-13)
            assert abs(py) < 1e-13 and (nx, ny) == (0.0, 1.0)


# --- compiled -------------------------------------------------------------------------------------------------
@needs_numba
@pytest.mark.slow
def test_the_compiled_parts_equal_the_python_parts_bit_for_bit(compiled):
    rng = np.random.default_rng(4)
    cases = [BAR_CASE] + [_random_pair(rng) for _ in range(20)]
    for args in cases:
        assert _same(compiled["toi"](*args, 2.0), polygon_time_of_impact(*args, 2.0))
    for w in (2.0, 0.1):  # a contact, none by the horizon
        wall = (SQUARE, 0.0, 0.0, 0.0, 0.0, 0.0, w, 0.6, 0.0, -1.0, 0.0, 5.0)
        assert _same(compiled["wall"](*wall), polygon_wall_time(*wall))


def _same(a: tuple, b: tuple) -> bool:
    """Bit for bit, the nan of no contact included."""
    return np.array(a, dtype=float).tobytes() == np.array(b, dtype=float).tobytes()
