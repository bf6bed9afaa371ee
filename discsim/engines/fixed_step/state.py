"""The fixed-step engine's public run state: plain numpy arrays and scalars.

A checkpoint stores it (:mod:`discsim.io.checkpoints`); an observer or an analysis may read it. Nothing
in it is Python-specific.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from discsim.engines.base import EngineState

__all__ = ["FixedStepState"]


@dataclass(eq=False)
class FixedStepState(EngineState):
    """Everything a fixed-step run needs to continue bit for bit (version 5).

    Per-disc arrays are indexed as ``discs``. Frame ``k`` falls at ``start_time + k / frame_rate`` (or
    ``start_time + k * dt``, as the engine was built), so the frame count fixes the frame times.

    Scalars:
        time: the current simulated time (at or after the last frame).
        frame_time: the time of the last frame done (the start time before the first).
        frames: frames done since the start.
        pair_tests, segment_tests, bisection_tests, detections, wall_hits, list_builds:
            the counters (see ``FixedStep.counts``).
        sensor_events: the sensor records (``ENTER``, ``LEAVE``) since the start (``FixedStep.counts["sensor_events"]``,
            as ``EventDriven``'s). The sensors' inside state at the last frame is that of ``frame_positions``
            (``Sensor.contains``): it needs no field of its own.
        max_overlap: the deepest disc-disc overlap seen, as a fraction of the contact distance.
        virial: the sum over the disc-disc impulses applied since the start of ``dp_i . (r_i - r_j)``
            (energy; ``FixedStep.pressure()``); NaN when unknown (a version 1 state: see below).
        dissipated: the kinetic energy taken by responses with restitution below 1 (or rough), and by the drag
            over the flights the frames and edits ended (``FixedStep.dissipated`` adds the flights under way).

    Arrays:
        ref_positions ``(N, 2)``, velocities ``(N, 2)``, ref_times ``(N,)``:
            disc ``i`` is at ``ref_positions[i] + velocities[i] (t - ref_times[i])``
            (lengths, length per time, times; not wrapped); under gravity or drag a disc of finite mass follows
            the parabola or the exponential flight from there (``discsim.physics.dynamics.advance``),
            ``velocities[i]`` its velocity at ``ref_times[i]``.
        images ``(N, 2)`` int64: box lengths to add to ``ref_positions`` to unwrap them
            (zero in a walled box).
        frame_positions ``(N, 2)``: the positions at ``frame_time``, wrapped into a periodic box.
        list_positions ``(N, 2)``: where the discs were when the Verlet list of the ``"grid"``
            broad phase was last built, or ``(0, 2)`` if it never was (``list_builds == 0``).
        list_i, list_j ``(P,)`` int64: the pairs of discs in that list.
        last_collision ``(N,)``: each disc's last response time (``-inf``: none), for the TC model.
        spins ``(N,)``: the angular velocities (radians per time, counter-clockwise positive); changed only by
            the responses of rough discs (``roughness`` above -1).
        angles ``(N,)``: each disc's angle at ``time`` (radians, counter-clockwise, 0 at the start; not wrapped).

    Versions: 1 had no ``virial``; it is read with ``virial = NaN`` (:meth:`from_arrays`), which
    ``FixedStep`` rebuilds from the event log when the log covers the whole run. 1 and 2 had no laws
    (``dissipated``, ``last_collision``): they are read with their defaults, 0 and ``-inf``. 1 to 3 had no
    spins (``spins``, ``angles``): they are read with zeros (the discs did not turn). 1 to 4 had no sensors
    (``sensor_events``): they are read with 0.
    """

    VERSION = 5

    time: float
    frame_time: float
    frames: int
    pair_tests: int
    segment_tests: int
    bisection_tests: int
    detections: int
    wall_hits: int
    list_builds: int
    max_overlap: float
    virial: float
    ref_positions: np.ndarray
    velocities: np.ndarray
    ref_times: np.ndarray
    images: np.ndarray
    frame_positions: np.ndarray
    list_positions: np.ndarray
    list_i: np.ndarray
    list_j: np.ndarray
    dissipated: float = 0.0
    last_collision: np.ndarray = None  # type: ignore[assignment]  # None: no response yet (filled in below)
    spins: np.ndarray = None  # type: ignore[assignment]  # None: zeros (filled in below)
    angles: np.ndarray = None  # type: ignore[assignment]  # None: zeros
    sensor_events: int = 0

    def __post_init__(self) -> None:
        n = len(self.ref_times)
        if self.last_collision is None:
            self.last_collision = np.full(n, -np.inf)
        if self.spins is None:
            self.spins = np.zeros(n)
        if self.angles is None:
            self.angles = np.zeros(n)

    @classmethod
    def from_arrays(cls, scalars: dict, arrays: dict[str, np.ndarray], version: int) -> FixedStepState:
        """As :meth:`EngineState.from_arrays`; a version 1 state (before ``virial``) gets ``virial = NaN``, and a
        version 1 or 2 state (before the laws) ``dissipated = 0`` and no last responses, and a version 1 to 3 state
        (before the spins) spins and angles zero, and a version 1 to 4 state (before the sensors)
        ``sensor_events = 0``."""
        if version == 1 and "virial" not in scalars:
            scalars = {**scalars, "virial": math.nan}
            version = 2
        if version == 2:
            n = len(arrays.get("ref_times", ()))
            scalars = {**scalars, "dissipated": 0.0}
            arrays = {**arrays, "last_collision": np.full(n, -np.inf)}
            version = 3
        if version == 3:
            n = len(arrays.get("ref_times", ()))
            arrays = {**arrays, "spins": np.zeros(n), "angles": np.zeros(n)}
            version = 4
        if version == 4:
            scalars = {**scalars, "sensor_events": 0}
            version = cls.VERSION
        return super().from_arrays(scalars, arrays, version)

    @property
    def counts(self) -> dict[str, int]:
        """The counters as ``FixedStep.counts`` gives them."""
        return {
            "frames": self.frames,
            "pair_tests": self.pair_tests,
            "segment_tests": self.segment_tests,
            "bisection_tests": self.bisection_tests,
            "detections": self.detections,
            "wall_hits": self.wall_hits,
            "list_builds": self.list_builds,
            "sensor_events": self.sensor_events,
        }
