"""Averages of a run at constant pressure (a :class:`discsim.Piston` on top of the box): the mean area, packing
fraction and compressibility factor, with error bars.

A piston run samples the isobaric ensemble of the gas plus the piston (at fixed total energy): the pressure ``P`` is
given, the area ``A(t) = w H(t)`` fluctuates. The piston's path is exact between its impacts (it falls at
``F / M``), and each impact's record in the log holds its height and velocity after (``yj``, ``vyj``), so the time
averages of ``A`` and of the discs' kinetic energy ``K`` are integrals of known pieces (a cubic for ``A``; ``K``
changes only at impacts, by what the piston's kinetic energy gains or loses). The compressibility factor at fixed
pressure is ``Z = P <A> / (N kT)`` with ``kT = <K> / N`` (a box with walls: ``2N`` degrees of freedom), comparable
with the one at fixed volume (:func:`discsim.thermo`) at the mean packing fraction.

The span is cut into blocks; the error bars come from the series' statistical inefficiency, as :func:`discsim.thermo`
does (:mod:`discsim.analysis.equilibration`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from discsim.analysis.equilibration import detect_equilibration, statistical_inefficiency
from discsim.errors import InvalidArgumentError, TimeError
from discsim.events import ADD, EVENT_DTYPE, REMOVE, SET, WALL
from discsim.physics.sources.piston import at

__all__ = ["IsobaricAverages", "isobaric"]

#: The most blocks of the series, and the fewest piston impacts per block.
SERIES_POINTS = 1000
BLOCK_HITS = 10


@dataclass(frozen=True)
class IsobaricAverages:
    """Averages of a run at constant pressure over ``[since, until]``, with error bars.

    Attributes:
        since, until: the span averaged (time units). n: discs. pressure: the piston's (force per length).
        area, area_err: the mean area ``w <H>`` (length^2) and its standard error.
        packing, packing_err: ``sum(pi r^2) / <A>`` and its standard error.
        energy: the discs' mean kinetic energy ``<K>``. temperature: ``kT = <K> / N``.
        z, z_err: ``Z = P <A> / (N kT)`` and its standard error.
        hits: the piston's impacts in the span. blocks: the blocks of the series. edges ``(blocks + 1,)``: their
        bounds. area_blocks, z_blocks ``(blocks,)``: each block's mean area and ``Z``. inefficiency: the
        statistical inefficiency of ``z_blocks``. independent: ``blocks / inefficiency``.
    """

    since: float
    until: float
    n: int
    pressure: float
    area: float
    area_err: float
    packing: float
    packing_err: float
    energy: float
    temperature: float
    z: float
    z_err: float
    hits: int
    blocks: int
    edges: np.ndarray
    area_blocks: np.ndarray
    z_blocks: np.ndarray
    inefficiency: float
    independent: float

    def __str__(self) -> str:
        return (
            f"at P = {self.pressure:.6g}: area {self.area:.6g} +- {self.area_err:.2g}, packing {self.packing:.5f} +- "
            f"{self.packing_err:.5f}, Z = {self.z:.4f} +- {self.z_err:.4f} (t in [{self.since:g}, {self.until:g}], "
            f"{self.hits} piston impacts, {self.blocks} blocks, g = {self.inefficiency:.3g})"
        )

    def plot(self, ax=None):
        """The area of each block against time, with the mean and its error band. Returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        ax.stairs(self.area_blocks, self.edges, label="blocks")
        ax.axhline(self.area, color="k", lw=1, label=f"<A> = {self.area:.5g} ± {self.area_err:.2g}")
        ax.axhspan(self.area - self.area_err, self.area + self.area_err, color="k", alpha=0.15)
        ax.set_xlabel("time")
        ax.set_ylabel("area A = w H")
        ax.legend()
        return ax


