"""``compress``: grow the discs to a target packing fraction (Lubachevsky-Stillinger), exactly event-driven.

See :func:`compress`. The loop itself is :mod:`.loop` (pure Python on lists, or compiled by numba).
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass

import numpy as np

from discsim import _numba
from discsim.cells import grid_shape, neighbour_pairs
from discsim.engines.compress import loop
from discsim.errors import InvalidArgumentError, PackingError, WrongTypeError
from discsim.model import Box, Discs
from discsim.scene import check_fits

__all__ = ["DENSEST_PACKING", "CompressionReport", "compress"]

#: The densest packing of equal discs in the plane, the triangular lattice: pi / (2 sqrt 3) = 0.9069.
DENSEST_PACKING = math.pi / (2.0 * math.sqrt(3.0))
#: Relative shrink of all radii at the end, beyond the smallest gap, when roundoff left a contact inside.
SHRINK = 1e-12
_HISTORY = np.dtype([("packing", "f8"), ("collisions", "i8"), ("seconds", "f8"), ("z", "f8"), ("time", "f8")])


@dataclass(frozen=True)
class CompressionReport:
    """What :func:`compress` did.

    Attributes:
        packing_fraction: the packing reached (after the final shrink, if any).
        target: the packing asked for.
        reached: True when the target was reached (to within the final shrink).
        jammed: True when the compression stopped because the pressure diverged below the target.
        reason: ``"reached"``, ``"jammed"`` or ``"max_collisions"``.
        collisions: disc-disc collisions in all. wall_events: disc-wall collisions.
        time: simulated time of the compression. seconds: wall-clock time.
        z: the reduced pressure ``PA / NkT`` (collision virial) of the last epoch; it diverges at jamming.
        epochs: thermostat epochs run. shrink: the factor the radii were scaled by at the end (1.0: none).
        backend: ``"python"`` or ``"numba"``.
        history: one row per epoch: packing, collisions so far, seconds so far, Z, simulated time.
    """

    packing_fraction: float
    target: float
    reached: bool
    jammed: bool
    reason: str
    collisions: int
    wall_events: int
    time: float
    seconds: float
    z: float
    epochs: int
    shrink: float
    backend: str
    history: np.ndarray

    def collisions_to(self, packing: float, n: int) -> float:
        """Collisions per disc (``n`` discs) spent to reach ``packing``, interpolated between epochs (nan if never)."""
        h = self.history
        if len(h) == 0 or h["packing"][-1] < packing * (1.0 - 1e-9):
            return math.nan
        k = int(np.searchsorted(h["packing"], packing * (1.0 - 1e-9)))
        if k == 0:
            return float(h["collisions"][0]) / n
        p0, p1 = h["packing"][k - 1], h["packing"][k]
        c0, c1 = h["collisions"][k - 1], h["collisions"][k]
        w = (packing - p0) / (p1 - p0) if p1 > p0 else 1.0
        return float(c0 + w * (c1 - c0)) / n

    def __str__(self) -> str:
        what = {
            "reached": "reached",
            "jammed": "JAMMED below",
            "max_collisions": "ran out of collisions (max_collisions) below",
        }[self.reason]
        return (
            f"packing {self.packing_fraction:.6f} ({what} the target {self.target:g}) after {self.collisions:,} "
            f"collisions, simulated time {self.time:.6g}, {self.seconds:.3g} s ({self.backend}), Z = {self.z:.4g}"
        )


def _positive(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise InvalidArgumentError(msg)
    if not (0.0 < value < math.inf):
        msg = f"{name} must be positive and finite, got {value!r}"
        raise InvalidArgumentError(msg)
    return float(value)


def _count(name: str, value) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        msg = f"{name} must be a positive integer or None, got {value!r}"
        raise InvalidArgumentError(msg)
    return int(value)


def compress(
    discs: Discs,
    box: Box,
    packing_fraction: float,
    growth_rate: float = 0.01,
    seed: int | None = None,
    *,
    temperature: float = 1.0,
    max_collisions: int | None = None,
    max_pressure: float = 1e5,
    epoch_collisions: int | None = None,
    backend: str = "auto",
    progress: bool = False,
) -> tuple[Discs, CompressionReport]:
    """Grow all discs until they fill ``packing_fraction`` of the box (Lubachevsky-Stillinger), exactly.

    The event-driven dynamics runs while every radius grows linearly in time, in proportion to itself:
    ``r_i(t) = r_i(0) (1 + g t)`` within an epoch, so the size ratios of a mixture stay as given (a 1:1.4
    binary mixture stays 1:1.4). ``g`` is set so that the mean diameter grows at ``growth_rate`` thermal
    speeds ``sqrt(kT / m)`` (``m`` the mean mass): the slower, the closer to equilibrium (a crystal for
    equal discs), the faster, the more disordered. Two discs touch when ``|dr + dv t| = s + s' t``
    (contact distance ``s`` growing at ``s'``), a quadratic solved by its cancellation-free root; a
    collision is elastic in the frame of the growing surfaces, so the normal separation speed after it
    exceeds the growth ``s'`` by as much as the approach speed did before (``vn' = 2 s' - vn``, momentum
    conserved); a disc against a wall likewise (``v' = 2 r' - v``). Every collision so adds kinetic energy:
    the thermostat rescales all velocities to ``kT = temperature`` at the end of each epoch of
    ``epoch_collisions`` collisions (default ``2 N``), where the radii are rebased and all predictions made
    afresh. Periodic and walled boxes; the box does not change, the discs grow.

    The compression stops when the target is reached, or, below it, when the reduced pressure ``Z``
    (collision virial of an epoch) exceeds ``max_pressure`` (the packing has jammed: free-volume theory
    puts the jamming packing within about ``2 phi / Z`` of the packing reached), or after
    ``max_collisions``. The report says which, with the packing reached; nothing is raised.

    At the end, if roundoff left a contact a hair inside (a relative 1e-16 or so), all radii shrink by
    that much and a relative ``SHRINK`` = 1e-12 more, so that ``EventDriven(discs, box)`` accepts the
    result (the report gives the factor). Velocities are at ``kT = temperature``.

    Args:
        discs: the starting discs (no overlaps; finite masses). Velocities are rescaled to ``kT``; all at
            rest, or ``seed`` given, draws new Gaussian velocities (zero total momentum).
        box: the box, periodic or walled.
        packing_fraction: the target, above the discs' packing now and below 0.9069 (``DENSEST_PACKING``).
        growth_rate: mean diameter growth per unit time, in thermal speeds (positive, finite; 0.001-0.1).
        seed: seed of the new velocities, or None to keep the directions given.
        temperature: kT of the thermostat. max_collisions: budget of collisions (None: none).
        max_pressure: the reduced pressure Z taken for jamming.
        epoch_collisions: collisions between two rescalings (default ``2 N``, at least 100).
        backend: ``"auto"`` (numba when it imports), ``"numba"`` or ``"python"``.
        progress: show a progress bar (tqdm when installed).

    Returns:
        ``(discs, report)``: the compressed discs (same masses and groups) and a :class:`CompressionReport`.

    Raises:
        PackingError: a target above 0.9069 or not above the packing now, or (``BoxTooSmallError``) a
            periodic box under 3 final diameters a side.
        InvalidArgumentError: a growth rate, temperature or limit that is not positive and finite; infinite
            masses. OverlapError, OutsideBoxError: discs that do not fit. All before anything runs.

    Example:
        >>> import discsim as ds
        >>> gas, box = ds.random_gas(100, 0.3, seed=1)
        >>> dense, report = ds.compress(gas, box, packing_fraction=0.6, backend="python")
        >>> report.reached, round(report.packing_fraction, 6)
        (True, 0.6)
    """
    if not isinstance(discs, Discs):
        msg = f"discs must be a discsim.Discs, got {type(discs).__name__}"
        raise WrongTypeError(msg)
    if not isinstance(box, Box):
        msg = f"box must be a discsim.Box, got {type(box).__name__}"
        raise WrongTypeError(msg)
    n = len(discs)
    radii = np.array(discs.radii, dtype=float)
    area = box.width * box.height
    phi0 = math.pi * float(np.sum(radii**2)) / area
    if isinstance(packing_fraction, bool) or not isinstance(packing_fraction, (int, float, np.integer, np.floating)):
        msg = f"packing_fraction must be a number, got {packing_fraction!r}"
        raise PackingError(msg)
    target = float(packing_fraction)
    if not (target < DENSEST_PACKING):  # also nan
        msg = (
            f"packing fraction {packing_fraction!r} cannot be reached: discs pack at most "
            f"pi / (2 sqrt 3) = {DENSEST_PACKING:.6f} (the triangular lattice)"
        )
        raise PackingError(msg)
    if not target > phi0:
        msg = f"packing fraction {packing_fraction!r} is not above the discs' packing now, {phi0:.6g}"
        raise PackingError(msg)
    growth_rate = _positive("growth_rate", growth_rate)
    temperature = _positive("temperature", temperature)
    max_pressure = _positive("max_pressure", max_pressure)
    max_collisions = _count("max_collisions", max_collisions)
    epoch_collisions = _count("epoch_collisions", epoch_collisions) or max(2 * n, 100)
    masses = np.array(discs.masses, dtype=float)
    if n == 0:
        msg = "compress needs at least one disc"
        raise InvalidArgumentError(msg)
    if not np.isfinite(masses).all():
        i = int(np.flatnonzero(~np.isfinite(masses))[0])
        msg = f"disc {i} has mass {masses[i]!r}: compress moves every disc, so masses must be finite"
        raise InvalidArgumentError(msg)
    check_fits(discs, box)
    name = _numba.resolve_backend(backend, ("python", "numba"), "compress")
    final = math.sqrt(target / phi0)
    nx, ny = grid_shape(
        box,
        2.0 * float(radii.max()) * final * (1.0 + 1e-9),
        max(4 * n, 64),
        what="the largest contact distance at the target packing",
    )

    mean_mass = float(masses.mean())
    velocities = np.array(discs.velocities, dtype=float)
    if seed is not None or not velocities.any():
        rng = np.random.default_rng(seed)
        velocities = rng.normal(size=(n, 2)) * np.sqrt(temperature / masses)[:, None]
        if n > 1:
            velocities -= (masses[:, None] * velocities).sum(axis=0) / masses.sum()
    positions = np.array(discs.positions, dtype=float)

    v_thermal = math.sqrt(temperature / mean_mass)
    history = []
    collisions = walls = epochs = 0
    sim_time = 0.0
    z = 1.0
    reason = "reached"
    phi = phi0
    start = _time.perf_counter()
    bar_context = None
    if progress:
        from discsim._progress import progress_bar

        bar_context = progress_bar(100.0, by_time=False, unit="%")
        bar = bar_context.__enter__()
        bar.start(0)
        bar_at = 0.0
    try:
        while True:
            energy = 0.5 * float(np.sum(masses[:, None] * velocities**2))
            if energy > 0:
                velocities *= math.sqrt(n * temperature / energy)  # the thermostat
            g = growth_rate * v_thermal / (2.0 * float(radii.mean()))
            t_end = (math.sqrt(target / phi) - 1.0) / g
            budget = epoch_collisions
            if max_collisions is not None:
                budget = min(budget, max_collisions - collisions)
            positions, new_velocities, t, stats = epoch(
                positions, velocities, radii, masses, box, (nx, ny), g, t_end, budget, name
            )
            epochs += 1
            done = stats["collisions"]
            collisions += done
            walls += stats["walls"]
            sim_time += t
            kt = 0.5 * (energy + 0.5 * float(np.sum(masses[:, None] * new_velocities**2))) / n
            velocities = new_velocities
            at_end = t >= t_end
            if at_end:
                radii = radii * math.sqrt(target / phi)
                phi = target
            else:
                radii = radii * (1.0 + g * t)
                phi = math.pi * float(np.sum(radii**2)) / area
            if t > 0:
                z = 1.0 + stats["virial"] / (2.0 * n * kt * t)
            elif done:
                z = math.inf  # collisions without the clock moving
            history.append((phi, collisions, _time.perf_counter() - start, z, sim_time))
            if progress:
                shown = min(100.0, 100.0 * (phi - phi0) / (target - phi0))  # percent of the way
                bar.update(shown - bar_at, collisions)
                bar_at = shown
            if at_end:
                break
            if z > max_pressure:
                reason = "jammed"
                break
            if max_collisions is not None and collisions >= max_collisions:
                reason = "max_collisions"
                break
    finally:
        if bar_context is not None:
            bar_context.__exit__(None, None, None)

    if box.periodic:
        positions = box.wrap(positions)
    shrink = _shrink(positions, radii, box)
    radii = radii * shrink
    energy = 0.5 * float(np.sum(masses[:, None] * velocities**2))
    if energy > 0:
        velocities *= math.sqrt(n * temperature / energy)
    result = Discs(positions, velocities, radii, discs.masses, discs.groups)
    reached = math.pi * float(np.sum(radii**2)) / area
    report = CompressionReport(
        packing_fraction=reached,
        target=target,
        reached=reason == "reached",
        jammed=reason == "jammed",
        reason=reason,
        collisions=collisions,
        wall_events=walls,
        time=sim_time,
        seconds=_time.perf_counter() - start,
        z=z,
        epochs=epochs,
        shrink=shrink,
        backend=name,
        history=np.array(history, dtype=_HISTORY),
    )
    return result, report


def epoch(positions, velocities, radii, masses, box: Box, grid: tuple[int, int], g, t_end, budget, backend):
    """One epoch of growing discs from time 0 (radii ``radii * (1 + g t)``) to ``t_end`` or ``budget`` collisions.

    Returns:
        ``(positions, velocities, t, stats)`` at the stopping time ``t`` (positions not wrapped), with
        ``stats``: ``collisions``, ``walls``, ``crossings``, ``stale`` (counts) and ``virial`` (the sum of
        impulse times contact distance over the collisions) and ``wall_virial``.
    """
    n = len(radii)
    nx, ny = grid
    if backend == "numba":
        from discsim.engines.compress import compiled

        run_epoch = compiled.run_epoch

        def floats(a):  # a fresh array: the loop writes into each
            return np.array(a, dtype=np.float64)

        def ints(a):
            return np.array(a, dtype=np.int64)
    else:  # plain lists: the pure-Python loop indexes them 3-5x faster than numpy arrays
        run_epoch = loop.run_epoch

        def floats(a):
            return [float(v) for v in a]

        def ints(a):
            return [int(v) for v in a]

    if box.periodic:
        positions = box.wrap(positions)
    cw, ch = box.width / nx, box.height / ny
    cells = np.clip((positions[:, 0] / cw).astype(np.int64), 0, nx - 1) * ny + np.clip(
        (positions[:, 1] / ch).astype(np.int64), 0, ny - 1
    )
    head, nxt, prv = _cell_lists(cells, nx * ny)
    x, y = floats(positions[:, 0]), floats(positions[:, 1])
    vx, vy = floats(velocities[:, 0]), floats(velocities[:, 1])
    out, iout = floats([0.0, 0.0, 0.0]), ints([0, 0, 0, 0])
    zeros = np.zeros(n, dtype=np.int64)
    t = run_epoch(
        x, y, vx, vy, floats(np.zeros(n)), floats(radii), floats(masses), ints(zeros), ints(cells), ints(head),
        ints(nxt), ints(prv), ints(zeros), floats(np.zeros(n)), ints(zeros), ints(zeros), ints(zeros), ints(zeros),
        floats([box.width, box.height, g, t_end, cw, ch]), ints([nx, ny, int(box.periodic), budget]), out, iout,
    )  # fmt: skip
    positions = np.column_stack([np.asarray(x, dtype=float), np.asarray(y, dtype=float)])
    velocities = np.column_stack([np.asarray(vx, dtype=float), np.asarray(vy, dtype=float)])
    stats = {
        "collisions": int(iout[0]),
        "walls": int(iout[1]),
        "crossings": int(iout[2]),
        "stale": int(iout[3]),
        "virial": float(out[1]),
        "wall_virial": float(out[2]),
    }
    return positions, velocities, float(t), stats


def _cell_lists(cells: np.ndarray, size: int):
    """``head`` (first disc of each cell, -1 if none), ``nxt`` and ``prv``: doubly linked lists by cell, numpy only."""
    order = np.argsort(cells, kind="stable")
    ordered = cells[order]
    same = ordered[1:] == ordered[:-1]
    nxt = np.full(len(cells), -1, dtype=np.int64)
    prv = np.full(len(cells), -1, dtype=np.int64)
    nxt[order[:-1][same]] = order[1:][same]
    prv[order[1:][same]] = order[:-1][same]
    head = np.full(size, -1, dtype=np.int64)
    first = np.ones(len(cells), dtype=bool)
    first[1:] = ~same
    head[ordered[first]] = order[first]
    return head, nxt, prv


def _shrink(positions: np.ndarray, radii: np.ndarray, box: Box) -> float:
    """1.0, or the factor that leaves every pair and wall a relative ``SHRINK`` apart if one is not."""
    i, j, d = neighbour_pairs(positions, 2.0 * float(radii.max()) * (1.0 + 1e-9), box)
    ratio = 1.0 if len(i) == 0 else float(np.min(np.hypot(d[:, 0], d[:, 1]) / (radii[i] + radii[j])))
    if not box.periodic:
        gaps = np.minimum(positions, box.size - positions) / radii[:, None]
        ratio = min(ratio, float(gaps.min()))
    if ratio >= 1.0 + SHRINK:
        return 1.0
    return min(ratio, 1.0) * (1.0 - SHRINK)
