"""Accuracy map: when is PIT good enough? Missed collisions, direction error and delay over step and density.

Run ``python benchmarks/accuracy_map.py`` (several minutes the first time) or ``--quick`` (seconds).

The study concludes that PIT "may be acceptable where the frame rate is high
and the objects are not very small", so that each moves only a little per
frame. This script draws that conclusion as a map. Its two axes:

* the frame step ``s = v dt / r``, how far a disc at the root-mean-square speed
  ``v`` moves in one frame, in radii: 13 values, log-spaced from 0.001 to 10
  (three per decade; the issue asks for 0.01 to 10, and the three smaller
  steps are added because the frame-time policies only reach 1 degree below
  0.01);
* the packing fraction ``eta``: 0.05, 0.1, 0.2, 0.3, 0.45 and 0.6.

Each cell: periodic gases of ``N`` discs from :func:`discsim.random_gas`
(radius 1, mass 1, ``kT = 1/2``, so ``v = 1`` and ``dt = s``), first run under
PIC for 10 collisions per disc so that they forget their lattice start; three
seeds in the full run, pooled (a collision missed early on sends a run off
course and costs several more, so single runs scatter). The horizon ``H`` is
two mean free times ``t_free`` (from Enskog's collision rate,
:func:`discsim.enskog_collision_rate`), rounded up to whole frames (at least
one frame): about two collisions per disc, so that errors have little time to
grow by chaos (at the largest steps one frame is longer, and ``H`` with it).
PIT (each response policy of :class:`discsim.FixedStep`) and PIC run from the
same start; PIT goes on one frame past ``H`` (PIC further), and
:func:`discsim.analysis.compare` judges PIT on PIC's collisions in ``[0, H]``:

* ``missed``: the fraction of PIC's collisions that PIT lacks;
* ``direction error``: mean angle (degrees) between the outgoing velocities of
  the matched collisions in the two runs;
* ``delay``: mean ``|t_PIT - t_PIC|`` over the matched collisions, in mean
  free times ``t_free`` (the CSV also has the signed mean delay in frames).

A cell is *good* when PIT misses at most 1% and its mean direction error is at
most 1 degree; the heat maps outline the good region in white (along the cell
edges: a contour of the good cells), and the printed boundary gives, for each
policy and packing fraction, the largest step ``s`` on the grid such that it
and every smaller step are good. A cell pools about ``3 N`` collisions, so 1%
missed is about a dozen collisions: read the boundary to within a grid step.

``swept`` tests one periodic image per pair, so in a periodic box it refuses
frames whose relative sweeps could reach a second image (``2 v_max dt + 2 r``
at least half the box side): in the full map at ``s = 10`` from packing 0.1 up
and at ``s = 4.6`` from 0.45 up (7 cells), in the quick mode's small boxes at
``s = 10``; those cells are left grey ("refused"), counted as not good.

A PIT run that exceeds the per-cell time budget (the ``swept`` policy at large
steps in dense gases follows thousands of collisions per frame) is stopped and
its cell left grey, counted as not good.

The map is one sweep, :func:`discsim.sweep` of :func:`discsim.tasks.pit_accuracy` over policies x steps x
packing fractions and the seeds 1, 2 and 3, on a local process pool (one worker per core); each task makes
its gas, equilibrates it, runs PIC (the truth, to its own horizon) and PIT, and returns counts and sums that
:func:`pool` adds up over the seeds with pandas. The sweep is cached and resumable: every finished cell and
seed is stored in ``results/cache/accuracy_map/`` (``accuracy_map_quick/`` for ``--quick``), so a rerun
reads the map back in seconds, and a run that was stopped or killed computes only the cells it had not
finished. Delete that folder to measure again (the cache key holds discsim's version, not the commit; cells
over budget are stored as such too). The table has no per-cell PIT time: the tasks return only what repeats
bit for bit; the sweep's wall time is printed.

Output: ``accuracy_map.csv`` (one row per policy and cell),
``accuracy_map_boundary.csv`` and ``accuracy_map.png`` in ``--results``.
The full run takes about seven minutes on two busy cores (load 4-5; eight and a half before it was a
sweep, one gas after another in one process), and seconds once cached.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
from benchutils import Column, format_table, load_average, machine_summary, parse_args, timed, write_csv

import discsim as ds

#: Response policies (those this discsim has), one row of panels each.
POLICIES = tuple(p for p in ("resolve", "revert", "separate", "bisect", "swept") if p in ds.POLICIES)
#: Units (those of :func:`discsim.tasks.pit_accuracy`): radius 1 and kT = 1/2 with mass 1, so the rms speed
#: is 1 and dt = s.
RADIUS = 1.0
TEMPERATURE = 0.5
V_RMS = math.sqrt(2.0 * TEMPERATURE)
#: The good region: at most this missed fraction and this mean direction error (degrees).
MISSED_LIMIT = 0.01
ANGLE_LIMIT = 1.0


@dataclasses.dataclass(frozen=True)
class Config:
    """Grid and run lengths of one mode.

    Attributes:
        n: discs per gas.
        steps: frame steps ``s = v dt / r``.
        fractions: packing fractions.
        free_times: horizon in mean free times (rounded up to whole frames).
        equilibrate_per_disc: PIC collisions per disc before the start.
        policies: PIT response policies.
        budget_s: wall-clock seconds one PIT run may take.
        seeds: one gas per seed and packing fraction; the cells pool them.
    """

    n: int
    steps: tuple[float, ...]
    fractions: tuple[float, ...]
    free_times: float
    equilibrate_per_disc: float
    policies: tuple[str, ...]
    budget_s: float
    seeds: tuple[int, ...]


FULL = Config(
    n=400,
    steps=tuple(np.logspace(-3.0, 1.0, 13).tolist()),
    fractions=(0.05, 0.1, 0.2, 0.3, 0.45, 0.6),
    free_times=2.0,
    equilibrate_per_disc=10.0,
    policies=POLICIES,
    budget_s=40.0,
    seeds=(1, 2, 3),
)
QUICK = Config(
    n=60,
    steps=(0.01, 0.1, 1.0, 10.0),
    fractions=(0.1, 0.45),
    free_times=2.0,
    equilibrate_per_disc=5.0,
    policies=POLICIES,
    budget_s=10.0,
    seeds=(1,),
)


# --- the sweep -------------------------------------------------------------------------------
def grid(config: Config) -> dict:
    """The sweep's grid: every packing fraction, policy and step (the map's rows in that order); the run
    lengths and the budget fixed.
    """
    return {
        "packing_fraction": list(config.fractions),
        "policy": list(config.policies),
        "step": list(config.steps),
        "n": config.n,
        "free_times": config.free_times,
        "equilibrate": config.equilibrate_per_disc,
        "budget": config.budget_s,
    }


def measure_all(config: Config, cache: Path):
    """Every policy, step and packing fraction for every seed (``ds.sweep``, cached): one row per task."""
    return ds.sweep(
        ds.tasks.pit_accuracy, grid(config), seeds=list(config.seeds), cache=cache, retries=1, progress=True
    )


_SUMMED = [
    "frames",
    "pair_tests",
    "truth_collisions",
    "matched",
    "missed",
    "spurious",
    "angle_count",
    "angle_sum",
    "delay_count",
    "abs_delay_sum",
    "delay_sum_frames",
]


def pool(table, config: Config) -> list[dict]:
    """One row of the map per policy, packing fraction and step: its seeds pooled (the sums and counts added).

    Fractions are of all PIC collisions of the seeds together; means are over all matched collisions;
    ``frames`` is per seed. A cell with a seed not measured (over budget, refused, or failed) has no numbers.
    """
    table = table.assign(status=table["status"].where(table["error"].isna(), "failed: " + table["error"]))
    rows = []
    for (eta, policy, step), cells in table.groupby(["packing_fraction", "policy", "step"], sort=False):
        first = cells.iloc[0]
        dt, free_time = step * RADIUS / V_RMS, float(first["free_time"])
        row = {
            "policy": policy,
            "packing_fraction": float(eta),
            "step": float(step),
            "dt": dt,
            "horizon": float(first["horizon"]),
            "free_time": free_time,
            "frames_per_free_time": free_time / dt,
            "seeds": len(cells),
        }
        failed = [status for status in cells["status"] if status != "ok"]
        if failed:
            rows.append({**row, "status": failed[0]})
            continue
        total = {key: float(value) for key, value in cells[_SUMMED].sum().items()}  # plain floats for the CSV
        truth, angles, delays = int(total["truth_collisions"]), int(total["angle_count"]), int(total["delay_count"])
        missed_fraction = total["missed"] / truth if truth else math.nan
        mean_angle = total["angle_sum"] / angles if angles else math.nan
        row.update(
            status="ok",
            frames=int(total["frames"]) // len(cells),
            pair_tests=int(total["pair_tests"]),
            truth_collisions=truth,
            collisions_per_disc=2.0 * truth / (len(cells) * config.n),
            matched=int(total["matched"]),
            missed=int(total["missed"]),
            spurious=int(total["spurious"]),
            missed_fraction=missed_fraction,
            spurious_fraction=total["spurious"] / truth if truth else math.nan,
            mean_direction_error_deg=mean_angle,
            max_direction_error_deg=float(cells.loc[cells["angle_count"] > 0, "angle_max"].max()),
            mean_abs_delay_free_times=total["abs_delay_sum"] / delays / free_time if delays else math.nan,
            mean_delay_frames=total["delay_sum_frames"] / delays if delays else math.nan,
            max_overlap=float(cells["max_overlap"].max()),
            good=bool(missed_fraction <= MISSED_LIMIT and mean_angle <= ANGLE_LIMIT),
        )
        rows.append(row)
    return rows


# --- the answer in numbers -----------------------------------------------------------------
def largest_good_step(rows: list[dict], test) -> tuple[float, float]:
    """The largest step such that it and every smaller step pass ``test``, and the first step that fails.

    Args:
        rows: one policy and packing fraction, any order.
        test: ``row -> bool``; cells not measured fail.

    Returns:
        ``(largest_good, first_bad)``: NaN for ``largest_good`` if the smallest
        step already fails, NaN for ``first_bad`` if every step passes.
    """
    good, bad = math.nan, math.nan
    for row in sorted(rows, key=lambda r: r["step"]):
        if row["status"] == "ok" and test(row):
            good = row["step"]
        else:
            bad = row["step"]
            break
    return good, bad


def boundary(rows: list[dict], config: Config) -> list[dict]:
    """Per policy and packing fraction: where PIT stops being good, by both criteria and by each alone."""

    def missed_ok(r):
        return r["missed_fraction"] <= MISSED_LIMIT

    def angle_ok(r):
        return r["mean_direction_error_deg"] <= ANGLE_LIMIT

    out = []
    for policy in config.policies:
        for eta in config.fractions:
            cells = [r for r in rows if r["policy"] == policy and r["packing_fraction"] == eta]
            good, bad = largest_good_step(cells, lambda r: r["good"])
            out.append(
                {
                    "policy": policy,
                    "packing_fraction": eta,
                    "largest_good_step": good,
                    "first_bad_step": bad,
                    "largest_step_missed_ok": largest_good_step(cells, missed_ok)[0],
                    "largest_step_angle_ok": largest_good_step(cells, angle_ok)[0],
                }
            )
    return out


def describe(good: float, bad: float, steps: tuple[float, ...]) -> str:
    """A boundary as text: ``"0.046"``, ``"< 0.001"`` or ``">= 10"``."""
    if math.isnan(good):
        return f"< {min(steps):.2g}"
    if math.isnan(bad):
        return f">= {good:.2g}"
    return f"{good:.2g}"


def boundary_table(limits: list[dict], config: Config) -> str:
    """Rows: packing fractions; columns: policies; cells: the largest good step."""
    table = []
    for eta in config.fractions:
        line = {"eta": eta}
        for lim in limits:
            if lim["packing_fraction"] == eta:
                line[lim["policy"]] = describe(lim["largest_good_step"], lim["first_bad_step"], config.steps)
        table.append(line)
    return format_table(table, [Column("eta", "eta", ".2f")] + [Column(p, p) for p in config.policies])


def matrix_table(rows: list[dict], policy: str, key: str, scale: float, fmt: str, config: Config) -> str:
    """One quantity for one policy as a table: rows are packing fractions, columns are steps."""
    table = []
    for eta in config.fractions:
        line = {"eta": eta}
        for k, row in enumerate(r for r in rows if r["policy"] == policy and r["packing_fraction"] == eta):
            line[f"s{k}"] = row[key] * scale if row["status"] == "ok" else "over"
        table.append(line)
    columns = [Column("eta", "eta \\ s", ".2f")]
    columns += [Column(f"s{k}", f"{s:.2g}", fmt) for k, s in enumerate(config.steps)]
    return format_table(table, columns)


# --- the picture ---------------------------------------------------------------------------
PANELS = (
    ("missed_fraction", 100.0, "missed collisions (%)", (0.1, 100.0)),
    ("mean_direction_error_deg", 1.0, "mean direction error (deg)", (1e-3, 100.0)),
    ("mean_abs_delay_free_times", 1.0, "mean |delay| / mean free time", (1e-6, 10.0)),
)


def grid_of(rows: list[dict], policy: str, key: str, config: Config) -> np.ndarray:
    """``(len(fractions), len(steps))`` values of ``key`` for ``policy`` (NaN where not measured)."""
    out = np.full((len(config.fractions), len(config.steps)), np.nan)
    for row in rows:
        if row["policy"] == policy and row["status"] == "ok":
            out[config.fractions.index(row["packing_fraction"]), config.steps.index(row["step"])] = row[key]
    return out


def _edges(centres: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges halfway between ``centres`` (in log space if ``log``)."""
    x = np.log10(centres) if log else np.asarray(centres, dtype=float)
    mid = (x[1:] + x[:-1]) / 2.0
    first = x[0] - (mid[0] - x[0]) if len(x) > 1 else x[0] - 0.5
    last = x[-1] + (x[-1] - mid[-1]) if len(x) > 1 else x[-1] + 0.5
    edges = np.concatenate([[first], mid, [last]])
    return 10.0**edges if log else edges


