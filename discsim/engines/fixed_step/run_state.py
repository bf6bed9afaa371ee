"""The fixed-step engine's run state in and out: the fresh state, ``state()`` and loading one.

:class:`FixedStepRun` is the part of :class:`~discsim.engines.fixed_step.engine.FixedStep` that turns its
working parts (the paths, the tally, the broad phase's Verlet list, the frame clock) into a
:class:`~discsim.engines.fixed_step.state.FixedStepState` and back: what a checkpoint stores, what
``add_discs`` and ``remove_discs`` rebuild from.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from discsim.engines.fixed_step.arrays import Paths, Shapes, Tally
from discsim.engines.fixed_step.state import FixedStepState
from discsim.errors import CheckpointError
from discsim.model import Box, Discs

__all__ = ["FixedStepRun"]


class FixedStepRun:
    """The run state of a fixed-step engine, out and in (a mixin of :class:`FixedStep`)."""

    # What the engine provides (declared for readers and the type checker).
    box: Box
    discs: Discs
    start_time: float
    time: float
    _frame_time: float
    _paths: Paths
    _tally: Tally
    _broad: Any
    _shapes: Shapes

    def _initial_state(self) -> FixedStepState:
        discs = self.discs
        n = len(discs)
        empty = np.zeros(0, dtype=np.int64)
        return FixedStepState(
            time=self.start_time,
            frame_time=self.start_time,
            frames=0,
            **dict.fromkeys(("pair_tests", "segment_tests", "bisection_tests", "detections", "wall_hits"), 0),
            list_builds=0,
            max_overlap=0.0,
            virial=0.0,
            ref_positions=discs.positions,
            velocities=discs.velocities,
            ref_times=np.full(n, self.start_time),
            images=np.zeros((n, 2), dtype=np.int64),
            frame_positions=discs.positions,
            list_positions=np.zeros((0, 2)),
            list_i=empty,
            list_j=empty,
            last_collision=np.full(n, -np.inf),
            spins=np.array(discs.spins),
            angles=np.zeros(n),
        )

    def state(self) -> FixedStepState:
        """The run state (:class:`~discsim.engines.fixed_step.state.FixedStepState`): new arrays."""
        paths, counts = self._paths, self._tally.counts
        spins, angles = paths.turning(float(self.time))
        list_positions, list_i, list_j = self._broad.export()
        return FixedStepState(
            time=float(self.time),
            frame_time=float(self._frame_time),
            frames=counts["frames"],
            pair_tests=counts["pair_tests"],
            segment_tests=counts["segment_tests"],
            bisection_tests=counts["bisection_tests"],
            detections=counts["detections"],
            wall_hits=counts["wall_hits"],
            list_builds=counts["list_builds"],
            max_overlap=float(self._tally.max_overlap),
            virial=float(self._tally.virial),
            ref_positions=paths.ref_positions.copy(),
            velocities=paths.velocities.copy(),
            ref_times=paths.ref_times.copy(),
            images=paths.images.copy(),
            frame_positions=paths.frame_positions.copy(),
            list_positions=list_positions,
            list_i=list_i,
            list_j=list_j,
            dissipated=float(self._tally.dissipated),
            last_collision=paths.last_collision.copy(),
            spins=spins,
            angles=angles,
            sensor_events=counts["sensor_events"],
        )

    def _load(self, state: FixedStepState) -> None:
        """Put the engine in ``state`` (copied)."""
        n = len(self.discs)
        arrays = {}
        for name, dtype, shape in (
            ("ref_positions", np.float64, (n, 2)),
            ("velocities", np.float64, (n, 2)),
            ("ref_times", np.float64, (n,)),
            ("images", np.int64, (n, 2)),
            ("frame_positions", np.float64, (n, 2)),
            ("last_collision", np.float64, (n,)),
            ("spins", np.float64, (n,)),
            ("angles", np.float64, (n,)),
        ):
            array = np.array(getattr(state, name), dtype=dtype)
            if array.shape != shape:
                msg = f"FixedStepState.{name} has shape {array.shape}; {shape} expected for {n} discs"
                raise CheckpointError(msg)
            arrays[name] = array
        shapes = self._shapes
        self._paths = Paths(
            self.box, **arrays, gravity=shapes.gravity, falls=shapes.falls, angle_time=float(state.time),
            drag=shapes.drag,
        )  # fmt: skip
        self._tally = Tally(state.counts, state.max_overlap, state.virial, state.dissipated)
        built = state.list_builds > 0 and len(state.list_positions) == n  # not after add_discs / remove_discs
        self._broad.load(state.list_positions, state.list_i, state.list_j, built=built)
        self._frame_time = float(state.frame_time)
        self.time = float(state.time)

    def _kept_state(self, keep: np.ndarray, added: Discs | None) -> FixedStepState:
        """The state of discs ``keep`` and then ``added`` (new at ``time``, where they are added, with their own
        spins), for ``add_discs`` and ``remove_discs``: the Verlet list dropped (rebuilt at the next frame)."""
        state = self.state()
        names = ("ref_positions", "velocities", "ref_times", "last_collision", "spins", "angles")
        arrays = {n: getattr(state, n)[keep] for n in names}
        arrays.update(images=state.images[keep], frame_positions=state.frame_positions[keep])
        if added is not None:
            k, t = len(added), self.time
            for name, rows in (
                ("ref_positions", added.positions),
                ("velocities", added.velocities),
                ("ref_times", np.full(k, t)),
                ("last_collision", np.full(k, -np.inf)),
                ("spins", added.spins),
                ("angles", np.zeros(k)),
                ("images", np.zeros((k, 2), dtype=np.int64)),
                ("frame_positions", added.positions),
            ):
                arrays[name] = np.concatenate([arrays[name], rows])
        empty = np.zeros(0, dtype=np.int64)
        return dataclasses.replace(state, **arrays, list_positions=np.zeros((0, 2)), list_i=empty, list_j=empty)
