"""discsim.plot renders with the Agg backend: each function returns its matplotlib object and draws something."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import math

import matplotlib.collections
import matplotlib.pyplot as plt
import matplotlib.quiver
import numpy as np
import pytest
from matplotlib import animation
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from PIL import Image

import discsim as ds
from discsim import plot


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def assert_not_blank(path):
    assert path.exists() and path.stat().st_size > 0
    pixels = np.asarray(Image.open(path).convert("RGB"), dtype=float)
    assert pixels.std() > 0


def case_runs(case):
    pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    return pic, pit


def test_plot_state_of_discs_and_of_an_engine(tmp_path):
    discs = ds.Discs([[2.0, 2.0], [5.0, 2.0]], [[1.0, 0.5], [0.0, 0.0]], radii=[1.0, 0.5], masses=[1.0, np.inf])
    ax = plot.plot_state(discs, box=ds.Box(8.0, 4.0))
    assert isinstance(ax, Axes)
    (circles,) = [c for c in ax.collections if len(c.get_paths()) == 2]
    # The obstacle is grey; the moving disc has its own colour.
    faces = circles.get_facecolor()
    assert np.allclose(faces[1][:3], 0.55) and not np.allclose(faces[0][:3], 0.55)
    assert len(ax.patches) == 1  # the box outline
    assert_not_blank(plot.save_figure(ax, tmp_path / "discs.png"))

    gas, box = ds.random_gas(40, 0.3, seed=1)
    sim = ds.FixedStep(gas, box, frame_rate=20.0).run(until=0.5)
    fig, given = plt.subplots()
    assert plot.plot_state(sim, ax=given) is given
    assert "t = 0.5" in given.get_title()
    assert_not_blank(plot.save_figure(fig, tmp_path / "sim.png"))


def test_plot_state_marks_the_turning_of_spinning_discs():
    discs = ds.Discs([[2.0, 2.0], [6.0, 2.0]], [[0.0, 0.0], [0.0, 0.0]], radii=1.0, spins=[math.pi / 2, 0.0])
    sim = ds.EventDriven(discs, ds.Box(8.0, 4.0)).run(until=1.0)
    (marks,) = [c for c in plot.plot_state(sim).collections if isinstance(c, matplotlib.collections.LineCollection)]
    # Disc 0 turned a quarter turn: its mark points up; disc 1 did not turn: along +x.
    np.testing.assert_allclose(marks.get_segments(), [[[2.0, 2.0], [2.0, 3.0]], [[6.0, 2.0], [7.0, 2.0]]], atol=1e-12)
    still = ds.Discs([[2.0, 2.0]], [[0.0, 0.0]], radii=1.0)  # nothing turns: no marks unless asked for
    lines = [c for c in plot.plot_state(still).collections if isinstance(c, matplotlib.collections.LineCollection)]
    assert lines == []
    assert len(plot.plot_state(still, marks=True).collections) == len(plot.plot_state(still).collections) + 1


def test_plot_state_clips_velocity_arrows_at_the_box():
    # A fast disc next to the right wall: its arrow (four radii long) would reach past the box.
    discs = ds.Discs([[7.0, 2.0], [2.0, 2.0]], [[3.0, 0.0], [0.5, 0.0]], radii=0.8)
    ax = plot.plot_state(discs, box=ds.Box(8.0, 4.0))
    (quiver,) = [c for c in ax.collections if isinstance(c, matplotlib.quiver.Quiver)]
    assert quiver.U[0] + quiver.X[0] > 8.0  # drawn to scale, it leaves the box ...
    ax.figure.canvas.draw()
    clip = quiver.get_clip_box()  # ... so it is cut at the walls (matplotlib keeps a rectangle as a box)
    bounds = ax.transData.inverted().transform(clip.get_points())
    np.testing.assert_allclose([bounds.min(axis=0), bounds.max(axis=0)], [[0.0, 0.0], [8.0, 4.0]], atol=1e-9)


def test_plot_trajectories_draws_one_path_per_disc(tmp_path):
    gas, box = ds.random_gas(12, 0.2, periodic=True, seed=5)
    sim = ds.EventDriven(gas, box).run(until=6.0)
    ax = plot.plot_trajectories(sim)
    assert len(ax.lines) == 12
    # Paths that cross the periodic edge are broken there, not drawn across the box.
    for line in ax.lines:
        xy = line.get_xydata()
        finite = np.isfinite(xy).all(axis=1)
        steps = np.abs(np.diff(xy[finite], axis=0))
        jumps = ~np.isfinite(xy).all(axis=1)
        assert (steps.max(initial=0.0) < box.width / 2) or jumps.any()
    assert_not_blank(plot.save_figure(ax, tmp_path / "paths.png"))
    assert len(plot.plot_trajectories(sim, discs=[0, 3]).lines) == 2
    with pytest.raises(IndexError, match="disc index 12"):
        plot.plot_trajectories(sim, discs=[12])


def test_plot_case_draws_pit_and_pic_side_by_side(tmp_path):
    case = ds.scenarios.multiple_collisions()
    pic, pit = case_runs(case)
    fig = plot.plot_case(pic, pit, title=case.name)
    assert isinstance(fig, Figure)
    ax_pit, ax_pic = fig.axes
    assert ax_pit.get_title().startswith("PIT") and ax_pic.get_title().startswith("PIC")
    # Each exact contact is an unfilled outline of both discs, on both panels (dashed on PIT's).
    for ax, style in ((ax_pic, "-"), (ax_pit, "--")):
        outlines = [p for p in ax.patches if isinstance(p, Circle) and not p.get_fill()]
        assert len(outlines) == 2 * pic.counts["collisions"] == 4
        assert {p.get_linestyle() for p in outlines} == {style}
        contacts = pic.events[pic.events["kind"] == 0]
        expected = sorted(
            [(float(e["xi"]), float(e["yi"])) for e in contacts] + [(float(e["xj"]), float(e["yj"])) for e in contacts]
        )
        np.testing.assert_allclose(sorted(p.center for p in outlines), expected)
    # One arrow per disc per collision of that run: 2 on PIT's panel, 4 on PIC's.
    arrows = {ax: sum(len(q.U) for q in ax.collections if isinstance(q, matplotlib.quiver.Quiver)) for ax in fig.axes}
    assert arrows[ax_pit] == 2 and arrows[ax_pic] == 4
    assert_not_blank(plot.save_figure(fig, tmp_path / "case3.png"))


@pytest.mark.slow  # about 6 s: a 61-frame GIF
def test_animate_saves_a_gif_of_two_runs(tmp_path):
    case = ds.scenarios.delay()
    pic, pit = case_runs(case)
    path = tmp_path / "movie" / "delay.gif"
    anim = plot.animate([pit, pic], path, fps=5)
    assert isinstance(anim, animation.FuncAnimation)
    assert_not_blank(path)
    with Image.open(path) as gif:
        assert gif.n_frames == 61  # each PIT frame (0 to 2.4 every 0.2) and 4 sub-frames between two
    # The clock is inside the first panel, and names the PIT frame on a frame time.
    fig = anim._fig
    (clock,) = [t for t in fig.axes[0].texts if t.get_text().startswith("t = ")]
    assert clock.get_transform() == fig.axes[0].transAxes and 0 <= min(clock.get_position()) <= 1
    assert clock.get_text() == "t = 2.400  (PIT frame 12)"  # the last frame drawn
    # PIC's collision is outlined on both panels once it has happened (solid on PIC's, dashed on PIT's).
    outlines = [[p for p in ax.patches if isinstance(p, Circle) and not p.get_fill()] for ax in fig.axes]
    assert [len(o) for o in outlines] == [2, 2] and all(p.get_visible() for o in outlines for p in o)
    assert {p.get_linestyle() for p in outlines[0]} == {"--"} and {p.get_linestyle() for p in outlines[1]} == {"-"}
    plot.close(anim)


def test_animate_refuses_what_it_cannot_write(tmp_path):
    case = ds.head_on(1.0, 1.0)
    sim = ds.EventDriven(case.discs, case.box).run(until=case.until)
    with pytest.raises(ValueError, match=r"\.gif or \.mp4"):
        plot.animate(sim, tmp_path / "movie.avi")
    if not animation.writers.is_available("ffmpeg"):
        with pytest.raises(RuntimeError, match="ffmpeg"):
            plot.animate(sim, tmp_path / "movie.mp4")
    assert not any(tmp_path.iterdir())  # nothing half-written


def test_plot_case_draws_into_given_axes_and_plot_cases_makes_one_grid(tmp_path):
    rows = []
    for case in ds.study_cases():
        pic, pit = case_runs(case)
        rows.append((pic, pit, case.name))
    fig, axes = plt.subplots(2, 2)
    assert plot.plot_case(rows[2][0], rows[2][1], ax=axes[1]) is fig
    assert axes[1][0].get_title().startswith("PIT") and axes[1][1].get_title().startswith("PIC")
    assert not axes[0][0].has_data() and not fig.legends  # the other axes untouched, no figure legend
    with pytest.raises(ds.InvalidArgumentError, match="two matplotlib axes"):
        plot.plot_case(rows[2][0], rows[2][1], ax=axes[0][0])
    grid = plot.plot_cases(rows)
    assert len(grid.subfigs) == 4 and len(grid.axes) == 8
    assert [sub._suptitle.get_text() for sub in grid.subfigs] == [name for *_, name in rows]
    assert_not_blank(plot.save_figure(grid, tmp_path / "cases.png"))
    with pytest.raises(ds.InvalidArgumentError, match="at least one"):
        plot.plot_cases([])


def test_case_figures_are_readable_zoomed_and_never_stack_labels():
    case = ds.scenarios.missed_collision()
    pic, pit = case_runs(case)
    fig = plot.plot_case(pic, pit)
    for ax in fig.axes:
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert (y1 - y0) / (x1 - x0) >= 0.35 - 1e-9  # not a flat strip
        places = np.array([t.get_position() for t in ax.texts])
        assert len(places) >= 4
        gaps = np.hypot(*(places[:, None, :] - places[None, :, :]).transpose(2, 0, 1))
        assert gaps[np.triu_indices(len(places), 1)].min() > 0.3  # no two labels on one spot
    # The near-static disc of case 1 gets one label for the frames it spends in place.
    assert any("-" in t.get_text() for t in fig.axes[0].texts)
    # Fixed obstacles (case 3's grey disc) get no frame labels at all.
    case = ds.scenarios.multiple_collisions()
    pic, pit = case_runs(case)
    fig = plot.plot_case(pic, pit)
    obstacle = pic.discs.positions[np.isinf(pic.discs.masses)][0]
    for ax in fig.axes:
        assert all(np.hypot(*(np.array(t.get_position()) - obstacle)) > 0.5 for t in ax.texts)


def test_animate_draws_small_discs_large_with_the_clock_and_arrows_clear_of_them(tmp_path):
    case = ds.scenarios.missed_collision()  # discs of radius 0.2 in a 20 x 10 box
    pic, pit = case_runs(case)
    path = tmp_path / "case1.gif"
    anim = plot.animate([pit, pic], path, arrows=True, dpi=80)
    fig = anim._fig
    ax = fig.axes[0]
    pixels_per_unit = np.diff(ax.transData.transform([[0.0, 0.0], [1.0, 0.0]]), axis=0)[0, 0] * 80 / fig.dpi
    assert 2 * 0.2 * pixels_per_unit > 9  # a disc over 9 pixels wide (4.6 when the whole box was shown)
    with Image.open(path) as gif:
        assert gif.n_frames == 61 and gif.size[0] == round(fig.get_figwidth() * 80)
    (clock,) = [t for t in ax.texts if t.get_text().startswith("t = ")]
    assert clock.get_position()[1] > 1.0  # above the panel, not over the discs
    assert ax.get_xlabel() == "x" and ax.get_ylabel() == "y"
    # One arrow per disc, along its velocity at the last frame.
    for panel, sim in zip(fig.axes, (pit, pic), strict=True):
        (quiver,) = [c for c in panel.collections if isinstance(c, matplotlib.quiver.Quiver)]
        np.testing.assert_allclose(quiver.get_offsets(), sim.positions)
        arrows = np.column_stack([quiver.U, quiver.V])
        np.testing.assert_allclose(arrows / np.abs(arrows).max(), sim.velocities / np.abs(sim.velocities).max())
        box = panel.transData.inverted().transform(quiver.get_clip_box().get_points())
        np.testing.assert_allclose(box, [[0.0, 0.0], [case.box.width, case.box.height]], atol=1e-9)  # cut at the walls
    plot.close(anim)
    # The whole box, when asked.
    whole = plot.animate(pic, zoom=False)
    assert whole._fig.axes[0].get_xlim()[1] > case.box.width
    plot.close(whole)


def test_animate_draws_the_velocity_of_a_falling_ball_at_each_frame(tmp_path):
    sim = ds.EventDriven(ds.Discs([[2.0, 8.0]], [[1.0, 0.0]], 0.5), ds.Box(10.0, 10.0), gravity=(0.0, -9.81))
    sim.run(until=1.0)  # no record yet: the log's velocity is the start's, (1, 0)
    anim = plot.animate(sim, tmp_path / "fall.gif", arrows=True, max_frames=8, dpi=40)  # drawn to the last frame
    (quiver,) = [c for c in anim._fig.axes[0].collections if isinstance(c, matplotlib.quiver.Quiver)]
    arrow = np.array([quiver.U[0], quiver.V[0]])
    np.testing.assert_allclose(arrow / np.hypot(*arrow), sim.velocities[0] / np.hypot(*sim.velocities[0]))
    plot.close(anim)


def test_state_figures_name_their_axes():
    ax = plot.plot_state(ds.Discs([[1.0, 1.0]], [[1.0, 0.0]], radii=0.5), box=ds.Box(4.0, 3.0))
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x", "y")


def test_animate_follows_discs_that_come_and_go():
    discs, box = ds.random_gas(12, 0.2, seed=4)
    sim = ds.EventDriven(discs, box).run(until=1.0)
    sim.remove_discs([2, 5])
    spots = ([x, y] for x in np.linspace(1.0, box.width - 1.0, 15) for y in np.linspace(1.0, box.height - 1.0, 15))
    spot = next(p for p in spots if (np.hypot(*(sim.positions - p).T) > sim.discs.radii + 0.6).all())
    sim.add_discs(ds.Discs([spot], [[1.0, -0.5]], 0.5))
    sim.run(until=2.0)
    anim = plot.animate(sim, times=[2.0, 0.5], arrows=True)  # the figure shows the first time, 2.0
    (collection,) = [
        c for c in anim._fig.axes[0].collections if isinstance(c, matplotlib.collections.EllipseCollection)
    ]
    expected = sim.trajectory([2.0])[0]
    offsets = np.asarray(collection.get_offsets())
    assert len(offsets) == len(expected) == 13  # one circle per disc id, the one added included
    shown = np.isfinite(expected).all(axis=1)
    np.testing.assert_allclose(offsets[shown], expected[shown])
    assert (offsets[~shown] > 1e8).all() and (~shown).sum() == 2  # the removed discs: moved out of sight
    # Each circle has its disc's size: the added one (id 12) its radius 0.5 (get_widths: full widths).
    np.testing.assert_allclose(collection.get_widths(), 2.0 * np.append(discs.radii, 0.5))
    plot.close(anim)


def sensed_run():
    discs, box = ds.random_gas(20, 0.2, seed=5)
    w, h = box.width, box.height
    sensors = [
        ds.Sensor.circle((0.3 * w, 0.3 * h), 0.15 * w),
        ds.Sensor.rectangle((0.6 * w, 0.1 * h), (0.9 * w, 0.4 * h)),
        ds.Sensor.line((0.1 * w, 0.7 * h), (0.9 * w, 0.7 * h)),
    ]
    return ds.EventDriven(discs, box, sensors=sensors).run(until=0.5), sensors


def sensor_artists(ax) -> dict:
    """The artists a plot tagged as sensors, by gid (``sensor k``, and ``sensor k inside`` for a wire's arrow)."""
    found: dict = {}
    for artist in ax.get_children():
        gid = artist.get_gid() or ""
        if gid.startswith("sensor"):
            assert gid not in found, f"two artists for {gid}"
            found[gid] = artist
    return found


def assert_draws_sensors(ax, sensors):
    from matplotlib.patches import Rectangle
    from matplotlib.text import Annotation

    artists = sensor_artists(ax)
    assert sorted(artists) == ["sensor 0", "sensor 1", "sensor 2", "sensor 2 inside"]  # one each, and one arrow
    circle, rectangle, wire, arrow = (artists[k] for k in sorted(artists))
    (cx, cy, r, _), (x0, y0, x1, y1), (p0x, p0y, p1x, p1y) = (s.params.tolist() for s in sensors)
    assert isinstance(circle, Circle) and circle.center == (cx, cy) and circle.radius == r
    assert circle.get_facecolor()[3] < 0.5  # translucent
    assert isinstance(rectangle, Rectangle) and rectangle.get_xy() == (x0, y0)
    assert (rectangle.get_width(), rectangle.get_height()) == (x1 - x0, y1 - y0)
    assert wire.get_xydata().tolist() == [[p0x, p0y], [p1x, p1y]] and wire.get_linestyle() == "--"
    # The arrow starts on the wire and points to its inside, the left of p1 - p0.
    assert isinstance(arrow, Annotation)
    (tx, ty), (sx, sy) = arrow.xy, arrow.xyann
    assert sensors[2].contains([tx, ty])[0]  # the tip lies inside
    assert abs((p1x - p0x) * (sy - p0y) - (p1y - p0y) * (sx - p0x)) < 1e-9  # the tail lies on the wire


def test_the_plots_draw_each_sensor_once(tmp_path):
    sim, sensors = sensed_run()
    assert_draws_sensors(plot.plot_state(sim), sensors)
    assert_draws_sensors(plot.plot_trajectories(sim), sensors)
    pit = ds.FixedStep(sim.discs, sim.box, frame_rate=20.0).run(until=0.5)
    _, pic_ax = plot.plot_case(sim, pit).axes[:2]
    assert_draws_sensors(pic_ax, sensors)
    anim = plot.animate(sim, zoom=False)
    assert_draws_sensors(anim._fig.axes[0], sensors)
    plot.close(anim)
    assert not sensor_artists(plot.plot_state(ds.EventDriven(*ds.random_gas(5, 0.2)).run(until=0.1)))
    assert_not_blank(plot.save_figure(plot.plot_state(sim), tmp_path / "sensors.png"))


def paddle_run():
    """A disc, a paddle moving at (-1, 0) from x = 8 and a fixed floor, run to t = 4."""
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0), velocity=(-1.0, 0.0))
    floor = ds.Segment((1.0, 1.0), (9.0, 1.0))
    discs = ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], radii=0.4)
    return ds.EventDriven(discs, ds.Box(10.0, 10.0), segments=[paddle, floor]).run(until=4.0)


