"""Event counts: the work PIC and PIT do for the same simulated time, and what PIT's work buys.

Run ``python benchmarks/event_counts.py`` (a few minutes) or ``--quick`` (seconds).

Scenarios. Two seeded random gases of ``N`` equal discs in a box with
reflecting walls (not periodic, so wall hits count too), a dilute one
(packing fraction 0.05) and a dense one (0.5), each first run under PIC for
10 collisions per disc so that it forgets its lattice start; and the study's
four cases (:func:`discsim.study_cases`), each from its own start.

Units. Gases: radius ``r = 1``, mass 1, ``kT = 450``, so the root-mean-square
speed is ``v = sqrt(2 kT / m) = 30`` and the frame step ``s = v dt / r`` runs
from 2 (15 frames per unit time: a disc moves two radii per frame) down to
0.031 (960 frames per unit time). The study cases keep their own units; there
``s`` uses the rms speed of the moving discs and the smallest radius, and the
case's own frame rate (5 or 10) runs as well as the seven common ones.

Horizon ``H``. Gases: two mean free times (Enskog's collision rate,
:func:`discsim.enskog_collision_rate`), rounded up to whole frames at 15 per
unit time, so that every frame rate ends on a frame at ``H`` (the dense gas:
one frame at 15 fps, about five collisions per disc). Study cases: the
scenario's ``until``. Every engine runs from the same start to ``H``; its
counts and wall-clock time are taken there. Then each run goes on for two more
frames (PIC for two frames of the slowest rate) and :func:`discsim.analysis.compare`
judges PIT against PIC on the collisions PIC has in ``[0, H]`` (the extra
frames let PIT report a collision just before ``H`` late instead of missing it).

Columns. PIC: ``collisions`` (disc-disc), ``wall hits``, ``crossings``
(cell-grid crossings), ``stale`` (invalidated events popped), ``predictions``
(discs re-predicted). PIT: ``frames``, ``pair tests`` (narrow-phase pair
checks), ``detections`` (pairs that got an impulse), ``wall hits``.
``work units`` counts "one disc checked against its cell neighbourhood": one
per PIC prediction, and ``N`` per PIT frame (every disc is moved and tested
each frame; the sub-frame policies' extra tests show in ``pair tests``).
``seconds``: wall-clock of building the engine and running it to ``H`` with
the event log kept (median of the repeats, a fresh engine each time); the
``x PIC`` columns divide by PIC's.
What the work buys, over PIC's collisions in ``[0, H]``: ``missed %`` and
``spurious %`` (per PIC collision), the mean and largest ``|delay|`` of the
matched collisions (time units; ``delay/dt`` in the CSV), the mean and largest
direction error of the outgoing velocities (degrees), the largest position
error at the frame times up to ``H`` (in radii), the deepest overlap up to
``H`` (fraction of the contact distance) and the relative change of kinetic
energy at ``H``. The PIC row's accuracy columns compare PIC against a second
PIC run with the other event queue (``queue="heap"``): the reference is
reproducible.

The frame rates double from one to the next, so their frame times nest: a
contact just before a frame of a slow rate is found at that same frame by the
faster ones, and their errors can be equal (the study's ``missed_collision``
and ``delay`` cases from 240 fps on). In ``wrong_direction`` a frame at 30 fps
and faster falls exactly on the contact, so ``resolve`` is exact there.

All five response policies run; the main table shows ``resolve``, a second
one puts the policies side by side. Output: ``event_counts.csv`` (every row
and column) and ``event_counts.png`` in ``--results``.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
from benchutils import (
    Column,
    announce,
    format_table,
    load_average,
    machine_summary,
    median,
    parse_args,
    timed,
    write_csv,
)

import discsim as ds

#: The issue's frame rates (frames per unit of simulated time).
FRAME_RATES = (15, 30, 60, 120, 240, 480, 960)
#: Response policies, in the order shown (those this discsim has).
POLICIES = tuple(p for p in ("resolve", "revert", "separate", "bisect", "swept") if p in ds.POLICIES)
#: Gas units: radius, and kT giving an rms speed of 30 (2D, mass 1: <v^2> = 2 kT).
RADIUS = 1.0
V_RMS = 30.0
TEMPERATURE = V_RMS**2 / 2.0
#: Frames run past the horizon before comparing (see the module docstring).
MARGIN_FRAMES = 2


@dataclasses.dataclass(frozen=True)
class Config:
    """Sizes and run lengths of one mode.

    Attributes:
        n: discs in each random gas.
        fractions: packing fractions of the gases.
        free_times: the gases' horizon in mean free times (before rounding up to whole frames).
        equilibrate_per_disc: PIC collisions per disc before the start.
        rates: PIT frame rates (frames per unit time; the study cases add their own).
        policies: PIT response policies run.
        repeats: timed runs per engine and frame rate (median reported).
        study_cases: include the study's four cases.
    """

    n: int
    fractions: tuple[float, ...]
    free_times: float
    equilibrate_per_disc: float
    rates: tuple[float, ...]
    policies: tuple[str, ...]
    repeats: int
    study_cases: bool = True


FULL = Config(
    n=300,
    fractions=(0.05, 0.5),
    free_times=2.0,
    equilibrate_per_disc=10.0,
    rates=FRAME_RATES,
    policies=POLICIES,
    repeats=3,
)
QUICK = Config(
    n=40,
    fractions=(0.05, 0.5),
    free_times=2.0,
    equilibrate_per_disc=5.0,
    rates=(15, 60, 240),
    policies=("resolve", "swept"),
    repeats=1,
)


@dataclasses.dataclass(frozen=True)
class Setup:
    """One scenario as run here: a start, a box, a horizon and the frame rates.

    Attributes:
        name: short label. discs: the start. box: the box.
        horizon: ``H`` (time units). rates: PIT frame rates.
        speed: rms speed of the moving discs. radius: the smallest radius.
    """

    name: str
    discs: ds.Discs
    box: ds.Box
    horizon: float
    rates: tuple[float, ...]
    speed: float
    radius: float

    def step(self, rate: float) -> float:
        """The frame step ``s = v dt / r`` at ``rate`` frames per unit time."""
        return self.speed / (rate * self.radius)


# --- scenarios -------------------------------------------------------------------------
def rms_speed(discs: ds.Discs) -> float:
    """Root-mean-square speed of the discs of finite mass."""
    moving = np.isfinite(discs.masses)
    return float(np.sqrt(np.mean(np.sum(discs.velocities[moving] ** 2, axis=1))))


def gas_setup(packing_fraction: float, config: Config) -> Setup:
    """An equilibrated walled random gas and its horizon (whole frames at the slowest rate)."""
    discs, box = ds.random_gas(
        config.n, packing_fraction, periodic=False, seed=1, temperature=TEMPERATURE, radius=RADIUS
    )
    start = ds.EventDriven(discs, box, record=False).run(events=round(config.equilibrate_per_disc * config.n))
    rate = float(ds.enskog_collision_rate(packing_fraction, radius=RADIUS, kT=TEMPERATURE))
    slowest = min(config.rates)
    horizon = max(1, math.ceil(config.free_times / rate * slowest - 1e-9)) / slowest
    discs = start.snapshot()
    return Setup(f"gas phi={packing_fraction:g}", discs, box, horizon, config.rates, rms_speed(discs), RADIUS)


def case_setup(case: ds.Scenario, config: Config) -> Setup:
    """One of the study's cases at its own frame rate and the common ones, to its own horizon."""
    rates = (case.frame_rate, *(r for r in config.rates if r != case.frame_rate))
    radius = float(case.discs.radii.min())
    return Setup(case.name, case.discs, case.box, case.until, rates, rms_speed(case.discs), radius)


