"""Contact times under a uniform acceleration (discsim.physics.roots): closed forms, brute force, free flight.

``accelerated_time_of_impact`` is held to closed forms (a fall from rest, a projectile, the come-back after a
bounce, a miss, a graze), to a brute force (numpy's roots of the quartic, polished, and a dense sampling that
would see any contact the function missed; exact rational arithmetic for the sign of ``f`` at the answer), to
``pair_time_of_impact`` bit for bit without acceleration, and its compiled form to its Python form bit for bit;
a ball bouncing on a fixed disc until it rolls off keeps its energy. ``accelerated_exit`` likewise against the
quadratic's roots (and 50-digit roots close to a line), ``exit_x``, and a coordinate bouncing on a floor.
"""

from __future__ import annotations

import math
import struct
from decimal import Decimal, localcontext
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from discsim._numba import available
from discsim.physics import dynamics, roots
from discsim.physics.roots import accelerated_exit, accelerated_time_of_impact

needs_numba = pytest.mark.skipif(not available(), reason="numba is not installed or hidden")
position = st.floats(-4.0, 4.0, allow_nan=False, allow_subnormal=False)
speed = st.floats(-3.0, 3.0, allow_nan=False, allow_subnormal=False)
pull = st.floats(-3.0, 3.0, allow_nan=False, allow_subnormal=False)
sigma_ = st.floats(0.2, 2.0)


# --- helpers: f, f' and f'' of the relative motion, a brute force, exact signs -----------------------------------


def _motion(t, d, w, a, sigma):
    """f, f' and f'' of f(t) = |d + w t + a t^2 / 2|^2 - sigma^2 (floats or numpy arrays of t)."""
    px, py = d[0] + w[0] * t + 0.5 * a[0] * t * t, d[1] + w[1] * t + 0.5 * a[1] * t * t
    vx, vy = w[0] + a[0] * t, w[1] + a[1] * t
    return (
        px * px + py * py - sigma * sigma,
        2.0 * (px * vx + py * vy),
        2.0 * (vx * vx + vy * vy + px * a[0] + py * a[1]),
    )


def _horizon(d, w, a, sigma):
    """No contact after this time: |p| >= |a| t^2 / 2 - |w| t - |d| > sigma."""
    an, wn, dn = math.hypot(*a), math.hypot(*w), math.hypot(*d)
    return 2.0 * (wn + math.sqrt(wn * wn + 2.0 * an * (dn + sigma))) / an


def _real_roots(coefficients, lo, hi):
    """numpy's real roots of a polynomial within [lo, hi] (a little slack), sorted."""
    found = np.roots(coefficients)
    real = found[np.abs(found.imag) <= 1e-7 * np.maximum(1.0, np.abs(found.real))].real
    return np.sort(real[(real >= lo - 1e-9) & (real <= hi + 1e-9)])


def _polish(t, d, w, a, sigma, derivative):
    """A few Newton steps on f (derivative 0) or f' (derivative 1) from numpy's root."""
    for _ in range(4):
        values = _motion(t, d, w, a, sigma)
        slope = values[derivative + 1]
        if slope == 0.0:
            break
        t = t - values[derivative] / slope
    return t


def _quartic(d, w, a, sigma):
    """The coefficients of f, highest first."""
    return [
        0.25 * (a[0] ** 2 + a[1] ** 2),
        w[0] * a[0] + w[1] * a[1],
        w[0] ** 2 + w[1] ** 2 + d[0] * a[0] + d[1] * a[1],
        2.0 * (d[0] * w[0] + d[1] * w[1]),
        d[0] ** 2 + d[1] ** 2 - sigma**2,
    ]


