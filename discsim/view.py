"""Watch a run in a browser: one self-contained HTML page that replays the exact motion from the event log.

:func:`view` writes a single HTML file (no network: the script, the style and the data are inline) that
replays a run of either engine, or several side by side (PIT against PIC), at any playback speed and frame
rate, with play, pause, step, a time scrubber, discs coloured by disc, group or speed, and the exact
contacts marked. Between events discs fly straight, or fall along exact parabolas under gravity (a disc at
rest stays put), so the page rebuilds every position exactly as :func:`discsim.trajectory.reconstruct` does,
with the same floating-point operations (the same numbers, bit for bit): it holds the discs' state where the
replay starts and each disc's state after each of its events. Where the run says how its discs turn (an
engine's spins, rough discs' spins after each collision), a radius line on each disc shows its angle.
The run's segments are drawn where they are at the time shown: a moving one (``Segment(..., velocity=v)``)
from ``p0 + v t`` to ``p1 + v t``. The run's sensors (:class:`~discsim.sensors.Sensor`) are drawn under the
discs: circles and rectangles as translucent outlined regions, trip wires dashed with a small arrow to their
inside (the left of ``p1 - p0``); a sensor lights up for 0.3 s of playing after a disc enters it.

In the page, ``window.discsim`` is a small API for scripts and tests: ``seek(t)``, ``time()``,
``positions(panel)`` (the centres last drawn, ``(N, 2)`` as nested lists), ``angles(panel)`` (the angles of
the marks last drawn, ``(N,)``, or null where the run does not say how its discs turn), ``sensors(panel)`` (each
sensor's ``shape``, ``params`` and whether it is ``lit`` at the time last drawn), ``segments(panel)`` (each
segment's end points ``[x0, y0, x1, y1]`` as last drawn), ``play()``, ``pause()``,
``step(frames)``, ``nextEvent()``, ``previousEvent()``, ``setSpeed(s)``, ``setFps(f)``, ``setColour(mode)``.
A page opened as ``view.html#t=1.25`` starts at that time.

Typical use::

    pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    ds.view(pic, "case.html", compare_with=pit)       # PIT left, PIC right, the exact contacts marked
    ds.view("run-folder")                              # a folder written by `discsim run --out run-folder`
"""

from __future__ import annotations

import base64
import html
import json
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from discsim.errors import InvalidArgumentError
from discsim.events import ADD, COLLISION, ENTER, EVENT_DTYPE, EventKind, disc_count, disc_partners
from discsim.trajectory import LastRecords, falling, flight, turning_history

if TYPE_CHECKING:
    from discsim.analysis.piston_path import PistonPath
    from discsim.model import Box

__all__ = ["COLOUR_MODES", "DEFAULT_MAX_EVENTS", "View", "view"]

#: How discs can be coloured: each disc its own colour, by collision group, or by speed (a colour scale).
COLOUR_MODES = ("auto", "disc", "group", "speed")
#: At most this many events (all runs together, within the shown span) unless ``max_events`` says otherwise:
#: about 140 bytes of page each (a collision holds both discs' state after it).
DEFAULT_MAX_EVENTS = 250_000
#: The files of a run folder written by ``discsim run --out DIR`` that the viewer reads.
RUN_FOLDER_FILES = ("events.dse", "state.dsc")

_ASSETS = Path(__file__).parent / "_assets"


@dataclass(frozen=True)
class _Run:
    """One run reduced to what the page needs: the scene, where its log starts, and its records chunk by chunk.

    ``chunks()`` walks the log from its start (a streamed log is read from disk chunk by chunk), so that
    a span late in a long log is replayed with memory flat in the log's length.
    """

    label: str
    engine: str
    box: Box
    segments: tuple
    origin: LastRecords
    start_time: float
    end_time: float
    chunks: Callable[[], Iterable[np.ndarray]]
    dt: float | None
    gravity: tuple[float, float] | None = None
    turning: tuple | None = None  # a turning_history of the discs by id, or None: the page draws no marks
    sensors: tuple = ()  # the run's Sensors, drawn as regions and trip wires
    piston: PistonPath | None = None  # the knots of the run's piston (a bar where it is), or None: no piston


