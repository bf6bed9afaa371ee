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
    cut = [line for line in map(where_log_stops, args.source) if line is not None]
    for line, records in cut:
        if not records:  # nothing whole to replay: say where the log stops, not that the run recorded nothing
            print(f"discsim view: {line}; nothing to replay", file=sys.stderr)
            return 1
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
    for line, _ in cut:
        print(f"  note: {line}; the page replays the run up to there", file=sys.stderr)
    return 0


def where_log_stops(source: str) -> tuple[str, int] | None:
    """For a run folder, checkpoint or event log whose log is cut short (or damaged): a line saying where the
    log stops, and the events before that; None when the log is whole (or there is none to look at).

    Reads only the log's block lengths and chunk headers (:func:`discsim.io.container.stream_extent`).
    """
    import discsim as ds
    from discsim.cli.run import RUN_FILES
    from discsim.io.container import STATE_MAGIC, stream_extent

    path = Path(source)
    log: Path | None = path
    checkpoint: Path | None = None
    if path.is_dir():
        log, checkpoint = path / RUN_FILES["events"], path / RUN_FILES["checkpoint"]
    elif path.is_file():
        with path.open("rb") as handle:
            if handle.read(len(STATE_MAGIC)) == STATE_MAGIC:
                log, checkpoint = None, path
    try:
        stream = ds.checkpoint_info(checkpoint)["stream"] if checkpoint and checkpoint.is_file() else None
        if log is None and stream is not None:
            log = Path(stream["path"])
            log = log if log.exists() else path.parent / log.name
        if log is None or not log.is_file():
            return None
        size = log.stat().st_size
        end, records, last = stream_extent(log)
    except (OSError, ds.DiscsimError):
        return None  # the viewer says what is wrong with it
    saw = stream.get("records", 0) if stream else 0
    if end == size and records >= saw:
        return None
    where = f"{log} stops at byte {end:,} of {size:,}"
    if stream and stream.get("end", 0) > size:
        where = f"{log} stops at byte {end:,} ({size:,} in the file, {stream['end']:,} when checkpointed)"
    until = f", up to t = {float(last['time']):g}" if "time" in last else ""
    line = f"{where}: cut short or damaged; its whole chunks hold {records:,} events{until}"
    if saw > records:
        line += f" (the checkpoint saw {saw:,})"
    return line, records
