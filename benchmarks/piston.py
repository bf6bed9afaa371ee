"""A piston at constant pressure (issue 28): the equation of state at fixed pressure against fixed volume, and slow
against sudden compressions of a dilute gas.

Run ``python benchmarks/piston.py`` (about a minute) or ``--quick`` (seconds).

1. **Equation of state.** For each packing fraction, a walled gas of N = 100 discs (``--quick``: 30) runs under a
   piston (``ds.Piston``, mass 25) at the pressure Henderson's equation gives for that packing in its starting box,
   in a box four times as tall; ``ds.thermo`` gives the mean area ``<A>``, the packing fraction and
   ``Z_P = P <A> / (N kT)``. Then the same gas is held at the mean area by a kinematic lid (``Piston(mass=inf,
   pressure=0)``, driven to ``<A> / w`` and stopped with ``set_piston(velocity=...)``) and ``Z_V = P_V A / (N kT)``
   is read from the momentum the discs give the lid (each bounce off a lid at rest gives ``2 m |vy|``), with
   batch-means error bars. Both count the whole box's area, so both carry the same surface term (discs keep a
   radius from each wall; about 12% at packing 0.34 and N = 100): they must agree with each other, not with the
   bulk equation of state (Henderson's curve is drawn for scale).
2. **Compressions.** 200 discs at packing 0.005 (nearly ideal: ``Z`` about 1.01) under a piston; the pressure is
   raised four-fold, in 400 small steps over 20,000 time units (slow) or at once (sudden), and the gas averaged
   over 10,000 (slow) or 20,000 (sudden) time units after. The 2D ideal gas's adiabat ``P A^2 = const``
   (``gamma = 2``) predicts ``kT`` x 2 and ``A`` x 0.5 for the slow one; the first law with a constant external
   pressure, ``kT`` x 2.5 and ``A`` x 0.625 for the sudden one on average over where the oscillating piston was at
   the jump, and exactly ``N kT_f (2 + 1 / 2N) = K + M U^2 / 2 + P_f A`` from the state at the jump (the row "first
   law at the jump"). The slow path (the area and kinetic temperature at the end of each step) is drawn against
   the adiabat ``kT A = const``.

Output: ``piston.csv`` (one row per measurement) and ``piston.png`` in ``--results``.
"""

from __future__ import annotations

import math
import sys

import numpy as np
from benchutils import Column, format_table, machine_summary, parse_args, write_csv

import discsim as ds

KEYS = ["part", "label", "packing", "packing_err", "z", "z_err", "value", "expected"]
COLUMNS = [
    Column("part", "part", "s"),
    Column("label", "what", "s"),
    Column("packing", "packing", ".4f"),
    Column("z", "Z / ratio", ".4f"),
    Column("z_err", "+-", ".4f"),
    Column("expected", "expected", ".4f"),
]


def kinetic(discs) -> float:
    return 0.5 * float(np.sum(discs.masses * np.sum(discs.velocities**2, axis=1)))


def lid_z(sim, since: float, height: float) -> tuple[float, float]:
    """``Z = P A / K`` at fixed volume: ``P`` the momentum the discs give the lid at rest per unit time and width."""
    ev = sim.events
    hits = ev[(ev["kind"] == int(ds.EventKind.WALL)) & np.isfinite(ev["yj"]) & (ev["time"] > since)]
    impulse = 2.0 * np.abs(hits["vyi"]) * sim.discs.masses[hits["i"]]
    edges = np.linspace(since, sim.time, 41)
    blocks = np.bincount(np.searchsorted(edges, hits["time"]) - 1, weights=impulse, minlength=40)[:40]
    scale = height / sim.kinetic_energy()
    z_blocks = blocks / np.diff(edges) * scale
    return float(impulse.sum() / (sim.time - since) * scale), float(z_blocks.std(ddof=1) / math.sqrt(40))


def equation_of_state(packing: float, n: int, duration: float) -> dict:
    """``Z`` at fixed pressure and at fixed volume (the mean area) for a gas started at ``packing``."""
    discs, box = ds.random_gas(n, packing, seed=5, periodic=False)
    pressure = ds.henderson_z(packing) * kinetic(discs) / box.area
    tall = ds.Box(box.width, 4.0 * box.height)
    sim = ds.EventDriven(discs, tall, piston=ds.Piston(mass=25.0, pressure=pressure, height=box.height))
    sim.run(until=duration)
    at_p = ds.thermo(sim, since=0.05 * duration)
    height = at_p.area / box.width
    lid = ds.EventDriven(sim.snapshot(), tall, piston=ds.Piston(math.inf, 0.0, height=sim.piston.height))
    lid.set_piston(velocity=(height - sim.piston.height) / 5.0)
    lid.run(until=5.0)
    lid.set_piston(velocity=0.0)
    start = lid.time
    lid.run(until=start + duration)
    z_v, z_v_err = lid_z(lid, start + 0.05 * duration, lid.piston.height)
    return {"at_p": at_p, "z_v": z_v, "z_v_err": z_v_err}


