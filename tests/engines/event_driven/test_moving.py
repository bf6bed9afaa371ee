"""Segments moving at a constant velocity in the event-driven engine (issue 28, item 1): closed forms, the bounce in
the segment's frame (Galilean invariance), restitution, checkpoints, queries and edits where the segment is now,
both backends bit for bit, bad input."""

import math
import re

import numpy as np
import pytest

import discsim as ds
from discsim.errors import InvalidArgumentError, InvalidDiscsError, OutsideBoxError

BOX = ds.Box(10.0, 10.0)


def ball(x, y, vx=0.0, vy=0.0, r=0.5):
    return ds.Discs([[x, y]], [[vx, vy]], radii=r)


@pytest.mark.parametrize("e", [1.0, 0.6])
def test_a_paddle_hits_a_disc_at_rest_at_the_exact_time_and_sends_it_off(e):
    # The paddle x = 8 - t meets the disc's edge at x = 2.5 at t = 5.5; in its frame the disc comes at +1 and
    # leaves at -e: in the box at -1 - e.
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0), velocity=(-1.0, 0.0))
    sim = ds.EventDriven(ball(2.0, 5.0), BOX, segments=[paddle], restitution=e)
    event = sim.step()
    assert (event.kind, event.i) == ("wall", 0)
    assert event.time == pytest.approx(5.5, rel=1e-14)
    assert sim.velocities[0] == pytest.approx([-1.0 - e, 0.0], rel=1e-14)
    # The energy the bounce took is counted in the paddle's frame: e = 1 takes none (the paddle did work).
    assert sim.dissipated == pytest.approx(0.5 * sim.discs.masses[0] * (1.0 - e * e), abs=1e-14)
    # Back off the left wall, it meets the paddle again where both are then.
    event = sim.step()
    assert event.time == pytest.approx(5.5 + 1.5 / (1.0 + e), rel=1e-13)
    event = sim.step()
    v = 1.0 + e
    t_wall = 5.5 + 1.5 / v
    t_meet = t_wall + (8.0 - t_wall - 1.0) / (e * v + 1.0)  # its edge 0.5 + e v dt + 0.5 (the wall: e) meets 8 - t
    assert event.time == pytest.approx(t_meet, rel=1e-13)


def test_a_disc_catches_up_with_a_receding_segment():
    # The segment x = 5 + 0.5 t recedes; the disc at 2 at speed 2: its edge 2.5 + 2 t meets it at t = 5 / 3.
    wall = ds.Segment((5.0, 0.0), (5.0, 10.0), velocity=(0.5, 0.0))
    sim = ds.EventDriven(ball(2.0, 5.0, 2.0), BOX, segments=[wall])
    event = sim.step()
    assert event.time == pytest.approx(2.5 / 1.5, rel=1e-14)
    assert sim.velocities[0] == pytest.approx([-1.0, 0.0], rel=1e-14)  # 2 u - v


def test_a_bounce_off_a_moving_end_point_is_the_fixed_one_seen_from_a_moving_frame():
    # In the segment's frame the segment is fixed and the disc moves at v - u: the same contact time, and the
    # velocity after differs by u (a glancing hit on the end point, far from the walls).
    u = np.array([-0.5, 0.1])
    p0, p1 = np.array([5.0, 2.0]), np.array([5.0, 5.0])
    x, v = np.array([3.5, 5.3]), np.array([1.0, 0.0])
    moving = ds.EventDriven(ball(*x, *v, r=0.4), BOX, segments=[ds.Segment(p0, p1, velocity=u)])
    fixed = ds.EventDriven(ball(*x, *(v - u), r=0.4), BOX, segments=[ds.Segment(p0, p1)])
    a, b = moving.step(), fixed.step()
    assert a.time == pytest.approx(b.time, rel=1e-12)
    assert moving.velocities[0] == pytest.approx(fixed.velocities[0] + u, rel=1e-12)
    assert moving.positions[0] == pytest.approx(fixed.positions[0] + u * a.time, rel=1e-12)
    assert not np.allclose(moving.velocities[0], v)  # it did bounce (off the end point: a slanted normal)


