"""Event-chain Monte Carlo as an engine: :class:`EventChain` (straight ECMC, Bernard, Krauth & Wilson 2009).

A second event-driven algorithm beside molecular dynamics: it samples the *canonical* ensemble of hard discs
(no velocities, no kinetic energy) by chains of moves, each exact to the contact, and measures the pressure
from its lifts. The driver runs it as any engine (``run(chains=k)``, progress, observers, checkpoints, Ctrl-C
after the batch of chains under way). The chains are :mod:`.loop`, compiled by numba (:mod:`.compiled`) or run
in pure Python on lists, the same events bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from discsim import _numba
from discsim._interrupt import deferred_interrupt
from discsim.cells import cell_lists, flat_cells, grid_shape
from discsim.engines.base import Engine, EngineState, register_engine
from discsim.engines.editing import Uneditable
from discsim.engines.event_chain import loop
from discsim.errors import CheckpointError, InvalidArgumentError
from discsim.model import Box, Discs, _readonly
from discsim.scene import Scene

__all__ = ["LIFT_DTYPE", "EventChain", "EventChainState"]

#: A lift of the log (``record_lifts=True``): the chain, its direction (0: +x, 1: +y), the disc that stops (``i``)
#: and the one that takes the move on (``j``), ``i``'s centre at the contact and the two centres' separation along
#: the chain.
LIFT_DTYPE = np.dtype(
    [("chain", "i8"), ("direction", "i1"), ("i", "i8"), ("j", "i8"), ("x", "f8"), ("y", "f8"), ("separation", "f8")]
)
#: Chains drawn per block of the random stream: chain ``k`` starts from block ``k // BLOCK``'s draw, so the
#: chains are the same however a run is cut into calls (and after a checkpoint).
BLOCK = 4096


@dataclass
class EventChainState(EngineState):
    """The run state of an :class:`EventChain`: everything it needs to go on bit for bit.

    Attributes:
        positions: ``(N, 2)`` centres, as the chains leave them (in the box, or on its far edge by roundoff).
        images: ``(N, 2)`` int64 times each crossed the periodic edges (unwrapped centres are
            ``positions + images * box.size``). cells: ``(N,)`` int64 each disc's cell, as the chains left it
            (a disc moved to a cell's edge belongs to the cell it entered).
        chains, lifts, crossings: counts. separation: the sum over the lifts of the two centres' separation
            along the chain (length), the pressure's estimator.
        lift_log: ``(L,)`` of :data:`LIFT_DTYPE`: every lift so far when the engine records them, else empty.
    """

    positions: np.ndarray
    images: np.ndarray
    cells: np.ndarray
    chains: int
    lifts: int
    crossings: int
    separation: float
    lift_log: np.ndarray


@register_engine
class EventChain(Uneditable, Engine):
    """Straight event-chain Monte Carlo of hard discs in a periodic box: the canonical ensemble, exactly.

    Each chain picks a disc at random and moves it along +x (chains alternate +x and +y) until it would touch
    another disc; that disc takes over the move for what is left of the chain's length, and so on, for a total
    displacement of ``chain_length``. Every move is exact to the contact (no overlap, no step size), every
    configuration of the discs is sampled with the same weight (Bernard, Krauth & Wilson, PRE 80, 056704
    (2009)), and nothing stands for time: ``time`` counts chains. The pressure comes from the lifts
    (Michel, Kapfer & Krauth, J. Chem. Phys. 140, 054116 (2014)): ``beta P A / N = 1 + S / (C ell)`` with ``S``
    the sum over the lifts of the two centres' separation along the chain, ``C`` the chains and ``ell`` their
    length (:meth:`compressibility_factor`, :meth:`pressure` in units of ``kT = 1``).

    Args:
        discs: the start (no overlaps; velocities and masses are not used: a Monte Carlo has neither).
        box: a periodic box (walls and segments are not supported), at least 3 largest diameters a side.
        chain_length: the displacement of each chain (length; default half the box's shorter side).
        seed: the seed of the random starts (None: one drawn from the operating system, kept in checkpoints).
        backend: ``"auto"`` (numba when it imports), ``"numba"`` or ``"python"``: the same chains bit for bit.
        record_lifts: keep every lift (:attr:`lifts`: 49 bytes a lift, some hundreds a chain in a dense
            liquid; in checkpoints too).

    Raises:
        InvalidArgumentError: a walled box, a chain length that is not positive and finite, a bad seed.
        OverlapError, OutsideBoxError, BoxTooSmallError: discs that do not fit, as ``EventDriven`` refuses.

    Example:
        >>> import discsim as ds
        >>> discs, box = ds.random_gas(100, 0.3, seed=1)
        >>> mc = ds.EventChain(discs, box, seed=2, backend="python").run(chains=500)
        >>> mc.counts["chains"], 1.5 < mc.compressibility_factor() < 2.3
        (500, True)
    """

    unit: ClassVar[str] = "chains"
    rate_count: ClassVar[str] = "lifts"
    progress_chunk: ClassVar[int] = 2000
    STATE = EventChainState
    EDIT_REFUSAL: ClassVar[str] = "start a new one from sim.snapshot() instead"

    def __init__(
        self,
        discs: Discs,
        box: Box,
        *,
        chain_length: float | None = None,
        seed: int | None = None,
        backend: str = "auto",
        record_lifts: bool = False,
    ):
        if not isinstance(box, Box) or not box.periodic:
            msg = f"EventChain runs in a periodic box only (walls and segments are not supported), got {box!r}"
            raise InvalidArgumentError(msg)
        if chain_length is None:
            chain_length = 0.5 * min(box.width, box.height)
        if (
            isinstance(chain_length, bool)
            or not isinstance(chain_length, (int, float, np.integer, np.floating))
            or not 0.0 < chain_length < math.inf
        ):
            msg = f"chain_length must be a positive, finite length, got {chain_length!r}"
            raise InvalidArgumentError(msg)
        if seed is None:
            seed = int(np.random.default_rng().integers(2**62))
        elif isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            msg = f"seed must be a non-negative integer or None, got {seed!r}"
            raise InvalidArgumentError(msg)
        if not isinstance(record_lifts, (bool, np.bool_)):
            msg = f"record_lifts must be True or False, got {record_lifts!r}"
            raise InvalidArgumentError(msg)
        settings: dict[str, Any] = {
            "record_lifts": bool(record_lifts),
            "chain_length": float(chain_length),
            "seed": int(seed),
            "backend": _numba.resolve_backend(backend, ("python", "numba"), "EventChain"),
        }
        self._configure(Scene(discs, box), settings)
        positions = box.wrap(np.array(discs.positions, dtype=float))
        nx, ny = self._grid
        cells = flat_cells(positions, nx, ny, box.width / nx, box.height / ny)
        self._state = EventChainState(
            positions, np.zeros((len(discs), 2), dtype=np.int64), cells, 0, 0, 0, 0.0, np.zeros(0, dtype=LIFT_DTYPE)
        )

    def _configure(self, scene: Scene, settings: dict) -> None:
        super().__init__(scene, record=False)
        self.settings = settings
        self.backend = settings["backend"]
        self.chain_length = settings["chain_length"]
        self.seed = settings["seed"]
        self.record_lifts = bool(settings.get("record_lifts", False))
        radii = np.asarray(scene.discs.radii, dtype=float)
        self._grid = grid_shape(scene.box, 2.0 * float(radii.max()), max(4 * len(radii), 64))

    # --- where it stands ---------------------------------------------------------------------------
    @property
    def time(self) -> float:  # type: ignore[override]
        """Chains run so far (a Monte Carlo has no physical time)."""
        return float(self._state.chains)

    @time.setter
    def time(self, value: float) -> None:
        if value != self._state.chains:
            msg = "an event chain's clock counts chains; run it with run(chains=...)"
            raise InvalidArgumentError(msg)

    @property
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres now (in the box)."""
        return _readonly(self.box.wrap(self._state.positions))

    @property
    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres now, each disc followed across the periodic edges."""
        return _readonly(self._state.positions + self._state.images * self.box.size)

    @property
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` zeros: a Monte Carlo moves discs without velocities."""
        return _readonly(np.zeros((len(self.discs), 2)))

    @property
    def counts(self) -> dict[str, int]:
        """``chains``, ``lifts`` (a disc passing the move on) and ``cell_crossings`` so far."""
        s = self._state
        return {"chains": s.chains, "lifts": s.lifts, "cell_crossings": s.crossings}

    @property
    def lifts(self) -> np.ndarray:
        """``(L,)`` every lift so far, of :data:`LIFT_DTYPE` (a read-only copy).

        Raises:
            InvalidArgumentError: if the engine was built without ``record_lifts=True``.
        """
        if not self.record_lifts:
            msg = "lifts needs the lift log: build the EventChain with record_lifts=True"
            raise InvalidArgumentError(msg)
        return _readonly(self._state.lift_log.copy())

    def compressibility_factor(self) -> float:
        """``beta P A / N`` from the lifts of every chain so far: ``1 + S / (C ell)`` (see the class docstring).

        Raises:
            InvalidArgumentError: before the first chain.
        """
        s = self._state
        if s.chains == 0:
            msg = "compressibility_factor() needs at least one chain: run(chains=...) first"
            raise InvalidArgumentError(msg)
        return 1.0 + s.separation / (s.chains * self.chain_length)

    def pressure(self) -> float:
        """``beta P`` (per area, ``kT = 1``): ``N / A`` times :meth:`compressibility_factor`."""
        return len(self.discs) / self.box.area * self.compressibility_factor()

    # --- the driver's protocol -------------------------------------------------------------------------
    def _advance(self, until: float, limit: int | None) -> int:
        """Run ``limit`` chains (``until`` is inf: a run takes no stop time), in batches Ctrl-C can stop between."""
        if limit is None:
            msg = "an event chain runs a number of chains: run(chains=...)"
            raise InvalidArgumentError(msg)
        done = 0
        with deferred_interrupt() as interrupted:
            while done < limit and not interrupted[0]:
                count = min(limit - done, BLOCK - self._state.chains % BLOCK)
                self._chains(count)
                done += count
        return done

    def _units(self) -> int:
        return self._state.chains

    def _event_count(self) -> int:
        return 0

    def step(self) -> dict[str, int]:
        """Run one chain; returns :attr:`counts`."""
        self._check_usable()
        self._advance(math.inf, 1)
        return self.counts

    def run(self, until=None, *, chains=None, events=None, observers=(), progress=False, record_to=None,
            checkpoint=None, checkpoint_every=None):  # fmt: skip
        """Run ``chains`` more chains; see :func:`discsim.run.driver.drive` (``events`` is another name for it).

        Raises:
            InvalidArgumentError: ``until`` or ``record_to`` given (no time, no event log), no count, or
                ``chains`` and ``events`` both given.
        """
        chains = self._count_only(
            until, chains, events, record_to, "chains", "an event chain has no physical time",
            "an event chain keeps no event log",
        )  # fmt: skip
        return super().run(
            None, events=chains, observers=observers, progress=progress, checkpoint=checkpoint,
            checkpoint_every=checkpoint_every,
        )  # fmt: skip

    def _chains(self, count: int) -> None:
        """Run ``count`` chains within one block of the random stream; the state is replaced at the end."""
        s = self._state
        n = len(self.discs)
        block, offset = divmod(s.chains, BLOCK)
        starts = np.random.default_rng([self.seed, block]).integers(0, n, size=BLOCK)[offset : offset + count]
        box, (nx, ny) = self.box, self._grid
        cw, ch = box.width / nx, box.height / ny
        positions, cells = s.positions, s.cells
        head, nxt, prv = cell_lists(cells, nx * ny)
        if self.backend == "numba":
            from discsim.engines.event_chain import compiled

            run_chains = compiled.run_chains

            def floats(a):
                return np.array(a, dtype=np.float64)

            def ints(a):
                return np.array(a, dtype=np.int64)
        else:  # plain lists: the pure-Python loop indexes them 3-5x faster than numpy arrays
            run_chains = loop.run_chains

            def floats(a):
                return [float(v) for v in a]

            def ints(a):
                return [int(v) for v in a]

        room = 0
        if self.record_lifts:  # room for the lifts the chains so far suggest; too little, and the batch runs again
            per_chain = s.lifts / s.chains if s.chains else 64.0
            room = max(1024, int(1.25 * per_chain * count) + 64)
        while True:
            x, y = floats(positions[:, 0]), floats(positions[:, 1])
            ix, iy = ints(s.images[:, 0]), ints(s.images[:, 1])
            out, iout, cell = floats([s.separation]), ints([0, 0, 0]), ints(cells)
            log = (ints(np.zeros(room)), ints(np.zeros(room)), ints(np.zeros(room)), floats(np.zeros(room)),
                   floats(np.zeros(room)), floats(np.zeros(room)))  # fmt: skip
            run_chains(
                x, y, floats(self.discs.radii), ix, iy, cell, ints(head), ints(nxt), ints(prv), ints(starts),
                floats([box.width, box.height, cw, ch, self.chain_length]), ints([nx, ny, s.chains % 2, s.chains]),
                out, iout, *log,
            )  # fmt: skip
            if int(iout[2]) <= room or not self.record_lifts:
                break
            room = int(iout[2])  # the same chains again (the state is untouched), with room for every lift
        lift_log = s.lift_log
        if self.record_lifts:
            new = np.zeros(int(iout[2]), dtype=LIFT_DTYPE)
            k = len(new)
            for name, column in zip(("chain", "i", "j", "x", "y", "separation"), log):
                new[name] = np.asarray(column)[:k]
            new["direction"] = new["chain"] % 2
            lift_log = np.concatenate([lift_log, new])
        self._state = EventChainState(
            np.column_stack([np.asarray(x, dtype=float), np.asarray(y, dtype=float)]),
            np.column_stack([np.asarray(ix, dtype=np.int64), np.asarray(iy, dtype=np.int64)]),
            np.asarray(cell, dtype=np.int64), s.chains + count, s.lifts + int(iout[0]),
            s.crossings + int(iout[1]), float(out[0]), lift_log,
        )  # fmt: skip

    # --- the checkpoint's protocol ------------------------------------------------------------------
    def state(self) -> EventChainState:
        s = self._state
        return EventChainState(
            s.positions.copy(),
            s.images.copy(),
            s.cells.copy(),
            s.chains,
            s.lifts,
            s.crossings,
            s.separation,
            s.lift_log.copy(),
        )

    def _settings(self) -> dict:
        return dict(self.settings)

    @classmethod
    def _restore(cls, scene, settings, state, events, start_time) -> EventChain:
        sim = cls.__new__(cls)
        settings = {k: v for k, v in settings.items() if k != "record"}
        settings["backend"] = _numba.resolve_backend(settings.get("backend", "auto"), ("python", "numba"), "load")
        sim._configure(scene, settings)
        n = len(scene)
        cells = np.asarray(state.cells, dtype=np.int64)
        if np.shape(state.positions) != (n, 2) or np.shape(state.images) != (n, 2) or cells.shape != (n,):
            msg = f"the state's positions {np.shape(state.positions)}, images or cells are not those of {n} discs"
            raise CheckpointError(msg)
        if len(cells) and not (0 <= cells.min() and cells.max() < sim._grid[0] * sim._grid[1]):
            msg = f"the state's cells run outside the grid of {sim._grid[0]} x {sim._grid[1]}"
            raise CheckpointError(msg)
        sim._state = EventChainState(
            np.asarray(state.positions, dtype=float), np.asarray(state.images, dtype=np.int64), cells,
            int(state.chains),
            int(state.lifts), int(state.crossings), float(state.separation),
            np.asarray(state.lift_log).astype(LIFT_DTYPE),
        )  # fmt: skip
        return sim