def compression(steps: int, duration: float, settle: float) -> tuple:
    """Quadruple the pressure on a dilute gas in ``steps`` equal ratios over ``duration``: the averages before and
    after (over ``settle`` time units, the first tenth skipped), the path ``(area, kT)`` at the end of each step, and
    the energy ``K + M U^2 / 2 + P_f A`` at the first change (what a sudden one keeps from then on)."""
    discs, box = ds.random_gas(200, 0.005, seed=7, periodic=False)
    p0 = ds.henderson_z(0.005) * kinetic(discs) / box.area
    piston = ds.Piston(mass=10.0, pressure=p0, height=box.height)
    sim = ds.EventDriven(discs, ds.Box(box.width, 3 * box.height), piston=piston).run(until=settle)
    before = ds.thermo(sim, since=settle / 10)
    pressures = p0 * 4.0 ** (np.arange(1, steps + 1) / steps)
    energy = sim.kinetic_energy() + 5.0 * sim.piston.velocity**2 + pressures[-1] * box.width * sim.piston.height
    path = []
    for p in pressures:
        sim.set_piston(pressure=p)
        sim.run(until=sim.time + duration / steps)
        path.append((box.width * sim.piston.height, sim.kinetic_energy() / len(discs)))
    end = sim.time
    sim.run(until=end + settle)
    return before, ds.thermo(sim, since=end + settle / 10), np.array(path), energy


def main(argv=None) -> int:
    args = parse_args(__doc__.splitlines()[0], argv)
    quick = args.quick
    print(f"discsim {ds.__version__} piston benchmark; {machine_summary()}")
    packings = (0.2, 0.35) if quick else (0.1, 0.2, 0.35, 0.5)
    n, duration = (30, 300.0) if quick else (100, 3000.0)
    rows, eos = [], []
    for packing in packings:
        out = equation_of_state(packing, n, duration)
        a = out["at_p"]
        eos.append((a.packing, a.packing_err, a.z, a.z_err, out["z_v"], out["z_v_err"]))
        rows.append({"part": "EOS", "label": f"fixed P, start {packing}", "packing": a.packing,
                     "packing_err": a.packing_err, "z": a.z, "z_err": a.z_err, "value": a.area,
                     "expected": out["z_v"]})  # fmt: skip
        rows.append({"part": "EOS", "label": "fixed V (the lid)", "packing": a.packing, "packing_err": 0.0,
                     "z": out["z_v"], "z_err": out["z_v_err"], "value": a.area, "expected": a.z})  # fmt: skip
    steps, ramp, settle = (40, 2000.0, 1000.0) if quick else (400, 20000.0, 10000.0)
    paths = {}
    for label, k, span, kt_ratio, area_ratio in (("slow", steps, ramp, 2.0, 0.5), ("sudden", 1, 1.0, 2.5, 0.625)):
        before, after, path, energy = compression(k, span, settle if k > 1 else 2 * settle)
        paths[label] = (before, after, path)
        if k == 1:  # the first law from the state at the jump (ideal gas, the piston's kT / 2): N kT (2 + 1 / 2N) = E
            first_law = energy / (2 * after.n + 0.5)
            rows.append({"part": "sudden compression", "label": "kT after / first law at the jump",
                         "packing": after.packing, "packing_err": 0.0, "z": after.temperature / first_law,
                         "z_err": math.nan, "value": after.temperature, "expected": 1.0})  # fmt: skip
        for what, got, expected in (
            ("kT after / before", after.temperature / before.temperature, kt_ratio),
            ("A after / before", after.area / before.area, area_ratio),
            ("P A^2 after / before", after.pressure * after.area**2 / (before.pressure * before.area**2),
             4.0 * area_ratio**2),
        ):  # fmt: skip
            rows.append({"part": f"{label} compression", "label": what, "packing": after.packing, "packing_err": 0.0,
                         "z": got, "z_err": math.nan, "value": got, "expected": expected})  # fmt: skip
    print(format_table(rows, COLUMNS))
    path = write_csv(args.results / "piston.csv", rows, KEYS)
    print(f"wrote {path}")
    figure = _plot(np.array(eos), paths, args.results / "piston.png")
    print(f"wrote {figure}")
    return 0


def _plot(eos: np.ndarray, paths: dict, where):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    eta = np.linspace(0.05, 0.55, 100)
    left.plot(eta, ds.henderson_z(eta), color="0.6", lw=1, label="Henderson (bulk, for scale)")
    left.errorbar(eos[:, 0], eos[:, 2], xerr=eos[:, 1], yerr=eos[:, 3], fmt="o", label="fixed pressure (piston)")
    left.errorbar(eos[:, 0], eos[:, 4], yerr=eos[:, 5], fmt="s", mfc="none", label="fixed volume (lid at rest)")
    left.set_xlabel("packing fraction")
    left.set_ylabel("Z = P A / (N kT), A the whole box")
    left.set_title("The equation of state, two ensembles")
    left.legend()
    before, after, path = paths["slow"]
    a0, t0 = before.area, before.temperature
    right.plot(path[:, 0] / a0, path[:, 1] / t0, lw=0.8, color="C0", alpha=0.6, label="slow: along the way")
    grid = np.linspace(0.45, 1.05, 50)
    right.plot(grid, 1.0 / grid, "k--", lw=1, label="adiabat kT A = const (P A² = const)")
    right.plot([after.area / a0], [after.temperature / t0], "o", color="C0", label="slow: settled")
    s_before, s_after, _ = paths["sudden"]
    right.plot([s_after.area / s_before.area], [s_after.temperature / s_before.temperature], "s", color="C3",
               label="sudden: settled")  # fmt: skip
    right.plot([0.625], [2.5], "x", color="C3", ms=10, label="first law, sudden: (0.625, 2.5)")
    right.plot([1.0], [1.0], "ko", ms=4)
    right.set_xlabel("area / area before")
    right.set_ylabel("kT / kT before")
    right.set_title("Four times the pressure: slow and sudden")
    right.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(where, dpi=110)
    plt.close(fig)
    return where


if __name__ == "__main__":
    sys.exit(main())