def _brute_force(d, w, a, sigma, tolerance=1e-6):
    """The earliest t >= 0 at which the pair touches or overlaps while approaching, from numpy's roots.

    It is 0 (touching and approaching now), a downward root of f, or a maximum of f below 0 (a pair that
    separates while overlapping, then turns back). Cases it cannot tell apart from a graze (a root where f' is
    nearly 0, a turning point where f is nearly 0 or f'' nearly 0) are ``assume``d away: the answer is then
    unique to far better than the comparison's tolerance.
    """
    horizon = _horizon(d, w, a, sigma)
    f0, fp0, _ = _motion(0.0, d, w, a, sigma)
    assume(abs(f0) > tolerance and abs(fp0) > tolerance)
    if f0 <= 0.0 and fp0 < 0.0:
        return 0.0
    c4, c3, c2, c1, c0 = _quartic(d, w, a, sigma)
    best = math.inf
    for r in _real_roots([c4, c3, c2, c1, c0], 0.0, horizon):
        r = _polish(r, d, w, a, sigma, 0)
        _, fp, _ = _motion(r, d, w, a, sigma)
        assume(abs(fp) > 1e-3 and r > 1e-6)
        if fp < 0.0:
            best = min(best, r)
    for c in _real_roots([4.0 * c4, 3.0 * c3, 2.0 * c2, c1], 0.0, horizon):
        c = _polish(c, d, w, a, sigma, 1)
        f, _, fpp = _motion(c, d, w, a, sigma)
        assume(abs(f) > tolerance and abs(fpp) > 1e-3 and c > 1e-6)
        if f < 0.0 and fpp < 0.0:
            best = min(best, c)
    return best


def _first_sampled_contact(d, w, a, sigma, end, samples=4001):
    """The first of ``samples`` times in [0, end] at which the pair overlaps (beyond roundoff) while approaching,
    or inf: a contact the function missed would show here."""
    t = np.linspace(0.0, end, samples)
    f, fp, _ = _motion(t, d, w, a, sigma)
    hits = np.flatnonzero((f < -1e-9) & (fp < -1e-9))
    return float(t[hits[0]]) if hits.size else math.inf


def _exact_f(t, d, w, a, sigma):
    """f(t) in exact rational arithmetic (the sign of f at a float time, free of roundoff)."""
    t = Fraction(t)
    half = Fraction(1, 2)
    px = Fraction(d[0]) + Fraction(w[0]) * t + half * Fraction(a[0]) * t * t
    py = Fraction(d[1]) + Fraction(w[1]) * t + half * Fraction(a[1]) * t * t
    return px * px + py * py - Fraction(sigma) ** 2


def _computed_f(t, d, w, a, sigma):
    """f as the contract of accelerated_time_of_impact computes it: |d + t (w + t a / 2)|^2 - sigma^2."""
    px, py = d[0] + t * (w[0] + t * (0.5 * a[0])), d[1] + t * (w[1] + t * (0.5 * a[1]))
    return px * px + py * py - sigma * sigma


def _toi(d, w, a, sigma):
    return accelerated_time_of_impact(d[0], d[1], w[0], w[1], a[0], a[1], sigma)


def _bits(x) -> bytes:
    return struct.pack("<d", x)


def _same(x, y) -> bool:
    """Bit for bit: floats by their 8 bytes (-0.0 is not 0.0), ints and tuples element by element."""
    if isinstance(x, tuple):
        return isinstance(y, tuple) and len(x) == len(y) and all(_same(p, q) for p, q in zip(x, y))
    if isinstance(x, float) or isinstance(y, float):
        return type(x) is type(y) and _bits(x) == _bits(y)
    return x == y


# --- closed forms ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("h", "g", "sigma"), [(2.0, 1.0, 1.0), (0.5, 9.81, 0.3), (7.25, 2.5, 1.7), (1e-3, 9.81, 1.0)])
def test_a_point_falling_from_rest_onto_a_fixed_disc_lands_at_sqrt_2h_over_g(h, g, sigma):
    t = accelerated_time_of_impact(0.0, sigma + h, 0.0, 0.0, 0.0, -g, sigma)
    assert t == pytest.approx(math.sqrt(2.0 * h / g), rel=1e-12, abs=0.0)
    d, w, a = (0.0, sigma + h), (0.0, 0.0), (0.0, -g)
    assert _computed_f(t, d, w, a, sigma) <= 0.0 < _computed_f(math.nextafter(t, 0.0), d, w, a, sigma)
    # Sideways gravity: the same fall rotated by 90 degrees.
    assert accelerated_time_of_impact(-(sigma + h), 0.0, 0.0, 0.0, g, 0.0, sigma) == t


