"""The command line: ``python -m discsim <command>`` and the ``discsim`` console script.

Each command lives in two functions, ``_add_<command>_parser(subparsers)``
(its options) and ``_run_<command>(args)`` (what it does, returning an exit
code); :func:`build_parser` calls every ``_add_*_parser`` in turn. A new command
needs its own pair and one line in :data:`_COMMANDS`, nothing else.

Commands:
    demo: run the study's four PIT failure cases under PIC (exact) and PIT
        (fixed step), print a comparison table, and write a figure per case
        plus an animation of one case to a folder.
    run: a long event-driven run of a hard-disc gas with a progress bar,
        periodic checkpoints, a streamed event log and ``--resume``; prints
        collisions, collisions/s, energy drift, pressure and Z at the end.
    sweep: run a task over a grid of parameters and seeds from a TOML spec, on a local pool or a dask
        cluster, cached and resumable (:func:`discsim.sweep`); writes the table as CSV (and Parquet).
    view: write a self-contained HTML page that replays a run folder (or event
        log, or checkpoint) exactly in a browser (:func:`discsim.view`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from discsim.engines.fixed_step import POLICIES

__all__ = ["build_parser", "main"]

#: Folder the demo writes to unless ``--out`` says otherwise.
DEFAULT_DEMO_DIR = "discsim-demo"
#: The demo's figure of all four cases, one row each.
DEMO_GRID_FILE = "study_cases.png"


# --- demo ------------------------------------------------------------------------------------------------


def _add_demo_parser(subparsers) -> None:
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
    parser.set_defaults(func=_run_demo)


def _failure(report) -> str:
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
    rows, written, grid = [], [], []
    gif_runs = None
    for number, case in enumerate(ds.study_cases(), start=1):
        pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
        pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=args.policy).run(until=case.until)
        report = ds.compare(pic, pit)
        rows.append((case.name, case.frame_rate, report))
        fig = plot.plot_case(pic, pit, title=f"Case {number}, {case.name}: {case.description}")
        written.append(plot.save_figure(fig, out / f"case{number}_{case.name}.png"))
        grid.append((pic, pit, f"Case {number}, {case.name}: {_failure(report)}"))
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
    print(_demo_table(rows))
    print(f"\nFigures written to {out.resolve()}:")
    for path in written:
        print(f"  {path.name}")
    return 0


# --- run -------------------------------------------------------------------------------------------------

#: Files ``discsim run`` keeps in its output folder.
RUN_FILES = {
    "run": "run.json",  # what was asked: identifies the run, so --resume never mixes two runs
    "checkpoint": "state.dsc",  # the whole state, rewritten every --checkpoint-every events and at the end
    "events": "events.dse",  # the event log, streamed in checksummed chunks (ds.read_events)
    "summary": "summary.json",  # the figures printed at the end
}
#: Physical events between checkpoints unless ``--checkpoint-every`` says otherwise.
DEFAULT_CHECKPOINT_EVERY = 1_000_000


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1 or str(value) != text.strip().lstrip("+"):
        msg = f"expected a positive integer, got {text!r}"
        raise argparse.ArgumentTypeError(msg)
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        msg = f"expected a positive finite number, got {text!r}"
        raise argparse.ArgumentTypeError(msg)
    return value


def _add_run_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "run",
        help="a long event-driven run of a hard-disc gas, with progress, checkpoints and a streamed event log",
        description=(
            "Simulate N hard discs at a packing fraction up to a time, streaming every event to "
            f"OUT/{RUN_FILES['events']} and checkpointing to OUT/{RUN_FILES['checkpoint']}. Killed at any "
            "moment, the run continues with --resume and ends exactly where it would have ended. At the end "
            "it prints collisions, collisions/s, the energy drift, the pressure and Z = PA/NkT averaged from "
            "--since on (with batch-means error bars) next to Henderson's equation of state, and writes them to "
            f"OUT/{RUN_FILES['summary']}."
        ),
    )
    parser.add_argument("--n", type=_positive_int, required=True, help="number of discs")
    parser.add_argument("--packing", type=_positive_float, required=True, help="packing fraction, in (0, 0.85]")
    parser.add_argument("--until", type=_positive_float, required=True, help="simulated time to reach")
    parser.add_argument("--seed", type=int, default=0, help="seed of the initial gas (default 0)")
    parser.add_argument("--out", required=True, help="folder for the checkpoint, the event log and the summary")
    parser.add_argument(
        "--checkpoint-every",
        type=_positive_int,
        default=DEFAULT_CHECKPOINT_EVERY,
        metavar="K",
        help=f"physical events between checkpoints (default {DEFAULT_CHECKPOINT_EVERY:,})",
    )
    parser.add_argument("--resume", action="store_true", help="continue the run already in --out")
    walls = parser.add_mutually_exclusive_group()
    walls.add_argument("--periodic", dest="periodic", action="store_true", default=True, help="periodic box (default)")
    walls.add_argument("--walls", dest="periodic", action="store_false", help="box with reflecting walls")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument(
        "--since",
        type=float,
        default=None,
        metavar="T",
        help="average P and Z from this time on, skipping the melting of the starting lattice "
        "(default: a fifth of --until)",
    )
    parser.set_defaults(func=_cmd_run)


def _write_json(path: Path, document: dict) -> None:
    """Write ``document`` as JSON atomically (temporary file, then ``os.replace``)."""
    import json
    import os

    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(document, indent=2) + "\n")
    os.replace(tmp, path)


def _run_identity(args) -> dict:
    return {"kind": "discsim run", "n": args.n, "packing": args.packing, "seed": args.seed, "periodic": args.periodic}


def _prepare_run_folder(args, out: Path, files: dict) -> str | None:
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
        return None
    try:
        recorded = json.loads(files["run"].read_text())
    except (OSError, ValueError) as exc:
        return f"{out} holds {', '.join(ours)} but no readable {files['run'].name} ({exc}); not resuming"
    asked = _run_identity(args)
    if recorded != asked:
        diff = ", ".join(
            f"{k}={recorded.get(k)!r} there, {v!r} asked" for k, v in asked.items() if recorded.get(k) != v
        )
        return f"{out} holds a different run ({diff}); choose another --out (nothing was changed)"
    if not files["checkpoint"].exists() and files["events"].exists():
        # Killed between creating the log and the first checkpoint: only acceptable if the log is empty.
        try:
            if len(ds.read_events(files["events"], partial=True).events):
                return f"{files['events']} holds events but there is no checkpoint to resume from"
        except ds.CheckpointError:
            pass  # not even a complete header: nothing was recorded
        files["events"].unlink()
    return None


def _run_summary(sim, args, e0: float, collisions0: int, seconds: float, files: dict) -> dict:
    import discsim as ds

    counts = sim.counts
    stream = ds.checkpoint_info(files["checkpoint"])["stream"] or {}
    records = stream.get("records", 0)
    size = files["events"].stat().st_size if files["events"].exists() else 0
    return {
        **_run_identity(args),
        "until": args.until,
        "time": sim.time,
        "collisions": counts["collisions"],
        "wall_hits": counts["wall_hits"],
        "session_seconds": seconds,
        "session_collisions": counts["collisions"] - collisions0,
        "collisions_per_s": (counts["collisions"] - collisions0) / seconds if seconds > 0 else float("nan"),
        "energy_drift": (sim.kinetic_energy() - e0) / e0,
        "max_overlap": sim.max_overlap,
        "pressure": sim.pressure() if sim.time > 0 else float("nan"),
        "Z_from_start": ds.compressibility_factor(sim) if sim.time > 0 else float("nan"),
        **_equilibrated(sim, args),
        "henderson_Z": float(ds.henderson_z(args.packing)),
        "events_on_disk": records,
        "bytes_per_event": size / records if records else float("nan"),
        "files": {k: str(v) for k, v in files.items()},
    }


def _equilibrated(sim, args) -> dict:
    """P and Z from ``--since`` on, with batch-means error bars (:func:`discsim.thermo`), read from the log on disk."""
    import discsim as ds

    since = args.until / 5.0 if args.since is None else args.since
    try:
        t = ds.thermo(sim, since=since)
    except ds.DiscsimError:  # --since outside the run, or a run of zero length
        nan = float("nan")
        return {"since": since, "Z": nan, "Z_err": nan, "pressure_since": nan, "pressure_err": nan}
    return {"since": t.since, "Z": t.z, "Z_err": t.z_err, "pressure_since": t.pressure, "pressure_err": t.pressure_err}


def _print_run_summary(s: dict, resumed: bool) -> None:
    box = "periodic box" if s["periodic"] else "box with walls"
    print(
        f"discsim run: N={s['n']}, packing {s['packing']:g}, {box}, seed {s['seed']}, t = {s['time']:g}"
        + (" (resumed)" if resumed else "")
    )
    rows = [
        ("collisions", f"{s['collisions']:,}", f"wall hits {s['wall_hits']:,}"),
        (
            "collisions/s",
            f"{s['collisions_per_s']:,.0f}",
            f"{s['session_collisions']:,} in {s['session_seconds']:.1f} s",
        ),
        ("energy drift", f"{s['energy_drift']:.2e}", "relative, since t = 0"),
        ("deepest overlap", f"{s['max_overlap']:.2e}", "fraction of the contact distance"),
        (
            "pressure P",
            f"{s['pressure_since']:.6g} ± {s['pressure_err']:.2g}",
            f"energy per area, collision virial since t = {s['since']:g} (batch means)",
        ),
        (
            "Z = PA/NkT",
            f"{s['Z']:.4f} ± {s['Z_err']:.4f}",
            f"Henderson: {s['henderson_Z']:.4f}; averaged from t = 0: {s['Z_from_start']:.4f}",
        ),
        ("events on disk", f"{s['events_on_disk']:,}", f"{s['bytes_per_event']:.1f} bytes/event"),
    ]
    for name, value, note in rows:
        print(f"  {name:<16}{value:>16}   {note}")
    print(
        f"  written to {Path(s['files']['checkpoint']).parent}: " + ", ".join(Path(p).name for p in s["files"].values())
    )


def _cmd_run(args) -> int:
    import time

    import discsim as ds

    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        print(f"discsim run: cannot create the output folder {str(out)!r}: {exc}", file=sys.stderr)
        return 1
    files = {key: out / name for key, name in RUN_FILES.items()}
    problem = _prepare_run_folder(args, out, files)
    if problem is not None:
        print(f"discsim run: {problem}", file=sys.stderr)
        return 1
    resumed = files["checkpoint"].exists()
    try:
        if resumed:
            sim = ds.load(files["checkpoint"])
            if args.until < sim.time:
                print(
                    f"discsim run: the run in {out} is already at t = {sim.time:g}, past --until {args.until:g}",
                    file=sys.stderr,
                )
                return 1
        else:
            discs, box = ds.random_gas(args.n, args.packing, periodic=args.periodic, seed=args.seed)
            sim = ds.EventDriven(discs, box, record=False)
            _write_json(files["run"], _run_identity(args))
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
        print(f"\ndiscsim run: interrupted; continue with the same command and --resume (from {out})", file=sys.stderr)
        return 130
    except OSError as exc:  # a full disk, say: the last checkpoint is whole (files are replaced atomically)
        print(f"discsim run: {_os_problem(exc, out)}", file=sys.stderr)
        return 1
    summary = _run_summary(sim, args, e0, collisions0, seconds, files)
    try:
        _write_json(files["summary"], summary)
    except OSError as exc:
        print(f"discsim run: {_os_problem(exc, out)}", file=sys.stderr)
        return 1
    _print_run_summary(summary, resumed)
    return 0


def _os_problem(exc: OSError, out: Path) -> str:
    """One line on a failed write: what failed, where, and how to go on."""
    what = exc.strerror or str(exc) or type(exc).__name__
    where = f" ({exc.filename})" if exc.filename else ""
    return (
        f"cannot write to {out}: {what}{where}; the last checkpoint there is intact: make room and continue "
        "with the same command and --resume"
    )


# --- view ------------------------------------------------------------------------------------------------

#: The page ``discsim view`` writes into a run folder unless ``--path`` says otherwise.
DEFAULT_VIEW_FILE = "view.html"


def _add_view_parser(subparsers) -> None:
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
    parser.add_argument("--until", type=float, default=None, help="last simulated time shown (default: the end)")
    parser.add_argument("--colour", default="auto", choices=["auto", "disc", "group", "speed"], help="disc colours")
    parser.add_argument(
        "--max-events", type=_positive_int, default=None, metavar="E", help="refuse pages holding more events"
    )
    parser.set_defaults(func=_run_view)


def _run_view(args) -> int:
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
        )
    except (ds.DiscsimError, OSError) as exc:
        print(f"discsim view: {exc}", file=sys.stderr)
        return 1
    t0, t1 = page.span
    print(f"discsim view: wrote {page.path} ({len(page.html):,} bytes, {page.events:,} events, t in [{t0:g}, {t1:g}])")
    print("  open it in a browser; Space plays and pauses, Left/Right step a frame, Shift+Left/Right an event")
    return 0


# --- sweep -----------------------------------------------------------------------------------------------

#: What ``discsim sweep`` writes into ``--out``.
SWEEP_FILES = {"cache": "cache", "csv": "sweep.csv", "parquet": "sweep.parquet", "failures": "failures.txt"}


def _add_sweep_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "sweep",
        help="run a task over a grid of parameters and seeds (local pool or dask), cached and resumable",
        description=(
            "Run the task a TOML spec names over its grid and seeds (see discsim.run.spec for the format) on "
            "a local process pool, or on a dask cluster with --scheduler. Every finished task is cached in "
            f"OUT/{SWEEP_FILES['cache']}/: run the same command again after a kill and only the missing tasks "
            f"run. The table goes to OUT/{SWEEP_FILES['csv']} (and OUT/{SWEEP_FILES['parquet']} when pyarrow is "
            f"installed); tasks that failed every attempt are listed with their tracebacks in "
            f"OUT/{SWEEP_FILES['failures']}, and the exit code is then 1."
        ),
    )
    parser.add_argument("spec", help="the sweep's TOML file: task, grid, seeds, root_seed, retries")
    parser.add_argument("--out", required=True, help="folder for the cache and the table")
    parser.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="a dask scheduler's address (e.g. tcp://host:8786), or 'local' for a dask LocalCluster here "
        "(default: a local process pool, no dask)",
    )
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="K",
        help="processes of the local pool or LocalCluster (default: the cores; 0: in this process)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.set_defaults(func=_run_sweep)


def _run_sweep(args) -> int:
    import warnings
    from contextlib import ExitStack

    import discsim as ds
    from discsim.run.spec import read_spec

    out = Path(args.out)
    try:
        spec = read_spec(args.spec)
    except ds.DiscsimError as exc:
        print(f"discsim sweep: {exc}", file=sys.stderr)
        return 1
    with ExitStack() as stack:
        client = None
        if args.scheduler is not None:
            try:
                from distributed import Client, LocalCluster
            except ImportError:
                need = 'discsim sweep: --scheduler needs dask.distributed: pip install "discsim[sweep]"'
                print(need, file=sys.stderr)
                return 1
            if args.scheduler == "local":
                cluster = LocalCluster(
                    n_workers=args.workers or None, threads_per_worker=1, processes=True, dashboard_address=":0"
                )
                stack.enter_context(cluster)
                client = stack.enter_context(Client(cluster))
            elif args.workers is not None:
                print("discsim sweep: --workers is for the local pool or --scheduler local", file=sys.stderr)
                return 2
            else:
                try:
                    client = stack.enter_context(Client(args.scheduler, timeout="30s"))
                except OSError as exc:
                    print(f"discsim sweep: cannot reach the scheduler {args.scheduler}: {exc}", file=sys.stderr)
                    return 1
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # failures are reported below
                table = ds.sweep(
                    spec.task,
                    spec.grid,
                    seeds=spec.seeds,
                    root_seed=spec.root_seed,
                    retries=spec.retries,
                    client=client,
                    workers=None if client is not None else args.workers,
                    cache=out / SWEEP_FILES["cache"],
                    progress=not args.no_progress,
                )
        except ds.Interrupted as exc:
            print(f"discsim sweep: {exc}; run the same command to finish it", file=sys.stderr)
            return 130
        except ds.DiscsimError as exc:
            print(f"discsim sweep: {exc}", file=sys.stderr)
            return 1
    return _write_sweep(table, out)


def _write_sweep(table, out: Path) -> int:
    import os

    info, failures = table.attrs["sweep"], table.attrs["failures"]
    csv = out / SWEEP_FILES["csv"]
    tmp = csv.with_name(f".{csv.name}.tmp")
    table.to_csv(tmp, index=False)
    os.replace(tmp, csv)
    written = [str(csv)]
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        pass
    else:
        parquet = out / SWEEP_FILES["parquet"]
        table.to_parquet(parquet, index=False)
        written.append(str(parquet))
    report = out / SWEEP_FILES["failures"]
    if failures:
        lines = []
        for f in failures:
            lines += [f"{f['params']} seed={f['seed']} ({f['attempts']} attempts): {f['error']}", f["traceback"], ""]
        report.write_text("\n".join(lines))
        written.append(str(report))
    else:
        report.unlink(missing_ok=True)
    print(
        f"discsim sweep: {info['tasks']} tasks ({info['ran']} ran, {info['cached']} from the cache, "
        f"{info['failed']} failed, {info['retries']} retries) in {info['seconds']:.1f} s on {info['where']}"
    )
    print(f"  wrote {', '.join(written)}")
    for f in failures:
        print(f"  failed: {f['params']} seed={f['seed']}: {f['error']}", file=sys.stderr)
    return 1 if failures else 0


# --- the parser ------------------------------------------------------------------------------------------

#: One ``_add_<command>_parser`` per command, in the order ``--help`` lists them.
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
