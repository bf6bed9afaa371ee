"""The event-driven engine (PIC): jump from one predicted collision to the next.

State is one ``bytearray`` of per-disc records, six float64 each:
``(x, y, vx, vy, t_ref, radius)``, read and written with one
:class:`struct.Struct` call (the hot loop works on Python floats, not numpy
scalars). A record is 48 contiguous bytes, so fetching a neighbour costs one
cache line: Python lists of float objects cost several, which made large
systems slow (same-process A/B against a list of tuples: +4% at N = 10^3,
+8% at 10^4, +7% at 10^5). Each disc flies straight from its reference
position at its own reference time, ``r + v (t - t_ref)``, until its
velocity changes: an event touches only the discs it involves (lazy clocks).

Each moving disc owns at most one pending event in the queue: the earliest of
its next wall hit, its next cell crossing and its next collision with a disc
in the 3x3 cells around it. A collision event carries the partner's collision
counter at prediction time and is stale when popped if the partner's counter
has moved on. The owner's own event is replaced whenever the owner is
re-predicted, so the queue never holds more than N events.

The hot loop, :meth:`EventDriven._process`, reads top to bottom: pop,
validate the counter, advance the discs involved, resolve, record,
re-predict, push.
"""

from __future__ import annotations

import contextlib
import gc
import math
import struct
import uuid
from operator import itemgetter
from pathlib import Path

import numpy as np

from discsim.cells import CellGrid
from discsim.engines.base import Engine
from discsim.errors import CheckpointError, InvalidArgumentError, TimeError
from discsim.events import EVENT_DTYPE, KIND_NAMES, Event, EventLog
from discsim.io.container import RecordWriter, read_state, write_state
from discsim.io.streams import stream_header
from discsim.kernels import reflect_off_segment, resolve_collision, segment_time_of_impact
from discsim.model import Box, Discs, Segment
from discsim.queue import CalendarEventQueue, EventQueue, HeapEventQueue
from discsim.scene import check_fits, check_scene

__all__ = ["EventDriven"]

# A disc's record in the state buffer: x, y, vx, vy, t_ref, radius (float64).
_RECORD = struct.Struct("6d")
_RECORD_BYTES = _RECORD.size
# Positions in a cell's static record (see EventDriven._make_predictor): the cell's index,
# its slot in its tile, and the ghost copies of it in other tiles.
_CELL_INDEX, _SLOT, _GHOSTS = 9, 10, 11
# Side, in cells, of the square tiles the table of cell members is cut into (see _tile_cells).
# With a ring of ghost cells a tile holds 12 x 12 = 144 slots, so every slot index is one of
# CPython's cached small ints and a 3x3 block reads no memory outside its tile.
_TILE = 10
# Systems of at least this many discs are numbered internally tile by tile (see _internal_order).
# Smaller ones fit in the caches, gain nothing, and keep the caller's numbering, which then also
# decides the order of simultaneous events, as the caller would expect.
_RENUMBER_MIN = 4096

INF = math.inf
# Kinds of queued events. COLLISION and WALL match discsim.eventlog.
_COLLISION, _WALL, _CROSSING, _SEGMENT = 0, 1, 2, 3
# Physical events between moves of the internal clock's epoch (at least 16 per disc).
_REBASE_EVENTS = 1 << 18
# Directions of a cell crossing.
_PLUS_X, _MINUS_X, _PLUS_Y, _MINUS_Y = 0, 1, 2, 3

_QUEUES = {"calendar": CalendarEventQueue, "sorted": EventQueue, "heap": HeapEventQueue}


