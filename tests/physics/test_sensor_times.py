"""The time a disc's centre next changes sides of a sensor (discsim.physics.sources.sensors): closed forms, brute
force, the compiled part, edge cases.

Closed forms: a chord through a circle (the quadratic's roots), a drop through a circle (``sqrt(2 h / g)``), a wire
crossed at constant speed, a thrown ball through a horizontal wire (up and down), a rectangle entered through a
corner region (the later slab entry) or missed (slab intervals apart), drag alone (``t = -log1p(-gamma tau) /
gamma``, or never when the disc stops short). Brute force: random states, accelerations and drags against the exact
flight (:func:`discsim.physics.dynamics.advance`) sampled densely, :meth:`discsim.sensors.Sensor.contains` deciding
the side. The compiled ``sensor_predict`` equals the Python ``predict`` bit for bit. Edge cases: a centre on the
boundary (strictly inside is inside), at rest, moving along the boundary, and a state that disagrees with the
geometry by roundoff (answered at once, never late).
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from discsim._numba import available
from discsim.physics import dynamics
from discsim.physics.sources import sensors as src
from discsim.physics.sources.sensors import circle_time, line_time, predict, rectangle_time
from discsim.sensors import Sensor

needs_numba = pytest.mark.skipif(not available(), reason="numba is not installed or hidden")
G = 9.81
NO = (0.0, 0.0, 0.0)  # no acceleration, no drag


def _position(state, t, ax=0.0, ay=0.0, drag=0.0):
    """The exact flight's centre ``t`` after ``state = (x, y, vx, vy)`` (a float ``t``)."""
    x, y, _, _ = dynamics.advance(*state, float(t), ax, ay, drag)
    return x, y


def _path(state, times, ax, ay, drag):
    """The exact flight's centres at ``times`` ``(T,)``: ``(T, 2)`` (advance; advance_many under drag)."""
    if drag == 0.0:
        x, y, _, _ = dynamics.advance(*(np.full_like(times, v) for v in state), times, ax, ay)
        return np.stack([x, y], axis=1)
    x, y, _, _ = dynamics.advance_many(*(np.full_like(times, v) for v in state), times, ax, ay, drag)
    return np.stack([x, y], axis=1)


def _depth(sensor: Sensor, points: np.ndarray) -> np.ndarray:
    """``(P,)``: how far inside each point is (negative outside; its distance to the edge within a factor, 0 on it)."""
    a0, a1, a2, a3 = sensor.params.tolist()
    x, y = points[:, 0], points[:, 1]
    if sensor.shape == "circle":
        return a2 - np.hypot(x - a0, y - a1)
    if sensor.shape == "rectangle":
        return np.minimum(np.minimum(x - a0, a2 - x), np.minimum(y - a1, a3 - y))
    return ((a2 - a0) * (y - a1) - (a3 - a1) * (x - a0)) / math.hypot(a2 - a0, a3 - a1)


def _contains_exactly(sensor: Sensor, state, ax, ay, drag, t, dt) -> bool:
    """:meth:`Sensor.contains` of the centre at ``t + dt`` along the exact flight, in 400-digit arithmetic."""
    with localcontext() as ctx:
        ctx.prec = 400
        x, y, vx, vy, gx, gy, gamma = (Decimal(v) for v in (*state, ax, ay, drag))
        time = Decimal(t) + Decimal(dt)
        if gamma == 0:
            tau, span = time, time * time / 2
        else:  # the spans of discsim.physics.damped
            tau = (1 - (-gamma * time).exp()) / gamma
            span = (time - tau) / gamma
        px, py = x + vx * tau + gx * span, y + vy * tau + gy * span
        a0, a1, a2, a3 = (Decimal(v) for v in sensor.params.tolist())
        if sensor.shape == "circle":
            return (px - a0) ** 2 + (py - a1) ** 2 < a2 * a2
        if sensor.shape == "rectangle":
            return a0 < px < a2 and a1 < py < a3
        return (a2 - a0) * (py - a1) - (a3 - a1) * (px - a0) > 0


def _predict(sensor: Sensor, state, ax, ay, drag, inside) -> float:
    return predict(*state, ax, ay, drag, sensor.code, *sensor.params.tolist(), inside)


# --- closed forms -----------------------------------------------------------------------------------------------
def test_a_chord_through_a_circle_enters_and_leaves_at_the_roots_of_the_quadratic():
    # Along y = 3 at speed 2 through a circle of radius 5: in at x = -4, out at x = 4.
    assert circle_time(-10.0, 3.0, 2.0, 0.0, *NO, 0.0, 0.0, 5.0, False) == 3.0
    assert circle_time(0.0, 3.0, 2.0, 0.0, *NO, 0.0, 0.0, 5.0, True) == 2.0
    # A slanted chord: |d + v t|^2 = R^2, d = (-6, 1) from the centre (1, -2), v = (1.5, -0.2), R = 2.
    d, v, r = np.array([-6.0, 1.0]), np.array([1.5, -0.2]), 2.0
    t_in, t_out = sorted(np.roots([v @ v, 2.0 * (d @ v), d @ d - r * r]).real)
    assert circle_time(-5.0, -1.0, 1.5, -0.2, *NO, 1.0, -2.0, r, False) == pytest.approx(t_in, rel=1e-14)
    x, y = _position((-5.0, -1.0, 1.5, -0.2), 0.5 * (t_in + t_out))  # half way along the chord: inside
    t = circle_time(x, y, 1.5, -0.2, *NO, 1.0, -2.0, r, True)
    assert t == pytest.approx(0.5 * (t_out - t_in), rel=1e-13)
    # The line passes |d x v| / |v| = 0.198 from the centre: it misses a circle of radius 0.15.
    assert circle_time(-5.0, -1.0, 1.5, -0.2, *NO, 1.0, -2.0, 0.15, False) == math.inf


