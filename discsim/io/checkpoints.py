"""Checkpoints: load a saved simulation, and resume a run that was interrupted.

A checkpoint is a state file (:mod:`discsim.io`: one JSON document plus named
numpy arrays, a SHA-256 checksum and a format version, written atomically)
made by ``EventDriven.save(path)`` or by ``run(checkpoint=path, ...)``. It
holds the initial discs, the box, the time, the counters, the settings, the
event queue and per-disc clocks, and the event log or where it was streamed.
No pickle is involved: loading a file never runs code from it.

Typical use::

    sim = ds.EventDriven(discs, box, record=False)
    sim.run(until=1e4, record_to="run/events.dse", checkpoint="run/state.dsc", checkpoint_every=10**6)
    # ... killed at any moment; later, in a new process:
    sim = ds.resume("run/state.dsc")         # same final state, bit for bit
"""

from __future__ import annotations

from pathlib import Path

from discsim.engines.event_driven import EventDriven
from discsim.errors import CheckpointError, DiscsimError
from discsim.io.container import read_state

__all__ = ["checkpoint_info", "load", "resume"]

#: Engines a checkpoint can hold, by the name stored in the file.
_ENGINES = {"EventDriven": EventDriven}


def checkpoint_info(path) -> dict:
    """What a checkpoint holds, without building the engine.

    Returns:
        A dict with ``engine``, ``n`` (discs), ``time``, ``counts`` (collisions,
        wall hits, ...), ``run_id``, ``stream`` (where the log was streamed, or
        None) and ``run`` (the goal of the ``run()`` call that wrote it:
        ``until``, ``events`` (total physical events), ``checkpoint_every``,
        ``record_to``, ``finished``; None for a file from ``save()``).

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
    _check_engine(meta, path)
    try:
        scalars = meta["state"]["scalars"]
        counts = {k: scalars[k] for k in ("collisions", "wall_hits", "cell_crossings", "stale", "predictions")}
        return {
            "engine": meta["engine"],
            "n": len(arrays["discs.radii"]),
            "time": scalars["time"],
            "counts": counts,
            "run_id": meta["run_id"],
            "stream": meta["stream"],
            "run": meta["run"],
        }
    except (KeyError, TypeError) as exc:
        msg = f"{path}: not a complete discsim checkpoint (missing {exc})"
        raise CheckpointError(msg) from exc


def _check_engine(meta, path) -> type:
    engine = meta.get("engine") if isinstance(meta, dict) else None
    if engine not in _ENGINES:
        msg = f"{path}: not a discsim checkpoint (engine {engine!r}; known: {sorted(_ENGINES)})"
        raise CheckpointError(msg)
    return _ENGINES[engine]


def load(path) -> EventDriven:
    """Load a simulation saved by ``save(path)`` or by ``run(checkpoint=path)``.

    The loaded engine continues exactly as the saved one would have: the same
    events, bit for bit. If the run streamed its log to disk, a later
    ``run(record_to=...)`` on that same file continues it (anything written
    after the checkpoint is cut off first).

    Args:
        path: the checkpoint file.

    Returns:
        The engine, at the saved time.

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
    meta, arrays = read_state(path)
    engine = _check_engine(meta, path)
    try:
        return engine._from_saved(meta, arrays)
    except (KeyError, TypeError, IndexError, DiscsimError) as exc:
        msg = f"{path}: the checkpoint is incomplete or inconsistent ({type(exc).__name__}: {exc})"
        raise CheckpointError(msg) from exc


def resume(path, *, progress: bool = False, record_to=None) -> EventDriven:
    """Continue the run that wrote checkpoint ``path`` to the end it was given.

    Loads the checkpoint and calls ``run`` with the same ``until`` and the
    remaining ``events``, the same ``checkpoint_every`` (writing to ``path``
    again) and the same streamed log, cut back to what the checkpoint saw.
    The final state equals that of the run had it never stopped, bit for bit.
    A checkpoint of a finished run is loaded and returned as it is.

    Args:
        path: a checkpoint written by ``run(checkpoint=path, ...)``.
        progress: show a progress bar.
        record_to: the streamed log, if it moved since (default: where the
            run wrote it).

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
    sim = load(path)
    if run["finished"]:
        return sim
    events = None if run["events"] is None else run["events"] - sim._physical()
    if record_to is None:
        record_to = run["record_to"]
    sim.run(
        until=run["until"],
        events=events,
        progress=progress,
        record_to=None if record_to is None else Path(record_to),
        checkpoint=path,
        checkpoint_every=run["checkpoint_every"],
    )
    return sim