def test_a_gas_pushed_by_a_piston_wall_heats_up():
    # A segment across the box closing at speed 0.2: every bounce off it adds energy to the gas.
    gas, box = ds.random_gas(40, 0.2, seed=6, periodic=False)
    w, h = box.width, box.height
    low = gas.positions[:, 1] + gas.radii < 0.9 * h
    discs = ds.Discs(gas.positions[low], gas.velocities[low], radii=gas.radii[low])
    lid = ds.Segment((-1.0, 0.98 * h), (w + 1.0, 0.98 * h), velocity=(0.0, -0.02 * h))
    sim = ds.EventDriven(discs, box, segments=[lid])
    e0 = sim.energy()
    sim.run(until=10.0)
    assert sim.counts["wall_hits"] > 10
    assert sim.energy() > e0 * 1.01
    assert (sim.positions[:, 1] + discs.radii <= 0.98 * h - 0.2 * h + 1e-9).all()  # all below the lid now
    sim._check()


def test_moving_segments_survive_checkpoints_and_give_both_backends_the_same_events(every_backend, tmp_path):
    discs, box = ds.random_gas(30, 0.05, seed=2, periodic=False)
    x = 0.3 * box.width
    clear = np.abs(discs.positions[:, 0] - x) > discs.radii + 1e-6  # none cut by the paddle at the start
    discs = ds.Discs(discs.positions[clear], discs.velocities[clear], radii=discs.radii[clear])
    paddle = ds.Segment((x, 0.2), (x, 0.6 * box.height), velocity=(0.05, 0.0))
    whole = ds.EventDriven(discs, box, segments=[paddle]).run(until=6.0)
    assert whole.backend == every_backend
    half = ds.EventDriven(discs, box, segments=[paddle]).run(until=3.0)
    half.save(tmp_path / "half.npz")
    resumed = ds.load(tmp_path / "half.npz")
    assert resumed.segments[0].velocity.tolist() == [0.05, 0.0]
    resumed.run(until=6.0)
    assert resumed.events.tobytes() == whole.events.tobytes()
    if every_backend == "numba":
        python = ds.EventDriven(discs, box, segments=[paddle], backend="python").run(until=6.0)
        assert python.events.tobytes() == whole.events.tobytes()


def test_queries_and_added_discs_see_the_segment_where_it_is_now():
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0), velocity=(-1.0, 0.0))
    sim = ds.EventDriven(ball(1.0, 9.0), BOX, segments=[paddle]).run(until=4.0)  # the paddle is at x = 4 now
    hit = sim.ray_cast([0.5, 5.0], [1.0, 0.0])
    assert (hit.kind, hit.index) == ("segment", 0)
    assert hit.point == pytest.approx([4.0, 5.0])
    with pytest.raises(OutsideBoxError, match="segment 0"):
        sim.add_discs(ball(4.2, 5.0))
    assert len(sim.add_discs(ball(8.0, 5.0))) == 1  # where the paddle was at the start: free now


@pytest.mark.parametrize(
    "make, error, words",
    [
        (lambda: ds.Segment((0, 0), (1, 1), velocity=(float("nan"), 0.0)), InvalidDiscsError, "velocity"),
        (
            lambda: ds.EventDriven(
                ball(2, 2), BOX, segments=[ds.Segment((5, 0), (5, 9), (1, 0))], gravity=(0, -1), restitution=0.8
            ),
            InvalidArgumentError,
            "segments[0]",
        ),
        (
            lambda: ds.FixedStep(ball(2, 2), BOX, segments=[ds.Segment((5, 0), (5, 9), (1, 0))], policy="bisect"),
            InvalidArgumentError,
            "segments[0] Segment([5.0, 0.0], [5.0, 9.0], velocity=[1.0, 0.0]) moves: policy 'bisect'",
        ),
        (
            lambda: ds.EventDriven(ball(5.2, 2), BOX, segments=[ds.Segment((5, 0), (5, 9), (1, 0))]),
            OutsideBoxError,
            "segment",
        ),
    ],
)
def test_bad_moving_segments_are_refused_by_name(make, error, words):
    with pytest.raises(error, match=re.escape(words)):
        make()


def test_a_fixed_segment_is_unchanged():
    s = ds.Segment((0.0, 0.0), (1.0, 0.0))
    assert not s.moving and s.at(5.0) is s and repr(s) == "Segment([0.0, 0.0], [1.0, 0.0])"
    assert math.isclose(ds.Segment((0, 0), (0, 1), velocity=(2, 0)).at(1.5).p0[0], 3.0)


