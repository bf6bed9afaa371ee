"""The event-driven engine's two backends side by side: pure Python against compiled (numba).

Run ``python benchmarks/backends.py`` (about 20 minutes) or ``--quick`` (a minute). Also a section of
``benchmarks/throughput.py``.

For each point (N, packing fraction, monodisperse or a 1:10 radius mixture), a seeded periodic gas is
built, equilibrated for one collision per disc, then timed over a fixed number of collisions, in a fresh
Python process per run (``measure_fresh``); the two backends alternate run by run (python, numba, python,
numba, ...) so that a slow spell of a shared machine hits both alike. Figures, as printed and written to
``backends.csv``:

* ``coll/s``: disc-disc collisions of the timed segment per wall-clock second, median over the runs, for
  each backend, and ``numba/python``, the ratio of the medians (the issue's target: 20x at N = 10^4,
  packing 0.3; 15x at 10^5 and 10^6).
* ``mix/mono``: the 1:10 mixture's rate over the monodisperse gas's at the same N and packing (target: at
  least 0.5 with the compiled backend).
* ``B/disc``: bytes of the compiled backend's state arrays per disc (``NumbaBackend.nbytes() / N``;
  target: at most 150).

A second table, ``backends_compile.csv``: seconds to build an engine and run its first event in a fresh
process, with an empty numba cache (``NUMBA_CACHE_DIR`` a new folder: what the first run in a fresh
environment costs) and then with that cache warm, twice: as this environment is, and with scipy hidden
(``scipy: hidden``), as in an environment of ``pip install "discsim[fast]"``, which has no scipy. When scipy
is installed, numba's first compilation or cache load imports ``scipy.linalg`` to look for a BLAS (0.25 s,
and 0.13 s more of ``numpy.f2py`` that scipy's import pulls in); the test extra brings scipy (through
freud), the fast extra does not.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from benchutils import Column, call_fresh, format_table, machine_summary, median, parse_args, write_csv

import discsim as ds


@dataclass(frozen=True)
class Point:
    """One measurement point."""

    n: int
    packing_fraction: float
    mixture: bool
    #: Collisions timed per backend (the Python backend gets fewer at large N: it is 20x slower).
    collisions: dict


FULL = [
    Point(1_000, 0.3, False, {"python": 200_000, "numba": 2_000_000}),
    Point(10_000, 0.3, False, {"python": 200_000, "numba": 3_000_000}),
    Point(10_000, 0.7, False, {"python": 200_000, "numba": 3_000_000}),
    Point(10_000, 0.3, True, {"python": 100_000, "numba": 2_000_000}),
    Point(100_000, 0.3, False, {"python": 200_000, "numba": 3_000_000}),
    Point(100_000, 0.3, True, {"python": 100_000, "numba": 2_000_000}),
    Point(1_000_000, 0.3, False, {"python": 300_000, "numba": 3_000_000}),
]
QUICK = [
    Point(1_000, 0.3, False, {"python": 5_000, "numba": 50_000}),
    Point(1_000, 0.3, True, {"python": 5_000, "numba": 50_000}),
]
BACKENDS = ("python", "numba")


def mixture(n: int, packing_fraction: float, seed: int) -> tuple[ds.Discs, ds.Box]:
    """A periodic 1:10 radius mixture: 10% of the discs of radius 10, the rest of radius 1, unit masses.

    The large discs sit on a square lattice, the small ones on a fine lattice in the space between
    (random sites); velocities are Gaussian (kT = 1) with zero total momentum.
    """
    rng = np.random.default_rng(seed)
    n_big = n // 10
    k = int(np.ceil(np.sqrt(n_big)))
    side = float(np.sqrt(np.pi * (n_big * 100.0 + (n - n_big)) / packing_fraction))
    lattice = (np.arange(k) + 0.5) * (side / k)
    big = np.array([(x, y) for x in lattice for y in lattice])[rng.permutation(k * k)[:n_big]]
    m = int(side / 2.2)
    spacing = side / m
    fine = (np.arange(m) + 0.5) * spacing
    sites = np.column_stack([np.repeat(fine, m), np.tile(fine, m)])  # site ix * m + iy is (fine[ix], fine[iy])
    # A site is taken when a large disc's centre is within 11.05 of it: test each large disc against the
    # window of sites around it only (O(N), not O(N^2): seconds at N = 10^5).
    reach = np.arange(-int(np.ceil(11.05 / spacing)) - 1, int(np.ceil(11.05 / spacing)) + 2)
    near = np.floor(big / spacing).astype(np.int64)
    ix = (near[:, 0, None, None] + reach[None, :, None]) % m
    iy = (near[:, 1, None, None] + reach[None, None, :]) % m
    window = (ix * m + iy).reshape(len(big), -1)
    d = sites[window] - big[:, None, :]
    d -= side * np.round(d / side)
    free = np.ones(len(sites), dtype=bool)
    free[window[(d**2).sum(-1) <= 11.05**2]] = False
    small = sites[free][rng.permutation(int(free.sum()))[: n - n_big]]
    radii = np.r_[np.full(n_big, 10.0), np.ones(n - n_big)]
    velocities = rng.normal(size=(n, 2))
    velocities -= velocities.mean(axis=0)
    return ds.Discs(np.vstack([big, small]), velocities, radii), ds.Box(side, side, periodic=True)


def measure(n: int, packing_fraction: float, mixed: bool, backend: str, collisions: int, seed: int) -> dict:
    """Build, equilibrate (one collision per disc) and time ``collisions`` collisions of one backend."""
    import time

    if mixed:
        discs, box = mixture(n, packing_fraction, seed)
    else:
        discs, box = ds.random_gas(n, packing_fraction, periodic=True, seed=seed)
    sim = ds.EventDriven(discs, box, record=False, backend=backend)
    sim.run(events=n)
    before = sim.counts["collisions"]
    start = time.perf_counter()
    sim.run(events=collisions)
    seconds = time.perf_counter() - start
    row = {"collisions": sim.counts["collisions"] - before, "seconds": seconds}
    if backend == "numba":
        row["bytes_per_disc"] = sim._backend.nbytes() / n
    return row


def measure_fresh(**args) -> dict:
    """:func:`measure` in a fresh Python process."""
    return call_fresh("backends", "measure", **args)


def backends_section(points: list[Point], repeats: int, results: Path) -> list[dict]:
    """Time every point under both backends (alternating, fresh processes); print and write the table."""
    rows = []
    mono_rate = {}
    for point in points:
        runs = {b: [] for b in BACKENDS}
        for seed in range(repeats):
            for backend in BACKENDS:
                runs[backend].append(
                    measure_fresh(
                        n=point.n,
                        packing_fraction=point.packing_fraction,
                        mixed=point.mixture,
                        backend=backend,
                        collisions=point.collisions[backend],
                        seed=seed,
                    )
                )
        rates = {b: [r["collisions"] / r["seconds"] for r in runs[b]] for b in BACKENDS}
        row = {
            "n": point.n,
            "packing_fraction": point.packing_fraction,
            "discs": "1:10 mixture" if point.mixture else "monodisperse",
            "python_rate": median(rates["python"]),
            "numba_rate": median(rates["numba"]),
            "numba_min": min(rates["numba"]),
            "numba_max": max(rates["numba"]),
            "bytes_per_disc": runs["numba"][0]["bytes_per_disc"],
            "runs": repeats,
        }
        row["speedup"] = row["numba_rate"] / row["python_rate"]
        if not point.mixture:
            mono_rate[point.n, point.packing_fraction] = row["numba_rate"]
        rows.append(row)
    for row in rows:
        mono = mono_rate.get((row["n"], row["packing_fraction"]))
        row["mix_over_mono"] = row["numba_rate"] / mono if row["discs"] != "monodisperse" and mono else float("nan")
    columns = [
        Column("n", "N"),
        Column("packing_fraction", "packing", ".2f"),
        Column("discs", "discs"),
        Column("python_rate", "python coll/s", ",.0f"),
        Column("numba_rate", "numba coll/s", ",.0f"),
        Column("speedup", "numba/python", ".1f"),
        Column("mix_over_mono", "mix/mono", ".2f"),
        Column("bytes_per_disc", "B/disc", ".0f"),
    ]
    print(format_table(rows, columns))
    keys = [
        "n",
        "packing_fraction",
        "discs",
        "python_rate",
        "numba_rate",
        "numba_min",
        "numba_max",
        "speedup",
        "mix_over_mono",
        "bytes_per_disc",
        "runs",
    ]
    write_csv(results / "backends.csv", rows, keys)
    return rows


_COMPILE_PROBE = """
import sys
import time
start = time.perf_counter()
if sys.argv[1:] == ["hidden"]:
    sys.modules["scipy"] = None  # imports of scipy fail, as when it is not installed