def test_a_fall_off_centre_lands_where_the_vertical_meets_the_circle():
    # From (0.6, 4) with g = 2 onto a circle of radius 1: lands at y = 0.8, after sqrt(2 * 3.2 / 2).
    t = accelerated_time_of_impact(0.6, 4.0, 0.0, 0.0, 0.0, -2.0, 1.0)
    assert t == pytest.approx(math.sqrt(3.2), rel=1e-12)


def test_a_projectile_reaches_the_circle_where_its_parabola_was_built_to():
    # Built backwards from the contact: at t* = 1.5 the point is at sigma (cos 60, sin 60) moving at (-1, -2)
    # (approaching: the normal component is negative), under g = 3 down. Earlier it was above and to the
    # right, outside the circle (the sampled f below says so).
    sigma, t_star, g = 1.25, 1.5, 3.0
    contact = (sigma * math.cos(math.pi / 3), sigma * math.sin(math.pi / 3))
    u = (-1.0, -2.0)
    a = (0.0, -g)
    d = (contact[0] - u[0] * t_star + 0.5 * a[0] * t_star**2, contact[1] - u[1] * t_star + 0.5 * a[1] * t_star**2)
    w = (u[0] - a[0] * t_star, u[1] - a[1] * t_star)
    assert np.all(_motion(np.linspace(0.0, 0.99 * t_star, 1000), d, w, a, sigma)[0] > 0.0)
    assert _toi(d, w, a, sigma) == pytest.approx(t_star, rel=1e-12)


@pytest.mark.parametrize(("v", "g", "sigma"), [(3.0, 1.0, 1.0), (0.7, 9.81, 0.5), (1e-3, 9.81, 1.0), (40.0, 2.0, 3.0)])
def test_a_vertical_bounce_on_top_of_a_fixed_disc_comes_back_at_2v_over_g(v, g, sigma):
    expected = 2.0 * v / g
    # Exactly at contact, and inside it or outside it by roundoff: the come-back, never 0 again.
    for y in (sigma, sigma * (1.0 - 2.0**-52), math.nextafter(sigma, 0.0), math.nextafter(sigma, 9.0)):
        t = accelerated_time_of_impact(0.0, y, 0.0, v, 0.0, -g, sigma)
        assert t == pytest.approx(expected, rel=1e-9)
    # Touching or overlapping, and approaching: at once.
    assert accelerated_time_of_impact(0.0, sigma, 0.0, -v, 0.0, -g, sigma) == 0.0
    assert accelerated_time_of_impact(0.0, 0.9 * sigma, 0.0, -v, 0.0, -g, sigma) == 0.0


def test_an_oblique_bounce_straight_up_comes_back_to_the_same_point_at_2v_over_g():
    # Leaving the circle at 60 degrees straight up (not along the normal): the vertical line x = sigma / 2 stays
    # outside the circle above the point, so it comes back to it at 2 v / g.
    sigma, v, g = 1.0, 1.5, 1.0
    d = (sigma * math.cos(math.pi / 3), sigma * math.sin(math.pi / 3))
    assert _toi(d, (0.0, v), (0.0, -g), sigma) == pytest.approx(2.0 * v / g, rel=1e-12)


def test_a_bounce_whose_gap_stays_within_roundoff_for_a_while_comes_back_all_the_same():
    # Leaving the circle slowly and obliquely: the computed f is one float above 0 at t = 0 and 0 again at
    # about 1e-15, before the pair parts for good; the contact is the come-back at 0.1367, not that float.
    # (Found by hypothesis against a false-position search, which stopped at 1.05e-15.)
    angle, speed_out, turn, sigma = 0.08984375, 0.125, -1.0, 1.254490713488739
    d = (sigma * math.cos(angle), sigma * math.sin(angle))
    w = (speed_out * math.cos(angle + turn), speed_out * math.sin(angle + turn))
    assert _computed_f(1.0545436435450911e-15, d, w, (-1.0, 0.0), sigma) <= 0.0  # the crossing of roundoff
    assert _toi(d, w, (-1.0, 0.0), sigma) == pytest.approx(0.136696015387724, rel=1e-12)