def test_a_disc_dropped_through_a_circle_enters_and_leaves_at_sqrt_2h_over_g():
    # Dropped from rest 3 above the centre of a circle of radius 1: in after falling 2, out after falling 4.
    assert circle_time(0.0, 3.0, 0.0, 0.0, 0.0, -G, 0.0, 0.0, 0.0, 1.0, False) == pytest.approx(
        math.sqrt(2.0 * 2.0 / G), rel=1e-15
    )
    assert circle_time(0.0, 0.5, 0.0, 0.0, 0.0, -G, 0.0, 0.0, 0.0, 1.0, True) == pytest.approx(
        math.sqrt(2.0 * 1.5 / G), rel=1e-15
    )
    # Thrown up from the centre at 3 under g = 2: rises 2.25 at most, leaves at y = 1 on the way up.
    assert circle_time(0.0, 0.0, 0.0, 3.0, 0.0, -2.0, 0.0, 0.0, 0.0, 1.0, True) == pytest.approx(
        (3.0 - math.sqrt(9.0 - 4.0)) / 2.0, rel=1e-15
    )


def test_a_wire_is_crossed_at_constant_speed_where_its_line_is_reached_on_or_beyond_the_segment():
    # The wire from (3, -1) to (3, 1): its left (inside) is x < 3. At speed 2 along x, x = 3 at 1.5.
    for y in (0.2, 10.0, -7.0):  # on the segment, beyond either end: the line's side changes all the same
        assert line_time(0.0, y, 2.0, 0.5, *NO, 3.0, -1.0, 3.0, 1.0, True) == 1.5
        assert line_time(6.0, y, -2.0, 0.5, *NO, 3.0, -1.0, 3.0, 1.0, False) == 1.5
    # A slanted wire: u = cross(e, p - p0) falls at cross(e, v) per unit time.
    e, p, v = np.array([2.0, 1.0]), np.array([-1.0, 2.0]), np.array([1.0, -1.5])
    u, du = e[0] * p[1] - e[1] * p[0], e[0] * v[1] - e[1] * v[0]
    assert line_time(*p, *v, *NO, 0.0, 0.0, *e, True) == pytest.approx(-u / du, rel=1e-15)
    assert line_time(*p, *-v, *NO, 0.0, 0.0, *e, True) == math.inf  # moving away


def test_a_ball_thrown_through_a_horizontal_wire_crosses_it_up_then_down():
    # The wire y = 2 (from x = -10 to 10: its left is above). Thrown up at 10 from y = 0: crosses at the roots of
    # 2 = 10 t - g t^2 / 2.
    s = math.sqrt(100.0 - 2.0 * G * 2.0)
    up, down = (10.0 - s) / G, (10.0 + s) / G
    wire = (-10.0, 2.0, 10.0, 2.0)
    assert line_time(0.0, 0.0, 1.0, 10.0, 0.0, -G, 0.0, *wire, False) == pytest.approx(up, rel=1e-15)
    x, y, vx, vy = dynamics.advance(0.0, 0.0, 1.0, 10.0, 1.0, 0.0, -G)  # above the wire, still rising
    assert line_time(x, y, vx, vy, 0.0, -G, 0.0, *wire, True) == pytest.approx(down - 1.0, rel=1e-14)
    x, y, vx, vy = dynamics.advance(0.0, 0.0, 1.0, 10.0, 1.5, 0.0, -G)  # above it, falling
    assert line_time(x, y, vx, vy, 0.0, -G, 0.0, *wire, True) == pytest.approx(down - 1.5, rel=1e-14)
    # Thrown too softly to reach it: never.
    assert line_time(0.0, 0.0, 1.0, 6.0, 0.0, -G, 0.0, *wire, False) == math.inf


def test_a_rectangle_is_entered_through_a_corner_region_at_the_later_slab_entry():
    box = (2.0, 3.0, 5.0, 5.0)  # [2, 5] x [3, 5]
    # From (0, 0) at (1, 2): x is in [2, 5] for t in [2, 5], y in [3, 5] for t in [1.5, 2.5]: in at 2 (by x).
    assert rectangle_time(0.0, 0.0, 1.0, 2.0, *NO, *box, False) == 2.0
    # From (0, -3) at (1, 2): x in [2, 5], y in [3, 4]: in at 3 (by y).
    assert rectangle_time(0.0, -3.0, 1.0, 2.0, *NO, *box, False) == 3.0
    # Leaving: the earlier slab exit (from (3, 4) at (1, 2): y = 5 at 0.5 before x = 5 at 2).
    assert rectangle_time(3.0, 4.0, 1.0, 2.0, *NO, *box, True) == 0.5


