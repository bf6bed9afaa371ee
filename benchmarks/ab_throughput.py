"""A/B throughput of the event-driven engine: collisions/s of two source trees, side by side in one run.

Shows whether a change keeps the engine's speed: the tree this script lives in
("new") against another checkout of discsim ("base"), e.g. a ``git worktree`` of
the commit before a refactor. Run::

    python benchmarks/ab_throughput.py --base PATH_TO_OTHER_CHECKOUT
    python benchmarks/ab_throughput.py --base PATH --sizes 1000 10000 --packings 0.3 --repeats 3 --collisions 200000
    python benchmarks/ab_throughput.py --base PATH --quick --out DIR     # seconds: proves the script runs
    python benchmarks/ab_throughput.py --base PATH --backend numba       # the compiled loop instead
    python benchmarks/ab_throughput.py --base PATH --compile             # numba's first compile and warm start
    python benchmarks/ab_throughput.py --base PATH --engine fixed-step   # FixedStep frames/s (policy resolve)

The defaults (N = 10^3, 10^4, 10^5; packing fractions 0.3 and 0.7; 5 repeats of
300,000 collisions) take about a quarter of an hour.

What one timed run is: a fresh Python process (:func:`measure`) with
``PYTHONPATH`` set to the tree under test and a neutral empty working folder;
it checks that ``discsim.__file__`` lies in that tree (an editable install of
another tree must not win) and fails loudly otherwise. Through the public API
alone, the same for both trees, it builds ``discsim.random_gas(N, phi, seed=s)``
(a periodic box), runs ``EventDriven(discs, box, record=False)`` for
``min(20,000, 2 N)`` collisions to warm up, then times ``sim.run(events=K)``
with ``time.perf_counter``: collisions/s is the growth of
``sim.counts["collisions"]`` over those seconds. Bytecode caches go to a
temporary folder, so neither tree is written to.

Order: repeat by repeat, point by point, base then new on even repeats and new
then base on odd ones (ABBA), so that a slow spell of the machine hits both
sides alike; the two runs of a pair use the same seed (the repeat's number), so
they simulate the same gas.

How to read the table (also ``ab_throughput.csv`` and ``ab_throughput.png`` in ``--out``):

* ``base coll/s``, ``new coll/s``: median collisions per wall-clock second of each tree.
* ``new/base``: median over the repeats of the per-pair ratio new/base; above 1
  the new tree is faster. ``min`` and ``max`` are the extreme pair ratios: the
  noise of this machine. A ratio is within the 3% target when it lies in
  0.97-1.03 (the band of the plot); trust a verdict only when min-max is narrower
  than the band, or repeat with more ``--repeats``.
* ``base_label``, ``new_label`` (CSV): ``git rev-parse --short HEAD`` of each tree,
  with ``+dirty`` when it has uncommitted changes (untracked files included).

Figures only: nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

from benchutils import Column, announce, format_table, machine_summary, median, results_folder, write_csv

#: The tree this script belongs to: the "new" side.
NEW_TREE = Path(__file__).resolve().parent.parent

#: Sizes, packing fractions, repeats and timed collisions of the two modes.
FULL = {"sizes": [1_000, 10_000, 100_000], "packings": [0.3, 0.7], "repeats": 5, "collisions": 300_000}
QUICK = {"sizes": [500], "packings": [0.3], "repeats": 1, "collisions": 20_000}

#: Warm-up before timing: ``WARMUP_PER_DISC`` collisions per disc, at most ``WARMUP_MAX``.
WARMUP_PER_DISC = 2
WARMUP_MAX = 20_000

SIDES = ("base", "new")

#: Run by :func:`measure` in a fresh interpreter; argv: tree, n, phi, seed, warm-up, timed collisions, backend.
#: Prints one JSON line. Public API only, so that it runs unchanged on both trees.
_PROBE = """
import gc, json, sys, time
from pathlib import Path
tree = Path(sys.argv[1]).resolve()
n, phi, seed = int(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])
warmup, collisions, backend = int(sys.argv[5]), int(sys.argv[6]), sys.argv[7]
import discsim
where = Path(discsim.__file__).resolve()
if not where.is_relative_to(tree):
    sys.exit(f"discsim was imported from {where}, not from the tree under test {tree}")
