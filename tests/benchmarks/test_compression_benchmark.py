"""benchmarks/compression.py runs in its --quick mode and writes its CSV (no speed is asserted)."""

import csv
import os
import subprocess
import sys

import pytest
from paths import BENCHMARKS


@pytest.mark.slow  # 6 s
def test_compression_benchmark_quick(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / "compression.py"), "--quick", "--results", str(tmp_path)],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert "coll/disc to 0.80" in done.stdout
    rows = list(csv.DictReader(open(tmp_path / "compression_quick.csv")))
    assert len(rows) == 4
    for row in rows:
        assert float(row["reached_packing"]) > 0.79
        assert float(row["coll_per_disc_080"]) > 0
