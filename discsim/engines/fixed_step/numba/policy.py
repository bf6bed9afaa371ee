"""The compiled frame as a policy: what the engine calls for its frames when ``backend="numba"``.

:class:`CompiledFrame` keeps the scene as plain arrays, calls
:func:`~discsim.engines.fixed_step.numba.kernels.frames` on the engine's
:class:`~discsim.engines.fixed_step.arrays.Paths` for one frame or a batch of them, and writes back what
the Python frame would: the counters, the deepest overlap and the collision virial
(:class:`~discsim.engines.fixed_step.arrays.Tally`), the Verlet list (kept in the broad phase, whose
:meth:`~discsim.engines.fixed_step.broad_phase.BroadPhase.export` reads it), the event log, and the
:class:`~discsim.events.Event` list that ``step()`` returns.
"""

from __future__ import annotations

import numpy as np

from discsim.cells import grid_shape
from discsim.engines.fixed_step.arrays import Paths, Shapes, Tally
from discsim.engines.fixed_step.broad_phase import BroadPhase, VerletGrid
from discsim.engines.fixed_step.frame import Policy
from discsim.engines.fixed_step.numba import kernels
from discsim.events import COLLISION, EVENT_DTYPE, WALL, Event

__all__ = ["CompiledFrame"]

#: Disc-frames per compiled call in a run (a batch of frames is 2^16 / N of them): a call lasts a few
#: milliseconds at most, so Ctrl-C, which waits for the call to end, still stops a run at once.
BATCH_WORK = 1 << 16
_COUNTERS = ("pair_tests", "segment_tests", "detections", "wall_hits", "list_builds")
_STATE = ("xi", "yi", "vxi", "vyi", "xj", "yj", "vxj", "vyj")


class CompiledFrame(Policy):
    """The frame of ``"resolve"``, ``"revert"`` or ``"separate"``, compiled: the same frames, bit for bit.

    Args:
        name: the policy (a key of :data:`~discsim.engines.fixed_step.numba.kernels.POLICY_CODES`).
        shapes: the scene as arrays. broad: the broad phase (the Verlet list is kept in it).

    Attributes:
        batch (int): frames per compiled call in a run (one call per frame costs the interpreter more
            than a small scene's frame does).
    """

    def __init__(self, name: str, shapes: Shapes, broad: BroadPhase):
        super().__init__(shapes, broad)
        self.name = name
        self._code = kernels.POLICY_CODES[name]
        scene, box = shapes.scene, shapes.box
        n = len(scene)
        self._scene = (
            np.ascontiguousarray(shapes.radii, dtype=np.float64),
            np.ascontiguousarray(scene.discs.masses, dtype=np.float64),
            bool(box.periodic),
            float(box.width),
            float(box.height),
            np.array(shapes.seg_ends, dtype=np.float64).reshape(-1, 4),
            np.ascontiguousarray(scene.group, dtype=np.int64),
            np.ascontiguousarray(scene.blocked, dtype=np.bool_),
            bool(scene.filtering),
        )
        self._grid = isinstance(broad, VerletGrid)
        if self._grid:
            # The numbers VerletGrid and neighbour_pairs compute, computed as they do.
            reach = shapes.diameter + broad.skin
            nx, ny = grid_shape(box, reach, max(4 * n, 1 << 16))
            self._list_args = ((0.5 * broad.skin) ** 2, reach * reach, nx, ny, nx / box.width, ny / box.height)
        else:
            self._list_args = (0.0, 0.0, 1, 1, 0.0, 0.0)
        self._no_list = np.zeros((0, 2))
        self._no_pairs = np.zeros(0, dtype=np.int64)
        self._counts = np.zeros(len(_COUNTERS), dtype=np.int64)
        self.batch = max(1, BATCH_WORK // max(n, 1))

    def frame(self, paths: Paths, tally: Tally, t0: float, t: float) -> list[Event]:
        """Move every disc from the frame at ``t0`` to ``t``, then answer what overlaps there.

        Returns:
            The :class:`~discsim.events.Event` of each response: wall hits, segment hits, then pairs.
        """
        return self.frames(paths, tally, t0, np.array([t]), events=True)

    def frames(self, paths: Paths, tally: Tally, t0: float, times: np.ndarray, events: bool = False):
        """The frames at ``times`` ``(F,)`` one after the other (the last frame was at ``t0``).

        Returns:
            With ``events``, the :class:`~discsim.events.Event` of each response, frame by frame;
            else None.
        """
        broad = self.broad
        if self._grid and broad.list_positions is not None:
            listed = (False, broad.list_positions, broad.list_i, broad.list_j, *self._list_args)
        else:
            listed = (not self._grid, self._no_list, self._no_pairs, self._no_pairs, *self._list_args)
        counts = self._counts
        counts[:] = 0
        state = (paths.ref_positions, paths.velocities, paths.ref_times, paths.images, paths.frame_positions)
        ev_n, ev_f, paths.frame_positions, list_pos, list_i, list_j, overlap, virial = kernels.frames(
            self._code, times, self._scene, state, listed, counts, tally.max_overlap, tally.virial
        )
        tally.max_overlap = overlap
        tally.virial = virial
        steps = counts.tolist()
        for name, step in zip(_COUNTERS, steps):
            tally.counts[name] += step
        if steps[kernels.C_LIST_BUILDS]:
            broad.list_positions, broad.list_i, broad.list_j = list_pos, list_i, list_j
        if not len(ev_n):
            return [] if events else None
        frame, i, j = ev_n[:, 0], ev_n[:, 1], ev_n[:, 2]
        at = times[frame]
        if tally.log is not None:
            records = np.empty(len(ev_n), dtype=EVENT_DTYPE)
            records["time"] = at
            records["kind"] = np.where(j < 0, WALL, COLLISION)
            records["i"] = i
            records["j"] = j
            for column, name in enumerate(_STATE):
                records[name] = ev_f[:, column]
            tally.log.extend(records)
        if not events:
            return None
        return [
            Event(t, "wall", a, b) if b < 0 else Event(t, "collision", a, b)
            for t, a, b in zip(at.tolist(), i.tolist(), j.tolist())
        ]