def setups(config: Config) -> list[Setup]:
    """Every scenario of this mode, gases first."""
    out = [gas_setup(phi, config) for phi in config.fractions]
    if config.study_cases:
        out += [case_setup(case, config) for case in ds.study_cases()]
    return out


# --- runs ------------------------------------------------------------------------------
def timed_runs(build, horizon: float, repeats: int):
    """Run ``repeats`` fresh engines from ``build()`` to ``horizon``.

    Returns:
        ``(engine, seconds, cpu_seconds)``: the last engine (at ``horizon``)
        and the median wall-clock and CPU seconds of the runs.
    """
    runs = [timed(lambda: build().run(until=horizon)) for _ in range(repeats)]
    return runs[-1].result, median([r.wall for r in runs]), median([r.cpu for r in runs])


def at_horizon(sim, setup: Setup) -> dict:
    """What an engine has counted at the horizon: its counts, deepest overlap and energy change."""
    e0 = setup.discs.kinetic_energy()
    return {
        **sim.counts,
        "max_overlap": max(float(sim.max_overlap), 0.0),
        "energy_change": (sim.kinetic_energy() - e0) / e0,
    }


def judge(truth, approx, setup: Setup, frame_interval: float) -> dict:
    """PIT's (or a second PIC's) errors on the truth's collisions in ``[0, H]``.

    Args:
        truth, approx: engines from ``setup.discs``, both run past ``setup.horizon``.
        setup: the scenario.
        frame_interval: spacing of the sample times of the position error.

    Returns:
        Counts and errors as a flat dict (see the module docstring).
    """
    horizon = setup.horizon
    count = math.floor(horizon / frame_interval * (1 + 1e-12) + 1e-9)
    times = np.minimum(np.arange(count + 1) * frame_interval, horizon)
    report = ds.compare(truth, approx, times=times)
    truth_events = truth.events
    truth_collisions = int(np.sum((truth_events["kind"] == 0) & (truth_events["time"] <= horizon)))
    within = np.array([m[2] <= horizon for m in report.matches], dtype=bool).reshape(-1)
    delays = np.abs(report.delays[within]) if within.size else np.zeros(0)
    angles = report.direction_errors[within] if within.size else np.zeros((0, 2))
    angles = angles[np.isfinite(angles)]
    missed = sum(1 for *_, t in report.missed_collisions if t <= horizon)
    spurious = sum(1 for *_, t in report.spurious_collisions if t <= horizon)
    return {
        "truth_collisions": truth_collisions,
        "matched": int(within.sum()),
        "missed": missed,
        "spurious": spurious,
        "missed_pct": 100.0 * missed / truth_collisions if truth_collisions else 0.0,
        "spurious_pct": 100.0 * spurious / truth_collisions if truth_collisions else 0.0,
        "mean_delay": float(delays.mean()) if delays.size else math.nan,
        "max_delay": float(delays.max()) if delays.size else math.nan,
        "mean_direction_error_deg": float(angles.mean()) if angles.size else math.nan,
        "max_direction_error_deg": float(angles.max()) if angles.size else math.nan,
        "position_error_max": report.position_error_max / setup.radius,
        "position_error_final": report.position_error_final / setup.radius,
    }