@dataclass(frozen=True)
class _Span:
    """A run's records for the span ``[t0, t1]``: where each disc stood at ``t0`` and the events in the span."""

    before: LastRecords
    events: np.ndarray


# --- reading the sources ---------------------------------------------------------------------------------


def _engine_flight(sim, name: str):
    laws = getattr(sim, "laws", None)
    return flight(getattr(laws, "gravity", None), getattr(laws, "drag", 0.0), what=f"the viewer of this {name}")


def _engine_turning(sim, events: np.ndarray, discs, ids) -> tuple | None:
    """A :func:`~discsim.trajectory.turning_history` of an engine's discs by id (None: no disc turns, or the
    spins after its collisions are not held). A disc added during the run starts without spin in it (the log's
    ``ADD`` records hold no spin)."""
    laws = getattr(sim, "laws", None)
    rough = bool(getattr(laws, "rough", False))
    if not rough and not np.any(discs.spins):
        return None
    ids = np.arange(len(discs)) if ids is None else np.asarray(ids)
    top = disc_count(events)
    spins0 = np.zeros(max(top, int(ids.max()) + 1 if len(ids) else 0))
    spins0[ids] = discs.spins
    try:
        return turning_history(events, sim.spin_events if rough else None, spins0, float(sim.start_time))
    except (AttributeError, ValueError):  # no spins after the log's collisions (e.g. a checkpoint without them)
        return None


def _from_engine(sim, label: str | None) -> _Run:
    name = type(sim).__name__
    gravity = _engine_flight(sim, name)
    context = getattr(sim, "run_context", None)
    stream = None if context is None else context.stream
    if stream is not None:  # the run streamed its log to disk: replay the file, with the engine's scene
        return _from_log_file(
            Path(stream["path"]),
            label or name,
            name,
            getattr(sim, "segments", ()),
            getattr(sim, "dt", None),
            tuple(getattr(sim, "sensors", ())),
        )
    if not getattr(sim, "record", True):
        msg = (
            f"cannot view this {name}: it was built with record=False, so it recorded no event log to replay; "
            "build it with record=True, or stream its log with run(record_to=PATH) and view PATH"
        )
        raise InvalidArgumentError(msg)
    events = sim.events
    if events.dtype != EVENT_DTYPE:
        msg = f"cannot view {label or name!r}: its log is not of the event dtype ({events.dtype})"
        raise InvalidArgumentError(msg)
    discs, ids = sim.run_context.log_origin(sim.discs) if context is not None else (sim.discs, None)
    dt = getattr(sim, "dt", None)
    turning = _engine_turning(sim, events, discs, ids)
    return _Run(
        label=label or name,
        engine=name,
        box=sim.box,
        segments=tuple(getattr(sim, "segments", ())),
        origin=LastRecords.at_start(discs, float(sim.start_time), ids),
        start_time=float(sim.start_time),
        end_time=float(sim.time),
        chunks=lambda: iter([events]),
        dt=float(dt) if dt else None,
        gravity=gravity,
        turning=turning,
        sensors=tuple(getattr(sim, "sensors", ())),
    )


def _from_stream(log, label: str, engine: str = "EventDriven", segments=(), dt=None) -> _Run:
    """A run from the :class:`~discsim.io.streams.StreamedEvents` of :func:`discsim.read_events` (in memory).

    ``segments``: the run's segments; none given, those of the log's header."""
    events = log.events
    gravity = flight(log.gravity, getattr(log, "drag", 0.0), what=f"the viewer of {label!r}")
    return _Run(
        label=label,
        engine=engine,
        box=log.box,
        segments=tuple(segments) or tuple(getattr(log, "segments", ())),
        origin=LastRecords.at_start(log.discs, float(log.start_time), log.ids, log.resting),
        start_time=float(log.start_time),
        end_time=float(log.end_time),
        chunks=lambda: iter([events]),
        dt=dt,
        gravity=gravity,
        sensors=tuple(getattr(log, "sensors", ())),
    )