class EventDriven(Engine):
    """Exact event-driven simulation of elastic hard discs (PIC).

    Args:
        discs: the discs at ``time = 0``.
        box: the box (reflecting walls or periodic).
        record: keep the event log (needed by ``events`` and ``trajectory``);
            switch off for long runs so memory stays flat.
        queue: the event queue, all three giving the same events bit for bit:
            ``"calendar"`` (the default: the near-future events in a
            ``sortedcontainers.SortedList``, later ones appended to time bins,
            O(1) per event; :class:`~discsim.queue.CalendarEventQueue`),
            ``"sorted"`` (every event in one ``SortedList``) or ``"heap"``
            (``heapq`` with lazy deletion).
        cell_size: side of the grid cells; default the largest disc diameter,
            grown where needed so that there are at most ``4 N + 9`` cells.
            Never below the largest diameter.
        segments: fixed :class:`~discsim.model.Segment` walls (walled boxes
            only), kept in a static per-cell table built once.
        pass_through: pairs of group labels (``discs.groups``) whose discs do
            not collide with each other, e.g. ``{(1, 1)}`` for bullets that
            pass through one another. Free when empty.

    Raises:
        OutsideBoxError, OverlapError: if the discs do not fit in the box.
        BoxTooSmallError: if a periodic box has fewer than 3 cells a side.

    Attributes:
        time (float): the current simulated time.
        counts (dict[str, int]): ``collisions`` (disc-disc), ``wall_hits``,
            ``cell_crossings``, ``stale`` (invalidated events popped) and
            ``predictions`` (discs re-predicted).
        max_queue (int): the most events the queue has held at once (at most N).
        max_overlap (float): the deepest overlap seen at a collision, as a
            fraction of the contact distance (roundoff only: about 1e-15).

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
        >>> sim = ds.EventDriven(discs, ds.Box(10.0, 10.0)).run(until=2.5)
        >>> sim.counts["collisions"], sim.velocities.tolist()
        (1, [[-1.0, 0.0], [1.0, 0.0]])
    """

    def __init__(
        self,
        discs: Discs,
        box: Box,
        *,
        record: bool = True,
        queue: str = "calendar",
        cell_size: float | None = None,
        segments=(),
        pass_through=(),
    ):
        self._setup(discs, box, record, queue, cell_size, segments, pass_through)
        n = len(discs)
        grid = self.grid
        pos, vel, radii = (a[self._order] for a in (discs.positions, discs.velocities, discs.radii))
        self._disc = _pack_records(pos[:, 0], pos[:, 1], vel[:, 0], vel[:, 1], np.zeros(n), radii)
        self._count = [0] * n
        self._cell = grid.cells_of(pos).tolist()
        members: list[list[int]] = [[] for _ in range(len(grid))]
        for i, c in enumerate(self._cell):
            members[c].append(i)
        # One tuple per cell; empty cells share the one empty tuple, so scanning them touches
        # no memory. _make_predictor moves them into tiles (see _tile_cells).
        self._cells: list[tuple[int, ...]] = [tuple(m) for m in members]
        self._kept_time, self._kept_partner, self._kept_stamp = [INF] * n, [-1] * n, [0] * n
        self._queue = _QUEUES[queue](n)
        self._log = EventLog()
        self._virial = 0.0
        self._last = None
        self._epoch, self._since_rebase = 0.0, 0
        self._counts = {"collisions": 0, "wall_hits": 0, "cell_crossings": 0, "stale": 0}
        self.max_overlap = 0.0
        self._predict, self._predictions = self._make_predictor(0)
        for i in range(n):
            if self._moving[i]:
                self._predict(i, 0.0, -1)
        self.max_queue = len(self._queue)

    def _setup(self, discs, box, record, queue, cell_size, segments, pass_through, order=None) -> None:
        """Validate and build what depends only on the settings: checks, grid, internal numbering, static lists."""
        super().__init__(discs, box, record)
        if queue not in _QUEUES:
            msg = f"queue must be one of {sorted(_QUEUES)}, got {queue!r}"
            raise InvalidArgumentError(msg)
        segments, pass_through = check_scene(discs, box, segments, pass_through)
        n = len(discs)
        diameter = 2.0 * float(discs.radii.max()) if n else 1.0
        if cell_size is None:
            grid = CellGrid(box, diameter, max_cells=4 * n + 9)
        else:
            if not (isinstance(cell_size, (int, float, np.integer, np.floating)) and diameter <= cell_size < INF):
                msg = f"cell_size {cell_size!r} is not finite or is below the largest disc diameter {diameter!r}"
                raise InvalidArgumentError(msg)
            grid = CellGrid(box, float(cell_size), what="the cell_size asked for")
        self.grid = grid
        self.time = 0.0
        self.queue_kind = queue
        self.cell_size = cell_size
        self.segments = segments
        self.pass_through = pass_through
        # Internally, large systems number their discs tile by tile of cells (see
        # _internal_order), so that discs close in space are close in memory; the public API,
        # the event log and the events returned speak the caller's numbering. ``_order[k]``
        # is the caller's index of internal disc k, ``_rank`` its inverse (None when both
        # are the identity).
        if order is None:
            order = _internal_order(grid, discs.positions) if n >= _RENUMBER_MIN else np.arange(n)
        self._order = np.asarray(order, dtype=np.int64)
        identity = bool(np.array_equal(self._order, np.arange(n)))
        self._rank = None if identity else np.argsort(self._order)
        self._caller_id = list(range(n)) if identity else self._order.tolist()
        self._radius = discs.radii[self._order].tolist()
        # Equal masses share one float object, so reading them costs no cache miss.
        shared: dict[float, float] = {}
        self._mass = [shared.setdefault(m, m) for m in discs.masses[self._order].tolist()]
        # The mass of every disc when all are equal and finite (the common case), else None:
        # the hot loop then skips two per-disc lookups, two cache misses at large N.
        self._one_mass = self._mass[0] if len(shared) == 1 and self._mass[0] != INF else None
        self._moving = np.isfinite(discs.masses[self._order]).tolist()
        self._rebase_every = max(_REBASE_EVENTS, 16 * n)

    # --- saving and restoring ----------------------------------------------------------
    # The per-disc records are saved as one array per field (the file format predates the records).
    _RECORD_FIELDS = ("_rx", "_ry", "_vx", "_vy", "_tr")
    _STATE_FLOATS = ("_kept_time",)
    _STATE_INTS = ("_count", "_kept_partner", "_kept_stamp")

    def _records(self, caller: bool = False) -> np.ndarray:
        """The per-disc records as an ``(N, 6)`` array: x, y, vx, vy, t_ref, radius.

        Rows in the internal numbering, or in the caller's with ``caller=True``.
        """
        records = np.frombuffer(self._disc, dtype=np.float64).reshape(-1, 6)
        return records[self._rank] if caller and self._rank is not None else records.copy()

    def _cell_members(self) -> list[tuple[int, ...]]:
        """The discs in each cell (a new list, indexed as the grid's cells)."""
        return [here[1][here[_SLOT]] for here in self._cell_info]

    def _get_state(self) -> dict:
        """Everything needed to continue bit for bit, as numpy arrays and plain numbers."""
        records = self._records()
        state = {name: records[:, k].copy() for k, name in enumerate(self._RECORD_FIELDS)}
        state.update({name: np.array(getattr(self, name), dtype=np.float64) for name in self._STATE_FLOATS})
        state.update({name: np.array(getattr(self, name), dtype=np.int64) for name in self._STATE_INTS})
        state["_cell"] = np.array([here[_CELL_INDEX] for here in self._where], dtype=np.int64)
        state["order"] = np.array(self._order, dtype=np.int64)  # every per-disc array is in this numbering
        # Order within a cell decides ties, so it is saved too.
        cells = self._cell_members()
        state["cell_members"] = np.array([j for members in cells for j in members], dtype=np.int64)
        state["cell_sizes"] = np.array([len(members) for members in cells], dtype=np.int64)
        pending = [(o, *self._queue.pending(o)) for o in range(len(self.discs))]
        pending = [(o, t, p) for o, t, p in pending if t != INF]
        state["queue_owner"] = np.array([o for o, _, _ in pending], dtype=np.int64)
        state["queue_time"] = np.array([t for _, t, _ in pending], dtype=np.float64)
        state["queue_payload"] = np.array([p for _, _, p in pending], dtype=np.int64).reshape(-1, 3)
        state["scalars"] = {
            "time": self.time,
            "epoch": self._epoch,
            "since_rebase": self._since_rebase,
            "virial": self._virial,
            "max_overlap": self.max_overlap,
            "max_queue": self.max_queue,
            "predictions": self._predictions(),
            "last": list(self._last) if self._last is not None else None,
            **self._counts,
        }
        state["settings"] = {
            "record": self.record,
            "queue": self.queue_kind,
            "cell_size": self.cell_size,
            "segments": [[*s.p0.tolist(), *s.p1.tolist()] for s in self.segments],
            "pass_through": sorted(self.pass_through),
        }
        state["events"] = self._log.to_array()
        return state

    @classmethod
    def _from_state(cls, discs: Discs, box: Box, state: dict) -> EventDriven:
        """Rebuild an engine from :meth:`_get_state` output and the initial discs."""
        settings, scalars = state["settings"], state["scalars"]
        sim = cls.__new__(cls)
        segments = [Segment(row[:2], row[2:]) for row in settings.get("segments", [])]
        sim._setup(
            discs,
            box,
            settings["record"],
            settings["queue"],
            settings["cell_size"],
            segments,
            [tuple(pair) for pair in settings.get("pass_through", [])],
            state["order"] if "order" in state else np.arange(len(discs)),  # older files: caller's numbering
        )
        for name in cls._STATE_FLOATS + cls._STATE_INTS + ("_cell",):
            setattr(sim, name, state[name].tolist())
        sim._disc = _pack_records(*(state[name] for name in cls._RECORD_FIELDS), discs.radii[sim._order])
        sizes = state["cell_sizes"].tolist()
        members = state["cell_members"].tolist()
        sim._cells, k = [], 0
        for size in sizes:
            sim._cells.append(tuple(members[k : k + size]))
            k += size
        sim._queue = _QUEUES[settings["queue"]](len(discs))
        for owner, t, payload in zip(
            state["queue_owner"].tolist(), state["queue_time"].tolist(), state["queue_payload"].tolist()
        ):
            sim._queue.push(owner, t, tuple(payload))
        sim._log = EventLog()
        if len(state["events"]):
            sim._log.extend(state["events"])
        sim.time = scalars["time"]
        sim._epoch = scalars.get("epoch", 0.0)
        sim._since_rebase = scalars.get("since_rebase", 0)
        sim._virial = scalars["virial"]
        sim.max_overlap = scalars["max_overlap"]
        sim.max_queue = scalars["max_queue"]
        sim._last = tuple(scalars["last"]) if scalars["last"] is not None else None
        sim._counts = {k: scalars[k] for k in ("collisions", "wall_hits", "cell_crossings", "stale")}
        sim._predict, sim._predictions = sim._make_predictor(scalars["predictions"])
        return sim

    # --- public protocol -------------------------------------------------------------
    @property
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres at ``time`` (a fresh copy; wrapped into a periodic box)."""
        t = self.time - self._epoch
        rx, ry, vx, vy, tr, _ = self._records(caller=True).T
        out = np.column_stack([rx + vx * (t - tr), ry + vy * (t - tr)])
        return self.box.wrap(out) if len(out) else out.reshape(0, 2)

    @property
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities at ``time`` (a fresh copy)."""
        return self._records(caller=True)[:, 2:4].copy()

    def _event_array(self) -> np.ndarray:
        return self._log.to_array()

    @property
    def counts(self) -> dict[str, int]:
        """Events so far: ``collisions``, ``wall_hits``, ``cell_crossings``, ``stale``, ``predictions``."""
        return {**self._counts, "predictions": self._predictions()}

    @property
    def queue_size(self) -> int:
        """Events pending in the queue now (at most N)."""
        return len(self._queue)

    @property
    def queue_storage(self) -> int:
        """Entries the queue holds in memory now, replaced (dead) ones included.

        Equals ``queue_size`` for ``queue="sorted"``; at most ``3 N + 64`` for
        ``"calendar"`` and ``2 N + 16`` for ``"heap"``, which drop dead entries lazily.
        """
        return self._queue.storage()

    def pressure(self) -> float:
        """Pressure from the collision virial, averaged since the start.

        ``P = (N kT + W / (2 t)) / A`` in 2D, with ``N kT`` the kinetic energy,
        ``W`` the sum over disc-disc collisions of ``dp_i . (r_i - r_j)`` and
        ``A`` the box area. With walls this is the bulk estimate (wall contacts
        are not counted). Units: energy per area.
        """
        elapsed = self.time - self.start_time
        if elapsed <= 0:
            msg = "pressure() needs a run of positive duration"
            raise InvalidArgumentError(msg)
        return (self.kinetic_energy() + self._virial / (2.0 * elapsed)) / self.box.area

    def run(
        self,
        until: float | None = None,
        *,
        events: int | None = None,
        progress: bool = False,
        record_to=None,
        checkpoint=None,
        checkpoint_every: int | None = None,
    ):
        """Process events up to time ``until`` and/or for ``events`` physical events.

        Args:
            until: stop time; events at exactly ``until`` are processed and
                ``time`` is set to ``until`` at the end.
            events: stop after this many collisions plus wall hits (cell
                crossings and stale events are bookkeeping and not counted).
                Without ``until``, the run also ends early when no disc can ever
                hit anything again. In a periodic box that is proven when every
                pair drifts alike, or moves relative to itself only along x or
                only along y and misses; other orbits that never meet on the
                torus look like slow ones, so give ``until`` for such scenes.
            progress: show a tqdm progress bar (simulated time or events, and
                collisions per second).
            record_to: stream the event log to this file in chunks of
                :attr:`stream_chunk` events (about 90 bytes per event), so
                memory stays flat. Works with ``record=False`` too. A new file
                starts with the discs where the log starts; the engine's own
                log file (after a resume, or a second ``run`` call) is
                continued; any other existing file is refused. Read it with
                :func:`discsim.read_events`; ``events`` and ``trajectory()``
                are then unavailable on the engine.
            checkpoint: write the whole state to this file (see :meth:`save`)
                when the run starts, every ``checkpoint_every`` physical
                events, and when it ends. A file already there must be a
                checkpoint of this same run (it is then replaced); anything
                else is refused. After a crash, :func:`discsim.resume`
                continues from the last checkpoint to the same final state,
                bit for bit.
            checkpoint_every: physical events between checkpoints (needs
                ``checkpoint``); default only at the start and the end.

        Returns:
            ``self``, so calls chain.

        Raises:
            TimeError: if ``until`` is before ``time``, NaN, or infinite without ``events``.
            InvalidArgumentError: if neither limit is given, ``events`` is not a whole number >= 0, or
                ``checkpoint_every`` is not a positive integer or comes without
                ``checkpoint``.
            CheckpointError: if ``record_to`` or ``checkpoint`` names a file
                that is damaged or belongs to another run (left untouched), or
                the engine's log on disk has a gap (events run while not
                recording). Nothing has been simulated then.
        """
        if until is None and events is None:
            msg = "run() needs until=... or events=..."
            raise InvalidArgumentError(msg)
        limit_t = INF if until is None else self._check_until(until)
        if events is None and limit_t == INF:
            msg = "run(until=inf) never ends: give a finite until or events=..."
            raise TimeError(msg)
        if events is not None and not _is_count(events):
            msg = f"events must be a non-negative integer, got {events!r}"
            raise InvalidArgumentError(msg)
        limit_n = -1 if events is None else int(events)
        if checkpoint_every is not None:
            if checkpoint is None:
                msg = "checkpoint_every needs checkpoint=path"
                raise InvalidArgumentError(msg)
            if isinstance(checkpoint_every, bool) or int(checkpoint_every) != checkpoint_every or checkpoint_every < 1:
                msg = f"checkpoint_every must be a positive integer (physical events), got {checkpoint_every!r}"
                raise InvalidArgumentError(msg)
            checkpoint_every = int(checkpoint_every)
        if record_to is None and checkpoint is None and not progress:
            done = self._process(limit_t, limit_n)
            if limit_t != INF and done != limit_n:  # stopped by the clock, not by the event count
                self.time = limit_t
            return self
        self._run_in_chunks(limit_t, limit_n, progress, record_to, checkpoint, checkpoint_every)
        return self

    def _run_with_progress(self, limit_t: float, limit_n: int) -> int:
        """Run with a progress bar only; return the physical events processed."""
        return self._run_in_chunks(limit_t, limit_n, True, None, None, None)

    def step(self) -> Event | None:
        """Process events up to and including the next collision or wall hit.

        Returns:
            The :class:`~discsim.engine.Event` processed, or None if no disc
            will ever hit anything (see ``events`` in :meth:`run` for how a
            periodic box proves that).
        """
        if self._process(INF, 1) == 0:
            return None
        t, kind, i, j = self._last
        caller = self._caller_id
        return Event(t, KIND_NAMES[kind], caller[i], caller[j] if j >= 0 else j)

    # --- long runs: progress, streamed logs, checkpoints --------------------------------
    #: Events per chunk of a log streamed by ``run(record_to=...)``; at most this
    #: many events are held in memory while streaming.
    stream_chunk = 16_384
    #: Physical events per call of the hot loop between progress-bar updates.
    _PROGRESS_CHUNK = 20_000
    # Class-level defaults, so that engines built by __init__ or _from_state have them.
    _run_id: str | None = None  # identifies this run in its checkpoints and streamed log
    _stream: dict | None = None  # this run's log on disk: path, run_id, base, records, end

    def _physical(self) -> int:
        """Physical events (collisions plus wall hits) processed since the start."""
        return self._counts["collisions"] + self._counts["wall_hits"]

    def _ensure_run_id(self) -> str:
        if self._run_id is None:
            self._run_id = uuid.uuid4().hex
        return self._run_id

    def _run_in_chunks(self, limit_t, limit_n, progress, record_to, checkpoint, every) -> int:
        """Run in slices of the hot loop, between which the bar, the log on disk and checkpoints are served.

        The slices change nothing in the dynamics: ``_process`` resumes exactly
        where it stopped. Returns the physical events processed.
        """
        from discsim.run.progress import progress_bar

        checkpoint = None if checkpoint is None else Path(checkpoint)
        if checkpoint is not None:
            if record_to is not None and Path(record_to).absolute() == checkpoint.absolute():
                msg = f"record_to and checkpoint must be two different files, got {checkpoint} twice"
                raise InvalidArgumentError(msg)
            self._check_checkpoint_target(checkpoint)
        writer = None if record_to is None else self._open_stream(Path(record_to))
        target = {
            "until": None if limit_t == INF else limit_t,
            "events": None if limit_n < 0 else self._physical() + limit_n,
            "checkpoint_every": every,
            "record_to": None if writer is None else str(writer.path.absolute()),
        }
        recording = self.record
        by_time = limit_n < 0
        try:
            self.record = recording or writer is not None  # the hot loop logs only when record is on
            if checkpoint is not None:
                self._write_checkpoint(checkpoint, writer, recording, {**target, "finished": False})
            total = limit_t - self.time if by_time else limit_n
            with progress_bar(total, by_time) if progress else contextlib.nullcontext() as bar:
                if bar is not None:
                    bar.start(self._counts["collisions"])
                done = since_checkpoint = 0
                while True:
                    chunk = self._PROGRESS_CHUNK
                    if limit_n >= 0:
                        chunk = min(chunk, limit_n - done)
                    if every is not None:
                        chunk = min(chunk, every - since_checkpoint)
                    if writer is not None:
                        chunk = min(chunk, max(1, self.stream_chunk - len(self._log)))
                    t0 = self.time
                    k = self._process(limit_t, chunk)
                    done += k
                    since_checkpoint += k
                    if bar is not None:
                        bar.update(self.time - t0 if by_time else k, self._counts["collisions"])
                    finishing = k < chunk or done == limit_n
                    if writer is not None and len(self._log) >= self.stream_chunk:
                        self._flush_stream(writer)
                    if every is not None and since_checkpoint >= every and not finishing:  # else the final one
                        self._write_checkpoint(checkpoint, writer, recording, {**target, "finished": False})
                        since_checkpoint = 0
                    if finishing:
                        break
                if limit_t != INF and done != limit_n:  # stopped by the clock, not by the event count
                    if bar is not None and by_time:
                        bar.update(limit_t - self.time, self._counts["collisions"])
                    self.time = limit_t
            if writer is not None:
                self._flush_stream(writer)
            if checkpoint is not None:
                self._write_checkpoint(checkpoint, writer, recording, {**target, "finished": True})
        finally:
            self.record = recording
            if writer is not None:
                writer.close()
        return done

    def _open_stream(self, path: Path) -> RecordWriter:
        """The writer of this run's log at ``path``: a new file, or this run's own file continued.

        Checks everything before touching anything: a foreign or damaged file,
        or a gap in the log (events processed while nothing recorded them),
        raises CheckpointError and leaves the file and the engine as they were.
        """
        stream, physical = self._stream, self._physical()
        if path.exists():
            if stream is None:
                msg = (
                    f"{path} already exists and is not this run's event log; discsim will not overwrite it "
                    "(choose another path or remove the file)"
                )
                raise CheckpointError(msg)
            if stream["base"] + stream["records"] + len(self._log) != physical:
                missed = physical - stream["base"] - stream["records"] - len(self._log)
                msg = (
                    f"{path}: the log on disk stops {missed} events before the engine (they ran without "
                    "record_to and record=False); stream to a new file instead"
                )
                raise CheckpointError(msg)
            writer = RecordWriter.reopen(
                path, stream["records"], stream["end"], expect={"run_id": stream["run_id"], "base": stream["base"]}
            )
            self._stream = {**stream, "path": str(path.absolute())}
            return writer
        from_start = stream is None and len(self._log) == physical  # the log in memory covers the whole run
        if from_start:
            discs, start, base = self.discs, self.start_time, 0
        else:
            discs, start, base = self.snapshot(), self.time, physical
        meta, arrays = stream_header(discs, self.box, start, self._ensure_run_id(), base)
        writer = RecordWriter.create(path, EVENT_DTYPE, meta, arrays)
        if not from_start:
            self._log.drain()  # events before ``start`` do not belong to the new file
        self._stream = {
            "path": str(path.absolute()),
            "run_id": self._run_id,
            "base": base,
            "records": 0,
            "end": writer.end,
        }
        return writer

    def _flush_stream(self, writer: RecordWriter) -> None:
        """Move the in-memory log to disk as one chunk, stamped with the time it covers up to."""
        writer.append(self._log.drain(), {"time": self.time})
        self._stream = {**self._stream, "records": writer.records, "end": writer.end}

    def _check_checkpoint_target(self, path: Path) -> None:
        """Refuse to overwrite a file that is not a checkpoint of this run (damaged ones included)."""
        if not path.parent.is_dir():
            msg = f"cannot write the checkpoint {path}: no folder {path.parent}"
            raise FileNotFoundError(msg)
        if path.exists():
            meta, _ = read_state(path)
            if self._run_id is None or meta.get("run_id") != self._run_id:
                msg = (
                    f"{path} holds a checkpoint of another run; discsim will not overwrite it "
                    "(choose another path, or resume that run with discsim.resume)"
                )
                raise CheckpointError(msg)

    def _write_checkpoint(self, path: Path, writer, recording: bool, run: dict) -> None:
        """Sync the log on disk first, then write the state, so a checkpoint never refers past the log."""
        if writer is not None:
            self._flush_stream(writer)
            writer.sync()
        state = self._get_state()
        state["settings"] = {**state["settings"], "record": recording}  # not the forced recording of streaming
        self._write_state_file(path, state, run)

    def save(self, path) -> Path:
        """Write the whole state to one file, so that :func:`discsim.load` continues bit for bit.

        The file holds the initial discs, the box, the time, the counters, the
        settings, the event queue, the per-disc clocks and the event log if
        recorded (or where it was streamed). It is written to a temporary
        file in the same folder and renamed over ``path``, so a crash never
        leaves half a file; a SHA-256 checksum and a format version guard the
        reading. Plain numbers and JSON only, no pickle: loading a file never
        runs code from it. An existing ``path`` is replaced.

        Args:
            path: the file to write (its folder must exist).

        Returns:
            The path written, as a :class:`~pathlib.Path`.

        Example:
            >>> import os, tempfile, discsim as ds
            >>> discs, box = ds.random_gas(50, 0.4, seed=2)
            >>> path = os.path.join(tempfile.mkdtemp(), "sim.dsc")
            >>> a = ds.EventDriven(discs, box).run(until=1.0)
            >>> _ = a.save(path)
            >>> b = ds.load(path)
            >>> a.run(until=3.0).events.tobytes() == b.run(until=3.0).events.tobytes()
            True
        """
        return self._write_state_file(Path(path), self._get_state(), None)

    def _write_state_file(self, path: Path, state: dict, run: dict | None) -> Path:
        """Lay out ``_get_state()`` output plus the initial discs for :func:`discsim.io.write_state`."""
        discs, box = self.discs, self.box
        meta = {
            "engine": type(self).__name__,
            "run_id": self._ensure_run_id(),
            "start_time": self.start_time,
            "box": {"width": box.width, "height": box.height, "periodic": box.periodic},
            "state": {k: v for k, v in state.items() if not isinstance(v, np.ndarray)},
            "stream": self._stream,
            "run": run,
        }
        arrays = {f"state.{k}": v for k, v in state.items() if isinstance(v, np.ndarray)}
        arrays.update(
            {
                "discs.positions": discs.positions,
                "discs.velocities": discs.velocities,
                "discs.radii": discs.radii,
                "discs.masses": discs.masses,
                "discs.groups": discs.groups,
            }
        )
        return write_state(path, meta, arrays)

    @classmethod
    def _from_saved(cls, meta: dict, arrays: dict) -> EventDriven:
        """Rebuild an engine from what :meth:`_write_state_file` wrote (see :func:`discsim.load`)."""
        discs = Discs(
            arrays["discs.positions"],
            arrays["discs.velocities"],
            arrays["discs.radii"],
            arrays["discs.masses"],
            arrays["discs.groups"],
        )
        box = Box(**meta["box"])
        state = dict(meta["state"])
        state.update({k.removeprefix("state."): v for k, v in arrays.items() if k.startswith("state.")})
        sim = cls._from_state(discs, box, state)
        sim.start_time = float(meta["start_time"])
        sim._run_id = meta["run_id"]
        sim._stream = meta["stream"]
        return sim

    @property
    def events(self) -> np.ndarray:
        """The recorded event log: a structured array ``(E,)`` of :data:`~discsim.events.EVENT_DTYPE`.

        Empty when the engine was built with ``record=False``.

        Raises:
            ValueError: if the log was streamed to disk (``run(record_to=...)``):
                read it with :func:`discsim.read_events`.
        """
        self._refuse_if_streamed("events")
        return super().events

    def trajectory(self, times) -> np.ndarray:
        """Exact positions ``(T, N, 2)`` at ``times`` ``(T,)``, rebuilt from the event log.

        Times must lie within ``[start_time, time]``. Needs ``record=True``.

        Raises:
            ValueError: if the engine does not hold its log (``record=False``, or
                streamed to disk: use :func:`discsim.trajectory_from_events`).
            TimeError: if a time lies outside the simulated span.
        """
        self._refuse_if_streamed("trajectory()")
        return super().trajectory(times)

    def _refuse_if_streamed(self, what: str) -> None:
        if self._stream is not None:
            path = self._stream["path"]
            msg = (
                f"{what} is not kept in memory: this run streamed its event log to {path!r}; "
                f"read it with ds.read_events({path!r}) and rebuild positions with "
                f"ds.trajectory_from_events({path!r}, times)"
            )
            raise InvalidArgumentError(msg)

    # --- prediction ------------------------------------------------------------------
    def _make_predictor(self, n_pred: int):
        """Build the prediction closures over the state lists (closures read locals fast).

        Returns ``(predict, predictions)``:

        - ``predict(i, t, exclude, direction=-1)`` schedules disc ``i``'s
          earliest event after time ``t``: its wall or segment hit, its cell
          crossing, or its collision with a disc in the 3x3 block of cells
          around it, never with ``exclude`` (the partner it has just left:
          roundoff must not make a pair collide twice). The earliest collision
          found is also kept per disc. After ``i`` crossed into a new cell in
          ``direction``, only the 3 cells that just became adjacent are scanned
          and the kept collision stands for the 6 that stay adjacent: that
          equals a full 3x3 re-prediction as long as the kept partner has not
          changed course since (else the full scan runs).
        - ``predictions()`` counts the predictions made (from ``n_pred``).

        The neighbour loop inlines :func:`discsim.kernels.time_of_impact`.
        Also builds the static per-cell records (``_cell_info``) and points each
        disc at its cell's record (``_where``, from the indices in ``_cell``).
        """
        disc, unpack = self._disc, _RECORD.unpack_from
        count = self._count
        grid, box = self.grid, self.box
        front = {_PLUS_X: (6, 7, 8), _MINUS_X: (0, 1, 2), _PLUS_Y: (2, 5, 8), _MINUS_Y: (0, 3, 6)}
        width, height, periodic = box.width, box.height, box.periodic
        # Segments near each cell (a static structure built once).
        segment_ends = [(*s.p0.tolist(), *s.p1.tolist()) for s in self.segments]
        reach = max(self._radius, default=0.0)
        segments_near = grid.segments_by_cell(self.segments, reach) if segment_ends else [()] * len(grid)
        # One static record per cell, so a prediction reads one tuple:
        # (block, tile, minimum-image shifts of the block, xlo, xhi, ylo, yhi, walls,
        # segments, the cell's index, its slot in the tile, its ghost copies). Each disc
        # holds its cell's record in ``where`` (built here from the cell indices in
        # ``_cell``), one pointer away. The cell members live in tiles (``_tile_cells``):
        # ``block(tile)`` fetches the 9 member tuples of the 3x3 block in one call, and
        # cells a wall cuts off are ghost slots that stay empty. ``walls`` has bit 1, 2,
        # 4, 8 set when a wall stands beyond the low-x, high-x, low-y, high-y side.
        # Records share one float per column and per row, which keeps them small.
        blocks, tiles, slots, ghosts = _tile_cells(grid, self._cells, periodic)
        del self._cells
        col_lo = [cx * grid.lx for cx in range(grid.nx)]
        col_hi = [*col_lo[1:], width]
        row_lo = [cy * grid.ly for cy in range(grid.ny)]
        row_hi = [*row_lo[1:], height]
        info = []
        for c, (shift, segs) in enumerate(zip(grid.shifts, segments_near)):
            cx, cy = divmod(c, grid.ny)
            walls = (
                0 if periodic else ((cx == 0) | (cx == grid.nx - 1) << 1 | (cy == 0) << 2 | (cy == grid.ny - 1) << 3)
            )
            here = (blocks[c], tiles[c], shift, col_lo[cx], col_hi[cx], row_lo[cy], row_hi[cy], walls, segs, c)
            info.append((*here, slots[c], ghosts[c]))
        self._cell_info = info
        self._where = where = [info[c] for c in self._cell]
        del self._cell
        kept_time, kept_partner, kept_stamp = self._kept_time, self._kept_partner, self._kept_stamp
        push, discard = self._queue.push, self._queue.discard
        # Collision filter: blocked[g][h] is True when groups g and h pass through each other.
        filtering = bool(self.pass_through)
        labels = sorted(set(self.discs.groups.tolist()))
        index = {g: k for k, g in enumerate(labels)}
        group = [index[g] for g in self.discs.groups[self._order].tolist()]
        blocked = [[(min(g, h), max(g, h)) in self.pass_through for h in labels] for g in labels]
        sqrt = math.sqrt
        # The payloads of wall, crossing and segment events, made once and shared:
        # ``payloads[kind][other]``. A pop then reads no freshly scattered tuple for them.
        payloads = [
            None,
            [(_WALL, 0, 0), (_WALL, 1, 0)],
            [(_CROSSING, direction, 0) for direction in range(4)],
            [(_SEGMENT, k, 0) for k in range(len(segment_ends))],
        ]

        def predict(i: int, t: float, exclude: int, direction: int = -1) -> None:
            nonlocal n_pred
            n_pred += 1
            xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
            dti = t - ti
            xi += vxi * dti
            yi += vyi * dti
            block, tile, shift, x_lo, x_hi, y_lo, y_hi, walls, segs, _, _, _ = where[i]
            block = block(tile)
            # 1. The earliest collision with a neighbour.
            partner = kept_partner[i]
            after_crossing = direction >= 0 and (partner < 0 or count[partner] == kept_stamp[i])
            if after_crossing:  # the 3 cells that just became adjacent; the kept collision covers the other 6
                k0, k1, k2 = front[direction]
                near = ((block[k0], shift[k0]), (block[k1], shift[k1]), (block[k2], shift[k2]))
            else:
                near = zip(block, shift)
            best, new_partner = INF, -1
            passes = blocked[group[i]] if filtering else None
            for others, (sx, sy) in near:
                if not others:
                    continue
                ox, oy = sx - xi, sy - yi
                for j in others:
                    if j == i or j == exclude or (filtering and passes[group[j]]):
                        continue
                    xj, yj, vxj, vyj, tj, rj = unpack(disc, j * _RECORD_BYTES)
                    dvx = vxj - vxi
                    dvy = vyj - vyi
                    dtj = t - tj
                    dx = xj + vxj * dtj + ox
                    dy = yj + vyj * dtj + oy
                    b = dx * dvx + dy * dvy
                    if b >= 0.0:
                        continue
                    s = ri + rj
                    cc = dx * dx + dy * dy - s * s
                    if cc <= 0.0:
                        tij = 0.0
                    else:
                        a = dvx * dvx + dvy * dvy
                        d = b * b - a * cc
                        if d <= 0.0:
                            continue
                        tij = cc / (-b + sqrt(d))
                    if tij < best:
                        best, new_partner = tij, j
            if after_crossing:
                t_hit = kept_time[i]
                if t + best < t_hit:
                    t_hit, partner = t + best, new_partner
                    kept_time[i], kept_partner[i], kept_stamp[i] = t_hit, partner, count[partner]
            else:
                t_hit, partner = t + best, new_partner
                kept_time[i], kept_partner[i] = t_hit, partner
                if partner >= 0:
                    kept_stamp[i] = count[partner]
            # 2. The next wall, segment or cell boundary.
            best, kind, other = INF, _CROSSING, 0
            if vxi > 0.0:
                if walls & 2:
                    best, kind = (width - ri - xi) / vxi, _WALL
                else:
                    best, other = (x_hi - xi) / vxi, _PLUS_X
            elif vxi < 0.0:
                if walls & 1:
                    best, kind = (ri - xi) / vxi, _WALL
                else:
                    best, other = (x_lo - xi) / vxi, _MINUS_X
            if vyi > 0.0:
                if walls & 8:
                    ty = (height - ri - yi) / vyi
                    if ty < best:
                        best, kind, other = ty, _WALL, 1
                else:
                    ty = (y_hi - yi) / vyi
                    if ty < best:
                        best, kind, other = ty, _CROSSING, _PLUS_Y
            elif vyi < 0.0:
                if walls & 4:
                    ty = (ri - yi) / vyi
                    if ty < best:
                        best, kind, other = ty, _WALL, 1
                else:
                    ty = (y_lo - yi) / vyi
                    if ty < best:
                        best, kind, other = ty, _CROSSING, _MINUS_Y
            for k in segs:
                if k != -2 - exclude:  # not the segment just left
                    ts = segment_time_of_impact(xi, yi, vxi, vyi, ri, *segment_ends[k])
                    if ts < best:
                        best, kind, other = ts, _SEGMENT, k
            if best < 0.0:
                best = 0.0
            # 3. Schedule the earlier of the two.
            t_best = t + best
            if t_hit <= t_best and partner >= 0:
                push(i, t_hit, (_COLLISION, partner, count[partner]))
            elif best == INF:
                discard(i)
            else:
                push(i, t_best, payloads[kind][other])

        def predictions() -> int:
            return n_pred

        return predict, predictions

    # --- the hot loop ----------------------------------------------------------------
    def _process(self, until: float, limit: int) -> int:
        """Process events with time <= ``until``; stop after ``limit`` physical events (-1: none).

        Returns the number of physical events (collisions plus wall hits) processed.

        Python's cyclic garbage collector is paused meanwhile (and restored as it
        was). The loop allocates millions of short-lived tuples and never a
        reference cycle, yet each allocation burst triggers a collection that walks
        what those tuples point at: memory scattered over the whole system, so at
        N = 10^5 the collections cost 10-15% of the run (same-process A/B, none
        at 10^3).
        """
        if not gc.isenabled():
            return self._process_open(limit) if until == INF else self._process_events(until, limit, -1)
        gc.disable()
        try:
            return self._process_open(limit) if until == INF else self._process_events(until, limit, -1)
        finally:
            gc.enable()

    def _process_open(self, limit: int) -> int:
        """:meth:`_process` with no time limit: also stop when no disc can ever hit anything again.

        In a periodic box, discs that never meet cross cells forever. The hot
        loop therefore returns after ``budget`` cell crossings in a row of
        calls; when a whole budget passed without a collision or wall hit,
        :meth:`_never_again` looks for a proof that none will ever come, and
        the budget doubles if it finds none (so the check costs O(log) calls).
        When it finds one, ``time`` goes back to the last collision or wall hit
        (or to where the call started): the crossings after it changed nothing.
        """
        done, start = 0, self.time
        budget = 64 + 16 * len(self.discs)
        while True:
            crossings = self._counts["cell_crossings"]
            k = self._process_events(INF, limit - done if limit >= 0 else -1, budget)
            done += k
            if done == limit or self._counts["cell_crossings"] - crossings < budget:
                return done  # the event limit, or nothing left in the queue
            if k == 0:
                if self._never_again():
                    self.time = self._last[0] if done else start
                    return done
                budget *= 2

    def _never_again(self) -> bool:
        """True if, from now on, no pair of discs can ever meet and no disc hits a wall or segment.

        Only periodic boxes (a moving disc always reaches a wall). A pair can
        never meet when its relative velocity is exactly zero, when its groups
        pass through each other, or when it moves relative to itself only along
        x (or only along y) and its minimum-image gap across that motion exceeds
        the contact distance. Any other pair might meet some day, and the answer is False.
        """
        box = self.box
        if not box.periodic or len(self.discs) < 2:
            return box.periodic or not self.velocities.any()
        pos, vel, radii = self.positions, self.velocities, self.discs.radii
        groups = self.discs.groups
        size = np.array([box.width, box.height])
        for i in range(len(pos) - 1):
            dv = vel[i + 1 :] - vel[i]
            still = (dv == 0.0).all(axis=1)
            if self.pass_through:
                a, b = np.minimum(groups[i], groups[i + 1 :]), np.maximum(groups[i], groups[i + 1 :])
                still |= np.array([(g, h) in self.pass_through for g, h in zip(a.tolist(), b.tolist())], dtype=bool)
            gap = pos[i + 1 :] - pos[i]
            gap -= size * np.round(gap / size)
            reach = (radii[i] + radii[i + 1 :]) * (1.0 + 1e-9) + 1e-12 * size.max()
            along_y = (dv[:, 0] == 0.0) & (np.abs(gap[:, 0]) > reach)  # x gap fixed for good
            along_x = (dv[:, 1] == 0.0) & (np.abs(gap[:, 1]) > reach)
            if not (still | along_y | along_x).all():
                return False
        return True

    def _process_events(self, until: float, limit: int, crossings: int) -> int:
        """The body of :meth:`_process`; also returns after ``crossings`` cell crossings (-1: no such limit)."""
        queue = self._queue
        pop_before = queue.pop_before
        predict = self._predict
        disc, unpack, pack = self._disc, _RECORD.unpack_from, _RECORD.pack_into
        count, mass, one_mass = self._count, self._mass, self._one_mass
        where, info, grid = self._where, self._cell_info, self.grid
        nx, ny = grid.nx, grid.ny
        width, height, periodic = self.box.width, self.box.height, self.box.periodic
        log = self._log if self.record else None
        caller = self._caller_id  # the caller's numbering, for the log
        counts = self._counts
        segment_ends = [(*seg.p0.tolist(), *seg.p1.tolist()) for seg in self.segments]
        n_coll = n_wall = n_cross = n_stale = 0
        done = 0
        max_queue = self.max_queue
        now, last, virial = None, None, self._virial
        sqrt, max_overlap = math.sqrt, self.max_overlap
        # Internal times run from the epoch, which moves every REBASE_EVERY physical events.
        epoch = self._epoch
        horizon = until - epoch
        rebase_at = self._rebase_every - self._since_rebase
        while done != limit:
            popped = pop_before(horizon)
            if popped is None:
                break
            t, i, (kind, other, stamp) = popped
            if kind == _COLLISION:
                j = other
                if count[j] != stamp:  # the partner has changed course since the prediction
                    n_stale += 1
                    predict(i, t, -1)
                    continue
                # Advance the two discs to the contact.
                xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                dt = t - ti
                xi += vxi * dt
                yi += vyi * dt
                xj, yj, vxj, vyj, tj, rj = unpack(disc, j * _RECORD_BYTES)
                dt = t - tj
                xj += vxj * dt
                yj += vyj * dt
                dx, dy = xj - xi, yj - yi
                if periodic:
                    dx -= width * round(dx / width)
                    dy -= height * round(dy / height)
                overlap = 1.0 - sqrt(dx * dx + dy * dy) / (ri + rj)
                if overlap > max_overlap:
                    max_overlap = overlap
                if one_mass is None:
                    mi, mj = mass[i], mass[j]
                else:
                    mi = mj = one_mass
                uxi, uyi, uxj, uyj = resolve_collision(dx, dy, vxi, vyi, vxj, vyj, mi, mj)
                pack(disc, i * _RECORD_BYTES, xi, yi, uxi, uyi, t, ri)
                pack(disc, j * _RECORD_BYTES, xj, yj, uxj, uyj, t, rj)
                virial -= mi * ((uxi - vxi) * dx + (uyi - vyi) * dy)  # owners are never obstacles
                count[i] += 1
                n_coll += 1
                done += 1
                if log is not None:
                    log.collision(t + epoch, caller[i], caller[j], xi, yi, uxi, uyi, xj, yj, uxj, uyj)
                predict(i, t, j)
                if mj != INF:  # obstacles never move, and their counter never changes
                    count[j] += 1
                    predict(j, t, i)
                    # Only here can the queue grow (j's slot may have been empty); other
                    # events pop their owner's event and push at most one back.
                    size = len(queue)
                    if size > max_queue:
                        max_queue = size
                last = (t + epoch, _COLLISION, i, j)
            elif kind == _WALL:
                xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                dt = t - ti
                xi += vxi * dt
                yi += vyi * dt
                if other == 0:
                    vxi = -vxi
                else:
                    vyi = -vyi
                pack(disc, i * _RECORD_BYTES, xi, yi, vxi, vyi, t, ri)
                count[i] += 1
                n_wall += 1
                done += 1
                if log is not None:
                    log.wall(t + epoch, caller[i], xi, yi, vxi, vyi)
                predict(i, t, -1)
                last = (t + epoch, _WALL, i, -1)
            elif kind == _SEGMENT:
                xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                dt = t - ti
                xi += vxi * dt
                yi += vyi * dt
                vxi, vyi = reflect_off_segment(xi, yi, vxi, vyi, *segment_ends[other])
                pack(disc, i * _RECORD_BYTES, xi, yi, vxi, vyi, t, ri)
                count[i] += 1
                n_wall += 1
                done += 1
                if log is not None:
                    log.wall(t + epoch, caller[i], xi, yi, vxi, vyi)
                predict(i, t, -2 - other)  # never the same segment again straight away
                last = (t + epoch, _WALL, i, -1)
            else:  # cell crossing: the trajectory is unchanged, only the neighbourhood
                here = where[i]
                tile, slot = here[1], here[_SLOT]
                others = tile[slot]
                if len(others) == 1:
                    others = ()
                else:
                    k = others.index(i)
                    others = others[:k] + others[k + 1 :]
                tile[slot] = others
                for tile, slot in here[_GHOSTS]:  # the copies in the rings of neighbouring tiles
                    tile[slot] = others
                cx, cy = divmod(here[_CELL_INDEX], ny)
                if other == _PLUS_X:
                    cx += 1
                    if cx == nx:
                        cx = 0
                        xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                        pack(disc, i * _RECORD_BYTES, xi - width, yi, vxi, vyi, ti, ri)
                elif other == _MINUS_X:
                    cx -= 1
                    if cx < 0:
                        cx = nx - 1
                        xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                        pack(disc, i * _RECORD_BYTES, xi + width, yi, vxi, vyi, ti, ri)
                elif other == _PLUS_Y:
                    cy += 1
                    if cy == ny:
                        cy = 0
                        xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                        pack(disc, i * _RECORD_BYTES, xi, yi - height, vxi, vyi, ti, ri)
                else:
                    cy -= 1
                    if cy < 0:
                        cy = ny - 1
                        xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                        pack(disc, i * _RECORD_BYTES, xi, yi + height, vxi, vyi, ti, ri)
                here = where[i] = info[cx * ny + cy]
                tile, slot = here[1], here[_SLOT]
                others = tile[slot] + (i,)
                tile[slot] = others
                for tile, slot in here[_GHOSTS]:
                    tile[slot] = others
                n_cross += 1
                predict(i, t, -1, other)
                if n_cross == crossings:
                    now = t
                    break
            now = t
            if done >= rebase_at:
                self._rebase(now)
                epoch, now = self._epoch, 0.0
                horizon = until - epoch
                rebase_at = done + self._rebase_every
        self._since_rebase = self._rebase_every - (rebase_at - done)
        self.max_queue = max_queue
        self._virial, self.max_overlap = virial, max_overlap
        if now is not None:
            self.time = now + epoch
        if last is not None:
            self._last = last
        counts["collisions"] += n_coll
        counts["wall_hits"] += n_wall
        counts["cell_crossings"] += n_cross
        counts["stale"] += n_stale
        return done

    def _rebase(self, shift: float) -> None:
        """Move the epoch of the internal clock forward by ``shift`` (the current internal time).

        Positions are ``r + v (t - t_ref)`` with times measured from the epoch;
        keeping those times small keeps their resolution, and so the contact
        geometry, at the roundoff of the first steps of the run however long
        it goes on. O(N log N); the hot loop calls it every ``_rebase_every``
        physical events, a count that does not depend on how a run is split.
        """
        records = np.frombuffer(self._disc, dtype=np.float64).reshape(-1, 6)  # a view: edits in place
        records[:, 4] -= shift
        self._kept_time[:] = [t - shift for t in self._kept_time]
        self._queue.shift_times(shift)
        self._epoch += shift

    # --- invariants ------------------------------------------------------------------
    def _check(self) -> None:
        """Assert every internal invariant; O(N). Called by the stress tests after each step."""
        self._queue._check()
        n = len(self.discs)
        assert len(self._queue) <= n
        cells = self._cell_members()
        assert len(cells) == len(self.grid)
        for here in self._cell_info:
            members = here[1][here[_SLOT]]
            assert all(tile[slot] is members for tile, slot in here[_GHOSTS]), "a ghost copy is out of date"
        seen = sorted(j for members in cells for j in members)
        assert seen == list(range(n)), "every disc is in exactly one cell"
        pos = self.positions[self._order]  # in the internal numbering
        expected = self.grid.cells_of(pos)
        grid = self.grid
        for i in range(n):
            c = self._where[i][_CELL_INDEX]
            assert i in cells[c]
            if expected[i] != c:  # only allowed on a cell boundary, within roundoff
                cx, cy = divmod(c, grid.ny)
                x, y = pos[i]
                tol = 1e-9 * max(grid.lx, grid.ly)
                inside_x = cx * grid.lx - tol <= x <= (cx + 1) * grid.lx + tol or (
                    self.box.periodic and (x < tol or x > self.box.width - tol)
                )
                inside_y = cy * grid.ly - tol <= y <= (cy + 1) * grid.ly + tol or (
                    self.box.periodic and (y < tol or y > self.box.height - tol)
                )
                assert inside_x and inside_y, f"disc {i} at {pos[i]} is not in its cell {c}"
            t_pending, payload = self._queue.pending(i)
            assert t_pending >= self.time - self._epoch - 1e-12 * max(1.0, self.time)
            if self._moving[i] and (self._records()[i, 2] or self._records()[i, 3]):
                assert payload is not None or t_pending == INF
        check_fits(Discs(self.positions, self.velocities, self.discs.radii, self.discs.masses), self.box)


