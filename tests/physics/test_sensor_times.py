"""The time a disc's centre next changes sides of a sensor (discsim.physics.sources.sensors): its edge cases.

A centre on an edge is outside (:meth:`discsim.sensors.Sensor.contains`: inside is strict).
"""

from __future__ import annotations

import math

import pytest

from discsim.physics.sources import sensors as src
from discsim.physics.sources.sensors import line_time
from discsim.sensors import Sensor

G = 9.81
NO = (0.0, 0.0, 0.0)  # no acceleration, no drag


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


def test_a_coordinate_at_rest_at_zero_pulled_down_crosses_at_once_not_zero_over_zero():
    # fall_to_zero's root 2 u / (s - v) was 0 / 0 there (ZeroDivisionError; nan compiled): a disc at rest on a wire,
    # pulled across it.
    assert src.fall_to_zero(0.0, 0.0, -G, 0.0) == 0.0
    assert src.fall_to_zero(-0.0, -0.0, -G, 0.0) == 0.0
    # So near 0 that 2 a u underflows to 0: still sqrt(2 u / -a).
    assert src.fall_to_zero(1e-310, 0.0, -1e-300, 0.0) == pytest.approx(math.sqrt(2e-10), rel=1e-9)
    assert src.fall_to_zero(4.0, 0.0, -2.0, 0.0) == 2.0