def test_no_contact_when_the_pull_points_away_or_the_path_passes_by():
    # Thrown away and pulled away: never comes back.
    assert accelerated_time_of_impact(0.0, 2.0, 0.0, 1.0, 0.0, 1.0, 1.0) == math.inf
    assert accelerated_time_of_impact(0.0, 1.0, 0.0, 1.0, 0.0, 0.5, 1.0) == math.inf  # just bounced, pulled off
    # Falling past the disc's side.
    assert accelerated_time_of_impact(1.5, 3.0, 0.0, 0.0, 0.0, -1.0, 1.0) == math.inf
    # Thrown sideways over the top: the parabola clears the circle (lowest |p| above sigma).
    d, w, a = (-3.0, 3.0), (4.0, 0.0), (0.0, -0.1)
    assert _toi(d, w, a, 1.0) == math.inf
    assert _first_sampled_contact(d, w, a, 1.0, _horizon(d, w, a, 1.0)) == math.inf
    # Rising towards the disc, turning back before it.
    assert accelerated_time_of_impact(0.0, -3.0, 0.0, 1.0, 0.0, -1.0, 1.0) == math.inf


@pytest.mark.parametrize("sigma", [1.0, 0.25, 2.0])
def test_a_graze_is_found_by_a_hair_and_missed_by_a_hair(sigma):
    g, height = 1.5, 3.0
    for offset, hits in ((sigma * (1.0 - 1e-6), True), (sigma * (1.0 + 1e-6), False)):
        t = accelerated_time_of_impact(offset, height, 0.0, 0.0, 0.0, -g, sigma)
        if hits:
            landing = math.sqrt(sigma * sigma - offset * offset)
            assert t == pytest.approx(math.sqrt(2.0 * (height - landing) / g), rel=1e-9)
        else:
            assert t == math.inf


def test_at_rest_in_contact_and_pulled_in_collides_at_once():
    # f(0) = 0 and f'(0) = 0, f decreasing after: approaching at second order.
    assert accelerated_time_of_impact(0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 1.0) == 0.0
    assert accelerated_time_of_impact(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0) == math.inf  # pulled off


def test_a_bounce_too_weak_to_lift_off_by_more_than_roundoff_comes_back_at_its_top():
    # Overlapping by roundoff and separating at 1e-20: f never becomes positive as computed; the pair turns back
    # at v / g, while still in contact, and that is the contact (not 0, not a fall through the disc).
    v, g = 1e-20, 1.0
    t = accelerated_time_of_impact(0.0, math.nextafter(1.0, 0.0), 0.0, v, 0.0, -g, 1.0)
    assert 0.0 < t < 1e-15


def test_a_ball_bouncing_on_a_fixed_disc_keeps_its_energy_and_never_sinks_in():
    # A point released slightly off the top of a fixed disc (radius 1, g = 1) bounces elastically (the normal
    # velocity reversed) until it rolls off: every contact at the disc's surface within roundoff, none at once
    # after the last, the energy |v|^2 / 2 + g y unchanged, and in the end a free fall past the disc.
    sigma, g = 1.0, 1.0
    x, y, vx, vy = 1e-6, 1.5, 0.0, 0.0
    energy = 0.5 * (vx * vx + vy * vy) + g * y
    bounces = 0
    while True:
        t = accelerated_time_of_impact(x, y, vx, vy, 0.0, -g, sigma)
        if t == math.inf:
            break
        assert t > 1e-6  # never the bounce just resolved again
        x, y, vx, vy = x + t * vx, y + t * (vy - 0.5 * g * t), vx, vy - g * t
        assert abs(math.hypot(x, y) - sigma) < 1e-12
        nx, ny = x / sigma, y / sigma
        vn = vx * nx + vy * ny
        assert vn < 0.0
        vx, vy = vx - 2.0 * vn * nx, vy - 2.0 * vn * ny
        assert 0.5 * (vx * vx + vy * vy) + g * y == pytest.approx(energy, rel=1e-12)
        bounces += 1
        assert bounces < 1000
    assert bounces == 8 and y < sigma  # bounced 8 times (the offset grows), then rolled off the side


