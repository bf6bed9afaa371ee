"""Checkpoints of every engine, both directions: save, load, resume, and what a file holds.

A checkpoint is a state file (:mod:`discsim.io.container`: one JSON document plus named numpy arrays, a
SHA-256 checksum, written atomically) made by ``sim.save(path)`` or by ``run(checkpoint=path, ...)``. It
holds the scene (initial discs, box, segments, collision filter), the engine's settings, its public run
state (``sim.state()``: an :class:`~discsim.engines.base.EngineState` of arrays and scalars), and the event
log or where it was streamed. No pickle: loading a file never runs code from it. After ``add_discs`` or
``remove_discs`` the ``discs.*`` arrays are the engine's discs now (as at the last change), ``origin.*``
(and ``origin.ids``) the discs where the log starts, ``ids`` each disc's id and ``next_id`` the next one.

Layouts: ``layout`` 2 (this one) stores the state's fields by name under ``state.``; files written before
it (an event-driven engine's private arrays, in its internal numbering) are read and converted, and
continue bit for bit.

Typical use::

    sim = ds.EventDriven(discs, box, record=False)
    sim.run(until=1e4, record_to="run/events.dse", checkpoint="run/state.dsc", checkpoint_every=10**6)
    # ... killed at any moment; later, in a new process:
    sim = ds.resume("run/state.dsc")         # same final state, bit for bit

This module imports no engine: it finds the class a file names in the registry
(:func:`discsim.engines.base.engine_class`), where each engine adds itself, and it provides
``Engine.save`` (:func:`save`) to the engines when imported (:func:`discsim.engines.base.provide`).
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from discsim._numba import available as numba_available
from discsim._numba import resolve_backend
from discsim.engines.base import Engine, EngineState, provide, registered_engines
from discsim.errors import CheckpointError, DiscsimError
from discsim.events import EVENT_DTYPE
from discsim.io.container import read_state, write_state
from discsim.io.streams import segment_past_rows, segments_from_rows
from discsim.model import Box, Discs, image_steps
from discsim.piston import Piston
from discsim.scene import Scene
from discsim.sensors import Sensor
from discsim.trajectory import reconstruct

__all__ = ["checkpoint_info", "load", "resume", "save", "write_checkpoint"]

#: The layout of the JSON document and the arrays written by this version.
LAYOUT = 2


def save(engine, path) -> Path:
    """Write ``engine``'s whole state to ``path`` (see ``Engine.save``); return the path."""
    return write_checkpoint(engine, Path(path), run=None, record=engine.record)


def write_checkpoint(engine, path, *, run: dict | None, record: bool) -> Path:
    """Write a checkpoint of ``engine`` to ``path``, atomically.

    Args:
        engine: any discsim engine.
        path: the file (its folder must exist); replaced if present.
        run: the goal of the ``run()`` call writing it (see :func:`checkpoint_info`), or None for ``save()``.
        record: the engine's own ``record`` setting (a streaming run records meanwhile).
    """
    context = engine.run_context
    run_id = context.ensure_run_id()
    scalars, arrays = engine.state().to_arrays()
    discs, box, scene = engine.discs, engine.box, engine.scene
    steered = any(s.pieces() for s in scene.segments)  # (where a steered segment was before: plots, contacts)
    meta = {
        "layout": LAYOUT,
        "engine": type(engine).__name__,
        "run_id": run_id,
        "start_time": engine.start_time,
        "time": engine.time,
        "counts": dict(engine.counts),
        "box": box.as_dict(),
        "scene": {
            "segments": [
                [*s.p0.tolist(), *s.p1.tolist(), *(s.velocity.tolist() if s.moving else [])] for s in scene.segments
            ],
            **({"segment_past": [segment_past_rows(s) for s in scene.segments]} if steered else {}),
            "pass_through": sorted(scene.pass_through),
            "sensors": [[sensor.code, *sensor.params.tolist()] for sensor in scene.sensors],
            **({} if getattr(scene, "piston", None) is None else {"piston": scene.piston.settings()}),
        },
        "settings": {**engine._settings(), "record": record},
        "state_version": engine.STATE.VERSION,
        "state": scalars,
        "stream": context.stream,
        "run": run,
    }
    out = {f"state.{name}": value for name, value in arrays.items()}
    out["events"] = context.log.to_array() if record else np.zeros(0, dtype=EVENT_DTYPE)
    spin_events = getattr(engine, "spin_events", None)  # a rough run's spins after each event of its log
    if record and spin_events is not None and len(spin_events):
        out["spin_events"] = spin_events
    out.update(_discs_arrays("discs", discs))
    if context.origin is not None:  # the discs changed (add_discs, remove_discs): discs.* are today's scene
        origin, origin_ids = context.origin
        out.update(_discs_arrays("origin", origin))
        if origin_ids is not None:
            out["origin.ids"] = np.asarray(origin_ids, dtype=np.int64)
        out["ids"] = np.asarray(engine.ids, dtype=np.int64)
        meta["next_id"] = context.next_id
    return write_state(Path(path), meta, out)