def pic_row(setup: Setup, repeats: int) -> tuple[dict, ds.EventDriven]:
    """PIC's row, and its engine run on to the end of the comparison (the truth for the PIT rows)."""
    sim, seconds, cpu = timed_runs(lambda: ds.EventDriven(setup.discs, setup.box), setup.horizon, repeats)
    row = {"method": "PIC", "policy": "", "seconds": seconds, "cpu_seconds": cpu, **at_horizon(sim, setup)}
    row["work_units"] = row["predictions"]
    end = setup.horizon + MARGIN_FRAMES / min(setup.rates)
    sim.run(until=end)
    check = ds.EventDriven(setup.discs, setup.box, queue="heap").run(until=end)
    row.update(judge(sim, check, setup, 1.0 / min(setup.rates)))
    return row, sim


def pit_row(setup: Setup, truth: ds.EventDriven, policy: str, rate: float, repeats: int) -> dict:
    """One PIT row: counts and seconds to ``H``, then the errors against ``truth``."""
    sim, seconds, cpu = timed_runs(
        lambda: ds.FixedStep(setup.discs, setup.box, frame_rate=rate, policy=policy), setup.horizon, repeats
    )
    row = {"method": "PIT", "policy": policy, "fps": rate, "step": setup.step(rate)}
    row.update(seconds=seconds, cpu_seconds=cpu, **at_horizon(sim, setup))
    row["collisions"] = row["detections"]
    row["work_units"] = row["frames"] * len(setup.discs)
    sim.run(until=setup.horizon + MARGIN_FRAMES / rate)
    row.update(judge(truth, sim, setup, 1.0 / rate))
    row["mean_delay_frames"] = row["mean_delay"] * rate
    row["max_delay_frames"] = row["max_delay"] * rate
    return row


