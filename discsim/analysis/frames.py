"""Frames: the exact state of every disc at chosen sample times, the input of every analysis.

A :class:`Frames` holds positions (wrapped and unwrapped) and velocities at ``T`` sample times, with the box
and the discs' radii, masses and groups. It comes from a finished run (:func:`frames`, rebuilt exactly from
the event log), from a run as it goes (:class:`discsim.Sampler`, which samples every ``dt`` of simulated
time and needs no log), or from a file (:func:`discsim.read_gsd`, :func:`discsim.read_xyz`). The analyses
(:func:`discsim.rdf`, :func:`discsim.psi6`, :func:`discsim.msd`, :func:`discsim.vacf`) take its arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from discsim.errors import InvalidArgumentError
from discsim.events import ADD, REMOVE, disc_partners
from discsim.model import Box, Discs
from discsim.trajectory import LastRecords, check_times, flight, reconstruct, replay, turning_at, turning_history

__all__ = ["Frames", "frames", "log_source", "states_at"]


@dataclass(frozen=True)
class Frames:
    """The discs at ``T`` sample times.

    Attributes:
        times: ``(T,)`` simulated times.
        positions: ``(T, N, 2)`` centres, wrapped into a periodic box.
        unwrapped: ``(T, N, 2)`` centres followed across the periodic edges (equal to ``positions`` with
            walls), continuous from the run's start: what a mean-squared displacement needs.
        velocities: ``(T, N, 2)`` velocities.
        box: the box.
        radii, masses: ``(N,)``; groups: ``(N,)`` integer group labels.
        spins, angles: ``(T, N)`` each disc's angular velocity (radians per time unit) and angle (radians,
            counter-clockwise, 0 at the run's start: what ``sim.angles`` says at those times), or None where the
            source does not say (a streamed log: its spins are not in it).
    """

    times: np.ndarray
    positions: np.ndarray
    unwrapped: np.ndarray
    velocities: np.ndarray
    box: Box
    radii: np.ndarray
    masses: np.ndarray
    groups: np.ndarray
    spins: np.ndarray | None = None
    angles: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.times)

    @property
    def n(self) -> int:
        """Number of discs."""
        return len(self.radii)

    def discs(self, k: int = -1) -> Discs:
        """Frame ``k`` as :class:`~discsim.model.Discs` (to start a new engine from it; with its spins if known)."""
        spins = None if self.spins is None else self.spins[k]
        return Discs(self.positions[k], self.velocities[k], self.radii, self.masses, self.groups, spins)

    @classmethod
    def from_discs(cls, discs: Discs, box: Box, time: float = 0.0, unwrapped=None) -> Frames:
        """One frame of ``discs`` in ``box`` at ``time``; ``unwrapped`` ``(N, 2)`` (default the positions)."""
        pos = np.asarray(discs.positions, dtype=float)[None].copy()
        vel = np.asarray(discs.velocities, dtype=float)[None].copy()
        unwrapped = pos if unwrapped is None else np.asarray(unwrapped, dtype=float)[None].copy()
        return cls(
            np.array([float(time)]),
            box.wrap(pos),
            unwrapped,
            vel,
            box,
            np.array(discs.radii, dtype=float),
            np.array(discs.masses, dtype=float),
            np.array(discs.groups),
        )

    @classmethod
    def concatenate(cls, parts: list[Frames]) -> Frames:
        """The frames of ``parts`` (same discs and box) one after the other."""
        if not parts:
            msg = "Frames.concatenate needs at least one Frames"
            raise InvalidArgumentError(msg)
        first = parts[0]
        turning = all(p.spins is not None and p.angles is not None for p in parts)
        return cls(
            np.concatenate([p.times for p in parts]),
            np.concatenate([p.positions for p in parts]),
            np.concatenate([p.unwrapped for p in parts]),
            np.concatenate([p.velocities for p in parts]),
            first.box,
            first.radii,
            first.masses,
            first.groups,
            np.concatenate([p.spins for p in parts]) if turning else None,  # type: ignore[misc]
            np.concatenate([p.angles for p in parts]) if turning else None,  # type: ignore[misc]
        )


def states_at(events: np.ndarray, positions0, velocities0, time0: float, times, box: Box):
    """Exact unwrapped positions and velocities ``(T, N, 2)`` each at ``times`` from a state and a log.

    Positions come from :func:`discsim.trajectory.reconstruct` (``unwrapped=True``), so they are those of
    ``sim.trajectory(times, unwrapped=True)``; velocities are each disc's last recorded velocity at or
    before each time (an event exactly at a sample time counts as done, as for positions).

    Args:
        events: structured array of :data:`~discsim.events.EVENT_DTYPE` in time order, after ``time0``.
        positions0, velocities0: ``(N, 2)`` state at ``time0`` (positions unwrapped or not).
        time0: when the state holds. times: ``(T,)`` times at or after ``time0``.
        box: the box.
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    positions0 = np.asarray(positions0, dtype=float)
    velocities0 = np.asarray(velocities0, dtype=float)
    unwrapped = reconstruct(events, positions0, velocities0, time0, times, box, unwrapped=True)
    n = len(positions0)
    # Each disc's records: its state at time0, then the log's rows that name it (as i, then as j).
    discs, t_recs, seqs, vels = [np.arange(n)], [np.full(n, float(time0))], [np.full(n, -1)], [velocities0]
    if len(events):
        discs.append(events["i"])
        t_recs.append(events["time"])
        seqs.append(np.arange(len(events)))
        vels.append(np.column_stack([events["vxi"], events["vyi"]]))
        pair = np.flatnonzero(disc_partners(events))
        discs.append(events["j"][pair])
        t_recs.append(events["time"][pair])
        seqs.append(pair)
        vels.append(np.column_stack([events["vxj"][pair], events["vyj"][pair]]))
    disc, t_rec, seq, vel = np.concatenate(discs), np.concatenate(t_recs), np.concatenate(seqs), np.vstack(vels)
    order = np.lexsort((seq, t_rec, disc))  # by disc, then time, then log order (as reconstruct)
    t_rec, vel = t_rec[order], vel[order]
    starts = np.searchsorted(disc[order], np.arange(n))
    velocities = np.empty((len(times), n, 2))
    for k, t in enumerate(times.tolist()):
        # A disc's records are in time order, so those at or before t are a prefix of its run of records.
        done = np.add.reduceat((t_rec <= t).astype(np.int64), starts)
        velocities[k] = vel[starts + np.maximum(done, 1) - 1]
    return unwrapped, velocities


