"""Linear drag in the event-driven engine (issue 27, item 4): closed forms, a brute-force oracle in lock-step,
energy bookkeeping, both backends bit for bit, trajectories, checkpoints, bad input."""

import math
import re

import numpy as np
import pytest

import discsim as ds
from discsim.errors import InvalidArgumentError, UnitsError
from discsim.physics.damped import spans_many

G = 9.81
BOX = ds.Box(10.0, 10.0)


def ball(x, y, vx=0.0, vy=0.0, r=1.0):
    return ds.Discs([[x, y]], [[vx, vy]], radii=r)


def times(sim, kind=None):
    return np.array([e["time"] for e in sim.events if kind is None or e["kind"] == kind])


# --- closed forms ---------------------------------------------------------------------------------------------
def test_a_disc_reaches_a_wall_at_the_exact_time_and_stops_short_of_the_next(every_backend):
    # From x = 2 at 8 under gamma = 0.5: the wall stops the centre at 9, reached when tau = 7 / 8; back at 4.5,
    # it would stop 9 farther on, but reaches x = 1 when tau = 8 / 4.5.
    gamma = 0.5
    sim = ds.EventDriven(ball(2.0, 5.0, 8.0), BOX, drag=gamma).run(until=30.0)
    first = -math.log1p(-gamma * 7.0 / 8.0) / gamma
    second = first - math.log1p(-gamma * 8.0 / 4.5) / gamma
    assert times(sim).tolist() == pytest.approx([first, second], rel=1e-14)
    # After the second bounce at 0.5: it stops at 1 + 0.5 / 0.5 = 2 without another event.
    assert sim.positions[0] == pytest.approx([2.0 - 0.5 * math.exp(-gamma * (30.0 - second)) / gamma, 5.0])
    assert sim.velocities[0, 0] == pytest.approx(0.5 * math.exp(-gamma * (30.0 - second)), rel=1e-12)


def test_a_ball_falls_at_its_terminal_velocity(every_backend):
    gamma = 4.0
    sim = ds.EventDriven(ball(5.0, 1000.0, 2.0, 0.0), ds.Box(10.0, 1001.0), gravity=(0.0, -G), drag=gamma)
    sim.run(until=10.0)
    assert sim.velocities[0] == pytest.approx([2.0 * math.exp(-40.0), -G / gamma], rel=1e-12)
    # Height: 1000 - (g / gamma) (t - tau(t)).
    assert sim.positions[0, 1] == pytest.approx(1000.0 - G / gamma * (10.0 - (1 - math.exp(-40.0)) / gamma), rel=1e-14)


def test_two_discs_meet_at_free_flights_contact_in_the_transformed_time(every_backend):
    gamma = 0.2
    discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
    sim = ds.EventDriven(discs, BOX, drag=gamma, gravity=(0.0, -1e-3))  # both fall: gravity cancels
    event = sim.step()
    assert event.kind == "collision"
    assert event.time == pytest.approx(-math.log1p(-gamma * 2.0) / gamma, rel=1e-13)


@pytest.mark.parametrize("gamma", [1e-12, 1e-9])
def test_a_ball_dropped_on_an_obstacle_under_a_tiny_drag_hits_it_at_contact_and_bounces(every_backend, gamma):
    # Once hit "at" 1.5 its contact distance, 1e-4 into the fall, and came to rest there in mid-air.
    discs = ds.Discs([[5.0, 3.0], [5.3, 6.0]], [[0.0, 0.0], [0.0, 0.0]], radii=1.0, masses=[np.inf, 1.0])
    sim = ds.EventDriven(discs, BOX, gravity=(0.0, -G), drag=gamma, restitution=0.7)
    event = sim.step()
    assert event.kind == "collision" and event.time == pytest.approx(0.4566036043583582, rel=1e-9)
    assert np.hypot(*(sim.positions[1] - sim.positions[0])) == pytest.approx(2.0, rel=1e-12)
    assert not sim.resting.any() and sim.velocities[1, 1] > 0.0


# --- the oracle -------------------------------------------------------------------------------------------------
_GRID = np.unique(np.concatenate([np.geomspace(1e-9, 50.0, 3000), np.linspace(0.0, 50.0, 20001)[1:]]))


def _bracket(values_at):
    """``(lo, hi)``: the grid's first step where ``values_at(t) <= 0`` (``(inf, inf)``: none up to the horizon)."""
    hit = np.flatnonzero(values_at(_GRID) <= 0.0)
    if not len(hit):
        return math.inf, math.inf
    k = hit[0]
    return (_GRID[k - 1] if k else 0.0), _GRID[k]


def _refine(values_at, lo, hi):
    """The first time in ``(lo, hi]`` where ``values_at(t) <= 0``, by bisection."""
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if values_at(np.array([mid]))[0] <= 0.0 else (mid, hi)
    return hi


