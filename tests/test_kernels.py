"""Time of impact and elastic response: exact values and properties (hypothesis)."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from discsim.kernels import resolve_collision, time_of_impact, wall_time

coord = st.floats(-50, 50, allow_nan=False)
speed = st.floats(-10, 10, allow_nan=False)
radius = st.floats(0.1, 3.0)
mass = st.floats(0.1, 100.0)


def test_head_on_time_is_gap_over_closing_speed():
    # Centres 10 apart, radii sum 3, closing at 2 + 0.5: contact after 7 / 2.5.
    assert time_of_impact(10.0, 0.0, -2.5, 0.0, 3.0) == pytest.approx(2.8, rel=1e-15)


def test_oblique_time_matches_hand_calculation():
    # Disc 2 at (4, 1) moving (-1, 0) towards disc 1 at rest; contact at distance 2:
    # (4 - t)^2 + 1 = 4  ->  t = 4 - sqrt(3).
    assert time_of_impact(4.0, 1.0, -1.0, 0.0, 2.0) == pytest.approx(4 - math.sqrt(3), rel=1e-14)


def test_receding_missing_and_overlapping_pairs():
    assert time_of_impact(4.0, 0.0, 1.0, 0.0, 2.0) == math.inf  # receding
    assert time_of_impact(4.0, 3.0, -1.0, 0.0, 2.0) == math.inf  # passes by
    assert time_of_impact(1.9, 0.0, -1.0, 0.0, 2.0) == 0.0  # overlapping and approaching: now
    assert time_of_impact(1.9, 0.0, 1.0, 0.0, 2.0) == math.inf  # overlapping but separating: never


def test_head_on_unequal_masses_textbook_velocities():
    # 1D elastic collision: u1' = (m1 - m2) u1 / (m1 + m2), u2' = 2 m1 u1 / (m1 + m2).
    m1, m2, u = 3.0, 1.0, 2.0
    v1x, v1y, v2x, v2y = resolve_collision(1.0, 0.0, u, 0.0, 0.0, 0.0, m1, m2)
    assert (v1x, v2x) == pytest.approx(((m1 - m2) * u / (m1 + m2), 2 * m1 * u / (m1 + m2)), rel=1e-15)
    assert v1y == v2y == 0.0


def test_equal_masses_oblique_leave_at_right_angles():
    # Moving disc hits a resting one at 30 degrees off the line of centres.
    n = np.array([math.cos(0.5), math.sin(0.5)])
    v1x, v1y, v2x, v2y = resolve_collision(*(2 * n), 1.0, 0.0, 0.0, 0.0, 1.0, 1.0)
    assert np.dot([v1x, v1y], [v2x, v2y]) == pytest.approx(0.0, abs=1e-15)
    assert [v2x, v2y] == pytest.approx(math.cos(0.5) * n, rel=1e-14)


def test_infinite_mass_is_a_mirror():
    v1x, v1y, v2x, v2y = resolve_collision(-1.0, -1.0, 0.0, 0.0, 2.0, 3.0, math.inf, 1.0)
    # The normal is (1, 1)/sqrt(2); the normal component of (2, 3) reverses: (-3, -2).
    assert (v1x, v1y) == (0.0, 0.0)
    assert (v2x, v2y) == pytest.approx((-3.0, -2.0), rel=1e-15)


def test_wall_time():
    assert wall_time(5.0, 2.0, 1.0, 10.0) == 2.0
    assert wall_time(5.0, -2.0, 1.0, 10.0) == 2.0
    assert wall_time(0.5, -2.0, 1.0, 10.0) == 0.0
    assert wall_time(5.0, 0.0, 1.0, 10.0) == math.inf


@st.composite
def pair(draw):
    x1, y1, x2, y2 = (draw(coord) for _ in range(4))
    u1, w1, u2, w2 = (draw(speed) for _ in range(4))
    r1, r2 = draw(radius), draw(radius)
    assume(math.hypot(x2 - x1, y2 - y1) > (r1 + r2) * (1 + 1e-6))
    return (x1, y1, u1, w1, r1), (x2, y2, u2, w2, r2)


@st.composite
def colliding_pair(draw):
    """A pair built backwards from a known contact at time ``t_star``."""
    t_star = draw(st.floats(0.01, 20.0))
    x, y = draw(coord), draw(coord)
    u1, w1, u2, w2 = (draw(speed) for _ in range(4))
    r1, r2 = draw(radius), draw(radius)
    angle = draw(st.floats(0, 2 * math.pi))
    n = (math.cos(angle), math.sin(angle))
    assume((u2 - u1) * n[0] + (w2 - w1) * n[1] < -1e-3)  # approaching at contact
    s = r1 + r2
    a = (x - u1 * t_star, y - w1 * t_star, u1, w1, r1)
    b = (x + s * n[0] - u2 * t_star, y + s * n[1] - w2 * t_star, u2, w2, r2)
    return a, b, t_star


def _toi(a, b):
    return time_of_impact(b[0] - a[0], b[1] - a[1], b[2] - a[2], b[3] - a[3], a[4] + b[4])


@settings(max_examples=300, deadline=None)
@given(pair())
def test_time_of_impact_is_symmetric(p):
    a, b = p  # mostly misses: symmetric infinities count too
    assert _toi(a, b) == _toi(b, a)


@settings(max_examples=300, deadline=None)
@given(st.one_of(pair(), colliding_pair().map(lambda p: p[:2])), coord, coord, speed, speed)
def test_time_of_impact_is_invariant_under_translation_and_common_velocity(p, sx, sy, ux, uy):
    a, b = p
    # The common velocity must leave the relative one resolvable: adding u to speeds of 1e-162 (hypothesis
    # found one) rounds their difference away, whatever the kernel.
    scale = 1.0 + abs(ux) + abs(uy) + max(abs(v) for v in (a[2], a[3], b[2], b[3]))
    assume(math.hypot(b[2] - a[2], b[3] - a[3]) > 1e-6 * scale)
    t = _toi(a, b)
    a2 = (a[0] + sx, a[1] + sy, a[2] + ux, a[3] + uy, a[4])
    b2 = (b[0] + sx, b[1] + sy, b[2] + ux, b[3] + uy, b[4])
    t2 = _toi(a2, b2)
    if math.isinf(t) or math.isinf(t2):
        # only a graze may flip between hit and miss under roundoff
        other, x, y = (t2, a2, b2) if math.isinf(t) else (t, a, b)
        assert math.isinf(other) or abs(_distance_at(x, y, other) - (a[4] + b[4])) < 1e-6
    else:
        assert t2 == pytest.approx(t, rel=1e-6, abs=1e-9)


def _distance_at(a, b, t):
    return math.hypot(b[0] - a[0] + t * (b[2] - a[2]), b[1] - a[1] + t * (b[3] - a[3]))


@settings(max_examples=300, deadline=None)
@given(colliding_pair())
def test_predicted_time_is_the_contact_time(p):
    a, b, t_star = p
    t = _toi(a, b)
    assert t == pytest.approx(t_star, rel=1e-8, abs=1e-9)
    assert _distance_at(a, b, t) == pytest.approx(a[4] + b[4], rel=1e-9)
    assert _toi(b, a) == t  # symmetric


@settings(max_examples=300, deadline=None)
@given(pair(), mass, mass, st.booleans())
def test_collision_conserves_momentum_and_energy(p, m1, m2, obstacle):
    a, b = p
    if obstacle:
        m1 = math.inf
        a = (a[0], a[1], 0.0, 0.0, a[4])
    dx, dy = b[0] - a[0], b[1] - a[1]
    v1x, v1y, v2x, v2y = resolve_collision(dx, dy, a[2], a[3], b[2], b[3], m1, m2)
    if obstacle:
        assert (v1x, v1y) == (0.0, 0.0)
        assert math.hypot(v2x, v2y) == pytest.approx(math.hypot(b[2], b[3]), rel=1e-12, abs=1e-12)
    else:
        scale = m1 * math.hypot(a[2], a[3]) + m2 * math.hypot(b[2], b[3]) + 1e-300
        assert m1 * v1x + m2 * v2x == pytest.approx(m1 * a[2] + m2 * b[2], abs=1e-13 * scale)
        assert m1 * v1y + m2 * v2y == pytest.approx(m1 * a[3] + m2 * b[3], abs=1e-13 * scale)
        e0 = m1 * (a[2] ** 2 + a[3] ** 2) + m2 * (b[2] ** 2 + b[3] ** 2)
        e1 = m1 * (v1x**2 + v1y**2) + m2 * (v2x**2 + v2y**2)
        assert e1 == pytest.approx(e0, rel=1e-12, abs=1e-300)
    # tangential components unchanged
    tx, ty = -dy, dx
    assert v2x * tx + v2y * ty == pytest.approx(b[2] * tx + b[3] * ty, rel=1e-9, abs=1e-9 * math.hypot(tx, ty))
