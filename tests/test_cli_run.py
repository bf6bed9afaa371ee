"""``discsim run`` end to end (summary, files, refusals, --resume, a SIGKILLed run) and the long-run benchmark."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from paths import ROOT

import discsim as ds
from discsim import _numba
from discsim.cli import RUN_FILES, main


def _args(out, until=10.0, packing=0.4, n=150, *extra) -> list[str]:
    return [
        "run",
        "--n",
        str(n),
        "--packing",
        str(packing),
        "--until",
        str(until),
        "--seed",
        "2",
        "--out",
        str(out),
        "--checkpoint-every",
        "1500",
        "--no-progress",
        *extra,
    ]


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def _assert_same_run(a: Path, b: Path) -> None:
    sa, sb = ds.load(a / RUN_FILES["checkpoint"]), ds.load(b / RUN_FILES["checkpoint"])
    assert sa.time == sb.time
    assert sa.positions.tobytes() == sb.positions.tobytes()
    assert sa.velocities.tobytes() == sb.velocities.tobytes()
    assert sa.counts == sb.counts and sa.max_overlap == sb.max_overlap and sa.pressure() == sb.pressure()
    ea, eb = ds.read_events(a / RUN_FILES["events"]), ds.read_events(b / RUN_FILES["events"])
    assert ea.events.tobytes() == eb.events.tobytes()


def test_run_writes_its_files_and_prints_a_summary(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(_args(out)) == 0
    printed = capsys.readouterr().out
    for word in ("collisions/s", "energy drift", "pressure P", "Z = PA/NkT", "Henderson: 2.8333"):
        assert word in printed
    assert sorted(p.name for p in out.iterdir()) == sorted(RUN_FILES.values())
    summary = json.loads((out / RUN_FILES["summary"]).read_text())
    discs, box = ds.random_gas(150, 0.4, periodic=True, seed=2)
    same = ds.EventDriven(discs, box, record=False).run(until=10.0)
    assert summary["collisions"] == same.counts["collisions"] > 1000
    assert summary["time"] == 10.0 and summary["collisions_per_s"] > 0
    assert abs(summary["energy_drift"]) < 1e-12
    kt = same.kinetic_energy() / 149  # canonical: 2N - 2 degrees of freedom at fixed momentum (issue 29)
    assert summary["pressure"] == pytest.approx(same.pressure() + kt / box.area, rel=1e-12)
    assert summary["henderson_Z"] == pytest.approx(2.8333, abs=1e-4)
    assert 0.8 < summary["Z"] / summary["henderson_Z"] < 1.2
    assert summary["since"] == 2.0 and summary["Z_err"] > 0  # a fifth of --until, with its error bar
    assert abs(summary["Z"] - summary["henderson_Z"]) < 4 * summary["Z_err"] + 0.03
    virial_rate = same.pressure() * box.area - same.kinetic_energy()  # W / (2 t)
    assert summary["Z_from_start"] == pytest.approx(1 + virial_rate / (150 * kt))
    assert summary["events_on_disk"] == len(ds.read_events(out / RUN_FILES["events"]).events)
    assert 89.0 < summary["bytes_per_event"] < 100.0  # 89 per event plus the header (the initial discs)
    assert ds.checkpoint_info(out / RUN_FILES["checkpoint"])["run"]["finished"]


def test_run_refuses_a_folder_that_holds_a_run_and_changes_nothing(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(_args(out, until=3.0)) == 0
    before = _snapshot(out)
    assert main(_args(out, until=3.0)) == 1
    assert "already holds a run" in capsys.readouterr().err
    assert main(_args(out, 3.0, 0.45, 150, "--resume")) == 1
    assert "holds a different run (packing=0.4 there, 0.45 asked)" in capsys.readouterr().err
    assert main(_args(out, 3.0, 0.4, 150, "--walls", "--resume")) == 1
    assert "periodic=True there" in capsys.readouterr().err
    assert main(_args(out, 2.0, 0.4, 150, "--resume")) == 1
    assert "past --until" in capsys.readouterr().err
    (out / RUN_FILES["checkpoint"]).write_bytes(before[RUN_FILES["checkpoint"]][:-7])
    assert main(_args(out, 5.0, 0.4, 150, "--resume")) == 1
    assert "truncated" in capsys.readouterr().err
    after = _snapshot(out)
    after[RUN_FILES["checkpoint"]] = before[RUN_FILES["checkpoint"]]
    assert after == before


def test_run_resume_extends_a_run_exactly(tmp_path):
    assert main(_args(tmp_path / "a", until=4.0)) == 0
    assert main(_args(tmp_path / "a", 9.0, 0.4, 150, "--resume")) == 0
    assert main(_args(tmp_path / "b", until=9.0)) == 0
    _assert_same_run(tmp_path / "a", tmp_path / "b")
    summary = json.loads((tmp_path / "a" / RUN_FILES["summary"]).read_text())
    assert 0 < summary["session_collisions"] < summary["collisions"]


def test_run_with_walls(tmp_path, capsys):
    out = tmp_path / "walls"
    assert main(_args(out, 3.0, 0.3, 100, "--walls")) == 0
    assert "box with walls" in capsys.readouterr().out
    summary = json.loads((out / RUN_FILES["summary"]).read_text())
    assert summary["periodic"] is False and summary["wall_hits"] > 0


def test_resume_with_no_run_in_the_folder_is_refused_and_creates_nothing(tmp_path, capsys):
    empty, missing = tmp_path / "empty", tmp_path / "missing" / "run"
    empty.mkdir()
    assert main(_args(empty, 3.0, 0.3, 100, "--resume")) == 1
    assert f"nothing to resume: {empty} is empty" in capsys.readouterr().err
    assert main(_args(missing, 3.0, 0.3, 100, "--resume")) == 1
    assert f"nothing to resume: {missing} does not exist" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == [empty] and not list(empty.iterdir())


def test_a_refused_gas_leaves_no_output_folder(tmp_path, capsys):
    out = tmp_path / "new" / "run"
    assert main(_args(out, 3.0, 0.9, 100)) == 1
    assert "packing fraction 0.9 cannot be reached" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_resuming_a_copied_folder_whose_log_was_deleted_is_refused(tmp_path, capsys):
    import shutil

    assert main(_args(tmp_path / "a", until=3.0)) == 0
    copy = tmp_path / "copy"
    shutil.copytree(tmp_path / "a", copy)
    (copy / RUN_FILES["events"]).unlink()
    before = _snapshot(copy)
    assert main(_args(copy, 6.0, 0.4, 150, "--resume")) == 1
    err = capsys.readouterr().err
    records = ds.checkpoint_info(copy / RUN_FILES["checkpoint"])["stream"]["records"]
    assert f"{copy / RUN_FILES['events']} is missing, but the checkpoint saw {records:,} events" in err
    assert _snapshot(copy) == before


@pytest.mark.parametrize(
    ("option", "value", "expected"),
    [
        ("--seed", "-3", "expected an integer, 0 or more, got '-3'"),
        ("--since", "nan", "expected a finite number, 0 or more, got 'nan'"),
        ("--since", "-1", "expected a finite number, 0 or more, got '-1'"),
        ("--since", "inf", "expected a finite number, 0 or more, got 'inf'"),
    ],
)
def test_a_negative_seed_or_since_is_a_usage_error(tmp_path, capsys, option, value, expected):
    args = _args(tmp_path / "run", 3.0, 0.3, 100)
    args += [option, value] if option not in args else []
    args[args.index(option) + 1] = value
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2 and expected in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_since_after_until_is_refused_before_anything_runs(tmp_path, capsys):
    assert main(_args(tmp_path / "run", 3.0, 0.3, 100, "--since", "3.5")) == 2
    assert "--since 3.5 must lie before --until 3" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())
    assert main(_args(tmp_path / "run", 3.0, 0.3, 100, "--since", "1")) == 0
    summary = json.loads((tmp_path / "run" / RUN_FILES["summary"]).read_text())
    assert summary["since"] == 1.0 and np.isfinite([summary["Z"], summary["Z_err"]]).all()


@pytest.mark.parametrize("backend", ["python", "numba"])
def test_backend_option_runs_and_resumes_under_the_backend_asked(tmp_path, capsys, backend):
    if backend == "numba" and not _numba.available():
        pytest.skip("numba is not installed or is hidden (the fast extra)")
    other = "numba" if backend == "python" and _numba.available() else "python"
    assert main(_args(tmp_path / "a", 4.0, 0.4, 150, "--backend", backend)) == 0
    assert f"{backend} backend" in capsys.readouterr().out
    assert json.loads((tmp_path / "a" / RUN_FILES["summary"]).read_text())["backend"] == backend
    assert main(_args(tmp_path / "a", 9.0, 0.4, 150, "--resume", "--backend", other)) == 0
    assert json.loads((tmp_path / "a" / RUN_FILES["summary"]).read_text())["backend"] == other
    assert main(_args(tmp_path / "b", until=9.0)) == 0  # auto
    assert json.loads((tmp_path / "b" / RUN_FILES["summary"]).read_text())["backend"] == (
        "numba" if _numba.available() else "python"
    )
    _assert_same_run(tmp_path / "a", tmp_path / "b")


def test_usage_errors_exit_with_2(capsys):
    for bad in (["--n", "0"], ["--packing", "-1"], ["--until", "nan"], ["--checkpoint-every", "1.5"]):
        args = _args("unused")
        k = args.index(bad[0])
        args[k + 1] = bad[1]
        with pytest.raises(SystemExit) as exit_info:
            main(args)
        assert exit_info.value.code == 2
    assert "expected a positive" in capsys.readouterr().err


def test_a_killed_cli_run_resumes_to_the_same_end(tmp_path):
    killed, straight = tmp_path / "killed", tmp_path / "straight"
    args = _args(killed, 60.0, 0.6, 300)
    args[args.index("--checkpoint-every") + 1] = "3000"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    # The killed run goes at the pure-Python pace (the compiled one can finish before the kill comes); the resume
    # and the straight run below take the default backend: the same events bit for bit either way.
    env["DISCSIM_NO_NUMBA"] = "1"
    process = subprocess.Popen([sys.executable, "-m", "discsim", *args], stderr=subprocess.PIPE, env=env)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and process.poll() is None:
            try:
                if ds.checkpoint_info(killed / RUN_FILES["checkpoint"])["counts"]["collisions"] > 0:
                    break
            except (FileNotFoundError, ds.CheckpointError):
                pass
            time.sleep(0.005)
        time.sleep(0.1)
        process.send_signal(signal.SIGKILL)
        _, stderr = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == -signal.SIGKILL, stderr.decode()
    assert not (killed / RUN_FILES["summary"]).exists()
    assert main([*args, "--resume"]) == 0
    straight_args = list(args)
    straight_args[straight_args.index("--out") + 1] = str(straight)
    assert main(straight_args) == 0
    _assert_same_run(killed, straight)


@pytest.mark.slow  # about 10 s: a benchmark script in its quick mode
def test_longrun_benchmark_quick(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "longrun.py"), "--quick", "--results", str(tmp_path)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    with open(tmp_path / "longrun_storage.csv", newline="") as handle:
        storage = list(csv.DictReader(handle))
    modes = {row["mode"]: row for row in storage}
    assert set(modes) == {"no log", "in memory", "streamed"}
    assert 89.0 <= float(modes["streamed"]["bytes_per_event"]) < 95.0
    assert float(modes["streamed"]["last_fifth_mb"]) < float(modes["in memory"]["last_fifth_mb"])
    with open(tmp_path / "longrun_dense.csv", newline="") as handle:
        dense = list(csv.DictReader(handle))
    assert len(dense) >= 3
    assert all(float(row["collisions_per_s"]) > 0 for row in dense)
    assert all(abs(float(row["energy_drift"])) < 1e-9 for row in dense)
    assert np.all(np.diff([int(row["collisions"]) for row in dense]) > 0)
    assert (tmp_path / "longrun.png").stat().st_size > 0
    assert "bytes/event" in done.stdout


def _cut_run_folder(folder: Path) -> tuple[Path, list[tuple[int, int]]]:
    """A run folder (as `discsim run` writes) whose log holds chunks of 100 events; ``(end offset, events before
    it)`` after the header and after each chunk."""
    folder.mkdir()
    sim = ds.EventDriven(*ds.random_gas(60, 0.4, seed=5), record=False)
    sim.stream_chunk = 100
    log = folder / RUN_FILES["events"]
    sim.run(until=6.0, record_to=log, checkpoint=folder / RUN_FILES["checkpoint"], checkpoint_every=10**6)
    walk = list(ds.io.container.iter_stream(log))
    return log, [(end, sum(len(w[2]) for w in walk[: k + 1])) for k, (*_, end) in enumerate(walk)]


def test_view_of_a_run_folder_whose_log_was_cut_says_where_it_stops(tmp_path, capsys):
    log, ends = _cut_run_folder(tmp_path / "run")
    first = next(k for k, (_, events) in enumerate(ends) if events)  # the first chunk that holds events
    data = log.read_bytes()
    log.write_bytes(data[: (ends[first - 1][0] + ends[first][0]) // 2])  # cut inside it
    assert main(["view", str(tmp_path / "run")]) == 1
    err = capsys.readouterr().err
    assert "recorded nothing" not in err
    saw = ds.checkpoint_info(tmp_path / "run" / RUN_FILES["checkpoint"])["stream"]["records"]
    assert f"events.dse stops at byte {ends[first - 1][0]:,} (" in err and f"the checkpoint saw {saw:,})" in err
    assert "whole chunks hold 0 events" in err and "nothing to replay" in err
    assert not (tmp_path / "run" / "view.html").exists()
    end, events = ends[first + 2]
    assert events == 300 < saw
    log.write_bytes(data[: end + 10])  # three chunks of events, then a cut
    assert ds.io.container.stream_extent(log)[:2] == (end, 300)
    assert main(["view", str(tmp_path / "run")]) == 0
    captured = capsys.readouterr()
    assert "300 events" in captured.out
    assert f"note: {log} stops at byte {end:,}" in captured.err and "whole chunks hold 300 events" in captured.err
    log.write_bytes(data)
    assert main(["view", str(tmp_path / "run")]) == 0
    assert "note" not in capsys.readouterr().err


def test_ctrl_c_while_placing_the_discs_leaves_nothing_and_says_so(tmp_path, capsys, monkeypatch):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(ds, "random_gas", interrupted)
    assert main(_args(tmp_path / "run", 3.0, 0.3, 100)) == 130
    assert "interrupted before anything was written; run the same command again" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())