def _from_log_file(path: Path, label: str, engine: str = "EventDriven", segments=(), dt=None, sensors=()) -> _Run:
    """A run from a streamed log on disk, read chunk by chunk when the page is made (never whole).

    ``segments``, ``sensors`` (an engine's, or a checkpoint's scene): the run's segments and sensors; none given,
    those of the log's header.
    """
    from discsim.io.container import stream_index
    from discsim.io.streams import iter_events

    log = iter_events(path, partial=True)
    meta = stream_index(path, partial=True)[0]
    gravity = flight(meta.get("gravity"), meta.get("drag", 0.0), what=f"the viewer of {str(path)!r}")
    return _Run(
        label=label,
        engine=engine,
        box=log.box,
        segments=tuple(segments) or log.segments,
        origin=LastRecords.at_start(log.discs, log.start_time, log.ids, log.resting),
        start_time=log.start_time,
        end_time=log.end_time,
        chunks=log.record_arrays,
        dt=dt,
        gravity=gravity,
        sensors=tuple(sensors) or log.sensors,
    )


def _checkpoint_scene(path: Path):
    """``(engine name, segments, dt, sensors)`` stored in a checkpoint, without building the engine (a moving
    segment with its velocity)."""
    from discsim.io.container import read_state
    from discsim.io.streams import segments_from_rows, sensors_from_rows

    meta, _ = read_state(path)
    scene = meta.get("scene") or {}
    segments = segments_from_rows(scene.get("segments"), path, scene.get("segment_past"))
    sensors = sensors_from_rows(scene.get("sensors"), path)
    dt = (meta.get("settings") or {}).get("dt")
    return str(meta.get("engine", "EventDriven")), segments, (float(dt) if dt else None), sensors


def _from_path(path: Path, label: str | None) -> _Run:
    from discsim.io.checkpoints import load
    from discsim.io.container import STATE_MAGIC

    if not path.exists():
        msg = f"cannot view {str(path)!r}: no such file or folder"
        raise InvalidArgumentError(msg)
    if path.is_dir():
        events_file, checkpoint = (path / name for name in RUN_FOLDER_FILES)
        if not events_file.exists():
            if checkpoint.exists():
                return _from_path(checkpoint, label or path.name)
            msg = (
                f"cannot view the folder {str(path)!r}: it holds no event log ({RUN_FOLDER_FILES[0]}) and no "
                f"checkpoint ({RUN_FOLDER_FILES[1]}); a run folder is written by `discsim run --out FOLDER`"
            )
            raise InvalidArgumentError(msg)
        scene = _checkpoint_scene(checkpoint) if checkpoint.exists() else ("EventDriven", (), None, ())
        return _from_log_file(events_file, label or path.name, *scene)
    with path.open("rb") as handle:
        is_state = handle.read(len(STATE_MAGIC)) == STATE_MAGIC
    if not is_state:  # an event log (read_events names what else it may be)
        return _from_log_file(path, label or path.name)
    sim = load(path)  # a checkpoint: its log is in it, or was streamed to a file it names
    stream = sim.run_context.stream
    if stream is not None:
        log_path = Path(stream["path"])
        if not log_path.is_absolute() and not log_path.exists():
            log_path = path.parent / log_path.name
        _, segments, dt, sensors = _checkpoint_scene(path)
        return _from_log_file(log_path, label or path.name, type(sim).__name__, segments, dt, sensors)
    return _with_piston(_from_engine(sim, label or path.name), sim)


def _as_run(source, label: str | None) -> _Run:
    from discsim.engines.base import Engine
    from discsim.io.streams import StreamedEvents

    if isinstance(source, _Run):
        return source
    if isinstance(source, (str, Path)):
        return _from_path(Path(source), label)
    if isinstance(source, StreamedEvents):
        return _from_stream(source, label or "event log")
    if isinstance(source, Engine):
        return _with_piston(_from_engine(source, label), source)
    msg = (
        f"cannot view a {type(source).__name__}: give an engine (EventDriven or FixedStep, record=True), "
        "a run folder or event-log path, or the StreamedEvents of ds.read_events"
    )
    raise InvalidArgumentError(msg)


