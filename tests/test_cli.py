"""The command line: python -m discsim demo."""

from __future__ import annotations

import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
from PIL import Image

from discsim import cli

CASES = ["missed_collision", "wrong_direction", "multiple_collisions", "delay"]


@pytest.mark.slow  # about 10 s (the GIF); test_demo_without_gif_and_with_another_policy stays quick
def test_demo_prints_the_table_and_writes_the_figures(tmp_path, capsys):
    out = tmp_path / "figures"
    assert cli.main(["demo", "--out", out]) == 0
    text = capsys.readouterr().out
    rows = [line for line in text.splitlines() if line.split() and line.split()[0] in CASES]
    assert [r.split()[0] for r in rows] == CASES  # one row per case, in the study's order
    assert "missed 1 collision" in rows[0]
    assert "direction off by 26.6 deg" in rows[1]
    assert "missed 1 collision" in rows[2]
    assert "late by 0.0629" in rows[3]
    pngs = sorted(p.name for p in out.glob("*.png"))
    assert pngs == [f"case{k}_{name}.png" for k, name in enumerate(CASES, start=1)] + [cli.DEMO_GRID_FILE]
    gifs = list(out.glob("*.gif"))
    assert [g.name for g in gifs] == ["case3_multiple_collisions.gif"]
    with Image.open(gifs[0]) as gif:
        assert gif.n_frames == 65  # PIT's 9 frame times (0 to 1.6 every 0.2) and 7 sub-frames between two
    for path in [*out.glob("*.png"), *gifs]:
        with Image.open(path) as image:
            assert np.asarray(image.convert("RGB"), dtype=float).std() > 0
    assert str(out.resolve()) in text


@pytest.mark.slow  # (3 s; the demo's quick test writes its figures)
def test_demo_without_gif_and_with_another_policy(tmp_path, capsys):
    assert cli.main(["demo", "--out", str(tmp_path), "--no-gif", "--policy", "revert"]) == 0
    assert "PIT (revert)" in capsys.readouterr().out
    assert len(list(tmp_path.glob("*.png"))) == 5 and not list(tmp_path.glob("*.gif"))


@pytest.mark.parametrize("policy", ["separate", pytest.param("bisect", marks=pytest.mark.slow)])
def test_demo_lists_the_cases_under_the_laws_after_the_four(tmp_path, capsys, policy):
    assert cli.main(["demo", "--out", str(tmp_path), "--no-gif", "--policy", policy]) == 0
    text = capsys.readouterr().out
    rows = [line.split() for line in text.splitlines() if line.startswith("bouncing_ball")]
    if policy == "bisect":  # gravity needs a policy that answers at the frame
        assert not rows and "cases under gravity need a policy that answers at the frame" in text
        return
    assert len(rows) == 1 and rows[0][1] == "30"
    pic_hits, pit_hits, matched = (int(v) for v in rows[0][2:5])
    assert pic_hits > 10 and 0 < matched <= min(pic_hits, pit_hits)
    assert len(list(tmp_path.glob("*.png"))) == 5  # no figure of its own


def test_usage_errors(capsys, tmp_path):
    assert cli.main([]) == 2  # no command: help, exit code 2
    assert "demo" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["demo", "--policy", "bounce"])
    assert exit_info.value.code == 2
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert cli.main(["demo", "--out", blocker / "sub"]) == 1
    assert "cannot create the output folder" in capsys.readouterr().err


def test_each_command_adds_its_own_parser():
    parser = cli.build_parser()
    assert parser.parse_args(["demo"]).out == cli.DEFAULT_DEMO_DIR
    assert cli._add_demo_parser in cli._COMMANDS


def test_python_dash_m_discsim_runs():
    result = subprocess.run(
        [sys.executable, "-m", "discsim", "demo", "--help"], capture_output=True, text=True, check=False
    )
    assert result.returncode == 0 and "--out" in result.stdout


def test_ctrl_c_and_errors_a_command_does_not_answer_give_a_line_not_a_traceback(monkeypatch, capsys):
    """Issue 30, item 13: Ctrl-C outside a command's own handling (a sweep's dask start-up, a table being written)
    printed a traceback; now one line and exit 130 (and a DiscsimError one line and exit 1)."""
    from discsim.errors import InvalidArgumentError

    def interrupted(args):
        raise KeyboardInterrupt

    def refused(args):
        raise InvalidArgumentError("no such thing")

    for func, code, words in ((interrupted, 130, "discsim demo: interrupted (Ctrl-C)"), (refused, 1, "no such")):
        parser = cli.build_parser()
        monkeypatch.setattr(cli, "build_parser", lambda parser=parser: parser)
        parser._subparsers._group_actions[0].choices["demo"].set_defaults(func=func)
        assert cli.main(["demo"]) == code
        err = capsys.readouterr().err
        assert words in err and "Traceback" not in err
