"""A/B instructions per collision of two source trees, counted by valgrind: a noise-free companion to ab_throughput.

Wall-clock rates on a shared machine drift by 10-25% within an hour, which hides a change of a few percent.
Instruction counts do not drift: the same binary, input and hash seed give the same count whatever else the
machine is doing. This script runs the public-API probe of ``ab_throughput.py`` under
``valgrind --tool=callgrind`` for two lengths of the timed segment, K1 and K2 collisions, and divides the
difference of the totals by K2 - K1: set-up, imports and warm-up cancel, and what is left is the event loop's
instructions per collision. Run::

    python benchmarks/ab_instructions.py --base PATH_TO_OTHER_CHECKOUT [--sizes 1000 10000] [--packings 0.3 0.7]
    python benchmarks/ab_instructions.py --base PATH --quick --out DIR

It needs valgrind (Debian's package); under it Python runs about 50 times slower, so the defaults (N = 10^3
and 10^4, packing 0.3 and 0.7, K1 = 20,000 and K2 = 60,000) take about 40 minutes. Instructions are not
seconds: cache misses, which dominate at N = 10^5, do not show here; read this table beside
``ab_throughput.csv``. Writes ``ab_instructions.csv`` under ``--out``. Figures only: nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

from ab_throughput import _PROBE, NEW_TREE, SIDES, tree_label, warmup_collisions
from benchutils import Column, announce, format_table, machine_summary, results_folder, write_csv

FULL = {"sizes": [1_000, 10_000], "packings": [0.3, 0.7], "short": 20_000, "long": 60_000}
QUICK = {"sizes": [200], "packings": [0.3], "short": 500, "long": 1_500}

COLUMNS = [
    Column("n", "N", ",d"),
    Column("packing", "phi", ".2f"),
    Column("base_per_collision", "base instr/coll", ",.0f"),
    Column("new_per_collision", "new instr/coll", ",.0f"),
    Column("ratio", "new/base", ".4f"),
]


def instructions(tree: Path, n: int, packing: float, collisions: int, scratch: Path) -> int:
    """Total instructions (callgrind's ``I refs``) of one probe run of ``tree`` with ``collisions`` timed."""
    workdir = scratch / "cwd"
    workdir.mkdir(parents=True, exist_ok=True)
    # DISCSIM_NO_NUMBA: trees with a compiled backend run their pure-Python loop, which is what is compared
    # (older trees ignore the variable).
    env = dict(
        os.environ,
        PYTHONPATH=str(tree),
        PYTHONPYCACHEPREFIX=str(scratch / "pycache"),
        PYTHONHASHSEED="0",
        DISCSIM_NO_NUMBA="1",
    )
    args = [str(tree), str(n), repr(packing), "1", str(warmup_collisions(n)), str(collisions), "python"]
    # Compile the bytecode first, outside the count, so that no counted run pays for it.
    subprocess.run([sys.executable, "-c", "import discsim"], cwd=workdir, env=env, check=True)
    command = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", sys.executable, "-c", _PROBE]
    done = subprocess.run([*command, *args], cwd=workdir, env=env, capture_output=True, text=True, check=False)
    found = re.search(r"I\s+refs:\s+([\d,]+)", done.stderr)
    if done.returncode or found is None:
        msg = f"the counted run of {tree} at N={n} phi={packing} failed:\n{done.stderr[-2000:]}"
        raise RuntimeError(msg)
    return int(found.group(1).replace(",", ""))


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", type=Path, required=True, help="the other checkout (the folder holding discsim/)")
    parser.add_argument("--sizes", type=int, nargs="+")
    parser.add_argument("--packings", type=float, nargs="+")
    parser.add_argument("--quick", action="store_true", help="a tiny run that proves the script works")
    parser.add_argument("--out", type=Path, help="CSV and PNG folder (default results/; --quick: a temporary one)")
    args = parser.parse_args(argv)
    if shutil.which("valgrind") is None:
        print("valgrind is not installed (apt-get install valgrind); nothing measured", file=sys.stderr)
        return 1
    plan = dict(QUICK if args.quick else FULL)
    plan["sizes"] = args.sizes or plan["sizes"]
    plan["packings"] = args.packings or plan["packings"]
    trees = {"base": args.base.resolve(), "new": NEW_TREE}
    labels = {side: tree_label(tree) for side, tree in trees.items()}
    announce(f"discsim A/B instructions per collision; {machine_summary()}")
    announce(f"base: {trees['base']} ({labels['base']}); new: {trees['new']} ({labels['new']})")
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for n in plan["sizes"]:
            for packing in plan["packings"]:
                row = {"n": n, "packing": packing}
                for side in SIDES:
                    counts = [
                        instructions(trees[side], n, packing, plan[k], Path(scratch) / side) for k in ("short", "long")
                    ]
                    row[f"{side}_per_collision"] = (counts[1] - counts[0]) / (plan["long"] - plan["short"])
                row["ratio"] = row["new_per_collision"] / row["base_per_collision"]
                row.update(base_label=labels["base"], new_label=labels["new"])
                announce(f"  N={n:,} phi={packing}: new/base {row['ratio']:.4f}")
                rows.append(row)
    print(format_table(rows, COLUMNS))
    out = results_folder(args.out, args.quick)
    write_csv(out / "ab_instructions.csv", rows, [*(c.key for c in COLUMNS), "base_label", "new_label"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