def plot(rows: list[dict], config: Config, path: Path) -> Path:
    """Heat maps: a row of panels per policy (missed, direction error, delay), the good region outlined."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    steps = np.array(config.steps)
    rows_y = np.arange(len(config.fractions), dtype=float)  # packing fractions as equal rows
    x_edges, y_edges = _edges(steps, log=True), _edges(rows_y, log=False)
    policies = config.policies
    fig, axes = plt.subplots(
        len(policies), 3, figsize=(19, 2.9 * len(policies) + 1.0), squeeze=False, constrained_layout=True
    )
    for a, policy in enumerate(policies):
        good = grid_of(rows, policy, "good", config)
        for b, (key, scale, label, limits) in enumerate(PANELS):
            ax = axes[a, b]
            values = grid_of(rows, policy, key, config) * scale
            shown = np.ma.masked_invalid(np.clip(values, *limits))
            ax.set_facecolor("0.8")
            mesh = ax.pcolormesh(x_edges, y_edges, shown, norm=LogNorm(*limits), cmap="viridis")
            fig.colorbar(mesh, ax=ax, label=label)
            _annotate(ax, steps, rows_y, values, mesh.norm)
            _outline(ax, np.nan_to_num(good) > 0.5, x_edges, y_edges)
            ax.set_xscale("log")
            ax.set_title(f"{policy}: {label}", fontsize=10)
            ax.set_xlabel("frame step s = v dt / r")
            ax.set_ylabel("packing fraction")
            ax.set_yticks(rows_y, [f"{eta:g}" for eta in config.fractions])
    fig.suptitle(
        f"PIT against PIC, N={config.n} x {len(config.seeds)} seed(s), horizon {config.free_times:g} mean free times."
        f"\nWhite outline: <= {100 * MISSED_LIMIT:g}% missed and <= {ANGLE_LIMIT:g} deg mean direction error. "
        "Grey: not measured."
    )
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _annotate(ax, steps: np.ndarray, rows_y: np.ndarray, values: np.ndarray, norm) -> None:
    """Write each cell's value in it, briefly, dark on the bright cells."""
    for a, y in enumerate(rows_y):
        for b, s in enumerate(steps):
            value = values[a, b]
            if np.isfinite(value):
                color = "k" if norm(np.clip(value, norm.vmin, norm.vmax)) > 0.6 else "w"
                ax.text(s, y, _brief(value), ha="center", va="center", fontsize=6, color=color)


