"""FixedStep reports sensors at its frames (issue 28, item 3): what changed between two frames, every policy,
both backends (the fixture in conftest.py).

The crossing frames are worked out by hand: a disc's centre flies straight at constant velocity, so it crosses a
sensor's edge at a time found from a line or a quadratic, and FixedStep reports it at the first frame after.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import discsim as ds
from discsim.engines.fixed_step import POLICIES
from discsim.engines.fixed_step.state import FixedStepState
from discsim.errors import DiscsimError, InvalidArgumentError
from discsim.events import ENTER, LEAVE, SENSED, Event
from discsim.sensors import Sensor

DT = 0.25  # frame times k / 4 are exact


def first_frame_after(t: float) -> float:
    """The time of the first frame (of ``DT``) strictly after ``t`` (``t`` is never a frame time here)."""
    return math.ceil(t / DT) * DT


def sensed(sim) -> np.ndarray:
    events = sim.events
    return events[np.isin(events["kind"], SENSED)]


def rows(sim) -> list[tuple]:
    """``(time, kind, disc, sensor)`` of each sensor record."""
    return [(float(r["time"]), int(r["kind"]), int(r["i"]), int(r["j"])) for r in sensed(sim)]


def lone(x, y, vx, vy, radius=0.1):
    return ds.Discs([[x, y]], [[vx, vy]], radius)


# --- crossing frames worked out by hand ---------------------------------------------------------------------------


@pytest.mark.parametrize("policy", POLICIES)
def test_a_disc_crosses_a_circle_along_a_chord(policy):
    # The centre (1, 5.3) + (1, 0) t is inside |p - (5, 5)| < 1 while |x - 5| < sqrt(1 - 0.3^2).
    half = math.sqrt(1.0 - 0.3**2)
    enter, leave = 4.0 - half, 4.0 + half  # 3.0461, 4.9539
    circle = Sensor.circle((5.0, 5.0), 1.0)
    sim = ds.FixedStep(lone(1.0, 5.3, 1.0, 0.0), ds.Box(10.0, 10.0), dt=DT, policy=policy, sensors=[circle])
    sim.run(until=7.0)
    assert rows(sim) == [(first_frame_after(enter), ENTER, 0, 0), (first_frame_after(leave), LEAVE, 0, 0)]
    assert rows(sim)[0][0] == 3.25 and rows(sim)[1][0] == 5.0
    assert sim.sensors == (circle,)


@pytest.mark.parametrize("policy", POLICIES)
def test_a_disc_crosses_a_rectangle(policy):
    # Up the line x = 5 from y = 1 at 1.3: inside 4 < y < 5 from t = 3 / 1.3 to 4 / 1.3.
    box = Sensor.rectangle((4.0, 4.0), (6.0, 5.0))
    sim = ds.FixedStep(lone(5.0, 1.0, 0.0, 1.3), ds.Box(10.0, 10.0), dt=DT, policy=policy, sensors=box)
    sim.run(until=5.0)
    assert rows(sim) == [(first_frame_after(3 / 1.3), ENTER, 0, 0), (first_frame_after(4 / 1.3), LEAVE, 0, 0)]
    assert [t for t, *_ in rows(sim)] == [2.5, 3.25]


@pytest.mark.parametrize("policy", POLICIES)
def test_a_line_crossed_both_ways_and_passed_beyond_its_end(policy):
    # The wire x = 5 from y = 1 to y = 9 points up: its left side is x < 5.
    wire = Sensor.line((5.0, 1.0), (5.0, 9.0))
    discs = ds.Discs(
        [[2.0, 2.0], [8.0, 4.0], [2.0, 9.5]],  # rightwards, leftwards, and above the wire's top end
        [[0.7, 0.0], [-1.1, 0.0], [0.7, 0.0]],
        0.1,
    )
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=DT, policy=policy, sensors=[wire])
    sim.run(until=6.0)
    # Disc 0 reaches x = 5 at 3 / 0.7 = 4.2857 going right (ends on the right: LEAVE); disc 1 at 3 / 1.1 = 2.7273
    # going left (ENTER); disc 2 passes x = 5 above the wire: nothing.
    assert rows(sim) == [(first_frame_after(3 / 1.1), ENTER, 1, 0), (first_frame_after(3 / 0.7), LEAVE, 0, 0)]
    record = sensed(sim)[0]
    t = float(record["time"])
    assert (record["xi"], record["yi"], record["vxi"], record["vyi"]) == (8.0 - 1.1 * t, 4.0, -1.1, 0.0)
    assert all(math.isnan(record[name]) for name in ("xj", "yj", "vxj", "vyj"))


@pytest.mark.parametrize("policy", POLICIES)
def test_records_come_by_disc_then_sensor_and_step_returns_them(policy):
    # Two discs cross a rectangle's edge (x = 4) and a wire (x = 4.2) in the same frame: x = 3.9, then 4.4.
    sensors = [Sensor.rectangle((4.0, 0.0), (6.0, 10.0)), Sensor.line((4.2, 10.0), (4.2, 0.0))]
    discs = ds.Discs([[3.9, 7.0], [3.9, 3.0]], [[2.0, 0.0], [2.0, 0.0]], 0.1)
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=DT, policy=policy, sensors=sensors)
    # The wire points down, so its left is x > 4.2: crossing it rightwards enters.
    expected = [Event(0.25, "enter", 0, 0), Event(0.25, "enter", 0, 1), Event(0.25, "enter", 1, 0)]
    assert sim.step() == [*expected, Event(0.25, "enter", 1, 1)]
    assert sim.step() == []
    assert rows(sim) == [(0.25, ENTER, 0, 0), (0.25, ENTER, 0, 1), (0.25, ENTER, 1, 0), (0.25, ENTER, 1, 1)]
    assert sim.counts["sensor_events"] == 4


@pytest.mark.parametrize("policy", POLICIES)
def test_a_bounce_is_seen_at_the_frames(policy):
    # A disc that leaves a rectangle (x >= 8 from t = 0.45), hits the wall at x = 9.5 and comes back in: LEAVE at
    # the frame 0.5, the wall hit, then ENTER at the first frame where it is back below x = 8.
    strip = Sensor.rectangle((6.0, 0.0), (8.0, 10.0))
    sim = ds.FixedStep(lone(7.1, 5.0, 2.0, 0.0, radius=0.5), ds.Box(10.0, 10.0), dt=DT, policy=policy, sensors=strip)
    sim.run(until=2.9)
    events = sim.events
    assert [int(k) for k in events["kind"]] == [LEAVE, ds.events.WALL, ENTER]
    assert events["time"][0] == 0.5 and events["time"][1] < events["time"][2]
    back = events[2]
    assert 6.0 < back["xi"] < 8.0 and back["vxi"] == -2.0
    assert back["xi"] + 2.0 * DT >= 8.0  # the frame before, it was still outside


# --- periodic boxes: wrapped positions, unwrapped steps -----------------------------------------------------------


@pytest.mark.parametrize("policy", ["resolve", "swept"])
def test_a_step_across_a_periodic_edge_is_not_a_step_across_the_box(policy):
    # A disc at x = 9.8 moving +2 per unit time: at the first frame it is at 10.3, wrapped to 0.3.
    box = ds.Box(10.0, 10.0, periodic=True)
    wires = [
        Sensor.line((5.0, 0.0), (5.0, 10.0)),  # the middle of the box: the wrapped positions straddle it
        Sensor.line((0.2, 0.0), (0.2, 10.0)),  # crossed at x = 10.2, past the edge
        Sensor.line((9.9, 0.0), (9.9, 10.0)),  # crossed at x = 9.9, before the edge
    ]
    circle = Sensor.circle((0.3, 5.0), 0.2)  # the wrapped position lands in it
    sim = ds.FixedStep(lone(9.8, 5.0, 2.0, 0.0), box, dt=DT, policy=policy, sensors=[*wires, circle])
    sim.step()
    # Each wire points up (left is -x): moving +x ends on the right, LEAVE.
    assert rows(sim) == [(0.25, LEAVE, 0, 1), (0.25, LEAVE, 0, 2), (0.25, ENTER, 0, 3)]
    assert sensed(sim)["xi"].tolist() == [sim.positions[0, 0]] * 3


def test_a_line_in_a_periodic_box_is_crossed_once_per_image_reached():
    # Faster than a box per frame: 9.8 to 21.3 crosses x = 0.2 at 10.2 and 20.2.
    box = ds.Box(10.0, 10.0, periodic=True)
    discs = ds.Discs([[9.8, 5.0]], [[46.0, 0.0]], 0.1)
    sim = ds.FixedStep(discs, box, dt=DT, sensors=[Sensor.line((0.2, 0.0), (0.2, 10.0))]).run(frames=1)
    assert rows(sim) == [(0.25, LEAVE, 0, 0), (0.25, LEAVE, 0, 0)]


@pytest.mark.parametrize(
    ("p0", "p1", "axis"),
    [
        ((0.0, 0.0), (0.0, 10.0), 0),
        ((10.0, 0.0), (10.0, 10.0), 0),  # the same wire: the box's edges x = 0 and x = 10 are one line
        ((0.0, 10.0), (10.0, 10.0), 1),
        ((0.0, 0.0), (0.0, 4.0), 0),  # along part of the edge: the second wrap passes beyond its end (y > 4)
    ],
)
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_trip_wire_on_a_periodic_edge_is_crossed_at_each_wrap_over_it(p0, p1, axis, sign):
    # The centre from 3.3 at speed 0.731 along the axis (0.09 across it) reaches the edge at 9.166 and 22.846
    # (+) or 4.514 and 18.194 (-), at 3.82 and 5.05 across (+) or 3.41 and 4.64 (-), and jumps to the other edge.
    velocity, start = [0.09, 0.09], [3.0, 3.0]
    velocity[axis], start[axis] = sign * 0.731, 3.3
    sim = ds.FixedStep(lone(*start, *velocity), ds.Box(10.0, 10.0, periodic=True), dt=DT,
                       sensors=[Sensor.line(p0, p1)])  # fmt: skip
    sim.run(until=25.0)
    first = (10.0 - 3.3) / 0.731 if sign > 0 else 3.3 / 0.731
    times = [first, first + 10.0 / 0.731]
    over = [t for t in times if p1[1] != 4.0 or 3.0 + 0.09 * t <= 4.0]
    turning = (p1[0] - p0[0]) * velocity[1] - (p1[1] - p0[1]) * velocity[0]
    kind = ENTER if turning > 0.0 else LEAVE
    assert rows(sim) == [(first_frame_after(t), kind, 0, 0) for t in over]


# --- what it misses (docs/study.md) -------------------------------------------------------------------------------


@pytest.mark.parametrize("policy", POLICIES)
def test_a_fast_disc_passes_clean_through_a_small_circle_unseen(policy):
    # The centre (2, 5) + (10, 0) t is at x = 4.5 at frame 1 and x = 7 at frame 2: outside |p - (5, 5)| < 0.2
    # both times, though it is inside from x = 4.8 to 5.2, t = 0.28 to 0.32, between them.
    pocket = Sensor.circle((5.0, 5.0), 0.2)
    sim = ds.FixedStep(lone(2.0, 5.0, 10.0, 0.0), ds.Box(10.0, 10.0), dt=DT, policy=policy, sensors=[pocket])
    sim.run(until=0.75)
    assert rows(sim) == []
    enter, leave = (4.8 - 2.0) / 10.0, (5.2 - 2.0) / 10.0
    assert DT < enter < leave < 2 * DT
    # The straight step between the two frames does pass through it: its middle, t = 0.3, is the centre.
    before, after = np.array([[4.5, 5.0]]), np.array([[7.0, 5.0]])
    assert not pocket.crossed(before, after)[0]  # a region is crossed when contains changes: it does not
    middle = before + (after - before) * (0.5 * (enter + leave) - DT) / DT
    np.testing.assert_allclose(middle, [[5.0, 5.0]], rtol=0, atol=1e-12)
    assert pocket.contains(middle)[0]


# --- checkpoints, snapshots, streams, edits ----------------------------------------------------------------------


def gas_with_sensors(policy="resolve", **kwargs):
    discs, box = ds.random_gas(40, 0.2, periodic=True, seed=7, temperature=4.0)
    w, h = box.width, box.height
    sensors = [
        Sensor.circle((0.5 * w, 0.5 * h), 0.2 * w),
        Sensor.rectangle((0.1 * w, 0.1 * h), (0.3 * w, 0.8 * h)),
        Sensor.line((0.7 * w, 0.05 * h), (0.75 * w, 0.95 * h)),
        Sensor.line((0.02 * w, 0.3 * h), (0.98 * w, 0.31 * h)),
    ]
    return ds.FixedStep(discs, box, dt=0.05, policy=policy, sensors=sensors, **kwargs)


@pytest.mark.parametrize("policy", ["resolve", "separate", "swept"])
def test_a_saved_and_loaded_run_reports_the_same_crossings(tmp_path, policy):
    whole = gas_with_sensors(policy).run(frames=100)
    half = gas_with_sensors(policy).run(frames=50)
    loaded = ds.load(half.save(tmp_path / "half.dsc"))
    assert loaded.sensors == half.sensors
    loaded.run(frames=50)
    assert len(sensed(whole)) > 20 and set(sensed(whole)["kind"].tolist()) == {ENTER, LEAVE}
    assert sensed(loaded).tobytes() == sensed(whole).tobytes()
    assert loaded.events.tobytes() == whole.events.tobytes() and loaded.counts == whole.counts


def test_a_run_from_a_snapshot_at_a_frame_reports_the_same_crossings():
    # "swept" leaves no overlap at the frames, so the snapshot is a valid start.
    whole = gas_with_sensors("swept").run(frames=100)
    half = gas_with_sensors("swept").run(frames=50)
    again = ds.FixedStep(half.snapshot(), half.box, dt=half.dt, policy="swept", sensors=half.sensors)
    again.run(frames=50)
    later = sensed(whole)[sensed(whole)["time"] > half.time]
    assert len(later) > 10
    got = sensed(again)
    assert got[["kind", "i", "j"]].tolist() == later[["kind", "i", "j"]].tolist()
    np.testing.assert_allclose(got["time"] + half.time, later["time"], rtol=0, atol=1e-12)


def test_a_streamed_run_in_two_calls_keeps_its_log(tmp_path):
    path = tmp_path / "events.dse"
    sim = gas_with_sensors(record=False)
    sim.stream_chunk = 16
    sim.run(frames=40, record_to=path)
    sim.run(frames=40, record_to=path)  # the stream's count of records must include the sensors'
    reference = gas_with_sensors().run(frames=80)
    assert ds.read_events(path).events.tobytes() == reference.events.tobytes()


def test_a_version_4_state_reads_with_no_sensor_records():
    scalars, arrays = gas_with_sensors().run(frames=5).state().to_arrays()
    old = {name: value for name, value in scalars.items() if name != "sensor_events"}
    state = FixedStepState.from_arrays(old, arrays, 4)
    assert state.sensor_events == 0 and FixedStepState.VERSION == 5


def test_sensor_records_name_discs_by_id_after_a_removal():
    wire = Sensor.line((5.0, 10.0), (5.0, 0.0))  # pointing down: left is x > 5
    discs = ds.Discs([[1.0, 1.0], [3.9, 3.0], [3.9, 7.0]], [[0.0, 0.0], [1.0, 0.0], [1.0, 0.0]], 0.1)
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=DT, sensors=[wire])
    sim.remove_discs([0])
    sim.run(until=1.5)
    assert rows(sim) == [(1.25, ENTER, 1, 0), (1.25, ENTER, 2, 0)]


def test_a_disc_moved_by_set_positions_counts_as_having_been_there_at_the_frame():
    # FixedStep takes a disc set somewhere as having been there at the last frame (its frame position): set into
    # a circle, it logs nothing until it leaves (as a disc that starts or is added inside one).
    pocket = Sensor.circle((5.0, 5.0), 1.0)
    sim = ds.FixedStep(lone(1.0, 5.0, 0.0, 1.0), ds.Box(10.0, 10.0), dt=DT, sensors=[pocket]).run(until=0.6)
    sim.set_positions([0], [[5.0, 5.0]])
    sim.run(until=2.0)
    assert rows(sim) == [(1.75, LEAVE, 0, 0)]  # y = 5 + (t - 0.6) reaches 6 at t = 1.6


def test_a_velocity_set_between_frames_in_a_periodic_box_keeps_the_line_step_straight():
    # Set moving +x at t = 0.1 from x = 9.7 (it was still since the frame at 0); at the frame 0.25 it is at
    # 10.0 wrapped to 0.0, having crossed the wire at x = 9.9 (and not the one across the middle).
    box = ds.Box(10.0, 10.0, periodic=True)
    wires = [Sensor.line((9.9, 0.0), (9.9, 10.0)), Sensor.line((5.0, 0.0), (5.0, 10.0))]
    sim = ds.FixedStep(lone(9.7, 5.0, 0.0, 0.0), box, dt=DT, sensors=wires).run(until=0.1)
    sim.set_velocities([0], [[2.0, 0.0]])
    sim.run(until=0.25)
    assert rows(sim) == [(0.25, LEAVE, 0, 0)]


def test_the_trajectory_is_unchanged_by_sensor_records():
    plain = ds.FixedStep(*ds.random_gas(10, 0.2, periodic=False, seed=3), dt=0.05).run(until=3.0)
    watched = ds.FixedStep(
        *ds.random_gas(10, 0.2, periodic=False, seed=3), dt=0.05, sensors=[Sensor.circle((5.0, 5.0), 3.0)] * 12
    ).run(until=3.0)
    assert len(sensed(watched)) > 0
    times = np.linspace(0.0, 3.0, 61)
    np.testing.assert_allclose(watched.trajectory(times), plain.trajectory(times), rtol=0, atol=1e-9)


def test_under_gravity_the_trajectory_is_unchanged_by_sensor_records():
    discs = ds.Discs([[2.0, 8.0], [5.0, 6.0]], [[0.5, 0.0], [0.0, 0.0]], 0.3)
    line = Sensor.line((0.0, 4.0), (10.0, 4.0))
    options = {"dt": DT, "gravity": (0.0, -9.81)}
    plain = ds.FixedStep(discs, ds.Box(10.0, 10.0), **options).run(until=3.0)
    watched = ds.FixedStep(discs, ds.Box(10.0, 10.0), sensors=[line, line], **options).run(until=3.0)
    assert sensed(watched)["j"].tolist().count(1) > 0
    times = np.linspace(0.0, 3.0, 31)
    np.testing.assert_allclose(watched.trajectory(times), plain.trajectory(times), rtol=0, atol=1e-9)


# --- bad input ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("sensors", "named"),
    [
        ("circle", "sensors[0]"),
        ([Sensor.circle((1.0, 1.0), 0.5), 3], "sensors[1]"),
        (7, "sensors must be a list"),
    ],
)
def test_bad_sensors_are_refused_by_name(sensors, named):
    with pytest.raises(InvalidArgumentError, match=named.replace("[", r"\[").replace("]", r"\]")) as info:
        ds.FixedStep(lone(1.0, 1.0, 1.0, 0.0), ds.Box(10.0, 10.0), dt=DT, sensors=sensors)
    assert isinstance(info.value, DiscsimError)


def test_no_sensors_log_nothing_and_cost_nothing():
    sim = ds.FixedStep(lone(1.0, 5.0, 1.0, 0.0), ds.Box(10.0, 10.0), dt=DT).run(until=2.0)
    assert sim.sensors == () and sim.counts["sensor_events"] == 0 and len(sensed(sim)) == 0


@pytest.mark.parametrize(
    "entry",  # a negative radius, an unknown shape, a line of one point, too few numbers, no list
    [["circle", 1.0, 1.0, -0.5, 0.0], ["hexagon", 0.0, 0.0, 1.0, 1.0], ["line", 1.0, 1.0, 1.0, 1.0], ["line", 1.0], 3],
)
@pytest.mark.one_backend
def test_a_checkpoint_with_a_broken_sensor_is_refused_by_name(entry):
    from discsim.engines.fixed_step.engine import _restored_sensors
    from discsim.errors import CheckpointError

    assert _restored_sensors({"sensors": [["rectangle", 0.0, 0.0, 1.0, 2.0]]}) == (
        Sensor.rectangle((0.0, 0.0), (1.0, 2.0)),
    )
    assert _restored_sensors({}) == ()
    with pytest.raises(CheckpointError, match=r"sensors\[1\] cannot be used"):
        _restored_sensors({"sensors": [["circle", 0.0, 0.0, 1.0, 0.0], entry]})