discs, box = discsim.random_gas(n, phi, seed=seed)
sim = discsim.EventDriven(discs, box, record=False, backend=backend)
sim.run(events=warmup)
gc.collect()
before = sim.counts["collisions"]
start = time.perf_counter()
sim.run(events=collisions)
seconds = time.perf_counter() - start
done = sim.counts["collisions"] - before
print(json.dumps({"discsim_file": str(where), "collisions": done, "seconds": seconds,
                  "collisions_per_s": done / seconds}))
"""


#: ``--engine fixed-step``: the same, for FixedStep frames (policy ``resolve``, the ``grid`` broad phase, no
#: log, ``dt = FRAME_DT``); "collisions" are frames here, and ``collisions_per_s`` frames per second.
_FRAME_PROBE = (
    _PROBE.replace(
        "sim = discsim.EventDriven(discs, box, record=False, backend=backend)",
        "sim = discsim.FixedStep(discs, box, dt=float(sys.argv[8]), record=False, backend=backend)",
    )
    .replace("sim.run(events=", "sim.run(frames=")
    .replace('sim.counts["collisions"]', "sim.counts['frames']")
)
#: Time step of the fixed-step probe: about 1% of a diameter per frame at kT = 1 (unit masses and radii).
FRAME_DT = 0.01


#: Run by :func:`start_seconds` in a fresh interpreter: seconds to import discsim, build a compiled engine of 100
#: discs and process its first event (the compile, or the load of the machine code from numba's cache).
_START_PROBE = """
import sys, time
start = time.perf_counter()
import discsim
sim = discsim.EventDriven(*discsim.random_gas(100, 0.3, seed=1), backend="numba")
sim.step()
print(time.perf_counter() - start)
"""


def start_seconds(tree: Path, cache: Path, scratch: Path) -> float:
    """Seconds of one :data:`_START_PROBE` run of ``tree`` with numba's cache in ``cache`` (empty: a cold start)."""
    env = dict(
        os.environ, PYTHONPATH=str(tree), PYTHONPYCACHEPREFIX=str(scratch / "pycache"), NUMBA_CACHE_DIR=str(cache)
    )
    env.pop("DISCSIM_NO_NUMBA", None)
    done = subprocess.run([sys.executable, "-c", _START_PROBE], cwd=scratch, env=env, capture_output=True, text=True)
    if done.returncode:
        msg = f"the start of {tree} failed:\n{done.stderr}"
        raise RuntimeError(msg)
    return float(done.stdout.split()[-1])


def compile_pairs(base: Path, repeats: int, scratch: Path) -> list[dict]:
    """Cold and warm starts of both trees, alternating; one row per kind of start (medians and pair ratios)."""
    trees = {"base": base, "new": NEW_TREE}
    seconds: dict[tuple[str, str], list[float]] = {(kind, side): [] for kind in ("cold", "warm") for side in SIDES}
    for repeat in range(repeats):
        for side in SIDES if repeat % 2 == 0 else SIDES[::-1]:
            cache = Path(tempfile.mkdtemp(dir=scratch))
            seconds["cold", side].append(start_seconds(trees[side], cache, scratch))
            seconds["warm", side].append(start_seconds(trees[side], cache, scratch))
            announce(
                f"  repeat {repeat + 1}/{repeats} {side}: cold {seconds['cold', side][-1]:.2f} s, "
                f"warm {seconds['warm', side][-1]:.2f} s"
            )
    rows = []
    for kind in ("cold", "warm"):
        ratios = [n / b for n, b in zip(seconds[kind, "new"], seconds[kind, "base"])]
        rows.append(
            {
                "start": kind,
                "repeats": repeats,
                "base_seconds": median(seconds[kind, "base"]),
                "new_seconds": median(seconds[kind, "new"]),
                "ratio_median": median(ratios),
                "ratio_min": min(ratios),
                "ratio_max": max(ratios),
            }
        )
    return rows


