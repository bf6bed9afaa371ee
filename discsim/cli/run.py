"""``discsim run``: a long event-driven run of a hard-disc gas.

A progress bar, periodic checkpoints, an event log streamed to disk and ``--resume``; at the end it prints
and writes the physics summary (:mod:`discsim.cli.summary`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from discsim.cli._common import make_output_folder, non_negative_float, non_negative_int, positive_float, positive_int
from discsim.cli.summary import print_run_summary, run_summary

#: Files ``discsim run`` keeps in its output folder.
RUN_FILES = {
    "run": "run.json",  # what was asked: identifies the run, so --resume never mixes two runs
    "checkpoint": "state.dsc",  # the whole state, rewritten every --checkpoint-every events and at the end
    "events": "events.dse",  # the event log, streamed in checksummed chunks (ds.read_events)
    "summary": "summary.json",  # the figures printed at the end
}
#: What ``--backend`` accepts: the event loop's backends (``EventDriven(backend=...)``).
BACKENDS = ("auto", "python", "numba")
#: Physical events between checkpoints unless ``--checkpoint-every`` says otherwise.
DEFAULT_CHECKPOINT_EVERY = 1_000_000


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``run`` and its options to ``subparsers``; its handler is :func:`handle`."""
    parser = subparsers.add_parser(
        "run",
        help="a long event-driven run of a hard-disc gas, with progress, checkpoints and a streamed event log",
        description=(
            "Simulate N hard discs at a packing fraction up to a time, streaming every event to "
            f"OUT/{RUN_FILES['events']} and checkpointing to OUT/{RUN_FILES['checkpoint']}. Killed at any "
            "moment, the run continues with --resume and ends exactly where it would have ended. At the end "
            "it prints collisions, collisions/s, the energy drift, the pressure and Z = PA/NkT averaged from "
            "--since on (error bars from the series' correlation time, a warning if it still drifts) next to "
            "Henderson's equation of state, and writes them to "
            f"OUT/{RUN_FILES['summary']}."
        ),
    )
    parser.add_argument("--n", type=positive_int, required=True, help="number of discs")
    parser.add_argument("--packing", type=positive_float, required=True, help="packing fraction, in (0, 0.85]")
    parser.add_argument("--until", type=positive_float, required=True, help="simulated time to reach")
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="seed of the initial gas, 0 or more (default 0)"
    )
    parser.add_argument("--out", required=True, help="folder for the checkpoint, the event log and the summary")
    parser.add_argument(
        "--checkpoint-every",
        type=positive_int,
        default=DEFAULT_CHECKPOINT_EVERY,
        metavar="K",
        help=f"physical events between checkpoints (default {DEFAULT_CHECKPOINT_EVERY:,})",
    )
    parser.add_argument(
        "--resume", action="store_true", help="continue the run already in --out (refused if --out holds no run)"
    )
    parser.add_argument(
        "--backend",
        choices=BACKENDS,
        default="auto",
        help="the event loop: numba (compiled, the fast extra), python, or auto: numba when installed (default); "
        "a run may resume under another backend, with the same events",
    )
    walls = parser.add_mutually_exclusive_group()
    walls.add_argument("--periodic", dest="periodic", action="store_true", default=True, help="periodic box (default)")
    walls.add_argument("--walls", dest="periodic", action="store_false", help="box with reflecting walls")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument(
        "--since",
        type=non_negative_float,
        default=None,
        metavar="T",
        help="average P and Z from this time on (0 or more, before --until), skipping the melting of the starting "
        "lattice (default: a fifth of --until)",
    )
    parser.set_defaults(func=handle)


def write_json(path: Path, document: dict[str, Any]) -> None:
    """Write ``document`` as JSON atomically (temporary file, then ``os.replace``)."""
    import json

    from discsim.io.container import replacing

    with replacing(path) as tmp:
        tmp.write_text(json.dumps(document, indent=2) + "\n")


def run_identity(args: argparse.Namespace) -> dict[str, Any]:
    """What identifies a run (``run.json``): ``--resume`` continues only the same one."""
    return {"kind": "discsim run", "n": args.n, "packing": args.packing, "seed": args.seed, "periodic": args.periodic}


