"""Sensors in the event-driven engine, attacked (issue 28 review): edits in callbacks at the moment of a crossing,
trip wires on a periodic box's edge. Every test runs on both backends (the directory's conftest)."""

import numpy as np
import pytest

import discsim as ds
from discsim.events import ENTER, SENSED

Sensor = ds.Sensor


def crossings(sim):
    """``[(time, "enter" | "leave", disc, sensor), ...]`` from the log."""
    ev = sim.events
    ev = ev[np.isin(ev["kind"], SENSED)]
    return [(float(e["time"]), "enter" if e["kind"] == ENTER else "leave", int(e["i"]), int(e["j"])) for e in ev]


def test_a_disc_put_back_where_it_is_as_it_enters_a_rectangle_enters_once():
    # The disc enters [4, 6] x [4, 6] at t = 3 with its centre exactly on the edge x = 4. A callback that sets its
    # position to where it is must not make it outside again (it entered again at once, with no leave between).
    sim = ds.EventDriven(ds.Discs([[1.0, 5.3]], [[1.0, 0.0]], radii=0.2), ds.Box(10.0, 10.0),
                         sensors=[Sensor.rectangle((4.0, 4.0), (6.0, 6.0))])  # fmt: skip
    calls = []

    def put_back(sim, crossing):
        calls.append(crossing.time)
        if len(calls) == 1:
            sim.set_positions([crossing.i], sim.positions[[crossing.i]])

    sim.on("enter", put_back)
    sim.run(until=6.0)
    assert [(k, t) for t, k, *_ in crossings(sim)] == [("enter", 3.0), ("leave", 5.0)]
    assert calls == [3.0]


@pytest.mark.parametrize("x", [0.0, 10.0])  # the same wire: the box's left edge is its right edge
def test_a_trip_wire_along_a_periodic_box_edge_reports_every_wrap_across_it(x):
    # From x = 3 at speed 1 in a periodic box of width 10: +x wraps at t = 7 and 17, -x at t = 3, 13 and 23.
    found = []
    for vx in (1.0, -1.0):
        sim = ds.EventDriven(ds.Discs([[3.0, 2.0]], [[vx, 0.0]], radii=0.2), ds.Box(10.0, 10.0, periodic=True),
                             sensors=[Sensor.line((x, 0.0), (x, 10.0))])  # fmt: skip
        sim.run(until=25.0)
        found.append(len(crossings(sim)))
    assert found == [2, 3]


def wraps(start, speed, length, until):
    """The times a centre from ``start`` at ``speed`` (not 0) along one axis of a periodic box of ``length`` reaches
    its edge (where it wraps), up to ``until``."""
    first = (length - start) / speed if speed > 0.0 else start / -speed
    return [first + k * length / abs(speed) for k in range(int((until - first) * abs(speed) / length) + 1)]


@pytest.mark.parametrize(
    ("p0", "p1", "axis"),
    [
        ((0.0, 0.0), (0.0, 10.0), 0),
        ((10.0, 0.0), (10.0, 10.0), 0),
        ((10.0, 10.0), (10.0, 0.0), 0),  # the other way round: entering and leaving swap
        ((0.0, 0.0), (10.0, 0.0), 1),
        ((0.0, 10.0), (10.0, 10.0), 1),
    ],
)
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_every_wrap_across_a_trip_wire_on_a_periodic_edge_is_reported_once_at_its_time(p0, p1, axis, sign):
    # Speeds and starts that are no round numbers: the wire's time and the wrap's differ by roundoff, yet each wrap
    # is one crossing, entering when the centre moves to the wire's left (cross(p1 - p0, v) > 0), else leaving.
    velocity = [0.0, 0.0]
    velocity[axis], velocity[1 - axis] = sign * 0.7310, 0.0917
    start = [3.3, 6.1] if axis == 0 else [6.1, 3.3]
    sim = ds.EventDriven(ds.Discs([start], [velocity], radii=0.2), ds.Box(10.0, 10.0, periodic=True),
                         sensors=[Sensor.line(p0, p1)])  # fmt: skip
    sim.run(until=60.0)
    found = crossings(sim)
    turning = (p1[0] - p0[0]) * velocity[1] - (p1[1] - p0[1]) * velocity[0]
    expected = wraps(start[axis], velocity[axis], 10.0, 60.0)
    assert len(expected) >= 4
    assert [k for _, k, *_ in found] == ["enter" if turning > 0.0 else "leave"] * len(expected)
    assert [t for t, *_ in found] == pytest.approx(expected, rel=1e-12)
    assert {(i, j) for _, _, i, j in found} == {(0, 0)}


