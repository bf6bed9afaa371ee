"""Every PIT variant against PIC on the study's four cases (and a gas): what accuracy costs what work.

Run ``python benchmarks/pit_variants.py`` (about a minute) or ``--quick`` (seconds).

Variants: the exact event-driven engine (``PIC``, :class:`discsim.EventDriven`)
and the fixed-step engine (:class:`discsim.FixedStep`) under each policy:
``resolve``, ``revert`` and ``separate`` respond at the frame where an overlap
is found; ``bisect`` halves the frame interval with the interference test until
the contact time is known to ``bisect_tol`` (default ``1e-6 dt``) and responds
there; ``swept`` tests the relative motion over the frame (the swept capsule)
and responds at the analytic contact time. Each fixed-step run uses the case's
own frame rate (the one at which the study's failure shows).

Cases: the study's four (:func:`discsim.study_cases`: a missed collision, a
wrong direction, a missed second collision, a delay) and a periodic
:func:`discsim.random_gas` at packing fraction 0.3 (2000 discs over 2 time
units at 10 frames per unit time; 100 discs over 1 with ``--quick``), which
shows the costs at scale.

Columns, as printed and written to ``pit_variants.csv`` in ``--results``:

* ``collisions``: disc-disc collisions the variant logged (PIC: the truth).
* ``missed``, ``spurious``: collisions of the truth that the variant does not
  have, and the reverse, from :func:`discsim.analysis.compare` (same pair within its
  default window). In a gas, a missed collision sends the paths apart and
  ``compare`` then counts what follows as missed and spurious too.
* ``dir err``: largest error in degrees of a matched collision's outgoing
  directions; ``delay``: largest ``|t_variant - t_truth|`` of a matched
  collision, signed (negative: early); ``overlap``: deepest disc-disc overlap
  on the variant's path, as a fraction of the contact distance.
* ``pair tests``: the fixed-step engine's narrow-phase disc-disc checks
  (``counts["pair_tests"]``: distances at the frame, swept-volume tests, and
  the tests after a response inside a frame); ``bisections``: the interference
  tests bisection spends (``counts["bisection_tests"]``); ``predictions``: for
  PIC, the discs it re-predicted (each a time of impact against the discs of
  its 3x3 cells), its counterpart of the pair tests.
* ``seconds``: wall-clock seconds to build the engine and run the case (median
  of the repeats; a busy machine inflates them, see the load in the header).
"""

from __future__ import annotations

import dataclasses
import math
import sys

from benchutils import Column, announce, format_table, machine_summary, median, parse_args, timed, write_csv

import discsim as ds

#: The fixed-step policies compared, in the order of the table.
POLICIES = ("resolve", "revert", "separate", "bisect", "swept")


@dataclasses.dataclass(frozen=True)
class Config:
    """Sizes of one mode.

    Attributes:
        gas_n, gas_until, gas_rate: discs, horizon and frame rate of the gas case.
        repeats: timed runs per variant and case (median reported).
    """

    gas_n: int
    gas_until: float
    gas_rate: float
    repeats: int


FULL = Config(gas_n=2000, gas_until=2.0, gas_rate=10.0, repeats=5)
QUICK = Config(gas_n=100, gas_until=1.0, gas_rate=10.0, repeats=1)

COLUMNS = [
    Column("case", "case"),
    Column("variant", "variant"),
    Column("frame_rate", "frames/t", "g"),
    Column("collisions", "collisions"),
    Column("missed", "missed"),
    Column("spurious", "spurious"),
    Column("max_direction_error_deg", "dir err (deg)", ".3g"),
    Column("max_delay", "delay", ".3g"),
    Column("max_overlap", "overlap", ".3g"),
    Column("pair_tests", "pair tests", ",d"),
    Column("bisection_tests", "bisections", ",d"),
    Column("predictions", "predictions", ",d"),
    Column("seconds", "seconds", ".4f"),
]
CSV_KEYS = [c.key for c in COLUMNS] + ["matched", "truth_collisions", "position_error_max", "detections", "wall_hits"]


def cases(config: Config) -> list[ds.Scenario]:
    """The study's four cases and the gas case of this mode."""
    discs, box = ds.random_gas(config.gas_n, 0.3, periodic=True, seed=7)
    gas = ds.Scenario(
        discs,
        box,
        frame_rate=config.gas_rate,
        until=config.gas_until,
        name=f"gas_{config.gas_n}",
        description="A periodic gas at packing fraction 0.3.",
    )
    return [*ds.study_cases(), gas]


def measure(case: ds.Scenario, repeats: int) -> list[dict]:
    """One row per variant (PIC first) for ``case``."""
    builders = {"PIC": lambda: ds.EventDriven(case.discs, case.box).run(until=case.until)}
    for policy in POLICIES:
        builders[policy] = lambda policy=policy: ds.FixedStep(
            case.discs, case.box, frame_rate=case.frame_rate, policy=policy
        ).run(until=case.until)
    runs = {}
    seconds = {name: [] for name in builders}
    for _ in range(repeats):  # variants interleaved, so that a busy spell hits them alike
        for name, build in builders.items():
            timing = timed(build)
            seconds[name].append(timing.wall)
            runs[name] = timing.result
    truth = runs["PIC"]
    rows = []
    for name, sim in runs.items():
        report = ds.compare(truth, sim)
        row = {
            "case": case.name,
            "variant": name,
            "frame_rate": math.nan if name == "PIC" else case.frame_rate,
            "collisions": report.approx_collisions,
            "truth_collisions": report.truth_collisions,
            "matched": report.matched,
            "missed": report.missed,
            "spurious": report.spurious,
            "max_direction_error_deg": report.max_direction_error,
            "max_delay": report.max_delay,
            "max_overlap": report.max_overlap,
            "position_error_max": report.position_error_max,
            "seconds": median(seconds[name]),
        }
        if name == "PIC":
            row.update(predictions=sim.counts["predictions"], wall_hits=sim.counts["wall_hits"])
        else:
            row.update(
                pair_tests=sim.counts["pair_tests"],
                bisection_tests=sim.counts["bisection_tests"],
                detections=sim.counts["detections"],
                wall_hits=sim.counts["wall_hits"],
            )
        rows.append(row)
    return rows


def main(argv=None) -> int:
    """Measure every variant on every case, print the table, write the CSV; return the exit code."""
    args = parse_args(__doc__.splitlines()[0], argv)
    config = QUICK if args.quick else FULL
    if args.repeats is not None:
        config = dataclasses.replace(config, repeats=args.repeats)
    print(f"discsim {ds.__version__} PIT variants against PIC; {machine_summary()}")
    print(f"mode: {'quick' if args.quick else 'full'}, median of {config.repeats} run(s) per point")
    rows = []
    for case in cases(config):
        announce(f"{case.name} ...")
        rows.extend(measure(case, config.repeats))
    print()
    print(format_table(rows, COLUMNS))
    print(
        "\nmissed/spurious/dir err/delay/overlap from discsim.analysis.compare against PIC; pair tests and bisections"
        " from FixedStep.counts; predictions from EventDriven.counts; seconds: median wall-clock of build + run."
    )
    path = write_csv(args.results / "pit_variants.csv", rows, CSV_KEYS)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