COMPILE_COLUMNS = [
    Column("start", "start"),
    Column("repeats", "repeats"),
    Column("base_seconds", "base s", ".2f"),
    Column("new_seconds", "new s", ".2f"),
    Column("ratio_median", "new/base", ".3f"),
    Column("ratio_min", "min", ".3f"),
    Column("ratio_max", "max", ".3f"),
]


def warmup_collisions(n: int) -> int:
    """Untimed collisions before the timed segment for ``n`` discs."""
    return min(WARMUP_MAX, WARMUP_PER_DISC * n)


def measure(
    tree: Path,
    n: int,
    packing: float,
    seed: int,
    collisions: int,
    scratch: Path,
    backend: str = "python",
    engine: str = "event-driven",
) -> dict:
    """One timed run of the tree ``tree`` in a fresh Python process.

    Args:
        tree: the source tree (the folder that holds the ``discsim`` package).
        n: number of discs. packing: packing fraction of the periodic random gas.
        seed: seed of :func:`discsim.random_gas`.
        collisions: collisions in the timed segment.
        scratch: a temporary folder; the run's working folder and bytecode cache go under it.
        backend: ``"python"`` (numba hidden) or ``"numba"`` (the compiled loop, from the tree's own cache of
            machine code: the warm-up pays any compile, outside the timed segment).
        engine: ``"event-driven"`` (collisions) or ``"fixed-step"`` (frames: ``collisions`` is a frame count).

    Returns:
        The probe's dict: ``discsim_file``, ``collisions`` (timed), ``seconds``, ``collisions_per_s``.

    Raises:
        RuntimeError: if the run fails or imported discsim from elsewhere than ``tree``.
    """
    workdir = scratch / "cwd"
    workdir.mkdir(exist_ok=True)
    # DISCSIM_NO_NUMBA: with backend "python", trees with a compiled backend run their pure-Python loop.
    env = dict(os.environ, PYTHONPATH=str(tree), PYTHONPYCACHEPREFIX=str(scratch / "pycache"), PYTHONHASHSEED="0")
    env.pop("DISCSIM_NO_NUMBA", None)
    if backend == "python":
        env["DISCSIM_NO_NUMBA"] = "1"
    warmup = warmup_collisions(n) if engine == "event-driven" else 5
    args = [str(tree), str(n), repr(packing), str(seed), str(warmup), str(collisions), backend, repr(FRAME_DT)]
    probe = _PROBE if engine == "event-driven" else _FRAME_PROBE
    done = subprocess.run(
        [sys.executable, "-c", probe, *args], cwd=workdir, env=env, capture_output=True, text=True, check=False
    )
    if done.returncode:
        msg = f"the timed run of {tree} at N={n} phi={packing} seed={seed} failed:\n{done.stderr}"
        raise RuntimeError(msg)
    result = json.loads(done.stdout.splitlines()[-1])
    if not Path(result["discsim_file"]).resolve().is_relative_to(tree.resolve()):
        msg = f"the timed run of {tree} imported discsim from {result['discsim_file']}"
        raise RuntimeError(msg)
    return result