def isobaric(sim, since: float | str | None = None) -> IsobaricAverages:
    """The averages of ``sim``, an :class:`~discsim.EventDriven` run with a piston that kept its log (in memory, or
    streamed with ``run(record_to=...)``: read back chunk by chunk, only the piston's impacts and the edits kept),
    from ``since`` on (``"auto"``: from the start of production that automated equilibration detection finds in the
    series of ``Z``; None: from the piston's first impact). :func:`discsim.thermo` calls it for a piston run.

    Raises:
        InvalidArgumentError: if ``sim`` has no piston or recorded no log, or the piston was never hit.
        TimeError: if ``since`` lies outside the span the log can follow: before the piston's first impact, or
            before a change of the pressure (``set_piston``) or of the discs (``set_velocities``, ``add_discs`` ...).
    """
    piston = getattr(sim, "piston", None)
    if piston is None:
        msg = "isobaric() needs a run with a piston (EventDriven(..., piston=ds.Piston(...)))"
        raise InvalidArgumentError(msg)
    laws = getattr(sim, "laws", None)
    if laws is not None and laws.falls:
        msg = (
            f"isobaric() averages a gas that keeps its kinetic energy between the piston's impacts; under gravity "
            f"{laws.gravity} it does not (sample it with ds.Sampler(dt) and sim.piston instead)"
        )
        raise InvalidArgumentError(msg)
    from discsim.analysis.frames import _log_source

    chunks = _log_source(sim, "isobaric()")[0]  # (refuses a run that recorded nothing, saying how to record)
    kept = []
    for records in chunks():
        keep = ((records["kind"] == WALL) & np.isfinite(records["yj"])) | np.isin(records["kind"], (SET, ADD, REMOVE))
        kept.append(records[keep])
    events = np.concatenate(kept) if kept else np.zeros(0, dtype=EVENT_DTYPE)
    hits = events[(events["kind"] == WALL) & np.isfinite(events["yj"])]
    if len(hits) < 2:
        msg = f"the piston was hit {len(hits)} time(s): run longer"
        raise InvalidArgumentError(msg)
    mass, width, now = piston.mass, sim.box.width, sim.time
    accel = 0.0 if mass == math.inf else piston.pressure * width / mass
    t, h, u = (np.asarray(hits[name], dtype=float) for name in ("time", "yj", "vyj"))
    # Where the path from each impact puts the piston at the next: a mismatch is a change (set_piston); edits of the
    # discs change their energy: the log is followed from the last of either.
    gap = t[1:] - t[:-1]
    reached, u_before = at(h[:-1], u[:-1], accel, gap)  # type: ignore[arg-type]  # (elementwise)
    broken = np.flatnonzero(~np.isclose(reached, h[1:], rtol=1e-9, atol=1e-12 * (1.0 + abs(h).max())))
    start = float(t[broken[-1] + 1]) if len(broken) else float(t[0])
    changed = float(getattr(piston, "since", 0.0))  # the last set_piston: its first impact after on, or none yet
    if changed > start:
        start = float(t[np.searchsorted(t, changed, side="left")]) if changed <= t[-1] else now
    edited = events["time"][np.isin(events["kind"], (SET, ADD, REMOVE))]
    if len(edited) and edited.max() >= start:
        start = float(t[np.searchsorted(t, edited.max(), side="right")]) if edited.max() < t[-1] else now
    auto = isinstance(since, str) and since == "auto"
    first = start if since is None or auto else float(since)
    if not (start <= first < now):
        msg = (
            f"since={since!r}: the log follows the piston from its first impact after the last change of the "
            f"pressure or the discs, at {start!r}, to the end of the run at {now!r}"
        )
        raise TimeError(msg)
    # The discs' kinetic energy after each impact, back from now: each impact took from them what it gave the piston.
    kinetic = np.empty(len(t))
    kinetic[-1] = sim.kinetic_energy()
    gained = 0.5 * mass * (u[1:] ** 2 - u_before**2) if mass != math.inf else np.zeros(len(t) - 1)
    kinetic[:-1] = kinetic[-1] + np.cumsum(gained[::-1])[::-1]
    span_hits = int(np.count_nonzero((t >= first) & (t <= now)))
    n_blocks = int(np.clip(span_hits // BLOCK_HITS, 2, SERIES_POINTS))
    edges = np.linspace(first, now, n_blocks + 1)
    area_int, kin_int = _integrals(edges, t, h, u, kinetic, accel)
    dt = np.diff(edges)
    area_blocks = width * np.diff(area_int) / dt
    kin_blocks = np.diff(kin_int) / dt
    z_blocks = piston.pressure * area_blocks / kin_blocks
    if auto:
        skip = detect_equilibration(z_blocks).t0
        edges, area_blocks, kin_blocks, z_blocks = edges[skip:], area_blocks[skip:], kin_blocks[skip:], z_blocks[skip:]
        first = float(edges[0])
    n = len(sim.discs)
    area = float(np.average(area_blocks, weights=np.diff(edges)))
    energy = float(np.average(kin_blocks, weights=np.diff(edges)))
    g = max(statistical_inefficiency(z_blocks), statistical_inefficiency(area_blocks))
    count = len(z_blocks)
    area_err = float(np.std(area_blocks, ddof=1) * math.sqrt(g / count))
    z = piston.pressure * area / energy
    z_err = float(np.std(z_blocks, ddof=1) * math.sqrt(g / count))
    covered = float(np.sum(np.pi * sim.discs.radii**2))
    return IsobaricAverages(
        since=first,
        until=float(now),
        n=n,
        pressure=float(piston.pressure),
        area=area,
        area_err=area_err,
        packing=covered / area,
        packing_err=covered / area * area_err / area,
        energy=energy,
        temperature=energy / n,
        z=float(z),
        z_err=z_err,
        hits=span_hits,
        blocks=count,
        edges=edges,
        area_blocks=area_blocks,
        z_blocks=z_blocks,
        inefficiency=float(g),
        independent=count / g,
    )


def _integrals(times, t, h, u, kinetic, accel):
    """``(integral of H, integral of K)`` from ``t[0]`` to each of ``times`` (all at or after ``t[0]``), over the
    piston's path from each impact ``(t, h, u)`` and the discs' kinetic energy after it."""
    gap = np.diff(t)
    pieces_h = h[:-1] * gap + 0.5 * u[:-1] * gap**2 - accel * gap**3 / 6.0
    cumulative_h = np.concatenate([[0.0], np.cumsum(pieces_h)])
    cumulative_k = np.concatenate([[0.0], np.cumsum(kinetic[:-1] * gap)])
    k = np.clip(np.searchsorted(t, times, side="right") - 1, 0, len(t) - 1)
    s = times - t[k]
    area = cumulative_h[k] + h[k] * s + 0.5 * u[k] * s**2 - accel * s**3 / 6.0
    return area, cumulative_k[k] + kinetic[k] * s