def scenario_rows(setup: Setup, config: Config) -> list[dict]:
    """PIC's row, then a row per policy and frame rate, with the ratios to PIC."""
    announce(f"  {setup.name}: N={len(setup.discs)}, H={setup.horizon:.4g}, {len(config.policies)} policies")
    pic, truth = pic_row(setup, config.repeats)
    rows = [pic]
    for policy in config.policies:
        for rate in setup.rates:
            rows.append(pit_row(setup, truth, policy, rate, config.repeats))
    common = {
        "scenario": setup.name,
        "n": len(setup.discs),
        "horizon": setup.horizon,
        "speed": setup.speed,
        "radius": setup.radius,
    }
    for row in rows:
        row.update(common)
        row["work_vs_pic"] = row["work_units"] / pic["work_units"] if pic["work_units"] else math.nan
        row["seconds_vs_pic"] = row["seconds"] / pic["seconds"]
    return rows


# --- output ----------------------------------------------------------------------------
MAIN_COLUMNS = [
    Column("method", "method"),
    Column("fps", "fps", "g"),
    Column("step", "s=v dt/r", ".3g"),
    Column("frames", "frames", ","),
    Column("pair_tests", "pair tests", ","),
    Column("collisions", "coll/detect", ","),
    Column("wall_hits", "wall hits", ","),
    Column("work_units", "work units", ","),
    Column("work_vs_pic", "x PIC", ".2f"),
    Column("seconds", "seconds", ".3f"),
    Column("seconds_vs_pic", "x PIC", ".2f"),
    Column("missed_pct", "missed %", ".1f"),
    Column("spurious_pct", "spur %", ".1f"),
    Column("mean_delay", "mean delay", ".2g"),
    Column("max_delay", "max delay", ".2g"),
    Column("mean_direction_error_deg", "mean dir deg", ".3g"),
    Column("max_direction_error_deg", "max dir deg", ".3g"),
    Column("position_error_max", "pos err/r", ".3g"),
    Column("max_overlap", "overlap", ".3g"),
    Column("energy_change", "dE/E", ".1e"),
]

CSV_KEYS = [
    "scenario",
    "n",
    "horizon",
    "speed",
    "radius",
    "method",
    "policy",
    "fps",
    "step",
    "frames",
    "pair_tests",
    "bisection_tests",
    "detections",
    "collisions",
    "wall_hits",
    "cell_crossings",
    "stale",
    "predictions",
    "work_units",
    "work_vs_pic",
    "seconds",
    "cpu_seconds",
    "seconds_vs_pic",
    "truth_collisions",
    "matched",
    "missed",
    "spurious",
    "missed_pct",
    "spurious_pct",
    "mean_delay",
    "max_delay",
    "mean_delay_frames",
    "max_delay_frames",
    "mean_direction_error_deg",
    "max_direction_error_deg",
    "position_error_max",
    "position_error_final",
    "max_overlap",
    "energy_change",
]


