"""The study's detectors for two moving, spinning polygons (discsim.analysis.polygon_detection): PIT, bisection and
swept volumes against the brute-force contact time, on closed forms and random pairs."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from discsim.analysis.polygon_detection import (
    bisect_contact,
    pit_contact,
    reference_contact,
    swept_contact,
    swept_region,
)
from discsim.polygons import Polygons, overlap_depth, regular_polygon

SQUARE = regular_polygon(4, math.sqrt(2.0), angle=math.pi / 4)  # [-1, 1]^2


def head_on():
    # Faces 3 apart, closing at 2: they touch at t = 1.5.
    return Polygons(SQUARE, [[0.0, 0.0], [5.0, 0.0]], velocities=[[1.0, 0.0], [-1.0, 0.0]])


def test_head_on_squares_each_detector_against_the_closed_form():
    pair = head_on()
    assert reference_contact(pair, 0, 1, 4.0, samples=1000).time == pytest.approx(1.5, abs=1e-11)
    pit = pit_contact(pair, 0, 1, 0.4, 4.0)
    assert pit.time == pytest.approx(1.6) and pit.depth == pytest.approx(0.2) and pit.tests == 4  # 0.1 each
    assert bisect_contact(pair, 0, 1, 0.4, 4.0, tol=1e-10).time == pytest.approx(1.5, abs=1e-10)
    swept = swept_contact(pair, 0, 1, 0.4, 4.0)
    assert swept.time == pytest.approx(1.6)  # the frame [1.2, 1.6] that holds the contact, none before


def bar_and_box():
    """A 1.0 x 0.02 bar spinning at 6 rad per unit time about its centre, and a 0.1 square 0.4 from it, whose
    near corner the bar's edge meets once (at 0.6 / 6 = 0.1 or so) and leaves again at once."""
    bar = np.array([[-0.5, -0.01], [0.5, -0.01], [0.5, 0.01], [-0.5, 0.01]])
    box = regular_polygon(4, 0.05 * math.sqrt(2.0), angle=math.pi / 4)
    phi = 0.6
    return Polygons([bar, box], [[0.0, 0.0], [0.45 * math.cos(phi), 0.45 * math.sin(phi)]], spins=[6.0, 0.0])


def test_a_spinning_bar_steps_past_a_box_under_pit_and_swept_volumes_catch_it():
    pair = bar_and_box()
    truth = reference_contact(pair, 0, 1, 0.5, samples=200_000).time
    assert 0.0 < truth < 0.1
    assert pit_contact(pair, 0, 1, 0.25, 0.5).time == math.inf  # at 0.25 the bar is 0.9 rad past the box's far corner
    assert bisect_contact(pair, 0, 1, 0.25, 0.5).time == math.inf  # bisection cannot refine what PIT never saw
    swept = swept_contact(pair, 0, 1, 0.25, 0.5)
    assert swept.time == 0.25  # the first frame holds it
    fine = bisect_contact(pair, 0, 1, 0.001, 0.5, tol=1e-12)  # a frame short enough to land inside the contact
    assert fine.time == pytest.approx(truth, abs=1e-9)


def test_the_swept_region_holds_every_sampled_pose_of_a_fast_spinner():
    # A hexagon turning 2.5 rad over the frame (below a half turn: the pushed-out hull) and 4 rad (beyond: circles).
    for spin in (2.5, 4.0):
        body = Polygons(regular_polygon(6, 1.0), [[0.0, 0.0]], velocities=[[0.7, -0.3]], spins=[spin])
        region = swept_region(body, 0, 0.0, 1.0)
        edges = np.roll(region, -1, axis=0) - region
        for t in np.linspace(0.0, 1.0, 101):
            v = body.world_vertices(0, t)
            rel = v[:, None, :] - region[None, :, :]
            inside = edges[None, :, 0] * rel[..., 1] - edges[None, :, 1] * rel[..., 0] >= -1e-12
            assert inside.all(), (spin, t)


@settings(max_examples=10, deadline=None)
@given(
    n=st.integers(3, 6), m=st.integers(3, 6), spin=st.floats(-4.0, 4.0), other=st.floats(-4.0, 4.0),
    gap=st.floats(0.1, 1.5), dt=st.floats(0.05, 0.5), slide=st.floats(-0.8, 0.8),
)  # fmt: skip
def test_swept_volumes_never_miss_and_pit_never_comes_early(n, m, spin, other, gap, dt, slide):
    pair = Polygons(
        [regular_polygon(n, 1.0), regular_polygon(m, 0.8)],
        [[0.0, 0.0], [1.8 + gap, slide]],
        velocities=[[0.6, 0.0], [-0.6, 0.0]],
        spins=[spin, other],
    )
    horizon = 3.0
    truth = reference_contact(pair, 0, 1, horizon, samples=1500).time
    pit = pit_contact(pair, 0, 1, dt, horizon)
    swept = swept_contact(pair, 0, 1, dt, horizon)
    bisect = bisect_contact(pair, 0, 1, dt, horizon, tol=1e-10)
    if math.isfinite(pit.time):
        assert pit.time >= truth - 1e-9 and pit.depth > 0.0
        assert truth - 1e-9 <= bisect.time <= pit.time
    first = min(truth, pit.time)  # (a real contact either saw)
    if math.isfinite(first):
        assert swept.time <= math.ceil(first / dt - 1e-9) * dt + 1e-9  # flagged by the frame that holds it
    assert overlap_depth(pair.world_vertices(0), pair.world_vertices(1)) < 0.0  # (apart at the start)
