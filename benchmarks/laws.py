"""Collisions per second under each law of motion and collision law, against the elastic gas, both backends.

Run ``python benchmarks/laws.py`` (a few minutes) or ``--quick`` (seconds). For each backend, a walled gas at
packing 0.3 (N = 10^4 compiled, 10^3 pure Python; ``--quick``: 2,000 and 500), warmed by 2 events per disc, is
timed over a fixed number of physical events (20 per disc; ``--quick``: 4) in a fresh Python process per run,
each law in turn (so a slow spell hits them alike), ``--repeats`` times (default 3), medians reported:

* ``elastic``: free flight and elastic collisions (today's physics; the pure-Python backend's own loop).
* ``gravity``: elastic, under gravity of a strength that makes the gas's scale height ``kT / (m g)`` half the
  box's height (a dense layer at the floor, a thin gas above it).
* ``restitution``: no gravity, ``restitution=0.9`` with ``tc`` a hundredth of the mean free time: a cooling
  granular gas.
* ``gravity+restitution``: both (the gas settles while it is timed).
* ``rough``: no gravity, elastic, ``roughness=0.5``: rough discs that spin (they start without spin).
* ``perfectly rough``: the same at ``roughness=1`` (energy conserved: the spins take their share and keep it).
* ``drag``: no gravity, elastic, ``drag=gamma`` with ``1 / gamma`` a hundred mean free times (the gas slows to
  about half its kinetic energy while it is timed): exponential flight, every time in closed form.
* ``gravity+drag``: both (walls and cell edges along gravity by bracketed roots; the gas falls towards its
  terminal velocity).
* ``sensors``: elastic, with six circle sensors (pockets a tenth of the box across) and two trip wires across the
  box (issue 28): every disc's prediction also asks when it next changes sides of each sensor over its cell.
* ``moving segment``: elastic, a lid across the box above every disc, coming down at a hundredth of the rms
  speed (issue 28): it is checked from every cell.
* ``piston``: elastic, the box's top wall a piston (issue 28) of the gas's total mass under the pressure of the gas
  (Henderson's), in a box three times as tall: every prediction also asks when the disc meets the piston, and a
  contact predicted before another disc hit it is dropped when it comes up (a stale event).

Under any law but the first the pure-Python backend runs the compiled loop's source interpreted (its own loop
knows free flight only). The issue's target: the compiled backend within 1.5x of its elastic rate under gravity
and restitution at N = 10^4. Output: ``laws.csv`` (one row per backend and law: collisions per second, and the
ratio to the elastic rate).
"""

from __future__ import annotations

import sys
import time

from benchutils import Column, call_fresh, format_table, machine_summary, median, parse_args, write_csv

import discsim as ds

LAWS = (
    "elastic", "gravity", "restitution", "gravity+restitution", "rough", "perfectly rough", "drag", "gravity+drag",
    "sensors", "moving segment", "piston",
)  # fmt: skip
KEYS = ["backend", "law", "n", "events", "collisions_per_s", "ratio_to_elastic", "repeats"]
COLUMNS = [
    Column("backend", "backend", "s"),
    Column("law", "law", "s"),
    Column("n", "N", "d"),
    Column("events", "events", "d"),
    Column("collisions_per_s", "collisions/s", ",.0f"),
    Column("ratio_to_elastic", "of elastic", ".2f"),
]


def keywords(law: str, discs, box) -> dict:
    """The engine's keywords for ``law``, scaled to the gas."""
    kt = float((discs.masses[:, None] * discs.velocities**2).sum() / (2 * len(discs)))
    out: dict = {}
    if "gravity" in law:
        out["gravity"] = (0.0, -2.0 * kt / box.height)  # scale height kT / (m g) = half the box
    n_density = len(discs) / box.area
    sigma = 2.0 * float(discs.radii.mean())
    free_time = 1.0 / (n_density * sigma * (kt * 3.14159) ** 0.5 * 2**0.5)
    if "restitution" in law:
        out.update(restitution=0.9, tc=free_time / 100.0)
    if "drag" in law:
        out["drag"] = 1.0 / (100.0 * free_time)
    if law == "rough":
        out["roughness"] = 0.5
    if law == "perfectly rough":
        out["roughness"] = 1.0
    w, h = box.width, box.height
    if law == "sensors":
        pockets = [ds.Sensor.circle((x, y), 0.05 * w) for x in (0.1 * w, 0.5 * w, 0.9 * w) for y in (0.1 * h, 0.9 * h)]
        out["sensors"] = [
            *pockets,
            ds.Sensor.line((0.0, 0.5 * h), (w, 0.5 * h)),
            ds.Sensor.line((0.5 * w, 0.0), (0.5 * w, h)),
        ]
    if law == "moving segment":
        top = float((discs.positions[:, 1] + discs.radii).max())
        rms = float(((discs.velocities**2).sum(axis=1).mean()) ** 0.5)
        lid = ds.Segment((-1.0, 0.5 * (top + h)), (w + 1.0, 0.5 * (top + h)), velocity=(0.0, -0.01 * rms))
        out["segments"] = [lid]
    return out


def measure(backend: str, law: str, n: int, events: int) -> dict:
    """One timed run in this process (call it in a fresh one): seconds and collisions for ``events`` events."""
    discs, box = ds.random_gas(n, 0.3, periodic=False, seed=1)
    extra = keywords(law, discs, box)
    if law == "piston":
        kinetic = 0.5 * float((discs.masses[:, None] * discs.velocities**2).sum())
        pressure = ds.henderson_z(0.3) * kinetic / box.area
        extra["piston"] = ds.Piston(mass=float(discs.masses.sum()), pressure=pressure, height=box.height)
        box = ds.Box(box.width, 3.0 * box.height)
    sim = ds.EventDriven(discs, box, backend=backend, record=False, **extra)
    sim.run(events=2 * n)
    before = sim.counts["collisions"]
    began = time.perf_counter()
    sim.run(events=events)
    return {"seconds": time.perf_counter() - began, "collisions": sim.counts["collisions"] - before}


def main(argv=None) -> int:
    args = parse_args(__doc__.splitlines()[0], argv)
    repeats = args.repeats or (1 if args.quick else 3)
    sizes = {"python": 500 if args.quick else 1000, "numba": 2000 if args.quick else 10_000}
    per_disc = 4 if args.quick else 20
    backends = ["python"] + (["numba"] if ds._numba.available() else [])
    print(f"discsim {ds.__version__} rates under each law; {machine_summary()}; {repeats} repeats, fresh processes")
    rates: dict[tuple[str, str], list[float]] = {}
    for _ in range(repeats):
        for backend in backends:
            for law in LAWS:
                n = sizes[backend]
                out = call_fresh("laws", "measure", backend=backend, law=law, n=n, events=per_disc * n)
                rates.setdefault((backend, law), []).append(out["collisions"] / out["seconds"])
    rows = []
    for backend in backends:
        base = median(rates[(backend, "elastic")])
        for law in LAWS:
            rate = median(rates[(backend, law)])
            rows.append({"backend": backend, "law": law, "n": sizes[backend], "events": per_disc * sizes[backend],
                         "collisions_per_s": rate, "ratio_to_elastic": rate / base, "repeats": repeats})  # fmt: skip
    print(format_table(rows, COLUMNS))
    path = write_csv(args.results / "laws.csv", rows, KEYS)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