def next_event_under_drag(pos, vel, radii, masses, box, gravity, gamma, resting):
    """``(dt, kind, i, j)`` of the earliest event, by brute force over every pair and wall: each one's first step on
    a dense grid of times where it happens, then bisection of those that could come first."""
    g = np.asarray(gravity, dtype=float)
    acc = np.where((np.isfinite(masses) & ~np.asarray(resting, dtype=bool))[:, None], g, 0.0)

    def path(k, t):
        tau, s, _ = spans_many(t, gamma)
        p, v, a = pos[k][:, None], vel[k][:, None], acc[k][:, None]
        return p + v * tau + a * s, v * (1 - gamma * tau) + a * tau

    def gap(t, i, j):
        (pi, vi), (pj, vj) = path(i, t), path(j, t)
        d, w = pj - pi, vj - vi
        closing = (d * w).sum(axis=0) < 0.0
        return np.where(closing, np.hypot(*d) - radii[i] - radii[j], 1.0)

    def beyond(t, i, axis, length):
        p, v = path(i, t)
        q, u, r = p[axis], v[axis], radii[i]
        return np.where(((q <= r) & (u < 0)) | ((q >= length - r) & (u > 0)), -1.0, 1.0)

    n = len(radii)
    grid = [path(k, _GRID) for k in range(n)]  # every disc's path on the grid, once

    def gap_grid(_, i, j):
        (pi, vi), (pj, vj) = grid[i], grid[j]
        d, w = pj - pi, vj - vi
        return np.where((d * w).sum(axis=0) < 0.0, np.hypot(*d) - radii[i] - radii[j], 1.0)

    def beyond_grid(_, i, axis, length):
        p, v = grid[i]
        q, u, r = p[axis], v[axis], radii[i]
        return np.where(((q <= r) & (u < 0)) | ((q >= length - r) & (u > 0)), -1.0, 1.0)

    candidates = []
    for i in range(n):
        for j in range(i + 1, n):
            lo, hi = _bracket(lambda _t, i=i, j=j: gap_grid(None, i, j))
            candidates.append((lo, hi, lambda t, i=i, j=j: gap(t, i, j), "collision", i, j))
        for axis, length in enumerate(box.size):
            lo, hi = _bracket(lambda _t, i=i, axis=axis, length=length: beyond_grid(None, i, axis, length))
            candidates.append(
                (lo, hi, lambda t, i=i, axis=axis, length=length: beyond(t, i, axis, length), "wall", i, -1)
            )
    first = min(c[1] for c in candidates)
    best = (math.inf, None, -1, -1)
    for lo, _hi, f, kind, i, j in candidates:
        if lo <= first:
            t = _refine(f, lo, _hi)
            if t < best[0]:
                best = (t, kind, i, j)
    return best


@pytest.mark.slow_on_python
@pytest.mark.parametrize("gravity", [(0.0, 0.0), (0.5, -3.0)])
def test_a_gas_under_drag_follows_the_oracle(every_backend, gravity):
    from oracle import scattered_discs

    discs = scattered_discs(10, 10.0, (0.5, 0.9), 4.0, obstacles=2)
    sim = ds.EventDriven(discs, BOX, gravity=gravity, drag=0.2, restitution=0.9)
    assert sim.backend == every_backend
    for _ in range(40):
        t0 = sim.time
        dt, kind, i, j = next_event_under_drag(
            sim.positions, sim.velocities, discs.radii, discs.masses, sim.box, gravity, 0.2, sim.resting
        )
        event = sim.step()
        assert event.time == pytest.approx(t0 + dt, rel=1e-7, abs=1e-8), (event, t0 + dt, kind, i, j)
        assert event.kind == kind and {event.i, event.j} == {i, j}, (event, kind, i, j)
        sim._check()


# --- energy, backends, trajectories, checkpoints -------------------------------------------------------------------
@pytest.mark.parametrize("gravity, e", [((0.0, 0.0), 1.0), ((0.0, -G), 1.0), ((2.0, -3.0), 0.8)])
def test_energy_plus_what_drag_and_collisions_took_is_constant_and_backends_agree(every_backend, gravity, e):
    discs, box = ds.random_gas(40, 0.3, seed=4, periodic=False)
    sim = ds.EventDriven(discs, box, gravity=gravity, drag=0.05, restitution=e, tc=1e-3)
    e0 = sim.energy()
    sim.run(events=1500)
    assert sim.dissipated > 0.0
    assert sim.energy() + sim.dissipated == pytest.approx(e0, rel=1e-9)
    sim.run(until=sim.time + 0.37)  # between events too (the flights under way)
    assert sim.energy() + sim.dissipated == pytest.approx(e0, rel=1e-9)
    sim._check()
    if every_backend == "numba":  # the pure-Python backend (the loop's source, interpreted): bit for bit
        python = ds.EventDriven(discs, box, gravity=gravity, drag=0.05, restitution=e, tc=1e-3, backend="python")
        python.run(events=1500)
        assert python.events.tobytes() == sim.events[: len(python.events)].tobytes()


