"""compare(): matching, the figures it reports, its input checks, and PIT's convergence on a dilute gas."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

import discsim as ds
from discsim.events import EVENT_DTYPE
from discsim.model import kinetic_energy
from discsim.trajectory import positions_from_log

NAN = math.nan


class Replay:
    """A stand-in engine that only replays a given log: the public protocol compare() reads, nothing else."""

    def __init__(self, discs, box, rows, time):
        self.discs, self.box = discs, box
        self.events = np.array(rows, dtype=EVENT_DTYPE)
        self.start_time, self.time = 0.0, time

    def trajectory(self, times, *, unwrapped=False):
        return positions_from_log(
            self.events, self.discs, self.box, 0.0, self.time, times, span="replayed span", unwrapped=unwrapped
        )

    @property
    def positions(self):
        return self.trajectory([self.time])[0]

    @property
    def velocities(self):
        vel = np.array(self.discs.velocities)
        for r in self.events:
            vel[r["i"]] = r["vxi"], r["vyi"]
            if r["j"] >= 0:
                vel[r["j"]] = r["vxj"], r["vyj"]
        return vel

    def kinetic_energy(self):
        return kinetic_energy(self.velocities, self.discs.masses)


def four_discs():
    discs = ds.Discs(
        [[1.0, 1.0], [4.0, 1.0], [1.0, 4.0], [4.0, 4.0]], [[1.0, 0.0], [0.0, 0.0], [0.0, 1.0], [0.0, 0.0]], radii=0.5
    )
    return discs, ds.Box(10.0, 10.0)


def collision(t, i, j, vi=(0.0, 0.0), vj=(1.0, 0.0)):
    """A collision record at ``t``; positions are irrelevant to the matching (the discs stop where they are)."""
    return (t, 0, i, j, 0.0, 0.0, *vi, 0.0, 0.0, *vj)


def test_matching_by_unordered_pair_and_nearest_time():
    discs, box = four_discs()
    truth = Replay(discs, box, [collision(1.0, 0, 1), collision(2.0, 2, 3), collision(3.0, 0, 1)], 5.0)
    approx = Replay(
        discs,
        box,
        [
            collision(1.05, 1, 0, vi=(1.0, 0.0), vj=(0.0, 0.0)),  # same pair, other order, 0.05 late
            collision(2.9, 0, 1),  # nearest to the truth's t = 3.0
            collision(4.0, 2, 3),  # 2.0 after the truth's: outside the window -> spurious, and 2-3 missed
        ],
        5.0,
    )
    report = ds.compare(truth, approx, window=0.5)
    assert report.matched == 2 and report.missed == 1 and report.spurious == 1
    assert [m[:2] for m in report.matches] == [(0, 1), (0, 1)]
    np.testing.assert_allclose(report.delays, [0.05, -0.1])
    assert report.missed_collisions == [(2, 3, 2.0)]
    assert report.spurious_collisions == [(2, 3, 4.0)]
    assert report.max_delay == pytest.approx(-0.1)  # signed, largest in size
    assert report.missed_fraction == pytest.approx(1 / 3)
    # Outgoing directions per disc: disc 0 stops (no direction: NaN), disc 1 goes the same way in both.
    np.testing.assert_allclose(report.direction_errors, [[NAN, 0.0], [NAN, 0.0]], atol=1e-12)
    # A window of 2 reaches the late 2-3 collision too.
    assert ds.compare(truth, approx, window=2.0).matched == 3


def test_direction_errors_per_disc_and_at_rest():
    discs, box = four_discs()
    truth = Replay(discs, box, [collision(1.0, 0, 1, vi=(0.0, 0.0), vj=(1.0, 0.0))], 2.0)
    approx = Replay(discs, box, [collision(1.1, 0, 1, vi=(0.0, 1.0), vj=(1.0, 1.0))], 2.0)
    report = ds.compare(truth, approx)
    # Disc 0 is at rest in the truth: no direction, NaN. Disc 1: 45 degrees off.
    assert math.isnan(report.direction_errors[0, 0])
    assert report.direction_errors[0, 1] == pytest.approx(45.0)
    assert report.max_direction_error == pytest.approx(45.0)
    data = report.to_dict()
    assert data["direction_errors"] == [[None, pytest.approx(45.0)]]
    json.dumps(data)  # plain, JSON-ready types


def test_default_window_is_two_frames_or_a_contact_distance_at_rms_speed():
    case = ds.scenarios.delay()
    pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    # rms speed 3, smallest contact distance 2 -> 2/3; two frames -> 0.4.
    assert ds.compare(pic, pit).window == pytest.approx(2.0 / 3.0)
    slow = ds.FixedStep(case.discs, case.box, frame_rate=1.0).run(until=2.0)
    pic2 = ds.EventDriven(case.discs, case.box).run(until=2.0)
    assert ds.compare(pic2, slow).window == pytest.approx(2.0)


def test_two_exact_runs_compare_clean_and_the_report_reads_well():
    discs, box = ds.random_gas(60, 0.3, seed=4)
    a = ds.EventDriven(discs, box).run(until=3.0)
    b = ds.EventDriven(discs, box, queue="heap").run(until=3.0)
    report = ds.compare(a, b)
    assert report.truth_collisions == report.approx_collisions == report.matched == a.counts["collisions"] > 20
    assert report.missed == report.spurious == 0
    assert report.position_error_max < 1e-9 and np.abs(report.delays).max() < 1e-12
    assert len(report.times) == 201  # no frame interval: evenly spaced samples
    text = str(report)
    for words in ("EventDriven against EventDriven", "matched", "missed 0", "position error", "kinetic energy"):
        assert words in text
    data = report.to_dict()
    assert data["matched"] == report.matched and len(data["matches"]) == report.matched
    assert json.loads(json.dumps(data))["missed"] == 0


def test_report_of_a_pit_run_names_what_went_wrong():
    case = ds.scenarios.multiple_collisions()
    pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    report = ds.compare(pic, pit)
    text = str(report)
    assert "FixedStep against EventDriven" in text
    assert "missed           1-2 at t=1.267" in text
    assert "direction error  max 26.6 deg" in text
    assert report.max_overlap == pytest.approx(pit.max_overlap) and report.max_overlap > 0.3
    summary = report.summary()
    assert summary["missed"] == 1 and summary["max_direction_error_deg"] == pytest.approx(26.565, abs=1e-3)
    np.testing.assert_allclose(report.times, np.arange(9) * 0.2, atol=1e-12)  # PIT's frame times


def test_runs_from_different_starts_are_refused():
    discs, box = four_discs()
    shift = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.25], [0.0, 0.0]])
    other = discs.replace(positions=discs.positions + shift)
    a = ds.EventDriven(discs, box).run(until=1.0)
    b = ds.EventDriven(other, box).run(until=1.0)
    with pytest.raises(ValueError, match=r"disc 2 has positions \[1\.0, 4\.0\] in truth but \[1\.0, 4\.25\]"):
        ds.compare(a, b)
    with pytest.raises(ValueError, match="different boxes"):
        ds.compare(a, ds.EventDriven(discs, ds.Box(11.0, 10.0)).run(until=1.0))
    with pytest.raises(ValueError, match="different numbers of discs"):
        ds.compare(a, ds.EventDriven(ds.Discs(discs.positions[:3], discs.velocities[:3], 0.5), box).run(until=1.0))
    with pytest.raises(ValueError, match="record=True"):
        ds.compare(a, ds.FixedStep(discs, box, record=False).run(until=1.0))
    with pytest.raises(ValueError, match="window must be"):
        ds.compare(a, a, window=-1.0)


def test_the_common_span_is_compared():
    case = ds.scenarios.delay()
    pic = ds.EventDriven(case.discs, case.box).run(until=2.0)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    report = ds.compare(pic, pit)
    assert report.horizon == 2.0 and report.times[-1] == pytest.approx(2.0)


def test_cradle_pit_lag_is_measured_exactly():
    # PIT passes the momentum one frame (0.1) per link: every resting disc ends 0.1 to the right
    # of where PIC leaves it, the last disc 4 frames (0.4) behind.
    case = ds.newtons_cradle(5)
    pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    report = ds.compare(pic, pit)
    assert report.position_error_final == pytest.approx(0.4, abs=1e-9)


def test_pit_converges_on_a_dilute_gas():
    """Missed fraction and position error fall to zero as the frame rate rises, the error like dt or faster.

    A dilute gas (packing fraction 0.05) of small discs (radius 0.05, rms speed sqrt(2)) over 0.25
    time units, about a tenth of the mean free time: 14 collisions, each disc in at most a few, so
    chaos has no time to amplify the errors. At 5 frames per unit time a frame moves a disc about
    three contact distances and PIT misses most collisions; at 320 and above it misses none, and the
    position error then falls in proportion to the frame interval (error / dt stays between about
    15 and 24 over a 256-fold range of rates). Measured at the frame times of each PIT run.
    """
    discs, box = ds.random_gas(100, 0.05, seed=2, radius=0.05)
    until = 0.25
    pic = ds.EventDriven(discs, box).run(until=until)
    assert pic.counts["collisions"] == 14
    rates = [5, 20, 80, 320, 1280, 5120, 20480]
    reports = [ds.compare(pic, ds.FixedStep(discs, box, frame_rate=r).run(until=until)) for r in rates]
    missed = [r.missed_fraction for r in reports]
    errors = np.array([r.position_error_max for r in reports])
    assert missed[0] > 0.5
    assert all(later <= earlier for earlier, later in itertools.pairwise(missed))
    assert missed[3:] == [0.0] * 4
    assert all(later < earlier for earlier, later in itertools.pairwise(errors[1:]))  # from 20 fps on
    assert errors[-1] < 0.2 * 0.05  # under a fifth of a radius
    assert errors[-1] < errors[0] / 100
    # At least first order: log-log slope of error against dt over the rates that miss nothing.
    dt = 1.0 / np.array(rates[3:], dtype=float)
    slope = np.polyfit(np.log(dt), np.log(errors[3:]), 1)[0]
    assert slope >= 0.9
    scaled = errors[2:] / (1.0 / np.array(rates[2:], dtype=float))
    assert scaled.max() / scaled.min() < 2.0  # error / dt bounded: error proportional to dt
    rms = np.array([r.position_error_rms for r in reports])
    assert rms[-1] < rms[2] / 100


def test_until_lets_a_detection_just_past_the_horizon_match():
    # Two discs meet at t = 0.95; PIT at 10 frames per unit time sees the overlap only at t = 1.0.
    discs = ds.Discs([[2.0, 5.0], [5.9, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], 1.0)
    box = ds.Box(20.0, 10.0)
    pic = ds.EventDriven(discs, box).run(until=1.2)
    pit = ds.FixedStep(discs, box, frame_rate=10.0).run(until=1.2)
    assert pic.events["time"][0] == pytest.approx(0.95)
    clipped = ds.compare(pic, pit, until=0.97, window=0.1)
    assert (clipped.truth_collisions, clipped.matched, clipped.missed, clipped.spurious) == (1, 1, 0, 0)
    assert clipped.delays[0] == pytest.approx(0.05)
    assert clipped.horizon == 0.97
    # without the grace the same horizon reads as a miss
    pic_short = ds.EventDriven(discs, box).run(until=0.97)
    pit_short = ds.FixedStep(discs, box, frame_rate=10.0).run(until=0.97)
    assert ds.compare(pic_short, pit_short, window=0.1).missed == 1
    with pytest.raises(ValueError, match="until=5.0 must lie within"):
        ds.compare(pic, pit, until=5.0)


def test_wall_hits_are_matched_per_disc_with_their_delays():
    discs = ds.Discs([[5.0, 5.0]], [[3.0, 0.0]], radii=1.0)
    pic = ds.EventDriven(discs, ds.Box(10.0, 10.0)).run(until=3.5)
    pit = ds.FixedStep(discs, ds.Box(10.0, 10.0), frame_rate=10.0).run(until=3.5)
    report = ds.compare(pic, pit)
    # The right wall at t = 4/3 (x + r = 9 + 1); PIT sees the disc past it at the next frame, t = 1.4.
    assert len(report.wall_matches) == 1 and not report.missed_wall_hits and not report.spurious_wall_hits
    i, t_truth, t_approx = report.wall_matches[0]
    assert i == 0 and t_truth == pytest.approx(4.0 / 3.0) and t_approx == pytest.approx(1.4)
    assert report.max_wall_delay == pytest.approx(1.4 - 4.0 / 3.0)
    assert math.isnan(report.max_rebound_error) and math.isnan(report.rebound_errors[0])  # no gravity
    assert report.truth_energy_error == report.truth_energy_change == 0.0
    summary = report.summary()
    assert summary["wall_matched"] == 1 and summary["max_wall_delay"] == pytest.approx(0.0667, abs=1e-4)
    assert json.loads(json.dumps(report.to_dict()))["rebound_errors"] == [None]
    text = str(report)
    assert "wall hits        matched 1, missed 0, spurious 0; delay max 0.06667" in text
    assert "rebound" not in text and "energy error" not in text