def drawn_segments(ax) -> list:
    (lines,) = [c for c in ax.collections if c.get_gid() == "segments"]
    return [s.tolist() for s in lines.get_segments()]


PADDLE_AT = {t: [[8.0 - t, 3.0], [8.0 - t, 7.0]] for t in (0.0, 1.5, 2.5, 4.0)}  # p0 + v t, p1 + v t
FLOOR = [[1.0, 1.0], [9.0, 1.0]]


def test_animate_draws_a_moving_segment_where_it_is_at_each_frame(tmp_path):
    sim = paddle_run()
    anim = plot.animate(sim, times=[1.5, 4.0])  # the figure shows the first frame
    assert drawn_segments(anim._fig.axes[0]) == [PADDLE_AT[1.5], FLOOR]
    plot.close(anim)
    anim = plot.animate(sim, tmp_path / "paddle.gif", times=[0.0, 2.5], dpi=30)  # saving draws to the last frame
    assert drawn_segments(anim._fig.axes[0]) == [PADDLE_AT[2.5], FLOOR]
    plot.close(anim)


def test_animate_draws_a_steered_segment_where_it_was_at_each_frame():
    # Fixed at x = 8 until t = 1, then at -1 along x: at 0.5 still at 8, at 3 at 6.
    paddle = ds.Segment((8.0, 3.0), (8.0, 7.0))
    sim = ds.EventDriven(ds.Discs([[2.0, 5.0]], [[0.5, 0.0]], radii=0.4), ds.Box(10.0, 10.0), segments=[paddle])
    sim.run(until=1.0).set_segment_velocity(0, (-1.0, 0.0)).run(until=3.0)
    anim = plot.animate(sim, times=[0.5, 3.0])  # the figure shows the first frame
    assert drawn_segments(anim._fig.axes[0]) == [[[8.0, 3.0], [8.0, 7.0]]]
    plot.close(anim)


