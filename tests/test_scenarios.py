"""The study's four PIT failure cases and the set pieces: each fails under PIT as the study says, never under PIC."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds
from discsim import scenarios


def runs(case, policy="resolve", frame_rate=None):
    """PIC, a second PIC (other queue) and PIT of a scenario, each to its horizon."""
    pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
    pic2 = ds.EventDriven(case.discs, case.box, queue="heap").run(until=case.until)
    rate = case.frame_rate if frame_rate is None else frame_rate
    pit = ds.FixedStep(case.discs, case.box, frame_rate=rate, policy=policy).run(until=case.until)
    return pic, pic2, pit


def assert_pic_is_consistent(pic, pic2):
    """Two exact runs agree to roundoff, and PIC never lets discs overlap."""
    same = ds.compare(pic, pic2)
    assert same.missed == same.spurious == 0
    assert same.matched == pic.counts["collisions"]
    assert np.abs(same.delays).max(initial=0.0) < 1e-12
    assert same.position_error_max < 1e-9
    assert same.max_overlap < 1e-9 and same.truth_max_overlap < 1e-9
    assert abs(same.truth_energy_change) < 1e-12


def test_the_four_cases_come_in_the_study_order():
    cases = ds.study_cases()
    assert [c.name for c in cases] == ["missed_collision", "wrong_direction", "multiple_collisions", "delay"]
    for case in cases:
        assert case.description
        frames = case.until * case.frame_rate
        assert frames == pytest.approx(round(frames))  # the horizon is a whole number of frames
        assert case.dt == pytest.approx(1.0 / case.frame_rate)


@pytest.mark.parametrize("policy", ["resolve", "revert", "separate"])
def test_case1_pit_misses_the_collision(policy):
    case = scenarios.missed_collision()
    pic, pic2, pit = runs(case, policy)
    assert_pic_is_consistent(pic, pic2)
    assert pic.counts["collisions"] == 1
    report = ds.compare(pic, pit)
    assert report.truth_collisions == 1 and report.approx_collisions == 0
    assert report.missed == 1 and report.missed_collisions[0][:2] == (0, 1)
    assert report.missed_collisions[0][2] == pytest.approx(0.1367, abs=1e-4)
    # Disc 0 should have stopped near x = 5.1; under PIT it flew on to x = 13.
    assert report.position_error_final > 7.0
    # At a frame rate where a frame moves disc 0 less than a contact distance, PIT sees it.
    fine = ds.compare(pic, runs(case, policy, frame_rate=100.0)[2])
    assert fine.missed == 0 and fine.matched == 1


def test_case2_pit_sends_the_discs_off_in_wrong_directions():
    case = scenarios.wrong_direction()
    pic, pic2, pit = runs(case)
    assert_pic_is_consistent(pic, pic2)
    report = ds.compare(pic, pit)
    assert report.matched == 1 and report.missed == report.spurious == 0
    # The line of centres at contact makes atan(1.2 / 1.6) with x; at the detecting frame atan(1.2 / 0.6).
    turned = math.degrees(math.atan2(1.2, 0.6) - math.atan2(1.2, 1.6))
    assert turned == pytest.approx(26.565, abs=1e-3)
    np.testing.assert_allclose(report.direction_errors, [[turned, turned]], atol=1e-9)
    assert report.max_direction_error > 20.0  # the stated threshold
    assert report.max_delay == pytest.approx(0.6 - 2.6 / 6.0)
    # Exact outgoing velocities (equal masses, disc 1 at rest): along and across the line of centres.
    np.testing.assert_allclose(pic.velocities, [[2.16, -2.88], [3.84, 2.88]], atol=1e-12)
    np.testing.assert_allclose(pit.velocities, [[4.8, -2.4], [1.2, 2.4]], atol=1e-12)
    # The error is PIT's frame, not the engine: at 100 times the frame rate it is under a degree.
    fine = ds.compare(pic, runs(case, frame_rate=500.0)[2])
    assert fine.max_direction_error < 1.0


@pytest.mark.parametrize("policy", ["resolve", "separate"])
def test_case3_pit_misses_the_chains_second_collision(policy):
    case = scenarios.multiple_collisions()
    pic, pic2, pit = runs(case, policy)
    assert_pic_is_consistent(pic, pic2)
    ev = pic.events
    chain = [(min(int(e["i"]), int(e["j"])), max(int(e["i"]), int(e["j"]))) for e in ev[ev["kind"] == 0]]
    assert chain == [(0, 1), (1, 2)]  # disc 0 hits disc 1, which hits the static disc 2
    report = ds.compare(pic, pit)
    assert [m[:2] for m in report.matches] == [(0, 1)]  # found, late
    assert [m[:2] for m in report.missed_collisions] == [(1, 2)]  # the second link never happens
    assert report.missed_collisions[0][2] == pytest.approx(1.2667, abs=1e-4)
    assert report.max_delay > 0
    np.testing.assert_array_equal(pit.positions[2], case.discs.positions[2])  # the obstacle never moved


def test_case4_pit_responds_late_and_shifts_the_paths():
    case = scenarios.delay()
    pic, pic2, pit = runs(case)
    assert_pic_is_consistent(pic, pic2)
    report = ds.compare(pic, pit)
    assert report.matched == 1 and report.missed == report.spurious == 0
    contact = (10.0 - math.sqrt(4.0 - 0.3**2)) / 6.0  # closing speed 6, contact distance 2, offset 0.3
    assert report.matches[0][2] == pytest.approx(contact, abs=1e-12)
    delay = 1.4 - contact
    assert report.max_delay == pytest.approx(delay, abs=1e-12)
    assert report.max_delay > 0.05
    # Almost the right directions (the study: "almost the same direction") ...
    assert report.max_direction_error < 5.0
    # ... but the paths after the collision are shifted: before it the runs agree exactly,
    # after it each disc is behind by about 2 v delay (forward for delay, back for delay).
    before = report.times < contact
    assert report.position_errors[before].max() < 1e-12
    assert report.position_error_final > 1.5 * 3.0 * delay
    assert report.position_error_final == pytest.approx(2 * 3.0 * delay, rel=0.25)


@settings(max_examples=20, deadline=None)
@given(m1=st.floats(0.05, 20.0), m2=st.one_of(st.floats(0.05, 20.0), st.just(math.inf)))
def test_head_on_under_pic_gives_the_closed_form(m1, m2):
    case = ds.head_on(m1, m2)
    sim = ds.EventDriven(case.discs, case.box).run(until=case.until)
    u1, u2 = (-1.0, 0.0) if math.isinf(m2) else ((m1 - m2) / (m1 + m2), 2.0 * m1 / (m1 + m2))
    np.testing.assert_allclose(sim.velocities, [[u1, 0.0], [u2, 0.0]], atol=1e-12)
    (event,) = sim.events
    assert event["time"] == 2.0


def test_head_on_rejects_an_infinite_moving_mass():
    with pytest.raises(ds.InvalidDiscsError, match="disc 0 has infinite mass"):
        ds.head_on(math.inf, 1.0)
    with pytest.raises(ds.InvalidDiscsError, match="disc 1 has mass -1.0"):
        ds.head_on(1.0, -1.0)


@pytest.mark.parametrize("n", [2, 3, 6])
def test_newtons_cradle_under_pic_passes_the_momentum_at_once(n):
    case = ds.newtons_cradle(n)
    sim = ds.EventDriven(case.discs, case.box).run(until=case.until)
    ev = sim.events
    assert len(ev) == n - 1 and (ev["time"] == 2.0).all()
    expected = np.zeros((n, 2))
    expected[-1, 0] = 1.0
    np.testing.assert_allclose(sim.velocities, expected, atol=1e-12)
    np.testing.assert_allclose(sim.positions[-1], [6.0 + 2.0 * (n - 2) + case.until - 2.0, 2.0])


@pytest.mark.parametrize("bad", [1, 0, 2.5, True, "five", float("nan"), float("inf"), None])
def test_newtons_cradle_rejects_bad_sizes(bad):
    with pytest.raises(ValueError, match="n must be an integer >= 2"):
        ds.newtons_cradle(bad)


def test_billiard_break_racks_the_triangle_and_conserves_energy():
    case = ds.billiard_break()
    assert len(case.discs) == 16
    sim = ds.EventDriven(case.discs, case.box).run(until=case.until)
    assert sim.counts["collisions"] >= 15
    assert sim.kinetic_energy() == pytest.approx(case.discs.kinetic_energy(), rel=1e-12)
    small = ds.billiard_break(rows=2, speed=5.0)
    assert len(small.discs) == 4 and small.discs.velocities[0, 0] == 5.0
    for kwargs in (
        {"rows": 0},
        {"rows": 2.5},
        {"rows": "5"},
        {"speed": 0.0},
        {"speed": float("nan")},
        {"speed": "fast"},
    ):
        with pytest.raises(ValueError):
            ds.billiard_break(**kwargs)
