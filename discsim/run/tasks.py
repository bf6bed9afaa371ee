"""Ready-made sweep tasks for the common studies: ``ds.sweep(ds.tasks.equation_of_state, {...})``.

Each task is a plain function of keyword parameters and ``seed`` that returns a dict of numbers (the
columns of the sweep's table), and depends on nothing else: the same parameters and seed give the same
numbers, bit for bit, on any worker (both event-driven backends give the same events).

- :func:`equation_of_state`: pressure, ``Z`` and collision rate of a hard-disc gas at one packing
  fraction, with batch-means error bars, beside Henderson's ``Z``.
- :func:`hard_disc_pressure`: ``beta P d^2`` of monodisperse hard discs at one packing fraction from either
  algorithm, event-driven molecular dynamics or event-chain Monte Carlo, with the task's seconds (the
  hexatic benchmark's task).
- :func:`pit_accuracy`: one cell of the PIT accuracy map (a response policy at a frame step and packing
  fraction): what fraction of the exact collisions PIT misses, how far it turns the outgoing directions and
  how late it responds, as counts and sums that pool over seeds.
"""

from __future__ import annotations

import math
import time

import numpy as np

from discsim.errors import InvalidArgumentError

__all__ = ["equation_of_state", "hard_disc_pressure", "pit_accuracy"]


