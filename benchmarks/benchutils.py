"""Small helpers shared by the benchmark scripts: command line, tables, CSV, timing.

The scripts run as ``python benchmarks/NAME.py`` (so this folder is on
``sys.path``) and import discsim like any user would. Nothing here knows about
discs; it formats rows (dicts) and measures wall-clock time.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import json
import math
import os
import platform
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import NamedTuple

__all__ = [
    "DEFAULT_RESULTS",
    "Column",
    "TimeLimitExceeded",
    "Timing",
    "announce",
    "call_fresh",
    "format_table",
    "load_average",
    "machine_summary",
    "median",
    "parse_args",
    "peak_resident_mb",
    "results_folder",
    "time_limit",
    "timed",
    "write_csv",
]

#: Where the scripts write their CSV and PNG files unless told otherwise.
DEFAULT_RESULTS = Path(__file__).resolve().parent / "results"


def parse_args(description: str, argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The options every benchmark script takes: ``--quick``, ``--results DIR``, ``--repeats K``.

    Args:
        description: the script's one-line purpose, shown by ``--help``.
        argv: arguments to parse (default ``sys.argv[1:]``).

    Returns:
        The namespace; ``results`` is a :class:`~pathlib.Path` that exists (``benchmarks/results/`` unless given, or
        for ``--quick`` a new temporary folder), and ``repeats`` is None unless given.
    """
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--quick", action="store_true", help="tiny sizes and one repeat: proves the script runs")
    parser.add_argument(
        "--results",
        type=Path,
        default=None,
        help="folder for CSV and PNG output (default: benchmarks/results/; with --quick a new temporary folder, so "
        "that a smoke run never overwrites measured results)",
    )
    parser.add_argument("--repeats", type=int, default=None, help="timed runs per measurement (median reported)")
    args = parser.parse_args(argv)
    if args.repeats is not None and args.repeats < 1:
        parser.error(f"--repeats must be at least 1, got {args.repeats}")
    args.results = results_folder(args.results, args.quick)
    return args


def results_folder(given: Path | None, quick: bool) -> Path:
    """The folder a script writes its CSV and PNG files into (made if missing): ``given``, else
    ``benchmarks/results/`` for a full run and a new temporary folder for a ``--quick`` one, so that a smoke run
    never overwrites measured results."""
    if given is not None:
        folder = given
    else:
        folder = Path(tempfile.mkdtemp(prefix="discsim-quick-")) if quick else DEFAULT_RESULTS
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def machine_summary() -> str:
    """One line naming the interpreter, platform, CPU count and load, for the printed header.

    The load average matters on a small machine: other processes slow every timing.
    """
    load = f", load average {load_average():.2f}"
    return (
        f"Python {platform.python_version()} ({platform.python_implementation()}), "
        f"{platform.system()} {platform.machine()}, {os.cpu_count()} CPU(s){load}, {time.strftime('%Y-%m-%d %H:%M')}"
    )


def median(values: Sequence[float]) -> float:
    """Median of ``values`` (NaN when empty)."""
    return statistics.median(values) if values else math.nan


class Timing(NamedTuple):
    """What :func:`timed` measured: wall-clock and CPU seconds, and the function's result."""

    wall: float
    cpu: float
    result: object


def timed(function: Callable[[], object]) -> Timing:
    """Call ``function()``; return its wall-clock seconds (``time.perf_counter``), CPU seconds
    (``time.process_time``, which other processes on a busy machine do not inflate) and result.
    """
    wall, cpu = time.perf_counter(), time.process_time()
    result = function()
    return Timing(time.perf_counter() - wall, time.process_time() - cpu, result)


def load_average() -> float:
    """The 1-minute load average (NaN where the platform has none)."""
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan


