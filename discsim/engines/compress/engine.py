"""Compression as an engine: :class:`Compression` grows the discs epoch by epoch, run by the driver.

The driver (:mod:`discsim.run.driver`) runs it as it runs any engine: ``run()`` to the end, or
``run(epochs=k)``, with a progress bar over the packing, observers and checkpoints between epochs, and
Ctrl-C stopping it after the epoch under way. :func:`compress` is the one-call form: build, run to the end,
return the discs and the report. The event loop of one epoch is :mod:`.loop`, wrapped by :mod:`.epoch`.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from discsim import _numba
from discsim._interrupt import deferred_interrupt
from discsim.cells import grid_shape
from discsim.engines.base import Engine, EngineState, register_engine
from discsim.engines.compress.epoch import epoch, shrink_factor
from discsim.engines.compress.report import DENSEST_PACKING, HISTORY, CompressionReport
from discsim.engines.editing import Uneditable
from discsim.errors import CheckpointError, InvalidArgumentError, PackingError, WrongTypeError
from discsim.model import Box, Discs, _readonly
from discsim.scene import Scene, check_fits

__all__ = ["Compression", "CompressionState", "compress"]

#: Why a compression stopped; "" while it runs.
REASONS = ("", "reached", "jammed", "max_collisions")


@dataclass
class CompressionState(EngineState):
    """The run state of a :class:`Compression` between two epochs: everything it needs to go on bit for bit.

    Attributes:
        positions: ``(N, 2)`` centres where the last epoch left them (wrapped at the next epoch's start).
        shift: ``(N, 2)`` what the wrapping took off so far: unwrapped centres are ``positions + shift``.
        velocities: ``(N, 2)`` velocities where the last epoch left them (before the next thermostat).
        radii: ``(N,)`` radii now. packing: their packing fraction.
        time: simulated time. collisions, walls, epochs: counts. z: the last epoch's reduced pressure.
        seconds: wall-clock seconds spent in epochs. reason: why it stopped (:data:`REASONS`; "" running).
        history: ``(epochs, 5)`` one row per epoch: packing, collisions, seconds, Z, time.
    """

    positions: np.ndarray
    shift: np.ndarray
    velocities: np.ndarray
    radii: np.ndarray
    packing: float
    time: float
    collisions: int
    walls: int
    epochs: int
    z: float
    seconds: float
    reason: str
    history: np.ndarray


@register_engine
class Compression(Uneditable, Engine):
    """Grow all discs until they fill ``packing_fraction`` of the box (Lubachevsky-Stillinger), exactly.

    An engine whose unit of work is a thermostat epoch: ``run()`` goes on to the end (the target, a jam
    or ``max_collisions``), ``run(epochs=k)`` does ``k`` more, ``run(progress=True)`` shows a bar over the
    packing, and ``run(checkpoint=path)`` writes checkpoints between epochs that :func:`discsim.resume`
    continues bit for bit. Ctrl-C stops it after the epoch under way (``ds.Interrupted``), consistent and
    able to go on. :attr:`report` says where it stands; :meth:`snapshot` gives the discs, valid for
    ``EventDriven``, at any point. The discs grow, so there is no event log: ``record_to``, ``trajectory``,
    ``on`` and the disc-editing methods are refused. The physics and the arguments are those of
    :func:`compress`.

    Args:
        discs: the starting discs (as for :func:`compress`, like every argument here).
        box: the box, periodic or walled.
        packing_fraction: the target.
        growth_rate: mean diameter growth per unit time, in thermal speeds.
        seed: seed of new velocities, or None to keep the directions given.
        temperature: kT of the thermostat.
        max_collisions: budget of collisions (None: none).
        max_pressure: the reduced pressure Z taken for jamming.
        epoch_collisions: collisions between two rescalings (default ``2 N``, at least 100).
        backend: ``"auto"``, ``"numba"`` or ``"python"``.

    Example:
        >>> import discsim as ds
        >>> gas, box = ds.random_gas(100, 0.3, seed=1)
        >>> c = ds.Compression(gas, box, 0.6, backend="python")
        >>> c.run(epochs=2).report.reason, c.run().report.reason, round(c.report.packing_fraction, 6)
        ('running', 'reached', 0.6)
    """

    unit: ClassVar[str] = "epochs"
    rate_count: ClassVar[str] = "collisions"
    progress_chunk: ClassVar[int] = 1
    runs_to_end: ClassVar[bool] = True
    STATE = CompressionState
    EDIT_REFUSAL: ClassVar[str] = (
        "the discs grow and no log is kept; compress first, then build an EventDriven from compression.snapshot()"
    )

    def __init__(
        self,
        discs: Discs,
        box: Box,
        packing_fraction: float,
        growth_rate: float = 0.01,
        seed: int | None = None,
        *,
        temperature: float = 1.0,
        max_collisions: int | None = None,
        max_pressure: float = 1e5,
        epoch_collisions: int | None = None,
        backend: str = "auto",
    ):
        if not isinstance(discs, Discs):
            msg = f"discs must be a discsim.Discs, got {type(discs).__name__}"
            raise WrongTypeError(msg)
        if not isinstance(box, Box):
            msg = f"box must be a discsim.Box, got {type(box).__name__}"
            raise WrongTypeError(msg)
        settings: dict[str, Any] = {
            "target": _target(packing_fraction, discs, box),
            "growth_rate": _positive("growth_rate", growth_rate),
            "temperature": _positive("temperature", temperature),
            "max_pressure": _positive("max_pressure", max_pressure),
            "max_collisions": _count("max_collisions", max_collisions),
            "epoch_collisions": _count("epoch_collisions", epoch_collisions) or max(2 * len(discs), 100),
            "backend": _numba.resolve_backend(backend, ("python", "numba"), "compress"),
        }
        masses = np.asarray(discs.masses, dtype=float)
        if not np.isfinite(masses).all():
            i = int(np.flatnonzero(~np.isfinite(masses))[0])
            msg = f"disc {i} has mass {masses[i]!r}: compress moves every disc, so masses must be finite"
            raise InvalidArgumentError(msg)
        check_fits(discs, box)
        self._configure(Scene(discs, box), settings)
        n, temperature = len(discs), settings["temperature"]
        velocities = np.array(discs.velocities, dtype=float)
        if seed is not None or not velocities.any():
            rng = np.random.default_rng(seed)
            velocities = rng.normal(size=(n, 2)) * np.sqrt(temperature / masses)[:, None]
            if n > 1:
                velocities -= (masses[:, None] * velocities).sum(axis=0) / masses.sum()
        positions = np.array(discs.positions, dtype=float)
        radii = np.array(discs.radii, dtype=float)
        self._state = CompressionState(
            positions, np.zeros_like(positions), velocities, radii, self._phi0, 0.0, 0, 0, 0, 1.0, 0.0, "",
            np.zeros((0, 5)),
        )  # fmt: skip

    def _configure(self, scene: Scene, settings: dict) -> None:
        """Set the engine up for ``scene`` and ``settings`` (checked): the cell grid, the fixed quantities."""
        super().__init__(scene, record=False)
        self.settings = settings
        self.backend = settings["backend"]
        discs, box = scene.discs, scene.box
        self._area = box.width * box.height
        self._masses = np.array(discs.masses, dtype=float)
        self._phi0 = math.pi * float(np.sum(np.asarray(discs.radii, dtype=float) ** 2)) / self._area
        final = math.sqrt(settings["target"] / self._phi0)
        self._grid = grid_shape(
            box,
            2.0 * float(np.max(discs.radii)) * final * (1.0 + 1e-9),
            max(4 * len(discs), 64),
            what="the largest contact distance at the target packing",
        )

    # --- where it stands --------------------------------------------------------------------
    @property
    def time(self) -> float:  # type: ignore[override]
        """Simulated time of the compression so far."""
        return self._state.time

    @time.setter
    def time(self, value: float) -> None:  # the driver settles runs with a stop time; compressions have none
        if value != self._state.time:
            msg = "a compression's clock moves only by whole epochs"
            raise InvalidArgumentError(msg)

    @property
    def finished(self) -> bool:
        """True once the compression stopped: the target reached, a jam, or ``max_collisions`` spent."""
        return self._state.reason != ""

    @property
    def radii(self) -> np.ndarray:
        """``(N,)`` radii now (before the final shrink :meth:`snapshot` applies)."""
        return _readonly(self._state.radii.copy())

    def _radii_now(self) -> np.ndarray:
        return self._state.radii

    @property
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres now (wrapped into a periodic box)."""
        p = self._state.positions
        return _readonly(self.box.wrap(p) if self.box.periodic else p.copy())

    @property
    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres now, each disc followed across the edges of a periodic box."""
        return _readonly(self._state.positions + self._state.shift)

    @property
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities now, at the thermostat's ``kT`` (as the next epoch starts them)."""
        return _readonly(self._thermostat(self._state.velocities)[0])

    @property
    def counts(self) -> dict[str, int]:
        """``collisions`` (disc with disc), ``wall_events`` and ``epochs`` so far."""
        s = self._state
        return {"collisions": s.collisions, "wall_events": s.walls, "epochs": s.epochs}

    @property
    def report(self) -> CompressionReport:
        """A :class:`CompressionReport` of the compression so far (``reason`` ``"running"`` until it stops)."""
        s = self._state
        shrink = self._shrink()
        radii = s.radii * shrink
        history = np.zeros(len(s.history), dtype=HISTORY)
        for k, name in enumerate(HISTORY.names or ()):
            history[name] = s.history[:, k]
        return CompressionReport(
            packing_fraction=math.pi * float(np.sum(radii**2)) / self._area,
            target=self.settings["target"],
            reached=s.reason == "reached",
            jammed=s.reason == "jammed",
            reason=s.reason or "running",
            collisions=s.collisions,
            wall_events=s.walls,
            time=s.time,
            seconds=s.seconds,
            z=s.z,
            epochs=s.epochs,
            shrink=shrink,
            backend=self.backend,
            history=history,
        )

    def _shrink(self) -> float:
        """The final shrink of the radii now (:func:`.epoch.shrink_factor`), worked out once per state."""
        s = self._state
        cached = getattr(self, "_shrink_cache", None)
        if cached is None or cached[0] is not s:
            cached = self._shrink_cache = (s, shrink_factor(self.positions, s.radii, self.box))
        return cached[1]

    def snapshot(self) -> Discs:
        """The discs now, valid for ``EventDriven``: radii shrunk past any contact roundoff left a hair inside
        (by the report's ``shrink``), velocities at ``kT`` (same masses and groups)."""
        s, d = self._state, self.discs
        radii = s.radii * self._shrink()
        return Discs(self.positions, self.velocities, radii, d.masses, d.groups)

    # --- the driver's protocol ---------------------------------------------------------------
    def _advance(self, until: float, limit: int | None) -> int:
        """Run up to ``limit`` epochs (None: to the end); ``until`` is inf (runs take no stop time)."""
        done = 0
        with deferred_interrupt() as interrupted:
            while not self.finished and (limit is None or done < limit) and not interrupted[0]:
                self._epoch()
                done += 1
        return done

    def _units(self) -> int:
        return self._state.epochs

    def _event_count(self) -> int:
        return 0

    def step(self) -> CompressionReport:
        """Run one epoch (none once finished) and return the :attr:`report`."""
        self._check_usable()
        self._advance(math.inf, 1)
        return self.report

    def run(
        self,
        until: float | None = None,
        *,
        epochs: int | None = None,
        events: int | None = None,
        observers=(),
        progress: bool = False,
        record_to=None,
        checkpoint=None,
        checkpoint_every: int | None = None,
    ):
        """Run to the end (no arguments) or for ``epochs`` more epochs; see :func:`discsim.run.driver.drive`.

        Args:
            until: not taken: a compression runs by epochs (an epoch cut short would change the result).
            epochs: epochs to run (None: to the end). events: another name for ``epochs`` (:func:`resume`).
            observers, progress, checkpoint, checkpoint_every: as for ``Engine.run`` (``progress`` shows
                the way from the packing at the start to the target; ``checkpoint_every`` counts epochs).
            record_to: not taken: the compression keeps no event log.

        Returns:
            ``self``, so calls chain.

        Raises:
            InvalidArgumentError: ``until`` or ``record_to`` given, ``epochs`` not a whole number >= 0, or
                ``epochs`` and ``events`` both given.
        """
        epochs = self._count_only(
            until, epochs, events, record_to, "epochs", "a compression runs by epochs, not to a time (or to its end)",
            "a compression keeps no event log (the discs grow)",
        )  # fmt: skip
        return super().run(
            None,
            events=epochs,
            observers=observers,
            progress=progress,
            checkpoint=checkpoint,
            checkpoint_every=checkpoint_every,
        )

    def _progress(self, plan) -> tuple[float, float, bool, str]:
        """A progress bar from the packing at the start to the target, in percent of the way."""
        target = self.settings["target"]
        shown = min(100.0, 100.0 * (self._state.packing - self._phi0) / (target - self._phi0))
        return shown, 100.0, False, "%"

    # --- one epoch ----------------------------------------------------------------------------------
    def _thermostat(self, velocities: np.ndarray) -> tuple[np.ndarray, float]:
        """``(velocities at kT, their kinetic energy before)``: all rescaled by one factor."""
        n = len(velocities)
        energy = 0.5 * float(np.sum(self._masses[:, None] * velocities**2))
        if energy > 0:
            velocities = velocities * math.sqrt(n * self.settings["temperature"] / energy)
        return velocities, energy

    def _epoch(self) -> None:
        """Thermostat, one epoch of growing discs, and the new state (set at once: Ctrl-C never splits it)."""
        started = _time.perf_counter()
        s, settings, box = self._state, self.settings, self.box
        n = len(s.radii)
        velocities, energy = self._thermostat(s.velocities)
        g = settings["growth_rate"] * math.sqrt(settings["temperature"] / float(self._masses.mean()))
        g /= 2.0 * float(s.radii.mean())
        target = settings["target"]
        t_end = (math.sqrt(target / s.packing) - 1.0) / g
        budget = settings["epoch_collisions"]
        if settings["max_collisions"] is not None:
            budget = min(budget, settings["max_collisions"] - s.collisions)
        start = box.wrap(s.positions) if box.periodic else s.positions
        positions, new_velocities, t, stats = epoch(
            start, velocities, s.radii, self._masses, box, self._grid, g, t_end, budget, self.backend
        )
        done = stats["collisions"]
        collisions = s.collisions + done
        kt = 0.5 * (energy + 0.5 * float(np.sum(self._masses[:, None] * new_velocities**2))) / n
        at_end = t >= t_end
        if at_end:
            radii, packing = s.radii * math.sqrt(target / s.packing), target
        else:
            radii = s.radii * (1.0 + g * t)
            packing = math.pi * float(np.sum(radii**2)) / self._area
        z = s.z
        if t > 0:
            z = 1.0 + stats["virial"] / (2.0 * n * kt * t)
        elif done or stats["walls"]:
            z = math.inf  # collisions without the clock moving
        reason = ""
        if at_end:
            reason = "reached"
        elif z > settings["max_pressure"]:
            reason = "jammed"
        elif settings["max_collisions"] is not None and collisions >= settings["max_collisions"]:
            reason = "max_collisions"
        seconds = s.seconds + (_time.perf_counter() - started)
        row = np.array([[packing, collisions, seconds, z, s.time + t]])
        self._state = CompressionState(
            positions, s.shift + (s.positions - start), new_velocities, radii, packing, s.time + t, collisions,
            s.walls + stats["walls"], s.epochs + 1, z, seconds, reason, np.concatenate([s.history, row]),
        )  # fmt: skip

    # --- the checkpoint's protocol -------------------------------------------------------------
    def state(self) -> CompressionState:
        s = self._state
        return CompressionState(
            s.positions.copy(), s.shift.copy(), s.velocities.copy(), s.radii.copy(), s.packing, s.time,
            s.collisions, s.walls, s.epochs, s.z, s.seconds, s.reason, s.history.copy(),
        )  # fmt: skip

    def _settings(self) -> dict:
        return dict(self.settings)

    @classmethod
    def _restore(cls, scene, settings, state, events, start_time) -> Compression:
        sim = cls.__new__(cls)
        settings = {k: v for k, v in settings.items() if k != "record"}
        settings["backend"] = _numba.resolve_backend(settings.get("backend", "auto"), ("python", "numba"), "load")
        sim._configure(scene, settings)
        n = len(scene)
        shapes = {"positions": (n, 2), "shift": (n, 2), "velocities": (n, 2), "radii": (n,)}
        for name, shape in shapes.items():
            if np.shape(getattr(state, name)) != shape:
                msg = f"the state's {name} has shape {np.shape(getattr(state, name))}, not {shape}"
                raise CheckpointError(msg)
        if state.reason not in REASONS or np.shape(state.history) != (state.epochs, 5):
            msg = f"the state's reason {state.reason!r} or history {np.shape(state.history)} is not a compression's"
            raise CheckpointError(msg)
        sim._state = state
        return sim


def compress(
    discs: Discs,
    box: Box,
    packing_fraction: float,
    growth_rate: float = 0.01,
    seed: int | None = None,
    *,
    temperature: float = 1.0,
    max_collisions: int | None = None,
    max_pressure: float = 1e5,
    epoch_collisions: int | None = None,
    backend: str = "auto",
    progress: bool = False,
) -> tuple[Discs, CompressionReport]:
    """Grow all discs until they fill ``packing_fraction`` of the box (Lubachevsky-Stillinger), exactly.

    The event-driven dynamics runs while every radius grows linearly in time, in proportion to itself:
    ``r_i(t) = r_i(0) (1 + g t)`` within an epoch, so the size ratios of a mixture stay as given (a 1:1.4
    binary mixture stays 1:1.4). ``g`` is set so that the mean diameter grows at ``growth_rate`` thermal
    speeds ``sqrt(kT / m)`` (``m`` the mean mass): the slower, the closer to equilibrium (a crystal for
    equal discs), the faster, the more disordered. Two discs touch when ``|dr + dv t| = s + s' t``
    (contact distance ``s`` growing at ``s'``), a quadratic solved by its cancellation-free root; a
    collision is elastic in the frame of the growing surfaces, so the normal separation speed after it
    exceeds the growth ``s'`` by as much as the approach speed did before (``vn' = 2 s' - vn``, momentum
    conserved); a disc against a wall likewise (``v' = 2 r' - v``). Every collision so adds kinetic energy:
    the thermostat rescales all velocities to ``kT = temperature`` at the end of each epoch of
    ``epoch_collisions`` collisions (default ``2 N``), where the radii are rebased and all predictions made
    afresh. Periodic and walled boxes; the box does not change, the discs grow.

    The compression stops when the target is reached, or, below it, when the reduced pressure ``Z``
    (collision virial of an epoch) exceeds ``max_pressure`` (the packing has jammed: free-volume theory
    puts the jamming packing within about ``2 phi / Z`` of the packing reached), or after
    ``max_collisions``. The report says which, with the packing reached; nothing is raised. A target at
    which a disc would span a walled box is refused, an epoch also ends after ``epoch_collisions`` wall hits,
    and an epoch whose clock did not move (discs wedged across a channel) is a jam, so a run always ends.

    At the end, if roundoff left a contact a hair inside (a relative 1e-16 or so), all radii shrink by
    that much and a relative ``SHRINK`` = 1e-12 more, so that ``EventDriven(discs, box)`` accepts the
    result (the report gives the factor). Velocities are at ``kT = temperature``.

    This is :class:`Compression` run to the end: use that engine for checkpoints, observers, or a
    compression done a few epochs at a time. Ctrl-C stops it after the epoch under way.

    Args:
        discs: the starting discs (no overlaps; finite masses). Velocities are rescaled to ``kT``; all at
            rest, or ``seed`` given, draws new Gaussian velocities (zero total momentum).
        box: the box, periodic or walled.
        packing_fraction: the target, above the discs' packing now and below 0.9069 (``DENSEST_PACKING``);
            in a walled box, low enough that every disc still fits across it.
        growth_rate: mean diameter growth per unit time, in thermal speeds (positive, finite; 0.001-0.1).
        seed: seed of the new velocities, or None to keep the directions given.
        temperature: kT of the thermostat. max_collisions: budget of collisions (None: none).
        max_pressure: the reduced pressure Z taken for jamming.
        epoch_collisions: collisions between two rescalings (default ``2 N``, at least 100).
        backend: ``"auto"`` (numba when it imports), ``"numba"`` or ``"python"``.
        progress: show a progress bar (tqdm when installed).

    Returns:
        ``(discs, report)``: the compressed discs (same masses and groups) and a :class:`CompressionReport`.

    Raises:
        PackingError: a target above 0.9069 or not above the packing now, or one at which a disc would no
            longer fit across a walled box, or (``BoxTooSmallError``) a periodic box under 3 final
            diameters a side.
        InvalidArgumentError: a growth rate, temperature or limit that is not positive and finite; infinite
            masses. OverlapError, OutsideBoxError: discs that do not fit. All before anything runs.

    Example:
        >>> import discsim as ds
        >>> gas, box = ds.random_gas(100, 0.3, seed=1)
        >>> dense, report = ds.compress(gas, box, packing_fraction=0.6, backend="python")
        >>> report.reached, round(report.packing_fraction, 6)
        (True, 0.6)
    """
    compression = Compression(
        discs,
        box,
        packing_fraction,
        growth_rate,
        seed,
        temperature=temperature,
        max_collisions=max_collisions,
        max_pressure=max_pressure,
        epoch_collisions=epoch_collisions,
        backend=backend,
    )
    compression.run(progress=progress)
    return compression.snapshot(), compression.report


def _target(packing_fraction, discs: Discs, box: Box) -> float:
    """The checked target packing fraction (a float)."""
    if isinstance(packing_fraction, bool) or not isinstance(packing_fraction, (int, float, np.integer, np.floating)):
        msg = f"packing_fraction must be a number, got {packing_fraction!r}"
        raise PackingError(msg)
    if len(discs) == 0:
        msg = "compress needs at least one disc"
        raise InvalidArgumentError(msg)
    target = float(packing_fraction)
    if not (target < DENSEST_PACKING):  # also nan
        msg = (
            f"packing fraction {packing_fraction!r} cannot be reached: discs pack at most "
            f"pi / (2 sqrt 3) = {DENSEST_PACKING:.6f} (the triangular lattice)"
        )
        raise PackingError(msg)
    radii = np.asarray(discs.radii, dtype=float)
    phi0 = math.pi * float(np.sum(radii**2)) / (box.width * box.height)
    if not target > phi0:
        msg = f"packing fraction {packing_fraction!r} is not above the discs' packing now, {phi0:.6g}"
        raise PackingError(msg)
    if not box.periodic:
        i = int(np.argmax(radii))
        final = 2.0 * float(radii[i]) * math.sqrt(target / phi0)
        side = min(box.width, box.height)
        if final >= side:
            msg = (
                f"packing fraction {packing_fraction!r} cannot be reached in this walled box: disc {i} would "
                f"grow to a diameter of {final:.6g}, not less than the box's side {side:g}"
            )
            raise PackingError(msg)
    return target


def _positive(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise InvalidArgumentError(msg)
    if not (0.0 < value < math.inf):
        msg = f"{name} must be positive and finite, got {value!r}"
        raise InvalidArgumentError(msg)
    return float(value)


def _count(name: str, value) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        msg = f"{name} must be a positive integer or None, got {value!r}"
        raise InvalidArgumentError(msg)
    return int(value)
