"""Contact times under linear drag (discsim.physics.damped): closed forms, brute force, the compiled parts.

The spans against their definition in 50-digit arithmetic; ``damped_exit`` and ``damped_time_of_impact``
against closed forms (the stopping distance ``v / gamma``, the terminal velocity ``g / gamma``, free flight's
contact in the transformed time) and, with gravity, against a dense sampling of the exact motion that would see
any crossing or contact they missed, and the answer's own residual; the compiled parts equal the Python ones bit
for bit.
"""

from __future__ import annotations

import math
from decimal import Decimal, getcontext

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from discsim._numba import available
from discsim.physics import damped, dynamics
from discsim.physics.damped import damped_exit, damped_time_of_impact, spans, spans_many, time_of_span
from discsim.physics.roots import accelerated_time_of_impact

needs_numba = pytest.mark.skipif(not available(), reason="numba is not installed or hidden")
coordinate = st.floats(0.5, 9.5)
speed = st.floats(-5.0, 5.0, allow_subnormal=False)
pull = st.floats(-10.0, 10.0, allow_subnormal=False)
drag = st.floats(1e-3, 5.0)


def _exact_spans(dt: float, gamma: float) -> tuple[float, float]:
    getcontext().prec = 50
    g, t = Decimal(gamma), Decimal(dt)
    tau = (1 - (-g * t).exp()) / g
    return float(tau), float((t - tau) / g)


@pytest.mark.parametrize("dt", [1e-9, 1e-4, 0.3, 0.499, 0.501, 2.0, 40.0, 500.0, -0.2])
@pytest.mark.parametrize("gamma", [1.0, 0.01])
def test_spans_have_full_precision_from_tiny_to_long_flights(dt, gamma):
    tau, s, e = spans(dt, gamma)
    tau_exact, s_exact = _exact_spans(dt, gamma)
    assert tau == pytest.approx(tau_exact, rel=4e-16)
    assert s == pytest.approx(s_exact, rel=4e-15)
    assert e == pytest.approx(math.exp(-gamma * dt), rel=4e-16, abs=0.0)
    many = spans_many(np.array([dt, dt]), gamma)
    assert [float(v[0]) for v in many] == pytest.approx([tau, s, e], rel=1e-15)  # numpy's expm1: to the last bit


def test_time_of_span_inverts_the_span_and_knows_where_the_drag_stops_the_motion():
    for t in (1e-6, 0.5, 3.0):
        assert time_of_span(spans(t, 0.7)[0], 0.7) == pytest.approx(t, rel=1e-12)
    assert time_of_span(1 / 0.7, 0.7) == math.inf
    assert time_of_span(math.inf, 0.7) == math.inf


# --- closed forms ---------------------------------------------------------------------------------------------
def test_a_coordinate_stops_short_of_a_line_beyond_its_stopping_distance():
    # From 2 at speed 3 under gamma 0.5 it stops at 2 + 3 / 0.5 = 8: never reaches 9, reaches 7 at tau = 5 / 3.
    assert damped_exit(2.0, 3.0, 0.0, 0.5, 0.0, 9.0) == (math.inf, 0)
    t, side = damped_exit(2.0, 3.0, 0.0, 0.5, 0.0, 7.0)
    assert side == 1 and t == pytest.approx(-math.log(1 - 0.5 * 5 / 3) / 0.5, rel=1e-15)


def test_a_coordinate_falling_from_rest_hits_the_floor_at_the_root_of_the_exact_motion():
    # x(t) = x0 - (g / gamma) (t - tau(t)): x0 = 5, g = 9.81, gamma = 2: lands when x = 1.
    t, side = damped_exit(5.0, 0.0, -9.81, 2.0, 1.0, 9.0)
    assert side == -1
    tau = -math.expm1(-2.0 * t) / 2.0
    assert 5.0 - 9.81 / 2.0 * (t - tau) == pytest.approx(1.0, abs=1e-13)
    # The terminal velocity: almost reached after many 1 / gamma.
    x, _, vx, vy = dynamics.advance(0.0, 0.0, 3.0, 0.0, 20.0, 0.0, -9.81, 2.0)
    assert vy == pytest.approx(-9.81 / 2.0, rel=1e-15) and vx == pytest.approx(3.0 * math.exp(-40.0), rel=1e-12)
    assert x == pytest.approx(3.0 / 2.0 * (1 - math.exp(-40.0)), rel=1e-15)