def test_a_rectangle_is_missed_when_the_slab_intervals_do_not_overlap():
    box = (2.0, 3.0, 5.0, 5.0)
    # At (2, 1) from (0, 0): x in [1, 2.5], y in [3, 5]; past the corner (5, 3) on the way.
    assert rectangle_time(0.0, 0.0, 2.0, 1.0, *NO, *box, False) == math.inf
    # Moving away, parallel to an edge outside, at rest outside: never.
    assert rectangle_time(0.0, 0.0, -1.0, -1.0, *NO, *box, False) == math.inf
    assert rectangle_time(0.0, 4.0, 0.0, 1.0, *NO, *box, False) == math.inf
    assert rectangle_time(0.0, 4.0, 0.0, 0.0, *NO, *box, False) == math.inf
    # Under gravity the parabola may pass over the box: thrown at (1, 4) from (0, 0) under g = 1, y = 5 when
    # 4 t - t^2 / 2 = 5 (t = 4 - sqrt(6) = 1.55): x = 1.55 < 2 while y < 5 ... then above 5 until x = 6.45 > 5.
    assert rectangle_time(0.0, 0.0, 1.0, 4.0, 0.0, -1.0, 0.0, *box, False) == math.inf
    # ... and it enters the same box thrown a little flatter: (1, 3.2): y = 3 at 1.2, x = 2 at 2 (y = 4.4).
    assert rectangle_time(0.0, 0.0, 1.0, 3.2, 0.0, -1.0, 0.0, *box, False) == 2.0


@pytest.mark.parametrize("gamma", [0.1, 0.3])
def test_drag_alone_reaches_a_sensor_at_the_time_of_its_span(gamma):
    def at_span(tau):  # the time the span tau(t) = (1 - e^(-gamma t)) / gamma reaches tau
        return -math.log1p(-gamma * tau) / gamma

    # Speed 2, stopping distance 2 / gamma (20, 6.7): a circle 5 away (tau = 2.5), a wire 3 away (tau = 1.5),
    # a rectangle 4 away (tau = 2).
    assert circle_time(-10.0, 0.0, 2.0, 0.0, 0.0, 0.0, gamma, 0.0, 0.0, 5.0, False) == pytest.approx(
        at_span(2.5), rel=1e-15
    )
    assert circle_time(0.0, 0.0, 2.0, 0.0, 0.0, 0.0, gamma, 0.0, 0.0, 5.0, True) == pytest.approx(
        at_span(2.5), rel=1e-15
    )
    assert line_time(0.0, 0.0, 2.0, 0.0, 0.0, 0.0, gamma, 3.0, -1.0, 3.0, 1.0, True) == pytest.approx(
        at_span(1.5), rel=1e-15
    )
    assert rectangle_time(0.0, 0.0, 2.0, 0.0, 0.0, 0.0, gamma, 4.0, -1.0, 5.0, 1.0, False) == pytest.approx(
        at_span(2.0), rel=1e-15
    )


def test_drag_alone_stops_a_disc_short_of_a_sensor_beyond_its_stopping_distance():
    # Speed 2 under gamma 0.5 stops after 4: never reaches a circle, a wire or a rectangle 5 away.
    assert circle_time(-10.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 5.0, False) == math.inf
    assert circle_time(0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 5.0, True) == math.inf
    assert line_time(0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.5, 5.0, -1.0, 5.0, 1.0, True) == math.inf
    assert rectangle_time(0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.5, 5.0, -1.0, 6.0, 1.0, False) == math.inf
    # Exactly the stopping distance: reached only as t -> inf.
    assert line_time(0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.5, 4.0, -1.0, 4.0, 1.0, True) == math.inf


def test_a_circle_under_gravity_and_drag_is_entered_and_left_where_the_fall_reaches_its_edge():
    # Dropped from rest under g and drag gamma: fallen h at the t where (g / gamma)(t - tau(t)) = h, solved here by
    # bisection of that closed form; from y = 3 it enters the unit circle at y = 1 (h = 2); from the centre it
    # leaves at y = -1 (h = 1).
    gamma = 0.5

    def fallen(h):
        lo, hi = 0.0, 10.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if G / gamma * (mid + math.expm1(-gamma * mid) / gamma) < h else (lo, mid)
        return hi

    assert circle_time(0.0, 3.0, 0.0, 0.0, 0.0, -G, gamma, 0.0, 0.0, 1.0, False) == pytest.approx(fallen(2.0), rel=1e-9)
    assert circle_time(0.0, 0.0, 0.0, 0.0, 0.0, -G, gamma, 0.0, 0.0, 1.0, True) == pytest.approx(fallen(1.0), rel=1e-9)


# --- brute force ------------------------------------------------------------------------------------------------
_coordinate = st.floats(-5.0, 5.0, allow_subnormal=False)
# Speeds below 1e-100 (not 0) are left out: under gravity and drag, damped._rising_root divides 0 by 0 for them (see
# test_a_wire_left_at_a_speed_of_1e_200_under_gravity_and_drag_is_a_known_zero_over_zero).
_speed = st.floats(-5.0, 5.0, allow_subnormal=False).filter(lambda v: v == 0.0 or abs(v) > 1e-100)
# Accelerations below 1e-150 (not 0) are left out: a circle's times take them in a time unit where they are about 1,
# in which a speed of 2 under 2e-308 is 1e154 and its square overflows (inf: never). roots.accelerated_time_of_impact
# shares the limit.
_pull = st.one_of(st.just(0.0), st.floats(-10.0, 10.0).filter(lambda a: a == 0.0 or abs(a) > 1e-150))
_drag = st.one_of(st.just(0.0), st.floats(0.02, 3.0))


