"""Sensors in the event-driven engine (issue 28, item 3): exact enter and leave times against closed forms and
a dense check of the exact trajectories, trip wires, pockets, callbacks, checkpoints, both backends bit for bit,
bad input."""

import math
import re

import numpy as np
import pytest

import discsim as ds
from discsim.errors import InvalidArgumentError
from discsim.events import ENTER, REMOVE, SENSED, Event

G = 9.81
BOX = ds.Box(10.0, 10.0)
Sensor = ds.Sensor


def ball(x, y, vx=0.0, vy=0.0, r=0.2):
    return ds.Discs([[x, y]], [[vx, vy]], radii=r)


def crossings(sim):
    """``[(time, "enter" | "leave", disc, sensor), ...]`` from the log."""
    ev = sim.events
    ev = ev[np.isin(ev["kind"], SENSED)]
    return [(float(e["time"]), "enter" if e["kind"] == ENTER else "leave", int(e["i"]), int(e["j"])) for e in ev]


# --- closed forms -----------------------------------------------------------------------------------------
def test_a_disc_crossing_a_circle_along_a_chord_enters_and_leaves_at_the_exact_times():
    # Centre at (1, 5.6) moving +x at 2 through the circle of radius 1 around (5, 5): half-chord sqrt(1 - 0.36).
    sim = ds.EventDriven(ball(1.0, 5.6, 2.0), BOX, sensors=[Sensor.circle((5.0, 5.0), 1.0)])
    sim.run(until=4.0)
    half = math.sqrt(1.0 - 0.36)
    (t0, k0, i0, s0), (t1, k1, _, _) = crossings(sim)
    assert (k0, i0, s0, k1) == ("enter", 0, 0, "leave")
    assert t0 == pytest.approx((4.0 - half) / 2.0, rel=1e-14)
    assert t1 == pytest.approx((4.0 + half) / 2.0, rel=1e-14)
    assert sim.counts["sensor_events"] == 2
    assert sim.counts["wall_hits"] == 0  # the motion does not change: no bounce, same straight path
    assert sim.positions[0] == pytest.approx([9.0, 5.6])


def test_a_trip_wire_reports_each_crossing_in_its_direction_and_nothing_beyond_its_ends():
    # A vertical wire at x = 7 from y = 0 to 6: its left (its inside) is x < 7. A disc at y = 5 goes right and
    # bounces back; one at y = 8 passes beyond the wire's end both ways.
    discs = ds.Discs([[1.0, 5.0], [1.0, 8.0]], [[1.0, 0.0], [1.0, 0.0]], radii=0.2)
    sim = ds.EventDriven(discs, BOX, sensors=[Sensor.line((7.0, 0.0), (7.0, 6.0))])
    sim.run(until=20.0)
    found = crossings(sim)
    assert [(k, i) for _, k, i, _ in found] == [("leave", 0), ("enter", 0)]
    # Out at x = 7 (t = 6), to the wall at x = 9.8 (t = 8.8), back at x = 7 (t = 11.6).
    assert [t for t, *_ in found] == pytest.approx([6.0, 11.6], rel=1e-14)


def test_a_rectangle_is_entered_when_the_second_coordinate_gets_in():
    # Moving (1, 1) from (0.5, 0.5) towards [2, 5] x [3, 5]: x is in from t = 1.5, y from t = 2.5.
    sim = ds.EventDriven(ball(0.5, 0.5, 1.0, 1.0), BOX, sensors=[Sensor.rectangle((2.0, 3.0), (5.0, 5.0))])
    sim.run(until=6.0)
    (t0, k0, *_), (t1, k1, *_) = crossings(sim)[:2]
    assert (k0, k1) == ("enter", "leave")
    assert t0 == pytest.approx(2.5) and t1 == pytest.approx(4.5)  # leaves through the right side, x = 5


def test_a_rectangle_missed_between_its_slabs_reports_nothing():
    # x is inside [4, 5] for t in (3.5, 4.5), y inside [6, 7] for t in (1.5, 2.5): never both.
    sim = ds.EventDriven(ball(0.5, 4.5, 1.0, 1.0, r=0.1), BOX, sensors=[Sensor.rectangle((4.0, 6.0), (5.0, 7.0))])
    sim.run(until=4.9)
    assert crossings(sim) == []