def test_a_coordinate_bouncing_on_a_floor_keeps_its_period():
    # x'' = -g over a floor at 0.3, reflected at every exit through it: the period stays 2 v / g and the
    # coordinate at each bounce is the floor within roundoff, whichever side of it roundoff leaves it.
    g, floor, v = 9.81, 0.3, 1.7
    x, below = floor, 0
    for _ in range(2000):
        t, side = accelerated_exit(x, v, -g, floor, 100.0)
        assert side == -1 and t == pytest.approx(2.0 * 1.7 / g, rel=1e-12)
        x, v = x + v * t - 0.5 * g * t * t, g * t - v
        below += x < floor
        assert abs(x - floor) < 1e-12
    assert below > 1000  # roundoff left it below the floor, and it came back all the same


# --- brute force ---------------------------------------------------------------------------------------------


def _check_against_brute_force(d, w, a, sigma):
    assume(math.hypot(*a) > 0.05)
    expected = _brute_force(d, w, a, sigma)
    t = _toi(d, w, a, sigma)
    horizon = _horizon(d, w, a, sigma)
    if expected == math.inf:
        assert t == math.inf
    else:
        assert t == pytest.approx(expected, rel=1e-9, abs=1e-12)
    # Never a contact missed: no sampled time before the answer overlaps while approaching.
    sampled = _first_sampled_contact(d, w, a, sigma, horizon if t == math.inf else t)
    assert sampled == math.inf or sampled >= t
    if 0.0 < t < math.inf and _motion(t, d, w, a, sigma)[1] < -1e-3:
        # A crossing: never before the contact by more than roundoff (exact f at the answer <= 0 up to the
        # roundoff of f itself), and the float before it outside.
        scale = (math.hypot(*d) + math.hypot(*w) * t + math.hypot(*a) * t * t + sigma) ** 2
        assert _exact_f(t, d, w, a, sigma) <= 8 * 2.0**-52 * scale
        assert _exact_f(math.nextafter(t, 0.0), d, w, a, sigma) >= -8 * 2.0**-52 * scale
        # The contract to the last bit: computed f <= 0 at the answer, > 0 at the float before it.
        assert _computed_f(t, d, w, a, sigma) <= 0.0 < _computed_f(math.nextafter(t, 0.0), d, w, a, sigma)
    return t


@settings(max_examples=300, deadline=None)
@given(position, position, speed, speed, pull, pull, sigma_)
@example(0.0, 3.0, 0.0, 0.0, 0.0, -1.0, 1.0)
@example(-3.0, 3.0, 4.0, 0.0, 0.0, -0.1, 1.0)
@example(0.3, 2.0, -1.0, 0.5, 0.0, -2.0, 0.7)
def test_the_contact_time_agrees_with_a_brute_force(dx, dy, dvx, dvy, ax, ay, sigma):
    _check_against_brute_force((dx, dy), (dvx, dvy), (ax, ay), sigma)


@settings(max_examples=200, deadline=None)
@given(st.floats(0.0, 2.0 * math.pi), st.floats(0.05, 3.0), st.floats(-1.4, 1.4), pull, pull, sigma_)
@example(0.08984375, 0.125, -1.0, -1.0, 0.0, 1.254490713488739)  # f(0) one float above 0, then 0 for a while
def test_the_come_back_after_a_bounce_is_found_and_never_zero(angle, speed_out, turn, ax, ay, sigma):
    # A point on the circle (|d| = sigma up to roundoff, either side) leaving it: normal speed > 0.
    d = (sigma * math.cos(angle), sigma * math.sin(angle))
    direction = angle + turn  # within 80 degrees of the outward normal
    w = (speed_out * math.cos(direction), speed_out * math.sin(direction))
    a = (ax, ay)
    assume(math.hypot(*a) > 0.05)
    t = _toi(d, w, a, sigma)
    assert t > 0.0
    # The brute force: f(t) / t is a cubic (f(0) = 0); its first root where f goes down.
    cubic = _quartic(d, w, a, sigma)[:4]
    horizon = _horizon(d, w, a, sigma)
    expected = math.inf
    for r in _real_roots(cubic, 1e-9, horizon):
        r = _polish(r, d, w, a, sigma, 0)
        fp = _motion(r, d, w, a, sigma)[1]
        assume(abs(fp) > 1e-3 and r > 1e-6)
        if fp < 0.0:
            expected = min(expected, r)
    for c in _real_roots([4.0 * cubic[0], 3.0 * cubic[1], 2.0 * cubic[2], cubic[3]], 1e-9, horizon):
        assume(abs(_motion(_polish(c, d, w, a, sigma, 1), d, w, a, sigma)[0]) > 1e-6)
    if expected == math.inf:
        assert t == math.inf
    else:
        assert t == pytest.approx(expected, rel=1e-9)