@pytest.mark.parametrize("laws", [{"gravity": (0.0, -0.1)}, {"drag": 0.05}])
def test_a_trip_wire_on_a_periodic_edge_under_gravity_or_drag_is_crossed_at_each_wrap(laws):
    # Gravity along y leaves x's flight straight: wraps at (10 - 3.3) / 1.7 + 10 k / 1.7. Drag slows it: the k-th
    # wrap is where x has gone 6.7 + 10 k, x(t) = 3.3 + 1.7 (1 - exp(-0.05 t)) / 0.05. The wires on x = 0 and x = 10
    # are one: the same log.
    logs = []
    for x in (0.0, 10.0):
        sim = ds.EventDriven(ds.Discs([[3.3, 8.0]], [[1.7, 0.3]], radii=0.2), ds.Box(10.0, 10.0, periodic=True),
                             sensors=[Sensor.line((x, 0.0), (x, 10.0))], **laws)  # fmt: skip
        sim.run(until=20.0)
        logs.append(crossings(sim))
    assert logs[0] == logs[1]
    if "drag" in laws:
        expected = [-np.log(1.0 - 0.05 * d / 1.7) / 0.05 for d in (6.7, 16.7)]
    else:
        expected = [(6.7 + 10.0 * k) / 1.7 for k in range(3)]
    assert [t for t, *_ in logs[0]] == pytest.approx(expected, rel=1e-12)
    assert [k for _, k, *_ in logs[0]] == ["leave"] * len(expected)


@pytest.mark.parametrize("vx", [0.7310, -0.7310])
def test_a_trip_wire_along_part_of_a_periodic_edge_reports_the_wraps_across_that_part_only(vx):
    # The wire (0, 2) to (0, 5) covers part of the left edge (the right edge too); the disc climbs 0.9 a lap, so it
    # wraps at y = 2.1, 3.0, 3.9, 4.8 over the wire and at 0.3, 1.2, 5.7, 6.6, ... beside it.
    lap = 10.0 / abs(vx)
    start_y = 0.3 - 0.9 * ((10.0 - 3.3) / vx if vx > 0 else 3.3 / -vx) / lap
    sim = ds.EventDriven(ds.Discs([[3.3, start_y % 10.0]], [[vx, 0.9 / lap]], radii=0.2),
                         ds.Box(10.0, 10.0, periodic=True), sensors=[Sensor.line((0.0, 2.0), (0.0, 5.0))])  # fmt: skip
    sim.run(until=9.5 * lap)
    found = crossings(sim)
    times = wraps(3.3, vx, 10.0, 9.5 * lap)
    assert [t for t, *_ in found] == pytest.approx([times[k] for k in (2, 3, 4, 5)], rel=1e-12)
    assert [k for _, k, *_ in found] == ["leave" if vx > 0 else "enter"] * 4
    ev = sim.events
    assert ev[np.isin(ev["kind"], SENSED)]["yi"] == pytest.approx([2.1, 3.0, 3.9, 4.8], rel=1e-12)


@pytest.mark.parametrize("vx", [0.7310, -0.7310])
def test_a_disc_starting_on_a_periodic_edge_under_a_trip_wire_is_reported_at_each_wrap(vx):
    # The wire points down the left edge: its left is the box's inside. A centre on the edge itself is on the line
    # (outside by Sensor.contains), but its side of a wire on the edge is the inside's: the wire is crossed only by
    # the jumps, each one entering (+x: from the right of the image at x = 10) or leaving (-x), none at the start.
    sim = ds.EventDriven(ds.Discs([[0.0, 5.0]], [[vx, 0.0]], radii=0.2), ds.Box(10.0, 10.0, periodic=True),
                         sensors=[Sensor.line((0.0, 10.0), (0.0, 0.0))])  # fmt: skip
    sim.run(until=30.0)
    found = crossings(sim)
    expected = [10.0 / 0.731, 20.0 / 0.731] if vx > 0 else [0.0, 10.0 / 0.731, 20.0 / 0.731]
    assert [t for t, *_ in found] == pytest.approx(expected, rel=1e-12, abs=1e-300)
    assert [k for _, k, *_ in found] == ["enter" if vx > 0 else "leave"] * len(expected)


def test_two_trip_wires_on_one_periodic_edge_are_two_events_of_one_wrap_in_the_sensors_order():
    # x = 0 pointing up (left: -x) and x = 10 pointing down (left: +x) are one line: each wrap +x leaves the first
    # and enters the second, two events at one time; a callback after each sees them one by one, and a pocket that
    # removes the disc at the first leaves nothing for the second.
    wires = [Sensor.line((0.0, 0.0), (0.0, 10.0)), Sensor.line((10.0, 10.0), (10.0, 0.0))]
    calls = []
    sim = ds.EventDriven(ds.Discs([[3.3, 5.0]], [[0.731, 0.0]], radii=0.2), ds.Box(10.0, 10.0, periodic=True),
                         sensors=wires)  # fmt: skip
    sim.on("enter", lambda sim, c: calls.append((c.time, "enter", c.sensor)))
    sim.on("leave", lambda sim, c: calls.append((c.time, "leave", c.sensor)))
    sim.run(until=25.0)
    first, second = 6.7 / 0.731, 16.7 / 0.731
    expected = [(first, "leave", 0), (first, "enter", 1), (second, "leave", 0), (second, "enter", 1)]
    assert [(k, j) for _, k, _, j in crossings(sim)] == [(k, j) for _, k, j in expected]
    assert [(k, j) for _, k, j in calls] == [(k, j) for _, k, j in expected]
    assert [t for t, *_ in calls] == pytest.approx([t for t, *_ in expected], rel=1e-12)
    assert sim.counts["sensor_events"] == 4
    pocket = ds.EventDriven(ds.Discs([[3.3, 5.0], [3.3, 2.0]], [[0.731, 0.0], [0.0, 0.0]], radii=0.2),
                            ds.Box(10.0, 10.0, periodic=True), sensors=wires)  # fmt: skip
    pocket.on("leave", lambda sim, c: sim.remove_discs([c.i]))
    pocket.run(until=25.0)
    assert [(k, i, j) for _, k, i, j in crossings(pocket)] == [("leave", 0, 0)]
    assert len(pocket.discs) == 1