@st.composite
def _sensors(draw, shape):
    cx, cy = draw(st.floats(-3.0, 3.0)), draw(st.floats(-3.0, 3.0))
    if shape == "circle":
        return Sensor.circle((cx, cy), draw(st.floats(0.2, 3.0)))
    if shape == "rectangle":
        return Sensor.rectangle((cx, cy), (cx + draw(st.floats(0.2, 4.0)), cy + draw(st.floats(0.2, 4.0))))
    angle, length = draw(st.floats(-math.pi, math.pi)), draw(st.floats(0.1, 5.0))
    return Sensor.line((cx, cy), (cx + length * math.cos(angle), cy + length * math.sin(angle)))


@st.composite
def _starts(draw, sensor):
    """A centre anywhere, or on (within roundoff of) the sensor's edge half the time."""
    if not draw(st.booleans()):
        return draw(_coordinate), draw(_coordinate)
    a0, a1, a2, a3 = sensor.params.tolist()
    f = draw(st.floats(0.0, 1.0))
    if sensor.shape == "circle":
        return a0 + a2 * math.cos(2 * math.pi * f), a1 + a2 * math.sin(2 * math.pi * f)
    if sensor.shape == "line":
        return a0 + f * (a2 - a0), a1 + f * (a3 - a1)
    side = draw(st.integers(0, 3))
    return ((a0, a1 + f * (a3 - a1)), (a2, a1 + f * (a3 - a1)), (a0 + f * (a2 - a0), a1), (a0 + f * (a2 - a0), a3))[
        side
    ]


_SAMPLES = 20000
_HORIZON = 8.0  # sampled densely to here; a drag's long tail (it stops, or sinks) more sparsely to _FAR / gamma
_FAR = 40.0


def _check_against_the_flight(sensor, state, ax, ay, drag):
    """The prediction from a consistent start is the first change of ``contains`` along the sampled flight."""
    start = np.array([state[:2]])
    inside = bool(sensor.contains(start)[0])
    t = _predict(sensor, state, ax, ay, drag, inside)
    assert not math.isnan(t)
    scale = 1.0 + float(np.abs(start).max()) + float(np.abs(sensor.params).max())
    horizon = _HORIZON if t == math.inf else min(max(2.0 * t, 1.0), _HORIZON)
    grid = np.linspace(0.0, horizon, _SAMPLES + 1)
    if drag != 0.0 and t == math.inf:
        grid = np.concatenate([grid, np.linspace(horizon, max(_FAR / drag, horizon), _SAMPLES + 1)[1:]])
    spacing = horizon / _SAMPLES
    path = _path(state, grid, ax, ay, drag)
    # The path's own size, for roundoff: positions carry ~1e-16 of it.
    eps = 1e-10 * (scale + float(np.abs(path).max()))
    depth = _depth(sensor, path)
    changed = sensor.contains(path) != inside
    clear = changed & (np.abs(depth) > eps)  # a change beyond roundoff of the edge
    if t == math.inf:
        assert not clear.any(), f"a change at {grid[np.argmax(clear)]} was missed"
        return
    at = max(t, 0.0)
    # On the edge at the predicted time (within roundoff of the flight's terms then), and no clear change before.
    edge = _depth(sensor, np.array([_position(state, at, ax, ay, drag)]))[0]
    terms = scale + math.hypot(*state[2:]) * at + math.hypot(ax, ay) * at * at
    assert abs(edge) <= 1e-10 * terms, f"at t = {t} the centre is {edge} from the edge"
    before = grid < at
    assert not (clear & before).any(), f"a change at {grid[np.argmax(clear & before)]} before t = {t}"
    # The first sampled change lies within one sample spacing of the prediction; if not, the crossing must show
    # on finer samples just after it, or be a touch.
    if at > horizon:  # beyond the sampled span (only the drag's tail): the edge check above is the test
        return
    if changed.any():
        first = grid[np.argmax(changed)]
        if abs(first - at) <= spacing * (1.0 + 1e-9):
            return
    # Finer and finer after t (a centre on one edge of a rectangle moving in, a hair inside another moving out, is
    # inside for as long as that hair takes to cross).
    fine = at + spacing * np.concatenate([np.logspace(-300.0, 0.0, 1201), np.linspace(0.0, 1.0, 1001)[1:]])
    if (sensor.contains(_path(state, fine, ax, ay, drag)) != inside).any():
        return
    tiny = [Decimal(spacing).scaleb(-k) for k in range(6, 390, 4)]  # below the floats too (a hair of 5e-324)
    if any(_contains_exactly(sensor, state, ax, ay, drag, at, dt) != inside for dt in tiny):
        return  # in by less than floats can show (on one edge moving in, 1e-290 inside another moving out)
    if sensor.shape == "rectangle":  # through a corner, one coordinate leaving its slab as the other enters its
        # own at the same time within roundoff: a tie that roundoff decides
        x, y = _position(state, at, ax, ay, drag)
        a0, a1, a2, a3 = sensor.params.tolist()
        if min(abs(x - a0), abs(x - a2)) <= eps and min(abs(y - a1), abs(y - a3)) <= eps:
            return
    # Else only a touch (a tangency: the depth grows as the square of the time from t) may count: the time of
    # impact under gravity (roots.accelerated_time_of_impact) counts one as a contact, and so an entry.
    near = _depth(sensor, _path(state, np.array([at + 1e-6, max(at - 1e-6, 0.0)]), ax, ay, drag))
    curvature = 1.0 + float(np.hypot(*state[2:])) ** 2 + math.hypot(ax, ay)
    assert np.abs(near).max() <= 1e-11 * curvature + eps, f"no change within a sample spacing after t = {t}"


