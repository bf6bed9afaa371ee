"""Pictures of discs, paths, PIT-against-PIC cases and animations (matplotlib).

The only module of discsim that imports matplotlib (with its part ``discsim._plot_sensors``). Every function
reads the engine protocol (``discs``, ``box``, ``time``, ``positions``, ``velocities``, ``events``,
``trajectory``), so it draws any engine; it uses ``dt`` (the frame interval) when an engine has one. Each returns
the matplotlib object it made or drew on; with ``ax=None`` it makes a new figure.

Lengths are drawn to scale: discs are circles of their true radii and the
axes have equal aspect.
An engine's sensors are drawn under the discs, as the viewer draws them; its segments where they are at the
time drawn (a moving one from ``p0 + v t`` to ``p1 + v t``, at each frame of an animation).
A run's piston (``sim.piston``) is a thick bar across the box where it is at the time drawn, the box above it
shaded (at each frame of an animation).
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib import animation
from matplotlib.collections import EllipseCollection, LineCollection, PatchCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Rectangle

from discsim._plot_gif import save_gif
from discsim._plot_piston import draw_piston, piston_mover
from discsim._plot_sensors import draw_segments, draw_sensors, segment_lines
from discsim.errors import InvalidArgumentError
from discsim.events import ADD, COLLISION
from discsim.model import Discs, frame_count
from discsim.trajectory import LastRecords, flight, replay

__all__ = ["animate", "close", "plot_case", "plot_cases", "plot_state", "plot_trajectories", "save_figure"]

_OBSTACLE = "0.55"


def _colours(n: int) -> list:
    cycle = matplotlib.color_sequences["tab10"]  # the colours of the tab10 colour map
    return [cycle[k % len(cycle)] for k in range(n)]


def _disc_colours(masses: np.ndarray) -> list:
    colours = _colours(len(masses))
    return [_OBSTACLE if math.isinf(m) else c for m, c in zip(masses.tolist(), colours, strict=True)]


def _axes(ax, figsize=(6.0, 4.5)):
    if ax is None:
        _, ax = plt.subplots(figsize=figsize)
    return ax


def _setup(ax, box, sensors=()) -> None:
    draw_sensors(ax, sensors, box)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    if box is None:
        ax.autoscale_view()
        return
    style: dict[str, Any] = {"linestyle": ":"} if box.periodic else {}
    ax.add_patch(Rectangle((0.0, 0.0), box.width, box.height, fill=False, edgecolor="0.2", linewidth=1.2, **style))
    pad = 0.02 * max(box.width, box.height)
    ax.set_xlim(-pad, box.width + pad)
    ax.set_ylim(-pad, box.height + pad)


def _circles(ax, positions, radii, colours, *, alpha=0.6, fill=True, linestyle="-", linewidth=1.0, zorder=2):
    patches = [Circle((float(x), float(y)), float(r)) for (x, y), r in zip(positions, radii, strict=True)]
    if fill:
        collection = PatchCollection(
            patches, facecolors=colours, edgecolors=colours, alpha=alpha, linewidths=linewidth, zorder=zorder
        )
    else:
        collection = PatchCollection(
            patches, facecolors="none", edgecolors=colours, linestyles=linestyle, linewidths=linewidth, zorder=zorder
        )
    ax.add_collection(collection)
    return collection


def _arrows(ax, positions, velocities, scale_time, colours, zorder=4):
    """Velocity arrows drawn to scale: an arrow is where the disc gets in ``scale_time``."""
    if not len(positions) or scale_time <= 0:
        return None
    x, y, u, v = positions[:, 0], positions[:, 1], velocities[:, 0] * scale_time, velocities[:, 1] * scale_time
    return ax.quiver(x, y, u, v, color=colours, angles="xy", scale_units="xy", scale=1.0, width=0.004, zorder=zorder)


def _arrow_time(radii: np.ndarray, velocities: np.ndarray) -> float:
    speed = float(np.hypot(velocities[:, 0], velocities[:, 1]).max()) if len(velocities) else 0.0
    return 4.0 * float(radii.max()) / speed if speed > 0 else 0.0


def plot_state(sim_or_discs, ax=None, box=None, *, arrows: bool = True, marks: bool | None = None):
    """Draw discs as circles to scale, with velocity arrows (and a mark on each disc that shows its turning).

    Args:
        sim_or_discs: an engine (drawn at its current ``time``) or a
            :class:`~discsim.model.Discs`.
        ax: matplotlib axes to draw on; None makes a new figure.
        box: the box to outline; default the engine's box (none for bare discs).
        arrows: draw velocity arrows; the longest is four radii of the largest
            disc long, the others to the same scale.
        marks: draw a radius of each disc at its angle (``sim.angles``; 0, along +x, for bare discs), which
            shows its turning from one plot to the next; None: when any disc spins or has turned.

    Returns:
        The matplotlib ``Axes``.

    Example:
        >>> import discsim as ds
        >>> ax = plot_state(ds.Discs([[2.0, 2.0]], [[1.0, 0.0]], radii=1.0), box=ds.Box(5.0, 4.0))
        >>> len(ax.collections) >= 1
        True
        >>> close(ax)
    """
    if isinstance(sim_or_discs, Discs):
        discs, positions, velocities, time = sim_or_discs, sim_or_discs.positions, sim_or_discs.velocities, None
    else:
        sim = sim_or_discs
        discs, positions, velocities, time = sim.discs, sim.positions, sim.velocities, sim.time
        box = sim.box if box is None else box
    ax = _axes(ax)
    colours = _disc_colours(discs.masses)
    _circles(ax, positions, discs.radii, colours)
    angles = getattr(sim_or_discs, "angles", np.zeros(len(discs)))  # an engine's; bare discs have not turned
    if marks or (marks is None and (getattr(sim_or_discs, "spins", discs.spins).any() or angles.any())):
        tips = positions + discs.radii[:, None] * np.column_stack([np.cos(angles), np.sin(angles)]).reshape(-1, 2)
        ax.add_collection(LineCollection(list(np.stack([positions, tips], axis=1)), colors="k", zorder=3))
    if arrows:
        quiver = _arrows(ax, positions, velocities, _arrow_time(discs.radii, velocities), colours)
        if quiver is not None and box is not None:  # arrows end at the walls, as the discs do
            quiver.set_clip_path(Rectangle((0.0, 0.0), box.width, box.height, transform=ax.transData))
    draw_segments(ax, getattr(sim_or_discs, "segments", ()), 0.0 if time is None else time)  # (Discs have none)
    _setup(ax, box, getattr(sim_or_discs, "sensors", ()))
    draw_piston(ax, sim_or_discs)  # a bar where the piston is now, the box above it shaded (none: nothing)
    if box is None and len(positions):
        r = float(discs.radii.max())
        ax.set_xlim(positions[:, 0].min() - 2 * r, positions[:, 0].max() + 2 * r)
        ax.set_ylim(positions[:, 1].min() - 2 * r, positions[:, 1].max() + 2 * r)
    if time is not None:
        ax.set_title(f"{type(sim_or_discs).__name__} at t = {time:.4g}")
    return ax


def _sample_times(sim, samples: int) -> np.ndarray:
    """Evenly spaced times over the simulated span plus every event time (for sharp corners)."""
    start, end = float(sim.start_time), float(sim.time)
    times = np.linspace(start, end, max(2, samples))
    events = sim.events
    if len(events):
        et = events["time"]
        times = np.union1d(times, et[(et >= start) & (et <= end)])
    return times


def _break_wraps(path: np.ndarray, box) -> np.ndarray:
    """Insert NaN rows where a periodic path jumps across the box, so lines are not drawn across it."""
    if box is None or not box.periodic or len(path) < 2:
        return path
    jump = (np.abs(np.diff(path, axis=0)) > 0.5 * box.size).any(axis=1)
    if not jump.any():
        return path
    return np.insert(path, np.flatnonzero(jump) + 1, np.nan, axis=0)


def plot_trajectories(sim, ax=None, discs=None, *, samples: int = 400):
    """Draw the paths of discs over the simulated span, from the event log.

    Args:
        sim: an engine built with ``record=True``.
        ax: matplotlib axes; None makes a new figure.
        discs: indices of the discs to draw; default all when N <= 50,
            else the first 50.
        samples: evenly spaced sample times, on top of every event time.

    Returns:
        The matplotlib ``Axes`` (paths as lines, start as dots, final discs as outlines).

    Example:
        >>> import discsim as ds
        >>> case = ds.head_on(1.0, 2.0)
        >>> sim = ds.EventDriven(case.discs, case.box).run(until=case.until)
        >>> ax = plot_trajectories(sim)
        >>> len(ax.lines)
        2
        >>> close(ax)
    """
    n = len(sim.discs)
    chosen = np.arange(min(n, 50)) if discs is None else np.atleast_1d(np.asarray(discs, dtype=np.int64))
    if chosen.size and (chosen.min() < 0 or chosen.max() >= n):
        bad = int(chosen[(chosen < 0) | (chosen >= n)][0])
        msg = f"disc index {bad} is out of range for {n} discs"
        raise IndexError(msg)
    ax = _axes(ax)
    times = _sample_times(sim, samples)
    paths = sim.trajectory(times)[:, sim.ids]  # the discs there now (NaN before one was added: not drawn)
    colours = _disc_colours(sim.discs.masses)
    for i in chosen.tolist():
        path = _break_wraps(paths[:, i, :], sim.box)
        ax.plot(path[:, 0], path[:, 1], color=colours[i], linewidth=1.2)
    starts = paths[0, chosen]
    ax.scatter(starts[:, 0], starts[:, 1], s=8, c=[colours[i] for i in chosen.tolist()], zorder=3)
    _circles(ax, paths[-1, chosen], sim.discs.radii[chosen], [colours[i] for i in chosen.tolist()], fill=False)
    draw_segments(ax, getattr(sim, "segments", ()), float(times[-1]))  # where they are with the final outlines
    _setup(ax, sim.box, getattr(sim, "sensors", ()))
    ax.set_title(f"{type(sim).__name__}: paths over t in [{times[0]:.3g}, {times[-1]:.3g}]")
    return ax


def _frame_times(truth, approx, max_frames: int) -> np.ndarray:
    start = max(float(truth.start_time), float(approx.start_time))
    end = min(float(truth.time), float(approx.time))
    dt = max(float(getattr(e, "dt", 0.0) or 0.0) for e in (truth, approx))
    if dt > 0:
        count = frame_count(start, end, dt)
        times = np.minimum(start + dt * np.arange(count + 1), end)
    else:
        times = np.linspace(start, end, 11)
    if len(times) > max_frames:
        times = times[np.linspace(0, len(times) - 1, max_frames).round().astype(int)]
    return times


def _case_limits(frames_list, radii, box, *, min_aspect: float = 0.35):
    """Axis limits ``(x0, x1, y0, y1)`` around every drawn disc, within the box (plus a margin).

    Neither side is shorter than ``min_aspect`` times the other (when the box allows): a case whose
    discs move along a line is not drawn as a flat strip.
    """
    points = np.concatenate([f.reshape(-1, 2) for f in frames_list])
    margin = 1.5 * float(radii.max())
    pad = 0.02 * max(box.width, box.height)
    lo = np.maximum(-pad, points.min(axis=0) - margin)
    hi = np.minimum(np.array([box.width, box.height]) + pad, points.max(axis=0) + margin)
    bounds = (np.array([-pad, -pad]), np.array([box.width + pad, box.height + pad]))
    for axis in (0, 1):
        need = min_aspect * float(hi[1 - axis] - lo[1 - axis]) - float(hi[axis] - lo[axis])
        if need > 0:  # grow this side about its centre, shifted back inside the box
            lo[axis] -= need / 2
            hi[axis] += need / 2
            shift = max(0.0, bounds[0][axis] - lo[axis]) - max(0.0, hi[axis] - bounds[1][axis])
            lo[axis] = max(bounds[0][axis], lo[axis] + shift)
            hi[axis] = min(bounds[1][axis], hi[axis] + shift)
    return float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1])


def _frame_labels(frames, discs, limits) -> list[tuple[float, float, str]]:
    """Frame numbers to write on the discs, ``(x, y, text)``, none overlapping another.

    A disc that stays in place (within a third of its radius) over several frames gets one label for
    them all (``"2-5"``); a label that would overlap one already placed (earlier frames first) is left
    out. Fixed obstacles get none. Label sizes are estimated from the axes' span (7-point text on a
    panel about 5 inches wide).
    """
    span = max(limits[1] - limits[0], limits[3] - limits[2])
    char, height = 0.014 * span, 0.045 * span  # one character's width and a line's height, in data units
    candidates = []
    for i in range(len(discs)):
        if np.isinf(discs.masses[i]):
            continue
        rest = float(discs.radii[i]) / 3.0
        first = 0
        for k in range(1, len(frames) + 1):
            if k == len(frames) or np.hypot(*(frames[k][i] - frames[first][i])) > rest:
                text = str(first) if k - 1 == first else f"{first}-{k - 1}"
                candidates.append((first, float(frames[first][i][0]), float(frames[first][i][1]), text))
                first = k
    placed: list[tuple[float, float, str]] = []
    for _, x, y, text in sorted(candidates, key=lambda c: c[0]):
        half = char * (len(text) + 1) / 2
        if all(abs(x - px) >= half + char * (len(pt) + 1) / 2 or abs(y - py) >= height for px, py, pt in placed):
            placed.append((x, y, text))
    return placed


def _draw_case_panel(ax, sim, truth, frames, times, arrow_time, contact_style, title, limits):
    discs = sim.discs
    colours = _disc_colours(discs.masses)
    n = len(discs)
    for k, positions in enumerate(frames):
        alpha = 0.12 + 0.43 * k / max(1, len(frames) - 1)
        _circles(ax, positions, discs.radii, colours, alpha=alpha, linewidth=0.6)
    if len(times) <= 25 and n <= 12:
        for x, y, text in _frame_labels(frames, discs, limits):
            ax.text(x, y, text, ha="center", va="center", fontsize=7, color="0.1", zorder=5)
    # Exact contacts (the truth's collisions) as unfilled outlines.
    ev = truth.events
    ev = ev[(ev["kind"] == COLLISION) & (ev["time"] <= times[-1])]
    for rec in ev[:40]:
        for d, x, y in ((int(rec["i"]), rec["xi"], rec["yi"]), (int(rec["j"]), rec["xj"], rec["yj"])):
            ax.add_patch(
                Circle(
                    (float(x), float(y)),
                    float(discs.radii[d]),
                    fill=False,
                    edgecolor=colours[d],
                    linestyle=contact_style,
                    linewidth=1.6,
                    zorder=3,
                )
            )
    # Velocities after each of this engine's collisions.
    own = sim.events
    own = own[(own["kind"] == COLLISION) & (own["time"] <= times[-1])][:40]
    if len(own):
        pos = np.concatenate([np.column_stack([own["xi"], own["yi"]]), np.column_stack([own["xj"], own["yj"]])])
        vel = np.concatenate([np.column_stack([own["vxi"], own["vyi"]]), np.column_stack([own["vxj"], own["vyj"]])])
        who = np.concatenate([own["i"], own["j"]]).tolist()
        _arrows(ax, pos, vel, arrow_time, [colours[d] for d in who])
    draw_segments(ax, getattr(sim, "segments", ()), float(times[-1]))  # where they are at the last frame
    _setup(ax, sim.box, getattr(sim, "sensors", ()))
    ax.set_xlim(limits[0], limits[1])
    ax.set_ylim(limits[2], limits[3])
    ax.set_title(title, fontsize=10)


_CASE_LEGEND = (
    Line2D([], [], color="0.3", linestyle="-", linewidth=1.6, label="exact contact (PIC)"),
    Line2D([], [], color="0.3", linestyle="--", linewidth=1.6, label="exact contact, for reference"),
    Line2D([], [], color="0.3", marker=r"$\rightarrow$", linestyle="none", markersize=12, label="velocity after"),
)


def _case_frames(truth, approx, max_frames: int):
    """Frame times, PIT's and PIC's positions at them, the frame interval and the axis limits of a case."""
    times = _frame_times(truth, approx, max_frames)
    dt = float(getattr(approx, "dt", 0.0) or 0.0) or (times[-1] - times[0]) / 10.0
    frames_pit, frames_pic = approx.trajectory(times), truth.trajectory(times)
    limits = _case_limits([frames_pit, frames_pic], truth.discs.radii, truth.box)
    return times, frames_pit, frames_pic, dt, limits


def _two_axes(ax):
    try:
        axes = list(np.ravel(np.asarray(ax, dtype=object)))
    except TypeError:
        axes = [ax]
    if len(axes) != 2 or not all(hasattr(a, "add_patch") for a in axes):
        msg = f"plot_case(ax=...) takes two matplotlib axes (PIT's, PIC's), got {ax!r}"
        raise InvalidArgumentError(msg)
    return axes


def plot_case(truth, approx, *, ax=None, title: str | None = None, max_frames: int = 40):
    """PIT and PIC side by side, drawn like the study's figures.

    Each panel shows the discs at every frame time (fainter earlier; frame
    numbers on small cases, one label for the frames a disc spends in one place, none stacked), zoomed to
    where the discs go (never flatter than about 1:3), the exact contacts of the truth as unfilled
    outlines (solid on the PIC panel, dashed on the PIT panel, for reference)
    and each disc's velocity after each of that run's collisions as an arrow
    (drawn as the path covered in two frames).

    Args:
        truth: the exact run (PIC), drawn on the right.
        approx: the fixed-step run (PIT), drawn on the left; its ``dt`` sets
            the frame times.
        ax: two matplotlib axes ``(PIT's, PIC's)`` to draw on, e.g. a row of a grid (see
            :func:`plot_cases`); None makes a new figure with a legend.
        title: title of the figure (or of the subfigure holding ``ax``).
        max_frames: at most this many frame times are drawn (evenly thinned).

    Returns:
        The matplotlib ``Figure`` (the one holding ``ax`` when given).

    Raises:
        InvalidArgumentError: if ``ax`` is not two axes.

    Example:
        >>> import discsim as ds
        >>> case = ds.scenarios.delay()
        >>> pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
        >>> pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
        >>> fig = plot_case(pic, pit, title=case.name)
        >>> len(fig.axes)
        2
        >>> close(fig)
    """
    own = ax is None
    if not own:
        ax_pit, ax_pic = _two_axes(ax)
    times, frames_pit, frames_pic, dt, limits = _case_frames(truth, approx, max_frames)
    if own:
        aspect = (limits[3] - limits[2]) / (limits[1] - limits[0])
        fig, (ax_pit, ax_pic) = plt.subplots(1, 2, figsize=(11.0, min(9.0, max(3.0, 5.5 * aspect + 1.2))))
    else:
        fig = ax_pit.figure
    rate = f", {1.0 / dt:.3g} frames per unit time" if dt > 0 else ""
    _draw_case_panel(
        ax_pit, approx, truth, frames_pit, times, 2.0 * dt, "--", f"PIT ({type(approx).__name__}{rate})", limits
    )
    _draw_case_panel(
        ax_pic, truth, truth, frames_pic, times, 2.0 * dt, "-", f"PIC ({type(truth).__name__}), the truth", limits
    )
    if title:
        fig.suptitle(textwrap.fill(title, 110), fontsize=11)
    if own:
        fig.legend(handles=list(_CASE_LEGEND), loc="lower center", ncol=3, fontsize=8, frameon=False)
        fig.tight_layout(rect=(0.0, 0.06, 1.0, 1.0))
    return fig


def plot_cases(cases, *, width: float = 11.0, max_frames: int = 40):
    """Several PIT-against-PIC cases in one figure: one row per case, PIT left, PIC right.

    Each row is a subfigure drawn by :func:`plot_case` with its title above it; rows are as tall as
    their cases need.

    Args:
        cases: a sequence of ``(truth, approx, title)``: the exact run (PIC), the fixed-step run (PIT)
            and the row's title (or None).
        width: figure width in inches.
        max_frames: at most this many frame times per case.

    Returns:
        The matplotlib ``Figure``.

    Example:
        >>> import discsim as ds
        >>> rows = []
        >>> for case in ds.study_cases()[:2]:
        ...     pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
        ...     pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
        ...     rows.append((pic, pit, case.name))
        >>> fig = plot_cases(rows)
        >>> len(fig.axes), len(fig.subfigs)
        (4, 2)
        >>> close(fig)
    """
    cases = list(cases)
    if not cases:
        msg = "plot_cases() needs at least one (truth, approx, title)"
        raise InvalidArgumentError(msg)
    heights = []
    for truth, approx, _ in cases:
        limits = _case_frames(truth, approx, max_frames)[-1]
        aspect = (limits[3] - limits[2]) / (limits[1] - limits[0])
        heights.append(min(0.9 * width, max(0.25 * width, 0.5 * width * aspect)) * 0.9 + 0.7)
    fig = plt.figure(figsize=(width, sum(heights) + 0.4), layout="constrained")
    rows = fig.subfigures(len(cases), 1, height_ratios=heights, squeeze=False)[:, 0]
    for row, (truth, approx, title) in zip(rows, cases, strict=True):
        plot_case(truth, approx, ax=row.subplots(1, 2), title=title, max_frames=max_frames)
    fig.legend(handles=list(_CASE_LEGEND), loc="outside lower center", ncol=3, fontsize=8, frameon=False)
    return fig


#: Frames a default animation aims at: a run with a frame interval gets sub-frames in between.
_ANIMATION_FRAMES = 60


def _animation_times(sims, max_frames: int) -> tuple[np.ndarray, float]:
    """Frame times of an animation and the frame interval of the runs (0 when none has one).

    With a frame interval ``dt`` (a PIT run), every frame time of that run is a movie frame, with evenly
    spaced sub-frames in between so that the motion reads (about ``_ANIMATION_FRAMES`` in all).
    """
    start = max(float(s.start_time) for s in sims)
    end = min(float(s.time) for s in sims)
    dt = max(float(getattr(s, "dt", 0.0) or 0.0) for s in sims)
    if dt > 0:
        count = frame_count(start, end, dt)
        sub = max(1, min(math.ceil(_ANIMATION_FRAMES / max(1, count)), max(1, (max_frames - 1) // max(1, count))))
        times = np.minimum(start + dt * (np.arange(count * sub + 1) / sub), end)
    else:
        times = np.linspace(start, end, _ANIMATION_FRAMES + 1)
    if len(times) > max_frames:
        times = times[np.linspace(0, len(times) - 1, max_frames).round().astype(int)]
    return times, dt


def _contact_outlines(ax, truth, colours, linestyle):
    """Unfilled outlines of ``truth``'s collisions (hidden; shown from their time on): ``[(time, patch)]``."""
    ev = truth.events
    ev = ev[ev["kind"] == COLLISION][:40]
    out = []
    for rec in ev:
        for d, x, y in ((int(rec["i"]), rec["xi"], rec["yi"]), (int(rec["j"]), rec["xj"], rec["yj"])):
            patch = Circle(
                (float(x), float(y)),
                float(truth.discs.radii[d]),
                fill=False,
                edgecolor=colours[d],
                linestyle=linestyle,
                linewidth=1.6,
                zorder=3,
                visible=False,
            )
            ax.add_patch(patch)
            out.append((float(rec["time"]), patch))
    return out