@settings(max_examples=200, deadline=None)
@given(position, position, speed, speed, pull, pull, sigma_, st.integers(-40, 40))
def test_a_time_unit_of_a_power_of_two_changes_nothing_but_the_unit(dx, dy, dvx, dvy, ax, ay, sigma, k):
    # Time in units of 2^k: velocities times 2^k, accelerations times 4^k, the contact time over 2^k, exactly
    # (as long as nothing is so small that its products are subnormal and lose bits).
    assume(max(abs(ax), abs(ay)) > 1e-3)
    assume(all(x == 0.0 or abs(x) > 1e-100 for x in (dx, dy, dvx, dvy, ax, ay)))
    t = accelerated_time_of_impact(dx, dy, dvx, dvy, ax, ay, sigma)
    scaled = accelerated_time_of_impact(
        dx, dy, math.ldexp(dvx, k), math.ldexp(dvy, k), math.ldexp(ax, 2 * k), math.ldexp(ay, 2 * k), sigma
    )
    assert _same(scaled, math.ldexp(t, -k))


@pytest.mark.parametrize("g", [1e-179, 3e-320, 1e-120, 1e120, 1e250])
def test_accelerations_far_from_one_are_taken_in_another_time_unit(g):
    # |a|^2 would underflow or overflow: the answer is that of g = 1 in the time unit 1 / sqrt(g), no hang.
    sigma, h = 1.0, 2.0
    t = accelerated_time_of_impact(0.0, sigma + h, 0.0, 0.0, 0.0, -g, sigma)
    assert t == pytest.approx(math.sqrt(2.0 * h) / math.sqrt(g), rel=1e-12)
    v = math.sqrt(g)  # thrown up at sqrt(g): back down at 2 v / g
    assert accelerated_time_of_impact(0.0, sigma, 0.0, v, 0.0, -g, sigma) == pytest.approx(2.0 * v / g, rel=1e-9)
    assert accelerated_time_of_impact(0.0, sigma + h, 0.0, 0.0, 0.0, g, sigma) == math.inf


# --- free flight: the dynamics functions, bit for bit --------------------------------------------------------


@settings(max_examples=300)
@given(position, position, speed, speed, sigma_, st.sampled_from([0.0, -0.0]), st.sampled_from([0.0, -0.0]))
@example(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0)
@example(1.0, 0.0, -1.0, 0.0, 1.0, -0.0, 0.0)
def test_without_acceleration_it_is_the_pair_time_of_impact_bit_for_bit(dx, dy, dvx, dvy, sigma, ax, ay):
    expected = dynamics.pair_time_of_impact(dx, dy, dvx, dvy, sigma)
    assert _same(accelerated_time_of_impact(dx, dy, dvx, dvy, ax, ay, sigma), expected)


@settings(max_examples=300)
@given(position, speed, position, position, st.sampled_from([0.0, -0.0]))
@example(5.0, 0.0, 1.0, 9.0, 0.0)
@example(10.0, 1.0, 1.0, 9.0, -0.0)
def test_without_acceleration_the_exit_is_exit_x_bit_for_bit(x, v, lo, hi, a):
    assert _same(accelerated_exit(x, v, a, lo, hi), dynamics.exit_x(x, v, lo, hi))


# --- accelerated_exit ----------------------------------------------------------------------------------------