def log_source(source, what: str):
    """``(events chunks, discs at start, box, start_time, end_time, engine or None)`` of a finished run.

    ``source`` is an engine holding its log (``record=True``), an engine whose log was streamed to disk
    (read back chunk by chunk), a :class:`~discsim.io.streams.StreamedEvents`, or the path of a streamed log.
    ``events chunks`` is a function returning an iterator of structured arrays in time order.

    The analyses built on it follow a fixed set of discs: a run that added or removed discs
    (``add_discs``, ``remove_discs``) is refused, when the engine says so or when a chunk holds an ``ADD``
    or ``REMOVE`` record (``sim.trajectory`` and :func:`discsim.contacts` do follow such runs).

    Raises:
        InvalidArgumentError: if the run recorded nothing (``record=False`` and no stream), or changed its
            set of discs, naming ``what``.
    """
    chunks, discs, box, start, end, sim = _log_source(source, what)
    if sim is not None and sim.run_context.origin is not None:
        raise InvalidArgumentError(_changed_message(what, None))

    def fixed():
        for records in chunks():
            changed = np.flatnonzero((records["kind"] == ADD) | (records["kind"] == REMOVE))
            if len(changed):
                raise InvalidArgumentError(_changed_message(what, float(records["time"][changed[0]])))
            yield records

    return fixed, discs, box, start, end, sim


def _changed_message(what: str, time: float | None) -> str:
    when = "" if time is None else f" at time {time!r}"
    return (
        f"{what} follows a fixed set of discs, and this run added or removed discs{when} (add_discs / "
        "remove_discs); use sim.trajectory(times) (NaN where a disc was not there) or analyse the spans "
        "between changes with fresh engines (sim.snapshot())"
    )


def _log_source(source, what: str):
    from discsim.io.container import iter_stream
    from discsim.io.streams import StreamedEvents, iter_events

    if isinstance(source, (str, Path)):  # read chunk by chunk, never whole
        chunked = iter_events(source)
        return chunked.record_arrays, chunked.discs, chunked.box, chunked.start_time, chunked.end_time, None
    if isinstance(source, StreamedEvents):
        log = source
        return (lambda: iter([log.events])), log.discs, log.box, log.start_time, log.end_time, None
    if not hasattr(source, "run_context") or not hasattr(source, "discs"):
        msg = f"{what} needs an engine, a streamed event log or its path, got {type(source).__name__}"
        raise InvalidArgumentError(msg)
    sim = source
    if sim.run_context.streamed:
        path = sim.run_context.stream["path"]
        header = next(iter_stream(path, partial=True))
        meta, arrays = header[0], header[1]
        discs = Discs(arrays["positions"], arrays["velocities"], arrays["radii"], arrays["masses"], arrays["groups"])
        start = float(meta["start_time"])

        def chunks():
            walk = iter_stream(path, partial=True)
            next(walk)
            for _meta, _arrays, records, _end in walk:
                yield records

        return chunks, discs, sim.box, start, sim.time, sim
    if not sim.record:
        msg = (
            f"{what} needs the run's event log, and this {type(sim).__name__} ran with record=False, recording "
            "nothing: build it with record=True, stream the log (run(record_to=...)), or sample during the run "
            "with ds.Sampler(dt)"
        )
        raise InvalidArgumentError(msg)
    return (lambda: iter([sim.run_context.log.to_array()])), sim.discs, sim.box, sim.start_time, sim.time, sim


