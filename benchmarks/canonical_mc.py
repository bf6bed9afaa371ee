"""An independent canonical (NVT) hard-disc Monte Carlo, to check the pressure discsim's event-driven runs give.

Run ``python benchmarks/canonical_mc.py`` (about ten minutes on two cores) or ``--quick`` (seconds).

Event-driven molecular dynamics samples the microcanonical ensemble at fixed total momentum: ``2N - 2``
degrees of freedom in a periodic box, so ``kT = K / (N - 1)``, not ``K / N``. This script checks that
:func:`discsim.thermo` turns such a run into the canonical ``beta P`` at small ``N``, where the two readings
differ by many error bars, against a sampler that shares nothing with discsim's engines: plain Metropolis
Monte Carlo (single-disc moves, uniform in a square of side ``2 delta``, tuned to about 40% acceptance during
the warm-up; M. P. Allen and D. J. Tildesley, *Computer Simulation of Liquids*, 2nd ed., chapter 4), with
the pressure from the pair distances just outside contact (the virtual-compression estimator of
R. Eppenga and D. Frenkel, Mol. Phys. 52, 1303 (1984)):

    Z = beta P A / N = 1 + C'(0) / (2 N),

where ``C(x)`` is the mean number of pairs at distances in ``[sigma, sigma (1 + x)]``: compressing the box
by a fraction ``xi`` brings ``C(xi / 2)`` pairs into overlap, and ``beta P = d ln Q / dA``. ``C`` is
histogrammed after every sweep (``N`` attempted moves) in bins of width ``x_max / bins`` and ``C'(0)`` is the
slope at 0 of a cubic through the origin fitted to the cumulative histogram; ``x_max`` is varied to show the
fit's own systematic error is below the statistical one. The error bar is from batch means over ``blocks``
consecutive batches of sweeps (each thousands of sweeps long, many correlation times of the pressure).
The only thing taken from discsim is the start (``ds.random_gas``'s jittered lattice), which the warm-up
melts.

Output: ``canonical_mc.csv`` in ``--results``: per ``(N, packing)`` the Monte Carlo ``Z`` and its error, the
event-driven ``Z`` from :func:`discsim.thermo` (the canonical estimate) and the naive ``1 + W / (2 t K)``
(``kT = K / N``), each with its error bar and its distance from the Monte Carlo value in combined sigmas.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit

import discsim as ds

#: The reference points of issue 29: (N, packing fraction).
POINTS = ((72, 0.65), (224, 0.67))
QUICK_POINTS = ((30, 0.60),)


@njit(cache=True)
def _overlaps(x, i, xi, yi, side, sigma2):
    n = x.shape[0]
    half = 0.5 * side
    for j in range(n):
        if j == i:
            continue
        dx = x[j, 0] - xi
        dy = x[j, 1] - yi
        if dx > half:
            dx -= side
        elif dx < -half:
            dx += side
        if dy > half:
            dy -= side
        elif dy < -half:
            dy += side
        if dx * dx + dy * dy < sigma2:
            return True
    return False


@njit(cache=True)
def _sweeps(x, side, sigma, delta, sweeps, x_max, bins, hist, seed):
    """``sweeps`` Metropolis sweeps of ``x`` (in place); adds each sweep's near-contact pair histogram to
    ``hist`` (bins of ``x_max / bins`` in ``r / sigma - 1``) when ``bins > 0``. Returns the acceptance."""
    np.random.seed(seed)  # noqa: NPY002 (numba compiles the legacy generator only, one per thread)
    n = x.shape[0]
    sigma2 = sigma * sigma
    reach = sigma * (1.0 + x_max)
    reach2 = reach * reach
    half = 0.5 * side
    accepted = 0
    for _ in range(sweeps):
        for _move in range(n):
            i = np.random.randint(n)  # noqa: NPY002
            xi = x[i, 0] + delta * (2.0 * np.random.random() - 1.0)  # noqa: NPY002
            yi = x[i, 1] + delta * (2.0 * np.random.random() - 1.0)  # noqa: NPY002
            xi -= side * math.floor(xi / side)
            yi -= side * math.floor(yi / side)
            if not _overlaps(x, i, xi, yi, side, sigma2):
                x[i, 0] = xi
                x[i, 1] = yi
                accepted += 1
        if bins > 0:
            for i in range(n - 1):
                for j in range(i + 1, n):
                    dx = x[j, 0] - x[i, 0]
                    dy = x[j, 1] - x[i, 1]
                    if dx > half:
                        dx -= side
                    elif dx < -half:
                        dx += side
                    if dy > half:
                        dy -= side
                    elif dy < -half:
                        dy += side
                    r2 = dx * dx + dy * dy
                    if r2 < reach2:
                        k = int((math.sqrt(r2) / sigma - 1.0) / x_max * bins)
                        if 0 <= k < bins:
                            hist[k] += 1.0
    return accepted / (sweeps * n)


def contact_slope(hist: np.ndarray, x_max: float, samples: int, fit_max: float | None = None) -> float:
    """``C'(0)``: the slope at contact of the mean cumulative pair count ``C(x)``, from a cubic through the origin
    fitted to the histogram ``hist`` (``(bins,)`` counts summed over ``samples``) up to ``fit_max``."""
    bins = len(hist)
    edges = np.linspace(0.0, x_max, bins + 1)[1:]
    cumulative = np.cumsum(hist) / samples
    keep = edges <= (fit_max if fit_max is not None else x_max) + 1e-12
    x = edges[keep]
    design = np.stack([x, x**2, x**3], axis=1)
    coefficients, *_ = np.linalg.lstsq(design, cumulative[keep], rcond=None)
    return float(coefficients[0])


def canonical_z(
    n: int,
    packing: float,
    sweeps: int,
    warmup: int,
    blocks: int = 40,
    x_max: float = 0.04,
    bins: int = 40,
    seed: int = 1,
) -> dict:
    """``Z = beta P A / N`` of ``n`` hard discs of diameter 2 at ``packing`` by Metropolis Monte Carlo.

    Returns a dict: ``z``, ``z_err`` (batch means over ``blocks``), ``z_fit_half`` (the fit over ``x_max / 2``:
    a check of the extrapolation), ``acceptance``, ``delta``, ``sweeps``, ``seconds``.
    """
    discs, box = ds.random_gas(n, packing, seed=seed)
    x = np.array(discs.positions, dtype=float)
    side = float(box.width)
    sigma = 2.0 * float(discs.radii[0])
    delta = 0.1 * sigma
    empty = np.zeros(1)
    begin = time.perf_counter()
    for k in range(20):  # warm-up, tuning delta towards 40% acceptance
        acceptance = _sweeps(x, side, sigma, delta, max(1, warmup // 20), x_max, 0, empty, seed * 1000 + k)
        delta *= min(2.0, max(0.5, acceptance / 0.4))
    per_block = max(1, sweeps // blocks)
    hists = np.zeros((blocks, bins))
    accepted = []
    for b in range(blocks):
        accepted.append(_sweeps(x, side, sigma, delta, per_block, x_max, bins, hists[b], seed * 1000 + 100 + b))
    seconds = time.perf_counter() - begin
    z_blocks = np.array([1.0 + contact_slope(h, x_max, per_block) / (2 * n) for h in hists])
    total = hists.sum(axis=0)
    z = 1.0 + contact_slope(total, x_max, per_block * blocks) / (2 * n)
    z_half = 1.0 + contact_slope(total, x_max, per_block * blocks, fit_max=x_max / 2) / (2 * n)
    return {
        "z": z,
        "z_err": float(np.std(z_blocks, ddof=1) / math.sqrt(blocks)),
        "z_fit_half": z_half,
        "acceptance": float(np.mean(accepted)),
        "delta": delta,
        "sweeps": per_block * blocks,
        "seconds": seconds,
    }


def event_driven_z(n: int, packing: float, collisions_per_disc: float, seed: int = 1) -> dict:
    """The event-driven ``Z`` at ``(n, packing)``: :func:`discsim.thermo` (canonical) and the naive ``kT = K/N``."""
    sim = ds.EventDriven(*ds.random_gas(n, packing, seed=seed), backend="auto")
    sim.run(until=1.0)
    rate = sim.counts["collisions"] * 2 / n  # collisions per disc per unit time
    until = collisions_per_disc / rate
    begin = time.perf_counter()
    sim.run(until=until)
    seconds = time.perf_counter() - begin
    since = until / 10
    t = ds.thermo(sim, since=since)
    # The reading with kT = K / N (what discsim gave before issue 29): the same virial, over N instead of N - 1.
    naive = 1.0 + (t.z - 1.0) * t.n / (t.n - 1)
    return {
        "z_md": t.z,
        "z_md_err": t.z_err,
        "z_naive": naive,
        "z_naive_err": t.z_err * t.n / (t.n - 1),
        "md_collisions_per_disc": 2 * sim.counts["collisions"] / n,
        "md_seconds": seconds,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a tiny run that only shows the script works")
    parser.add_argument("--results", type=Path, default=Path(__file__).parent / "results")
    parser.add_argument("--sweeps", type=int, default=400_000, help="Monte Carlo sweeps per point")
    parser.add_argument("--collisions", type=float, default=100_000, help="event-driven collisions per disc")
    args = parser.parse_args(argv)
    points = QUICK_POINTS if args.quick else POINTS
    sweeps, warmup, collisions = (4000, 1000, 2000) if args.quick else (args.sweeps, 20_000, args.collisions)
    rows = []
    args.results.mkdir(parents=True, exist_ok=True)
    cache_path = args.results / "cache" / "canonical_mc.json"
    cache = json.loads(cache_path.read_text()) if cache_path.exists() else {}
    for n, packing in points:
        key = f"n={n} packing={packing} sweeps={sweeps} warmup={warmup}"
        mc = cache[key] if key in cache and not args.quick else canonical_z(n, packing, sweeps, warmup)
        if not args.quick:  # the Monte Carlo shares nothing with discsim's engines: keep it across edits of those
            cache[key] = mc
            cache_path.parent.mkdir(parents=True, exist_ok=True)
            cache_path.write_text(json.dumps(cache, indent=1))
        md = event_driven_z(n, packing, collisions)
        row = {"n": n, "packing": packing, **mc, **md}
        for name in ("md", "naive"):
            row[f"{name}_sigmas"] = (row[f"z_{name}"] - mc["z"]) / math.hypot(row[f"z_{name}_err"], mc["z_err"])
        rows.append(row)
        print(
            f"N = {n:4d}, packing {packing:.2f}: MC Z = {mc['z']:.4f} +- {mc['z_err']:.4f} "
            f"(fit to x_max/2: {mc['z_fit_half']:.4f}; {mc['sweeps']:,} sweeps, {mc['seconds']:.0f} s); "
            f"thermo Z = {md['z_md']:.4f} +- {md['z_md_err']:.4f} ({row['md_sigmas']:+.1f} sigma); "
            f"kT = K/N: {md['z_naive']:.4f} ({row['naive_sigmas']:+.1f} sigma)",
            flush=True,
        )
    path = args.results / ("canonical_mc_quick.csv" if args.quick else "canonical_mc.csv")
    keys = list(rows[0])
    with open(path, "w") as handle:
        handle.write(",".join(keys) + "\n")
        for row in rows:
            handle.write(",".join(f"{row[k]:.6g}" if isinstance(row[k], float) else str(row[k]) for k in keys) + "\n")
    print(f"written to {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