def prepare_run_folder(args: argparse.Namespace, out: Path, files: dict[str, Path]) -> str | None:
    """Check that ``out`` may receive this run; return an error message, or None when it may."""
    import json

    import discsim as ds

    ours = [files[k].name for k in ("run", "checkpoint", "events", "summary") if files[k].exists()]
    if ours and not args.resume:
        return (
            f"{out} already holds a run ({', '.join(ours)}); add --resume to continue it, "
            "or choose another --out (nothing was changed)"
        )
    if not ours:
        if args.resume:
            where = "is empty" if out.is_dir() else "does not exist"
            return (
                f"nothing to resume: {out} {where} (no {files['run'].name}, {files['checkpoint'].name} nor "
                f"{files['events'].name}); drop --resume to start a new run there (nothing was changed)"
            )
        return None
    try:
        recorded = json.loads(files["run"].read_text())
    except (OSError, ValueError) as exc:
        return f"{out} holds {', '.join(ours)} but no readable {files['run'].name} ({exc}); not resuming"
    asked = run_identity(args)
    if recorded != asked:
        diff = ", ".join(
            f"{k}={recorded.get(k)!r} there, {v!r} asked" for k, v in asked.items() if recorded.get(k) != v
        )
        return f"{out} holds a different run ({diff}); choose another --out (nothing was changed)"
    if files["checkpoint"].exists() and not files["events"].exists():
        try:
            stream = ds.checkpoint_info(files["checkpoint"])["stream"]
        except ds.CheckpointError as exc:
            return str(exc)
        if stream is not None:  # the run streamed its events: a resume would start a log without them
            return (
                f"{files['events']} is missing, but the checkpoint saw {stream.get('records', 0):,} events streamed "
                f"to it; resuming would leave them out of the log. Put the log back, or start a new run in another "
                "folder (nothing was changed)"
            )
    if not files["checkpoint"].exists() and files["events"].exists():
        # Killed between creating the log and the first checkpoint: only acceptable if the log is empty.
        try:
            if len(ds.read_events(files["events"], partial=True).events):
                return f"{files['events']} holds events but there is no checkpoint to resume from"
        except ds.CheckpointError:
            pass  # not even a complete header: nothing was recorded
        files["events"].unlink()
    return None


def handle(args: argparse.Namespace) -> int:
    """Start or resume the run in ``args.out``, print and write its summary; return the exit code."""
    import time

    import discsim as ds

    if args.since is not None and args.since >= args.until:
        print(f"discsim run: --since {args.since:g} must lie before --until {args.until:g}", file=sys.stderr)
        return 2
    out = Path(args.out)
    files = {key: out / name for key, name in RUN_FILES.items()}
    problem = prepare_run_folder(args, out, files)
    if problem is not None:
        print(f"discsim run: {problem}", file=sys.stderr)
        return 1
    resumed = files["checkpoint"].exists()
    try:
        if resumed:
            sim = ds.load(files["checkpoint"], backend=args.backend)
            if args.until < sim.time:
                print(
                    f"discsim run: the run in {out} is already at t = {sim.time:g}, past --until {args.until:g}",
                    file=sys.stderr,
                )
                return 1
        else:  # the discs first: a refused gas (--packing 0.9) leaves no folder behind
            discs, box = ds.random_gas(args.n, args.packing, periodic=args.periodic, seed=args.seed)
            sim = ds.EventDriven(discs, box, record=False, backend=args.backend)
            if not make_output_folder("run", out):
                return 1
            write_json(files["run"], run_identity(args))
        e0, collisions0 = sim.discs.kinetic_energy(), sim.counts["collisions"]
        start = time.perf_counter()
        sim.run(
            until=args.until,
            progress=not args.no_progress,
            record_to=files["events"],
            checkpoint=files["checkpoint"],
            checkpoint_every=args.checkpoint_every,
        )
        seconds = time.perf_counter() - start
    except ds.DiscsimError as exc:
        print(f"discsim run: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        if not files["run"].exists():  # stopped while placing the discs: nothing was written, nothing to resume
            print("\ndiscsim run: interrupted before anything was written; run the same command again", file=sys.stderr)
        else:
            print(
                f"\ndiscsim run: interrupted; continue with the same command and --resume (from {out})", file=sys.stderr
            )
        return 130
    except OSError as exc:  # a full disk, say: the last checkpoint is whole (files are replaced atomically)
        print(f"discsim run: {os_problem(exc, out)}", file=sys.stderr)
        return 1
    summary = run_summary(sim, args, run_identity(args), e0, collisions0, seconds, files)
    try:
        write_json(files["summary"], summary)
    except OSError as exc:
        print(f"discsim run: {os_problem(exc, out)}", file=sys.stderr)
        return 1
    print_run_summary(summary, resumed)
    return 0


def os_problem(exc: OSError, out: Path) -> str:
    """One line on a failed write: what failed, where, and how to go on."""
    what = exc.strerror or str(exc) or type(exc).__name__
    where = f" ({exc.filename})" if exc.filename else ""
    return (
        f"cannot write to {out}: {what}{where}; the last checkpoint there is intact: make room and continue "
        "with the same command and --resume"
    )