@st.composite
def _flights(draw, shape):
    """A sensor of ``shape``, a state, an acceleration (often 0) and a drag (often 0)."""
    sensor = draw(_sensors(shape))
    x, y = draw(_starts(sensor))
    state = (x, y, draw(_speed), draw(_speed))
    ax, ay, drag = draw(_pull), draw(_pull), draw(_drag)
    if shape == "line":  # across a wire at a slant of 1e-213, speeds and accelerations become tiny again
        a0, a1, a2, a3 = sensor.params.tolist()
        v_across = (a2 - a0) * state[3] - (a3 - a1) * state[2]
        a_across = (a2 - a0) * ay - (a3 - a1) * ax
        assume(not 0.0 < abs(v_across) < 1e-100 and not 0.0 < abs(a_across) < 1e-150)
    return sensor, state, ax, ay, drag


@pytest.mark.parametrize("shape", ["circle", "rectangle", "line"])
@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_the_time_is_the_first_change_of_sides_along_the_exact_flight(shape, data):
    _check_against_the_flight(*data.draw(_flights(shape)))


@pytest.mark.slow
@pytest.mark.parametrize("shape", ["circle", "rectangle", "line"])
@settings(max_examples=2000, deadline=None)
@given(data=st.data())
def test_the_time_is_the_first_change_of_sides_along_the_exact_flight_many(shape, data):
    _check_against_the_flight(*data.draw(_flights(shape)))


@pytest.mark.parametrize(
    ("sensor", "state", "ax", "ay", "drag"),
    [  # examples hypothesis found
        # The entry through the bottom edge rounds below it (was inf: the search stuck a hair short of the edge).
        (Sensor.rectangle((0.0, 1.1230806982588442), (2.0, 2.1230806982588444)), (0.0, -1.7032920680984636, 0.5, 1.0),
         0.0, 0.0, 0.0),
        # A disc a hair outside a circle, recorded as geometry says, under a gravity of 5e-290 (|a|^2 underflowed).
        (Sensor.circle((1.0, 0.0), 0.2), (1.2, 0.0, 0.0, 0.0), 0.0, 4.717782670673017e-290, 0.0),
        (Sensor.circle((1.0, 0.0), 0.2), (1.0, 0.0, 0.0, 0.0), 0.0, 4.717782670673017e-290, 0.0),
        # Through a rectangle's corner, only touching it (was 1: entered): x leaves its slab as y enters its own.
        (Sensor.rectangle((0.0, 1.0), (1.0, 2.0)), (0.0, 0.0, 1.0, 1.0), 0.0, 0.0, 0.0),
        (Sensor.rectangle((0.0, 0.0), (1.0, 1.0)), (1.0, 0.0, -1.0, -1.0), 0.0, 2.0, 0.0),
        # On one edge of a rectangle moving in, a hair inside the other moving out: in for 5e-17, 1e-156, 8e-290.
        (Sensor.rectangle((0.0, 0.0), (1.0, 0.5)), (0.0, 0.49999999999999994, 1.0, 1.0), 0.0, 0.0, 0.0),
        (Sensor.rectangle((0.0, 0.0), (1.0, 1.0)), (1.0022195967678843e-156, 0.0, -1.0, 1.0), 0.0, 0.0, 0.0),
        (Sensor.rectangle((0.0, 0.0), (1.0, 1.0)), (1.0, 8.511770570882049e-290, -1.0, -1.0), 0.0, 0.0, 0.0),
        (Sensor.rectangle((0.0, 0.0), (1.0, 1.0)), (1.0, 5e-324, -1.0, -1.0), 0.0, 0.0, 0.0),
        # The same under drag; and on an edge moving in at 5e-66 under drag: in by 3e-66 when the other enters.
        (Sensor.rectangle((0.0, 1.0), (1.0, 2.0)), (0.9999999999999999, 1.0, 1.0, 1.0), 0.0, 0.0, 1.0),
        (Sensor.rectangle((0.0, 0.0), (0.5, 1.0)), (1.0, 1.0, -1.0, -5.444178998618439e-66), 0.0, 0.0, 1.0),
        # Through the corner (x0, 1) under drag: x leaves its slab as y enters its own, both at 1.59 (a tie).
        (Sensor.rectangle((-3.1495664222176614e-295, 0.0), (1.0, 1.0)), (-3.1495664222176614e-295, 1.0, 1.0, 1.0),
         -1.0, -1.0, 1.0),
        # Pulled along the tangent y = 1 of the circle around (1, 0): a touch at (1, 1), counted as an entry.
        (Sensor.circle((1.0, 0.0), 1.0), (0.0, 1.0, 0.0, 0.0), 1.0, 0.0, 0.0),
        # On a wire, moving away, pulled back by 3e-24: back through it after 7e23.
        (Sensor.line((0.0, 0.0), (1.0, 0.0)), (0.0, 0.0, 0.0, -1.0), 0.0, 2.725015926323743e-24, 0.0),
    ],
)  # fmt: skip
def test_the_examples_hypothesis_found(sensor, state, ax, ay, drag):
    _check_against_the_flight(sensor, state, ax, ay, drag)


