"""benchmarks/fixed_step_frames.py runs in its ``--quick`` mode and writes its tables.

No test here asserts a speed: timings belong to the script's output, not to pass/fail.
"""

import math
import os
import subprocess
import sys

import pytest
from benchscripts import read_csv
from paths import BENCHMARKS

from discsim import _numba


@pytest.mark.slow
def test_fixed_step_frames_quick_writes_its_tables(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / "fixed_step_frames.py"), "--quick", "--results", str(tmp_path)],
        capture_output=True,
        text=True,
        env=env,
        timeout=900,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "us/frame" in done.stdout
    rows = read_csv(tmp_path / "fixed_step_frames.csv")
    engines = {r["engine"] for r in rows}
    assert "python" in engines and ("numba" in engines) == _numba.available()
    assert all(float(r["us_per_frame"]) > 0 and float(r["cpu_us_per_frame"]) > 0 for r in rows)
    python = next(r for r in rows if r["engine"] == "python")
    assert float(python["speedup_vs_python"]) == 1.0
    if "pymunk" in engines:
        assert all(not math.isnan(float(r["pymunk_ratio"])) for r in rows)
    sub = read_csv(tmp_path / "fixed_step_sub_frames.csv")
    expected = {(p, e) for p in ("bisect", "swept") for e in ["python"] + ["numba"] * _numba.available()}
    assert {(r["policy"], r["engine"]) for r in sub} == expected
    assert all(float(r["us_per_frame"]) > 0 and float(r["detections_per_frame"]) >= 0 for r in sub)
    assert all(float(r["speedup_vs_python"]) == 1.0 for r in sub if r["engine"] == "python")
    if _numba.available():
        compiled = read_csv(tmp_path / "fixed_step_frames_compile.csv")
        assert [r["cache"] for r in compiled] == ["cold", "warm"]
        assert all(float(r["seconds"]) >= float(r["first_frame_seconds"]) > 0 for r in compiled)