def main_table(rows: list[dict], scenario: str) -> str:
    """PIC and the ``resolve`` rows of one scenario."""
    shown = [r for r in rows if r["scenario"] == scenario and r["policy"] in ("", "resolve")]
    return format_table(shown, MAIN_COLUMNS)


def policy_table(rows: list[dict], policies: tuple[str, ...]) -> str:
    """Policies side by side: missed %, mean direction error and seconds per scenario and frame rate."""
    wide = {}
    for row in rows:
        if row["method"] != "PIT":
            continue
        key = (row["scenario"], row["fps"])
        entry = wide.setdefault(key, {"scenario": row["scenario"], "fps": row["fps"], "step": row["step"]})
        entry[f"missed_{row['policy']}"] = row["missed_pct"]
        entry[f"angle_{row['policy']}"] = row["mean_direction_error_deg"]
        entry[f"seconds_{row['policy']}"] = row["seconds"]
    columns = [Column("scenario", "scenario"), Column("fps", "fps", "g"), Column("step", "s", ".3g")]
    columns += [Column(f"missed_{p}", f"miss% {p}", ".1f") for p in policies]
    columns += [Column(f"angle_{p}", f"deg {p}", ".2g") for p in policies]
    columns += [Column(f"seconds_{p}", f"s {p}", ".3f") for p in policies]
    return format_table(list(wide.values()), columns)