def run_flight(source, engine, what: str):
    """The gravity ``(gx, gy)`` (or None) of the run behind ``source``: its engine's laws, or a streamed log's
    header (:func:`discsim.trajectory.flight`, which refuses drag)."""
    from discsim.io.container import stream_index
    from discsim.io.streams import StreamedEvents

    if engine is not None:
        laws = getattr(engine, "laws", None)
        return flight(getattr(laws, "gravity", None), getattr(laws, "drag", 0.0), what=what)
    if isinstance(source, StreamedEvents):
        return flight(source.gravity, getattr(source, "drag", 0.0), what=what)
    meta = stream_index(Path(source))[0]
    return flight(meta.get("gravity"), meta.get("drag", 0.0), what=what)


def _start_still(source, engine) -> np.ndarray | None:
    """``(N,)`` bool, the discs at rest where a streamed log starts (its header's ``resting``), or None: none."""
    from discsim.io.streams import StreamedEvents, iter_events

    if engine is not None:
        if not engine.run_context.streamed:
            return None  # a log held in memory starts where the run starts: no disc at rest
        source = engine.run_context.stream["path"]
    if isinstance(source, StreamedEvents):
        return source.resting
    return iter_events(source, partial=engine is not None).resting


def _turning(engine, discs: Discs, start: float, times: np.ndarray):
    """``(spins, angles)`` ``(T, N)`` each at ``times`` for an engine's run (None, None where it does not say)."""
    if engine is None or engine.run_context.streamed:
        return None, None
    laws = getattr(engine, "laws", None)
    spin_events = getattr(engine, "spin_events", None) if getattr(laws, "rough", False) else None
    if getattr(laws, "rough", False) and spin_events is None:
        return None, None
    try:
        history = turning_history(engine.run_context.log.to_array(), spin_events, discs.spins, start)
    except ValueError:  # the spins after the log's events are not all held (e.g. a log from before spins)
        return None, None
    return turning_at(history, times)


def frames(source, times) -> Frames:
    """The exact state of every disc at ``times``, rebuilt from a finished run's event log.

    Args:
        source: an engine that recorded its log (``record=True``), or streamed it (``run(record_to=...)``),
            a :class:`~discsim.io.streams.StreamedEvents` or the path of a streamed log.
        times: ``(T,)`` simulated times within the run's span, any order (frames come in that order).

    Returns:
        :class:`Frames`: ``positions`` equal ``sim.trajectory(times)`` (to roundoff at the periodic edges),
        ``unwrapped`` equal ``sim.trajectory(times, unwrapped=True)``, and the velocities at those times: along
        the exact parabolas under gravity (a disc at rest stays put). From an engine, also each disc's spin and
        angle (``spins``, ``angles``: those of ``sim.spins`` and ``sim.angles`` at those times).

    Raises:
        InvalidArgumentError: if the run recorded nothing (``record=False``): sample during the run with
            :class:`discsim.Sampler` instead; or if it has drag (exponential flight, not replayed yet).
        TimeError: if a time is not finite or lies outside the run's span.

    Example:
        >>> import discsim as ds
        >>> sim = ds.EventDriven(*ds.random_gas(50, 0.3, seed=1)).run(until=2.0)
        >>> f = ds.frames(sim, [0.0, 1.0, 2.0])
        >>> f.positions.shape, bool(np.allclose(f.velocities[-1], sim.velocities))
        ((3, 50, 2), True)
    """
    chunks, discs, box, start, end, engine = log_source(source, "frames()")
    gravity = run_flight(source, engine, "frames()")
    times = check_times(times, start, end, "simulated span")
    # A streamed log is read one chunk at a time, up to the last time asked: memory flat in its length.
    origin = LastRecords.at_start(discs, start, still=_start_still(source, engine))
    unwrapped, velocities = replay(chunks(), origin, times, box, unwrapped=True, velocities=True, gravity=gravity)
    spins, angles = _turning(engine, discs, start, times)
    return Frames(
        times,
        box.wrap(unwrapped),
        unwrapped,
        velocities,
        box,
        np.array(discs.radii, dtype=float),
        np.array(discs.masses, dtype=float),
        np.array(discs.groups),
        spins,
        angles,
    )
