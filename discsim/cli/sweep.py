"""``discsim sweep``: a task over a grid of parameters and seeds from a TOML spec (:func:`discsim.sweep`).

On a local process pool or a dask cluster, cached and resumable; writes the table as CSV (and Parquet).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from discsim.cli._common import make_output_folder

if TYPE_CHECKING:
    import pandas as pd

#: What ``discsim sweep`` writes into ``--out``.
SWEEP_FILES = {"cache": "cache", "csv": "sweep.csv", "parquet": "sweep.parquet", "failures": "failures.txt"}


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``sweep`` and its options to ``subparsers``; its handler is :func:`handle`."""
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
    parser.set_defaults(func=handle)


def handle(args: argparse.Namespace) -> int:
    """Run the sweep the spec names, write its table into ``args.out``; return the exit code."""
    import warnings
    from contextlib import ExitStack

    import discsim as ds
    from discsim.run.spec import read_spec

    out = Path(args.out)
    _import_from_current_folder()
    try:
        spec = read_spec(args.spec)
    except ds.DiscsimError as exc:
        print(f"discsim sweep: {exc}", file=sys.stderr)
        return 1
    if not make_output_folder("sweep", out):
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
                warnings.showwarning = _show_warning  # a line of its own, not a source line
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
    return write_sweep(table, out)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Print a warning of the sweep (a damaged cache entry) as ``discsim sweep: warning: ...``."""
    print(f"discsim sweep: warning: {message}", file=sys.stderr)


def _import_from_current_folder() -> None:
    """Put the current folder first on ``sys.path``, as ``python -m`` does, so that the spec's
    ``task = "mytask:function"`` finds ``./mytask.py`` (the installed ``discsim`` script puts its own folder
    there instead). The local pool's workers inherit the path (fork) or are given it (spawn, dask's
    LocalCluster)."""
    import os

    here = os.getcwd()
    if not any(os.path.abspath(entry or os.curdir) == here for entry in sys.path):
        sys.path.insert(0, here)


def write_sweep(table: pd.DataFrame, out: Path) -> int:
    """Write the sweep's table (CSV, and Parquet when pyarrow is installed) and its failures into ``out``, print
    what ran; return the exit code (1 when a task failed every attempt)."""
    import os

    info, failures = table.attrs["sweep"], table.attrs["failures"]
    csv = out / SWEEP_FILES["csv"]
    written = []
    target = csv
    try:
        tmp = csv.with_name(f".{csv.name}.tmp")
        table.to_csv(tmp, index=False)
        os.replace(tmp, csv)
        written.append(str(csv))
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            pass
        else:
            target = out / SWEEP_FILES["parquet"]
            table.to_parquet(target, index=False)
            written.append(str(target))
        target = out / SWEEP_FILES["failures"]
        if failures:
            lines = []
            for f in failures:
                lines += [
                    f"{f['params']} seed={f['seed']} ({f['attempts']} attempts): {f['error']}",
                    f["traceback"],
                    "",
                ]
            target.write_text("\n".join(lines))
            written.append(str(target))
        else:
            target.unlink(missing_ok=True)
    except OSError as exc:
        Path(csv.with_name(f".{csv.name}.tmp")).unlink(missing_ok=True)
        print(
            f"discsim sweep: cannot write {str(target)!r}: {exc}; every finished task is in the cache "
            f"{str(out / SWEEP_FILES['cache'])!r}, so the same command writes the table without running them again",
            file=sys.stderr,
        )
        return 1
    print(
        f"discsim sweep: {info['tasks']} tasks ({info['ran']} ran, {info['cached']} from the cache, "
        f"{info['failed']} failed, {info['retries']} retries) in {info['seconds']:.1f} s on {info['where']}"
    )
    print(f"  wrote {', '.join(written)}")
    for f in failures:
        print(f"  failed: {f['params']} seed={f['seed']}: {f['error']}", file=sys.stderr)
    return 1 if failures else 0