import discsim as ds
sim = ds.EventDriven(*ds.random_gas(100, 0.3, seed=1), backend="numba")
sim.step()
print(time.perf_counter() - start)
"""


def compile_section(repeats: int, results: Path) -> list[dict]:
    """Seconds to import discsim, build an engine and process one event: cold numba cache, then warm.

    Warm runs alternate with scipy visible and hidden (see the module docstring).
    """
    rows = []
    states = (("cold", "visible"), ("warm", "visible"), ("warm", "hidden"), ("warm", "visible"), ("warm", "hidden"))
    for attempt in range(repeats):
        with tempfile.TemporaryDirectory() as cache:
            env = {**os.environ, "NUMBA_CACHE_DIR": cache}
            for state, scipy in states:
                done = subprocess.run(
                    [sys.executable, "-c", _COMPILE_PROBE, scipy],
                    capture_output=True,
                    text=True,
                    env=env,
                    check=True,
                )
                seconds = float(done.stdout.split()[-1])
                rows.append({"cache": state, "scipy": scipy, "attempt": attempt, "seconds": seconds})
    summary = [
        {
            "cache": state,
            "scipy": scipy,
            "seconds": median([r["seconds"] for r in rows if (r["cache"], r["scipy"]) == (state, scipy)]),
        }
        for state, scipy in dict.fromkeys(states)
    ]
    columns = [
        Column("cache", "numba cache"),
        Column("scipy", "scipy"),
        Column("seconds", "import+build+1 event s", ".2f"),
    ]
    print(format_table(summary, columns))
    write_csv(results / "backends_compile.csv", rows, ["cache", "scipy", "attempt", "seconds"])
    return rows


def main(argv=None) -> int:
    args = parse_args(__doc__.splitlines()[0], argv)
    points = QUICK if args.quick else FULL
    repeats = args.repeats or (1 if args.quick else 3)
    print(f"discsim {ds.__version__} backends; {machine_summary()}")
    print("\n== Collisions per second, python against numba ==")
    backends_section(points, repeats, args.results)
    print("\n== Compile time of the numba backend ==")
    compile_section(1 if args.quick else 3, args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