def _with_piston(run: _Run, sim) -> _Run:
    """``run`` with the knots of ``sim``'s piston (:func:`~discsim.analysis.piston_path.piston_path`), if it has one."""
    from discsim.analysis.piston_path import piston_path

    return (
        run if getattr(getattr(sim, "scene", None), "piston", None) is None else replace(run, piston=piston_path(sim))
    )


# --- packing the data ------------------------------------------------------------------------------------


def _b64(array: np.ndarray, dtype: str) -> str:
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


def _read_span(run: _Run, t0: float, t1: float, limit: int) -> tuple[_Span, bool]:
    """Where each disc stood at ``t0`` and the events in ``[t0, t1]``, reading the log chunk by chunk.

    Records before ``t0`` only move each disc's last record on (:meth:`LastRecords.after`); reading stops at
    the first chunk past ``t1``, or once more than ``limit`` events are held (then the second value is True).
    """
    before, held, count = run.origin, [], 0
    for records in run.chunks():
        if not len(records):
            continue
        times = records["time"]
        if times.min() > t1:
            break
        if times.max() < t0:  # wholly before the span: only where it leaves each disc
            before = before.after(records)
            continue
        early = times < t0
        if early.any():
            before = before.after(records[early])
        inside = records[~early & (times <= t1)]
        if len(inside):
            held.append(inside)
            count += len(inside)
            if count > limit:
                return _Span(before, np.concatenate(held)), True
    events = np.concatenate(held) if held else np.zeros(0, dtype=EVENT_DTYPE)
    return _Span(before, events), False


def _records(span: _Span, t0: float):
    """Each disc's state records from ``t0`` on, as :func:`discsim.trajectory.reconstruct` orders them.

    Returns ``(starts (M + 1,), times (R,), states (R, 4), partners (R,), kinds (R,))``: disc id ``d`` owns records
    ``starts[d]:starts[d + 1]``, sorted by time then log order; a record holds ``x, y, vx, vy`` after the
    event at ``times`` (NaN while the disc is not there: before its ``ADD`` record, from its ``REMOVE``
    record on); ``partners`` is -2 for the disc's last record before ``t0`` (or where the log starts), -1 for
    a wall hit or a change, else the other disc; ``kinds`` each record's event kind (-1 for the first, and
    :data:`~discsim.events.EventKind.WALL` for a first record at rest: :attr:`LastRecords.still`). A disc keeps
    its last record at or before ``t0``, so that positions in the span come from the same records, and the same
    arithmetic, as ``trajectory()``.
    """
    events = span.events
    top = disc_count(events)
    before = span.before.grown(top)
    n = len(before)
    pair = np.flatnonzero(disc_partners(events))
    ev = events[pair]
    disc = np.concatenate([np.arange(n), events["i"], ev["j"]])
    times = np.concatenate([before.times, events["time"], ev["time"]])
    seq = np.concatenate([np.full(n, -1), np.arange(len(events)), pair])
    partner = np.concatenate([np.full(n, -2), np.where(disc_partners(events), events["j"], -1), ev["i"]])
    kind = np.concatenate([np.where(before.still, int(EventKind.WALL), -1), events["kind"], ev["kind"]])
    states = np.vstack(
        [
            np.hstack([before.positions, before.velocities]),
            np.column_stack([events["xi"], events["yi"], events["vxi"], events["vyi"]]),
            np.column_stack([ev["xj"], ev["yj"], ev["vxj"], ev["vyj"]]),
        ]
    )
    order = np.lexsort((seq, times, disc))  # by disc, then time, then log order
    disc, times, partner, states, kind = disc[order], times[order], partner[order], states[order], kind[order]
    # Drop a record when the same disc has a later one still at or before t0.
    superseded = np.zeros(len(disc), dtype=bool)
    superseded[:-1] = (disc[1:] == disc[:-1]) & (times[1:] <= t0)
    keep = ~superseded
    disc, times, partner, states, kind = disc[keep], times[keep], partner[keep], states[keep], kind[keep]
    starts = np.searchsorted(disc, np.arange(n + 1))
    return starts, times, states, partner, kind