def plot(rows: list[dict], path: Path) -> Path:
    """Six panels against the frame rate.

    Top four, policy ``resolve``, every scenario: work units, seconds, missed %
    and mean direction error; PIC's work and seconds are horizontal dashed
    lines in the colour of their scenario. Bottom two, the gases only: missed %
    and seconds of each policy.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 2, figsize=(12, 12.5), constrained_layout=True)
    (ax_work, ax_time), (ax_missed, ax_angle), (ax_policy_missed, ax_policy_time) = axes
    for k, scenario in enumerate(dict.fromkeys(r["scenario"] for r in rows)):
        color = f"C{k}"
        pic = next(r for r in rows if r["scenario"] == scenario and r["method"] == "PIC")
        pit = sorted(
            (r for r in rows if r["scenario"] == scenario and r["policy"] == "resolve"), key=lambda r: r["fps"]
        )
        fps = [r["fps"] for r in pit]
        style = "o-" if scenario.startswith("gas") else ".:"
        ax_work.loglog(fps, [r["work_units"] for r in pit], style, color=color, label=scenario)
        ax_work.axhline(pic["work_units"], color=color, ls="--", lw=1)
        ax_time.loglog(fps, [r["seconds"] for r in pit], style, color=color, label=scenario)
        ax_time.axhline(pic["seconds"], color=color, ls="--", lw=1)
        ax_missed.semilogx(fps, [r["missed_pct"] for r in pit], style, color=color, label=scenario)
        angles = [max(r["mean_direction_error_deg"], 1e-3) for r in pit]
        ax_angle.loglog(fps, angles, style, color=color, label=scenario)
    _plot_policies(rows, ax_policy_missed, ax_policy_time)
    ax_missed.axhline(1.0, color="0.4", ls=":", lw=1)
    ax_angle.axhline(1.0, color="0.4", ls=":", lw=1)
    ax_work.set(ylabel="work units (disc neighbourhood checks)", title="work to the horizon (dashed: PIC)")
    ax_time.set(ylabel="wall-clock seconds (median)", title="cost to the horizon (dashed: PIC)")
    ax_missed.set(ylabel="PIC collisions missed (%)", title="what the work buys: missed collisions (dotted: 1%)")
    ax_angle.set(
        ylabel="mean direction error (degrees)", title="what the work buys: direction error (dotted: 1 deg; floor 1e-3)"
    )
    for ax in axes.flat[:4]:
        ax.set_xlabel("PIT frame rate (frames per unit time), policy resolve")
    rates = sorted({r["fps"] for r in rows if r["method"] == "PIT"})
    for ax in axes.flat:
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xticks(rates, [f"{rate:g}" for rate in rates], fontsize=8)
        ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    ax_work.legend(fontsize=8)
    fig.suptitle("PIC against PIT over the same simulated time")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _plot_policies(rows: list[dict], ax_missed, ax_time) -> None:
    """Missed % and seconds of every policy against the frame rate, for the gases (solid: dilute, dashed: dense)."""
    gases = [s for s in dict.fromkeys(r["scenario"] for r in rows) if s.startswith("gas")]
    policies = list(dict.fromkeys(r["policy"] for r in rows if r["method"] == "PIT"))
    for k, policy in enumerate(policies):
        for gas, style in zip(gases, ("o-", "s--", "^:")):
            pit = sorted((r for r in rows if r["scenario"] == gas and r["policy"] == policy), key=lambda r: r["fps"])
            fps = [r["fps"] for r in pit]
            label = f"{policy}, {gas}"
            ax_missed.semilogx(fps, [r["missed_pct"] for r in pit], style, color=f"C{k}", label=label)
            ax_time.loglog(fps, [r["seconds"] for r in pit], style, color=f"C{k}", label=label)
    for gas, style in zip(gases, ("-", "--", ":")):
        pic = next(r for r in rows if r["scenario"] == gas and r["method"] == "PIC")
        ax_time.axhline(pic["seconds"], color="k", ls=style, lw=1, label=f"PIC, {gas}")
    ax_missed.axhline(1.0, color="0.4", ls=":", lw=1)
    ax_missed.set(xlabel="PIT frame rate", ylabel="PIC collisions missed (%)", title="gases: missed, each policy")
    ax_time.set(xlabel="PIT frame rate", ylabel="wall-clock seconds (median)", title="gases: cost, each policy")
    ax_missed.legend(fontsize=7, ncol=2)
    ax_time.legend(fontsize=7, ncol=2)


def main(argv=None) -> int:
    """Run every scenario, print the tables, write the CSV and the PNG; return the exit code."""
    args = parse_args(__doc__.splitlines()[0], argv)
    config = QUICK if args.quick else FULL
    if args.repeats is not None:
        config = dataclasses.replace(config, repeats=args.repeats)
    print(f"discsim {ds.__version__} event counts; {machine_summary()}")
    print(
        f"mode: {'quick' if args.quick else 'full'}; gases: N={config.n}, walled box, radius {RADIUS:g}, "
        f"kT={TEMPERATURE:g} (v_rms={V_RMS:g}), horizon {config.free_times:g} mean free times in whole frames at "
        f"{min(config.rates):g} fps; seconds: median of {config.repeats} run(s)"
    )
    rows = []
    for setup in setups(config):
        rows += scenario_rows(setup, config)
        pic = rows[-(1 + len(config.policies) * len(setup.rates))]
        print(f"\n== {setup.name}: N={len(setup.discs)}, {setup.box}, horizon H={setup.horizon:.4g} ==")
        print(
            f"v_rms={setup.speed:.3g}, r={setup.radius:g}. PIC: {pic['collisions']:,} collisions "
            f"({2 * pic['collisions'] / len(setup.discs):.1f} per disc), {pic['wall_hits']:,} wall hits, "
            f"{pic['cell_crossings']:,} cell crossings, {pic['stale']:,} stale events, "
            f"{pic['predictions']:,} predictions. PIT policy resolve:"
        )
        print(main_table(rows, setup.name))
    print("\n== response policies side by side (miss% = missed %, deg = mean direction error, s = seconds) ==")
    print(policy_table(rows, config.policies))
    csv_path = write_csv(args.results / "event_counts.csv", rows, CSV_KEYS)
    png = plot(rows, args.results / "event_counts.png")
    print(f"\nload average at the end: {load_average():.2f}")
    print(f"wrote {csv_path}, {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
