"""The physics summary that ``discsim run`` prints and writes at the end of a run.

Collisions, collisions/s, the energy drift, the deepest overlap, the canonical pressure and Z = beta P A / N
(``kT = K / (N - 1)`` in a periodic box, :func:`discsim.thermo`; from the start, and from ``--since`` on with
error bars from the correlation time and a flag when the series still drifts) next to Henderson's equation of
state, and what the event log costs on disk.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from discsim.engines.event_driven import EventDriven


def run_summary(
    sim: EventDriven,
    args: argparse.Namespace,
    identity: dict[str, Any],
    e0: float,
    collisions0: int,
    seconds: float,
    files: dict[str, Path],
) -> dict[str, Any]:
    """The summary of the run ``sim`` after a session of ``seconds`` that began at kinetic energy ``e0``
    (at t = 0) and ``collisions0`` collisions; ``identity`` is what identifies the run (``run.json``)."""
    import discsim as ds

    counts = sim.counts
    stream = ds.checkpoint_info(files["checkpoint"])["stream"] or {}
    records = stream.get("records", 0)
    size = files["events"].stat().st_size if files["events"].exists() else 0
    return {
        **identity,
        "until": args.until,
        "backend": sim.backend,
        "time": sim.time,
        "collisions": counts["collisions"],
        "wall_hits": counts["wall_hits"],
        "session_seconds": seconds,
        "session_collisions": counts["collisions"] - collisions0,
        "collisions_per_s": (counts["collisions"] - collisions0) / seconds if seconds > 0 else float("nan"),
        "energy_drift": (sim.kinetic_energy() - e0) / e0,
        "max_overlap": sim.max_overlap,
        "pressure": canonical_pressure(sim) if sim.time > 0 else float("nan"),
        "Z_from_start": ds.compressibility_factor(sim) if sim.time > 0 else float("nan"),
        **equilibrated(sim, args),
        "henderson_Z": float(ds.henderson_z(args.packing)),
        "events_on_disk": records,
        "bytes_per_event": size / records if records else float("nan"),
        "files": {k: str(v) for k, v in files.items()},
    }


def canonical_pressure(sim: EventDriven) -> float:
    """The canonical ``P = Z N kT / A`` from the start (the engine's ``pressure()`` is the mechanical one)."""
    import numpy as np

    import discsim as ds
    from discsim.analysis.thermo import kinetic_temperature

    n = int(np.count_nonzero(np.isfinite(np.asarray(sim.discs.masses, dtype=float))))
    return ds.compressibility_factor(sim) * n * kinetic_temperature(sim) / sim.box.area


def equilibrated(sim: EventDriven, args: argparse.Namespace) -> dict[str, Any]:
    """P and Z from ``--since`` on, with error bars from the correlation time (:func:`discsim.thermo`), read from
    the log on disk; ``Z_drifting`` says whether the series still drifts (the warning is kept for the table)."""
    import warnings

    import discsim as ds

    since = args.until / 5.0 if args.since is None else args.since
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ds.EquilibrationWarning)
            t = ds.thermo(sim, since=since)
    except ds.DiscsimError:  # --since outside the run, or a run of zero length
        nan = float("nan")
        return {"since": since, "Z": nan, "Z_err": nan, "pressure_since": nan, "pressure_err": nan, "Z_drifting": False}
    return {
        "since": t.since,
        "Z": t.z,
        "Z_err": t.z_err,
        "pressure_since": t.pressure,
        "pressure_err": t.pressure_err,
        "Z_drifting": t.drifting,
    }


def print_run_summary(s: dict[str, Any], resumed: bool) -> None:
    """Print the summary ``s`` (from :func:`run_summary`) as a small table."""
    box = "periodic box" if s["periodic"] else "box with walls"
    print(
        f"discsim run: N={s['n']}, packing {s['packing']:g}, {box}, seed {s['seed']}, {s['backend']} backend, "
        f"t = {s['time']:g}" + (" (resumed)" if resumed else "")
    )
    rows = [
        ("collisions", f"{s['collisions']:,}", f"wall hits {s['wall_hits']:,}"),
        (
            "collisions/s",
            f"{s['collisions_per_s']:,.0f}",
            f"{s['session_collisions']:,} in {s['session_seconds']:.1f} s",
        ),
        ("energy drift", f"{s['energy_drift']:.2e}", "relative, since t = 0"),
        ("deepest overlap", f"{s['max_overlap']:.2e}", "fraction of the contact distance"),
        (
            "pressure P",
            f"{s['pressure_since']:.6g} ± {s['pressure_err']:.2g}",
            f"energy per area, canonical (kT = K/(N-1)), since t = {s['since']:g}",
        ),
        (
            "Z = PA/NkT",
            f"{s['Z']:.4f} ± {s['Z_err']:.4f}",
            f"Henderson: {s['henderson_Z']:.4f}; averaged from t = 0: {s['Z_from_start']:.4f}"
            + ("; STILL DRIFTING: run longer" if s.get("Z_drifting") else ""),
        ),
        ("events on disk", f"{s['events_on_disk']:,}", f"{s['bytes_per_event']:.1f} bytes/event"),
    ]
    for name, value, note in rows:
        print(f"  {name:<16}{value:>16}   {note}")
    print(
        f"  written to {Path(s['files']['checkpoint']).parent}: " + ", ".join(Path(p).name for p in s["files"].values())
    )
