"""The command line: ``python -m discsim <command>`` and the ``discsim`` console script.

Each command lives in two functions, ``_add_<command>_parser(subparsers)``
(its options) and ``_run_<command>(args)`` (what it does, returning an exit
code); :func:`build_parser` calls every ``_add_*_parser`` in turn. A new command
needs its own pair and one line in :data:`_COMMANDS`, nothing else.

Commands:
    demo: run the study's four PIT failure cases under PIC (exact) and PIT
        (fixed step), print a comparison table, and write a figure per case
        plus an animation of one case to a folder.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["build_parser", "main"]

#: Folder the demo writes to unless ``--out`` says otherwise.
DEFAULT_DEMO_DIR = "discsim-demo"


# --- demo ------------------------------------------------------------------------------------------------


def _add_demo_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "demo",
        help="run the study's four PIT failure cases under PIC and PIT, print a table, write figures",
        description=(
            "Run the four cases of the collision-detection study (missed collision, wrong direction, "
            "multiple collisions, delay) with the exact event-driven engine (PIC) and the fixed-step "
            "engine (PIT) at each case's frame rate; print one comparison row per case; write one "
            "PNG per case and a GIF of the multiple-collisions case."
        ),
    )
    parser.add_argument(
        "--out", default=DEFAULT_DEMO_DIR, help=f"folder for the figures (default: {DEFAULT_DEMO_DIR}/)"
    )
    parser.add_argument(
        "--policy",
        default="resolve",
        choices=["resolve", "revert", "separate"],
        help="PIT's response to an overlap (default: resolve)",
    )
    parser.add_argument("--no-gif", action="store_true", help="skip the animation (faster)")
    parser.set_defaults(func=_run_demo)


def _failure(report) -> str:
    """One phrase naming the worst of what PIT got wrong in a comparison."""
    if report.missed:
        return f"missed {report.missed} collision{'s' if report.missed > 1 else ''}"
    if report.spurious:
        return f"{report.spurious} spurious collision{'s' if report.spurious > 1 else ''}"
    if report.max_direction_error >= 10.0:
        return f"direction off by {report.max_direction_error:.1f} deg"
    if report.max_delay > 0:
        return f"late by {report.max_delay:.3g}"
    return "none"


def _demo_table(rows) -> str:
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
                _failure(r),
            )
        )
    widths = [max(len(h), *(len(b[k]) for b in body)) for k, h in enumerate(header)]
    lines = [header, tuple("-" * w for w in widths), *body]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in lines)


def _run_demo(args) -> int:
    import discsim as ds
    from discsim import plot

    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        print(f"discsim demo: cannot create the output folder {str(out)!r}: {exc}", file=sys.stderr)
        return 1
    rows, written = [], []
    gif_runs = None
    for number, case in enumerate(ds.study_cases(), start=1):
        pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
        pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=args.policy).run(until=case.until)
        report = ds.compare(pic, pit)
        rows.append((case.name, case.frame_rate, report))
        fig = plot.plot_case(pic, pit, title=f"Case {number}, {case.name}: {case.description}")
        written.append(plot.save_figure(fig, out / f"case{number}_{case.name}.png"))
        if case.name == "multiple_collisions":
            gif_runs = (number, case, pit, pic)
    if gif_runs is not None and not args.no_gif:
        number, case, pit, pic = gif_runs
        path = out / f"case{number}_{case.name}.gif"
        anim = plot.animate([pit, pic], path, fps=4, title=f"Case {number}: {case.name} (PIT left, PIC right)")
        plot.close(anim)
        written.append(path)
    print(f"The collision-detection study's four cases, PIT ({args.policy}) against PIC (exact):\n")
    print(_demo_table(rows))
    print(f"\nFigures written to {out.resolve()}:")
    for path in written:
        print(f"  {path.name}")
    return 0


# --- the parser ------------------------------------------------------------------------------------------

#: One ``_add_<command>_parser`` per command, in the order ``--help`` lists them.
_COMMANDS = (_add_demo_parser,)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand.

    Example:
        >>> build_parser().parse_args(["demo", "--out", "figs"]).out
        'figs'
    """
    parser = argparse.ArgumentParser(
        prog="discsim", description="Exact event-driven simulation of elastic hard discs in 2D."
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for add in _COMMANDS:
        add(subparsers)
    return parser


def main(argv=None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``) and return the exit code.

    Exit codes: 0 on success, 1 when the command failed, 2 on a usage error.

    Example:
        >>> main([])  # no command: prints the help to stderr
        2
    """
    parser = build_parser()
    args = parser.parse_args(None if argv is None else [str(a) for a in argv])
    if getattr(args, "func", None) is None:
        parser.print_help(sys.stderr)
        return 2
    return int(args.func(args))