# --- the compiled part ------------------------------------------------------------------------------------------
def _random_inputs(rng, count):
    """Random inputs to ``predict`` of every shape, inside or not as the geometry says (and a few that disagree)."""
    rows = []
    for k in range(count):
        shape = (src.CIRCLE, src.RECTANGLE, src.LINE)[k % 3]
        cx, cy = rng.uniform(-3, 3, 2)
        if shape == src.CIRCLE:
            sensor = Sensor.circle((cx, cy), rng.uniform(0.2, 3))
        elif shape == src.RECTANGLE:
            sensor = Sensor.rectangle((cx, cy), (cx + rng.uniform(0.2, 4), cy + rng.uniform(0.2, 4)))
        else:
            sensor = Sensor.line((cx, cy), (cx + rng.uniform(-4, 4), cy + rng.uniform(-4, 4)))
        x, y, vx, vy = rng.uniform(-5, 5, 4).tolist()
        ax, ay = (rng.choice([0.0, 1.0], 2) * rng.normal(scale=5, size=2)).tolist()
        drag = float(rng.choice([0.0, rng.uniform(0.01, 3)]))
        inside = bool(sensor.contains([x, y])[0]) != (k % 17 == 0)
        rows.append((x, y, vx, vy, ax, ay, drag, float(shape), *sensor.params.tolist(), inside))
    return rows


#: Inputs the edge cases below take: on an edge, at rest, extreme accelerations.
_EDGE_INPUTS = [
    (0.0, 0.0, 0.0, 0.0, 0.0, -G, 0.0, 3.0, 1.0, 0.0, -1.0, 0.0, False),
    (0.0, 0.0, 0.0, 0.0, 0.0, -G, 0.5, 3.0, 1.0, 0.0, -1.0, 0.0, False),
    (0.0, 0.5, -1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 2.0, 1.0, False),
    (1.0, 1.0, 0.0, 0.0, 0.0, -G, 0.0, 2.0, 0.0, 0.0, 2.0, 1.0, False),
    (0.0, 0.0, 1.0, 0.0, 0.0, -1e-200, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, True),
    (0.0, 0.0, 1.0, 0.0, 0.0, -1e200, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, True),
    (math.nextafter(1.0, 2.0), 0.0, -1.0, 0.0, 0.0, -G, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, True),
]


def _bits(value: float) -> int:
    """The float's 64 bits (so that -0.0 and 0.0 differ, and nan equals itself)."""
    return int(np.float64(value).view(np.int64))


@needs_numba
def test_the_compiled_part_equals_the_python_one_bit_for_bit():
    from discsim.physics import compiled

    for args in _EDGE_INPUTS + _random_inputs(np.random.default_rng(28), 3000):
        expected = predict(*args)
        got = compiled.sensor_predict(*args)
        assert _bits(got) == _bits(expected), args
    assert src.PARTS[-1] is src.predict


# --- edge cases -------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("pull", [(0.0, 0.0, 0.0), (0.0, -G, 0.0), (0.0, 0.0, 0.5), (0.0, -G, 0.5)])
def test_a_disc_at_rest_never_changes_sides_unless_pulled_across(pull):
    ax, ay, drag = pull
    falls = ay != 0.0
    # A circle and a rectangle around (0, 0), the disc inside at the centre or outside beside them.
    if not (falls and drag != 0.0):
        t = circle_time(0.0, 0.0, 0.0, 0.0, ax, ay, drag, 0.0, 0.0, 1.0, True)
        assert (t < math.inf) == falls
        assert circle_time(3.0, 0.0, 0.0, 0.0, ax, ay, drag, 0.0, 0.0, 1.0, False) == math.inf
    t = rectangle_time(0.0, 0.0, 0.0, 0.0, ax, ay, drag, -1.0, -1.0, 1.0, 1.0, True)
    assert (t < math.inf) == falls
    assert rectangle_time(3.0, 0.0, 0.0, 0.0, ax, ay, drag, -1.0, -1.0, 1.0, 1.0, False) == math.inf
    # A vertical wire: gravity runs along it, never across.
    assert line_time(-1.0, 0.0, 0.0, 0.0, ax, ay, drag, 0.0, -1.0, 0.0, 1.0, True) == math.inf


def test_a_disc_on_a_circle_crosses_at_once_only_moving_or_pulled_inwards():
    # On the circle of radius 1 at (1, 0): outside (inside is strictly within).
    assert not Sensor.circle((0.0, 0.0), 1.0).contains([1.0, 0.0])[0]
    r = (0.0, 0.0, 1.0)
    assert circle_time(1.0, 0.0, -1.0, 0.0, *NO, *r, False) == 0.0  # inwards
    assert circle_time(1.0, 0.0, 1.0, 0.0, *NO, *r, False) == math.inf  # outwards
    assert circle_time(1.0, 0.0, 0.0, 1.0, *NO, *r, False) == math.inf  # along the tangent: outside from then on
    assert circle_time(1.0, 0.0, 0.0, 0.0, *NO, *r, False) == math.inf  # at rest
    assert circle_time(1.0, 0.0, 0.0, 1.0, -G, 0.0, 0.0, *r, False) == 0.0  # along the tangent, pulled in
    assert circle_time(1.0, 0.0, 0.0, 0.0, -G, 0.0, 0.0, *r, False) == 0.0  # at rest, pulled in
    assert circle_time(1.0, 0.0, 0.0, 1.0, G, 0.0, 0.0, *r, False) == math.inf  # along the tangent, pulled out
    assert circle_time(1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.5, *r, False) == 0.0  # inwards under drag