def _brief(value: float) -> str:
    """A number in at most five characters: ``0``, ``3e-13``, ``0.25``, ``4.6``, ``98``.

    Example:
        >>> [_brief(v) for v in (0.0, 2.7e-13, 0.0046, 0.254, 4.62, 98.2, 100.0)]
        ['0', '3e-13', '5e-3', '0.25', '4.6', '98', '100']
    """
    if value == 0:
        return "0"
    if abs(value) < 0.01:
        mantissa, exponent = f"{value:.0e}".split("e")
        return f"{mantissa}e{int(exponent)}"
    if abs(value) < 10:
        return f"{value:.2g}"
    return f"{value:.0f}"


def _outline(ax, good: np.ndarray, x_edges: np.ndarray, y_edges: np.ndarray) -> None:
    """Draw the border of the good cells along the cell edges (the contour of the good region)."""
    rows, cols = good.shape
    for a in range(rows):
        for b in range(cols):
            if not good[a, b]:
                continue
            x0, x1, y0, y1 = x_edges[b], x_edges[b + 1], y_edges[a], y_edges[a + 1]
            if b == 0 or not good[a, b - 1]:
                ax.plot([x0, x0], [y0, y1], color="w", lw=2.5)
            if b == cols - 1 or not good[a, b + 1]:
                ax.plot([x1, x1], [y0, y1], color="w", lw=2.5)
            if a == 0 or not good[a - 1, b]:
                ax.plot([x0, x1], [y0, y0], color="w", lw=2.5)
            if a == rows - 1 or not good[a + 1, b]:
                ax.plot([x0, x1], [y1, y1], color="w", lw=2.5)


