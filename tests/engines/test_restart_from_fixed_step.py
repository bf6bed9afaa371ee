"""Restarting an engine from a fixed-step snapshot (issue 19): ``Engine.from_snapshot(source, repair=...)``.

A fixed-step state may hold overlapping pairs and discs cut by a wall or a segment. By default the restart
refuses, naming every such disc (checked against a brute-force list); ``repair="push"`` moves them the least
needed (closed forms for one pair, one wall cut, an obstacle, a periodic pair; no cheaper valid move in a
random search), keeps the velocities, and the event-driven engine then runs valid (its invariants checked
along the run) under every backend.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import discsim as ds
from discsim.engines.event_driven.invariants import check
from discsim.repair import STOP, push_apart, violations


def brute_force_violations(discs, box, segments=(), tolerance=1e-9):
    """Every overlapping pair and every cut disc, O(N^2), by depth (the oracle of the refusal's list)."""
    pos, r = discs.positions, discs.radii
    pairs = []
    for i in range(len(r)):
        for j in range(i + 1, len(r)):
            d = box.minimum_image(pos[j] - pos[i])
            depth = r[i] + r[j] - math.hypot(*d)
            if depth > tolerance * (r[i] + r[j]):
                pairs.append((depth, i, j))
    cut = []
    for i in range(len(r)):
        reach = 0.0 if box.periodic else max(r[i] - pos[i].min(), (pos[i] + r[i] - box.size).max())
        for s in segments:
            reach = max(reach, r[i] - float(s.distance(pos[i][None])[0]))
        if reach > tolerance * r[i]:
            cut.append((reach, i))
    return sorted(pairs, reverse=True), sorted(cut, reverse=True)


def coarse(periodic: bool, seed: int = 1, segments=False):
    """A fixed-step run at a coarse step ("resolve" leaves the pairs and wall cuts it found where they were)."""
    discs, box = ds.random_gas(200, 0.5, periodic=periodic, seed=seed)
    options = {}
    if segments:
        w, h = box.width, box.height
        options["segments"] = ds.polygon([(0.3 * w, 0.3 * h), (0.7 * w, 0.3 * h), (0.5 * w, 0.7 * h)])
        keep = np.ones(len(discs), dtype=bool)
        for segment in options["segments"]:
            keep &= segment.distance(discs.positions) > discs.radii * 1.01
        discs = ds.Discs(discs.positions[keep], discs.velocities[keep], discs.radii[keep])
    return ds.FixedStep(discs, box, dt=0.2, policy="resolve", **options).run(until=3.0)


def assert_unchanged(sim, before):
    assert sim.time == before[0] and sim.counts == before[1] and sim.positions.tobytes() == before[2]


# --- the default: refuse, naming the discs ----------------------------------------------------------------------
@pytest.mark.parametrize("periodic", [False, True])
def test_the_default_refuses_naming_every_overlapping_pair_and_cut_disc(periodic):
    fs = coarse(periodic)
    before = (fs.time, fs.counts, fs.positions.tobytes())
    pairs, cut = brute_force_violations(fs.snapshot(), fs.box)
    assert len(pairs) > 20 and (periodic or len(cut) > 3)  # the coarse step left plenty
    with pytest.raises(ds.OverlapError) as caught:
        ds.EventDriven.from_snapshot(fs)
    text = str(caught.value)
    assert f"the snapshot of FixedStep at time {fs.time!r} is not a valid start" in text
    assert f"({len(pairs)} pairs)" in text and "repair='push'" in text
    for depth, i, j in pairs[:10]:  # the deepest ten, with their depths
        assert f"{i} and {j} by {depth:.6g}" in text
    if cut:
        assert f"({len(cut)} discs)" in text or len(cut) <= 10
        for reach, i in cut[:10]:
            assert f"{i} by {reach:.6g}" in text
    found = violations(fs.snapshot(), fs.box)
    assert found.pairs.tolist() == [[i, j] for _, i, j in pairs]
    assert found.cut.tolist() == [i for _, i in cut]
    assert_unchanged(fs, before)


def test_a_disc_cut_by_a_wall_alone_is_refused_as_outside_the_box():
    discs = ds.Discs([[3.0, 1.0]], [[2.0, 0.0]], 0.5)
    fs = ds.FixedStep(discs, ds.Box(4.0, 2.0), dt=0.5).run(frames=1)  # x = 4.0, past the wall at 3.5
    with pytest.raises(ds.OutsideBoxError, match=r"discs 0 by 0\.5 are cut by a wall or a segment"):
        ds.EventDriven.from_snapshot(fs)


def test_a_valid_snapshot_restarts_as_it_is_under_both_choices():
    discs, box = ds.random_gas(100, 0.4, seed=2)
    ed = ds.EventDriven(discs, box).run(until=3.0)
    for repair in ("refuse", "push"):
        sim = ds.EventDriven.from_snapshot(ed, repair=repair)
        assert sim.discs.positions.tobytes() == ed.positions.tobytes()
        assert sim.discs.velocities.tobytes() == ed.velocities.tobytes()
        assert sim.time == 0.0 and sim.counts["collisions"] == 0
        if repair == "push":
            assert sim.repair.sweeps == 0 and not len(sim.repair.moved) and "nothing to repair" in str(sim.repair)
        else:
            assert sim.repair is None
    assert ds.EventDriven(discs, box).repair is None


# --- push: the least moves --------------------------------------------------------------------------------------
@pytest.mark.parametrize(("masses", "shares"), [((1.0, 1.0), (0.5, 0.5)), ((1.0, 3.0), (0.75, 0.25))])
def test_one_pair_moves_apart_along_its_line_of_centres_in_inverse_proportion_to_the_masses(masses, shares):
    angle = 0.7
    u = np.array([math.cos(angle), math.sin(angle)])
    a = np.array([5.0, 5.0])
    depth = 0.3
    discs = ds.Discs([a, a + (2.0 - depth) * u], [[0.3, -1.0], [1.5, 0.2]], radii=1.0, masses=list(masses))
    done = push_apart(discs, ds.Box(10.0, 10.0))
    np.testing.assert_allclose(done.displacements[0], -shares[0] * depth * u, rtol=0, atol=1e-15)
    np.testing.assert_allclose(done.displacements[1], shares[1] * depth * u, rtol=0, atol=1e-15)
    gap = done.discs.positions[1] - done.discs.positions[0]
    assert math.hypot(*gap) == pytest.approx(2.0, rel=1e-15)  # just touching
    assert done.discs.velocities.tobytes() == discs.velocities.tobytes()
    assert done.sweeps == 1 and done.found.pairs.tolist() == [[0, 1]]
    # No valid move is cheaper (kinetic metric sum m |dr|^2): a random search around the answer.
    m = np.array(masses)
    cost = float(m @ (done.distances**2))
    rng = np.random.default_rng(0)
    trial = done.displacements[None] + rng.normal(scale=0.05, size=(200_000, 2, 2))
    gap = (discs.positions[1] + trial[:, 1]) - (discs.positions[0] + trial[:, 0])
    valid = np.hypot(gap[:, 0], gap[:, 1]) >= 2.0
    costs = (m[None, :] * (trial**2).sum(axis=2)).sum(axis=1)
    assert valid.sum() > 10_000 and costs[valid].min() >= cost


def test_an_obstacle_stays_and_the_other_disc_moves_the_whole_depth():
    discs = ds.Discs([[5.0, 5.0], [6.5, 5.0]], [[0.0, 0.0], [1.0, 0.0]], radii=1.0, masses=[math.inf, 2.0])
    done = push_apart(discs, ds.Box(10.0, 10.0))
    assert done.displacements.tolist() == [[0.0, 0.0], [0.5, 0.0]]


def test_a_wall_cut_disc_moves_along_the_normal_to_touch_the_wall():
    discs = ds.Discs([[0.7, 5.0], [9.2, 9.9]], [[-1.0, 0.0], [1.0, 1.0]], radii=1.0)
    done = push_apart(discs, ds.Box(10.0, 10.0))
    np.testing.assert_allclose(done.displacements, [[0.3, 0.0], [-0.2, -0.9]], rtol=0, atol=1e-15)
    assert done.discs.positions.tolist() == [[1.0, 5.0], [9.0, 9.0]]  # touching the walls, a corner for disc 1


def test_a_pair_across_a_periodic_edge_moves_along_the_minimum_image_and_stays_wrapped():
    discs = ds.Discs([[0.4, 5.0], [9.1, 5.0]], [[0.0, 0.0], [0.0, 0.0]], radii=1.0)  # 1.3 apart through x = 0
    done = push_apart(discs, ds.Box(10.0, 10.0, periodic=True))
    np.testing.assert_allclose(done.displacements, [[0.35, 0.0], [-0.35, 0.0]], rtol=0, atol=1e-14)
    np.testing.assert_allclose(done.discs.positions, [[0.75, 5.0], [8.75, 5.0]], rtol=0, atol=1e-14)


def test_a_segment_cut_disc_moves_out_on_its_centres_side():
    segment = ds.Segment((2.0, 5.0), (8.0, 5.0))
    discs = ds.Discs([[4.0, 5.6], [6.0, 4.2]], [[0.0, -1.0], [0.0, 1.0]], radii=1.0)
    done = push_apart(discs, ds.Box(10.0, 10.0), segments=[segment])
    np.testing.assert_allclose(done.displacements, [[0.0, 0.4], [0.0, -0.2]], rtol=0, atol=1e-14)


def test_discs_of_groups_that_pass_through_each_other_are_not_pushed():
    discs = ds.Discs([[4.0, 5.0], [5.0, 5.0]], [[0.0, 0.0], [0.0, 0.0]], radii=1.0, groups=[1, 1])
    done = push_apart(discs, ds.Box(10.0, 10.0), pass_through={(1, 1)})
    assert done.sweeps == 0 and not done.displacements.any()
    sim = ds.EventDriven.from_snapshot(discs, ds.Box(10.0, 10.0), pass_through={(1, 1)})
    assert sim.pass_through == frozenset({(1, 1)})


# --- push: a coarse fixed-step run restarts and runs valid ---------------------------------------------------------
@pytest.mark.parametrize(("periodic", "segments"), [(False, False), (True, False), (False, True)])
def test_a_coarse_fixed_step_run_restarts_event_driven_and_runs_valid(periodic, segments, every_backend):
    fs = coarse(periodic, segments=segments)
    snapshot = fs.snapshot()
    pairs, cut = brute_force_violations(snapshot, fs.box, fs.segments)
    assert len(pairs) > 10 and (periodic or len(cut) > 0)
    sim = ds.EventDriven.from_snapshot(fs, repair="push")
    assert sim.backend == every_backend and sim.segments == fs.segments
    report = sim.repair
    # The report is the move made; the discs not involved did not move, to the bit; velocities are kept.
    np.testing.assert_allclose(fs.box.minimum_image(sim.discs.positions - snapshot.positions), report.displacements)
    still = report.distances == 0.0
    assert sim.discs.positions[still].tobytes() == snapshot.positions[still].tobytes()
    assert sim.discs.velocities.tobytes() == snapshot.velocities.tobytes()
    moved = set(report.moved.tolist())
    assert all(i in moved or j in moved for _, i, j in pairs) and {i for _, i in cut} <= moved
    assert report.distances.max() < 1.5 * max([d for d, *_ in pairs] + [d for d, _ in cut])
    assert not violations(sim.discs, sim.box, segments=sim.segments, tolerance=STOP)
    assert f"moved {len(report.moved)} discs" in str(report)
    check(sim)
    energy = sim.kinetic_energy()
    for _ in range(10):
        sim.run(events=300)
        check(sim)
    assert sim.counts["collisions"] > 1000 and sim.kinetic_energy() == pytest.approx(energy, rel=1e-12)


def test_a_fixed_step_engine_restarts_too_with_options_of_its_own():
    fs = coarse(periodic=True)
    finer = ds.FixedStep.from_snapshot(fs, repair="push", dt=0.01, policy="separate", record=False)
    assert finer.dt == 0.01 and finer.policy == "separate" and finer.record is False
    assert len(finer.repair.moved) > 10
    finer.run(until=1.0)
    assert finer.max_overlap < 0.05


def test_discs_and_their_box_restart_as_an_engine_does():
    fs = coarse(periodic=False)
    from_discs = ds.EventDriven.from_snapshot(fs.snapshot(), fs.box, repair="push")
    from_engine = ds.EventDriven.from_snapshot(fs, repair="push")
    assert from_discs.discs.positions.tobytes() == from_engine.discs.positions.tobytes()


# --- bad input, named before anything changes ------------------------------------------------------------------
@pytest.mark.parametrize(
    ("call", "error", "named"),
    [
        (lambda fs: ds.EventDriven.from_snapshot(fs, repair="fix"), ds.InvalidArgumentError, "'fix'"),
        (lambda fs: ds.EventDriven.from_snapshot(fs, repair=None), ds.InvalidArgumentError, "None"),
        (lambda fs: ds.EventDriven.from_snapshot(fs.snapshot()), ds.InvalidArgumentError, "needs their box"),
        (lambda fs: ds.EventDriven.from_snapshot(fs, ds.Box(50.0, 50.0)), ds.InvalidArgumentError, "50"),
        (lambda fs: ds.EventDriven.from_snapshot(fs, segments=[]), ds.InvalidArgumentError, "segments=[]"),
        (
            lambda fs: ds.EventDriven.from_snapshot(fs, pass_through={(0, 0)}),
            ds.InvalidArgumentError,
            "pass_through={(0, 0)}",
        ),
        (lambda fs: ds.EventDriven.from_snapshot([[1.0, 2.0]]), ds.WrongTypeError, "list"),
        (lambda fs: ds.EventDriven.from_snapshot(fs, repair="push", queue="fifo"), ds.InvalidArgumentError, "fifo"),
    ],
)
def test_bad_arguments_are_named_and_the_source_is_left_as_it_was(call, error, named):
    fs = coarse(periodic=False)
    before = (fs.time, fs.counts, fs.positions.tobytes())
    with pytest.raises(error) as caught:
        call(fs)
    assert named in str(caught.value)
    assert_unchanged(fs, before)


@pytest.mark.parametrize(
    ("discs", "segments", "error", "named"),
    [
        (ds.Discs([[4.0, 5.0], [5.0, 5.0]], [[0, 0], [0, 0]], 1.0, [math.inf] * 2), (), ds.OverlapError, "0 and 1"),
        (ds.Discs([[0.5, 5.0]], [[0, 0]], 1.0, math.inf), (), ds.OutsideBoxError, "disc 0 is an obstacle"),
        (ds.Discs([[5.0, 5.0]], [[0, 1]], 1.0), (ds.Segment((2, 5), (8, 5)),), ds.OutsideBoxError, "centre on"),
        (ds.Discs([[5.0, 5.0]], [[0, 1]], 6.0), (), ds.OutsideBoxError, "wider than the box"),
    ],
)
def test_what_no_move_repairs_is_refused_naming_the_discs(discs, segments, error, named):
    with pytest.raises(error, match=named):
        ds.EventDriven.from_snapshot(discs, ds.Box(10.0, 10.0), repair="push", segments=segments)


def test_a_box_too_small_for_the_discs_is_refused_after_the_sweeps(monkeypatch):
    import discsim.repair as repair

    monkeypatch.setattr(repair, "MAX_SWEEPS", 50)
    positions = [[1.0 + 0.5 * k, 2.0] for k in range(7)]  # seven discs of diameter 2 in a 4 x 4 box
    discs = ds.Discs(positions, np.zeros((7, 2)), 1.0)
    with pytest.raises(ds.OverlapError, match="no valid state in 50 sweeps"):
        push_apart(discs, ds.Box(4.0, 4.0))
