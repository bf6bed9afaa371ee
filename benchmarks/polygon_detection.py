"""The study's comparison for spinning polygons: PIT, sub-frame bisection and swept volumes against the true contact.

Run ``python benchmarks/polygon_detection.py`` (a few minutes) or ``--quick`` (seconds). Issue 33, item 3: the
study (``docs/study.md``) compares, for discs, the periodic interference test (PIT) with the exact prediction
(PIC); for objects that turn it suggests sub-frame bisection and swept volumes. This script measures the three on
pairs of regular polygons (squares, hexagons, 12-gons, circumradius 1) closing head-on at relative speed 2 from a
random gap (0.05-1.5 between their circumcircles), a random sideways offset, random orientations and spins of a
given turn per frame ``a`` (either sign) at frames of ``dt = 0.1``, over 3 time units. The truth is the brute-force
first contact (:func:`discsim.analysis.polygon_detection.reference_contact`: the overlap sampled finer than any
contact here lasts, then bisected).

Columns, as printed and written to ``polygon_detection.csv`` in ``--results`` (with ``polygon_detection.png``: the
miss rate and the swept volumes' false alarms against the turn per frame):

* ``contacts``: pairs that touch within the span (the truth).
* ``pit missed``: of those, the share whose first contact PIT never sees at a frame (it finds a later overlap, or
  none); bisection misses the same ones (it refines only what PIT saw).
* ``pit depth``: the mean overlap when PIT sees it (a fraction of the circumradius); ``pit late``: the mean delay
  after the true contact, in frames.
* ``bisect err``: the largest ``|t - truth|`` of bisection where PIT saw the first contact (its tolerance 1e-9).
* ``swept alarms``: of all pairs, the share whose swept regions meet in a frame before the one holding the contact
  (a false alarm; a pair that never touches counts if any frame is flagged); swept volumes miss none.
* ``tests/frame``: separating-axis tests per frame: PIT 1; bisection adds its steps at the frame it refines; the
  swept test is one test of two hulls per frame (larger polygons).
* ``PIC = truth``: the share of pairs whose certified time of impact
  (:func:`discsim.physics.polygons.polygon_time_of_impact`, compiled) equals the brute-force time to 1e-9 (both
  none counts); ``PIC us/pair``: what it cost, microseconds per pair (one prediction, no frames).
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
from benchutils import Column, format_table, machine_summary, parse_args, write_csv

from discsim._compiled import compile_from_source, jit
from discsim._numba import available
from discsim.analysis.polygon_detection import bisect_contact, pit_contact, reference_contact, swept_contact
from discsim.physics import polygons as parts
from discsim.polygons import Polygons, regular_polygon

# The certified time of impact, compiled by numba from the parts' source (plain Python without numba).
TOI = (
    compile_from_source(parts.PARTS, jit)[parts.polygon_time_of_impact] if available() else parts.polygon_time_of_impact
)

DT = 0.1
HORIZON = 3.0
SIDES = (4, 6, 12)
TURNS = (0.1, 0.3, 0.6, 1.2, 2.4)  # radians per frame
KEYS = ["sides", "turn", "pairs", "contacts", "pit_missed", "pit_depth", "pit_late", "bisect_err", "swept_alarms",
        "bisect_tests_per_frame", "pic_agrees", "pic_us", "seconds"]  # fmt: skip
COLUMNS = [
    Column("sides", "sides", "d"),
    Column("turn", "turn/frame", ".1f"),
    Column("contacts", "contacts", "d"),
    Column("pit_missed", "pit missed", ".3f"),
    Column("pit_depth", "pit depth", ".3f"),
    Column("pit_late", "pit late", ".2f"),
    Column("bisect_err", "bisect err", ".1e"),
    Column("swept_alarms", "swept alarms", ".3f"),
    Column("bisect_tests_per_frame", "tests/frame (bisect)", ".2f"),
    Column("pic_agrees", "PIC = truth", ".3f"),
    Column("pic_us", "PIC us/pair", ".1f"),
    Column("seconds", "seconds", ".1f"),
]


def pair(rng: np.random.Generator, sides: int, turn: float) -> Polygons:
    gap = rng.uniform(0.05, 1.5)
    spins = rng.choice([-1.0, 1.0], size=2) * turn / DT
    return Polygons(
        regular_polygon(sides, 1.0),
        [[0.0, 0.0], [2.0 + gap, rng.uniform(-1.2, 1.2)]],
        angles=rng.uniform(0.0, 2.0 * math.pi, size=2),
        velocities=[[1.0, 0.0], [-1.0, 0.0]],
        spins=spins,
    )


def certified_contact(bodies: Polygons) -> float:
    """The first contact of the pair by the certified time of impact (:mod:`discsim.physics.polygons`)."""
    (a, b), (pa, pb), (va, vb) = bodies.vertices, bodies.positions, bodies.velocities
    ta, tb = bodies.angles
    wa, wb = bodies.spins
    return TOI(a, pa[0], pa[1], ta, va[0], va[1], wa, b, pb[0], pb[1], tb, vb[0], vb[1], wb, HORIZON)[0]


def measure(sides: int, turn: float, pairs: int, seed: int) -> dict:
    rng = np.random.default_rng([seed, sides, int(turn * 1000)])
    samples = int(max(2000.0, 400.0 * turn / DT))  # a step under a 40th of a radian at the fastest spin
    contacts = missed = alarms = agree = 0
    pic_seconds = 0.0
    depths, lates, errors, tests = [], [], [], []
    start = time.perf_counter()
    for _ in range(pairs):
        bodies = pair(rng, sides, turn)
        truth = reference_contact(bodies, 0, 1, HORIZON, samples=samples).time
        begin = time.perf_counter()
        certified = certified_contact(bodies)
        pic_seconds += time.perf_counter() - begin
        agree += certified == truth or abs(certified - truth) <= 1e-9
        frame_end = math.ceil(truth / DT - 1e-9) * DT if math.isfinite(truth) else math.inf
        swept = swept_contact(bodies, 0, 1, DT, HORIZON)
        alarms += swept.time < frame_end - 1e-9
        if not math.isfinite(truth):
            continue
        contacts += 1
        pit = pit_contact(bodies, 0, 1, DT, HORIZON)
        if pit.time > frame_end + 1e-9:
            missed += 1
            continue
        depths.append(pit.depth)
        lates.append((pit.time - truth) / DT)
        bisect = bisect_contact(bodies, 0, 1, DT, HORIZON, tol=1e-9)
        errors.append(abs(bisect.time - truth))
        tests.append(bisect.tests / (pit.time / DT))
    return {
        "sides": sides,
        "turn": turn,
        "pairs": pairs,
        "contacts": contacts,
        "pit_missed": missed / contacts if contacts else math.nan,
        "pit_depth": float(np.mean(depths)) if depths else math.nan,
        "pit_late": float(np.mean(lates)) if lates else math.nan,
        "bisect_err": float(np.max(errors)) if errors else math.nan,
        "swept_alarms": alarms / pairs,
        "bisect_tests_per_frame": float(np.mean(tests)) if tests else math.nan,
        "pic_agrees": agree / pairs,
        "pic_us": 1e6 * pic_seconds / pairs,
        "seconds": time.perf_counter() - start,
    }


def plot(rows: list[dict], path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for k, sides in enumerate(sorted({r["sides"] for r in rows})):
        mine = [r for r in rows if r["sides"] == sides]
        turns = [r["turn"] for r in mine]
        colour = f"C{k}"
        ax.plot(turns, [r["pit_missed"] for r in mine], "o-", color=colour, label=f"PIT missed, {sides}-gons")
        ax.plot(
            turns, [r["swept_alarms"] for r in mine], "s--", color=colour, label=f"swept false alarms, {sides}-gons"
        )
    ax.set_xlabel("turn per frame (rad)")
    ax.set_ylabel("share of pairs")
    ax.set_xscale("log")
    ax.set_title("Spinning polygons: PIT's misses, swept volumes' false alarms", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    args = parse_args(__doc__.splitlines()[0], argv)
    quick = args.quick
    sides, turns, pairs = ((4, 12), (0.3, 2.4), 8) if quick else (SIDES, TURNS, 80)
    print(machine_summary())
    certified_contact(pair(np.random.default_rng(0), 4, 0.3))  # (numba compiles it here, not in the first row)
    rows = [measure(s, a, pairs, seed=1) for s in sides for a in turns]
    print(format_table(rows, COLUMNS))
    folder = args.results
    name = "polygon_detection_quick" if quick else "polygon_detection"
    print(f"wrote {write_csv(folder / f'{name}.csv', rows, KEYS)}")
    plot(rows, folder / f"{name}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