def test_a_disc_on_a_wire_crosses_at_once_only_moving_or_pulled_to_its_left():
    wire = (1.0, 0.0, -1.0, 0.0)  # from (1, 0) to (-1, 0): its left is below
    assert not Sensor.line(wire[:2], wire[2:]).contains([0.0, 0.0])[0]  # on it: not on its left
    assert line_time(0.0, 0.0, 0.0, -1.0, *NO, *wire, False) == 0.0  # moving down
    assert line_time(0.0, 0.0, 0.0, 1.0, *NO, *wire, False) == math.inf  # moving up
    assert line_time(0.0, 0.0, 1.0, 0.0, *NO, *wire, False) == math.inf  # along it
    assert line_time(0.0, 0.0, 0.0, 0.0, *NO, *wire, False) == math.inf  # at rest
    assert line_time(0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.5, *wire, False) == 0.0  # moving down under drag
    for drag in (0.0, 0.5):  # at rest or moving along it, falling: through it at once
        assert line_time(0.0, 0.0, 0.0, 0.0, 0.0, -G, drag, *wire, False) == 0.0
        assert line_time(0.0, 0.0, 1.0, 0.0, 0.0, -G, drag, *wire, False) == 0.0
        # Thrown up off it, falling: back through it when it comes back down (2 v / g without drag).
        t = line_time(0.0, 0.0, 0.0, 3.0, 0.0, -G, drag, *wire, False)
        assert t == pytest.approx(6.0 / G, rel=1e-15) if drag == 0.0 else 0.0 < t < 6.0 / G


def test_a_disc_on_a_rectangles_edge_enters_at_once_only_moving_or_pulled_inwards():
    box = (0.0, 0.0, 2.0, 1.0)
    assert not Sensor.rectangle(box[:2], box[2:]).contains([[0.0, 0.5], [1.0, 1.0], [2.0, 0.0]]).any()
    assert rectangle_time(0.0, 0.5, 1.0, 0.0, *NO, *box, False) == 0.0  # inwards through the left edge
    assert rectangle_time(2.0, 0.5, -1.0, 0.3, *NO, *box, False) == 0.0  # inwards through the right edge
    assert rectangle_time(0.0, 0.0, 1.0, 1.0, *NO, *box, False) == 0.0  # inwards through a corner
    assert rectangle_time(0.0, 0.5, -1.0, 0.0, *NO, *box, False) == math.inf  # outwards
    assert rectangle_time(1.0, 1.0, 0.3, 1.0, *NO, *box, False) == math.inf  # outwards through the top
    assert rectangle_time(0.0, 0.5, 0.0, 0.0, *NO, *box, False) == math.inf  # at rest
    assert rectangle_time(0.0, -1.0, 0.0, 1.0, *NO, *box, False) == math.inf  # up along the left edge's line
    assert rectangle_time(1.0, 1.0, 1.0, 0.0, *NO, *box, False) == math.inf  # along the top edge
    assert rectangle_time(0.0, 0.5, -1.0, 0.0, 0.0, 0.0, 0.5, *box, False) == math.inf  # outwards under drag
    assert rectangle_time(1.0, 1.0, 0.0, 0.0, 0.0, -G, 0.0, *box, False) == 0.0  # at rest on the top, falling
    assert rectangle_time(1.0, 1.0, 0.0, 0.0, 0.0, -G, 0.5, *box, False) == 0.0  # ... under drag too
    assert rectangle_time(1.0, 0.0, 0.0, 0.0, 0.0, -G, 0.0, *box, False) == math.inf  # on the bottom, falling away
    # Through a corner, touching it only: never in (it was: the other coordinate, leaving its slab, was on its edge).
    assert rectangle_time(-1.0, 0.0, 1.0, 1.0, *NO, *box, False) == math.inf  # the corner (0, 1)
    assert rectangle_time(3.0, 2.0, -1.0, -1.0, *NO, 0.0, 1.0, 2.0, 2.0, False) == math.inf  # (2, 1)
    assert rectangle_time(3.0, 0.0, -1.0, 1.0, *NO, 0.0, 1.0, 2.0, 2.0, False) == 1.0  # in through (2, 1)
    # Thrown up off the top: back in when it comes down, 2 v / g later.
    assert rectangle_time(1.0, 1.0, 0.0, 3.0, 0.0, -G, 0.0, *box, False) == pytest.approx(6.0 / G, rel=1e-15)


_shapes = [
    ("circle", Sensor.circle((0.0, 0.0), 1.0)),
    ("rectangle", Sensor.rectangle((-1.0, -1.0), (1.0, 1.0))),
    ("line", Sensor.line((1.0, -1.0), (1.0, 1.0))),  # its left: x < 1
]
_laws = [(0.0, 0.0, 0.0), (0.0, -G, 0.0), (0.0, 0.0, 0.5), (0.3, -G, 0.5), (-G, 0.0, 0.0)]


@pytest.mark.parametrize(("name", "sensor"), _shapes)
@pytest.mark.parametrize("law", _laws)
@pytest.mark.parametrize("off", [0.0, 1e-16, 1e-15, 1e-13])
def test_a_state_that_disagrees_with_the_geometry_by_roundoff_changes_sides_at_once(name, sensor, law, off):
    ax, ay, drag = law
    if name == "circle" and drag != 0.0 and ay != 0.0:
        return
    # At the right edge x = 1 (each shape has it at (1, 0)), a hair outside, moving out (and along y).
    x = math.nextafter(1.0, 2.0) if off == 0.0 else 1.0 + off
    assert not sensor.contains([x, 0.0])[0]
    t = _predict(sensor, (x, 0.0, 1.0, 0.2), ax, ay, drag, True)  # recorded inside
    assert t <= 1e-12
    # A hair inside, moving in, recorded outside: in at once.
    x = math.nextafter(1.0, 0.0) if off == 0.0 else 1.0 - off
    assert sensor.contains([x, 0.0])[0]
    t = _predict(sensor, (x, 0.0, -1.0, 0.2), ax, ay, drag, False)
    assert t <= 1e-12


