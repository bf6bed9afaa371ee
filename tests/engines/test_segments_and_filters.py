"""Segment walls and collision filtering in the event-driven engine."""

import math

import numpy as np
import pytest
from oracle import next_event

import discsim as ds
from discsim.kernels import segment_time_of_impact

pytestmark = pytest.mark.usefixtures("every_backend")  # every test once per backend


def test_disc_bounces_off_a_segment_face_at_the_exact_time():
    seg = ds.Segment((2.0, 5.0), (8.0, 5.0))
    discs = ds.Discs([[4.0, 1.0]], [[0.5, 2.0]], 1.0)
    sim = ds.EventDriven(discs, ds.Box(10.0, 10.0), segments=[seg])
    event = sim.step()
    assert event.kind == "wall"
    assert event.time == pytest.approx(1.5, rel=1e-14)  # y: 1 + 2 t = 4
    assert sim.velocities[0] == pytest.approx([0.5, -2.0], rel=1e-14)


def test_disc_bounces_off_a_segment_end_point_like_off_a_point():
    seg = ds.Segment((0.0, 5.0), (5.0, 5.0))
    # aim at the end point (5, 5) so that contact happens at 30 degrees off-centre
    n = np.array([math.cos(math.radians(-60)), math.sin(math.radians(-60))])  # from end point to centre
    v = np.array([0.0, 1.0])
    contact = np.array([5.0, 5.0]) + 1.0 * n
    start = contact - 2.0 * v
    sim = ds.EventDriven(ds.Discs([start], [v], 1.0), ds.Box(10.0, 10.0), segments=[seg])
    event = sim.step()
    assert event.time == pytest.approx(2.0, rel=1e-12)
    assert sim.velocities[0] == pytest.approx(v - 2 * np.dot(v, n) * n, abs=1e-12)


def _triangle_gas(n=25, seed=0):
    vertices = np.array([[1.0, 1.0], [29.0, 1.0], [15.0, 26.0]])
    rng = np.random.default_rng(seed)
    segments = ds.polygon(vertices)
    pos = []
    while len(pos) < n:
        p = rng.uniform(2, 28, size=2)
        inside = all(_signed_distance(p, vertices[k], vertices[(k + 1) % 3]) > 0.6 for k in range(3))
        if inside and all(np.hypot(*(p - q)) > 1.01 for q in pos):
            pos.append(p)
    discs = ds.Discs(np.array(pos), rng.normal(size=(n, 2)), 0.5)
    return discs, segments, vertices


def _signed_distance(p, a, b):
    e = b - a
    normal = np.array([-e[1], e[0]]) / np.hypot(*e)  # inward for counter-clockwise vertices
    return float(np.dot(p - a, normal))


def test_gas_in_a_triangle_never_leaves_it_and_conserves_energy():
    discs, segments, vertices = _triangle_gas()
    sim = ds.EventDriven(discs, ds.Box(30.0, 30.0), segments=segments)
    e0 = sim.kinetic_energy()
    for _ in range(40):
        sim.run(events=100)
        for p in sim.positions:
            for k in range(3):
                assert _signed_distance(p, vertices[k], vertices[(k + 1) % 3]) >= 0.5 * (1 - 1e-9)
    assert sim.counts["wall_hits"] > 100
    assert sim.kinetic_energy() == pytest.approx(e0, rel=1e-12)


def test_segments_follow_the_oracle_in_lock_step():
    discs, segments, _ = _triangle_gas(seed=1)
    sim = ds.EventDriven(discs, ds.Box(30.0, 30.0), segments=segments)
    exclude = set()
    for _ in range(300):
        t0 = sim.time
        dt, kind, i, j = next_event(
            sim.positions, sim.velocities, discs.radii, discs.masses, sim.box, exclude, segments=segments
        )
        event = sim.step()
        assert event.time == pytest.approx(t0 + dt, rel=1e-9, abs=1e-9)
        assert (event.kind, {event.i, event.j}) == (kind, {i, j})
        if kind == "collision":
            exclude = {frozenset((i, j))}
        else:  # which segment was hit: the one the disc now touches
            p = sim.positions[event.i]
            k = int(np.argmin([s.distance(p)[0] for s in segments]))
            exclude = {frozenset((event.i, -2 - k))}