# --- main ----------------------------------------------------------------------------------
CSV_KEYS = [
    "policy",
    "packing_fraction",
    "step",
    "dt",
    "horizon",
    "free_time",
    "frames_per_free_time",
    "seeds",
    "status",
    "frames",
    "pair_tests",
    "truth_collisions",
    "collisions_per_disc",
    "matched",
    "missed",
    "spurious",
    "missed_fraction",
    "spurious_fraction",
    "mean_direction_error_deg",
    "max_direction_error_deg",
    "mean_abs_delay_free_times",
    "mean_delay_frames",
    "max_overlap",
    "good",
]
BOUNDARY_KEYS = [
    "policy",
    "packing_fraction",
    "largest_good_step",
    "first_bad_step",
    "largest_step_missed_ok",
    "largest_step_angle_ok",
]


def report(rows: list[dict], config: Config) -> list[dict]:
    """Print the maps as tables and the boundary; return the boundary rows."""
    for eta in config.fractions:
        mine = [r for r in rows if r["packing_fraction"] == eta]
        per_disc = [r["collisions_per_disc"] for r in mine if r["status"] == "ok"]
        spread = f"{min(per_disc):.2f} to {max(per_disc):.2f}" if per_disc else "-"
        print(
            f"eta={eta:g}: mean free time {mine[0]['free_time']:.4g}; PIC collisions per disc in [0, H]: "
            f"{spread} (over the steps)"
        )
    for policy in config.policies:
        print(f"\n== {policy}: missed collisions (%) ==")
        print(matrix_table(rows, policy, "missed_fraction", 100.0, ".3g", config))
        print(f"-- {policy}: mean direction error (degrees) --")
        print(matrix_table(rows, policy, "mean_direction_error_deg", 1.0, ".3g", config))
        print(f"-- {policy}: mean |delay| (mean free times) --")
        print(matrix_table(rows, policy, "mean_abs_delay_free_times", 1.0, ".2g", config))
    limits = boundary(rows, config)
    print(
        f"\n== boundary: largest s = v dt / r with <= {100 * MISSED_LIMIT:g}% missed and <= {ANGLE_LIMIT:g} deg "
        "mean direction error (at it and every smaller step) =="
    )
    print(boundary_table(limits, config))
    return limits