def test_a_paddle_steered_mid_run_stays_where_it_is_and_moves_on_at_its_new_velocity(tmp_path):
    # Fixed at x = 8 until t = 2, then sweeping left at 2: it meets the disc's edge (x = 2.5) at 2 + 5.5 / 2.
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0))
    sim = ds.EventDriven(ball(2.0, 5.0), BOX, segments=[paddle]).run(until=2.0)
    assert sim.backend in ("python", "numba")
    sim.set_segment_velocity(0, (-2.0, 0.0))
    assert sim.segments[0].at(2.0).p0 == pytest.approx([8.0, 3.0])
    event = sim.step()
    assert event.time == pytest.approx(2.0 + 5.5 / 2.0, rel=1e-14)
    assert sim.velocities[0] == pytest.approx([-4.0, 0.0], rel=1e-14)
    sim.set_segment_velocity(0, (0.0, 0.0))  # stopped where it is: x = 8 - 2 * (t - 2)
    sim.run(until=6.0)
    assert sim.segments[0].at(6.0).p0 == pytest.approx([8.0 - 2.0 * (4.75 - 2.0), 3.0])  # where it stopped
    sim.save(tmp_path / "steered.npz")
    assert ds.load(tmp_path / "steered.npz").segments[0].velocity.tolist() == [0.0, 0.0]
    # Where it was at every time (drawn there by plots and the viewer): fixed, then sweeping, then stopped.
    steered = sim.segments[0]
    assert [float(steered.at(t).p0[0]) for t in (1.0, 2.0, 3.0, 6.0)] == pytest.approx([8.0, 8.0, 6.0, 2.5])
    assert [(until, piece.velocity.tolist()) for until, piece in steered.pieces()] == [
        (2.0, [0.0, 0.0]),
        (pytest.approx(4.75), [-2.0, 0.0]),
    ]
    # The contact at 4.75 came while it swept at 2 onto the disc at rest: the speed of approach in its frame is 2
    # (not 0, as the motion it has now would say).
    first, *later = [c for c in ds.contacts(sim) if c.kind == "segment"]
    assert first.time == pytest.approx(4.75) and first.speed == pytest.approx(2.0, rel=1e-12)
    assert later and all(c.speed == pytest.approx(4.0, rel=1e-12) for c in later)  # it came back at 4: stopped


def test_a_steered_segment_remembers_its_motions():
    s = ds.Segment((0.0, 0.0), (0.0, 1.0))
    moved = s.steered(2.0, (1.0, 0.0)).steered(4.0, (0.0, -0.5))
    assert [moved.at(t).p0.tolist() for t in (0.0, 2.0, 3.0, 4.0, 6.0)] == [
        [0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, -1.0]
    ]  # fmt: skip
    assert moved.moving and repr(moved) == "Segment([2.0, 2.0], [2.0, 3.0], velocity=[0.0, -0.5])"
    assert [until for until, _ in moved.pieces()] == [2.0, 4.0] and s.pieces() == []
    with pytest.raises(ds.DiscsimError, match="velocity must be 2 finite numbers"):
        s.steered(1.0, (math.nan, 0.0))


def test_steering_a_segment_is_refused_by_name_and_changes_nothing():
    sim = ds.EventDriven(
        ball(2.0, 5.0), BOX, segments=[ds.Segment((8.0, 3.0), (8.0, 7.0))], gravity=(0.0, -1.0), restitution=0.8
    )
    with pytest.raises(InvalidArgumentError, match="segments\\[0\\]"):
        sim.set_segment_velocity(0, (1.0, 0.0))
    assert not sim.segments[0].moving
    with pytest.raises(InvalidArgumentError, match="segment index 3"):
        sim.set_segment_velocity(3, (1.0, 0.0))
    with pytest.raises(InvalidArgumentError, match="velocity"):
        sim.set_segment_velocity(0, (float("inf"), 0.0))
    with pytest.raises(InvalidArgumentError, match="FixedStep cannot change a segment"):
        ds.FixedStep(ball(2.0, 5.0), BOX, segments=[ds.Segment((8.0, 3.0), (8.0, 7.0))]).set_segment_velocity(0, (1, 0))


