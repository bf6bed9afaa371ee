"""Running a benchmark script's ``--quick`` mode and reading what it wrote, for the tests of this folder."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

from paths import BENCHMARKS


def run_quick(script: str, results: Path) -> subprocess.CompletedProcess:
    """``python benchmarks/SCRIPT --quick --results RESULTS`` in a fresh process (matplotlib's Agg backend)."""
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run(
        [sys.executable, str(BENCHMARKS / script), "--quick", "--results", str(results)],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
        check=False,
    )


def read_csv(path: Path) -> list[dict]:
    """The rows of a CSV file as dicts of strings."""
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))