def main(argv=None) -> int:
    """Measure (or read back) the map, print it, write the CSV files and the PNG; return the exit code."""
    args = parse_args(__doc__.splitlines()[0], argv)
    config = QUICK if args.quick else FULL
    cache = args.results / "cache" / ("accuracy_map_quick" if args.quick else "accuracy_map")
    print(f"discsim {ds.__version__} accuracy map; {machine_summary()}")
    print(
        f"mode: {'quick' if args.quick else 'full'}; periodic gas, N={config.n}, radius {RADIUS:g}, kT={TEMPERATURE:g} "
        f"(v_rms={V_RMS:g}, so dt = s); seeds {list(config.seeds)} pooled; horizon {config.free_times:g} mean free "
        "times in whole frames; "
        f"policies {', '.join(config.policies)}; budget {config.budget_s:g} s per PIT run; cache {cache}",
        flush=True,
    )
    run = timed(lambda: measure_all(config, cache))
    table = run.result
    info = table.attrs["sweep"]
    rows = pool(table, config)
    limits = report(rows, config)
    csv_path = write_csv(args.results / "accuracy_map.csv", rows, CSV_KEYS)
    boundary_path = write_csv(args.results / "accuracy_map_boundary.csv", limits, BOUNDARY_KEYS)
    png = plot(rows, config, args.results / "accuracy_map.png")
    print(
        f"\nsweep of {info['tasks']} tasks on {info['where']}: {info['ran']} ran ({info['task_seconds']:.0f} s in "
        f"them), {info['cached']} from the cache, {info['failed']} failed, {info['retries']} retried; "
        f"{run.wall:.0f} s wall; load average at the end: {load_average():.2f}"
    )
    print(f"wrote {csv_path}, {boundary_path}, {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