def test_under_gravity_a_ball_on_a_conveyor_bounces_as_on_a_fixed_floor_seen_from_the_belt():
    # Galilean invariance with gravity: the belt y = 2 moving at u = 0.5 along x; in its frame the ball bounces as on
    # a fixed floor with its velocity less u (straight up and down here): the same times, velocities differing by u.
    g = (0.0, -2.0)
    belt = ds.Segment((-5.0, 2.0), (15.0, 2.0), velocity=(0.5, 0.0))
    moving = ds.EventDriven(ball(3.0, 5.0, 0.5, 0.0), ds.Box(12.0, 10.0), segments=[belt], gravity=g)
    fixed = ds.EventDriven(
        ball(3.0, 5.0, 0.0, 0.0), ds.Box(12.0, 10.0), segments=[ds.Segment((-5.0, 2.0), (15.0, 2.0))], gravity=g
    )
    for _ in range(3):  # three bounces on the belt, none on a wall
        a, b = moving.step(), fixed.step()
        assert a.kind == b.kind == "wall" and a.time == pytest.approx(b.time, rel=1e-13)
        assert moving.velocities[0] == pytest.approx(fixed.velocities[0] + [0.5, 0.0], rel=1e-12, abs=1e-12)
    assert a.time == pytest.approx(math.sqrt(2 * 2.5 / 2.0) * 5, rel=1e-12)  # fall 2.5, then two full hops


def test_a_rising_platform_meets_a_falling_ball_and_sends_it_up_at_2u_minus_v():
    # The ball falls from y = 8 (g = 1); the platform y = 1 + 0.5 t rises: 7.5 - t^2 / 2 = 1.5 + 0.5 t... its rim
    # at y - 0.5 meets the platform when 8 - t^2 / 2 - 0.5 = 1 + 0.5 t, t = (-0.5 + sqrt(0.25 + 13)) / 1.
    platform = ds.Segment((2.0, 1.0), (8.0, 1.0), velocity=(0.0, 0.5))
    sim = ds.EventDriven(ball(5.0, 8.0), BOX, segments=[platform], gravity=(0.0, -1.0))
    event = sim.step()
    t = -0.5 + math.sqrt(0.25 + 13.0)
    assert (event.kind, event.time) == ("wall", pytest.approx(t, rel=1e-13))
    assert sim.velocities[0] == pytest.approx([0.0, 2 * 0.5 + t], rel=1e-13)
    assert not sim.resting[0]


def test_a_rising_platform_wakes_a_disc_at_rest_and_what_rests_on_it_falls():
    # Disc 0 rests on a post (an obstacle), disc 1 on disc 0. A platform rising at 1 from y = 2 meets disc 0 with its
    # end point (4.6, 2 + t) at t = 1.7 (0.4^2 + 0.3^2 = 0.5^2), normal (0.8, 0.6): in the platform's frame the disc
    # comes at (0, -1) and leaves at (0.96, -0.28); in the box at (0.96, 0.72). Disc 1, its support gone, falls.
    discs = ds.Discs([[5.0, 3.0], [5.0, 4.0], [5.0, 5.0]], np.zeros((3, 2)), radii=0.5, masses=[math.inf, 1.0, 1.0])
    platform = ds.Segment((3.0, 2.0), (4.6, 2.0), velocity=(0.0, 1.0))
    sim = ds.EventDriven(discs, BOX, segments=[platform], gravity=(0.0, -1.0))
    sim.run(until=0.1)
    assert sim.resting.tolist() == [False, True, True]
    event = sim.step()
    assert (event.kind, event.i, event.time) == ("wall", 1, pytest.approx(1.7, rel=1e-13))
    assert sim.velocities[1] == pytest.approx([0.96, 0.72], rel=1e-12)
    assert sim.resting.tolist() == [False, False, False]
    assert sim.events[-1]["kind"] == int(ds.EventKind.SET) and sim.events[-1]["i"] == 2  # it falls from here
    sim.run(until=event.time + 0.2)  # (disc 1, rising, knocks it up at once)
    assert not sim.resting[2] and sim.velocities[2, 1] != 0.0


