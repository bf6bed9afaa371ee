"""Extreme units (issue 18, part 3): inside the supported range a run is the same in any units; outside it
the input is refused up front with UnitsError (before, discs passed through each other unseen).

The range (``discsim.model``): lengths (radii, box sides) in [1e-50, 1e50], coordinates at most 1e50, speeds
0 or in [1e-50, 1e50], finite masses in [1e-100, 1e100], smallest radius at least 1e-10 of the box's longer side.
"""

from __future__ import annotations

import numpy as np
import pytest

import discsim as ds
from discsim.model import LENGTH_RANGE, MASS_RANGE, RESOLUTION, SPEED_RANGE

GAS = ds.random_gas(200, 0.3, periodic=True, seed=3)
UNTIL = 5.0


def _scaled(length: float, speed: float, mass: float = 1.0, periodic: bool = True):
    discs, box = GAS
    scaled = ds.Discs(discs.positions * length, discs.velocities * speed, discs.radii * length, mass)
    return scaled, ds.Box(box.width * length, box.height * length, periodic=periodic)


def _collisions(length: float, speed: float, mass: float = 1.0) -> int:
    sim = ds.EventDriven(*_scaled(length, speed, mass), record=False).run(until=UNTIL * length / speed)
    return sim.counts["collisions"]


def _extremes():
    """Scale factors that put the largest (or smallest) length and speed of the gas right at the bounds."""
    discs, box = GAS
    speeds = np.hypot(*discs.velocities.T)
    big_l = LENGTH_RANGE[1] / max(box.width, box.height)
    small_l = LENGTH_RANGE[0] / discs.radii.min()
    big_v = SPEED_RANGE[1] / speeds.max()
    small_v = SPEED_RANGE[0] / speeds[speeds > 0].min()
    return big_l, small_l, big_v, small_v


BIG_L, SMALL_L, BIG_V, SMALL_V = _extremes()


@pytest.mark.parametrize(
    ("length", "speed"),
    [(BIG_L, BIG_V), (SMALL_L, SMALL_V), (BIG_L, SMALL_V), (SMALL_L, BIG_V), (1.0, BIG_V), (BIG_L, 1.0)],
)
def test_at_the_bounds_the_run_is_the_same_as_in_ordinary_units(length, speed):
    assert _collisions(length, speed) == _collisions(1.0, 1.0) > 100


@pytest.mark.parametrize("mass", [MASS_RANGE[0], MASS_RANGE[1]])
def test_masses_at_the_bounds(mass):
    assert _collisions(BIG_L, BIG_V, mass) == _collisions(1.0, 1.0) > 100


@pytest.mark.parametrize(
    ("length", "speed", "match"),
    [
        (1e80, 1e80, "radius"),  # issue 18: 0 collisions where the unscaled run has hundreds
        (1e160, 1e160, "radius"),
        (1e-200, 1e-200, "radius"),
        (1.0, 1e200, "speed"),
        (BIG_L * 1.01, 1.0, "coordinate|radius|box"),
        (SMALL_L / 1.01, 1.0, "radius"),
        (1.0, BIG_V * 1.01, "speed"),
        (1.0, SMALL_V / 1.01, "speed"),
    ],
)
def test_outside_the_range_is_refused_up_front(length, speed, match):
    with pytest.raises(ds.UnitsError, match=match) as caught:
        ds.EventDriven(*_scaled(length, speed))
    assert isinstance(caught.value, ds.DiscsimError)
    assert "express it in other units" in str(caught.value)


def test_positions_alone_scaled_down_are_refused_not_a_zero_division():
    discs, box = GAS
    with pytest.raises(ds.DiscsimError):
        ds.EventDriven(ds.Discs(discs.positions * 1e-200, discs.velocities, discs.radii), box)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"radii": 1e51}, r"disc 0 has radius 1e\+51"),
        ({"radii": [0.5, 1e-60]}, r"disc 1 has radius 1e-60"),
        ({"velocities": [[0, 0], [1e-60, 0]]}, r"disc 1 has speed 1e-60"),
        ({"velocities": [[2e50, 0], [0, 0]]}, r"disc 0 has speed 2e\+50"),
        ({"masses": [1.0, 1e101]}, r"disc 1 has mass 1e\+101"),
        ({"masses": [1e-101, 1.0]}, r"disc 0 has mass 1e-101"),
        ({"positions": [[2e50, 0], [0, 0]]}, r"disc 0 has coordinate 2e\+50"),
    ],
)
def test_each_quantity_is_checked_by_name(kwargs, match):
    args = {"positions": [[1.0, 1.0], [3.0, 1.0]], "velocities": [[1.0, 0.0], [0.0, 0.0]], "radii": 0.5, **kwargs}
    with pytest.raises(ds.UnitsError, match=match):
        ds.Discs(**args)


def test_zero_speeds_tiny_coordinates_and_obstacles_are_fine():
    discs = ds.Discs([[1e-300, 1.0], [3.0, 1.0]], [[0.0, 0.0], [1e-50, 0.0]], 0.5, masses=[np.inf, 1.0])
    ds.EventDriven(discs, ds.Box(10.0, 10.0, periodic=True))


@pytest.mark.parametrize(("w", "h"), [(1e51, 1.0), (1.0, 1e-51)])
def test_box_sides_outside_the_range(w, h):
    with pytest.raises(ds.UnitsError, match="box (width|height)"):
        ds.Box(w, h)


def test_radii_too_small_for_the_box_are_refused():
    """Far from the origin a coordinate resolves 2.2e-16 of it: radius 1 in a box 1e17 wide missed its contacts."""
    for engine in (ds.EventDriven, ds.FixedStep):
        width = 1.01 / RESOLUTION
        discs = ds.Discs([[width / 2, 5.0], [width / 2 + 10, 5.0]], [[1.0, 0.3], [-1.0, 0.0]], 1.0)
        with pytest.raises(ds.UnitsError, match=r"disc 0 has radius 1\.0, below 1e-10 of the box's longer side"):
            engine(discs, ds.Box(width, 10.0))
    ds.EventDriven(discs, ds.Box(0.99 / RESOLUTION, 10.0))
