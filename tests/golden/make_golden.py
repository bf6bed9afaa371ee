"""Record the golden event logs that pin both engines' behaviour bit for bit.

Run from the repository root, on the engine whose behaviour is the reference::

    python tests/golden/make_golden.py          # writes tests/golden/*.npz and tests/fixtures/*.dsc

The scenes cover walled and periodic boxes, mixtures of radii and masses, obstacles, segment walls,
pass-through groups, N from 2 to 5,000 (internal renumbering from N = 4096 on), a run long enough to move the
internal clock's epoch, both engines and all five PIT policies. ``tests/engines/test_golden.py`` replays every scene
and compares every field of the log, the final state and the counters exactly. The logs were first recorded
on commit d8e6d8f, before the redesign of issue 14; the files must never be re-recorded to make a test pass.

Only the public API is used, so the script runs on any version of discsim.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np

import discsim as ds

HERE = Path(__file__).resolve().parent
FIXTURES = HERE.parent / "fixtures"
#: Logs longer than this are stored as a SHA-256 digest plus their first and last rows.
FULL_LOG_LIMIT = 20_000
EDGE_ROWS = 500


def _mixture(n: int, periodic: bool, seed: int, obstacles: int = 0):
    """A gas with three radii and random masses (radii shrunk, so nothing overlaps), some discs fixed."""
    discs, box = ds.random_gas(n, 0.35, periodic=periodic, seed=seed)
    rng = np.random.default_rng(seed + 100)
    radii = discs.radii * np.array([1.0, 0.5, 0.75])[np.arange(n) % 3]
    masses = rng.uniform(0.5, 3.0, n)
    velocities = np.array(discs.velocities)
    if obstacles:
        masses[:obstacles] = np.inf
        velocities[:obstacles] = 0.0
    return ds.Discs(discs.positions, velocities, radii, masses, groups=np.arange(n) % 3), box


def _with_segments(n: int, seed: int):
    """A walled mixture with a triangle of segments inside; discs the segments would cut are left out."""
    discs, box = _mixture(n, False, seed, obstacles=3)
    w, h = box.width, box.height
    segments = [
        *ds.polygon([(0.3 * w, 0.3 * h), (0.7 * w, 0.3 * h), (0.5 * w, 0.7 * h)]),
        ds.Segment((0.05 * w, 0.9 * h), (0.3 * w, 0.95 * h)),
    ]
    keep = np.ones(n, dtype=bool)
    for segment in segments:
        keep &= segment.distance(discs.positions) > discs.radii * 1.01
    discs = ds.Discs(
        discs.positions[keep], discs.velocities[keep], discs.radii[keep], discs.masses[keep], discs.groups[keep]
    )
    return discs, box, segments


def event_driven_scenes() -> dict:
    """name -> (build, how): build() gives (discs, box, engine kwargs); how is ('until', T) or ('events', K)."""
    scenes = {}
    for case in [ds.head_on(1.0, 3.0), ds.newtons_cradle(5), ds.billiard_break(), *ds.study_cases()]:
        scenes[f"ed_{case.name}"] = (lambda c=case: (c.discs, c.box, {}), ("until", case.until))
    scenes["ed_walled_gas_50"] = (lambda: (*ds.random_gas(50, 0.4, periodic=False, seed=1), {}), ("until", 10.0))
    scenes["ed_periodic_gas_200"] = (lambda: (*ds.random_gas(200, 0.5, seed=2), {}), ("events", 6000))
    scenes["ed_walled_mixture"] = (lambda: (*_mixture(120, False, 3, obstacles=5), {}), ("until", 6.0))
    scenes["ed_periodic_mixture"] = (lambda: (*_mixture(150, True, 4, obstacles=4), {}), ("events", 5000))

    def segments():
        discs, box, segs = _with_segments(90, 5)
        return discs, box, {"segments": segs}

    scenes["ed_segments"] = (segments, ("until", 8.0))

    def pass_through():
        discs, box = ds.random_gas(150, 0.3, seed=6)
        discs = ds.Discs(discs.positions, discs.velocities, discs.radii, discs.masses, groups=np.arange(150) % 3)
        return discs, box, {"pass_through": {(1, 1), (0, 2)}}

    scenes["ed_pass_through"] = (pass_through, ("until", 5.0))
    for queue in ("sorted", "heap"):
        scenes[f"ed_queue_{queue}"] = (
            lambda q=queue: (*ds.random_gas(300, 0.45, seed=7), {"queue": q}),
            ("events", 4000),
        )
    scenes["ed_cell_size"] = (lambda: (*ds.random_gas(300, 0.2, seed=8), {"cell_size": 3.5}), ("events", 3000))
    scenes["ed_periodic_5000"] = (lambda: (*ds.random_gas(5000, 0.3, seed=9), {}), ("events", 15000))
    scenes["ed_walled_5000"] = (lambda: (*ds.random_gas(5000, 0.6, periodic=False, seed=10), {}), ("events", 15000))
    # Long enough to move the internal clock's epoch (every 2^18 physical events).
    scenes["ed_rebase"] = (lambda: (*ds.random_gas(400, 0.5, seed=11), {}), ("events", 300_000))
    return scenes


def fixed_step_scenes() -> dict:
    """name -> (build, how), as for :func:`event_driven_scenes`; kwargs go to FixedStep."""
    scenes = {}
    for policy in ("resolve", "revert", "separate", "bisect", "swept"):
        for case in ds.study_cases():
            scenes[f"fs_{policy}_{case.name}"] = (
                lambda c=case, p=policy: (c.discs, c.box, {"frame_rate": c.frame_rate, "policy": p}),
                ("until", case.until),
            )

        def walled(p=policy):
            discs, box, segs = _with_segments(90, 12)
            return discs, box, {"frame_rate": 40.0, "policy": p, "segments": segs, "pass_through": {(0, 1)}}

        scenes[f"fs_{policy}_walled_mixture"] = (walled, ("until", 4.0))
        scenes[f"fs_{policy}_periodic"] = (
            lambda p=policy: (*ds.random_gas(200, 0.4, seed=13), {"dt": 0.02, "policy": p}),
            ("until", 3.0),
        )
    scenes["fs_resolve_all_pairs"] = (
        lambda: (*_mixture(80, True, 14), {"dt": 0.01, "broad_phase": "all-pairs", "pass_through": {(2, 2)}}),
        ("frames", 150),
    )
    scenes["fs_swept_all_pairs"] = (
        lambda: (*_mixture(80, False, 15, obstacles=2), {"dt": 0.05, "policy": "swept", "broad_phase": "all-pairs"}),
        ("frames", 80),
    )
    return scenes


def run_scene(engine: str, build, how):
    """Build and run one scene; return the engine."""
    discs, box, kwargs = build()
    sim = (ds.EventDriven if engine == "ed" else ds.FixedStep)(discs, box, **kwargs)
    key, value = how
    sim.run(**{key: value})
    return sim


def summary(sim) -> dict:
    """What a golden file holds: the log (whole, or digest and edges), the final state and the counters."""
    events = sim.events
    out = {
        "time": np.float64(sim.time),
        "positions": sim.positions,
        "velocities": sim.velocities,
        "counts": np.array(json.dumps(dict(sim.counts), sort_keys=True)),
        "max_overlap": np.float64(sim.max_overlap),
        "n_events": np.int64(len(events)),
        "events_sha256": np.array(hashlib.sha256(events.tobytes()).hexdigest()),
    }
    if len(events) <= FULL_LOG_LIMIT:
        out["events"] = events
    else:
        out["events_head"] = events[:EDGE_ROWS]
        out["events_tail"] = events[-EDGE_ROWS:]
    return out


def all_scenes() -> dict:
    scenes = {name: ("ed", *spec) for name, spec in event_driven_scenes().items()}
    scenes.update({name: ("fs", *spec) for name, spec in fixed_step_scenes().items()})
    return scenes


def make_fixtures() -> None:
    """Checkpoints in the pre-redesign file format, with what continuing them must give."""
    FIXTURES.mkdir(exist_ok=True)
    discs, box, segs = _with_segments(60, 20)
    sim = ds.EventDriven(discs, box, segments=segs, pass_through={(1, 2)}).run(until=1.5)
    sim.save(FIXTURES / "v0_walled_segments.dsc")
    sim.run(until=4.0)
    np.savez_compressed(FIXTURES / "v0_walled_segments.npz", **summary(sim))
    discs, box = ds.random_gas(4200, 0.25, seed=21)
    sim = ds.EventDriven(discs, box, record=False, queue="heap").run(events=3000)
    sim.save(FIXTURES / "v0_periodic_4200.dsc")
    sim.run(events=4000)
    np.savez_compressed(FIXTURES / "v0_periodic_4200.npz", **summary(sim))


def main(argv: list[str]) -> int:
    only = set(argv)
    for name, (engine, build, how) in all_scenes().items():
        if only and name not in only:
            continue
        sim = run_scene(engine, build, how)
        np.savez_compressed(HERE / f"{name}.npz", **summary(sim))
        print(f"{name:40s} {len(sim.events):8d} events  t = {sim.time:.6g}")
    if not only or "fixtures" in only:
        make_fixtures()
        print("fixtures written")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
