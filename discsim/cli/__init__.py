"""The command line: ``python -m discsim <command>`` and the ``discsim`` console script.

One module per command, each with ``add_parser(subparsers)`` (its options, and its handler as the parser's
``func`` default) and ``handle(args)`` (what it does, returning an exit code); :func:`build_parser` calls every
``add_parser`` in turn. A new command is a new module, its import below and one entry in :data:`_COMMANDS`.

Commands:
    demo (:mod:`discsim.cli.demo`): run the study's four PIT failure cases under PIC (exact) and PIT
        (fixed step), print a comparison table, and write a figure per case plus an animation of one case to
        a folder.
    run (:mod:`discsim.cli.run`): a long event-driven run of a hard-disc gas with a progress bar, periodic
        checkpoints, a streamed event log and ``--resume``; prints collisions, collisions/s, energy drift,
        pressure and Z at the end (:mod:`discsim.cli.summary`).
    sweep (:mod:`discsim.cli.sweep`): run a task over a grid of parameters and seeds from a TOML spec, on a
        local pool or a dask cluster, cached and resumable (:func:`discsim.sweep`); writes the table as CSV
        (and Parquet).
    view (:mod:`discsim.cli.view`): write a self-contained HTML page that replays a run folder (or event log,
        or checkpoint) exactly in a browser (:func:`discsim.view`).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from os import PathLike

from discsim.cli.demo import DEFAULT_DEMO_DIR, DEMO_GRID_FILE
from discsim.cli.demo import add_parser as _add_demo_parser
from discsim.cli.run import DEFAULT_CHECKPOINT_EVERY, RUN_FILES
from discsim.cli.run import add_parser as _add_run_parser
from discsim.cli.sweep import SWEEP_FILES
from discsim.cli.sweep import add_parser as _add_sweep_parser
from discsim.cli.view import DEFAULT_VIEW_FILE
from discsim.cli.view import add_parser as _add_view_parser
from discsim.errors import DiscsimError

__all__ = [
    "DEFAULT_CHECKPOINT_EVERY",
    "DEFAULT_DEMO_DIR",
    "DEFAULT_VIEW_FILE",
    "DEMO_GRID_FILE",
    "RUN_FILES",
    "SWEEP_FILES",
    "build_parser",
    "main",
]

#: Each command's ``add_parser``, in the order ``--help`` lists them.
_COMMANDS = (_add_demo_parser, _add_run_parser, _add_sweep_parser, _add_view_parser)


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


def main(argv: Sequence[str | PathLike[str]] | None = None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``) and return the exit code.

    Exit codes: 0 on success, 1 when the command failed, 2 on a usage error, 130 when interrupted (Ctrl-C).

    Example:
        >>> main([])  # no command: prints the help to stderr
        2
    """
    parser = build_parser()
    args = parser.parse_args(None if argv is None else [str(a) for a in argv])
    if getattr(args, "func", None) is None:
        parser.print_help(sys.stderr)
        return 2
    try:
        return int(args.func(args))
    except KeyboardInterrupt:  # Ctrl-C where a command does not answer it itself (a start-up, a file written)
        print(f"discsim {args.command}: interrupted (Ctrl-C)", file=sys.stderr)
        return 130
    except DiscsimError as exc:  # what a command does not answer itself: a message, never a traceback
        print(f"discsim {args.command}: {exc}", file=sys.stderr)
        return 1
