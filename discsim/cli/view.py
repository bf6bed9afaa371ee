"""``discsim view``: a self-contained HTML page that replays a run exactly in a browser (:func:`discsim.view`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from discsim.cli._common import positive_int

#: The page ``discsim view`` writes into a run folder unless ``--path`` says otherwise.
DEFAULT_VIEW_FILE = "view.html"


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``view`` and its options to ``subparsers``; its handler is :func:`handle`."""
    parser = subparsers.add_parser(
        "view",
        help="write an HTML page that replays a run folder exactly in a browser (no network needed)",
        description=(
            "Write one self-contained HTML page that replays the exact motion of a run from its event log: "
            "play, pause, step, a time scrubber, any speed and frame rate, discs coloured by disc, group or "
            "speed. SOURCE is a folder written by `discsim run --out`, an event log or a checkpoint; give two "
            "(e.g. a PIT run and a PIC run) to see them side by side with the exact contacts marked."
        ),
    )
    parser.add_argument("source", nargs="+", help="run folder, event log (.dse) or checkpoint (.dsc)")
    parser.add_argument(
        "--path",
        default=None,
        help=f"the page to write (default: {DEFAULT_VIEW_FILE} in the run folder, or beside the file)",
    )
    parser.add_argument("--start", type=float, default=None, help="first simulated time shown (default: the start)")
    parser.add_argument(
        "--until",
        type=float,
        default=None,
        help="last simulated time shown (default: the end, or the first --max-events events from --start on)",
    )
    parser.add_argument("--colour", default="auto", choices=["auto", "disc", "group", "speed"], help="disc colours")
    parser.add_argument("--arrows", action="store_true", help="draw velocity arrows (the page can switch them)")
    parser.add_argument(
        "--max-events", type=positive_int, default=None, metavar="E", help="refuse pages holding more events"
    )
    parser.set_defaults(func=handle)


def handle(args: argparse.Namespace) -> int:
    """Write the page and say where; return the exit code."""
    import discsim as ds
    from discsim.view import DEFAULT_MAX_EVENTS, view

    first = Path(args.source[0])
    path = Path(args.path) if args.path else (first if first.is_dir() else first.parent) / DEFAULT_VIEW_FILE
    try:
        page = view(
            args.source if len(args.source) > 1 else args.source[0],
            path,
            colour=args.colour,
            start=args.start,
            until=args.until,
            max_events=args.max_events or DEFAULT_MAX_EVENTS,
            arrows=args.arrows,
        )
    except (ds.DiscsimError, OSError) as exc:
        print(f"discsim view: {exc}", file=sys.stderr)
        return 1
    t0, t1 = page.span
    if page.note:
        print(f"discsim view: {page.note}")
    print(f"discsim view: wrote {page.path} ({len(page.html):,} bytes, {page.events:,} events, t in [{t0:g}, {t1:g}])")
    print("  open it in a browser; Space plays and pauses, Left/Right step a frame, Shift+Left/Right an event")
    return 0