def equation_of_state(
    packing_fraction: float,
    *,
    seed: int = 0,
    n: int = 1000,
    equilibrate: float = 20.0,
    measure: float = 50.0,
    blocks: int = 10,
    periodic: bool = True,
    backend: str = "auto",
) -> dict:
    """Pressure, ``Z = P A / (N kT)`` and collision rate of a hard-disc gas at one packing fraction.

    A gas of ``n`` discs of radius 1 and mass 1 at ``kT = 1`` (:func:`discsim.random_gas`, a jittered
    lattice start) runs ``equilibrate`` collisions per disc to melt and forget its start; a fresh run from
    there measures for ``measure`` collisions per disc (both converted to time with Enskog's collision
    rate, :func:`discsim.enskog_collision_rate`), and :func:`discsim.thermo` averages it with batch-means
    error bars. Near and above the freezing range (packing 0.70-0.72) a lattice start melts slowly, and
    the numbers are those of whatever the run reached.

    Args:
        packing_fraction: ``N pi r^2 / A`` in ``(0, 0.85]``.
        seed: the gas's seed (positions and velocities).
        n: discs. equilibrate, measure: collisions per disc (positive).
        blocks: batches of the error bars (>= 2).
        periodic: periodic box (True) or reflecting walls (then the pressure is the bulk one).
        backend: the event-driven backend (``"auto"``, ``"python"`` or ``"numba"``).

    Returns:
        ``z``, ``z_err``, ``pressure``, ``pressure_err`` (energy per area), ``collision_rate``,
        ``collision_rate_err`` (collisions per disc per unit time), ``collisions`` (in the measured span),
        ``time`` (its length) and ``henderson_z`` (the reference at this packing fraction).

    Example:
        >>> out = equation_of_state(0.3, n=200, equilibrate=2, measure=10, seed=1)
        >>> sorted(out)[:3], bool(abs(out["z"] - out["henderson_z"]) < 6 * out["z_err"] + 0.05)
        (['collision_rate', 'collision_rate_err', 'collisions'], True)
    """
    from discsim.analysis.theory import enskog_collision_rate, henderson_z
    from discsim.analysis.thermo import thermo
    from discsim.engines.event_driven import EventDriven
    from discsim.scenarios import random_gas

    for name, value in (("equilibrate", equilibrate), ("measure", measure)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not (value >= 0 and math.isfinite(value)):
            msg = f"{name} must be a number of collisions per disc >= 0, got {value!r}"
            raise InvalidArgumentError(msg)
    if not measure > 0:
        msg = f"measure must be positive (collisions per disc to average over), got {measure!r}"
        raise InvalidArgumentError(msg)
    discs, box = random_gas(n, packing_fraction, periodic=periodic, seed=seed)
    rate = float(enskog_collision_rate(packing_fraction))
    if equilibrate > 0:
        discs = EventDriven(discs, box, record=False, backend=backend).run(until=equilibrate / rate).snapshot()
    span = measure / rate
    sim = EventDriven(discs, box, record=True, backend=backend).run(until=span)
    averages = thermo(sim, blocks=blocks)
    return {
        "z": averages.z,
        "z_err": averages.z_err,
        "pressure": averages.pressure,
        "pressure_err": averages.pressure_err,
        "collision_rate": averages.collision_rate,
        "collision_rate_err": averages.collision_rate_err,
        "collisions": averages.collisions,
        "time": span,
        "henderson_z": float(henderson_z(packing_fraction)),
    }


#: The algorithms :func:`hard_disc_pressure` runs.
ALGORITHMS = ("edmd", "ecmc")


def hard_disc_pressure(
    algorithm: str,
    packing_fraction: float,
    *,
    seed: int = 0,
    n: int = 256,
    equilibrate: float = 10.0,
    measure: float = 40.0,
    blocks: int = 8,
    start: str = "lattice",
    backend: str = "auto",
) -> dict:
    """``beta P d^2`` and ``Z`` of ``n`` equal hard discs (diameter ``d``) in a square periodic box, by either
    algorithm, with the seconds it took.

    ``"edmd"``: :class:`discsim.EventDriven` (``kT = 1``), ``equilibrate`` then ``measure`` collisions per disc
    (converted to time with Enskog's rate), ``Z`` from the collision virial at the canonical ``kT``
    (:func:`discsim.compressibility_factor`). ``"ecmc"``: :class:`discsim.EventChain`, ``equilibrate`` then
    ``measure`` chains per disc (chains of half the box), ``Z`` from the lifts. Either way the measured span is
    cut into ``blocks`` consecutive blocks, each measured afresh, and the error bar is their standard error
    (blocks longer than the correlation time make it honest; compare seeds to check). ``beta P d^2 = Z * 4 phi
    / pi``.

    Args:
        algorithm: ``"edmd"`` or ``"ecmc"``.
        packing_fraction: ``N pi d^2 / (4 A)``.
        seed: the start's seed (and the chains'). n: discs (a square number gives a square box's lattice).
        equilibrate, measure: collisions per disc (EDMD) or chains per disc (ECMC), >= 0 and > 0.
        blocks: blocks of the measured span (>= 2).
        start: ``"lattice"`` or ``"random"`` (:func:`discsim.random_gas`).
        backend: ``"auto"``, ``"python"`` or ``"numba"``.

    Returns:
        ``z``, ``z_err``, ``beta_p_d2``, ``beta_p_d2_err``, ``work`` (collisions, or lifts, measured) and
        ``seconds`` (the task's wall time, its start and equilibration included).

    Example:
        >>> out = hard_disc_pressure("ecmc", 0.5, n=64, equilibrate=2, measure=8, seed=1, backend="python")
        >>> 3.0 < out["z"] < 5.0, abs(out["beta_p_d2"] - out["z"] * 2.0 / math.pi) < 1e-12
        (True, True)
    """
    from discsim.analysis.theory import enskog_collision_rate
    from discsim.analysis.thermo import compressibility_factor
    from discsim.engines.event_chain import EventChain
    from discsim.engines.event_driven import EventDriven
    from discsim.scenarios import random_gas

    if algorithm not in ALGORITHMS:
        msg = f"algorithm must be one of {list(ALGORITHMS)}, got {algorithm!r}"
        raise InvalidArgumentError(msg)
    for name, value in (("equilibrate", equilibrate), ("measure", measure)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not (value >= 0 and math.isfinite(value)):
            msg = f"{name} must be a number >= 0 (collisions or chains per disc), got {value!r}"
            raise InvalidArgumentError(msg)
    if not measure > 0 or isinstance(blocks, bool) or not isinstance(blocks, int) or blocks < 2:
        msg = f"measure must be positive and blocks an integer >= 2, got {measure!r} and {blocks!r}"
        raise InvalidArgumentError(msg)
    began = time.perf_counter()
    discs, box = random_gas(n, packing_fraction, periodic=True, seed=seed, start=start)
    zs, work = [], 0
    if algorithm == "edmd":
        rate = float(enskog_collision_rate(packing_fraction))
        if equilibrate > 0:
            discs = EventDriven(discs, box, record=False, backend=backend).run(until=equilibrate / rate).snapshot()
        for _ in range(blocks):
            sim = EventDriven(discs, box, record=False, backend=backend).run(until=measure / blocks / rate)
            zs.append(compressibility_factor(sim))
            work += sim.counts["collisions"]
            discs = sim.snapshot()
    else:
        chain = EventChain(discs, box, seed=seed, backend=backend)
        chain.run(chains=max(0, round(equilibrate * n)))
        per_block = max(1, round(measure * n / blocks))
        for _ in range(blocks):
            before = chain.state()
            chain.run(chains=per_block)
            after = chain.state()
            zs.append(1.0 + (after.separation - before.separation) / (per_block * chain.chain_length))
            work += after.lifts - before.lifts
    z = float(np.mean(zs))
    z_err = float(np.std(zs, ddof=1) / math.sqrt(blocks))
    scale = 4.0 * packing_fraction / math.pi
    return {
        "z": z,
        "z_err": z_err,
        "beta_p_d2": z * scale,
        "beta_p_d2_err": z_err * scale,
        "work": int(work),
        "seconds": time.perf_counter() - began,
    }


#: PIT frames run past the horizon before comparing (a contact just before it is seen one frame later).
MARGIN_FRAMES = 1


def pit_accuracy(
    policy: str,
    step: float,
    packing_fraction: float,
    *,
    seed: int = 0,
    n: int = 400,
    free_times: float = 2.0,
    equilibrate: float = 10.0,
    budget: float | None = None,
    backend: str = "auto",
) -> dict:
    """One cell of the PIT accuracy map: a fixed-step policy against the exact run, on one gas.

    Units: discs of radius 1 and mass 1 at ``kT = 1/2``, so the root-mean-square speed is 1 and the frame
    interval is ``dt = step`` (``step = v dt / r``, how far a typical disc moves in a frame, in radii). A
    periodic gas of ``n`` discs (:func:`discsim.random_gas`) runs ``equilibrate`` collisions per disc under
    PIC to forget its lattice start; from there PIC (the truth) and PIT (:class:`discsim.FixedStep` with
    ``policy``) run over the horizon ``H``: ``free_times`` mean free times (Enskog's), rounded up to whole
    frames (at least one), PIT one frame further; :func:`discsim.compare` matches PIT's collisions to
    PIC's in ``[0, H]``.

    Args:
        policy: a fixed-step response policy (:data:`discsim.POLICIES`).
        step: the frame step ``v dt / r`` (positive).
        packing_fraction: of the gas, in ``(0, 0.85]``.
        seed: the gas's seed. n: discs.
        free_times: the horizon in mean free times. equilibrate: PIC collisions per disc before the start.
        budget: wall-clock seconds the PIT run may take (checked between runs of frames), or None; a run
            over budget gives ``status = "over budget"`` and no errors (its numbers then depend on the
            machine, so leave it None where results must repeat).
        backend: the backend of both engines (``"auto"``, ``"python"``, ``"numba"``).

    Returns:
        ``status`` (``"ok"``, ``"over budget"`` or ``"refused: ..."`` when the policy refuses the frame),
        ``dt``, ``horizon``, ``free_time``; PIT's ``frames`` and ``pair_tests``; counts over PIC's
        collisions in ``[0, H]``: ``truth_collisions``, ``matched``, ``missed``, ``spurious``; the outgoing
        direction errors (degrees) ``angle_count``, ``angle_sum``, ``angle_max``; the matched delays
        ``delay_count``, ``abs_delay_sum`` (time) and ``delay_sum_frames`` (signed, in frames);
        ``max_overlap``; and per cell ``missed_fraction``, ``mean_direction_error_deg`` and
        ``mean_abs_delay_free_times``. Sums and counts add up over seeds; NaN where not measured.

    Example:
        >>> out = pit_accuracy("resolve", 0.01, 0.1, n=60, seed=1, equilibrate=2)
        >>> out["status"], out["missed"] <= out["truth_collisions"]
        ('ok', True)
    """
    from discsim.analysis.compare import compare
    from discsim.analysis.theory import enskog_collision_rate
    from discsim.engines.event_driven import EventDriven
    from discsim.engines.fixed_step import POLICIES, FixedStep
    from discsim.errors import DiscsimError
    from discsim.scenarios import random_gas

    if policy not in POLICIES:
        msg = f"policy must be one of {list(POLICIES)}, got {policy!r}"
        raise InvalidArgumentError(msg)
    if isinstance(step, bool) or not isinstance(step, (int, float)) or not (step > 0 and math.isfinite(step)):
        msg = f"step must be a positive number (v dt / r), got {step!r}"
        raise InvalidArgumentError(msg)
    discs, box = random_gas(n, packing_fraction, periodic=True, seed=seed, temperature=0.5, radius=1.0)
    if equilibrate > 0:
        warm = EventDriven(discs, box, record=False, backend=backend)
        discs = warm.run(events=max(1, round(equilibrate * n))).snapshot()
    free_time = 1.0 / float(enskog_collision_rate(packing_fraction, radius=1.0, kT=0.5))
    dt = float(step)
    horizon = max(1, math.ceil(free_times * free_time / dt - 1e-9)) * dt
    out = {"status": "ok", "dt": dt, "horizon": horizon, "free_time": free_time}
    nan = {key: math.nan for key in _ERROR_KEYS}
    truth = EventDriven(discs, box, backend=backend).run(until=horizon + (MARGIN_FRAMES + 1) * dt)
    try:
        pit = FixedStep(discs, box, dt=dt, policy=policy, backend=backend)
    except (DiscsimError, ValueError) as exc:
        return {**out, "status": f"refused: {exc}", "frames": math.nan, "pair_tests": math.nan, **nan}
    end = horizon + MARGIN_FRAMES * dt
    started = time.perf_counter()
    try:
        while pit.time < end - 1e-9 * dt:
            pit.run(until=min(end, pit.time + max(dt, end / 64)))
            if budget is not None and time.perf_counter() - started > budget:
                return {**out, "status": "over budget", "frames": pit.frames, "pair_tests": math.nan, **nan}
    except (DiscsimError, ValueError) as exc:  # swept refuses frames whose sweeps could wrap a small box
        return {**out, "status": f"refused: {exc}", "frames": pit.frames, "pair_tests": math.nan, **nan}
    out.update(frames=pit.frames, pair_tests=pit.counts["pair_tests"])
    out.update(_errors_up_to(compare(truth, pit, times=[horizon]), truth, pit, horizon, free_time))
    return out


_ERROR_KEYS = (
    "truth_collisions",
    "matched",
    "missed",
    "spurious",
    "angle_count",
    "angle_sum",
    "angle_max",
    "delay_count",
    "abs_delay_sum",
    "delay_sum_frames",
    "max_overlap",
    "missed_fraction",
    "mean_direction_error_deg",
    "mean_abs_delay_free_times",
)


def _errors_up_to(report, truth, pit, until: float, free_time: float) -> dict:
    """Counts and sums of PIT's errors on PIC's collisions in ``[0, until]``."""
    events = truth.events
    within = np.array([m[2] <= until for m in report.matches], dtype=bool).reshape(-1)
    delays = report.delays[within] if within.size else np.zeros(0)
    angles = report.direction_errors[within] if within.size else np.zeros((0, 2))
    angles = angles[np.isfinite(angles)]
    collisions = int(np.sum((events["kind"] == 0) & (events["time"] <= until)))
    missed = sum(1 for *_, t in report.missed_collisions if t <= until)
    return {
        "truth_collisions": collisions,
        "matched": int(within.sum()),
        "missed": missed,
        "spurious": sum(1 for *_, t in report.spurious_collisions if t <= until),
        "angle_count": int(angles.size),
        "angle_sum": float(angles.sum()),
        "angle_max": float(angles.max()) if angles.size else math.nan,
        "delay_count": int(delays.size),
        "abs_delay_sum": float(np.abs(delays).sum()),
        "delay_sum_frames": float(delays.sum()) / pit.dt,
        "max_overlap": float(report.max_overlap),
        "missed_fraction": missed / collisions if collisions else math.nan,
        "mean_direction_error_deg": float(angles.mean()) if angles.size else math.nan,
        "mean_abs_delay_free_times": float(np.abs(delays).mean()) / free_time if delays.size else math.nan,
    }