def test_a_ball_dropped_through_a_circle_under_gravity_enters_and_leaves_at_sqrt_2h_over_g():
    # Dropped from y = 9 at x = 5 onto nothing: the circle of radius 1 around (5, 5) spans y in [4, 6].
    sim = ds.EventDriven(ball(5.0, 9.0), BOX, gravity=(0.0, -G), sensors=[Sensor.circle((5.0, 5.0), 1.0)])
    sim.run(until=1.1)
    (t0, k0, *_), (t1, k1, *_) = crossings(sim)
    assert (k0, k1) == ("enter", "leave")
    assert t0 == pytest.approx(math.sqrt(2 * 3.0 / G), rel=1e-12)
    assert t1 == pytest.approx(math.sqrt(2 * 5.0 / G), rel=1e-12)


def test_a_thrown_ball_crosses_a_horizontal_wire_up_then_down():
    # Thrown up at 8 from y = 1 through a wire at y = 3 (left of (0,3) -> (10,3) is above it).
    sim = ds.EventDriven(
        ball(5.0, 1.0, 0.0, 8.0), BOX, gravity=(0.0, -G), sensors=[Sensor.line((0.0, 3.0), (10.0, 3.0))]
    )
    sim.run(until=1.5)
    found = crossings(sim)
    assert [k for _, k, *_ in found] == ["enter", "leave"]
    s = math.sqrt(64.0 - 2 * G * 2.0)
    assert [t for t, *_ in found] == pytest.approx([(8.0 - s) / G, (8.0 + s) / G], rel=1e-12)


def test_under_drag_a_wire_is_crossed_at_the_span_and_a_disc_that_stops_short_never_crosses():
    gamma = 0.5
    # From x = 1 at 2: stops at x = 1 + 2 / gamma = 5. A wire at x = 3 is crossed at tau = 1; one at 6 never.
    sim = ds.EventDriven(
        ball(1.0, 5.0, 2.0), BOX, drag=gamma,
        sensors=[Sensor.line((3.0, 0.0), (3.0, 10.0)), Sensor.line((6.0, 0.0), (6.0, 10.0))],
    )  # fmt: skip
    sim.run(until=50.0)
    found = crossings(sim)
    assert [(k, s) for _, k, _, s in found] == [("leave", 0)]
    assert found[0][0] == pytest.approx(-math.log1p(-gamma * 1.0) / gamma, rel=1e-13)


# --- against a dense check of the exact trajectories ------------------------------------------------------
@pytest.mark.slow_on_python
@pytest.mark.parametrize(
    "gravity, periodic", [(None, True), (None, False), pytest.param((0.3, -2.0), False, marks=pytest.mark.slow)]
)
def test_every_crossing_of_a_gas_matches_a_dense_check_of_its_trajectories(gravity, periodic):
    discs, box = ds.random_gas(20, 0.25, seed=3, periodic=periodic)
    scale = box.width / 10.0
    sensors = [
        Sensor.circle((3.0 * scale, 4.0 * scale), 1.7 * scale),
        Sensor.rectangle((5.5 * scale, 1.0 * scale), (8.0 * scale, 3.5 * scale)),
        Sensor.line((1.0 * scale, 7.5 * scale), (8.5 * scale, 6.0 * scale)),
    ]
    sim = ds.EventDriven(discs, box, sensors=sensors, gravity=gravity)
    horizon = 8.0
    sim.run(until=horizon)
    found = crossings(sim)
    assert len(found) > 20
    times = np.linspace(0.0, horizon, 40001)
    paths = sim.trajectory(times)  # (T, N, 2)
    dt = times[1] - times[0]
    for k, sensor in enumerate(sensors):
        for i in range(len(discs)):
            logged = [(t, kind) for t, kind, d, s in found if d == i and s == k]
            before, after = paths[:-1, i], paths[1:, i]
            if sensor.shape == "line":  # (a step across a periodic box's edge is a jump, not a crossing)
                jump = (np.abs(after - before) > 0.5 * np.array(box.size)).any(axis=1)
                steps = np.flatnonzero(sensor.crossed(before, after) & ~jump)
            else:
                inside = sensor.contains(paths[:, i])
                steps = np.flatnonzero(inside[1:] != inside[:-1])
            seen = [(times[s], "enter" if sensor.contains(after[s])[0] else "leave") for s in steps]
            # Every crossing seen between two samples is logged within that step, in its direction, and no other
            # (a graze that the samples straddle can hide a pair: allow those only in pairs within a step).
            assert len(logged) >= len(seen), (k, i, logged, seen)
            for t, kind in seen:
                near = [lk for lt, lk in logged if t - 1e-9 <= lt <= t + dt + 1e-9]
                assert kind in near, (k, i, t, kind, logged)
            unseen = [lt for lt, _ in logged if not any(t - 1e-9 <= lt <= t + dt + 1e-9 for t, _ in seen)]
            assert len(unseen) % 2 == 0, (k, i, unseen)


