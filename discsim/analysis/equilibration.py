"""Correlation time and the start of equilibrium of a time series: numpy in, numbers out.

The statistical inefficiency ``g = 1 + 2 sum_t (1 - t/T) C(t)`` of a series of ``T`` samples (``C`` its
normalised autocorrelation, summed up to its first zero after ``t = 3``) is the number of samples per
independent one (W. Janke, in *Quantum Simulations of Complex Many-Body Systems*, NIC 10, 423 (2002);
J. D. Chodera et al., J. Chem. Theory Comput. 3, 26 (2007)), so the mean of the series has the variance
``var(x) g / T``. The start of the production run is the ``t0`` that maximises the number of independent
samples left after it, ``N_eff(t0) = (T - t0 + 1) / g(t0)`` (J. D. Chodera, J. Chem. Theory Comput. 12, 1799
(2016)): an unequilibrated start drifts, which lengthens the apparent correlation of the whole series and
costs more than the samples it takes away. Both follow ``pymbar.timeseries`` (``statisticalInefficiency``
with ``fast=False, mintime=3``, and ``detectEquilibration``) to roundoff, without depending on it.

Whether what is left still drifts is judged by Geweke's diagnostic (J. Geweke, in *Bayesian Statistics 4*,
169 (1992)): the means of its first 10% and its last 50% compared in units of their standard errors (each
from its own ``g``); a series at equilibrium gives a standard normal score. A slow, steady drift of a
few samples (the order of a structure still relaxing) is judged by the least-squares slope over its standard
error, the residuals' variance inflated by their statistical inefficiency (the effective sample size of a
regression on autocorrelated data; e.g. B. D. Santer et al., J. Geophys. Res. 105, 7337 (2000)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Equilibration", "detect_equilibration", "geweke_score", "statistical_inefficiency", "trend_score"]

#: The lag up to which the autocorrelation is summed even where it dips below zero (pymbar's ``mintime``).
MIN_LAG = 3


def statistical_inefficiency(x) -> float:
    """The statistical inefficiency ``g >= 1`` of the series ``x`` ``(T,)``: samples per independent sample.

    ``g = 1 + 2 sum_{t=1}^{t_c} (1 - t/T) C(t)``, with ``C(t)`` the autocorrelation at lag ``t`` and ``t_c``
    the lag before the first ``C(t) <= 0`` beyond ``t = 3``; a constant series (or one of fewer than 2
    samples) gives 1. Computed from one FFT.

    Example:
        >>> import numpy as np
        >>> white = np.random.default_rng(0).normal(size=2000)
        >>> round(statistical_inefficiency(np.repeat(white, 5)), 2)  # blocks of 5 equal samples: g near 5
        4.97
    """
    a = np.asarray(x, dtype=float)
    t = len(a)
    if t < 2:
        return 1.0
    d = a - a.mean()
    variance = float(np.dot(d, d)) / t
    if variance <= 0.0:
        return 1.0
    size = 1 << (2 * t - 1).bit_length()
    spectrum = np.fft.rfft(d, size)
    sums = np.fft.irfft(spectrum * np.conj(spectrum), size)[1:t]  # sum_k d_k d_{k+lag}, lag = 1 .. T-1
    lags = np.arange(1, t)
    c = sums / ((t - lags) * variance)
    stop = np.flatnonzero((c <= 0.0) & (lags > MIN_LAG))
    cut = int(stop[0]) if len(stop) else t - 1
    g = 1.0 + 2.0 * float(np.sum(c[:cut] * (1.0 - lags[:cut] / t)))
    return max(g, 1.0)


@dataclass(frozen=True)
class Equilibration:
    """The start of production of a series (Chodera 2016).

    Attributes:
        t0: the index of the first production sample. g: the statistical inefficiency of ``x[t0:]``.
        n_eff: the independent samples in ``x[t0:]``, ``(T - t0 + 1) / g``.
        g_all, n_eff_all: the same for the whole series (``t0 = 0``).
    """

    t0: int
    g: float
    n_eff: float
    g_all: float
    n_eff_all: float


def detect_equilibration(x, nskip: int = 1) -> Equilibration:
    """The start ``t0`` of the production part of ``x`` ``(T,)`` that maximises ``N_eff = (T - t0 + 1) / g(t0)``.

    Args:
        x: the series, in time order (``T >= 2`` samples).
        nskip: try every ``nskip``-th start only (faster on long series).

    Example:
        >>> import numpy as np
        >>> rng = np.random.default_rng(0)
        >>> drift = np.concatenate([np.linspace(5.0, 0.0, 200), np.zeros(800)]) + rng.normal(size=1000)
        >>> 150 < detect_equilibration(drift).t0 < 250
        True
    """
    a = np.asarray(x, dtype=float)
    t = len(a)
    starts = np.arange(0, max(t - 1, 1), max(1, int(nskip)))
    g = np.array([statistical_inefficiency(a[s:]) for s in starts])
    n_eff = (t - starts + 1) / g
    best = int(np.argmax(n_eff))
    return Equilibration(int(starts[best]), float(g[best]), float(n_eff[best]), float(g[0]), float(n_eff[0]))


def geweke_score(x, first: float = 0.1, last: float = 0.5) -> float:
    """Geweke's score of ``x``: (mean of the first ``first`` - mean of the last ``last``) over their combined
    standard error, each from its own statistical inefficiency. About standard normal at equilibrium; 0 for a
    series too short (under 20 samples) or constant."""
    a = np.asarray(x, dtype=float)
    t = len(a)
    if t < 20:
        return 0.0
    head, tail = a[: max(2, int(first * t))], a[t - max(2, int(last * t)) :]

    def variance_of_mean(part: np.ndarray) -> float:
        return float(np.var(part, ddof=1)) * statistical_inefficiency(part) / len(part)

    spread = math.sqrt(variance_of_mean(head) + variance_of_mean(tail))
    if spread == 0.0:
        return 0.0
    return float((head.mean() - tail.mean()) / spread)


def trend_score(x) -> float:
    """The least-squares slope of ``x`` ``(T,)`` against its index over its standard error, the residuals'
    variance inflated by their statistical inefficiency. About standard normal at equilibrium; large for a steady
    drift; 0 for fewer than 3 samples or a series on a straight line with no scatter.

    Example:
        >>> import numpy as np
        >>> noise = np.random.default_rng(1).normal(size=100)
        >>> abs(trend_score(noise)) < 3, trend_score(noise + np.linspace(3.0, 0.0, 100)) < -5
        (True, True)
    """
    a = np.asarray(x, dtype=float)
    t = len(a)
    if t < 3:
        return 0.0
    index = np.arange(t) - (t - 1) / 2.0
    spread = float(np.dot(index, index))
    slope = float(np.dot(index, a - a.mean())) / spread
    residuals = a - a.mean() - slope * index
    variance = float(np.dot(residuals, residuals)) / (t - 2) * statistical_inefficiency(residuals) / spread
    if variance <= 0.0:
        return 0.0
    return slope / math.sqrt(variance)
