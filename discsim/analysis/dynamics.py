"""Dynamics of a run: mean-squared displacement, self-diffusion, velocity autocorrelation, free times.

Numpy in, numpy out. The mean-squared displacement needs unwrapped positions (each disc followed across
the periodic edges): ``Frames.unwrapped`` from :func:`discsim.frames` or :class:`discsim.Sampler`, or
``sim.trajectory(times, unwrapped=True)``. Free times come from the event log (``sim.events``) or from a
:class:`discsim.Sampler` that collected them during a run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from discsim.errors import InvalidArgumentError
from discsim.events import COLLISION, disc_count, disc_partners

__all__ = ["MSD", "VACF", "FreeTimes", "free_times", "free_times_of", "msd", "vacf"]


def _series(values, times, what: str) -> tuple[np.ndarray, np.ndarray]:
    """``values`` ``(T, N, 2)`` and ``times`` ``(T,)`` checked; times increasing and evenly spaced."""
    try:
        x = np.asarray(values, dtype=float)
        t = np.asarray(times, dtype=float)
    except (TypeError, ValueError) as exc:
        msg = f"{what} needs numeric arrays (T, N, 2) and (T,)"
        raise InvalidArgumentError(msg) from exc
    if x.ndim != 3 or x.shape[2] != 2 or x.shape[1] == 0:
        msg = f"{what}: expected an array of shape (T, N, 2), got shape {x.shape}"
        raise InvalidArgumentError(msg)
    if t.shape != (x.shape[0],):
        msg = f"{what}: times must have shape ({x.shape[0]},) to match the frames, got shape {t.shape}"
        raise InvalidArgumentError(msg)
    if len(t) < 2:
        msg = f"{what} needs at least 2 frames, got {len(t)}"
        raise InvalidArgumentError(msg)
    if not (np.isfinite(x).all() and np.isfinite(t).all()):
        msg = f"{what}: positions, velocities and times must be finite"
        raise InvalidArgumentError(msg)
    step = np.diff(t)
    if not (step > 0).all() or not np.allclose(step, step[0], rtol=1e-9, atol=0.0):
        msg = (
            f"{what} needs evenly spaced, increasing times (every lag is averaged over all time origins); "
            f"got steps from {step.min()!r} to {step.max()!r}"
        )
        raise InvalidArgumentError(msg)
    return x, t


def _autocorrelation(x: np.ndarray) -> np.ndarray:
    """``(T,)`` ``sum over discs and axes of x(t0) . x(t0 + lag)``, averaged over the ``T - lag`` origins (FFT)."""
    t = x.shape[0]
    size = 1 << (2 * t - 1).bit_length()
    spectrum = np.fft.rfft(x, n=size, axis=0)
    power = (spectrum * spectrum.conj()).real
    corr = np.fft.irfft(power, n=size, axis=0)[:t]
    return corr.sum(axis=(1, 2)) / (t - np.arange(t))


@dataclass(frozen=True)
class MSD:
    """A mean-squared displacement (see :func:`msd`).

    Attributes:
        lags: ``(L,)`` time lags, from 0. msd: ``(L,)`` ``<|r(t0 + lag) - r(t0)|^2>`` (length^2), averaged over
            discs and time origins. origins: ``(L,)`` time origins averaged at each lag. n: discs.
    """

    lags: np.ndarray
    msd: np.ndarray
    origins: np.ndarray
    n: int

    def diffusion(self, window: tuple[float, float] | None = None) -> float:
        """The self-diffusion coefficient ``D = slope / 4`` (2D Einstein relation) of a straight-line fit.

        Args:
            window: ``(t_min, t_max)`` lags to fit (length^2 per time); default the second half of the lags.
                The fit should start after the ballistic regime (several mean free times).

        Raises:
            InvalidArgumentError: if the window holds fewer than 2 lags.
        """
        if window is None:
            window = (0.5 * float(self.lags[-1]), float(self.lags[-1]))
        lo, hi = window
        use = (self.lags >= lo) & (self.lags <= hi)
        if use.sum() < 2:
            msg = f"diffusion(): the window {window!r} holds {int(use.sum())} lag(s); a straight line needs 2"
            raise InvalidArgumentError(msg)
        slope = np.polyfit(self.lags[use], self.msd[use], 1)[0]
        return float(slope / 4.0)

    def plot(self, ax=None):
        """The MSD against the lag on log-log axes. Returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        ax.loglog(self.lags[1:], self.msd[1:])
        ax.set_xlabel("lag t")
        ax.set_ylabel("MSD <|r(t) - r(0)|²>")
        return ax