def test_a_coordinate_just_bounced_off_the_floor_comes_back_never_at_once():
    for below in (0.0, 1e-15):
        t, side = damped_exit(1.0 - below, 2.0, -9.81, 0.5, 1.0, 9.0)
        assert side == -1 and t > 0.3
        x, _, _, _ = dynamics.advance(1.0 - below, 0.0, 2.0, 0.0, t, -9.81, 0.0, 0.5)
        assert x == pytest.approx(1.0 - below, abs=1e-14)


def test_a_pair_without_relative_acceleration_meets_at_free_flights_contact_in_the_span():
    tau = 2.0  # free flight: 4 apart, closing at 1, contact at distance 2
    for gamma in (0.1, 0.4):
        t = damped_time_of_impact(4.0, 0.0, -1.0, 0.0, 0.0, 0.0, gamma, 2.0)
        assert t == pytest.approx(-math.log1p(-gamma * tau) / gamma, rel=1e-15)
    assert damped_time_of_impact(4.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.5, 2.0) == math.inf  # stops after 2


# --- brute force ----------------------------------------------------------------------------------------------
def _coordinate(t, x, v, a, gamma):
    tau, s, _ = spans_many(t, gamma)
    return x + v * tau + a * s


@settings(max_examples=300, deadline=None)
@given(coordinate, speed, pull, drag)
def test_exits_are_the_first_crossing_of_the_exact_motion(x, v, a, gamma):
    lo, hi = 0.0, 10.0
    t, side = damped_exit(x, v, a, gamma, lo, hi)
    horizon = t if t < math.inf else 60.0 / gamma
    grid = np.linspace(0.0, horizon, 20001)[:-1]
    path = _coordinate(grid, x, v, a, gamma)
    assert ((path >= lo - 1e-12) & (path <= hi + 1e-12)).all()  # no crossing before the answer
    if t < math.inf:
        line = hi if side > 0 else lo
        at = _coordinate(np.array([t]), x, v, a, gamma)[0]
        assert at == pytest.approx(line, abs=1e-12)
        before = _coordinate(np.array([np.nextafter(t, 0.0)]), x, v, a, gamma)[0]
        assert (before <= line + 1e-12) if side > 0 else (before >= line - 1e-12)
    else:  # only the drag stops a coordinate short of both lines; an acceleration takes it to one, unless so
        # small that it would take longer than 1e250 (damped._NEVER: never)
        assert side == 0 and abs(a) < 1e-240


def _separation(t, d, w, acc, gamma):
    tau, s, _ = spans_many(t, gamma)
    return np.hypot(d[0] + w[0] * tau + acc[0] * s, d[1] + w[1] * tau + acc[1] * s)


@settings(max_examples=300, deadline=None)
@given(
    st.floats(-5.0, 5.0), st.floats(-5.0, 5.0), speed, speed, st.floats(-3.0, 3.0, allow_subnormal=False),
    st.floats(-10.0, -0.1), st.floats(0.01, 3.0), st.floats(0.3, 2.0),
)  # fmt: skip
def test_a_falling_disc_against_a_still_one_is_never_missed(dx, dy, wx, wy, ax, ay, gamma, sigma):
    assume(math.hypot(dx, dy) > sigma * 1.001)
    d, w, acc = (dx, dy), (wx, wy), (ax, ay)
    t = damped_time_of_impact(dx, dy, wx, wy, ax, ay, gamma, sigma)
    horizon = t if t < math.inf else 40.0 / gamma + 20.0
    grid = np.linspace(0.0, horizon, 100001)[:-1]
    assert (_separation(grid, d, w, acc, gamma) > sigma * (1 - 1e-12)).all()
    if t < math.inf:
        assert _separation(np.array([t]), d, w, acc, gamma)[0] == pytest.approx(sigma, rel=1e-9)


@pytest.mark.parametrize("gamma", [1e-12, 1e-9, 1e-6, 1e-3])
def test_a_falling_disc_under_a_tiny_drag_meets_a_still_one_where_it_would_without(gamma):
    # Dropped 3 above a still disc and 0.3 to the side (contact at 2): the drag moves the contact by about
    # gamma t. (The curvature bound once took the terminal velocity g / gamma as the largest speed: steps of
    # 1e-7 of the fall, and after _MAX_STEPS a "contact" 1.5 sigma apart.)
    t = damped_time_of_impact(-0.3, -3.0, 0.0, 0.0, 0.0, 9.81, gamma, 2.0)
    assert t == pytest.approx(accelerated_time_of_impact(-0.3, -3.0, 0.0, 0.0, 0.0, 9.81, 2.0), rel=10 * gamma + 1e-12)
    assert _separation(np.array([t]), (-0.3, -3.0), (0.0, 0.0), (0.0, 9.81), gamma)[0] == pytest.approx(2.0, rel=1e-12)