class TimeLimitExceeded(Exception):
    """Raised inside a :func:`time_limit` block when its wall-clock budget runs out."""


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[bool]:
    """Interrupt the block with :class:`TimeLimitExceeded` after ``seconds`` of wall-clock time.

    Uses ``SIGALRM``, so it works in the main thread on POSIX systems; elsewhere
    the block runs to completion. Yields whether the limit is enforced.
    """
    if not hasattr(signal, "setitimer"):
        yield False
        return

    def _expire(signum, frame):
        raise TimeLimitExceeded(f"over the {seconds:g} s budget")

    previous = signal.signal(signal.SIGALRM, _expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield True
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)


class Column:
    """One column of a printed table and CSV file.

    Args:
        key: the row dict key.
        title: the printed header.
        fmt: a format spec for numbers (``",.0f"``, ``".3g"``...); strings print as they are.
    """

    def __init__(self, key: str, title: str, fmt: str = ""):
        self.key, self.title, self.fmt = key, title, fmt

    def render(self, row: dict) -> str:
        """The cell text of ``row`` (empty when the key is absent or None)."""
        value = row.get(self.key)
        if value is None:
            return ""
        if isinstance(value, float) and math.isnan(value):
            return "-"
        if isinstance(value, int | float) and not isinstance(value, bool) and self.fmt:
            return format(value, self.fmt)
        return str(value)


def format_table(rows: Sequence[dict], columns: Sequence[Column]) -> str:
    """Rows as a fixed-width text table with a header line.

    Example:
        >>> print(format_table([{"n": 1000, "rate": 1234.5}], [Column("n", "N"), Column("rate", "coll/s", ",.0f")]))
           N  coll/s
        ----  ------
        1000   1,234
    """
    cells = [[c.render(r) for c in columns] for r in rows]
    widths = [max([len(c.title)] + [len(line[k]) for line in cells]) for k, c in enumerate(columns)]
    lines = ["  ".join(c.title.rjust(w) for c, w in zip(columns, widths, strict=True))]
    lines.append("  ".join("-" * w for w in widths))
    lines += ["  ".join(text.rjust(w) for text, w in zip(line, widths, strict=True)) for line in cells]
    return "\n".join(lines)


def write_csv(path: Path, rows: Sequence[dict], keys: Sequence[str]) -> Path:
    """Write ``rows`` (dicts) to ``path`` with the columns ``keys``; return the path."""
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(keys), extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: _csv_value(row.get(k)) for k in keys})
    return path


def _csv_value(value):
    if isinstance(value, float):
        return repr(value)
    return "" if value is None else value


_FRESH_PROBE = """
import json, sys
sys.path.insert(0, sys.argv[1])
module = __import__(sys.argv[2])
print(json.dumps(getattr(module, sys.argv[3])(**json.loads(sys.argv[4]))))
"""


def call_fresh(module: str, function: str, **args) -> dict:
    """``module.function(**args)`` in a fresh Python process (a script of this folder); its JSON result.

    Every timed run of the scripts gets its own interpreter, as a user's run would: in one process a run
    inherits the heap (and the caches) the runs before it left behind.

    Raises:
        RuntimeError: with the child's stderr, if it fails.
    """
    here = str(Path(__file__).resolve().parent)
    command = [sys.executable, "-c", _FRESH_PROBE, here, module, function, json.dumps(args)]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode:
        msg = f"{module}.{function}({args}) failed in a fresh process:\n{done.stderr}"
        raise RuntimeError(msg)
    return json.loads(done.stdout.splitlines()[-1])


def peak_resident_mb() -> float:
    """Peak resident memory of this process so far, in MB (NaN if unknown).

    On Linux this is ``VmHWM`` from ``/proc/self/status``: unlike
    ``resource.ru_maxrss``, which Linux carries over from the parent across
    ``fork`` and ``exec``, it covers this program alone. Elsewhere ``ru_maxrss``.
    """
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024  # kB
    except OSError:
        pass
    try:
        import resource
    except ImportError:  # Windows
        return math.nan
    scale = 1 if sys.platform == "darwin" else 1024  # bytes on macOS, kilobytes on Linux and BSD
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * scale / 2**20


def announce(text: str) -> None:
    """Print a progress line to stderr (the tables go to stdout)."""
    print(text, file=sys.stderr, flush=True)