def _discs_arrays(prefix: str, discs: Discs) -> dict[str, np.ndarray]:
    return {
        f"{prefix}.positions": discs.positions,
        f"{prefix}.velocities": discs.velocities,
        f"{prefix}.radii": discs.radii,
        f"{prefix}.masses": discs.masses,
        f"{prefix}.groups": discs.groups,
        f"{prefix}.spins": discs.spins,
        f"{prefix}.inertia": discs.inertia,
    }


def _discs_from(arrays: dict, prefix: str) -> Discs:
    names = ("positions", "velocities", "radii", "masses", "groups")
    turning = {name: arrays.get(f"{prefix}.{name}") for name in ("spins", "inertia")}  # absent: files before spins
    return Discs(*(arrays[f"{prefix}.{name}"] for name in names), **turning)


def checkpoint_info(path) -> dict:
    """What a checkpoint holds, without building the engine.

    Returns:
        A dict with ``engine``, ``n`` (discs), ``time``, ``counts`` (collisions,
        wall hits, ...), ``run_id``, ``stream`` (where the log was streamed, or
        None) and ``run`` (the goal of the ``run()`` call that wrote it:
        ``until``, ``events`` (total units of work: physical events, or frames),
        ``checkpoint_every``, ``record_to``, ``finished``; None for a file from ``save()``).

    Raises:
        FileNotFoundError: if there is no such file.
        CheckpointError: if it is damaged, of another format version, or not a checkpoint.

    Example:
        >>> import os, tempfile, discsim as ds
        >>> discs, box = ds.random_gas(30, 0.3, seed=0)
        >>> path = os.path.join(tempfile.mkdtemp(), "sim.dsc")
        >>> _ = ds.EventDriven(discs, box).run(until=0.5).save(path)
        >>> info = ds.checkpoint_info(path)
        >>> info["engine"], info["n"], info["time"], info["run"]
        ('EventDriven', 30, 0.5, None)
    """
    meta, arrays = read_state(path)
    _engine_class(meta, path)
    try:
        if meta.get("layout") == LAYOUT:
            time, counts = meta["time"], meta["counts"]
        else:  # the first layout
            scalars = meta["state"]["scalars"]
            time = scalars["time"]
            counts = {k: scalars[k] for k in ("collisions", "wall_hits", "cell_crossings", "stale", "predictions")}
        return {
            "engine": meta["engine"],
            "n": len(arrays["discs.radii"]),
            "time": time,
            "counts": counts,
            "run_id": meta["run_id"],
            "stream": meta["stream"],
            "run": meta["run"],
        }
    except (KeyError, TypeError) as exc:
        msg = f"{path}: not a complete discsim checkpoint (missing {exc})"
        raise CheckpointError(msg) from exc


def _engine_class(meta, path) -> type[Engine]:
    engine = meta.get("engine") if isinstance(meta, dict) else None
    engines = registered_engines()
    if not isinstance(engine, str) or engine not in engines:
        msg = f"{path}: not a discsim checkpoint (engine {engine!r}; known: {sorted(engines)})"
        raise CheckpointError(msg)
    return engines[engine]


def __getattr__(name: str):
    """``ENGINES``, the old table of engines by name: now :func:`discsim.engines.base.registered_engines`."""
    if name == "ENGINES":
        msg = "discsim.io.checkpoints.ENGINES is deprecated: use discsim.engines.base.registered_engines()"
        warnings.warn(msg, DeprecationWarning, stacklevel=2)
        return registered_engines()
    msg = f"module {__name__!r} has no attribute {name!r}"
    raise AttributeError(msg)


