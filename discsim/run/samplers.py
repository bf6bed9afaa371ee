"""Samplers: observers that measure a run as it goes, so a long run need not keep its event log.

:class:`Sampler` takes the exact state of every disc every ``dt`` of simulated time, and gathers the
collision virial in blocks (for :func:`discsim.thermo`) and, if asked, the free times between collisions
(for :func:`discsim.free_times`). :class:`GSDWriter` is a sampler that writes each frame to a GSD file.

How a sample is exact: the driver runs the engine in chunks of events and hands each chunk's events to
the observers (the engine records them meanwhile, even with ``record=False``, and forgets them after the
chunk). The sampler keeps the state at the end of the previous chunk (unwrapped positions, velocities,
time); the sample times inside the chunk are rebuilt from that state and the chunk's events, exactly as
``sim.trajectory`` rebuilds them from the whole log (:func:`discsim.analysis.frames.states_at`). The
engine's own stops are not changed, so a sampled run gives the same events, bit for bit, as one without.
"""

from __future__ import annotations

from typing import cast

import numpy as np

from discsim._validate import positive_finite
from discsim.analysis.dynamics import free_times_of
from discsim.analysis.frames import Frames, states_at
from discsim.analysis.thermo import VirialBlocks, kinetic_temperature
from discsim.errors import InvalidArgumentError
from discsim.events import ADD, REMOVE
from discsim.model import frame_count
from discsim.run.observers import Observer

__all__ = ["GSDWriter", "Sampler"]

#: Events per chunk while sampling: bounds the log held at once (about 90 bytes an event).
SAMPLE_CHUNK = 16_384


class Sampler(Observer):
    """Samples the exact state every ``dt`` of simulated time during a run; gathers the virial and free times.

    Samples fall at ``t0, t0 + dt, t0 + 2 dt, ...``, ``t0`` the engine's time when the sampler first sees it
    (the run's start). The same sampler can follow one engine over several ``run()`` calls; it refuses
    another engine, or an engine that moved (``step()``) while it was not looking.

    Args:
        dt: simulated time between samples (positive). The virial blocks are ``dt / 8`` long (they merge in
            pairs beyond 65,536 blocks), so :func:`discsim.thermo` rounds ``since`` up to a multiple of that.
        keep: keep every frame in memory (:attr:`frames`); False keeps none (use ``fn``, or only the
            virial and free times).
        fn: called as ``fn(frames)`` with each new sample (a one-frame :class:`~discsim.analysis.frames.Frames`).
        free_times: collect the free times between collisions (one float per collision: memory grows with
            the run). walls: count wall hits as collisions for the free times.

    Attributes:
        frames: the samples so far (:class:`~discsim.analysis.frames.Frames`), or None before any.
        virial_blocks: the virial and collisions in blocks (:class:`~discsim.analysis.thermo.VirialBlocks`).

    Example:
        >>> import discsim as ds
        >>> sampler = ds.Sampler(dt=0.5)
        >>> sim = ds.EventDriven(*ds.random_gas(100, 0.4, seed=1), record=False)
        >>> _ = sim.run(until=2.0, observers=[sampler])
        >>> sampler.frames.times.tolist(), sampler.frames.unwrapped.shape
        ([0.0, 0.5, 1.0, 1.5, 2.0], (5, 100, 2))
    """

    wants_events = True

    def __init__(self, dt, *, keep: bool = True, fn=None, free_times: bool = False, walls: bool = False):
        self.dt = positive_finite("dt", dt)
        if fn is not None and not callable(fn):
            msg = f"fn must be a callable fn(frames), got {type(fn).__name__}"
            raise InvalidArgumentError(msg)
        self.keep = bool(keep)
        self.fn = fn
        self.free_time_walls = bool(walls)
        self._collect_free = bool(free_times)
        self._parts: list[Frames] = []
        # None until start() (the first run): update() and _sample() come only after it.
        self._engine_id: int | None = None
        self._origin: float | None = None
        self._next = 0  # index of the next sample time
        # (time, unwrapped positions, velocities) where the next chunk starts
        self._state: tuple[float, np.ndarray, np.ndarray] | None = None
        self._units: int | None = None
        self.virial_blocks: VirialBlocks | None = None
        self._free: list[np.ndarray] = []
        self._free_discs: list[np.ndarray] = []
        self._free_starts: list[np.ndarray] = []
        self._last: np.ndarray | None = None

    # --- results --------------------------------------------------------------------------
    @property
    def frames(self) -> Frames | None:
        """The samples so far, or None before any (or with ``keep=False``)."""
        if not self._parts:
            return None
        if len(self._parts) > 1:
            self._parts = [Frames.concatenate(self._parts)]
        return self._parts[0]

    @property
    def free_time_values(self):
        """A function returning ``(times, discs, starts)`` of the free times, or None if not collected."""
        if not self._collect_free:
            return None

        def values():
            if not self._free:
                return np.zeros(0), np.zeros(0, np.int64), np.zeros(0)
            return np.concatenate(self._free), np.concatenate(self._free_discs), np.concatenate(self._free_starts)

        return values

    # --- the observer's protocol ------------------------------------------------------------
    def check(self, engine, plan) -> None:
        if self._engine_id is not None and self._engine_id != id(engine):
            msg = "this Sampler already follows another engine; use one Sampler per engine"
            raise InvalidArgumentError(msg)
        if self._state is not None and (engine.time != self._state[0] or engine._units() != self._units):
            msg = (
                f"this Sampler last saw the engine at t={self._state[0]!r}, and it is now at t={engine.time!r}: "
                "it moved outside run(..., observers=[sampler]) and the sampler missed those events"
            )
            raise InvalidArgumentError(msg)
        if self._state is not None and engine.run_context.structure != self._structure:
            raise InvalidArgumentError(self._changed_message(engine.time))

    @staticmethod
    def _changed_message(time: float) -> str:
        return (
            f"a Sampler follows a fixed set of discs, and discs were added or removed (add_discs / remove_discs) "
            f"at time {time!r}; sample each span between changes with its own Sampler"
        )

    def start(self, engine, plan) -> None:
        self._structure = engine.run_context.structure
        if self._engine_id is None:
            self._engine_id = id(engine)
            self._origin = origin = engine.time
            masses = np.asarray(engine.discs.masses, dtype=float)
            self.virial_blocks = VirialBlocks(
                origin, self.dt / 8, masses, engine.box, engine.kinetic_energy(), kinetic_temperature(engine)
            )
            self._last = np.full(len(engine.discs), np.nan)
        self._state = (engine.time, engine.unwrapped_positions, engine.velocities)
        self._units = engine._units()
        # A sample at this very time waits for the first chunk: events at exactly a sample time count as done.

    def next_stop(self, engine) -> int:
        return SAMPLE_CHUNK

    def update(self, engine, events, done, finishing) -> None:
        changed = np.flatnonzero((events["kind"] == ADD) | (events["kind"] == REMOVE))
        if len(changed):  # a callback changed the discs: the samples after it would be wrong
            raise InvalidArgumentError(self._changed_message(float(events["time"][changed[0]])))
        blocks, last = self.virial_blocks, self._last
        assert blocks is not None and last is not None, "start() comes before update()"
        blocks.add(events, engine.time)
        if self._collect_free:
            times, discs, starts, self._last = free_times_of(events, last, blocks.masses, self.free_time_walls)
            if len(times):
                self._free.append(times)
                self._free_discs.append(discs)
                self._free_starts.append(starts)
        self._sample(engine, events)
        self._state = (engine.time, engine.unwrapped_positions, engine.velocities)
        self._units = engine._units()

    # --- sampling -----------------------------------------------------------------------------
    def sample_times(self, until: float) -> np.ndarray:
        """The sample times not yet taken, up to ``until``."""
        origin = cast(float, self._origin)  # None only before the first run, where this raises TypeError as it did
        last = frame_count(origin, until, self.dt)
        if last < self._next:
            return np.zeros(0)
        k = np.arange(self._next, last + 1)
        return origin + k * self.dt

    def _sample(self, engine, events) -> None:
        assert self._state is not None, "start() comes before update()"
        t0, unwrapped0, velocities0 = self._state
        now = engine.time
        times = self.sample_times(now)
        times = times[times >= t0 - 1e-12 * max(1.0, abs(t0))]
        if not len(times):
            return
        times = np.minimum(times, now)  # roundoff at the chunk's end
        unwrapped, velocities = states_at(events, unwrapped0, velocities0, t0, times, engine.box)
        d = engine.discs
        new = Frames(
            times,
            engine.box.wrap(unwrapped),
            unwrapped,
            velocities,
            engine.box,
            np.array(d.radii, dtype=float),
            np.array(d.masses, dtype=float),
            np.array(d.groups),
        )
        self._next += len(times)
        if self.keep:
            self._parts.append(new)
        if self.fn is not None:
            self.fn(new)
        self.on_frames(new)

    def on_frames(self, new: Frames) -> None:
        """Called with each batch of new samples; subclasses override it (the GSD writer writes them)."""