def tree_label(tree: Path) -> str:
    """``git rev-parse --short HEAD`` of ``tree``, plus ``+dirty`` when it has uncommitted changes.

    ``unknown`` when ``tree`` is not a git checkout (or git is missing).
    """
    try:
        head = subprocess.run(
            ["git", "-C", str(tree), "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=False
        )
        status = subprocess.run(
            ["git", "-C", str(tree), "status", "--porcelain"], capture_output=True, text=True, check=False
        )
    except OSError:
        return "unknown"
    if head.returncode or status.returncode:
        return "unknown"
    return head.stdout.strip() + ("+dirty" if status.stdout.strip() else "")


def summarise(pairs: list[dict], n: int, packing: float) -> dict:
    """One table row from the pairs of one point (each a dict with ``base`` and ``new`` collisions/s)."""
    ratios = [p["new"] / p["base"] for p in pairs]
    return {
        "n": n,
        "packing": packing,
        "repeats": len(pairs),
        "base_median": median([p["base"] for p in pairs]),
        "new_median": median([p["new"] for p in pairs]),
        "ratio_median": median(ratios),
        "ratio_min": min(ratios),
        "ratio_max": max(ratios),
    }


COLUMNS = [
    Column("n", "N", ","),
    Column("packing", "phi", ".2f"),
    Column("repeats", "repeats"),
    Column("base_median", "base coll/s", ",.0f"),
    Column("new_median", "new coll/s", ",.0f"),
    Column("ratio_median", "new/base", ".3f"),
    Column("ratio_min", "min", ".3f"),
    Column("ratio_max", "max", ".3f"),
]
CSV_KEYS = [c.key for c in COLUMNS] + ["base_label", "new_label", "backend"]


def run_pairs(base: Path, options: dict, scratch: Path) -> list[dict]:
    """Every timed run, interleaved ABBA over the repeats; one summary row per (N, phi)."""
    trees = {"base": base, "new": NEW_TREE}
    points = [(n, phi) for n in options["sizes"] for phi in options["packings"]]
    pairs = {point: [] for point in points}
    for repeat in range(options["repeats"]):
        order = SIDES if repeat % 2 == 0 else SIDES[::-1]
        for n, phi in points:
            rates = {}
            for side in order:
                result = measure(
                    trees[side], n, phi, repeat, options["collisions"], scratch, options["backend"], options["engine"]
                )
                rates[side] = result["collisions_per_s"]
            ratio = rates["new"] / rates["base"]
            announce(
                f"  repeat {repeat + 1}/{options['repeats']} N={n:,} phi={phi:g} ({' then '.join(order)}): "
                f"base {rates['base']:,.0f}, new {rates['new']:,.0f} {options['rate']}, new/base {ratio:.3f}"
            )
            pairs[n, phi].append(rates)
    return [summarise(pairs[point], *point) for point in points]


def plot(rows: list[dict], path: Path, title: str) -> Path:
    """The median ratio new/base against N, one series per packing fraction, min-max error bars, a 0.97-1.03 band."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4), constrained_layout=True)
    ax.axhspan(0.97, 1.03, color="0.85", label="target: within 3%")
    ax.axhline(1.0, color="0.5", linewidth=1)
    fractions = sorted({r["packing"] for r in rows})
    for k, phi in enumerate(fractions):
        series = [r for r in rows if r["packing"] == phi]
        shift = 1.06 ** (k - (len(fractions) - 1) / 2)  # side by side at each N, on the log axis
        ratios = [r["ratio_median"] for r in series]
        ax.errorbar(
            [r["n"] * shift for r in series],
            ratios,
            yerr=[
                [m - r["ratio_min"] for m, r in zip(ratios, series)],
                [r["ratio_max"] - m for m, r in zip(ratios, series)],
            ],
            marker="o",
            linestyle="none",
            capsize=3,
            label=f"phi={phi:g}",
        )
    low = min([0.95] + [r["ratio_min"] - 0.01 for r in rows])
    high = max([1.05] + [r["ratio_max"] + 0.01 for r in rows])
    ax.set(xscale="log", ylim=(low, high), xlabel="N discs", ylabel="collisions/s new / base (median, min-max)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command line; options left out take the values of :data:`FULL`, or of :data:`QUICK` with ``--quick``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", type=Path, required=True, help="the other checkout (the folder holding discsim/)")
    parser.add_argument("--sizes", type=int, nargs="+", help=f"numbers of discs N (default {FULL['sizes']})")
    parser.add_argument("--packings", type=float, nargs="+", help=f"packing fractions (default {FULL['packings']})")
    parser.add_argument("--repeats", type=int, help=f"pairs of runs per point (default {FULL['repeats']})")
    parser.add_argument("--collisions", type=int, help=f"timed collisions per run (default {FULL['collisions']:,})")
    parser.add_argument("--quick", action="store_true", help=f"{QUICK}: proves the script runs")
    parser.add_argument("--out", type=Path, help="CSV and PNG folder (default results/; --quick: a temporary one)")
    parser.add_argument(
        "--backend", choices=("python", "numba"), default="python", help="the event loop compared (default python)"
    )
    parser.add_argument(
        "--compile", action="store_true", help="time numba's cold and warm starts instead (--repeats pairs)"
    )
    parser.add_argument(
        "--engine",
        choices=("event-driven", "fixed-step"),
        default="event-driven",
        help="EventDriven collisions/s (default) or FixedStep frames/s (--collisions counts frames then)",
    )
    args = parser.parse_args(argv)
    defaults = QUICK if args.quick else FULL
    for key, value in defaults.items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    if not (args.base / "discsim" / "__init__.py").is_file():
        parser.error(f"--base {args.base} holds no discsim/__init__.py")
    args.base = args.base.resolve()
    for key in ("repeats", "collisions"):
        if getattr(args, key) < 1:
            parser.error(f"--{key} must be at least 1, got {getattr(args, key)}")
    if min(args.sizes) < 1:
        parser.error(f"--sizes must be at least 1, got {min(args.sizes)}")
    args.out = results_folder(args.out, args.quick)
    return args


def main(argv: Sequence[str] | None = None) -> int:
    """Run every pair, print the table, write ``ab_throughput.csv`` and ``ab_throughput.png``; return the exit code."""
    args = parse_args(argv)
    if args.compile:
        return compile_main(args)
    options = {key: getattr(args, key) for key in (*FULL, "backend", "engine")}
    options["rate"] = "coll/s" if args.engine == "event-driven" else "frames/s"
    labels = {"base_label": tree_label(args.base), "new_label": tree_label(NEW_TREE), "backend": args.backend}
    print(f"discsim A/B throughput; {machine_summary()}")
    print(f"base: {args.base} ({labels['base_label']}); new: {NEW_TREE} ({labels['new_label']})")
    if args.base == NEW_TREE:
        print("base and new are the same tree: the ratios show the noise alone")
    print(
        f"{options['collisions']:,} timed collisions per run, after min({WARMUP_MAX:,}, {WARMUP_PER_DISC} N) "
        f"to warm up; {options['repeats']} pair(s) per point, ABBA order, each run in a fresh process"
    )
    with tempfile.TemporaryDirectory(prefix="ab_throughput_") as scratch:
        rows = run_pairs(args.base, options, Path(scratch))
    for row in rows:
        row.update(labels)
    columns = [Column(c.key, c.title.replace("coll/s", options["rate"]), c.fmt) for c in COLUMNS]
    print(format_table(rows, columns))
    stem = "ab_throughput" if args.engine == "event-driven" else "ab_throughput_frames"
    stem = stem if args.backend == "python" else f"{stem}_{args.backend}"
    csv_path = write_csv(args.out / f"{stem}.csv", rows, CSV_KEYS)
    engine = "EventDriven" if args.engine == "event-driven" else "FixedStep"
    title = f"discsim {engine} ({args.backend}): {labels['new_label']} / {labels['base_label']}"
    png = plot(rows, args.out / f"{stem}.png", title)
    print(f"wrote {csv_path}, {png}")
    return 0


def compile_main(args: argparse.Namespace) -> int:
    """``--compile``: the cold and warm starts table, ``ab_throughput_compile.csv``."""
    labels = {"base_label": tree_label(args.base), "new_label": tree_label(NEW_TREE)}
    print(f"discsim A/B start of the compiled backend; {machine_summary()}")
    print(f"base: {args.base} ({labels['base_label']}); new: {NEW_TREE} ({labels['new_label']})")
    print("import + build 100 discs + first event, fresh processes; cold: an empty numba cache, warm: the same again")
    with tempfile.TemporaryDirectory(prefix="ab_compile_") as scratch:
        rows = compile_pairs(args.base, args.repeats, Path(scratch))
    for row in rows:
        row.update(labels)
    print(format_table(rows, COMPILE_COLUMNS))
    path = write_csv(args.out / "ab_throughput_compile.csv", rows, [c.key for c in COMPILE_COLUMNS] + list(labels))
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