def test_a_coordinate_bounced_off_the_floor_comes_back_at_minus_2v_over_a():
    for v, a in ((3.0, -1.0), (0.1, -9.81), (1e-8, -9.81), (7.3, -0.3)):
        assert accelerated_exit(0.0, v, a, 0.0, 1e9) == (-2.0 * v / a, -1)
        assert accelerated_exit(2.5, v, a, 2.5, 1e9) == (-2.0 * v / a, -1)
        # Below the floor by roundoff: the same come-back (it comes back to where it is), not 0.
        assert accelerated_exit(math.nextafter(2.5, 0.0), v, a, 2.5, 1e9) == (-2.0 * v / a, -1)
        assert accelerated_exit(2.5 - 1e-12, v, a, 2.5, 1e9) == (-2.0 * v / a, -1)
    # Mirrored: bounced off a ceiling under a pull upwards.
    assert accelerated_exit(4.0, -3.0, 1.0, -1e9, 4.0) == (6.0, 1)
    assert accelerated_exit(math.nextafter(4.0, 9.0), -3.0, 1.0, -1e9, 4.0) == (6.0, 1)
    # Just above the floor (inside), the true crossing, next to -2 v / a.
    t, side = accelerated_exit(math.nextafter(2.5, 9.0), 3.0, -1.0, 2.5, 1e9)
    assert side == -1 and t == pytest.approx(6.0, rel=1e-12) and t >= 6.0


def test_exit_closed_forms():
    # From rest, pulled up by 2 from 1 to 9: sqrt(2 * 8 / 2).
    t, side = accelerated_exit(1.0, 0.0, 2.0, 0.0, 9.0)
    assert side == 1 and t == pytest.approx(math.sqrt(8.0), rel=1e-15)
    # Thrown up at 4 under g = 2 towards a ceiling 3 above: 3 = 4 t - t^2, t = 1 (moving up at 2).
    assert accelerated_exit(0.0, 4.0, -2.0, -10.0, 3.0) == (1.0, 1)
    # Thrown down at 1 under a pull up of 2 towards a floor 0.2 below: 0.2 - t + t^2 = 0, moving down at sqrt(0.2).
    t, side = accelerated_exit(0.2, -1.0, 2.0, 0.0, 10.0)
    assert side == -1 and t == pytest.approx((1.0 - math.sqrt(0.2)) / 2.0, rel=1e-15)
    # ... a floor 0.5 below: it turns first (at 0.5, 0.25 above it) and leaves by the ceiling.
    t, side = accelerated_exit(0.5, -1.0, 2.0, 0.0, 10.0)
    assert side == 1 and t == pytest.approx(0.5 + math.sqrt(2.0 * 9.75 / 2.0), rel=1e-15)
    # Reaching a line with zero speed is a turn, not an exit: 2 t - t^2 tops out at 1 = hi, then falls to -100.
    t, side = accelerated_exit(0.0, 2.0, -2.0, -100.0, 1.0)
    assert side == -1 and t == pytest.approx(1.0 + math.sqrt(101.0), rel=1e-15)


def test_exit_of_a_coordinate_already_past_its_line():
    # Past the line it moves to: the (negative) time it crossed it, as exit_x.
    t, side = accelerated_exit(11.0, 2.0, -2.0, 0.0, 10.0)  # crossed 10 moving up at sqrt(8), a while ago
    assert side == 1 and t == pytest.approx(2.0 * (10.0 - 11.0) / (2.0 + math.sqrt(8.0)), rel=1e-15) and t < 0.0
    t, side = accelerated_exit(-1.0, -2.0, 2.0, 0.0, 10.0)
    assert side == -1 and t < 0.0
    # Past it, moving towards it, and never meeting it again: 0, the caller acts now.
    assert accelerated_exit(-1.0, -0.5, -2.0, 0.0, 10.0) == (0.0, -1)
    assert accelerated_exit(11.0, 0.5, 2.0, 0.0, 10.0) == (0.0, 1)
    # Past it and moving away from it (a bounce that left it past the line): back to where it is.
    assert accelerated_exit(-1.0, 0.5, -2.0, 0.0, 10.0) == (0.5, -1)
    assert accelerated_exit(11.0, -0.5, 2.0, 0.0, 10.0) == (0.5, 1)