@pytest.mark.parametrize(("name", "sensor"), _shapes)
@pytest.mark.parametrize("law", _laws)
def test_a_state_that_disagrees_by_roundoff_but_heads_back_keeps_its_side_until_the_real_crossing(name, sensor, law):
    ax, ay, drag = law
    if name == "circle" and drag != 0.0 and ay != 0.0:
        return
    # A hair outside the right edge x = 1, recorded inside, moving back in at 1: it crosses the far side
    # (x = -1; the wire at x = 1 is not crossed again) later, or never; never at once.
    state = (math.nextafter(1.0, 2.0), 0.0, -1.0, 0.0)
    t = _predict(sensor, state, ax, ay, drag, True)
    assert t > 0.1


def test_a_coordinate_at_rest_at_zero_pulled_down_crosses_at_once_not_zero_over_zero():
    # fall_to_zero's root 2 u / (s - v) was 0 / 0 there (ZeroDivisionError; nan compiled): a disc at rest on a wire,
    # pulled across it.
    assert src.fall_to_zero(0.0, 0.0, -G, 0.0) == 0.0
    assert src.fall_to_zero(-0.0, -0.0, -G, 0.0) == 0.0
    # So near 0 that 2 a u underflows to 0: still sqrt(2 u / -a).
    assert src.fall_to_zero(1e-310, 0.0, -1e-300, 0.0) == pytest.approx(math.sqrt(2e-10), rel=1e-9)
    assert src.fall_to_zero(4.0, 0.0, -2.0, 0.0) == 2.0


def test_a_rectangle_entered_through_an_edge_is_never_missed_when_the_entry_point_rounds_outside():
    # Up through the bottom edge y = y0 at (y0 - y) / vy. The centre there, y + vy t, rounds below y0 about half
    # the time; the search then stepped by less than an ulp of the entry time, got stuck, and answered inf (20% of
    # these entries were missed).
    rng = np.random.default_rng(3)
    for _ in range(2000):
        x, y, vy, y0 = rng.uniform(0.2, 1.8), rng.uniform(-5.0, 0.0), rng.uniform(0.1, 5.0), rng.uniform(0.5, 2.0)
        t = rectangle_time(x, y, 0.0, vy, *NO, 0.0, y0, 2.0, y0 + 3.0, False)
        assert t == pytest.approx((y0 - y) / vy, rel=1e-15, abs=1e-15)
        # ... and under gravity and drag, where the entry is a root found to adjacent floats.
        t = rectangle_time(x, y, 0.0, vy + 20.0, 0.0, -G, 0.3, 0.0, y0, 2.0, y0 + 3.0, False)
        yt = dynamics.advance(x, y, 0.0, vy + 20.0, t, 0.0, -G, 0.3)[1]
        assert t < math.inf and yt == pytest.approx(y0, abs=1e-13)


@pytest.mark.parametrize("g", [1e-200, 1e-120, 1e120, 1e200])
def test_a_circle_is_left_under_a_tiny_or_a_huge_gravity(g):
    # |a|^2 underflowed (ZeroDivisionError) or overflowed (inf: never) in accelerated_leave; it now takes the
    # acceleration in a time unit where it is about 1, as accelerated_time_of_impact does.
    t = circle_time(0.0, 0.0, 1.0, 0.0, 0.0, -g, 0.0, 0.0, 0.0, 1.0, True)  # at speed 1 from the centre
    expected = 1.0 if g < 1.0 else math.sqrt(2.0 / g)  # free flight's 1; a fall through 1 at once
    assert t == pytest.approx(expected, rel=1e-12)
    t = circle_time(0.0, 0.0, 0.0, 0.0, 0.0, -g, 0.0, 0.0, 0.0, 1.0, True)  # dropped at the centre
    assert t == pytest.approx(math.sqrt(2.0 / g), rel=1e-12)


def test_a_wire_left_at_a_speed_of_1e_200_under_gravity_and_drag_comes_back_at_once():
    # On the wire y = 0 (its left above), moving down at 1e-200, pulled up under drag: the path turns at once and
    # comes back through the wire. damped_exit's _rising_root starts at the turn, where the rise left and the speed
    # are both 0 (v tau underflows): tau = 2 rise / (u + sqrt(u^2 + 2 a rise)) is 0 / 0. A floor's exit_y does the
    # same for a disc on it moving up at 1e-200 (compiled: a time; Python: ZeroDivisionError).
    t = line_time(0.0, 0.0, 0.0, -1e-200, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, False)
    assert 0.0 <= t < 1e-100


def test_a_wire_under_a_subnormal_acceleration_across_it_and_drag_is_never_crossed_back():
    # A wire at a slant of 3e-213 under a sideways gravity of 1.5e-98: 5e-311 across it. damped_exit's turn,
    # log1p(-gamma v / a), is log1p(inf); the position there is nan and _rising_root takes the square root of a
    # negative number (compiled: inf, never).
    # (damped._rising_root now answers at once for a coordinate already on its line: the turn's nan goes no further)
    t = line_time(0.0, 0.0, 0.0, -1.0, -1.4622246823854183e-98, 0.0, 1.0, 0.0, 0.0, 1.0, 3.4414524385645964e-213, False)
    assert t == math.inf
