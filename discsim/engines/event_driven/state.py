"""The event-driven engine's public run state: plain numpy arrays and scalars, in the caller's numbering.

Every backend loads it and exports it (:class:`EventDrivenState`); a checkpoint stores it; an observer or an
analysis may read it. Nothing in it is Python-specific.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from discsim.engines.base import EngineState
from discsim.errors import CheckpointError
from discsim.physics.dynamics import advance_many

__all__ = ["EventDrivenState"]


@dataclass(eq=False)
class EventDrivenState(EngineState):
    """Everything an event-driven run needs to continue bit for bit (version 5: version 1 plus the laws' fields
    (version 2), the discs' turning (version 3), the sensors' (version 4) and the piston's (version 5); an older
    state reads the fields it lacks as their defaults: no disc at rest, no collision recorded, spins and angles zero,
    no sensor, no piston).

    Per-disc arrays are indexed in the caller's numbering (as ``discs``); disc
    indices inside arrays (partners, cell members, queue owners) too. Times in
    ``ref_times``, ``kept_time`` and ``queue_time`` count from ``epoch`` (the
    internal clock's origin moves forward during long runs, so that these
    times keep their resolution).

    Scalars:
        time: the current simulated time. epoch: origin of the internal times.
        since_rebase: physical events since the epoch last moved.
        collisions, wall_hits, cell_crossings, stale, predictions: the counters.
        virial: sum over collisions of ``dp_i . (r_i - r_j)`` (pressure).
        max_overlap: deepest overlap at a contact, as a fraction of the contact distance.
        max_queue: most events pending at once.
        last_time, last_kind, last_i, last_j: the last physical event (``last_kind`` -1 if none).
        grid_nx, grid_ny: the cell grid the cell indices refer to.

    Arrays:
        ref_positions ``(N, 2)``, velocities ``(N, 2)``, ref_times ``(N,)``:
            disc ``i`` is at ``ref_positions[i] + velocities[i] (t - ref_times[i])``
            (not wrapped: may lie up to a cell outside a periodic box).
        images ``(N, 2)`` int64: box lengths to add to that position to unwrap it.
        collision_counts ``(N,)`` int64: per-disc counters that invalidate stale predictions.
        cell ``(N,)`` int64: each disc's cell; cell_members ``(N,)`` and
            cell_sizes ``(C,)``: the discs of each cell in order (order decides ties).
        kept_time, kept_partner, kept_stamp ``(N,)``: each disc's earliest predicted
            collision from its last full scan (partner -1 if none) and the partner's counter then.
        order ``(N,)`` int64: the backend's internal numbering (internal disc ``k``
            is disc ``order[k]``); it decides the order of simultaneous events.
        queue_owner, queue_time, queue_kind, queue_other, queue_stamp ``(Q,)``:
            the pending events, one per owner: kind (:class:`~discsim.events.EventKind`),
            the partner (collision), wall axis, crossing direction or segment, and
            the partner's counter (collisions only).
        resting ``(N,)`` int64: 1 for a disc at rest under gravity (velocity zero, gravity off).
        last_collision ``(N,)``: each disc's last collision time (absolute; ``-inf`` if none or unrecorded),
            kept for the TC model only.
        spins ``(N,)``: each disc's angular velocity (radians per time unit, counter-clockwise positive); constant
            between its collisions, changed only by those of rough discs (``roughness`` above -1).
        angles ``(N,)``: each disc's angle at ``time`` (radians, counter-clockwise, 0 at the start): the
            orientation a viewer's mark shows; no law reads it.
        sensed ``(N, S)`` int64: 1 where disc ``i``'s centre is inside sensor ``k`` (:class:`discsim.Sensor`; a
            line's left side) as the run knows it (a disc on the edge just after crossing it counts as crossed);
            ``(N, 0)`` without sensors, or unknown: the backend then takes it from where the discs are.
        piston ``(5,)``: the piston's (:class:`discsim.Piston`) height and velocity at the internal time ``piston[2]``
            (counted from ``epoch``, as ``ref_times``), its impacts so far (the stamp of the contacts predicted with
            it, in ``queue_stamp``) and the pressure on it; ``(0,)`` without a piston.

    Scalars of the laws: dissipated (kinetic energy lost in collisions and by discs coming to rest),
    rests (discs put to rest). Of the sensors: sensor_events (enter and leave events).
    """

    VERSION = 5

    time: float
    epoch: float
    since_rebase: int
    collisions: int
    wall_hits: int
    cell_crossings: int
    stale: int
    predictions: int
    virial: float
    max_overlap: float
    max_queue: int
    last_time: float
    last_kind: int
    last_i: int
    last_j: int
    grid_nx: int
    grid_ny: int
    ref_positions: np.ndarray
    velocities: np.ndarray
    ref_times: np.ndarray
    images: np.ndarray
    collision_counts: np.ndarray
    cell: np.ndarray
    cell_members: np.ndarray
    cell_sizes: np.ndarray
    kept_time: np.ndarray
    kept_partner: np.ndarray
    kept_stamp: np.ndarray
    order: np.ndarray
    queue_owner: np.ndarray
    queue_time: np.ndarray
    queue_kind: np.ndarray
    queue_other: np.ndarray
    queue_stamp: np.ndarray
    resting: np.ndarray = None  # type: ignore[assignment]  # None: none at rest (filled in by __post_init__)
    last_collision: np.ndarray = None  # type: ignore[assignment]  # None: no collision recorded
    dissipated: float = 0.0
    rests: int = 0
    spins: np.ndarray = None  # type: ignore[assignment]  # None: zeros (filled in by __post_init__)
    angles: np.ndarray = None  # type: ignore[assignment]  # None: zeros
    sensed: np.ndarray = None  # type: ignore[assignment]  # None: (N, 0), taken from the positions when loaded
    sensor_events: int = 0
    piston: np.ndarray = None  # type: ignore[assignment]  # None: (0,), no piston

    def __post_init__(self) -> None:
        n = len(self.order)
        if self.resting is None:
            self.resting = np.zeros(n, dtype=np.int64)
        if self.last_collision is None:
            self.last_collision = np.full(n, -np.inf)
        if self.spins is None:
            self.spins = np.zeros(n)
        if self.angles is None:
            self.angles = np.zeros(n)
        if self.sensed is None:
            self.sensed = np.zeros((n, 0), dtype=np.int64)
        if self.piston is None:
            self.piston = np.zeros(0)

    @classmethod
    def from_arrays(cls, scalars: dict, arrays: dict[str, np.ndarray], version: int):
        """As :meth:`EngineState.from_arrays`; a version-1 state (before the laws) gets their defaults, a version-1
        or 2 state (before spins) spins and angles zero, a version 1 to 3 state no sensor, 1 to 4 no piston."""
        n = len(arrays.get("order", ()))
        if version == 1:
            arrays = {**arrays, "resting": np.zeros(n, dtype=np.int64), "last_collision": np.full(n, -np.inf)}
            scalars = {**scalars, "dissipated": 0.0, "rests": 0}
            version = 2
        if version == 2:
            arrays = {**arrays, "spins": np.zeros(n), "angles": np.zeros(n)}
            version = 3
        if version == 3:
            arrays = {**arrays, "sensed": np.zeros((n, 0), dtype=np.int64)}
            scalars = {**scalars, "sensor_events": 0}
            version = 4
        if version == 4:
            arrays = {**arrays, "piston": np.zeros(0)}
            version = cls.VERSION
        return super().from_arrays(scalars, arrays, version)

    def check(self, n: int, n_cells: int) -> None:
        """Refuse a state that cannot belong to ``n`` discs on a grid of ``n_cells`` cells.

        Checks every field's shape and type, that the numbers are finite, that indices lie in range
        and that the cells and the numbering are permutations of the discs. O(N log N).

        Raises:
            CheckpointError: naming the field and what is wrong with it.
        """

        def fail(field: str, what: str) -> None:
            msg = f"EventDrivenState.{field}: {what}"
            raise CheckpointError(msg)

        shapes = {
            "ref_positions": ((n, 2), "f"),
            "velocities": ((n, 2), "f"),
            "ref_times": ((n,), "f"),
            "images": ((n, 2), "i"),
            "collision_counts": ((n,), "i"),
            "cell": ((n,), "i"),
            "cell_members": ((n,), "i"),
            "cell_sizes": ((n_cells,), "i"),
            "kept_time": ((n,), "f"),
            "kept_partner": ((n,), "i"),
            "kept_stamp": ((n,), "i"),
            "order": ((n,), "i"),
            "resting": ((n,), "i"),
            "last_collision": ((n,), "f"),
            "spins": ((n,), "f"),
            "angles": ((n,), "f"),
        }
        q = np.shape(self.queue_owner)
        shapes.update(
            {
                name: (q, kind)
                for name, kind in (
                    ("queue_owner", "i"),
                    ("queue_time", "f"),
                    ("queue_kind", "i"),
                    ("queue_other", "i"),
                    ("queue_stamp", "i"),
                )
            }
        )
        for field, (shape, kind) in shapes.items():
            value = getattr(self, field)
            if not isinstance(value, np.ndarray) or value.shape != shape or value.dtype.kind != kind:
                got = f"{value.dtype} {value.shape}" if isinstance(value, np.ndarray) else type(value).__name__
                fail(field, f"expected a {'float' if kind == 'f' else 'integer'} array of shape {shape}, got {got}")
        for field in ("time", "epoch", "virial", "max_overlap", "last_time"):
            if not isinstance(getattr(self, field), (int, float)) or not np.isfinite(getattr(self, field)):
                fail(field, f"expected a finite number, got {getattr(self, field)!r}")
        for field in ("ref_positions", "velocities", "ref_times", "queue_time", "spins", "angles"):
            bad = ~np.isfinite(getattr(self, field))
            if bad.any():
                fail(field, f"non-finite value {getattr(self, field)[bad].flat[0]!r}")
        for field in ("order", "cell_members"):
            if not np.array_equal(np.sort(getattr(self, field)), np.arange(n)):
                fail(field, f"expected each disc 0..{n - 1} exactly once")
        if ((self.cell < 0) | (self.cell >= n_cells)).any() or (self.cell_sizes < 0).any():
            fail("cell", f"cell indices must lie in [0, {n_cells})")
        listed = (
            np.repeat(np.arange(n_cells), np.clip(self.cell_sizes, 0, None)) if self.cell_sizes.sum() == n else None
        )
        if listed is None or not np.array_equal(listed[np.argsort(self.cell_members)], self.cell):
            fail("cell_sizes", "the cells' members and the discs' cells disagree")
        if len(self.queue_owner) > n or len(np.unique(self.queue_owner)) != len(self.queue_owner):
            fail("queue_owner", "at most one pending event per disc")
        if ((self.queue_owner < 0) | (self.queue_owner >= n)).any():
            fail("queue_owner", f"disc indices must lie in [0, {n})")
        if ((self.queue_kind < 0) | ((self.queue_kind > 3) & (self.queue_kind != 7) & (self.queue_kind != 10))).any():
            fail("queue_kind", "kinds are 0 (collision), 1 (wall), 2 (crossing), 3 (segment), 7 (sensor), 10 (piston)")
        piston = self.piston
        if not isinstance(piston, np.ndarray) or piston.shape not in ((0,), (5,)) or not np.isfinite(piston).all():
            fail("piston", f"expected 5 finite numbers or none, got {piston!r}")
        sensed = self.sensed
        if not isinstance(sensed, np.ndarray) or sensed.ndim != 2 or len(sensed) != n or sensed.dtype.kind != "i":
            got = f"{sensed.dtype} {sensed.shape}" if isinstance(sensed, np.ndarray) else type(sensed).__name__
            fail("sensed", f"expected an integer array of shape ({n}, S), got {got}")
        if ((sensed != 0) & (sensed != 1)).any():
            fail("sensed", "expected 0 or 1")
        partners = self.queue_other[self.queue_kind == 0]
        if ((partners < 0) | (partners >= n)).any() or ((self.kept_partner < -1) | (self.kept_partner >= n)).any():
            fail("queue_other", f"collision partners must lie in [0, {n})")

    @property
    def counts(self) -> dict[str, int]:
        """The counters as ``EventDriven.counts`` gives them."""
        return {
            "collisions": self.collisions,
            "wall_hits": self.wall_hits,
            "cell_crossings": self.cell_crossings,
            "stale": self.stale,
            "predictions": self.predictions,
        }

    def positions_at(self, time: float, gravity=None, falls: np.ndarray | None = None, drag: float = 0.0) -> np.ndarray:
        """``(N, 2)`` centres at ``time`` (absolute), not wrapped.

        Args:
            gravity: the run's ``(gx, gy)`` (None: none).
            falls: ``(N,)`` bool, the discs that fall (finite mass and not at rest); None: all that are not at
                rest.
            drag: the run's drag ``gamma`` (0: none).
        """
        t = time - self.epoch
        (x0, y0), (vx, vy) = self.ref_positions.T, self.velocities.T
        x, y, _, _ = advance_many(x0, y0, vx, vy, t - self.ref_times, 0.0, 0.0, drag)
        if gravity is not None and tuple(gravity) != (0.0, 0.0):
            falls = self.resting == 0 if falls is None else falls
            gx, gy = float(gravity[0]), float(gravity[1])
            fx, fy, _, _ = advance_many(x0, y0, vx, vy, t - self.ref_times, gx, gy, drag)
            x, y = np.where(falls, fx, x), np.where(falls, fy, y)
        return np.column_stack([x, y]).reshape(-1, 2)