def test_segment_time_agrees_with_bisection_of_the_distance():
    rng = np.random.default_rng(5)
    seg = ds.Segment((0.0, 0.0), (4.0, 1.0))
    for _ in range(200):
        p, v, r = rng.uniform(-6, 8, size=2), rng.normal(size=2) * 3, rng.uniform(0.2, 1.5)
        if seg.distance(p)[0] <= r:
            continue
        t = segment_time_of_impact(*p, *v, r, *seg.p0, *seg.p1)
        grid = np.linspace(0, 20, 20001)
        dist = seg.distance(p + grid[:, None] * v)
        touching = np.flatnonzero(dist <= r)
        if touching.size == 0:
            assert math.isinf(t) or seg.distance(p + t * v)[0] == pytest.approx(r, rel=1e-6)
        else:
            assert t == pytest.approx(grid[touching[0]], abs=2e-3)
            assert seg.distance(p + t * v)[0] == pytest.approx(r, rel=1e-9)


def test_discs_cut_by_a_segment_are_refused():
    discs = ds.Discs([[5.0, 5.2]], [[0.0, 0.0]], 0.5)
    with pytest.raises(ds.OutsideBoxError, match="disc 0 .* cut by segment 0"):
        ds.EventDriven(discs, ds.Box(10.0, 10.0), segments=[ds.Segment((0, 5), (10, 5))])
    with pytest.raises(ValueError, match="segments need a box with walls"):
        ds.EventDriven(discs, ds.Box(10.0, 10.0, periodic=True), segments=[ds.Segment((0, 1), (10, 1))])
    with pytest.raises(ds.InvalidDiscsError, match="end points must differ"):
        ds.Segment((1, 1), (1, 1))


def test_bullets_pass_through_each_other_but_hit_targets():
    # Two bullets (group 1) fired at each other head on, and a target (group 0) behind one of them.
    pos = [[2.0, 5.0], [12.0, 5.0], [18.0, 5.0]]
    vel = [[3.0, 0.0], [-3.0, 0.0], [0.0, 0.0]]
    discs = ds.Discs(pos, vel, 0.5, groups=[1, 1, 0])
    sim = ds.EventDriven(discs, ds.Box(20.0, 10.0), pass_through={(1, 1)})
    sim.run(until=5.5)  # bullet 0 reaches the target (contact at x = 17) at t = 5
    ev = sim.events
    pairs = {frozenset((int(a), int(b))) for a, b in zip(ev["i"], ev["j"]) if b >= 0}
    assert frozenset((0, 1)) not in pairs
    assert frozenset((0, 2)) in pairs  # bullet 0 flies through bullet 1 and hits the target
    # without the filter the bullets collide first
    plain = ds.EventDriven(ds.Discs(pos, vel, 0.5, groups=[1, 1, 0]), ds.Box(20.0, 10.0)).run(until=3.0)
    first = plain.events[0]
    assert {int(first["i"]), int(first["j"])} == {0, 1}


@pytest.mark.slow_on_python
def test_filtered_gas_follows_the_oracle_and_allows_overlaps_within_passing_groups():
    discs, box = ds.random_gas(40, 0.3, seed=8)
    groups = np.arange(40) % 3
    # groups 1 and 2 ignore each other; group 0 collides with everyone
    filtered = ds.Discs(discs.positions, discs.velocities, discs.radii, groups=groups)
    rules = {(1, 2), (2, 2)}
    sim = ds.EventDriven(filtered, box, pass_through=rules)
    exclude = set()
    normalized = {tuple(sorted(p)) for p in rules}
    for _ in range(300):
        t0 = sim.time
        dt, _, i, j = next_event(
            sim.positions,
            sim.velocities,
            discs.radii,
            discs.masses,
            box,
            exclude,
            groups=groups,
            pass_through=normalized,
        )
        event = sim.step()
        assert event.time == pytest.approx(t0 + dt, rel=1e-9, abs=1e-9)
        assert {event.i, event.j} == {i, j}
        g = sorted((groups[event.i], groups[event.j]))
        assert tuple(g) not in normalized
        exclude = {frozenset((i, j))}
    # overlapping discs of passing groups are a valid start
    two = ds.Discs([[5.0, 5.0], [5.3, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], 0.5, groups=[2, 2])
    ds.EventDriven(two, ds.Box(10, 10), pass_through=rules).run(until=1.0)
    with pytest.raises(ds.OverlapError):
        ds.EventDriven(two, ds.Box(10, 10))
