"""Ready-made initial conditions.

:func:`random_gas` makes seeded, non-overlapping gases at a chosen packing
fraction. The study's four PIT failure cases and other set pieces live here too.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.errors import PackingError
from discsim.state import Box, Discs

__all__ = ["random_gas"]

#: Densest packing fraction a triangular lattice reaches in a square box here.
_MAX_PACKING = 0.85


def _lattice(n: int, side: float, radius: float, periodic: bool, rng: np.random.Generator):
    """``n`` sites of a near-triangular lattice in a square of ``side``, and their spacing."""
    rows = max(2, math.ceil(math.sqrt(n * 2.0 / math.sqrt(3.0))))
    if periodic and rows % 2:
        rows += 1  # an even number of rows keeps the staggering consistent across the wrap
    cols = max(1, math.ceil(n / rows))
    while cols * rows < n:
        cols += 1
    if periodic:
        ax, ay = side / cols, side / rows
        x0, y0 = 0.25 * ax, 0.5 * ay
    else:
        inner = side - 2.0 * radius
        ax = inner / (cols - 0.5) if cols > 1 else inner
        ay = inner / (rows - 1)
        x0 = y0 = radius
    jj, ii = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    x = x0 + (ii + 0.5 * (jj % 2)) * ax
    y = y0 + jj * ay
    sites = np.column_stack([x.ravel(), y.ravel()])
    spacing = min(ax, math.hypot(0.5 * ax, ay)) if cols > 1 else ay
    if not periodic and cols == 1:
        spacing = ay
    chosen = np.sort(rng.choice(len(sites), size=n, replace=False))
    return sites[chosen], spacing


def random_gas(
    n: int,
    packing_fraction: float,
    periodic: bool = True,
    seed: int | None = 0,
    temperature: float = 1.0,
    radius: float = 1.0,
    mass: float = 1.0,
):
    """A gas of ``n`` equal discs in a square box at a given packing fraction.

    Discs start on randomly occupied, randomly jittered sites of a triangular
    lattice (so even dense gases start without overlaps), with Gaussian
    velocities shifted to zero total momentum and scaled so that the kinetic
    energy is exactly ``n * temperature`` (2D equipartition, ``kT`` units).
    A dense start is a crystal; let it run a few collisions per disc to melt.

    Args:
        n: number of discs (>= 1).
        packing_fraction: ``n pi r^2 / area``, in ``(0, 0.85]``.
        periodic: periodic box (True) or reflecting walls.
        seed: seed of ``numpy.random.default_rng``; the same seed gives the same gas.
        temperature: ``kT`` in energy units (positive).
        radius: disc radius (length units). mass: disc mass.

    Returns:
        ``(discs, box)``.

    Raises:
        PackingError: if the packing fraction is not in ``(0, 0.85]`` or the
            lattice cannot hold ``n`` discs without overlap in that box.

    Example:
        >>> discs, box = random_gas(100, 0.3, seed=1)
        >>> len(discs), round(discs.kinetic_energy(), 9), bool(abs(discs.momentum()).max() < 1e-12)
        (100, 100.0, True)
    """
    if int(n) != n or n < 1:
        msg = f"n must be a positive integer, got {n!r}"
        raise ValueError(msg)
    n = int(n)
    if not (0.0 < packing_fraction <= _MAX_PACKING):
        msg = f"packing fraction {packing_fraction!r} cannot be reached: it must lie in (0, {_MAX_PACKING}]"
        raise PackingError(msg)
    if not (temperature > 0 and math.isfinite(temperature)):
        msg = f"temperature must be positive and finite, got {temperature!r}"
        raise ValueError(msg)
    rng = np.random.default_rng(seed)
    side = math.sqrt(n * math.pi * radius**2 / packing_fraction)
    if not periodic and side < 2.0 * radius:
        msg = f"packing fraction {packing_fraction!r} cannot be reached with {n} disc(s) in a walled box"
        raise PackingError(msg)
    positions, spacing = _lattice(n, side, radius, periodic, rng)
    slack = spacing - 2.0 * radius
    if slack < 1e-9 * radius:
        msg = (
            f"packing fraction {packing_fraction!r} cannot be reached for n={n} "
            f"({'periodic' if periodic else 'walled'} box): lattice spacing {spacing:.6g} < diameter {2 * radius:g}"
        )
        raise PackingError(msg)
    jitter = 0.49 * slack / math.sqrt(2.0)
    positions = positions + rng.uniform(-jitter, jitter, size=positions.shape)
    if periodic:
        positions = np.mod(positions, side)
    else:
        positions = np.clip(positions, radius, side - radius)
    velocities = rng.normal(0.0, math.sqrt(temperature / mass), size=(n, 2))
    if n > 1:
        velocities -= velocities.mean(axis=0)
    energy = 0.5 * mass * float(np.sum(velocities**2))
    if energy > 0:
        velocities *= math.sqrt(n * temperature / energy)
    return Discs(positions, velocities, radius, mass), Box(side, side, periodic=periodic)