def test_trajectories_follow_the_exponential_flight(every_backend):
    gamma = 0.3
    sim = ds.EventDriven(ball(2.0, 8.0, 5.0, 1.0), BOX, gravity=(0.0, -G), drag=gamma).run(until=6.0)
    ts = np.linspace(0.0, 6.0, 37)
    path = sim.trajectory(ts)[:, 0]
    for k, t in enumerate(ts):  # against a fresh run stopped at each time
        here = ds.EventDriven(ball(2.0, 8.0, 5.0, 1.0), BOX, gravity=(0.0, -G), drag=gamma).run(until=float(t))
        assert path[k] == pytest.approx(here.positions[0], abs=1e-10)


def test_a_run_under_drag_continues_from_a_checkpoint_bit_for_bit(every_backend, tmp_path):
    discs, box = ds.random_gas(30, 0.3, seed=9, periodic=False)
    laws = {"gravity": (0.0, -2.0), "restitution": 0.9, "tc": 1e-3, "drag": 0.1}
    whole = ds.EventDriven(discs, box, **laws).run(events=600)
    half = ds.EventDriven(discs, box, **laws).run(events=300)
    half.save(tmp_path / "half.dsc")
    resumed = ds.load(tmp_path / "half.dsc").run(events=300)
    assert resumed.laws == whole.laws and resumed.laws.drag == 0.1
    assert resumed.events[-300:].tobytes() == whole.events[-300:].tobytes()  # (wall records hold NaNs)
    assert resumed.dissipated == pytest.approx(whole.dissipated, rel=1e-12)


def test_replays_of_free_flight_refuse_a_run_under_drag(tmp_path):
    # They once replayed it as free flight: frames() put the disc at x = -8.3, outside the box.
    sim = ds.EventDriven(ball(2.0, 5.0, 8.0), BOX, drag=0.5).run(until=5.0)
    with pytest.raises(InvalidArgumentError, match="drag 0.5"):
        ds.frames(sim, [2.5])
    path = tmp_path / "events.dse"
    ds.EventDriven(ball(2.0, 5.0, 8.0), BOX, drag=0.5, record=False).run(until=5.0, record_to=path)
    with pytest.raises(InvalidArgumentError, match="drag 0.5"):
        ds.trajectory_from_events(path, [2.5])
    # The log read whole rebuilds the exponential flights (its header holds the drag), as trajectory() does.
    assert ds.read_events(path).trajectory([2.5]) == pytest.approx(sim.trajectory([2.5]), abs=1e-12)


def test_drag_zero_is_todays_physics():
    discs, box = ds.random_gas(30, 0.3, seed=1)
    plain = ds.EventDriven(discs, box, backend="python").run(events=300)
    spelled = ds.EventDriven(discs, box, backend="python", drag=0.0).run(events=300)
    assert spelled.laws.default and plain.events.tobytes() == spelled.events.tobytes()


@pytest.mark.parametrize("drag", [-0.1, math.nan, math.inf, "strong", None])
def test_bad_drag_is_refused_naming_it(drag):
    with pytest.raises(InvalidArgumentError, match="drag"):
        ds.EventDriven(ball(5.0, 5.0), BOX, drag=drag)


def test_a_log_streamed_under_drag_says_so_and_its_replays_refuse_it(tmp_path):
    path = tmp_path / "drag.dslog"
    ds.EventDriven(ball(2.0, 5.0, 8.0), BOX, drag=0.5).run(until=3.0, record_to=path)
    with pytest.raises(InvalidArgumentError, match="drag 0.5"):
        ds.frames(path, [1.0])
    with pytest.raises(InvalidArgumentError, match="drag 0.5"):
        ds.trajectory_from_events(path, [1.0])


@pytest.mark.parametrize("drag", [5e-324, 1e-315, 1e-101, 1e101])
def test_a_drag_outside_the_supported_units_is_refused_naming_it(drag):
    # A subnormal drag once flew a disc through the wall: gamma t loses its digits, so tau(0.875) came out 1.
    with pytest.raises(UnitsError, match=re.escape(f"drag {drag!r}")):
        ds.EventDriven(ball(2.0, 5.0, 8.0), BOX, drag=drag)


@pytest.mark.parametrize("drag", [1e-100, 1e100])
def test_the_ends_of_the_drags_units_fly_as_no_drag_and_as_an_instant_stop(drag):
    sim = ds.EventDriven(ball(2.0, 5.0, 8.0), BOX, drag=drag)
    sim.run(until=1.5)
    if drag < 1.0:
        assert times(sim).tolist() == [0.875] and sim.positions[0].tolist() == [4.0, 5.0]
    else:
        assert times(sim).tolist() == [] and sim.positions[0] == pytest.approx([2.0 + 8.0 / drag, 5.0], abs=1e-15)