# --- pockets, callbacks, step ----------------------------------------------------------------------------
def test_a_pocket_removes_a_disc_at_the_moment_it_enters():
    discs = ds.Discs([[1.0, 1.0], [5.0, 5.0]], [[1.0, 1.0], [0.0, 0.3]], radii=0.3)
    sim = ds.EventDriven(discs, BOX, sensors=[Sensor.circle((9.0, 9.0), 0.6)])
    entered = []

    def pocket(sim, crossing):
        entered.append(crossing)
        sim.remove_discs([crossing.i])

    sim.on("enter", pocket)
    sim.run(until=20.0)
    assert len(entered) == 1 and len(sim.discs) == 1
    c = entered[0]
    assert (c.kind, c.i, c.sensor) == ("enter", 0, 0)
    assert c.time == pytest.approx(8.0 - 0.6 / math.sqrt(2.0), rel=1e-12)
    assert c.position == pytest.approx([9.0 - 0.6 / math.sqrt(2.0)] * 2, rel=1e-12)
    kinds = [int(e["kind"]) for e in sim.events if e["time"] == c.time]
    assert kinds == [ENTER, REMOVE]


def test_step_returns_sensor_events_and_look_only_callbacks_see_them_in_order():
    sim = ds.EventDriven(ball(1.0, 5.0, 1.0), BOX, sensors=[Sensor.rectangle((2.0, 4.0), (3.0, 6.0))])
    assert sim.step() == Event(1.0, "enter", 0, 0)
    assert sim.step() == Event(2.0, "leave", 0, 0)
    seen = []
    sim.on("enter", lambda s, c: seen.append((c.time, c.kind)), changes=False)
    sim.on("leave", lambda s, c: seen.append((c.time, c.kind)), changes=False)
    sim.run(until=30.0)
    assert seen == [pytest.approx((t, k)) for t, k, *_ in crossings(sim)[2:]]
    assert [k for _, k in seen][:2] == ["enter", "leave"]


# --- state: checkpoints, edits -----------------------------------------------------------------------------
def test_a_run_saved_and_loaded_halfway_gives_the_same_crossings(tmp_path):
    discs, box = ds.random_gas(30, 0.3, seed=5)
    sensors = [Sensor.circle((box.width / 2, box.height / 2), box.width / 5), Sensor.line((0.0, 1.0), box.size)]
    whole = ds.EventDriven(discs, box, sensors=sensors).run(until=4.0)
    half = ds.EventDriven(discs, box, sensors=sensors).run(until=2.0)
    half.save(tmp_path / "half.npz")
    resumed = ds.load(tmp_path / "half.npz")
    assert resumed.sensors == tuple(sensors)
    resumed.run(until=4.0)
    assert resumed.events.tobytes() == whole.events.tobytes()
    assert resumed.counts["sensor_events"] == whole.counts["sensor_events"] > 0


def test_a_disc_moved_into_a_sensor_counts_as_inside_without_an_event():
    sim = ds.EventDriven(ball(1.0, 1.0, 0.0, 0.5), BOX, sensors=[Sensor.circle((5.0, 5.0), 1.0)])
    sim.set_positions([0], [[5.0, 5.0]])
    sim.run(until=3.0)
    assert [(k, round(t, 12)) for t, k, *_ in crossings(sim)] == [("leave", 2.0)]