def test_the_still_plots_draw_a_moving_segment_where_it_is_at_their_time():
    sim = paddle_run()
    assert drawn_segments(plot.plot_state(sim)) == [PADDLE_AT[4.0], FLOOR]
    assert drawn_segments(plot.plot_trajectories(sim)) == [PADDLE_AT[4.0], FLOOR]  # with the final outlines
    pit = ds.FixedStep(ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], radii=0.4), sim.box, frame_rate=10.0).run(until=4.0)
    pit_ax, pic_ax = plot.plot_case(sim, pit).axes[:2]
    assert drawn_segments(pic_ax) == [PADDLE_AT[4.0], FLOOR]  # at the last frame
    assert not [c for c in pit_ax.collections if c.get_gid() == "segments"]  # PIT's run has no segments


def piston_run():
    """A small gas under a piston, and the piston's height when the run stood at 2.5 and at 6."""
    discs, _ = ds.random_gas(8, 0.15, seed=2, periodic=False)
    box = ds.Box(discs.positions[:, 0].max() + 1.5, 80.0)
    top = float((discs.positions[:, 1] + discs.radii).max()) + 3.0
    sim = ds.EventDriven(discs, box, piston=ds.Piston(mass=5.0, pressure=0.4, height=top, velocity=-0.2))
    at = {t: sim.run(until=t).piston.height for t in (2.5, 6.0)}
    return sim, at