def msd(unwrapped, times, *, max_lag: float | None = None) -> MSD:
    """The mean-squared displacement of unwrapped positions, averaged over discs and all time origins.

    ``MSD(lag) = < |r_i(t0 + lag) - r_i(t0)|^2 >`` over discs ``i`` and origins ``t0`` among the frames, by
    FFT (O(N T log T)). For discs in free flight, ``MSD = v^2 lag^2`` exactly.

    Args:
        unwrapped: ``(T, N, 2)`` positions followed across the periodic edges (``Frames.unwrapped``).
        times: ``(T,)`` evenly spaced, increasing times.
        max_lag: keep lags up to this (default all; the longest lags average few origins).

    Returns:
        :class:`MSD` (``lags``, ``msd``, ``diffusion(window)``, ``plot()``).

    Raises:
        InvalidArgumentError: on arrays of the wrong shape, fewer than 2 frames, or uneven times.

    Example:
        >>> import numpy as np, discsim as ds
        >>> t = np.arange(5.0)
        >>> path = np.array([[0.0, 0.0], [3.0, 4.0]])[None] + np.array([[1.0, 0.0], [0.0, 2.0]]) * t[:, None, None]
        >>> ds.msd(path, t).msd.tolist()  # v^2 = 1 and 4: their mean 2.5 times t^2
        [0.0, 2.5, 10.0, 22.5, 40.0]
    """
    x, t = _series(unwrapped, times, "msd()")
    n = x.shape[1]
    x = x - x.mean(axis=0)  # the MSD does not depend on the origin of coordinates; this helps roundoff
    steps = len(t)
    sq = np.einsum("tnk,tnk->t", x, x)  # |r(t)|^2 summed over discs
    # sum over origins of |r(t0)|^2 + |r(t0 + lag)|^2, for each lag (the standard FFT method)
    total = 2.0 * sq.sum()
    s1 = np.empty(steps)
    for lag in range(steps):
        if lag:
            total -= sq[lag - 1] + sq[steps - lag]
        s1[lag] = total
    s1 /= steps - np.arange(steps)
    values = np.maximum((s1 - 2.0 * _autocorrelation(x)) / n, 0.0)
    values[0] = 0.0
    lags = t - t[0]
    origins = steps - np.arange(steps)
    if max_lag is not None:
        keep = lags <= max_lag
        lags, values, origins = lags[keep], values[keep], origins[keep]
    return MSD(lags, values, origins, n)


@dataclass(frozen=True)
class VACF:
    """A velocity autocorrelation function (see :func:`vacf`).

    Attributes:
        lags: ``(L,)`` time lags. c: ``(L,)`` ``<v(t0) . v(t0 + lag)>`` (velocity^2). normalized: ``c / c[0]``.
        n: discs.
    """

    lags: np.ndarray
    c: np.ndarray
    n: int

    @property
    def normalized(self) -> np.ndarray:
        """``c / c[0]``."""
        return self.c / self.c[0]

    def diffusion(self) -> float:
        """``D = (1/2) * integral of c`` over the lags (Green-Kubo in 2D, trapezoidal rule)."""
        return float(np.sum(0.5 * (self.c[1:] + self.c[:-1]) * np.diff(self.lags)) / 2.0)

    def plot(self, ax=None):
        """``c(lag) / c(0)`` against the lag. Returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        ax.plot(self.lags, self.normalized)
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.set_xlabel("lag t")
        ax.set_ylabel("<v(0)·v(t)> / <v²>")
        return ax


def vacf(velocities, times, *, max_lag: float | None = None) -> VACF:
    """The velocity autocorrelation ``<v_i(t0) . v_i(t0 + lag)>``, averaged over discs and time origins.

    Args:
        velocities: ``(T, N, 2)`` (``Frames.velocities``). times: ``(T,)`` evenly spaced, increasing.
        max_lag: keep lags up to this (default all).

    Returns:
        :class:`VACF` (``c``, ``normalized``, ``diffusion()``, ``plot()``). At lag 0, ``c = <|v|^2> = 2 kT / m``.

    Raises:
        InvalidArgumentError: as :func:`msd`.

    Example:
        >>> import numpy as np, discsim as ds
        >>> v = np.tile([[1.0, 2.0]], (4, 1, 1))  # one disc in free flight: c = |v|^2 at every lag
        >>> ds.vacf(v, np.arange(4.0)).c.tolist()
        [5.0, 5.0, 5.0, 5.0]
    """
    v, t = _series(velocities, times, "vacf()")
    c = _autocorrelation(v) / v.shape[1]
    lags = t - t[0]
    if max_lag is not None:
        keep = lags <= max_lag
        lags, c = lags[keep], c[keep]
    return VACF(lags, c, v.shape[1])


@dataclass(frozen=True)
class FreeTimes:
    """Free times between consecutive collisions of each disc (see :func:`free_times`).

    Attributes:
        times: ``(K,)`` every free time (time units). discs: ``(K,)`` whose.
        mean: their mean (the mean free time; ``1 / collision rate per disc`` in equilibrium).
        walls: whether wall and segment hits counted as collisions.
    """

    times: np.ndarray
    discs: np.ndarray
    walls: bool

    @property
    def mean(self) -> float:
        """The mean free time (NaN if none)."""
        return float(self.times.mean()) if len(self.times) else math.nan

    def histogram(self, bins=50) -> tuple[np.ndarray, np.ndarray]:
        """``(density, edges)``: the probability density of the free times (``numpy.histogram``)."""
        return np.histogram(self.times, bins=bins, density=True)

    def plot(self, ax=None, bins=50):
        """The density of free times on a log scale, with the exponential of the same mean. Returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        density, edges = self.histogram(bins)
        centres = 0.5 * (edges[1:] + edges[:-1])
        ax.semilogy(centres, density, drawstyle="steps-mid", label="free times")
        ax.semilogy(centres, np.exp(-centres / self.mean) / self.mean, "k--", lw=1, label="exponential, same mean")
        ax.set_xlabel("free time")
        ax.set_ylabel("density")
        ax.legend()
        return ax