def test_both_backends_give_the_same_crossings_bit_for_bit(every_backend):
    discs, box = ds.random_gas(25, 0.3, seed=8)
    sensors = [Sensor.rectangle((1.0, 1.0), (box.width / 2, box.height / 3)), Sensor.line((0.5, 0.5), (4.0, 9.0))]
    sim = ds.EventDriven(discs, box, sensors=sensors).run(events=800)
    assert sim.backend == every_backend
    sim._check()
    if every_backend == "numba":
        python = ds.EventDriven(discs, box, sensors=sensors, backend="python").run(events=800)
        assert python.events.tobytes() == sim.events.tobytes()


def test_a_periodic_gas_counts_the_flux_through_a_wire():
    # Every disc moving right at 1 in a periodic box of width L crosses a full-height wire once per L / 1.
    discs, box = ds.random_gas(16, 0.2, seed=1, periodic=True)
    v = np.zeros((16, 2))
    v[:, 0] = 1.0
    discs = ds.Discs(discs.positions, v, radii=discs.radii)
    wire = Sensor.line((box.width / 2, 0.0), (box.width / 2, box.height))
    sim = ds.EventDriven(discs, box, sensors=[wire]).run(until=3 * box.width)
    assert sim.counts["collisions"] == 0
    assert [k for _, k, *_ in crossings(sim)].count("leave") == 3 * 16


# --- bad input -------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: Sensor.circle((1.0, 1.0), -1.0), "radius"),
        (lambda: Sensor.circle((1.0, float("nan")), 1.0), "centre"),
        (lambda: Sensor.rectangle((2.0, 2.0), (1.0, 3.0)), "upper_right"),
        (lambda: Sensor.line((1.0, 1.0), (1.0, 1.0)), "differ"),
        (lambda: ds.EventDriven(ball(1.0, 1.0), BOX, sensors=["pocket"]), "sensors[0]"),
        (
            lambda: ds.EventDriven(
                ball(1.0, 1.0), ds.Box(10.0, 10.0, periodic=True), sensors=[Sensor.circle((9.5, 5.0), 1.0)]
            ),
            "inside the periodic box",
        ),
    ],
)
def test_bad_sensors_are_refused_by_name(make, words):
    with pytest.raises(InvalidArgumentError, match=re.escape(words)):
        make()


def test_a_ball_falling_under_drag_through_a_circle_enters_and_leaves_where_its_fall_says():
    gamma = 0.8

    def fallen(h):  # the time a ball dropped from rest has fallen h: (g / gamma)(t - tau(t)) = h, by bisection
        lo, hi = 0.0, 20.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if G / gamma * (mid + math.expm1(-gamma * mid) / gamma) < h else (lo, mid)
        return hi

    sim = ds.EventDriven(ball(5.0, 9.0), BOX, gravity=(0.0, -G), drag=gamma, sensors=[Sensor.circle((5.0, 5.0), 1.0)])
    sim.run(until=2.5)
    (t0, k0, *_), (t1, k1, *_) = crossings(sim)
    assert (k0, k1) == ("enter", "leave")
    assert t0 == pytest.approx(fallen(3.0), rel=1e-10) and t1 == pytest.approx(fallen(5.0), rel=1e-10)


def test_the_losses_of_a_run_with_sensors_sum_to_what_it_dissipated():
    discs, box = ds.random_gas(20, 0.3, seed=1, periodic=False)
    sensors = [Sensor.circle(box.size / 2, box.width / 4), Sensor.line((0.0, 1.0), (box.width, 2.0))]
    sim = ds.EventDriven(discs, box, restitution=0.9, sensors=sensors).run(until=3.0)
    losses = sim.event_losses()
    assert np.isin(sim.events["kind"], SENSED).any()
    assert (losses[np.isin(sim.events["kind"], SENSED)] == 0.0).all()
    assert losses.sum() == pytest.approx(sim.dissipated, rel=1e-10)