def piston_artists(ax) -> dict:
    return {a.get_gid(): a for a in [*ax.lines, *ax.patches] if (a.get_gid() or "").startswith("piston")}


def test_plot_state_draws_the_piston_where_it_is_and_shades_the_box_above_it():
    sim, at = piston_run()
    drawn = piston_artists(plot.plot_state(sim))
    assert set(drawn) == {"piston", "piston above"}
    assert list(drawn["piston"].get_ydata()) == [at[6.0]] * 2 and list(drawn["piston"].get_xdata()) == [
        0,
        sim.box.width,
    ]
    shade = drawn["piston above"]
    assert (shade.get_y(), shade.get_y() + shade.get_height()) == pytest.approx((at[6.0], sim.box.height), rel=1e-15)
    assert not piston_artists(plot.plot_state(ds.EventDriven(*ds.random_gas(10, 0.2)).run(until=0.5)))


def test_animate_draws_the_piston_where_it_is_at_each_frame(tmp_path):
    sim, at = piston_run()
    anim = plot.animate(sim, times=[2.5, 6.0])  # the figure shows the first frame
    bar = piston_artists(anim._fig.axes[0])["piston"]
    assert bar.get_ydata()[0] == pytest.approx(at[2.5], rel=1e-12)
    plot.close(anim)
    anim = plot.animate(sim, tmp_path / "piston.gif", times=[2.5, 6.0], dpi=30)  # saving draws to the last frame
    drawn = piston_artists(anim._fig.axes[0])
    assert drawn["piston"].get_ydata()[0] == pytest.approx(at[6.0], rel=1e-12)
    assert drawn["piston above"].get_y() == drawn["piston"].get_ydata()[0]
    plot.close(anim)
    plain = plot.animate(ds.EventDriven(*ds.random_gas(10, 0.2)).run(until=0.5))
    assert not piston_artists(plain._fig.axes[0])
    plot.close(plain)
