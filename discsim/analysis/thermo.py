"""Thermodynamic measurements of a run: packing fraction, pressure, compressibility factor, collision rate.

Numbers in, numbers out: these read a finished engine (any engine with ``pressure()``,
``kinetic_energy()`` and ``box``), its event log, or the blocks a :class:`discsim.Sampler` gathered
during a run, and know nothing of how it ran.

Error bars come from **batch means** (block averaging; H. Flyvbjerg and H. G. Petersen,
J. Chem. Phys. 91, 461 (1989); M. P. Allen and D. J. Tildesley, *Computer Simulation of Liquids*, 2nd ed.,
section 8.4): the span ``[since, end]`` is cut into ``blocks`` consecutive batches of equal duration, each
batch gives its own pressure, ``Z`` and collision rate, and the error bar is the standard error of the
batch values, ``std(batch, ddof=1) / sqrt(blocks)``. It is honest when each batch is much longer than the
correlation time of the virial (a few collision times; at packing 0.5 a batch of 1 time unit of discs of
radius 1 holds about 3 collisions per disc).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from discsim._validate import is_count
from discsim.engines.record import collision_virials
from discsim.errors import InvalidArgumentError, TimeError

__all__ = [
    "ThermoAverages",
    "VirialBlocks",
    "collision_virials",
    "compressibility_factor",
    "packing_fraction",
    "thermo",
]

#: Fine blocks a :class:`VirialBlocks` keeps at most before it merges neighbours (doubling their width).
MAX_FINE_BLOCKS = 1 << 16


def packing_fraction(radii: np.ndarray, area: float) -> float:
    """Fraction of ``area`` covered by discs of ``radii`` ``(N,)``."""
    return float(math.pi * np.sum(np.asarray(radii, dtype=float) ** 2) / area)


def compressibility_factor(sim, since: float | None = None) -> float:
    """``Z = P A / (N kT)`` of a run (``N kT`` is the kinetic energy), from the engine's ``pressure()``.

    Args:
        sim: an engine: :class:`~discsim.EventDriven` (the exact collision virial) or
            :class:`~discsim.FixedStep` (the virial of the impulses its frames applied; see
            ``FixedStep.pressure``).
        since: average from this time on (skip the melting of a starting lattice); None: from the start,
            from the engine's own running virial (no log needed). With ``since``, the run must have kept
            its event log (see :func:`thermo`, which also gives the error bar).

    Raises:
        InvalidArgumentError: if the object has no ``pressure()`` (it is not an engine) or no
            kinetic energy (no free disc moves), or ``since`` is given and the run recorded nothing.
        TimeError: if ``since`` lies outside the run.
    """
    _check_pressure_engine(sim, "compressibility_factor")
    energy = sim.kinetic_energy()
    if energy <= 0.0:
        msg = "compressibility_factor needs moving discs: the kinetic energy is 0"
        raise InvalidArgumentError(msg)
    if since is not None:
        return thermo(sim, since=since).z
    return sim.pressure() * sim.box.area / energy


def _check_pressure_engine(sim, what: str) -> None:
    if not callable(getattr(sim, "pressure", None)):
        msg = f"{what} needs an engine with pressure() (EventDriven or FixedStep), got {type(sim).__name__}"
        raise InvalidArgumentError(msg)


@dataclass(frozen=True)
class ThermoAverages:
    """Pressure, compressibility factor and collision rate over ``[since, until]``, with batch-means errors.

    Attributes:
        since, until: the span averaged (time units).
        blocks: the number of batches of the error bars. method: ``"batch means"``.
        n: discs counted (finite mass). area: the box area. energy: the kinetic energy ``N kT``.
        pressure, pressure_err: ``P = (N kT + W / (2 t)) / A`` (energy per area) and its standard error;
            with walls, the bulk estimate (wall contacts are not counted), as ``sim.pressure()``.
        z, z_err: ``Z = P A / (N kT)`` and its standard error.
        collision_rate, collision_rate_err: disc-disc collisions per disc per unit time
            (``2 C / (N t)``, comparable with :func:`discsim.enskog_collision_rate`).
        collisions: disc-disc collisions in the span.
        edges: ``(blocks + 1,)`` the batches' bounds. z_blocks: ``(blocks,)`` each batch's ``Z``.
    """

    since: float
    until: float
    blocks: int
    n: int
    area: float
    energy: float
    pressure: float
    pressure_err: float
    z: float
    z_err: float
    collision_rate: float
    collision_rate_err: float
    collisions: int
    edges: np.ndarray
    z_blocks: np.ndarray
    method: str = "batch means"

    def __str__(self) -> str:
        return (
            f"Z = {self.z:.4f} +- {self.z_err:.4f}, P = {self.pressure:.6g} +- {self.pressure_err:.2g}, "
            f"collision rate {self.collision_rate:.5g} +- {self.collision_rate_err:.2g} per disc "
            f"(t in [{self.since:g}, {self.until:g}], {self.method} over {self.blocks} blocks)"
        )

    def plot(self, ax=None):
        """``Z`` of each batch against time, with the mean and its error band. Returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        ax.stairs(self.z_blocks, self.edges, label="batches")
        ax.axhline(self.z, color="k", lw=1, label=f"Z = {self.z:.4f} ± {self.z_err:.4f}")
        ax.axhspan(self.z - self.z_err, self.z + self.z_err, color="k", alpha=0.15)
        ax.set_xlabel("time")
        ax.set_ylabel("Z = PA / NkT")
        ax.legend()
        return ax


