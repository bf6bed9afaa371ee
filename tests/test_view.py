"""ds.view: a self-contained replay page, checked in a real browser (headless Chromium) against trajectory().

The browser tests open the page with Debian's ``chromium`` (``.ci/run`` installs it when it can), drive it
through its JavaScript API (``window.discsim``), read the centres it drew back from the DOM
(``--dump-dom``) and compare them with ``trajectory()`` at the same times; they skip, saying why, only when
no Chromium binary is found.
"""

from __future__ import annotations

import base64
import html
import json
import os
import re
import shutil
import subprocess
import time

import matplotlib

matplotlib.use("Agg")

import matplotlib.image
import numpy as np
import pytest

import discsim as ds
from discsim import cli

CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome")


def chromium() -> str:
    found = os.environ.get("DISCSIM_CHROMIUM") or next(filter(None, map(shutil.which, CHROMIUM_NAMES)), None)
    if not found:
        names = ", ".join(CHROMIUM_NAMES)
        pytest.skip(f"no Chromium binary found (looked for {names} on PATH and DISCSIM_CHROMIUM): apt install chromium")
    return found


def browser_args(*extra) -> list[str]:
    return [chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--mute-audio", *extra]


def drive(page_path, tmp_path, script: str, *, budget_ms: int = 3000) -> dict:
    """Open ``page_path`` in headless Chromium, run ``script`` (JS, after the page's own), return its readout.

    ``script`` drives ``window.discsim`` and ends by calling ``discsim.readout()`` or writing JSON into
    ``#ds-readout`` itself; ``--dump-dom`` prints the DOM once the page is idle (virtual time), and the
    JSON is read back from it.
    """
    text = page_path.read_text(encoding="utf-8")
    driven = tmp_path / f"driven-{time.monotonic_ns()}.html"
    driven.write_text(text.replace("</body>", f"<script>\n{script}\n</script>\n</body>"), encoding="utf-8")
    result = subprocess.run(
        browser_args(f"--virtual-time-budget={budget_ms}", "--dump-dom", driven.as_uri()),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    found = re.search(r'<pre id="ds-readout"[^>]*>(.*?)</pre>', result.stdout, re.S)
    assert found and found.group(1), f"no readout in the page (exit {result.returncode}): {result.stderr[-2000:]}"
    return json.loads(html.unescape(found.group(1)))


SEEK_SCRIPT = """
const out = [];
for (const t of TIMES) {
  discsim.seek(t);
  out.push({time: discsim.time(), positions: Array.from({length: discsim.panels}, (_, k) => discsim.positions(k))});
}
document.getElementById("ds-readout").textContent = JSON.stringify(out);
"""


def seek_all(page_path, tmp_path, times) -> list[dict]:
    return drive(page_path, tmp_path, SEEK_SCRIPT.replace("TIMES", json.dumps([float(t) for t in times])))


def assert_same_positions(drawn, expected):
    drawn = np.asarray(drawn, dtype=float)
    assert drawn.shape == expected.shape
    np.testing.assert_allclose(drawn, expected, rtol=1e-9, atol=1e-12 * max(1.0, float(np.abs(expected).max())))


def case_runs(case):
    pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    return pic, pit


# --- in the browser ---------------------------------------------------------------------------------------


def test_the_page_draws_pit_and_pic_where_trajectory_puts_them(tmp_path):
    case = ds.scenarios.multiple_collisions()
    pic, pit = case_runs(case)
    page = ds.view(pic, tmp_path / "case3.html", compare_with=pit)
    assert page.path == tmp_path / "case3.html" and page.path.exists()
    events = np.concatenate([pic.events["time"], pit.events["time"]])
    times = np.unique(np.concatenate([np.linspace(0.0, case.until, 23), events, events + 1e-7, [0.4321]]))
    times = times[times <= case.until]
    readout = seek_all(page.path, tmp_path, times)
    assert [r["time"] for r in readout] == times.tolist()
    pit_expected, pic_expected = pit.trajectory(times), pic.trajectory(times)
    for k, r in enumerate(readout):
        pit_drawn, pic_drawn = r["positions"]  # PIT left, PIC right
        assert_same_positions(pit_drawn, pit_expected[k])
        assert_same_positions(pic_drawn, pic_expected[k])


@pytest.mark.slow  # (2 s in the browser)
def test_a_periodic_gas_wraps_like_trajectory_and_a_window_replays_exactly(tmp_path):
    discs, box = ds.random_gas(150, 0.35, periodic=True, seed=3)
    sim = ds.EventDriven(discs, box).run(until=4.0)
    page = ds.view(sim, tmp_path / "gas.html", start=1.5, until=3.0, colour="speed")
    assert page.span == (1.5, 3.0)
    times = np.concatenate([np.linspace(1.5, 3.0, 7), sim.events["time"][(sim.events["time"] > 1.5)][:5]])
    times = times[times <= 3.0]
    readout = seek_all(page.path, tmp_path, times)
    expected = sim.trajectory(times)
    for k, r in enumerate(readout):
        (drawn,) = r["positions"]
        assert_same_positions(drawn, expected[k])
    # Seeking outside the span clamps to it.
    (first, last) = seek_all(page.path, tmp_path, [0.0, 99.0])
    assert (first["time"], last["time"]) == (1.5, 3.0)


def test_playing_advances_the_clock_and_draws_the_exact_positions(tmp_path):
    case = ds.scenarios.delay()
    pic, pit = case_runs(case)
    page = ds.view([pit, pic], tmp_path / "delay.html", fps=25)
    script = """
discsim.setSpeed(0.5);
discsim.play();
setTimeout(() => {
  discsim.pause();
  const frames = [discsim.time()];
  discsim.step(1); frames.push(discsim.time());
  discsim.step(1); frames.push(discsim.time());
  discsim.step(-1); frames.push(discsim.time());
  discsim.seek(0.05); discsim.nextEvent(); frames.push(discsim.time());
  discsim.seek(0.0); discsim.play();
  setTimeout(() => {
    discsim.pause();
    const t = discsim.time();
    document.getElementById("ds-readout").textContent = JSON.stringify({
      frames, time: t, playing: discsim.playing(),
      positions: [discsim.positions(0), discsim.positions(1)],
    });
  }, 1500);
}, 1000);
"""
    out = drive(page.path, tmp_path, script, budget_ms=5000)
    first, after_one, after_two, back, next_event = out["frames"]
    assert 0.3 < first < 0.7  # about 1 s of virtual time at 0.5 time units per second
    dt = pit.dt
    assert after_one == pytest.approx(dt * (np.floor(first / dt) + 1), rel=1e-12)  # the next PIT frame
    assert after_two == pytest.approx(after_one + dt, rel=1e-12) and back == pytest.approx(after_one, rel=1e-12)
    all_events = np.concatenate([pic.events["time"], pit.events["time"]])
    assert next_event == all_events[all_events > 0.05].min()
    assert not out["playing"] and 0.5 < out["time"] <= case.until
    t = out["time"]
    assert_same_positions(out["positions"][0], pit.trajectory([t])[0])
    assert_same_positions(out["positions"][1], pic.trajectory([t])[0])


def test_the_screenshot_is_not_blank(tmp_path):
    case = ds.billiard_break()
    sim = ds.EventDriven(case.discs, case.box).run(until=case.until)
    page = ds.view(sim, tmp_path / "break.html")
    shot = tmp_path / "break.png"
    uri = page.path.as_uri() + f"#t={case.until / 2}"
    subprocess.run(
        browser_args("--window-size=1100,800", "--virtual-time-budget=1000", f"--screenshot={shot}", uri),
        capture_output=True,
        timeout=120,
        check=False,
    )
    assert shot.exists(), "Chromium wrote no screenshot"
    pixels = matplotlib.image.imread(shot)[..., :3]
    assert pixels.shape[0] > 300 and pixels.shape[1] > 300
    assert pixels.std() > 0.05  # discs, box, controls: far from a uniform page
    # The discs are drawn in colour (a blank or all-grey page has equal RGB channels everywhere).
    assert (np.ptp(pixels, axis=2) > 0.2).mean() > 0.01


def test_a_run_folder_is_replayed_from_its_streamed_log(tmp_path, capsys):
    out = tmp_path / "run"
    assert cli.main(["run", "--n", "40", "--packing", "0.3", "--until", "2", "--out", out, "--no-progress"]) == 0
    assert cli.main(["view", out]) == 0
    written = out / "view.html"
    assert written.exists() and str(written) in capsys.readouterr().out
    log = ds.read_events(out / "events.dse")
    times = [0.0, 0.77, 2.0]
    readout = seek_all(written, tmp_path, times)
    expected = log.trajectory(times)
    for k, r in enumerate(readout):
        assert_same_positions(r["positions"][0], expected[k])


# --- without a browser -------------------------------------------------------------------------------------


def test_the_page_is_self_contained_and_shows_inline_in_jupyter(tmp_path):
    case = ds.head_on(1.0, 3.0)
    sim = ds.EventDriven(case.discs, case.box).run(until=case.until)
    page = ds.view(sim, path=None)
    assert page.path is None and page.events == len(sim.events) and page.span == (0.0, case.until)
    text = page.html
    assert "://" not in text and "<script src" not in text and "<link" not in text  # no network at all
    assert "window.discsim" in text
    inline = page._repr_html_()
    assert inline.startswith("<iframe srcdoc=") and "&lt;script&gt;" not in inline[:20]
    assert html.unescape(re.search(r'srcdoc="(.*?)"', inline, re.S).group(1)) == text
    assert page.save(tmp_path / "sub" / "page.html").read_text(encoding="utf-8") == text
    assert "page.html" in repr(page)


def test_a_streamed_run_and_a_checkpoint_can_be_viewed(tmp_path):
    discs, box = ds.random_gas(30, 0.3, seed=2)
    sim = ds.EventDriven(discs, box, record=False).run(until=1.0, record_to=tmp_path / "events.dse")
    from_engine = ds.view(sim, path=None)
    from_file = ds.view(tmp_path / "events.dse", path=None)
    from_log = ds.view(ds.read_events(tmp_path / "events.dse"), path=None)
    assert from_engine.events == from_file.events == from_log.events > 0
    fixed = ds.FixedStep(discs, box, frame_rate=20.0).run(until=0.5)
    fixed.save(tmp_path / "fixed.dsc")
    again = ds.view(tmp_path / "fixed.dsc", path=None)
    assert again.events == len(fixed.events) and "PIT (fixed.dsc, 20 frames per unit time)" in again.html
    both = ds.view(ds.EventDriven(discs, box).run(until=0.5), path=None, compare_with=tmp_path / "fixed.dsc")
    assert "PIT (fixed.dsc, 20 frames per unit time) | PIC (EventDriven), the truth" in both.html


@pytest.mark.parametrize(
    ("make", "kwargs", "match"),
    [
        (lambda p: ds.EventDriven(*ds.random_gas(10, 0.2), record=False).run(until=1.0), {}, "record=False"),
        (lambda p: ds.EventDriven(*ds.random_gas(10, 0.2)), {}, "recorded nothing"),
        (lambda p: ds.FixedStep(*ds.random_gas(10, 0.2)), {}, "recorded nothing"),
        (lambda p: p / "missing", {}, "no such file or folder"),
        (lambda p: p, {}, "holds no event log"),
        (lambda p: object(), {}, "cannot view a object"),
        (lambda p: ds.EventDriven(*ds.random_gas(10, 0.2)).run(until=1.0), {"colour": "mass"}, "colour must be"),
        (lambda p: ds.EventDriven(*ds.random_gas(10, 0.2)).run(until=1.0), {"until": 2.0}, r"\[0.0, 1.0\]"),
        (lambda p: ds.EventDriven(*ds.random_gas(10, 0.2)).run(until=1.0), {"speed": -1.0}, "speed must be"),
        (lambda p: ds.EventDriven(*ds.random_gas(10, 0.2)).run(until=1.0), {"labels": ["a", "b"]}, "labels must"),
        (
            lambda p: ds.EventDriven(*ds.random_gas(30, 0.3)).run(until=3.0),
            {"until": 3.0, "max_events": 10},
            "max_events=10",
        ),
        (lambda p: [], {}, "at least one run"),
    ],
)
def test_bad_input_is_refused_by_name_before_anything_is_written(tmp_path, make, kwargs, match):
    empty = tmp_path / "empty"
    empty.mkdir()
    source = make(empty)
    with pytest.raises(ds.DiscsimError, match=match):
        ds.view(source, tmp_path / "view.html", **kwargs)
    assert not (tmp_path / "view.html").exists()


def test_the_command_line_refuses_a_folder_that_recorded_nothing(tmp_path, capsys):
    assert cli.main(["view", tmp_path]) == 1
    err = capsys.readouterr().err
    assert "discsim view:" in err and "holds no event log" in err
    assert not list(tmp_path.iterdir())


def test_only_the_front_door_and_the_command_line_import_the_viewer():
    import ast
    from pathlib import Path

    package = Path(ds.__file__).parent
    importers = set()
    for path in package.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = [node.module] if isinstance(node, ast.ImportFrom) else []
            names += [a.name for a in node.names] if isinstance(node, ast.Import) else []
            if "discsim.view" in names:
                importers.add(path.relative_to(package).as_posix())
    assert importers == {"__init__.py", "cli/view.py"}
    assert "matplotlib" not in (package / "view.py").read_text()  # `import discsim` stays free of matplotlib


# --- spans, long logs, discs that come and go (issue 31) ---------------------------------------------------


def _events_in(events, t0, t1):
    return int(((events["time"] >= t0) & (events["time"] <= t1)).sum())


def test_a_late_span_holds_and_counts_only_its_own_events(tmp_path, monkeypatch):
    discs, box = ds.random_gas(300, 0.5, seed=1)
    sim = ds.EventDriven(discs, box).run(until=4.0)
    inside = _events_in(sim.events, 3.0, 3.5)
    assert 0 < inside < len(sim.events) // 4
    page = ds.view(sim, None, start=3.0, until=3.5, max_events=inside, labels=["gas"])  # earlier events do not count
    assert page.events == inside and page.note is None
    # A streamed log is read chunk by chunk, never whole, and gives the same page.
    streamed = ds.EventDriven(discs, box, record=False)
    streamed.stream_chunk = 500
    streamed.run(until=4.0, record_to=tmp_path / "events.dse")
    from discsim.io import container, streams

    def refuse(*args, **kwargs):
        raise AssertionError("the whole log was read into memory")

    monkeypatch.setattr(container, "read_stream", refuse)
    monkeypatch.setattr(streams, "read_stream", refuse)
    for source in (tmp_path / "events.dse", streamed):
        again = ds.view(source, None, start=3.0, until=3.5, max_events=inside, labels=["gas"])
        assert again.events == inside and again.html == page.html


def test_a_plain_view_of_a_long_run_shows_its_first_events_and_says_so(tmp_path, capsys):
    out = tmp_path / "run"
    assert cli.main(["run", "--n", "100", "--packing", "0.5", "--until", "3", "--out", out, "--no-progress"]) == 0
    capsys.readouterr()
    assert cli.main(["view", out, "--max-events", "300"]) == 0
    said = capsys.readouterr().out
    assert "showing the first" in said and "max_events=300" in said
    log = ds.read_events(out / "events.dse")
    page = ds.view(out, None, max_events=300)
    t0, t1 = page.span
    assert t0 == 0.0 and t1 < log.end_time and page.events == _events_in(log.events, 0.0, t1) <= 300
    assert _events_in(log.events, 0.0, log.events["time"][page.events]) > 300  # the next event would be one too many
    late = ds.view(out, None, start=2.0, max_events=50)
    assert late.span[0] == 2.0 and late.events <= 50 and "after t = 2" in late.note


def _editing_run():
    discs, box = ds.random_gas(12, 0.2, seed=4)
    sim = ds.EventDriven(discs, box).run(until=1.0)
    sim.remove_discs([2, 5])
    spot = next(
        p
        for p in ([x, y] for x in np.linspace(1.0, box.width - 1.0, 15) for y in np.linspace(1.0, box.height - 1.0, 15))
        if (np.hypot(*(sim.positions - p).T) > sim.discs.radii + 0.6).all()
    )
    sim.add_discs(ds.Discs([spot], [[1.0, -0.5]], 0.5))
    sim.run(until=2.0)
    sim.remove_discs([0])
    sim.run(until=3.0)
    return sim


def test_a_run_whose_discs_come_and_go_is_drawn_where_trajectory_puts_them(tmp_path):
    sim = _editing_run()
    page = ds.view(sim, tmp_path / "edit.html", start=0.5)
    times = [0.5, 0.99, 1.0, 1.5, 2.0, 2.5, 3.0]
    readout = seek_all(page.path, tmp_path, times)
    expected = sim.trajectory(times)
    assert expected.shape[1] == 13 and np.isnan(expected[0, 12]).all() and np.isnan(expected[-1, [0, 2, 5]]).all()
    for k, r in enumerate(readout):
        (drawn,) = r["positions"]
        drawn = np.array([[np.nan, np.nan] if p[0] is None else p for p in drawn], dtype=float)
        np.testing.assert_array_equal(np.isnan(drawn), np.isnan(expected[k]))
        assert_same_positions(np.nan_to_num(drawn), np.nan_to_num(expected[k]))


def test_the_time_box_follows_playback_and_the_clock_sits_above_the_discs(tmp_path):
    case = ds.scenarios.missed_collision()
    pic, pit = case_runs(case)
    page = ds.view(pic, tmp_path / "missed.html", compare_with=pit, arrows=True)
    script = """
discsim.setSpeed(0.2);
discsim.play();
setTimeout(() => {
  discsim.pause();
  const box = Array.from(document.querySelectorAll("#ds-controls input[type=number]"))[0];
  const clocks = Array.from(document.querySelectorAll(".ds-clock")).map((c) => c.textContent);
  const zoom = discsim.setZoom(4, 1.0, 1.0);
  const zoomed = document.querySelector(".ds-clock").textContent;
  document.getElementById("ds-readout").textContent = JSON.stringify({
    time: discsim.time(), box: Number(box.value), clocks, zoom, zoomed, unzoomed: discsim.setZoom(1),
  });
}, 1000);
"""
    out = drive(page.path, tmp_path, script, budget_ms=3000)
    assert out["time"] > 0.05 and out["box"] == pytest.approx(out["time"], rel=1e-9)
    assert out["clocks"] == [f"t = {out['time']:.4f}"] * 2
    assert out["zoom"] == 4 and "zoom 4x" in out["zoomed"] and out["unzoomed"] == 1


# --- under gravity, and rough discs that spin (issue 27) --------------------------------------------------


def page_data(page) -> dict:
    found = re.search(r'<script type="application/json" id="ds-data">(.*?)</script>', page.html, re.S)
    assert found
    return json.loads(found.group(1).replace("<\\/", "</"))


def thrown_under_gravity():
    discs = ds.Discs(
        [[2.0, 1.5], [6.0, 6.0], [5.0, 2.0]],
        [[1.5, 6.0], [-1.0, 0.0], [0.0, 0.0]],
        radii=[1.0, 0.8, 0.5],
        masses=[1.0, 1.0, np.inf],
    )
    return ds.EventDriven(discs, ds.Box(10, 10), gravity=(0.0, -9.81), restitution=0.6, rest_speed=1.0).run(until=6.0)


def test_the_page_gets_the_gravity_and_each_record_s_fall_and_turning():
    sim = thrown_under_gravity()
    (run,) = page_data(ds.view(sim, path=None))["runs"]
    assert run["gravity"] == [0.0, -9.81] and run["turning"] is None
    falls = np.frombuffer(base64.b64decode(run["falls"]), dtype=np.uint8)
    starts = np.frombuffer(base64.b64decode(run["starts"]), dtype=np.int32)
    assert falls[starts[2]] == 0  # the obstacle never falls
    assert falls[starts[0] : starts[1]].any() and not falls[starts[1] - 1]  # disc 0 falls, then rests
    rough = ds.EventDriven(*ds.random_gas(12, 0.3, seed=4), roughness=0.5).run(until=1.0)
    (run,) = page_data(ds.view(rough, path=None))["runs"]
    assert run["gravity"] is None and run["turning"] is not None


def test_the_page_draws_parabolas_and_rest_where_trajectory_puts_them(tmp_path):
    sim = thrown_under_gravity()
    assert sim.resting[:2].all()
    page = ds.view(sim, tmp_path / "gravity.html")
    events = sim.events["time"]
    times = np.unique(np.concatenate([np.linspace(0.0, 6.0, 37), events, events + 1e-6]))
    times = times[times <= 6.0]
    expected = sim.trajectory(times)
    for k, r in enumerate(seek_all(page.path, tmp_path, times)):
        (drawn,) = r["positions"]
        assert_same_positions(drawn, expected[k])
    # A window that starts after both discs came to rest keeps them there.
    late = ds.view(sim, tmp_path / "late.html", start=5.0)
    (r,) = seek_all(late.path, tmp_path, [5.5])
    assert_same_positions(r["positions"][0], sim.trajectory([5.5])[0])


@pytest.mark.slow  # (2 s in the browser)
def test_the_page_marks_each_disc_s_angle_as_frames_give_it(tmp_path):
    sim = ds.EventDriven(*ds.random_gas(20, 0.3, seed=4), roughness=0.5).run(until=3.0)
    assert sim.counts["collisions"] > 5
    page = ds.view(sim, tmp_path / "rough.html", start=0.5)
    times = [0.5, 1.7, 3.0]
    script = (
        "const out = []; for (const t of TIMES) { discsim.seek(t); out.push(discsim.angles(0)); }"
        "document.getElementById('ds-readout').textContent = JSON.stringify(out);"
    ).replace("TIMES", json.dumps(times))
    drawn = drive(page.path, tmp_path, script)
    expected = ds.frames(sim, times).angles
    np.testing.assert_allclose(np.array(drawn), expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(drawn[-1], sim.angles, rtol=1e-12, atol=1e-12)
    smooth = ds.view(ds.EventDriven(*ds.random_gas(20, 0.3, seed=4)).run(until=1.0), tmp_path / "smooth.html")
    script = "document.getElementById('ds-readout').textContent = JSON.stringify({a: discsim.angles(0)});"
    assert drive(smooth.path, tmp_path, script)["a"] is None  # no disc turns: no marks


def test_a_streamed_run_under_gravity_is_viewed_from_its_log(tmp_path):
    discs = thrown_under_gravity().discs
    path = tmp_path / "events.dse"
    sim = ds.EventDriven(discs, ds.Box(10, 10), gravity=(0.0, -9.81), restitution=0.6, rest_speed=1.0, record=False)
    sim.run(until=6.0, record_to=path)
    from_file, from_engine = page_data(ds.view(path, path=None)), page_data(ds.view(sim, path=None))
    assert from_file["runs"][0]["gravity"] == from_engine["runs"][0]["gravity"] == [0.0, -9.81]
    assert from_file["runs"][0]["falls"] == page_data(ds.view(thrown_under_gravity(), path=None))["runs"][0]["falls"]


def test_a_log_streamed_from_mid_run_draws_the_discs_at_rest_where_they_rest(tmp_path):
    discs = ds.Discs(
        [[2.0, 1.0], [6.0, 6.0], [8.5, 8.5]], [[0.0, 0.0], [-1.0, 0.0], [0.0, 0.0]], [1.0, 0.8, 0.5], groups=[0, 0, 1]
    )
    laws = {"gravity": (0.0, -9.81), "restitution": {(0, 0): 0.6, (0, 1): 0.6, (1, 1): 0.95}, "rest_speed": 1.0}
    sim = ds.EventDriven(discs, ds.Box(10, 10), record=False, **laws).run(until=3.0)
    assert sim.resting.tolist() == [True, True, False]
    sim.run(until=4.0, record_to=tmp_path / "events.dse")
    page = ds.view(tmp_path / "events.dse", tmp_path / "late.html")
    times = np.linspace(3.0, 4.0, 6)
    expected = ds.EventDriven(discs, ds.Box(10, 10), **laws).run(until=4.0).trajectory(times)
    for k, r in enumerate(seek_all(page.path, tmp_path, times)):
        assert_same_positions(r["positions"][0], expected[k])


# --- sensors ---------------------------------------------------------------------------------------------


def sensed_gas(**kwargs):
    """A gas with a circle, a rectangle and a trip wire, and the sensors (discs enter each within t = 2)."""
    discs, box = ds.random_gas(20, 0.2, seed=5)
    w, h = box.width, box.height
    sensors = [
        ds.Sensor.circle((0.3 * w, 0.3 * h), 0.15 * w),
        ds.Sensor.rectangle((0.6 * w, 0.1 * h), (0.9 * w, 0.4 * h)),
        ds.Sensor.line((0.1 * w, 0.7 * h), (0.9 * w, 0.7 * h)),
    ]
    return ds.EventDriven(discs, box, sensors=sensors, **kwargs), sensors


def sensor_rows(sensors) -> list[list[float]]:
    return [[s.code, *s.params.tolist()] for s in sensors]


def test_the_page_gets_the_sensors_of_a_live_run_and_when_discs_enter_them():
    sim, sensors = sensed_gas()
    sim.run(until=2.0)
    (run,) = page_data(ds.view(sim, path=None))["runs"]
    assert run["sensors"] == sensor_rows(sensors)
    entered = sim.events[sim.events["kind"] == ds.events.ENTER]
    assert len(entered) >= 2
    times = np.frombuffer(base64.b64decode(run["enter_times"]), dtype="<f8")
    which = np.frombuffer(base64.b64decode(run["enter_sensors"]), dtype="<i4")
    assert times.tolist() == entered["time"].tolist() and which.tolist() == entered["j"].tolist()
    # A window that starts later holds only the entries in it; a run without sensors has none.
    (late,) = page_data(ds.view(sim, path=None, start=1.0))["runs"]
    late_times = np.frombuffer(base64.b64decode(late["enter_times"]), dtype="<f8")
    assert late_times.tolist() == entered["time"][entered["time"] >= 1.0].tolist()
    (plain,) = page_data(ds.view(ds.EventDriven(*ds.random_gas(10, 0.2)).run(until=0.5), path=None))["runs"]
    assert plain["sensors"] == [] and plain["enter_times"] == ""


def test_the_sensors_come_back_from_a_stream_a_run_folder_and_a_checkpoint(tmp_path):
    folder = tmp_path / "run"
    folder.mkdir()
    streamed, sensors = sensed_gas(record=False)
    streamed.run(until=2.0, record_to=folder / "events.dse")
    streamed.save(folder / "state.dsc")
    in_memory, _ = sensed_gas()
    in_memory.run(until=2.0).save(tmp_path / "memory.dsc")
    rows = sensor_rows(sensors)
    for source in (streamed, folder, folder / "state.dsc", tmp_path / "memory.dsc"):
        (run,) = page_data(ds.view(source, path=None))["runs"]
        assert run["sensors"] == rows, source
    # A log whose header holds the sensors (stream_header(sensors=...)) is drawn with them on its own.
    from discsim.io.container import RecordWriter
    from discsim.io.streams import stream_header

    log = tmp_path / "header.dse"
    meta, arrays = stream_header(
        in_memory.run_context.log_origin(in_memory.discs)[0], in_memory.box, 0.0, "r", 0, sensors=sensors
    )
    with RecordWriter.create(log, ds.events.EVENT_DTYPE, meta, arrays) as writer:
        writer.append(in_memory.events, {"time": 2.0})
    assert ds.read_events(log).sensors == ds.iter_events(log).sensors == tuple(sensors)
    for source in (log, ds.read_events(log)):
        (run,) = page_data(ds.view(source, path=None))["runs"]
        assert run["sensors"] == rows


def test_a_bare_log_streamed_by_a_run_holds_its_sensors(tmp_path):
    sim, sensors = sensed_gas(record=False)
    sim.run(until=1.0, record_to=tmp_path / "events.dse")
    (run,) = page_data(ds.view(tmp_path / "events.dse", path=None))["runs"]
    assert run["sensors"] == sensor_rows(sensors)


def test_a_damaged_sensor_row_in_a_log_header_is_refused_by_name(tmp_path):
    from discsim.io.container import RecordWriter
    from discsim.io.streams import stream_header

    discs, box = ds.random_gas(5, 0.2, seed=1)
    meta, arrays = stream_header(discs, box, 0.0, "r", 0)
    with RecordWriter.create(tmp_path / "none.dse", ds.events.EVENT_DTYPE, meta, arrays):
        pass
    assert ds.read_events(tmp_path / "none.dse").sensors == ()  # a header without sensors (an older log): none
    meta["sensors"] = [[1, 2.0, 2.0, -1.0, 0.0]]  # a circle of negative radius
    path = tmp_path / "bad.dse"
    with RecordWriter.create(path, ds.events.EVENT_DTYPE, meta, arrays):
        pass
    with pytest.raises(ds.errors.CheckpointError, match=r"bad.dse.*sensors\[0\]"):
        ds.read_events(path)
    with pytest.raises(ds.errors.CheckpointError, match=r"bad.dse.*sensors\[0\]"):
        ds.view(path, path=None)


def test_the_page_draws_the_sensors_and_lights_one_a_disc_enters(tmp_path):
    sim, _ = sensed_gas()
    sim.run(until=2.0)
    entered = sim.events[sim.events["kind"] == ds.events.ENTER]
    t_enter, k = float(entered["time"][0]), int(entered["j"][0])
    page = ds.view(sim, tmp_path / "sensors.html", speed=0.2)  # a flash lasts 0.3 s of playing: 0.06 here
    script = (
        "const out = []; for (const t of TIMES) { discsim.seek(t); out.push(discsim.sensors(0)); }"
        "document.getElementById('ds-readout').textContent = JSON.stringify(out);"
    ).replace("TIMES", json.dumps([t_enter - 0.01, t_enter, t_enter + 0.03, t_enter + 0.1]))
    before, at, just_after, later = drive(page.path, tmp_path, script)
    assert [s["shape"] for s in at] == ["circle", "rectangle", "line"]
    assert not before[k]["lit"] and at[k]["lit"] and just_after[k]["lit"] and not later[k]["lit"]
    # The screenshot shows the sensors' gold (outlines and the lit rectangle), which nothing else is drawn in.
    shot = tmp_path / "sensors.png"
    subprocess.run(
        browser_args("--window-size=900,900", "--virtual-time-budget=1000", f"--screenshot={shot}", page.path.as_uri()),
        capture_output=True,
        timeout=120,
        check=False,
    )
    assert shot.exists(), "Chromium wrote no screenshot"
    pixels = matplotlib.image.imread(shot)[..., :3]
    gold = np.array([0xB8, 0x86, 0x0B]) / 255.0
    assert (np.abs(pixels - gold).max(axis=2) < 0.03).sum() > 100


# --- moving segments ---------------------------------------------------------------------------------------

PADDLE = ((8.0, 3.0), (8.0, 7.0), (-1.0, 0.0))  # p0, p1 at time 0 and the velocity: x = 8 - t
FLOOR = ((1.0, 1.0), (9.0, 1.0))  # a fixed segment
SEGMENT_ROWS = [[8.0, 3.0, 8.0, 7.0, -1.0, 0.0], [1.0, 1.0, 9.0, 1.0]]  # a moving row carries its velocity


def paddle_run(**kwargs):
    """A disc in a 10 x 10 box, a paddle that moves at (-1, 0) and a fixed floor."""
    p0, p1, v = PADDLE
    segments = [ds.Segment(p0, p1, velocity=v), ds.Segment(*FLOOR)]
    disc = ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], radii=0.4)
    return ds.EventDriven(disc, ds.Box(10.0, 10.0), segments=segments, **kwargs)


def test_the_page_gets_each_moving_segment_s_velocity_and_a_fixed_one_as_before():
    (run,) = page_data(ds.view(paddle_run().run(until=4.0), path=None))["runs"]
    assert run["segments"] == SEGMENT_ROWS


def test_moving_segments_come_back_from_a_stream_a_run_folder_and_a_checkpoint(tmp_path):
    folder = tmp_path / "run"
    folder.mkdir()
    streamed = paddle_run(record=False).run(until=4.0, record_to=folder / "events.dse")
    streamed.save(folder / "state.dsc")  # its log is the file: the viewer reads the scene from the checkpoint
    in_memory = paddle_run().run(until=4.0)
    in_memory.save(tmp_path / "memory.dsc")
    assert [s.velocity.tolist() for s in ds.load(folder / "state.dsc").segments] == [[-1.0, 0.0], [0.0, 0.0]]
    # The log's header holds them too: the log alone, on disk or read back, is drawn with its segments.
    log = ds.read_events(folder / "events.dse")
    assert [repr(s) for s in log.segments] == [repr(s) for s in streamed.segments]
    assert [repr(s) for s in ds.iter_events(folder / "events.dse").segments] == [repr(s) for s in log.segments]
    for source in (streamed, folder, folder / "state.dsc", tmp_path / "memory.dsc", folder / "events.dse", log):
        (run,) = page_data(ds.view(source, path=None))["runs"]
        assert run["segments"] == SEGMENT_ROWS, source


def test_a_damaged_segment_row_in_a_log_header_is_refused_by_name(tmp_path):
    from discsim.io.container import RecordWriter
    from discsim.io.streams import stream_header

    discs, box = ds.random_gas(5, 0.2, seed=1)
    meta, arrays = stream_header(discs, box, 0.0, "r", 0)
    meta["segments"] = [[1.0, 1.0, 1.0, 1.0]]  # both end points the same
    path = tmp_path / "bad.dse"
    with RecordWriter.create(path, ds.events.EVENT_DTYPE, meta, arrays):
        pass
    for read in (ds.read_events, ds.iter_events, lambda p: ds.view(p, path=None)):
        with pytest.raises(ds.errors.CheckpointError, match=r"bad.dse.*segments\[0\].*must differ"):
            read(path)


def test_the_page_draws_a_moving_segment_where_it_is_at_each_time(tmp_path):
    page = ds.view(paddle_run().run(until=4.0), tmp_path / "paddle.html")
    times = [0.0, 1.25, 4.0]
    script = (
        "const out = []; for (const t of TIMES) { discsim.seek(t); out.push(discsim.segments(0)); }"
        "document.getElementById('ds-readout').textContent = JSON.stringify(out);"
    ).replace("TIMES", json.dumps(times))
    drawn = drive(page.path, tmp_path, script)
    (p0x, p0y), (p1x, p1y), (vx, vy) = PADDLE
    for t, (paddle, floor) in zip(times, drawn, strict=True):
        assert paddle == [p0x + vx * t, p0y + vy * t, p1x + vx * t, p1y + vy * t]  # p0 + v t, p1 + v t
        assert floor == [*FLOOR[0], *FLOOR[1]]  # a fixed segment stays put


def test_the_page_draws_a_steered_segment_where_it_was_at_each_time(tmp_path):
    sim = paddle_run().run(until=1.0)  # the paddle x = 8 - t until 1, then stopped at 7
    sim.set_segment_velocity(0, (0.0, 0.0)).run(until=3.0)
    page = ds.view(sim, tmp_path / "steered.html")
    times = [0.5, 2.0]
    script = (
        "const out = []; for (const t of TIMES) { discsim.seek(t); out.push(discsim.segments(0)); }"
        "document.getElementById('ds-readout').textContent = JSON.stringify(out);"
    ).replace("TIMES", json.dumps(times))
    drawn = drive(page.path, tmp_path, script)
    assert [paddle for paddle, _ in drawn] == [[7.5, 3.0, 7.5, 7.0], [7.0, 3.0, 7.0, 7.0]]


def piston_gas():
    """A small gas under a piston, and the piston's height sampled (run stopped) at some times."""
    discs, _ = ds.random_gas(8, 0.15, seed=2, periodic=False)
    box = ds.Box(discs.positions[:, 0].max() + 1.5, 80.0)
    top = float((discs.positions[:, 1] + discs.radii).max()) + 3.0
    sim = ds.EventDriven(discs, box, piston=ds.Piston(mass=5.0, pressure=0.4, height=top, velocity=-0.2))
    times, heights = np.linspace(0.37, 9.9, 12), []
    for t in times:
        heights.append(sim.run(until=float(t)).piston.height)
    return sim, times, np.array(heights)


def knots(run) -> dict:
    return {k: np.frombuffer(base64.b64decode(v), dtype="<f8") for k, v in run["piston"].items()}


def test_the_page_gets_the_piston_s_knots_from_the_span_s_start_and_a_run_without_one_none(tmp_path):
    from discsim.analysis.piston_path import piston_path

    sim, _, _ = piston_gas()
    path = piston_path(sim)
    (run,) = page_data(ds.view(sim, path=None))["runs"]
    got = knots(run)
    for name in ("times", "heights", "velocities", "accel"):
        assert got[name].tolist() == getattr(path, name).tolist()
    (late,) = page_data(ds.view(sim, path=None, start=5.0, until=8.0))["runs"]
    kept = knots(late)["times"]
    assert kept[0] <= 5.0 < kept[1] and kept[-1] <= 8.0 and set(kept) <= set(path.times)
    sim.save(tmp_path / "piston.dsc")  # a checkpoint that holds its log: the same knots
    (saved,) = page_data(ds.view(tmp_path / "piston.dsc", path=None))["runs"]
    assert {k: v.tolist() for k, v in knots(saved).items()} == {k: v.tolist() for k, v in got.items()}
    (plain,) = page_data(ds.view(ds.EventDriven(*ds.random_gas(10, 0.2)).run(until=0.5), path=None))["runs"]
    assert plain["piston"] is None


@pytest.mark.slow  # (3 s in the browser; the page's knots are checked quick above)
def test_the_page_draws_the_piston_where_it_was_at_each_frame(tmp_path):
    from discsim.analysis.piston_path import piston_path

    sim, times, heights = piston_gas()
    page = ds.view(sim, tmp_path / "piston.html")
    script = (
        "const out = []; for (const t of TIMES) { discsim.seek(t); out.push(discsim.piston(0)); }"
        "document.getElementById('ds-readout').textContent = JSON.stringify(out);"
    ).replace("TIMES", json.dumps(times.tolist()))
    drawn = drive(page.path, tmp_path, script)
    assert [d["time"] for d in drawn] == times.tolist()
    got = np.array([d["height"] for d in drawn])
    assert got.tolist() == piston_path(sim).height(times).tolist()  # the same arithmetic, bit for bit
    assert got == pytest.approx(heights, rel=1e-12)  # where the run had it
    # The screenshot shows the bar in the piston's blue grey, which nothing else is drawn in.
    shot = tmp_path / "piston.png"
    subprocess.run(
        browser_args("--window-size=900,900", "--virtual-time-budget=1000", f"--screenshot={shot}", page.path.as_uri()),
        capture_output=True,
        timeout=120,
        check=False,
    )
    assert shot.exists(), "Chromium wrote no screenshot"
    pixels = matplotlib.image.imread(shot)[..., :3]
    assert (np.abs(pixels - np.array([0x37, 0x47, 0x4F]) / 255.0).max(axis=2) < 0.03).sum() > 100
    plain = ds.view(ds.EventDriven(*ds.random_gas(10, 0.2)).run(until=0.5), tmp_path / "plain.html")
    assert (
        drive(
            plain.path,
            tmp_path,
            "document.getElementById('ds-readout').textContent = JSON.stringify(discsim.piston(0));",
        )
        is None
    )