def animate(
    sim,
    path=None,
    *,
    times=None,
    fps: float = 10.0,
    dpi: int = 80,
    max_frames: int = 200,
    title=None,
    arrows: bool = False,
    zoom: bool = True,
):
    """Animate one run, or several side by side, from their event logs.

    The time is written above the first panel, clear of the discs (with the frame number on a PIT frame
    time), each run's segments are drawn where they are at each frame's time (a moving one from ``p0 + v t`` to
    ``p1 + v t``), and the collisions of the event-driven runs are outlined from their time on (solid on their own
    panel, dashed on the others, as in :func:`plot_case`).

    Args:
        sim: an engine, or a sequence of engines over the same box (e.g.
            ``[pit, pic]``), each built with ``record=True``.
        path: where to save: ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).
            None saves nothing.
        times: the frame times ``(T,)``; default about 60 evenly spaced times, which include every
            frame time of the run with the largest ``dt``; at most ``max_frames`` of them.
        fps: frames per second of the movie.
        dpi: resolution of a saved movie.
        max_frames: cap on the default number of frames.
        title: figure title.
        arrows: draw each disc's velocity as an arrow (the fastest is four radii of the largest disc long).
        zoom: show only the part of the box the discs visit (with a margin, as :func:`plot_case` does),
            so that small discs in a large box are drawn large enough to see; False shows the whole box.

    Returns:
        The ``matplotlib.animation.FuncAnimation``.

    Raises:
        ValueError: on a file suffix other than ``.gif`` or ``.mp4``.
        RuntimeError: for ``.mp4`` when no ffmpeg writer is available.

    Example:
        >>> import discsim as ds
        >>> case = ds.head_on(1.0, 1.0)
        >>> sim = ds.EventDriven(case.discs, case.box).run(until=case.until)
        >>> anim = animate(sim)
        >>> close(anim)
    """
    sims = list(sim) if isinstance(sim, Sequence) else [sim]
    if not sims:
        msg = "animate() needs at least one engine"
        raise InvalidArgumentError(msg)
    if path is not None:
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".gif", ".mp4"):
            msg = f"animate() saves .gif or .mp4 files, got {str(path)!r}"
            raise InvalidArgumentError(msg)
        if suffix == ".mp4" and not animation.writers.is_available("ffmpeg"):
            msg = f"cannot write {str(path)!r}: MP4 needs ffmpeg, which was not found; save a .gif instead"
            raise RuntimeError(msg)
    if times is None:
        times, dt = _animation_times(sims, max_frames)
    else:
        times, dt = np.atleast_1d(np.asarray(times, dtype=float)), 0.0
    box = sims[0].box
    paths_of = [s.trajectory(times) for s in sims]
    radii = np.concatenate([np.asarray(s.discs.radii, dtype=float) for s in sims])
    if zoom:
        seen = [p[np.isfinite(p).all(axis=-1)] for p in paths_of]
        limits = _case_limits(seen, radii, box, min_aspect=0.5)
    else:
        pad = 0.02 * max(box.width, box.height)
        limits = (-pad, box.width + pad, -pad, box.height + pad)
    aspect = (limits[3] - limits[2]) / (limits[1] - limits[0])
    width = 4.5 * len(sims)
    fig, axes = plt.subplots(1, len(sims), figsize=(width, max(2.5, 4.5 * aspect + 0.9)), squeeze=False)
    truths = [s for s in sims if type(s).__name__ == "EventDriven"]
    panels, outlines, dynamic, pistons = [], [], [], []
    for ax, s, paths in zip(axes[0], sims, paths_of, strict=True):
        start, ids = s.run_context.log_origin(s.discs)  # the log names discs by id: one column each
        origin = LastRecords.at_start(start, float(s.start_time), ids)
        scene = origin.after(s.events[s.events["kind"] == ADD]).grown(paths.shape[1])  # with the discs added
        colours = _disc_colours(np.nan_to_num(scene.masses, nan=1.0))
        # One collection of circles per panel, moved each frame (its offsets), not one patch per disc.
        d = 2.0 * np.nan_to_num(scene.radii)
        style: dict[str, Any] = {"facecolors": colours, "edgecolors": colours, "alpha": 0.75, "zorder": 2}
        discs = ax.add_collection(  # sizes in data units ("xy"): the discs to scale
            EllipseCollection(d, d, 0 * d, units="xy", offsets=paths[0], offset_transform=ax.transData, **style)
        )
        dynamic.append(discs)
        quiver = None
        if arrows:
            laws = getattr(s, "laws", None)  # under gravity the velocities change between records
            gravity = flight(getattr(laws, "gravity", None), getattr(laws, "drag", 0.0), what="animate(arrows=True)")
            speeds = replay([s.events], origin, times, s.box, velocities=True, gravity=gravity)[1]
            scale = _arrow_time(s.discs.radii, speeds.reshape(-1, 2)[np.isfinite(speeds.reshape(-1, 2)).all(axis=1)])
            quiver = _arrows(ax, np.nan_to_num(paths[0]), np.nan_to_num(speeds[0]) * 0.0, max(scale, 1e-300), colours)
            if quiver is not None:  # cut at the walls, as in plot_state
                quiver.set_clip_path(Rectangle((0.0, 0.0), s.box.width, s.box.height, transform=ax.transData))
                dynamic.append(quiver)
            speeds = speeds * scale
        if len(sims) > 1:
            for truth in truths:
                outlines += _contact_outlines(ax, truth, colours, "-" if truth is s else "--")
        segments = tuple(getattr(s, "segments", ()))
        walls = draw_segments(ax, segments, float(times[0]))
        moving = walls if any(s.moving or s.pieces() for s in segments) else None  # moved (or steered): each frame
        dynamic += [] if moving is None else [moving]
        _setup(ax, s.box, getattr(s, "sensors", ()))
        pistons.append(piston_mover(ax, s, times, dynamic))  # where the piston is at each frame (none: no-op)
        ax.set_xlim(limits[0], limits[1])
        ax.set_ylim(limits[2], limits[3])
        ax.set_title(type(s).__name__, fontsize=10, loc="left")
        panels.append((paths, discs, quiver, speeds if arrows else None, segments, moving))
    dynamic += [patch for _, patch in outlines]
    clock = axes[0][0].text(
        1.0, 1.02, "", transform=axes[0][0].transAxes, ha="right", va="bottom", fontsize=9, zorder=6
    )  # above the panel: never over the discs
    dynamic.append(clock)
    if title:
        fig.suptitle(title)
    fig.tight_layout()

    def update(k):
        for paths, discs, quiver, speeds, segments, moving in panels:
            here = paths[k]
            gone = ~np.isfinite(here).all(axis=1)  # not there at this time (added later, or removed)
            discs.set_offsets(np.where(gone[:, None], 1e9, here))
            if quiver is not None:
                quiver.set_offsets(np.where(gone[:, None], 1e9, here))
                quiver.set_UVC(*np.nan_to_num(speeds[k]).T)
            if moving is not None:
                moving.set_segments(segment_lines(segments, float(times[k])))
        for t, patch in outlines:
            patch.set_visible(t <= times[k])
        for move in pistons:
            move(k)
        frame = (times[k] - times[0]) / dt if dt > 0 else math.nan
        on_frame = dt > 0 and abs(frame - round(frame)) < 1e-9
        clock.set_text(f"t = {times[k]:.3f}" + (f"  (PIT frame {round(frame)})" if on_frame else ""))
        return dynamic

    update(0)
    anim = animation.FuncAnimation(fig, update, frames=len(times), interval=1000.0 / fps, blit=False)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        if path.suffix.lower() == ".gif":
            save_gif(fig, update, dynamic, len(times), path, fps, dpi)
            anim._draw_was_started = True  # type: ignore[attr-defined]  # saved without FuncAnimation's loop
        else:
            # matplotlib's stubs ask for an int, but the writer takes any positive frame rate.
            anim.save(str(path), writer=animation.FFMpegWriter(fps=fps), dpi=dpi)  # type: ignore[arg-type]
    return anim


def _figure_of(obj: Any) -> Figure:
    if isinstance(obj, animation.Animation):
        return obj._fig  # type: ignore[attr-defined]  # the animation's figure, not in matplotlib's stubs
    return getattr(obj, "figure", obj)


def save_figure(obj, path, *, dpi: int = 110) -> Path:
    """Save the figure of ``obj`` (a Figure or Axes) to ``path``, close it, and return the path.

    Example:
        >>> import tempfile, discsim as ds
        >>> ax = plot_state(ds.Discs([[1.0, 1.0]], [[0.0, 0.0]], radii=0.5), box=ds.Box(2.0, 2.0))
        >>> save_figure(ax, tempfile.mkdtemp() + "/state.png").exists()
        True
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = _figure_of(obj)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def close(obj) -> None:
    """Close the figure of ``obj`` (a Figure, Axes or animation), freeing its memory."""
    if isinstance(obj, animation.Animation):
        obj.pause()
        # Discarded on purpose: spare the "Animation was deleted without rendering anything" warning.
        obj._draw_was_started = True  # type: ignore[attr-defined]  # Animation's private flag, not in its stubs
    plt.close(_figure_of(obj))