class VirialBlocks:
    """The collision virial and the collision count in consecutive time blocks, gathered chunk by chunk.

    Blocks start at ``origin`` and are ``width`` long; when there are more than :data:`MAX_FINE_BLOCKS`,
    neighbours merge (the width doubles), so memory stays bounded on a run of any length. A
    :class:`discsim.Sampler` keeps one during a run; :func:`thermo` averages it.

    Args:
        origin: the time the first block starts. width: the blocks' duration.
        masses: ``(N,)`` the discs' masses. box: the box. energy: the kinetic energy ``N kT``.
    """

    def __init__(self, origin: float, width: float, masses: np.ndarray, box, energy: float):
        self.origin = float(origin)
        self.width = float(width)
        self.masses = np.asarray(masses, dtype=float)
        self.box = box
        self.energy = float(energy)
        self.end = self.origin
        self.virial = np.zeros(0)
        self.collisions = np.zeros(0, dtype=np.int64)

    def add(self, events: np.ndarray, time: float) -> None:
        """Count the disc-disc collisions of ``events`` (time order); the blocks now cover up to ``time``."""
        times, w = collision_virials(events, self.masses, self.box)
        self.end = max(self.end, float(time))
        need = max(1, math.ceil((self.end - self.origin) / self.width))
        while need > MAX_FINE_BLOCKS:
            self._merge()
            need = max(1, math.ceil((self.end - self.origin) / self.width))
        if need > len(self.virial):
            self.virial = np.concatenate([self.virial, np.zeros(need - len(self.virial))])
            self.collisions = np.concatenate([self.collisions, np.zeros(need - len(self.collisions), np.int64)])
        if len(times):
            k = np.clip(((times - self.origin) // self.width).astype(np.int64), 0, len(self.virial) - 1)
            self.virial += np.bincount(k, weights=w, minlength=len(self.virial))
            self.collisions += np.bincount(k, minlength=len(self.collisions))

    def _merge(self) -> None:
        if len(self.virial) % 2:
            self.virial = np.append(self.virial, 0.0)
            self.collisions = np.append(self.collisions, 0)
        self.virial = self.virial.reshape(-1, 2).sum(axis=1)
        self.collisions = self.collisions.reshape(-1, 2).sum(axis=1)
        self.width *= 2.0

    def edges(self) -> np.ndarray:
        """``(B + 1,)`` the blocks' bounds; the last block ends at ``end``."""
        edges = self.origin + self.width * np.arange(len(self.virial) + 1)
        edges[-1] = self.end
        return edges


def thermo(source, since: float | None = None, blocks: int = 10) -> ThermoAverages:
    """Pressure, ``Z`` and collision rate of a run from ``since`` on, with error bars from batch means.

    The virial of each disc-disc collision comes from the event log (:func:`collision_virials`); over the
    whole run it equals the engine's own (``sim.pressure()``) to roundoff (for a ``FixedStep``, whose log holds
    the states where its impulses were applied, too; except ``"revert"``'s rare impulses along the frame's
    line of centres rather than the restored one). The method of the error bars
    (batch means) is described in the module docstring.

    Args:
        source: an engine (event-driven or fixed-step) that recorded its log (``record=True``) or streamed it
            (``run(record_to=...)``, read back chunk by chunk, so memory stays flat), a
            :class:`~discsim.io.streams.StreamedEvents` or the path of a streamed log; or a
            :class:`discsim.Sampler` that observed the run (which needs no log: its blocks are ``dt / 8``
            long, and ``since`` is rounded up to a block's start).
        since: average from this time on, to skip the melting of a starting lattice; None: from the start.
        blocks: batches of the error bars (an integer >= 2).

    Returns:
        :class:`ThermoAverages`.

    Raises:
        InvalidArgumentError: if the run recorded nothing (``record=False`` and no stream), the engine has no
            pressure, the discs are at rest, or ``blocks`` is not an integer >= 2.
        TimeError: if ``since`` is not a time within the run (``start <= since < end``).

    Example:
        >>> import discsim as ds
        >>> sim = ds.EventDriven(*ds.random_gas(200, 0.3, seed=1)).run(until=6.0)
        >>> t = ds.thermo(sim, since=1.0)
        >>> bool(abs(t.z - ds.henderson_z(0.3)) < 5 * t.z_err + 0.05), t.since, t.blocks
        (True, 1.0, 10)
    """
    if not is_count(blocks) or blocks < 2:
        msg = f"blocks must be an integer >= 2 (batches of the error bar), got {blocks!r}"
        raise InvalidArgumentError(msg)
    blocks = int(blocks)
    if isinstance(source, VirialBlocks) or hasattr(source, "virial_blocks"):
        fine = source if isinstance(source, VirialBlocks) else source.virial_blocks
        if fine is None:
            msg = "thermo() of a Sampler that has not observed a run yet"
            raise InvalidArgumentError(msg)
        return _from_blocks(fine, since, blocks)
    from discsim.analysis.frames import log_source

    engine = source if hasattr(source, "run_context") else None
    if engine is not None:
        _check_pressure_engine(engine, "thermo()")
    chunks, discs, box, start, end, sim = log_source(source, "thermo()")
    energy = sim.kinetic_energy() if sim is not None else discs.kinetic_energy()
    since = _check_since(since, start, end)
    edges = np.linspace(since, end, blocks + 1)
    edges[-1] = end
    masses = np.asarray(discs.masses, dtype=float)
    virial, collisions = np.zeros(blocks), np.zeros(blocks, dtype=np.int64)
    for events in chunks():
        times, w = collision_virials(events, masses, box)
        keep = times > since  # an event exactly at `since` belongs to the past
        times, w = times[keep], w[keep]
        k = np.clip(np.searchsorted(edges, times, side="left") - 1, 0, blocks - 1)
        virial += np.bincount(k, weights=w, minlength=blocks)
        collisions += np.bincount(k, minlength=blocks)
    return _averages(edges, virial, collisions, masses, box, energy)


def _check_since(since, start: float, end: float) -> float:
    if since is None:
        since = start
    if isinstance(since, bool) or not isinstance(since, (int, float, np.integer, np.floating)):
        msg = f"since must be a time (a number), got {since!r}"
        raise TimeError(msg)
    since = float(since)
    if not (start <= since < end):
        msg = f"since={since!r} is outside the run: it must lie in [{start!r}, {end!r}) (the simulated span)"
        raise TimeError(msg)
    return since


def _from_blocks(fine: VirialBlocks, since, blocks: int) -> ThermoAverages:
    edges = fine.edges()
    since = _check_since(since, fine.origin, fine.end)
    first = int(np.searchsorted(edges, since - 1e-9 * fine.width, side="left"))  # the first edge at or after since
    first = min(first, len(edges) - 2)
    available = len(edges) - 1 - first
    if available < blocks:
        msg = (
            f"the Sampler holds {available} block(s) of {fine.width:g} time units after since={since!r}, fewer than "
            f"blocks={blocks}: sample with a smaller dt, run longer or ask for fewer blocks"
        )
        raise InvalidArgumentError(msg)
    groups = np.array_split(np.arange(first, len(edges) - 1), blocks)
    bounds = np.array([edges[g[0]] for g in groups] + [edges[-1]])
    virial = np.array([fine.virial[g].sum() for g in groups])
    collisions = np.array([fine.collisions[g].sum() for g in groups])
    return _averages(bounds, virial, collisions, fine.masses, fine.box, fine.energy)


def _averages(edges, virial, collisions, masses, box, energy) -> ThermoAverages:
    if energy <= 0.0:
        msg = "thermo() needs moving discs: the kinetic energy is 0"
        raise InvalidArgumentError(msg)
    n = int(np.count_nonzero(np.isfinite(masses)))
    durations = np.diff(edges)
    total = float(durations.sum())
    weights = durations / total
    area = box.area
    m = len(durations)

    def mean_err(per_block: np.ndarray, overall: float) -> float:
        # Standard error of a ratio of sums over batches (the batch-means error for equal batches).
        return float(math.sqrt(np.sum(weights**2 * (per_block - overall) ** 2) * m / (m - 1)))

    z_blocks = 1.0 + virial / (2.0 * energy * durations)
    z = 1.0 + float(virial.sum()) / (2.0 * energy * total)
    rate_blocks = 2.0 * collisions / (n * durations)
    rate = 2.0 * float(collisions.sum()) / (n * total)
    z_err = mean_err(z_blocks, z)
    return ThermoAverages(
        since=float(edges[0]),
        until=float(edges[-1]),
        blocks=m,
        n=n,
        area=area,
        energy=float(energy),
        pressure=z * energy / area,
        pressure_err=z_err * energy / area,
        z=z,
        z_err=z_err,
        collision_rate=rate,
        collision_rate_err=mean_err(rate_blocks, rate),
        collisions=int(collisions.sum()),
        edges=np.asarray(edges, dtype=float),
        z_blocks=z_blocks,
    )