def test_under_drag_a_disc_meets_a_moving_wall_at_the_exact_time():
    # x(t) = 2 + (3 / gamma) (1 - exp(-gamma t)) (radius 0.5) against the wall 9 - 0.5 t: bisect the gap's root.
    gamma = 0.4
    wall = ds.Segment((9.0, 1.0), (9.0, 9.0), velocity=(-0.5, 0.0))
    sim = ds.EventDriven(ball(2.0, 5.0, 3.0, 0.0), BOX, segments=[wall], drag=gamma)
    event = sim.step()

    def gap(t):
        return 9.0 - 0.5 * t - (2.5 + 3.0 / gamma * (1.0 - math.exp(-gamma * t)))

    lo, hi = 0.0, 20.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if gap(mid) > 0 else (lo, mid)
    assert event.time == pytest.approx(lo, rel=1e-12)
    v = 3.0 * math.exp(-gamma * lo)
    assert sim.velocities[0, 0] == pytest.approx(2 * -0.5 - v, rel=1e-12)


def test_a_rough_disc_bounces_off_a_moving_segment_as_off_a_fixed_one_from_its_frame():
    u = np.array([0.0, 0.7])
    wall = [ds.Segment((6.0, 0.5), (6.0, 9.5), velocity=u)]
    spin = ds.Discs([[3.0, 5.0]], [[1.0, 0.4]], radii=0.5, spins=[2.0])
    moving = ds.EventDriven(spin, BOX, segments=wall, roughness=0.6)
    still = ds.EventDriven(
        ds.Discs([[3.0, 5.0]], [[1.0, 0.4 - 0.7]], radii=0.5, spins=[2.0]), BOX,
        segments=[ds.Segment((6.0, 0.5), (6.0, 9.5))], roughness=0.6,
    )  # fmt: skip
    a, b = moving.step(), still.step()
    assert a.time == pytest.approx(b.time, rel=1e-13)
    assert moving.velocities[0] == pytest.approx(still.velocities[0] + u, rel=1e-12)
    assert moving.spins[0] == pytest.approx(still.spins[0], rel=1e-12) and moving.spins[0] != 2.0


@pytest.mark.slow
def test_a_box_of_four_moving_segments_closes_slowly_on_a_gas_and_heats_it_along_the_adiabat():
    # Four walls closing at a speed far below the gas's: a slow compression, dK = -P dA with P = Z K / A, so
    # ln(K1 / K0) = integral of Z(eta) / eta from eta0 to eta1: halving the side (eta x4) multiplies K by 4 for an
    # ideal gas (P A^2 = const), by more for hard discs (Henderson's Z). The walls overlap at the corners.
    discs, box = ds.random_gas(60, 0.02, seed=3, periodic=False)
    side, u = box.width, 0.002
    walls = [
        ds.Segment((0.0, 0.0), (0.0, side), velocity=(u, 0.0)),
        ds.Segment((side, 0.0), (side, side), velocity=(-u, 0.0)),
        ds.Segment((0.0, 0.0), (side, 0.0), velocity=(0.0, u)),
        ds.Segment((0.0, side), (side, side), velocity=(0.0, -u)),
    ]
    margin = float(discs.radii.max()) * 1.01
    inside = np.all((discs.positions > margin) & (discs.positions < side - margin), axis=1)
    discs = ds.Discs(discs.positions[inside], discs.velocities[inside], radii=discs.radii[inside])
    sim = ds.EventDriven(discs, box, segments=walls)
    k0 = sim.kinetic_energy()
    t_half = side / 4 / u  # each wall has moved a quarter of the side: the square's side is halved
    sim.run(until=t_half)
    # The ideal part over the area the centres can reach, (side - 2r)^2, the hard discs' part from Henderson's Z.
    r = float(discs.radii[0])
    ideal = ((side - 2 * r) / (side / 2 - 2 * r)) ** 2
    eta0 = float(np.sum(np.pi * discs.radii**2)) / side**2
    eta = np.linspace(eta0, 4.0 * eta0, 2001)
    f = (ds.henderson_z(eta) - 1.0) / eta
    expected = ideal * math.exp(float(np.sum((f[1:] + f[:-1]) * np.diff(eta)) / 2.0))
    assert expected > 4.5  # (the walls' reach and the discs' own area both show)
    assert sim.kinetic_energy() / k0 == pytest.approx(expected, rel=0.02)
    lo, hi = u * t_half, side - u * t_half
    assert ((sim.positions > lo) & (sim.positions < hi)).all()