def load(path, *, backend: str | None = None):
    """Load a simulation saved by ``save(path)`` or by ``run(checkpoint=path)``.

    The loaded engine continues exactly as the saved one would have: the same
    events, bit for bit, under either backend. If the run streamed its log to disk, a later
    ``run(record_to=...)`` on that same file continues it (anything written
    after the checkpoint is cut off first).

    Args:
        path: the checkpoint file.
        backend: the backend to continue with (``"auto"``, ``"python"``, ``"numba"``); None: the one
            that wrote the file, or ``"auto"`` if that one cannot run here (numba missing).

    Returns:
        The engine (:class:`~discsim.EventDriven` or :class:`~discsim.FixedStep`), at the saved time.

    Raises:
        FileNotFoundError: if there is no such file.
        CheckpointError: if the file is truncated, corrupted (checksum), of an
            incompatible format version, or not a discsim checkpoint.

    Example:
        >>> import os, tempfile, discsim as ds
        >>> discs, box = ds.random_gas(40, 0.5, seed=3)
        >>> path = os.path.join(tempfile.mkdtemp(), "sim.dsc")
        >>> sim = ds.EventDriven(discs, box, queue="heap").run(events=200)
        >>> copy = ds.load(sim.save(path))
        >>> copy.time == sim.time, copy.counts == sim.counts, copy.queue_kind
        (True, True, 'heap')
    """
    if backend is not None:
        resolve_backend(backend, ("python", "numba"), "load")
    meta, arrays = read_state(path)
    engine = _engine_class(meta, path)
    try:
        discs = _discs_from(arrays, "discs")
        changed = "ids" in arrays  # the discs changed: discs.* are the engine's own (a fixed-step run may overlap)
        box = Box(**meta["box"])
        if meta.get("layout") == LAYOUT:
            scene_meta, settings = meta["scene"], meta["settings"]
            state = engine.STATE.from_arrays(
                meta["state"],
                {k.removeprefix("state."): v for k, v in arrays.items() if k.startswith("state.")},
                meta["state_version"],
            )
            events = arrays["events"]
        else:
            scene_meta, settings, state, events = _first_layout(engine, meta, arrays)
        if backend is not None or (settings.get("backend") == "numba" and not numba_available()):
            settings = {**settings, "backend": backend or "auto"}
        segments = list(segments_from_rows(scene_meta.get("segments", []), path, scene_meta.get("segment_past")))
        pass_through = [tuple(pair) for pair in scene_meta.get("pass_through", [])]
        sensors = [Sensor(int(row[0]), row[1:]) for row in scene_meta.get("sensors", [])]
        piston = Piston(*scene_meta["piston"]) if scene_meta.get("piston") is not None else None
        if changed:
            scene = Scene(
                discs, box, tuple(segments), frozenset(pass_through), sensors=sensors, piston=piston, check=False
            )
        else:
            scene = Scene(discs, box, segments, pass_through, sensors=sensors, piston=piston)
        sim = engine._restore(scene, settings, state, events, float(meta["start_time"]))
        if "spin_events" in arrays:
            sim._restore_spin_events(arrays["spin_events"])
        if changed:
            ids = np.asarray(arrays["ids"], dtype=np.int64)
            if ids.shape != (len(discs),):
                msg = f"ids of shape {ids.shape} for {len(discs)} discs"
                raise ValueError(msg)
            origin_ids = arrays.get("origin.ids")
            sim.run_context.log.flush()
            sim.run_context.set_ids(ids, int(meta["next_id"]), (_discs_from(arrays, "origin"), origin_ids))
    except (KeyError, TypeError, IndexError, ValueError, DiscsimError) as exc:
        msg = f"{path}: the checkpoint is incomplete or inconsistent ({type(exc).__name__}: {exc})"
        raise CheckpointError(msg) from exc
    sim.run_context.run_id = meta["run_id"]
    sim.run_context.stream = meta["stream"]
    return sim


