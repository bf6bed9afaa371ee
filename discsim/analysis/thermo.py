"""Thermodynamic measurements of a run: packing fraction, pressure, compressibility factor, collision rate.

Numbers in, numbers out: these read a finished engine (any engine with ``pressure()``,
``kinetic_energy()`` and ``box``), its event log, or the blocks a :class:`discsim.Sampler` gathered
during a run, and know nothing of how it ran.

**Ensemble.** An event-driven run of hard discs conserves the kinetic energy ``K`` and, in a periodic box
without obstacles or segments, the total momentum: it samples the microcanonical ensemble at fixed momentum
(the molecular-dynamics ensemble), with ``2N - 2`` degrees of freedom, so its temperature is
``kT = K_int / (N - 1)`` (``K_int`` the kinetic energy in the centre-of-mass frame), not ``K / N``
(J. J. Erpenbeck and W. W. Wood, in *Statistical Mechanics B*, ed. B. J. Berne (1977); J. L. Lebowitz,
J. K. Percus and L. Verlet, Phys. Rev. 153, 250 (1967)). For hard discs the configurations are uniform over
the allowed ones in both ensembles, and the velocities are independent of them with
``<(v_i - v_j)_x^2> = kT (1/m_i + 1/m_j)`` exactly at that ``kT``; so the collision virial ``W`` per unit
time is the canonical one at ``kT``, and the canonical pressure of ``N`` discs at ``kT`` is

    beta P A = N + W / (2 t kT),    Z = beta P A / N = 1 + W / (2 t N kT),

with no further correction at any ``N``. Reading ``kT`` as ``K / N`` instead puts ``Z - 1`` too high by
``N / (N - 1)``: 1.4% at ``N = 72``, many error bars of a long run. The engines' own ``pressure()`` is the
mechanical one, the momentum flux ``(K + W / (2 t)) / A``: it is short of the canonical ``P`` by ``kT / A``
(the two degrees of freedom the fixed momentum removes). In a box with walls, or with fixed obstacles or
segments, momentum is not conserved: ``2N`` degrees of freedom, ``kT = K / N``.

**Error bars and equilibration.** :func:`thermo` cuts the span into a series of short, equal blocks (up to
:data:`SERIES_POINTS`) and gives each block's ``Z``. Its error bar is ``sqrt(var(Z) g / T)`` from the series'
statistical inefficiency ``g`` (the number of blocks per independent sample, from its autocorrelation:
:mod:`discsim.analysis.equilibration`), so it grows with the correlation time instead of assuming that a fixed
number of batches are independent; ``blocks=k`` gives the batch means over ``k`` batches of earlier versions
(H. Flyvbjerg and H. G. Petersen, J. Chem. Phys. 91, 461 (1989)). The start of the production part is
found by the automated equilibration detection of J. D. Chodera, J. Chem. Theory Comput. 12, 1799 (2016)
(``since="auto"``), and a production series that still drifts (Geweke's diagnostic beyond 3), holds fewer
than :data:`MIN_INDEPENDENT` independent samples, or starts more than half-way through the run raises an
:class:`~discsim.errors.EquilibrationWarning`. ``Z`` alone can look stationary while the structure is still
relaxing (a lattice start at packing 0.70 melts over thousands of collisions per disc, and ``Z`` climbs with
it by less than its noise per block), so where positions are at hand (a log in memory, or a Sampler that kept
its frames) the global bond-orientational order ``|psi6|``, the slowest observable of dense discs (the one
E. P. Bernard and W. Krauth, PRL 107, 155704 (2011), and M. Engel et al., PRE 87, 042134 (2013), judge
equilibration by), is checked on :data:`ORDER_FRAMES` frames of the production span: a slow drift
(:func:`~discsim.analysis.equilibration.trend_score` beyond :data:`ORDER_TREND_LIMIT`) or a transient (Geweke's
score beyond :data:`ORDER_GEWEKE_LIMIT`) warns too.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from discsim._validate import is_count
from discsim.analysis.equilibration import detect_equilibration, geweke_score, statistical_inefficiency, trend_score
from discsim.engines.record import collision_virials
from discsim.errors import EquilibrationWarning, InvalidArgumentError, TimeError
from discsim.events import WALL

__all__ = [
    "ThermoAverages",
    "VirialBlocks",
    "collision_virials",
    "compressibility_factor",
    "kinetic_temperature",
    "packing_fraction",
    "thermo",
]

#: Fine blocks a :class:`VirialBlocks` keeps at most before it merges neighbours (doubling their width).
MAX_FINE_BLOCKS = 1 << 16
#: Fine time bins of the virial read from an event log (the series and the batches are made of them).
LOG_BINS = 1 << 13
#: The most blocks of the ``Z`` series :func:`thermo` analyses; at least ``SERIES_COLLISIONS`` collisions each.
SERIES_POINTS = 1000
SERIES_COLLISIONS = 10
#: Geweke scores beyond this, or fewer independent samples than ``MIN_INDEPENDENT``, warn.
GEWEKE_LIMIT = 3.0
MIN_INDEPENDENT = 10
#: Frames of the global psi6 that :func:`thermo` checks over the production span (when it has positions), and
#: the trend (its least-squares slope over its standard error: a slow drift) and the Geweke score (a transient)
#: beyond which it warns. On 64 frames of an AR(1) series at equilibrium, |trend| > 4 comes up 0.1% of the time
#: with a correlation of 0.5 from frame to frame, 1.5% with 0.7 and 8% with 0.9 (3 independent samples in the
#: span: a run that is short for its structure anyway).
ORDER_FRAMES = 64
ORDER_TREND_LIMIT = 4.0
ORDER_GEWEKE_LIMIT = 5.0


def packing_fraction(radii: np.ndarray, area: float) -> float:
    """Fraction of ``area`` covered by discs of ``radii`` ``(N,)``."""
    return float(math.pi * np.sum(np.asarray(radii, dtype=float) ** 2) / area)


def kinetic_temperature(sim) -> float:
    """``kT`` of an engine's discs: the kinetic energy over the degrees of freedom.

    In a periodic box with no fixed obstacle (infinite mass) and no segment, the total momentum is conserved:
    ``kT = (K - |p|^2 / (2 M)) / (N - 1)``, ``2N - 2`` degrees of freedom (``p`` the total momentum, ``M``
    the total mass). Otherwise ``kT = K / N``. ``N`` counts the discs of finite mass.

    Example:
        >>> import discsim as ds
        >>> sim = ds.EventDriven(*ds.random_gas(100, 0.3, seed=1))  # K = 100, zero momentum
        >>> round(kinetic_temperature(sim), 12)
        1.010101010101
    """
    masses = np.asarray(sim.discs.masses, dtype=float)
    segments = getattr(getattr(sim, "scene", None), "segments", ())
    conserved = bool(sim.box.periodic) and not len(segments)
    return _temperature(masses, sim.kinetic_energy(), np.asarray(sim.momentum(), dtype=float), conserved)


def _temperature(masses: np.ndarray, energy: float, momentum: np.ndarray, conserved: bool) -> float:
    finite = np.isfinite(masses)
    n = int(np.count_nonzero(finite))
    if n == 0:
        return 0.0
    if conserved and n >= 2 and bool(finite.all()):
        internal = energy - float(np.dot(momentum, momentum)) / (2.0 * float(masses.sum()))
        return internal / (n - 1)
    return energy / n


def compressibility_factor(sim, since: float | str | None = None) -> float:
    """The canonical ``Z = beta P A / N`` of a run, from the engine's ``pressure()`` (see the module's Ensemble).

    ``Z = 1 + W / (2 t N kT)`` with ``kT`` from :func:`kinetic_temperature` (``K / (N - 1)`` in a periodic box)
    and ``W / (2 t) = P_mech A - K`` the engine's collision virial per unit time.

    Args:
        sim: an engine: :class:`~discsim.EventDriven` (the exact collision virial) or
            :class:`~discsim.FixedStep` (the virial of the impulses its frames applied; see
            ``FixedStep.pressure``).
        since: average from this time on (skip the melting of a starting lattice), or ``"auto"`` (the start
            :func:`thermo` detects); None: from the start, from the engine's own running virial (no log
            needed). With ``since``, the run must have kept its event log (see :func:`thermo`, which also
            gives the error bar).

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
    n = int(np.count_nonzero(np.isfinite(np.asarray(sim.discs.masses, dtype=float))))
    return 1.0 + (sim.pressure() * sim.box.area - energy) / (n * kinetic_temperature(sim))