@pytest.mark.parametrize("gamma", [1e6, 1e12, 1e20])
def test_a_disc_sinking_at_its_terminal_velocity_under_a_huge_drag_meets_a_still_one_at_contact(gamma):
    # From rest, 3 above and 0.3 to the side: the separation along gravity is -3 + g s(t), s = (t - tau) / gamma,
    # and reaches -sqrt(4 - 0.09). (The curvature bound once took |a - gamma p'| at the terminal velocity, all
    # roundoff, for the curvature: steps of 1e-4 of the way, and a "contact" 1.3 sigma apart after _MAX_STEPS.)
    t = damped_time_of_impact(-0.3, -3.0, 0.0, 0.0, 0.0, 9.81, gamma, 2.0)
    assert t == pytest.approx(gamma * (3.0 - math.sqrt(3.91)) / 9.81 + 1.0 / gamma, rel=1e-9)
    assert _separation(np.array([t]), (-0.3, -3.0), (0.0, 0.0), (0.0, 9.81), gamma)[0] == pytest.approx(2.0, rel=1e-12)


@pytest.mark.slow  # (2 s; test_a_falling_disc_against_a_still_one_is_never_missed stays quick)
@settings(max_examples=300, deadline=None)
@given(
    st.floats(-5.0, 5.0), st.floats(-5.0, 5.0), speed, speed, st.floats(-3.0, 3.0, allow_subnormal=False),
    st.floats(-10.0, -0.1), st.floats(-12.0, 12.0), st.floats(0.3, 2.0),
)  # fmt: skip
def test_a_falling_disc_against_a_still_one_is_met_at_contact_under_drags_from_tiny_to_huge(
    dx, dy, wx, wy, ax, ay, log_gamma, sigma
):
    assume(math.hypot(dx, dy) > sigma * 1.001)
    gamma = 10.0**log_gamma
    d, w, acc = (dx, dy), (wx, wy), (ax, ay)
    t = damped_time_of_impact(dx, dy, wx, wy, ax, ay, gamma, sigma)
    horizon = t if t < math.inf else min(40.0 / gamma + 20.0, 300.0)
    grid = np.linspace(0.0, horizon, 100001)[:-1]
    assert (_separation(grid, d, w, acc, gamma) > sigma * (1 - 1e-12)).all()
    if t < math.inf:  # a contact, not a time the search gave up at
        assert _separation(np.array([t]), d, w, acc, gamma)[0] == pytest.approx(sigma, rel=1e-9)


def test_a_graze_and_a_bounce_back():
    # Passing just above a still disc while sinking very slowly: touches (at 1e-9 below contact at x = 0) or not.
    hit = damped_time_of_impact(-5.0, 2.0 - 1e-9, 1.0, 0.0, 0.0, -1e-12, 0.1, 2.0)
    miss = damped_time_of_impact(-5.0, 2.0 + 1e-6, 1.0, 0.0, 0.0, -1e-12, 0.1, 2.0)
    assert hit == pytest.approx(-math.log1p(-0.1 * 5.0) / 0.1, rel=1e-3) and miss == math.inf
    # Just bounced up off a disc at rest (touching, separating): it comes back down onto it later, not at once.
    t = damped_time_of_impact(0.0, 2.0, 0.0, 1.0, 0.0, -9.81, 0.5, 2.0)
    assert 0.15 < t < 2.0 / 9.81
    assert _separation(np.array([t]), (0.0, 2.0), (0.0, 1.0), (0.0, -9.81), 0.5)[0] == pytest.approx(2.0, rel=1e-9)


@needs_numba
def test_the_compiled_parts_equal_the_python_ones_bit_for_bit():
    from discsim.physics import compiled

    rng = np.random.default_rng(5)
    for _ in range(300):
        x, v, g = rng.uniform(1, 9), rng.normal(scale=3), rng.uniform(0.01, 3)
        a = rng.choice([0.0, rng.normal(scale=5)])
        assert compiled.exit_x(x, v, 0.0, 10.0, a, g) == dynamics.exit_x(x, v, 0.0, 10.0, a, g)
        d = rng.uniform(-5, 5, size=2)
        w = rng.normal(size=2) * 2
        args = (d[0], d[1], w[0], w[1], 1.5, 0.0, -rng.uniform(0.1, 5), g)
        assert compiled.pair_time_of_impact(*args) == dynamics.pair_time_of_impact(*args)
        step = (x, 1.0, v, 0.5, 0.7, 0.0, -2.0, g)
        assert compiled.advance(*step) == dynamics.advance(*step)
    assert damped.PARTS[-1] is damped.damped_time_of_impact
