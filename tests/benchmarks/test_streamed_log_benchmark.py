"""benchmarks/streamed_log.py runs (``--quick``) and writes its table; no speed is asserted."""

from benchscripts import read_csv, run_quick


def test_the_streamed_log_benchmark_runs(tmp_path):
    done = run_quick("streamed_log.py", tmp_path)
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "streamed_log.csv")
    assert [r["task"] for r in rows] == ["view", "trajectory", "frames", "read whole"]
    assert all(float(r["seconds"]) > 0 and float(r["peak_mb"]) > 0 for r in rows)
