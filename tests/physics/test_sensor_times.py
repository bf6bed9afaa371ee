"""The time a disc's centre next changes sides of a sensor (discsim.physics.sources.sensors): its edge cases.

A centre on an edge is outside (:meth:`discsim.sensors.Sensor.contains`: inside is strict).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from discsim.physics import dynamics
from discsim.physics.sources import sensors as src
from discsim.physics.sources.sensors import circle_time, line_time, predict, rectangle_time
from discsim.sensors import Sensor

G = 9.81
NO = (0.0, 0.0, 0.0)  # no acceleration, no drag


def _predict(sensor: Sensor, state, ax, ay, drag, inside) -> float:
    return predict(*state, ax, ay, drag, sensor.code, *sensor.params.tolist(), inside)


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