def _check_pressure_engine(sim, what: str) -> None:
    if not callable(getattr(sim, "pressure", None)):
        msg = f"{what} needs an engine with pressure() (EventDriven or FixedStep), got {type(sim).__name__}"
        raise InvalidArgumentError(msg)


@dataclass(frozen=True)
class ThermoAverages:
    """Canonical pressure, compressibility factor and collision rate over ``[since, until]``, with error bars.

    Attributes:
        since, until: the span averaged (time units): ``since`` is the start of production (the one asked,
            or the one detected with ``since="auto"``).
        blocks: the blocks of the series (``method="statistical inefficiency"``) or the batches
            (``"batch means"``). method: how the error bars were made.
        n: discs counted (finite mass). area: the box area. energy: the kinetic energy ``K``.
        temperature: ``kT`` (``K / (N - 1)`` in a periodic box: see the module's Ensemble).
        pressure, pressure_err: the canonical ``P = (N kT + W / (2 t)) / A`` (energy per area) and its standard
            error; with walls, the bulk estimate (wall contacts are not counted).
        z, z_err: ``Z = P A / (N kT)`` and its standard error.
        collision_rate, collision_rate_err: disc-disc collisions per disc per unit time
            (``2 C / (N t)``, comparable with :func:`discsim.enskog_collision_rate`).
        collisions: disc-disc collisions in the span.
        edges: ``(blocks + 1,)`` the blocks' bounds. z_blocks: ``(blocks,)`` each block's ``Z``.
        inefficiency: the statistical inefficiency ``g`` of ``z_blocks`` (blocks per independent sample).
        independent: the independent samples in the span, ``blocks / g``.
        equilibrium_start: the start of production that automated equilibration detection (Chodera 2016)
            finds in the series from the ``since`` asked (equal to ``since`` when it finds none to skip).
        geweke: Geweke's score of the production series (first 10% against last 50%; about standard normal at
            equilibrium). drifting: whether the averages warned (:class:`~discsim.errors.EquilibrationWarning`).
        order: ``(F,)`` the global ``|psi6|`` at :data:`ORDER_FRAMES` times of the production span, or empty when
            no positions were at hand (a streamed log, a Sampler that kept no frames). order_independent: its
            independent samples (``F / g``; NaN when empty).
    """

    since: float
    until: float
    blocks: int
    n: int
    area: float
    energy: float
    temperature: float
    pressure: float
    pressure_err: float
    z: float
    z_err: float
    collision_rate: float
    collision_rate_err: float
    collisions: int
    edges: np.ndarray
    z_blocks: np.ndarray
    inefficiency: float
    independent: float
    equilibrium_start: float
    geweke: float
    drifting: bool
    order: np.ndarray
    order_independent: float
    method: str = "statistical inefficiency"

    def __str__(self) -> str:
        how = (
            f"batch means over {self.blocks} blocks"
            if self.method == "batch means"
            else f"{self.blocks} blocks, g = {self.inefficiency:.3g}, {self.independent:.0f} independent"
        )
        return (
            f"Z = {self.z:.4f} +- {self.z_err:.4f}, P = {self.pressure:.6g} +- {self.pressure_err:.2g}, "
            f"collision rate {self.collision_rate:.5g} +- {self.collision_rate_err:.2g} per disc "
            f"(t in [{self.since:g}, {self.until:g}], {how}{', DRIFTING' if self.drifting else ''})"
        )

    def plot(self, ax=None):
        """``Z`` of each block against time, with the mean and its error band. Returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        ax.stairs(self.z_blocks, self.edges, label="blocks")
        ax.axhline(self.z, color="k", lw=1, label=f"Z = {self.z:.4f} ± {self.z_err:.4f}")
        ax.axhspan(self.z - self.z_err, self.z + self.z_err, color="k", alpha=0.15)
        ax.set_xlabel("time")
        ax.set_ylabel("Z = βPA / N")
        ax.legend()
        return ax


class VirialBlocks:
    """The collision virial and the collision count in consecutive time blocks, gathered chunk by chunk.

    Blocks start at ``origin`` and are ``width`` long; when there are more than :data:`MAX_FINE_BLOCKS`,
    neighbours merge (the width doubles), so memory stays bounded on a run of any length. A
    :class:`discsim.Sampler` keeps one during a run; :func:`thermo` averages it.

    Args:
        origin: the time the first block starts. width: the blocks' duration.
        masses: ``(N,)`` the discs' masses. box: the box. energy: the kinetic energy.
        temperature: ``kT`` (see :func:`kinetic_temperature`); None: ``energy / N``, the reading of a run that
            does not conserve momentum.
    """

    def __init__(
        self, origin: float, width: float, masses: np.ndarray, box, energy: float, temperature: float | None = None
    ):
        self.origin = float(origin)
        self.width = float(width)
        self.masses = np.asarray(masses, dtype=float)
        self.box = box
        self.energy = float(energy)
        n = max(1, int(np.count_nonzero(np.isfinite(self.masses))))
        self.temperature = self.energy / n if temperature is None else float(temperature)
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


def thermo(source, since: float | str | None = None, blocks: int | None = None) -> ThermoAverages:
    """Canonical pressure, ``Z`` and collision rate of a run from ``since`` on, with honest error bars.

    ``Z = beta P A / N`` at ``kT = K / (N - 1)`` in a periodic box (the run samples the microcanonical
    ensemble at fixed momentum; see the module's Ensemble), so it is the canonical ``Z`` at every ``N``. The
    virial of each disc-disc collision comes from the event log (:func:`collision_virials`); over the whole
    run ``W`` equals the engine's own (``sim.pressure()``, the mechanical pressure) to roundoff. The error bar
    comes from the statistical inefficiency of the series of the blocks' ``Z``, and the series is checked for
    drift (see the module's Error bars and equilibration).

    Args:
        source: an engine (event-driven or fixed-step) that recorded its log (``record=True``) or streamed it
            (``run(record_to=...)``, read back chunk by chunk, so memory stays flat; after ``add_discs`` or
            ``remove_discs``, the span since the last such change, the discs being today's), a
            :class:`~discsim.io.streams.StreamedEvents` or the path of a streamed log; or a
            :class:`discsim.Sampler` that observed the run (which needs no log: its blocks are ``dt / 8``
            long, and ``since`` is rounded up to a block's start). A log in memory is replayed at 64 times for
            the psi6 check (a few seconds for 10,000 discs); a streamed log is not.
        since: average from this time on, to skip the melting of a starting lattice; ``"auto"``: from the start
            of production that automated equilibration detection (Chodera 2016) finds; None: from the start.
        blocks: None: error bars from the statistical inefficiency of the series; an integer >= 2: batch means
            over that many batches (the error bars of earlier versions).

    Returns:
        :class:`ThermoAverages`; for a run at constant pressure (a :class:`discsim.Piston`), the
        :class:`~discsim.analysis.isobaric.IsobaricAverages` of :func:`~discsim.analysis.isobaric.isobaric`: the
        mean area, packing fraction and ``Z`` with their error bars.

    Warns:
        EquilibrationWarning: if the production series still drifts (Geweke's score beyond 3), holds fewer than
            10 independent samples, or (``since="auto"``) starts after the first half of the run; or if the
            global psi6 still relaxes over the span (see the module's Error bars and equilibration).

    Raises:
        InvalidArgumentError: if the run recorded nothing (``record=False`` and no stream), the engine has no
            pressure, the discs are at rest, or ``blocks`` is not None or an integer >= 2.
        TimeError: if ``since`` is not ``"auto"`` or a time within the run (``start <= since < end``).

    Example:
        >>> import discsim as ds
        >>> sim = ds.EventDriven(*ds.random_gas(200, 0.3, seed=1)).run(until=6.0)
        >>> t = ds.thermo(sim, since=1.0)
        >>> bool(abs(t.z - ds.henderson_z(0.3)) < 5 * t.z_err + 0.05), t.since, t.method, t.drifting
        (True, 1.0, 'statistical inefficiency', False)
    """
    if getattr(getattr(source, "scene", None), "piston", None) is not None and blocks is None:
        from discsim.analysis.isobaric import isobaric  # a run at constant pressure: its area fluctuates

        return isobaric(source, since)  # type: ignore[return-value]
    if blocks is not None and (not is_count(blocks) or blocks < 2):
        msg = f"blocks must be None or an integer >= 2 (batches of the error bar), got {blocks!r}"
        raise InvalidArgumentError(msg)
    auto = isinstance(since, str) and since == "auto"
    if isinstance(source, VirialBlocks) or hasattr(source, "virial_blocks"):
        fine = source if isinstance(source, VirialBlocks) else source.virial_blocks
        if fine is None:
            msg = "thermo() of a Sampler that has not observed a run yet"
            raise InvalidArgumentError(msg)
        edges, virial, collisions = _sampler_bins(fine, None if auto else since, blocks)
        kept = getattr(source, "frames", None) if not isinstance(source, VirialBlocks) else None

        def sampled_order(start: float, end: float) -> np.ndarray:
            if kept is None:
                return np.zeros(0)
            inside = np.flatnonzero(kept.times >= start - 1e-9 * fine.width)
            pick = inside[np.unique(np.linspace(0, len(inside) - 1, min(len(inside), ORDER_FRAMES)).astype(int))]
            return _order(kept.positions[pick], fine.box) if len(inside) >= 2 else np.zeros(0)

        return _analyse(
            edges, virial, collisions, fine.masses, fine.box, fine.energy, fine.temperature, auto, blocks, sampled_order
        )
    from discsim.analysis.frames import _log_source, log_source

    engine = source if hasattr(source, "run_context") else None
    if engine is not None:
        _check_pressure_engine(engine, "thermo()")
    changed = engine is not None and engine.run_context.origin is not None
    if engine is not None and changed:  # discs added or removed: the span since the last change, today's discs
        chunks, _, box, start, end, sim = _log_source(engine, "thermo()")
        discs = engine.discs
        start = _last_change(chunks, start)
        if since is not None and not auto and isinstance(since, (int, float)) and since < start:
            msg = (
                f"since={since!r} is before the last change of the discs (add_discs / remove_discs) at time "
                f"{start!r}: thermo() averages a fixed set of discs, from then on"
            )
            raise TimeError(msg)
        masses = np.full(engine.run_context.next_id, np.nan)  # by id: the log names the discs by id
        masses[engine.ids] = discs.masses
    else:
        chunks, discs, box, start, end, sim = log_source(source, "thermo()")
        masses = np.asarray(discs.masses, dtype=float)
    first = _check_since(None if auto else since, start, end)
    bins = LOG_BINS if blocks is None else blocks * math.ceil(LOG_BINS / blocks)  # equal batches
    edges = np.linspace(first, end, bins + 1)
    edges[-1] = end
    virial, collisions = np.zeros(bins), np.zeros(bins, dtype=np.int64)
    walls = False
    for events in chunks():
        walls = walls or bool(np.any(events["kind"] == WALL))
        times, w = collision_virials(events, masses, box)
        keep = times > first  # an event exactly at `since` belongs to the past
        times, w = times[keep], w[keep]
        k = np.clip(np.searchsorted(edges, times, side="left") - 1, 0, bins - 1)
        virial += np.bincount(k, weights=w, minlength=bins)
        collisions += np.bincount(k, minlength=bins)
    holder = sim if sim is not None else discs
    energy = holder.kinetic_energy()
    masses = np.asarray(discs.masses, dtype=float)  # today's discs, by index
    segments = getattr(getattr(sim, "scene", None), "segments", ())
    conserved = bool(box.periodic) and not walls and not len(segments)
    kt = _temperature(masses, energy, np.asarray(holder.momentum(), dtype=float), conserved)

    def logged_order(start: float, end: float) -> np.ndarray:
        if engine is None or not getattr(engine, "record", False) or changed:  # a streamed log: too costly to replay
            return np.zeros(0)
        from discsim.analysis.frames import frames

        return _order(frames(engine, np.linspace(start, end, ORDER_FRAMES)).positions, box)

    return _analyse(edges, virial, collisions, masses, box, energy, kt, auto, blocks, logged_order)


def _order(positions: np.ndarray, box) -> np.ndarray:
    """``(F,)`` the global ``|psi6|`` of ``(F, N, 2)`` positions."""
    from discsim.analysis.structure import psi6

    if positions.shape[1] < 7:  # six neighbours each: too few discs for a bond order
        return np.zeros(0)
    return np.atleast_1d(np.asarray(psi6(positions, box).order, dtype=float))


def _last_change(chunks, start: float) -> float:
    """The time of the log's last ``ADD`` or ``REMOVE`` record (``start`` if none)."""
    from discsim.events import ADD, REMOVE

    last = start
    for records in chunks():
        changed = records["time"][(records["kind"] == ADD) | (records["kind"] == REMOVE)]
        if len(changed):
            last = max(last, float(changed.max()))
    return last


def _check_since(since, start: float, end: float) -> float:
    if since is None:
        since = start
    if isinstance(since, bool) or not isinstance(since, (int, float, np.integer, np.floating)):
        msg = f'since must be a time (a number) or "auto", got {since!r}'
        raise TimeError(msg)
    since = float(since)
    if not (start <= since < end):
        msg = f"since={since!r} is outside the run: it must lie in [{start!r}, {end!r}) (the simulated span)"
        raise TimeError(msg)
    return since


def _sampler_bins(fine: VirialBlocks, since, blocks: int | None):
    """The Sampler's blocks from the first one that starts at or after ``since``."""
    edges = fine.edges()
    since = _check_since(since, fine.origin, fine.end)
    first = int(np.searchsorted(edges, since - 1e-9 * fine.width, side="left"))  # the first edge at or after since
    first = min(first, len(edges) - 2)
    available = len(edges) - 1 - first
    if available < (blocks or 2):
        msg = (
            f"the Sampler holds {available} block(s) of {fine.width:g} time units after since={since!r}, fewer than "
            f"{'blocks=' + str(blocks) if blocks else 'the 2 a series needs'}: sample with a smaller dt, run "
            "longer or ask for fewer blocks"
        )
        raise InvalidArgumentError(msg)
    return edges[first:], fine.virial[first:], fine.collisions[first:]


def _grouped(edges: np.ndarray, virial: np.ndarray, collisions: np.ndarray, groups: list[np.ndarray]):
    bounds = np.array([edges[g[0]] for g in groups] + [edges[-1]])
    return bounds, np.array([virial[g].sum() for g in groups]), np.array([collisions[g].sum() for g in groups])


def _analyse(
    edges, virial, collisions, masses, box, energy, kt, auto: bool, blocks: int | None, order_of
) -> ThermoAverages:
    """The averages over fine bins ``edges`` ``(F + 1,)`` holding ``virial`` and ``collisions`` ``(F,)``;
    ``order_of(start, end)`` gives the global ``|psi6|`` at frames of the production span (or nothing)."""
    if energy <= 0.0 or kt <= 0.0:
        msg = "thermo() needs moving discs: the kinetic energy is 0"
        raise InvalidArgumentError(msg)
    n = int(np.count_nonzero(np.isfinite(masses)))
    fine = len(virial)
    points = int(min(SERIES_POINTS, fine, max(20, int(collisions.sum()) // SERIES_COLLISIONS)))
    groups = np.array_split(np.arange(fine), points)
    bounds, v, c = _grouped(edges, virial, collisions, groups)

    def z_of(w, duration):
        return 1.0 + w / (2.0 * n * kt * duration)

    series = z_of(v, np.diff(bounds))
    found = detect_equilibration(series, nskip=max(1, points // 200))
    t0 = found.t0 if auto else 0
    production = series[t0:]
    g = statistical_inefficiency(production)
    independent = len(production) / g
    geweke = geweke_score(production)
    start = int(groups[t0][0])
    span = float(edges[-1] - edges[start])
    z = z_of(float(virial[start:].sum()), span)
    rate = 2.0 * float(collisions[start:].sum()) / (n * span)
    if blocks is None:
        method, out_edges, z_blocks = "statistical inefficiency", bounds[t0:], production
        rates = 2.0 * c[t0:] / (n * np.diff(out_edges))
        m = len(production)
        z_err = math.sqrt(float(np.var(production, ddof=1)) * g / m) if m > 1 else float("nan")
        rate_err = math.sqrt(float(np.var(rates, ddof=1)) * statistical_inefficiency(rates) / m) if m > 1 else math.nan
    else:
        if fine - start < blocks:
            msg = f"the span after since holds {fine - start} bins, fewer than blocks={blocks}: ask for fewer blocks"
            raise InvalidArgumentError(msg)
        batches = np.array_split(np.arange(start, fine), blocks)
        out_edges, bv, bc = _grouped(edges, virial, collisions, batches)
        durations = np.diff(out_edges)
        weights = durations / durations.sum()
        method, z_blocks = "batch means", z_of(bv, durations)

        def mean_err(per_block: np.ndarray, overall: float) -> float:
            # Standard error of a ratio of sums over batches (the batch-means error for equal batches).
            return float(math.sqrt(np.sum(weights**2 * (per_block - overall) ** 2) * blocks / (blocks - 1)))

        z_err, rate_err = mean_err(z_blocks, z), mean_err(2.0 * bc / (n * durations), rate)
    late = auto and t0 > len(series) // 2
    order = order_of(float(edges[start]), float(edges[-1]))
    order_independent = len(order) / statistical_inefficiency(order) if len(order) else math.nan
    order_trend = trend_score(order) if len(order) else 0.0
    order_geweke = geweke_score(order) if len(order) else 0.0
    relaxing = abs(order_trend) > ORDER_TREND_LIMIT or abs(order_geweke) > ORDER_GEWEKE_LIMIT
    drifting = abs(geweke) > GEWEKE_LIMIT or independent < MIN_INDEPENDENT or late or relaxing
    if drifting:
        reasons = []
        if abs(geweke) > GEWEKE_LIMIT:
            reasons.append(f"Z still drifts (Geweke score {geweke:+.1f}: its first 10% against its last 50%)")
        if independent < MIN_INDEPENDENT:
            reasons.append(f"Z holds only {independent:.1f} independent samples (g = {g:.3g} blocks)")
        if late:
            reasons.append("Z only reaches equilibrium in the second half of the run")
        if relaxing:
            reasons.append(
                f"the structure still relaxes: the global psi6 goes from {order[0]:.3g} to {order[-1]:.3g} with "
                f"{order_independent:.1f} independent samples in {len(order)} frames (its trend {order_trend:+.1f} "
                f"standard errors, Geweke {order_geweke:+.1f})"
            )
        msg = (
            f"thermo(): the run over t in [{edges[start]:g}, {edges[-1]:g}] is not a production run at equilibrium: "
            f"{'; '.join(reasons)}. Automated equilibration detection (Chodera 2016) on Z puts the "
            f"start at t = {bounds[found.t0]:g}; pass since='auto' or run longer (Z = {z:.4f} +- {z_err:.4f} is "
            "not trustworthy)"
        )
        warnings.warn(msg, EquilibrationWarning, stacklevel=3)
    return ThermoAverages(
        since=float(edges[start]),
        until=float(edges[-1]),
        blocks=len(z_blocks),
        n=n,
        area=box.area,
        energy=float(energy),
        temperature=float(kt),
        pressure=z * n * kt / box.area,
        pressure_err=z_err * n * kt / box.area,
        z=z,
        z_err=z_err,
        collision_rate=rate,
        collision_rate_err=rate_err,
        collisions=int(collisions[start:].sum()),
        edges=np.asarray(out_edges, dtype=float),
        z_blocks=np.asarray(z_blocks, dtype=float),
        inefficiency=g,
        independent=independent,
        equilibrium_start=float(bounds[found.t0]),
        geweke=geweke,
        drifting=drifting,
        order=order,
        order_independent=order_independent,
        method=method,
    )