def _first_layout(engine: Any, meta: dict, arrays: dict) -> tuple[dict, dict, EngineState, np.ndarray]:
    """``(scene, settings, state, events)`` from a file of the first layout, for ``engine`` (the class the file
    names: that layout held event-driven engines only, and ``EventDriven`` reads it).

    That layout stored the engine's private lists by attribute name, in its internal numbering (``order``;
    files older still used the caller's numbering throughout), and each queued event's payload as
    ``(kind, other, stamp)``. It kept no image counters: they are rebuilt from the log when it covers
    the whole run, and start from zero otherwise (``unwrapped_positions`` then count from the load).
    """
    if engine.__name__ != "EventDriven":
        msg = f"layout {meta.get('layout')!r} holds event-driven engines only, not {engine.__name__}"
        raise CheckpointError(msg)
    old = dict(meta["state"])
    old.update({k.removeprefix("state."): v for k, v in arrays.items() if k.startswith("state.")})
    scalars, settings = old["scalars"], old["settings"]
    n = len(arrays["discs.radii"])
    order = np.asarray(old.get("order", np.arange(n)), dtype=np.int64)

    def caller(values) -> np.ndarray:  # per-disc values in internal numbering -> caller's numbering
        values = np.asarray(values)
        out = np.empty_like(values)
        out[order] = values
        return out

    def ids(values) -> np.ndarray:  # internal disc numbers -> the caller's (-1 stays -1)
        values = np.asarray(values, dtype=np.int64)
        return np.where(values >= 0, order[np.maximum(values, 0)], values)

    payload = np.asarray(old["queue_payload"], dtype=np.int64).reshape(-1, 3)
    kinds = payload[:, 0]
    members, sizes = old["cell_members"], old["cell_sizes"]
    last = scalars["last"]
    box = Box(**meta["box"])
    cell_size = settings["cell_size"]
    grid = engine.cell_grid(arrays["discs.radii"], box, cell_size)
    state = engine.STATE(
        time=scalars["time"],
        epoch=scalars.get("epoch", 0.0),
        since_rebase=scalars.get("since_rebase", 0),
        collisions=scalars["collisions"],
        wall_hits=scalars["wall_hits"],
        cell_crossings=scalars["cell_crossings"],
        stale=scalars["stale"],
        predictions=scalars["predictions"],
        virial=scalars["virial"],
        max_overlap=scalars["max_overlap"],
        max_queue=scalars["max_queue"],
        last_time=0.0 if last is None else last[0],
        last_kind=-1 if last is None else last[1],
        last_i=-1 if last is None else int(order[last[2]]),
        last_j=-1 if last is None else int(ids([last[3]])[0]),
        grid_nx=grid.nx,
        grid_ny=grid.ny,
        ref_positions=caller(np.column_stack([old["_rx"], old["_ry"]]).reshape(n, 2)),
        velocities=caller(np.column_stack([old["_vx"], old["_vy"]]).reshape(n, 2)),
        ref_times=caller(old["_tr"]),
        images=np.zeros((n, 2), dtype=np.int64),  # not recorded then: from the log below, where there is one
        collision_counts=caller(np.asarray(old["_count"], dtype=np.int64)),
        cell=caller(np.asarray(old["_cell"], dtype=np.int64)),
        cell_members=ids(members),
        cell_sizes=np.asarray(sizes, dtype=np.int64),
        kept_time=caller(np.asarray(old["_kept_time"], dtype=np.float64)),
        kept_partner=caller(ids(old["_kept_partner"])),
        kept_stamp=caller(np.asarray(old["_kept_stamp"], dtype=np.int64)),
        order=order,
        queue_owner=ids(old["queue_owner"]),
        queue_time=np.asarray(old["queue_time"], dtype=np.float64),
        queue_kind=kinds,
        queue_other=np.where(kinds == 0, ids(payload[:, 1]), payload[:, 1]),
        queue_stamp=payload[:, 2],
    )
    events = old["events"]
    if box.periodic and len(events) and meta["stream"] is None and meta["start_time"] == 0.0:
        # The log covers the whole run: the whole box lengths each disc crossed are in it.
        unwrapped = reconstruct(
            events, arrays["discs.positions"], arrays["discs.velocities"], 0.0, [state.time], box, unwrapped=True
        )[0]
        state.images = image_steps(unwrapped, state.positions_at(state.time), box.size).astype(np.int64)
    scene = {"segments": settings.get("segments", []), "pass_through": settings.get("pass_through", [])}
    new_settings = {"record": settings["record"], "queue": settings["queue"], "cell_size": cell_size}
    return scene, new_settings, state, events


def resume(path, *, progress: bool = False, record_to=None, backend: str | None = None):
    """Continue the run that wrote checkpoint ``path`` to the end it was given.

    Loads the checkpoint and calls ``run`` with the same ``until`` and the
    remaining units of work, the same ``checkpoint_every`` (writing to ``path``
    again) and the same streamed log, cut back to what the checkpoint saw.
    The final state equals that of the run had it never stopped, bit for bit.
    A checkpoint of a finished run is loaded and returned as it is.

    Args:
        path: a checkpoint written by ``run(checkpoint=path, ...)``.
        progress: show a progress bar.
        record_to: the streamed log, if it moved since (default: where the
            run wrote it).
        backend: as for :func:`load`.

    Returns:
        The engine at the end of the run.

    Raises:
        CheckpointError: if the checkpoint or the log is damaged or foreign,
            or the checkpoint was written by ``save()`` (no run to resume:
            use :func:`load` and ``run``).

    Example:
        >>> import os, tempfile, discsim as ds
        >>> folder = tempfile.mkdtemp()
        >>> state, log = os.path.join(folder, "state.dsc"), os.path.join(folder, "events.dse")
        >>> discs, box = ds.random_gas(30, 0.3, seed=4)
        >>> sim = ds.EventDriven(discs, box).run(until=2.0, checkpoint=state, record_to=log)
        >>> ds.resume(state).positions.tobytes() == sim.positions.tobytes()
        True
    """
    info = checkpoint_info(path)
    run = info["run"]
    if run is None:
        msg = f"{path} was written by save(), not by run(checkpoint=...): no run to resume; use load() and run()"
        raise CheckpointError(msg)
    sim = load(path, backend=backend)
    if run["finished"]:
        return sim
    remaining = None if run["events"] is None else run["events"] - sim._units()
    if record_to is None:
        record_to = run["record_to"]
    sim.run(
        until=run["until"],
        events=remaining,
        progress=progress,
        record_to=None if record_to is None else Path(record_to),
        checkpoint=path,
        checkpoint_every=run["checkpoint_every"],
    )
    return sim


provide("save", save)
