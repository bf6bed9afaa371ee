"""Contact data from the log (issue 19, part 2): hand-computed head-on, oblique and wall contacts."""

from __future__ import annotations

import math

import numpy as np
import pytest

import discsim as ds


def test_head_on_unequal_masses(every_backend):
    # m1 = 1 at speed 2 hits m2 = 3 at rest: mu = 3/4, J = 2 mu 2 = 3; contact at x = 5 at t = 1 (gap 2).
    discs = ds.Discs([[2.0, 5.0], [6.0, 5.0]], [[2.0, 0.0], [0.0, 0.0]], radii=1.0, masses=[1.0, 3.0])
    sim = ds.EventDriven(discs, ds.Box(20.0, 10.0)).run(until=1.5)
    c = ds.contacts(sim)
    assert len(c) == 1 and c.kind[0] == "collision" and (c.i[0], c.j[0]) == (0, 1)
    assert c.time[0] == 1.0
    np.testing.assert_allclose(c.point[0], [5.0, 5.0])
    np.testing.assert_allclose(c.normal[0], [1.0, 0.0])
    assert c.impulse[0] == pytest.approx(3.0) and c.speed[0] == pytest.approx(2.0)
    np.testing.assert_allclose(sim.velocities, [[-1.0, 0.0], [1.0, 0.0]])


def test_oblique_equal_masses():
    # disc 1 at rest, disc 0 moving +x, offset in y by 1 (radii 1): contact where the centres are 2 apart,
    # normal (sqrt(3)/2, 1/2), speed sqrt(3)/2, J = 2 (1/2) speed; afterwards the 90-degree rule.
    discs = ds.Discs([[2.0, 5.0], [8.0, 6.0]], [[1.0, 0.0], [0.0, 0.0]], radii=1.0)
    sim = ds.EventDriven(discs, ds.Box(20.0, 10.0)).run(until=5.0)
    c = ds.contacts(sim)
    n = np.array([math.sqrt(3) / 2, 0.5])
    assert c.time[0] == pytest.approx(6.0 - math.sqrt(3))
    np.testing.assert_allclose(c.normal[0], n)
    np.testing.assert_allclose(c.point[0], [8.0, 6.0] - n)
    assert c.speed[0] == pytest.approx(math.sqrt(3) / 2)
    assert c.impulse[0] == pytest.approx(math.sqrt(3) / 2)
    v = sim.velocities
    assert float(v[0] @ v[1]) == pytest.approx(0.0, abs=1e-12)


def test_walls_segments_and_changes_in_between(every_backend):
    seg = ds.Segment([6.0, 0.0], [6.0, 10.0])
    discs = ds.Discs([[2.0, 5.0]], [[-1.0, 0.0]], radii=0.5, masses=2.0)
    sim = ds.EventDriven(discs, ds.Box(10.0, 10.0), segments=[seg]).run(until=2.0)  # left wall at t = 1.5
    sim.set_velocities([0], [[0.0, 3.0]])  # then up: the top wall at y = 9.5
    sim.run(until=4.0)
    sim.set_velocities([0], [[2.0, 0.0]])  # then right from x = 1: the segment at x = 5.5 at t = 6.25
    sim.run(until=7.0)
    c = ds.contacts(sim)
    assert c.kind.tolist() == ["wall", "wall", "segment"]
    assert c.surface.tolist() == [-1, -4, 0]
    np.testing.assert_allclose(c.normal, [[-1.0, 0.0], [0.0, 1.0], [1.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(c.speed, [1.0, 3.0, 2.0])
    np.testing.assert_allclose(c.impulse, [4.0, 12.0, 8.0])  # 2 m v
    np.testing.assert_allclose(c.point[0], [0.0, 5.0])


def test_from_a_log_with_its_discs_and_fixed_step(every_backend):
    discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
    box = ds.Box(10.0, 10.0)
    pic = ds.EventDriven(discs, box).run(until=2.5)
    c = ds.contacts(pic.events, discs, box)
    assert c.impulse.tolist() == [2.0] and c.speed.tolist() == [2.0]
    pit = ds.FixedStep(discs, box, dt=0.5).run(until=2.5)
    c = ds.contacts(pit)
    assert c.kind[0] == "collision" and c.impulse[0] == pytest.approx(2.0) and c.speed[0] == pytest.approx(2.0)
    with pytest.raises(ds.DiscsimError, match="discs"):
        ds.contacts(pic.events)