class GSDWriter(Sampler):
    """Writes the exact state every ``dt`` of simulated time to a GSD file (HOOMD-blue's format), as a run goes.

    Needs the ``gsd`` package (``pip install discsim[io]``). One frame per sample; the file layout is that of
    :func:`discsim.write_gsd`. A file already at ``path`` is refused when the writer starts (nothing is
    overwritten); the same writer continues its own file over several ``run()`` calls.

    Args:
        path: the GSD file to create. dt: simulated time between frames.
    """

    def __init__(self, path, dt):
        from pathlib import Path

        super().__init__(dt, keep=False)
        self.path = Path(path)
        self._file = None
        self._written = 0

    def check(self, engine, plan) -> None:
        super().check(engine, plan)
        from discsim.io.gsd import require_gsd

        require_gsd()
        if self._written == 0 and self._file is None and self.path.exists():
            msg = f"{self.path} already exists; discsim will not overwrite it (choose another path or remove it)"
            raise InvalidArgumentError(msg)
        if not self.path.parent.is_dir():
            msg = f"cannot write the GSD file {self.path}: no folder {self.path.parent}"
            raise FileNotFoundError(msg)

    def start(self, engine, plan) -> None:
        from discsim.io.gsd import open_gsd

        self._file = open_gsd(self.path, "w" if self._written == 0 else "a")
        super().start(engine, plan)

    def on_frames(self, new: Frames) -> None:
        from discsim.io.gsd import append_frames

        self._written = append_frames(self._file, new, self._written)

    def finish(self, engine, completed) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None

    def undo_start(self) -> None:
        if self._written == 0:
            self.path.unlink(missing_ok=True)