def _discs_of(span: _Span) -> LastRecords:
    """Every disc id the span shows, with radii, masses and groups (those added in the span included)."""
    events = span.events
    top = disc_count(events)
    return span.before.after(events[events["kind"] == ADD]).grown(top) if len(events) else span.before


def _span(runs: list[_Run], start, until) -> tuple[float, float]:
    lo = max(r.start_time for r in runs)
    hi = min(r.end_time for r in runs)
    t0 = lo if start is None else float(start)
    t1 = hi if until is None else float(until)
    if not (math.isfinite(t0) and math.isfinite(t1)):
        msg = f"start and until must be finite times, got start={start!r}, until={until!r}"
        raise InvalidArgumentError(msg)
    if t0 < lo or t1 > hi or t1 < t0:
        what = "the span every run covers" if len(runs) > 1 else "the run's span"
        msg = f"cannot show t in [{t0!r}, {t1!r}]: {what} is [{lo!r}, {hi!r}]"
        raise InvalidArgumentError(msg)
    return t0, t1


def _turning_records(history: tuple, starts: np.ndarray, times: np.ndarray) -> np.ndarray:
    """``(R, 2)``: each record's spin and angle at its time (records of ``_records``; a disc the history does not
    know: no spin, angle 0)."""
    h_starts, h_times, h_spins, h_angles = history
    out = np.zeros((len(times), 2))
    for d in range(min(len(starts), len(h_starts)) - 1):
        lo, hi, a, b = starts[d], starts[d + 1], h_starts[d], h_starts[d + 1]
        if lo == hi:
            continue
        k = np.maximum(a + np.searchsorted(h_times[a:b], times[lo:hi], side="right") - 1, a)
        out[lo:hi, 0] = h_spins[k]
        out[lo:hi, 1] = h_angles[k] + h_spins[k] * (times[lo:hi] - h_times[k])
    return out


def _run_data(run: _Run, span: _Span, t0: float, t1: float, truth: bool) -> dict:
    from discsim.io.streams import segment_past_rows, segment_rows

    starts, times, states, partners, kinds = _records(span, t0)
    discs = _discs_of(span)
    disc = np.repeat(np.arange(len(starts) - 1), np.diff(starts))
    # Under gravity a record's disc falls after it, unless it came to rest there or cannot move (obstacle).
    falls = (
        falling(disc, states, kinds, run.gravity, discs.masses)
        if run.gravity is not None
        else np.zeros(len(times), dtype=bool)
    )
    turning = None if run.turning is None else _turning_records(run.turning, starts, times)
    box = run.box
    ev = span.events
    contacts = ev[(ev["kind"] == COLLISION) & (ev["time"] >= t0) & (ev["time"] <= t1)]
    entries = ev[(ev["kind"] == ENTER) & (ev["time"] >= t0) & (ev["time"] <= t1)]  # j: the sensor
    speeds = np.hypot(states[:, 2], states[:, 3])
    speeds = speeds[np.isfinite(speeds)]
    return {
        "label": run.label,
        "engine": run.engine,
        "dt": run.dt,
        "truth": truth,
        "n": len(discs),
        "box": {"width": float(box.width), "height": float(box.height), "periodic": bool(box.periodic)},
        "segments": segment_rows(run.segments),  # as checkpoints store them: [p0, p1] or [p0, p1, velocity]
        "segment_past": [segment_past_rows(segment) for segment in run.segments],  # a steered one's earlier motions
        "sensors": [[sensor.code, *sensor.params.tolist()] for sensor in run.sensors],  # as checkpoints store them
        "enter_times": _b64(entries["time"], "<f8"),
        "enter_sensors": _b64(entries["j"], "<i4"),
        "radii": _b64(np.nan_to_num(discs.radii), "<f8"),
        "fixed": _b64(np.isinf(discs.masses), "u1"),
        "groups": _b64(discs.groups, "<i4"),
        "starts": _b64(starts, "<i4"),
        "times": _b64(times, "<f8"),
        "states": _b64(states, "<f8"),
        "partners": _b64(partners, "<i4"),
        "gravity": None if run.gravity is None else list(run.gravity),
        "falls": _b64(falls, "u1"),
        "turning": None if turning is None else _b64(turning, "<f8"),
        "contact_times": _b64(contacts["time"], "<f8"),
        "contact_pairs": _b64(np.column_stack([contacts["i"], contacts["j"]]), "<i4"),
        "max_speed": float(np.quantile(speeds, 0.99)) if len(speeds) else 0.0,  # the fastest 1% saturate
        "piston": None
        if run.piston is None
        else {k: _b64(v, "<f8") for k, v in run.piston.span(t0, t1)._asdict().items()},
    }