@pytest.mark.parametrize(
    ("lower_left", "upper_right"),
    [((0.0, 4.0), (3.1, 6.0)), ((6.9, 4.0), (10.0, 6.0)), ((4.0, 0.0), (6.0, 3.1)), ((4.0, 6.9), (6.0, 10.0))],
)
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_rectangle_on_a_periodic_edge_is_left_and_entered_once_at_each_wrap(lower_left, upper_right, sign):
    # The rectangle touches one edge: crossing that edge is leaving it (or entering it, from the other side),
    # whichever of the sensor's time and the wrap's comes first by roundoff.
    axis = 0 if lower_left[1] == 4.0 else 1
    velocity = [0.0, 0.0]
    velocity[axis] = sign * 0.7310
    start = [5.0, 5.0]
    start[axis] = 3.3
    sim = ds.EventDriven(ds.Discs([start], [velocity], radii=0.2), ds.Box(10.0, 10.0, periodic=True),
                         sensors=[Sensor.rectangle(lower_left, upper_right)])  # fmt: skip
    sim.run(until=60.0)
    found = crossings(sim)
    lo, hi = lower_left[axis], upper_right[axis]
    x, v, t, expected = start[axis], velocity[axis], 0.0, []
    while True:  # the centre's walk along the axis: the region's edges and the box's, in order
        edges = [e for e in (lo, hi, 0.0, 10.0) if (e - x) * v > 0.0]
        e = min(edges, key=lambda e: (e - x) / v)
        t += (e - x) / v
        if t > 60.0:
            break
        if e in (0.0, 10.0):  # the region's edge on the box's edge (0 and 10 are one line): leaving it, or
            # entering it from the other side
            expected.append((t, "leave" if (e == 0.0) == (lo == 0.0) else "enter"))
        else:
            expected.append((t, "enter" if (e == lo) == (v > 0) else "leave"))
        x = e if e not in (0.0, 10.0) else 10.0 - e
    assert [k for _, k, *_ in found] == [k for _, k in expected]
    assert [t for t, *_ in found] == pytest.approx([t for t, _ in expected], rel=1e-12)


def test_a_disc_leaving_a_region_on_a_periodic_box_edge_is_reported_leaving():
    # [0, 3] x [4, 6] touches the periodic box's edge x = 0: a disc going -x leaves it there (t = 2, 12, 22), as
    # the wrap takes it to x = 10, and enters it again at x = 3 (t = 9, 19). The wrap took its side afresh without
    # an event: the leaves were lost, the log said enter, enter.
    sim = ds.EventDriven(ds.Discs([[2.0, 5.0]], [[-1.0, 0.0]], radii=0.2), ds.Box(10.0, 10.0, periodic=True),
                         sensors=[Sensor.rectangle((0.0, 4.0), (3.0, 6.0))])  # fmt: skip
    sim.run(until=25.0)
    found = crossings(sim)
    assert [k for _, k, *_ in found] == ["leave", "enter", "leave", "enter", "leave"]
    assert [t for t, *_ in found] == pytest.approx([2.0, 9.0, 12.0, 19.0, 22.0], rel=1e-14)


def test_crossings_of_two_sensors_at_one_instant_come_in_the_sensors_order():
    sensors = [Sensor.circle((5.0, 5.0), 1.0), Sensor.circle((5.0, 5.0), 1.0)]
    sim = ds.EventDriven(ds.Discs([[1.0, 5.3]], [[1.0, 0.0]], radii=0.2), ds.Box(10.0, 10.0), sensors=sensors)
    sim.run(until=6.0)
    assert [(k, j) for _, k, _, j in crossings(sim)] == [("enter", 0), ("enter", 1), ("leave", 0), ("leave", 1)]


def test_a_trip_wire_reaching_beyond_a_periodic_box_is_refused_naming_it():
    # Its part beyond the edge x = 0 would never be crossed (the discs wrap to x = 10): it was accepted, and the
    # wrapped part never reported (found by the issue 28 trip-wire fix).
    discs = ds.Discs([[5.0, 2.0]], [[1.0, 0.0]], radii=0.2)
    with pytest.raises(
        ds.DiscsimError, match=r"sensors\[1\] .* must lie inside the periodic box 10 x 10 \(a trip wire"
    ):
        wires = [Sensor.line((3.0, 0.0), (3.0, 10.0)), Sensor.line((-2.0, 5.0), (3.0, 5.0))]
        ds.EventDriven(discs, ds.Box(10.0, 10.0, periodic=True), sensors=wires)
