"""``discsim demo``: the study's four PIT failure cases under PIC (exact) and PIT (fixed step).

Prints one comparison row per case and writes a figure per case, all four in one figure and an animation of
the multiple-collisions case to a folder; then one row per case under the laws of motion
(:func:`discsim.scenarios.law_cases`: a ball bouncing to rest under gravity with restitution, a ball falling at
its terminal velocity under drag), table only.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from discsim.cli._common import make_output_folder
from discsim.engines.fixed_step import POLICIES, SUB_FRAME_POLICIES

if TYPE_CHECKING:
    from discsim.analysis.compare import Comparison

#: Folder the demo writes to unless ``--out`` says otherwise.
DEFAULT_DEMO_DIR = "discsim-demo"
#: The demo's figure of all four cases, one row each.
DEMO_GRID_FILE = "study_cases.png"


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``demo`` and its options to ``subparsers``; its handler is :func:`handle`."""
    parser = subparsers.add_parser(
        "demo",
        help="run the study's four PIT failure cases under PIC and PIT, print a table, write figures",
        description=(
            "Run the four cases of the collision-detection study (missed collision, wrong direction, "
            "multiple collisions, delay) with the exact event-driven engine (PIC) and the fixed-step "
            "engine (PIT) at each case's frame rate; print one comparison row per case; write one "
            f"PNG per case, all four in one figure ({DEMO_GRID_FILE}) and a GIF of the multiple-collisions case."
        ),
    )
    parser.add_argument(
        "--out", default=DEFAULT_DEMO_DIR, help=f"folder for the figures (default: {DEFAULT_DEMO_DIR}/)"
    )
    parser.add_argument(
        "--policy",
        default="resolve",
        choices=list(POLICIES),
        help="PIT's response to an overlap (default: resolve; bisect and swept find the contact inside the frame)",
    )
    parser.add_argument("--no-gif", action="store_true", help="skip the animation (faster)")
    parser.set_defaults(func=handle)


def failure(report: Comparison) -> str:
    """One phrase naming the worst of what PIT got wrong in a comparison."""
    if report.missed:
        return f"missed {report.missed} collision{'s' if report.missed > 1 else ''}"
    if report.spurious:
        return f"{report.spurious} spurious collision{'s' if report.spurious > 1 else ''}"
    if report.max_direction_error >= 10.0:
        return f"direction off by {report.max_direction_error:.1f} deg"
    if report.max_delay > 1e-9 * max(1.0, report.horizon):  # beyond roundoff
        return f"late by {report.max_delay:.3g}"
    return "none"


def demo_table(rows: Sequence[tuple[str, float, Comparison]]) -> str:
    """The comparison table: a header, a rule and one row per ``(case name, frame rate, report)``."""
    header = (
        "case",
        "fps",
        "PIC coll",
        "PIT coll",
        "matched",
        "missed",
        "max delay",
        "max dir err",
        "max pos err",
        "overlap",
        "PIT failure",
    )
    body = []
    for name, rate, r in rows:
        body.append(
            (
                name,
                f"{rate:g}",
                str(r.truth_collisions),
                str(r.approx_collisions),
                str(r.matched),
                str(r.missed),
                f"{r.max_delay:.4f}",
                f"{r.max_direction_error:.1f} deg",
                f"{r.position_error_max:.3f}",
                f"{r.max_overlap:.0%}",
                failure(r),
            )
        )
    widths = [max(len(h), *(len(b[k]) for b in body)) for k, h in enumerate(header)]
    lines = [header, tuple("-" * w for w in widths), *body]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in lines)


def law_table(rows: Sequence[tuple[str, float, Comparison]]) -> str:
    """The table of the cases under the laws: bounces (wall hits), their delays and rebound heights, energy."""
    header = ("case", "fps", "PIC hits", "PIT hits", "matched", "max delay", "max rebound err", "PIT energy err")
    body = [
        (
            name,
            f"{rate:g}",
            str(r.truth_wall_hits),
            str(r.approx_wall_hits),
            str(len(r.wall_matches)),
            f"{r.max_wall_delay:.4f}",
            f"{r.max_rebound_error:.3f}",
            f"{r.approx_energy_error:+.2e}",
        )
        for name, rate, r in rows
    ]
    widths = [max(len(h), *(len(b[k]) for b in body)) for k, h in enumerate(header)]
    lines = [header, tuple("-" * w for w in widths), *body]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in lines)


def handle(args: argparse.Namespace) -> int:
    """Run the four cases, print the table, write the figures into ``args.out``; return the exit code."""
    import discsim as ds
    from discsim import plot

    out = Path(args.out)
    if not make_output_folder("demo", out):
        return 1
    rows, written, grid = [], [], []
    gif_runs = None
    for number, case in enumerate(ds.study_cases(), start=1):
        pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
        pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=args.policy).run(until=case.until)
        report = ds.compare(pic, pit)
        rows.append((case.name, case.frame_rate, report))
        fig = plot.plot_case(pic, pit, title=f"Case {number}, {case.name}: {case.description}")
        written.append(plot.save_figure(fig, out / f"case{number}_{case.name}.png"))
        grid.append((pic, pit, f"Case {number}, {case.name}: {failure(report)}"))
        if case.name == "multiple_collisions":
            gif_runs = (number, case, pit, pic)
    fig = plot.plot_cases(grid)
    fig.suptitle(f"The study's four cases: PIT ({args.policy}, left) against PIC (exact, right)", fontsize=12)
    written.append(plot.save_figure(fig, out / DEMO_GRID_FILE))
    if gif_runs is not None and not args.no_gif:
        number, case, pit, pic = gif_runs
        path = out / f"case{number}_{case.name}.gif"
        anim = plot.animate([pit, pic], path, fps=12, title=f"Case {number}: {case.name} (PIT left, PIC right)")
        plot.close(anim)
        written.append(path)
    print(f"The collision-detection study's four cases, PIT ({args.policy}) against PIC (exact):\n")
    print(demo_table(rows))
    if args.policy in SUB_FRAME_POLICIES:
        print(f"\nThe cases under gravity need a policy that answers at the frame ({args.policy!r} does not).")
    else:
        law_rows = []
        for case in ds.scenarios.law_cases():
            pic = ds.EventDriven(case.discs, case.box, **case.laws).run(until=case.until)
            pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=args.policy, **case.laws)
            law_rows.append((case.name, case.frame_rate, ds.compare(pic, pit.run(until=case.until))))
        print(f"\nUnder the laws of motion, PIT ({args.policy}) against PIC: bounces (wall hits) and energy:\n")
        print(law_table(law_rows))
    print(f"\nFigures written to {out.resolve()}:")
    for path in written:
        print(f"  {path.name}")
    return 0