def _check_nonempty(run: _Run) -> None:
    if run.end_time <= run.start_time and not any(len(c) for c in run.chunks()):
        msg = (
            f"cannot view {run.label!r}: it recorded nothing (no event, and no time elapsed: "
            f"t = {run.start_time!r}); run it first, e.g. sim.run(until=...)"
        )
        raise InvalidArgumentError(msg)


def _panel_labels(runs: list[_Run], labels) -> list[str]:
    if labels is not None:
        labels = [str(x) for x in labels]
        if len(labels) != len(runs):
            msg = f"labels must name each of the {len(runs)} runs, got {len(labels)}"
            raise InvalidArgumentError(msg)
        return labels
    out = []
    for r in runs:
        if r.engine == "FixedStep" and r.dt:
            out.append(f"PIT ({r.label}, {1.0 / r.dt:.3g} frames per unit time)")
        elif r.engine == "EventDriven" and len(runs) > 1:
            out.append(f"PIC ({r.label}), the truth")
        else:
            out.append(r.label)
    return out


# --- the page --------------------------------------------------------------------------------------------


class View:
    """A replay page made by :func:`view`: the HTML text, and the file it was written to (if any).

    In Jupyter the object shows itself inline (an ``iframe`` whose ``srcdoc`` is the page).

    Attributes:
        html: the whole page, one self-contained HTML document (str).
        path: the file written, or None.
        span: ``(t0, t1)``, the simulated times the page replays.
        events: the number of events it holds (all runs together), those in ``span``.
        note: None, or what the page shows instead of what was asked (the first ``max_events`` events when
            no ``until`` was given and the run holds more).
    """

    def __init__(
        self, html_text: str, path: Path | None, span: tuple[float, float], events: int, height: int, note=None
    ):
        self.html = html_text
        self.note = note
        self.path = path
        self.span = span
        self.events = events
        self._height = height

    def save(self, path) -> Path:
        """Write the page to ``path`` (its folder is created) and return the path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(self.html, encoding="utf-8")
        self.path = path
        return path

    def _repr_html_(self) -> str:
        return (
            f'<iframe srcdoc="{html.escape(self.html, quote=True)}" '
            f'style="width: 100%; height: {self._height}px; border: 0" sandbox="allow-scripts"></iframe>'
        )

    def __repr__(self) -> str:
        where = f", path={str(self.path)!r}" if self.path else ""
        return f"View(span={self.span}, events={self.events}, {len(self.html):,} bytes{where})"


def view(
    source,
    path="view.html",
    *,
    compare_with=None,
    labels=None,
    colour: str = "auto",
    speed: float | None = None,
    fps: float = 30.0,
    start: float | None = None,
    until: float | None = None,
    contact_window: float | None = None,
    max_events: int = DEFAULT_MAX_EVENTS,
    title: str | None = None,
    arrows: bool = False,
) -> View:
    """Write a self-contained HTML page that replays runs exactly, from their event logs.

    Args:
        source: what to replay: an engine (``EventDriven`` or ``FixedStep``, built with ``record=True``), a
            run folder written by ``discsim run --out FOLDER``, an event-log file (``run(record_to=...)``)
            or a checkpoint, the :class:`~discsim.io.streams.StreamedEvents` of :func:`discsim.read_events`;
            or a list of these, drawn side by side on one clock (e.g. ``[pit, pic]``).
        path: the HTML file to write (its folder is created); None writes nothing (the returned
            :class:`View` still holds the page, e.g. to show it in Jupyter).
        compare_with: another run (or list of runs) drawn to the left of ``source``: ``view(pic,
            compare_with=pit)`` draws PIT left and PIC right, like the study's figures.
        labels: one title per panel; default the engine and, for PIT, its frame rate.
        colour: ``"disc"`` (each disc its own colour), ``"group"`` (by collision group), ``"speed"`` (viridis
            from 0 to the 99th percentile of the speeds in the replay), or ``"auto"``: ``"disc"`` up to 20
            discs, else ``"group"`` when the groups differ, else ``"speed"``. Fixed obstacles are grey.
            The page can switch.
        speed: playback speed in simulated time per second of real time; default the span over 10 s
            (at least one frame interval of a PIT run per 0.25 s). The page can change it.
        fps: frames drawn per second of real time while playing.
        start, until: the span of simulated time to replay (default all that every run covers). Only the
            events in the span count and are held: a streamed log is read chunk by chunk, from its start
            to ``until``, keeping each disc's last record before ``start`` (memory flat in the log's length).
            With no ``until`` and more than ``max_events`` events from ``start`` on, the page shows the
            first ``max_events`` of them and says so (:attr:`View.note`).
        contact_window: exact contacts (collisions of the event-driven runs) are drawn as outlines from
            their time on, for this long in simulated time; default: for ever when the runs hold at most
            60 contacts, else 2% of the span.
        max_events: at most this many events in the page (about 140 bytes each): a span that holds more,
            with ``until`` given, is refused (ask for a shorter one).
        title: the page's title.
        arrows: start with velocity arrows drawn (an arrow is where the disc gets in the time the fastest
            1% take to fly four radii of the largest disc). The page can switch them, and zoom (mouse wheel,
            drag, double-click for the whole box).

    Returns:
        A :class:`View` (``html``, ``path``, ``span``, ``events``; shows itself inline in Jupyter).

    Raises:
        InvalidArgumentError: before anything is written, for a run that recorded nothing (``record=False``,
            or no time elapsed), a folder or file with no event log, a span outside the runs, a bad
            ``colour``, ``speed``, ``fps``, ``labels`` or ``max_events``, or more events than ``max_events``
            between ``start`` and a given ``until``.
        CheckpointError: for a damaged event log or checkpoint.

    Example:
        >>> import discsim as ds
        >>> case = ds.head_on(1.0, 2.0)
        >>> sim = ds.EventDriven(case.discs, case.box).run(until=case.until)
        >>> page = ds.view(sim, path=None)
        >>> page.html.startswith("<!DOCTYPE html>"), page.events == len(sim.events), "http" in page.html
        (True, True, False)
    """
    sources = list(source) if isinstance(source, Sequence) and not isinstance(source, str) else [source]
    if compare_with is not None:
        others = (
            list(compare_with)
            if isinstance(compare_with, Sequence) and not isinstance(compare_with, str)
            else [compare_with]
        )
        sources = others + sources
    if not sources:
        msg = "view() needs at least one run"
        raise InvalidArgumentError(msg)
    if colour not in COLOUR_MODES:
        msg = f"colour must be one of {', '.join(map(repr, COLOUR_MODES))}, got {colour!r}"
        raise InvalidArgumentError(msg)
    for name, value in (("speed", speed), ("fps", fps), ("contact_window", contact_window)):
        if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            msg = f"{name} must be a positive finite number, got {value!r}"
            raise InvalidArgumentError(msg)
    if isinstance(max_events, bool) or not isinstance(max_events, (int, np.integer)) or max_events < 1:
        msg = f"max_events must be a positive integer, got {max_events!r}"
        raise InvalidArgumentError(msg)
    runs = [_as_run(s, None) for s in sources]
    for r in runs:
        _check_nonempty(r)
    panel_labels = _panel_labels(runs, labels)
    t0, t1 = _span(runs, start, until)
    spans = [_read_span(r, t0, t1, max_events)[0] for r in runs]
    held = sum(len(s.events) for s in spans)
    note = None
    if held > max_events:
        if until is not None:
            msg = (
                f"the replay would hold more than max_events={max_events:,} events in [{t0!r}, {t1!r}] (about 140 "
                "bytes each); choose a shorter span with start= and until= (--start/--until), or raise max_events"
            )
            raise InvalidArgumentError(msg)
        # No end asked for: show the first max_events events from t0 on (every run holds all those it has).
        times = np.sort(np.concatenate([s.events["time"] for s in spans]))
        below = times[times < times[max_events]]
        if not len(below):
            msg = f"more than max_events={max_events:,} events happen at t = {times[0]!r}; raise max_events"
            raise InvalidArgumentError(msg)
        t1 = float(below[-1])
        spans = [_Span(s.before, s.events[s.events["time"] <= t1]) for s in spans]
        held = sum(len(s.events) for s in spans)
        note = (
            f"more than max_events={max_events:,} events after t = {t0:g}: showing the first {held:,}, "
            f"t in [{t0:g}, {t1:g}]; choose the span with start= and until= (--start/--until) or raise max_events"
        )
    has_truth = any(r.engine == "EventDriven" for r in runs)
    data_runs = []
    for r, sp, label in zip(runs, spans, panel_labels, strict=True):
        d = _run_data(r, sp, t0, t1, truth=r.engine == "EventDriven" or not has_truth)
        d["label"] = label
        data_runs.append(d)
    if colour == "auto":
        first = _discs_of(spans[0])
        n, groups = int(np.isfinite(first.radii).sum()), first.groups[np.isfinite(first.radii)]
        colour = "disc" if n <= 20 else ("group" if len(np.unique(groups)) > 1 else "speed")
    if speed is None:
        speed = (t1 - t0) / 10.0 if t1 > t0 else 1.0
        frame = max((r.dt or 0.0) for r in runs)
        speed = max(speed, 4.0 * frame) if frame else speed
        speed = min(speed, t1 - t0) if t1 > t0 else speed
    n_contacts = max(int((s.events["kind"] == COLLISION).sum()) for s in spans)
    if contact_window is None:
        contact_window = math.inf if n_contacts <= 60 else 0.02 * (t1 - t0)
    data = {
        "version": 1,
        "title": title or " | ".join(panel_labels),
        "span": [t0, t1],
        "speed": float(speed),
        "fps": float(fps),
        "colour": colour,
        "arrows": bool(arrows),
        "contact_window": None if math.isinf(contact_window) else float(contact_window),
        "runs": data_runs,
    }
    page = _page(data)
    height = 760 if len(runs) > 1 else 700
    result = View(page, None, (t0, t1), held, height, note)
    if path is not None:
        result.save(path)
    return result


def _page(data: dict) -> str:
    """The HTML document: the style, the data (JSON) and the player script, all inline."""
    script = (_ASSETS / "viewer.js").read_text(encoding="utf-8")
    style = (_ASSETS / "viewer.css").read_text(encoding="utf-8")
    payload = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
    title = html.escape(data["title"])
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>discsim: {title}</title>\n<style>\n{style}</style>\n</head>\n<body>\n"
        f'<header><h1>{title}</h1><p id="ds-info"></p></header>\n'
        '<main id="ds-panels"></main>\n'
        '<nav id="ds-controls"></nav>\n'
        '<pre id="ds-readout" hidden></pre>\n'
        f'<script type="application/json" id="ds-data">{payload}</script>\n'
        f"<script>\n{script}</script>\n</body>\n</html>\n"
    )