def _internal_order(grid: CellGrid, positions: np.ndarray) -> np.ndarray:
    """The internal numbering of the discs: tile by tile of ``_TILE`` x ``_TILE`` cells.

    Discs are sorted by tile, then by cell within the tile (stable, so the
    caller's order stands within a cell). Neighbours then have nearby numbers,
    and their records, counters and kept collisions share cache lines and
    pages: at N = 10^5 the caller's order can cost up to 10% (a shuffled
    gas) against this one. Returns ``order``, ``(N,)``: internal disc k is
    the caller's disc ``order[k]``.
    """
    if not len(positions):
        return np.zeros(0, dtype=np.int64)
    cx, cy = np.divmod(grid.cells_of(positions), grid.ny)
    tiles_y = -(-grid.ny // _TILE)
    tile = (cx // _TILE) * tiles_y + cy // _TILE
    key = (tile * _TILE + cx % _TILE) * _TILE + cy % _TILE
    return np.argsort(key, kind="stable").astype(np.int64)


def _tile_cells(grid: CellGrid, members: list[tuple[int, ...]], periodic: bool):
    """Cut the table of cell members into tiles of ``_TILE`` x ``_TILE`` cells with a ring of ghost cells.

    A prediction fetches the member tuples of the 3x3 block of cells around a
    disc. From one table of all cells, with an ``itemgetter`` per cell over 9
    global indices, that reads the getter, its 9 index ints and 3 stretches of
    the table, far apart at large N: 10 cache misses or so before the first
    neighbour. A tile instead holds its cells and a ring of copies (ghosts) of
    the cells around it, so every block lies in one tile, and the getters, one
    per position in a tile and shared by all tiles, index with small ints that
    stay in cache. A wall leaves its ghost slots empty; a periodic box fills
    them from the opposite side. A cell's tuple is replaced in its own slot
    and in every ghost copy at once (36% of cells have copies, in 1 to 3 other tiles).

    Args:
        grid: the cell grid.
        members: the discs in each cell, indexed as the grid's cells.
        periodic: whether the box wraps around.

    Returns:
        ``(blocks, tiles, slots, ghosts)``, lists indexed by cell: the getter that
        fetches the cell's 3x3 block from its tile (in the order of
        ``grid.shifts``), the tile (a list), the cell's slot in it, and a tuple of
        ``(tile, slot)`` pairs, the cell's ghost copies.
    """
    nx, ny, size = grid.nx, grid.ny, _TILE + 2
    n_cells = nx * ny
    blocks: list = [None] * n_cells
    tiles: list = [None] * n_cells
    slots = [0] * n_cells
    ghosts: list[list] = [[] for _ in range(n_cells)]
    getters: dict[tuple[int, int], itemgetter] = {}
    for x0 in range(0, nx, _TILE):
        for y0 in range(0, ny, _TILE):
            w, h = min(_TILE, nx - x0), min(_TILE, ny - y0)
            tile = [()] * (size * size)
            for lx in range(w + 2):
                for ly in range(h + 2):
                    cx, cy = x0 + lx - 1, y0 + ly - 1
                    if periodic:
                        cx, cy = cx % nx, cy % ny
                    elif not (0 <= cx < nx and 0 <= cy < ny):
                        continue  # beyond a wall: always empty
                    c, slot = cx * ny + cy, lx * size + ly
                    tile[slot] = members[c]
                    if 1 <= lx <= w and 1 <= ly <= h:  # the cell's own slot
                        if (lx, ly) not in getters:
                            near = [(lx + dx) * size + ly + dy for dx in (-1, 0, 1) for dy in (-1, 0, 1)]
                            getters[lx, ly] = itemgetter(*near)
                        blocks[c], tiles[c], slots[c] = getters[lx, ly], tile, slot
                    else:
                        ghosts[c].append((tile, slot))
    return blocks, tiles, slots, [tuple(copies) for copies in ghosts]


def _is_count(value) -> bool:
    """True for a whole number >= 0 (an int, or a float such as 5.0); False for bools, NaN and the rest."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        return False
    return math.isfinite(value) and value >= 0 and int(value) == value


def _pack_records(x, y, vx, vy, t_ref, radius) -> bytearray:
    """The state buffer of per-disc records from ``(N,)`` arrays, one per field."""
    return bytearray(np.column_stack([x, y, vx, vy, t_ref, radius]).astype(np.float64).tobytes())