@settings(max_examples=300)
@given(st.floats(-1e3, 1e3), st.floats(0.01, 5.0), st.floats(0.01, 5.0), st.integers(1, 15), st.booleans())
def test_an_exit_close_to_a_line_is_accurate_to_roundoff(x, speed_in, g, digits, upwards):
    # 10^-digits from the line, moving towards it under a pull either way: the time to roundoff, against the
    # root computed with 40 digits (the textbook formula loses them: (-v - s) / a with s close to -v).
    gap = 10.0**-digits
    line = x + gap if upwards else x - gap
    assume(line != x)  # the gap not lost to x's roundoff (the exact root below takes the line as it is)
    v = speed_in if upwards else -speed_in
    for a in (g, -g):
        if a * v < 0.0 and v * v <= 4.0 * g * gap:
            continue  # pulled back before it gets there
        lo, hi = (x - 1e4, line) if upwards else (line, x + 1e4)
        t, side = accelerated_exit(x, v, a, lo, hi)
        assert side == (1 if upwards else -1)
        with localcontext() as context:
            context.prec = 50
            dv, da, dgap = Decimal(v), Decimal(a), Decimal(line) - Decimal(x)
            s = (dv * dv + 2 * da * dgap).sqrt()
            exact = (-dv + s) / da if upwards else (-dv - s) / da
        assert t == pytest.approx(float(exact), rel=1e-13, abs=0.0)


@settings(max_examples=300)
@given(position, speed, pull, st.floats(0.1, 4.0), st.floats(0.1, 4.0))
@example(0.0, 3.0, -1.0, 0.1, 100.0)
def test_the_exit_agrees_with_a_brute_force(x, v, a, below, above):
    lo, hi = x - below, x + above
    assume(abs(a) > 1e-3)
    best = (math.inf, 0)
    for line, side in ((lo, -1), (hi, 1)):
        speed2 = v * v + 2.0 * a * (line - x)
        assume(abs(speed2) > 1e-6)  # reaching a line at nearly zero speed: a graze, either answer right
        for r in _real_roots([0.5 * a, v, x - line], 0.0, math.inf):
            if side * (v + a * r) > 0.0 and r < best[0]:
                best = (r, side)
    t, side = accelerated_exit(x, v, a, lo, hi)
    assert side == best[1]
    assert t == pytest.approx(best[0], rel=1e-9)
    assert lo - 1e-9 <= x + v * t + 0.5 * a * t * t <= hi + 1e-9


# --- compiled ------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def compiled():
    from discsim._compiled import compile_from_source, jit

    parts = compile_from_source(roots.PARTS, jit)
    return parts[roots.accelerated_time_of_impact], parts[roots.accelerated_exit]


@needs_numba
@settings(max_examples=500, deadline=None)
@given(position, position, speed, speed, pull, pull, sigma_, st.booleans())
@example(0.0, 1.0, 0.0, 3.0, 0.0, -1.0, 1.0, False)
@example(0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 1.0, True)
@example(0.5, 2.0, -1.0, 0.0, 0.0, 0.0, 1.0, False)
def test_the_compiled_parts_equal_the_python_parts_bit_for_bit(compiled, dx, dy, dvx, dvy, ax, ay, sigma, on_circle):
    toi, exit_ = compiled
    if on_circle:  # just after a bounce, where the answer needs every step
        norm = math.hypot(dx, dy) or 1.0
        dx, dy = sigma * dx / norm, sigma * dy / norm
    args = (dx, dy, dvx, dvy, ax, ay, sigma)
    assert _same(toi(*args), accelerated_time_of_impact(*args))
    for g in (1e-179, 1e250):  # another time unit
        args = (dx, dy, dvx, dvy, ax * g, ay * g, sigma)
        assert _same(toi(*args), accelerated_time_of_impact(*args))
    for lo, hi in ((dx - 1.0, dx + 2.0), (dx, dx + 5.0), (dx + 0.5, dx - 0.5)):
        assert _same(exit_(dx, dvx, ax, lo, hi), accelerated_exit(dx, dvx, ax, lo, hi))