def _collision_records(events: np.ndarray, masses: np.ndarray | None, walls: bool):
    """``(disc, time)`` of every change of course of a free disc in ``events``, log order kept."""
    kinds = events["kind"] == COLLISION
    if walls:
        kinds = np.ones(len(events), dtype=bool)
    rows = events[kinds]
    pair = disc_partners(rows)
    disc = np.concatenate([rows["i"], rows["j"][pair]])
    time = np.concatenate([rows["time"], rows["time"][pair]])
    seq = np.concatenate([np.arange(len(rows)), np.flatnonzero(pair)])
    if masses is not None and len(disc):
        free = np.isfinite(masses[disc])  # an obstacle never moves: it has no free flight
        disc, time, seq = disc[free], time[free], seq[free]
    order = np.lexsort((seq, time, disc))
    return disc[order], time[order]


def free_times_of(events: np.ndarray, last: np.ndarray, masses=None, walls: bool = False):
    """The free times completed in a chunk of the log, and each disc's last collision after it.

    Args:
        events: a chunk of the log (:data:`~discsim.events.EVENT_DTYPE`, time order).
        last: ``(N,)`` each disc's last collision time before the chunk (NaN: none yet; the flight since the
            start is cut off by the start, so it is not a free time).
        masses: ``(N,)`` (obstacles, of infinite mass, are left out), or None. walls: count wall hits.

    Returns:
        ``(times, discs, starts, last)``: the free times, whose, when each began, and the updated ``last``
        (a new array).
    """
    disc, time = _collision_records(events, masses, walls)
    last = np.array(last, dtype=float)
    if not len(disc):
        return np.zeros(0), np.zeros(0, np.int64), np.zeros(0), last
    first = np.ones(len(disc), dtype=bool)
    first[1:] = disc[1:] != disc[:-1]
    previous = np.empty(len(disc))
    previous[1:] = time[:-1]
    previous[first] = last[disc[first]]
    gaps = time - previous
    keep = np.isfinite(gaps)
    ends = np.append(np.flatnonzero(first)[1:] - 1, len(disc) - 1)
    last[disc[ends]] = time[ends]
    return gaps[keep], disc[keep], previous[keep], last


def free_times(source, *, walls: bool = False, since: float | None = None) -> FreeTimes:
    """Free times between consecutive collisions of each disc, from an event log or a :class:`discsim.Sampler`.

    The flight before a disc's first collision (cut off by the start) and the one after its last (cut off by
    the end) are not free times. Obstacles (infinite mass) are left out.

    Args:
        source: an engine that recorded its log, a structured array of :data:`~discsim.events.EVENT_DTYPE`
            (``sim.events``), or a :class:`discsim.Sampler` built with ``free_times=True``.
        walls: count wall and segment hits as collisions too (default: disc-disc collisions only).
        since: keep only the free times that start after this time (skip an equilibration).

    Returns:
        :class:`FreeTimes` (``times``, ``mean``, ``histogram()``, ``plot()``).

    Raises:
        InvalidArgumentError: if the engine recorded nothing (``record=False``), or the Sampler did not
            collect free times.

    Example:
        >>> import discsim as ds
        >>> sim = ds.EventDriven(*ds.random_gas(300, 0.2, seed=1)).run(until=20.0)
        >>> ft = ds.free_times(sim, since=2.0)
        >>> rate = ds.enskog_collision_rate(0.2)
        >>> bool(abs(ft.mean * rate - 1) < 0.1)
        True
    """
    if hasattr(source, "free_time_values"):
        if source.free_time_values is None:
            msg = "this Sampler did not collect free times: build it with ds.Sampler(dt, free_times=True)"
            raise InvalidArgumentError(msg)
        times, discs, start = source.free_time_values()
        if bool(source.free_time_walls) != bool(walls):
            msg = f"this Sampler collected free times with walls={source.free_time_walls}, asked walls={walls}"
            raise InvalidArgumentError(msg)
    else:
        masses = None
        if isinstance(source, np.ndarray):
            events = source
        else:
            from discsim.analysis.frames import log_source

            chunks, start_discs, _, _, _, _ = log_source(source, "free_times()")
            events = np.concatenate(list(chunks()))
            masses = np.asarray(start_discs.masses, dtype=float)
        n = disc_count(events)
        times, discs, start, _ = free_times_of(events, np.full(n, np.nan), masses, walls)
    if since is not None:
        keep = start > since
        times, discs = times[keep], discs[keep]
    return FreeTimes(times, discs, bool(walls))
