"""The compiled frame as a policy: what the engine calls for its frames when ``backend="numba"``.

:func:`compiled_policy` gives the engine's policy: :class:`CompiledFrame` (``"resolve"``, ``"revert"``,
``"separate"``) or :class:`CompiledSubFrame` (``"bisect"``, ``"swept"``). :class:`CompiledFrame` keeps the
scene as plain arrays, calls
:func:`~discsim.engines.fixed_step.numba.kernels.frames` on the engine's
:class:`~discsim.engines.fixed_step.arrays.Paths` for one frame or a batch of them, and writes back what
the Python frame would: the counters, the deepest overlap and the collision virial
(:class:`~discsim.engines.fixed_step.arrays.Tally`), the Verlet list (kept in the broad phase, whose
:meth:`~discsim.engines.fixed_step.broad_phase.BroadPhase.export` reads it), the event log, and the
:class:`~discsim.events.Event` list that ``step()`` returns.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.cells import grid_shape
from discsim.engines.fixed_step.arrays import Paths, Shapes, Tally
from discsim.engines.fixed_step.broad_phase import AllPairs, BroadPhase, VerletGrid
from discsim.engines.fixed_step.frame import Policy
from discsim.engines.fixed_step.numba import kernels, sub_frame
from discsim.engines.fixed_step.sub_frame import SubFrame, Swept
from discsim.errors import JammedError
from discsim.events import COLLISION, EVENT_DTYPE, WALL, Event

__all__ = ["CompiledFrame", "CompiledSubFrame", "compiled_policy"]

#: Disc-frames per compiled call in a run (a batch of frames is 2^16 / N of them): a call lasts a few
#: milliseconds at most, so Ctrl-C, which waits for the call to end, still stops a run at once.
BATCH_WORK = 1 << 16
_COUNTERS = ("pair_tests", "segment_tests", "detections", "wall_hits", "list_builds")
_SUB_COUNTERS = ("pair_tests", "segment_tests", "bisection_tests", "detections", "wall_hits")
_STATE = ("xi", "yi", "vxi", "vyi", "xj", "yj", "vxj", "vyj")


def compiled_policy(name: str, shapes: Shapes, broad: BroadPhase, bisect_tol: float) -> Policy:
    """The compiled policy ``name`` (any of the engine's five) over ``shapes`` and ``broad``."""
    if name in sub_frame.SUB_FRAME_CODES:
        return CompiledSubFrame(name, shapes, broad, bisect_tol)
    return CompiledFrame(name, shapes, broad)


def _scene_arrays(shapes: Shapes) -> tuple:
    """The ``scene`` argument of the compiled frames: radii, masses, the box, segments, collision filter."""
    scene, box = shapes.scene, shapes.box
    return (
        np.ascontiguousarray(shapes.radii, dtype=np.float64),
        np.ascontiguousarray(scene.discs.masses, dtype=np.float64),
        bool(box.periodic),
        float(box.width),
        float(box.height),
        np.concatenate([np.array(shapes.seg_ends, dtype=np.float64).reshape(-1, 4), shapes.seg_v], axis=1),
        np.ascontiguousarray(scene.group, dtype=np.int64),
        np.ascontiguousarray(scene.blocked, dtype=np.bool_),
        bool(scene.filtering),
    )


def _law_arrays(shapes: Shapes) -> tuple:
    """The first nine slots of the ``laws`` argument of the compiled frames: gravity, the drag, the discs they move,
    and the restitution (the last two, ``Paths.last_collision`` and the energy lost, come with each call)."""
    gx, gy = shapes.gravity
    return (
        float(gx),
        float(gy),
        float(shapes.drag),
        np.ascontiguousarray(shapes.falls, dtype=np.bool_),
        float(shapes.e),
        bool(shapes.per_group),
        np.array(shapes.e_table, dtype=np.float64).reshape(len(shapes.e_table), -1),
        np.array(shapes.e_group, dtype=np.int64).reshape(-1),
        float(shapes.tc),
    )


def _turning_arrays(shapes: Shapes) -> tuple[float, np.ndarray]:
    """The fixed slots of the ``turning`` argument of the compiled frames: the roughness and the moments of inertia
    (the spins and angles, ``Paths``', come with each call)."""
    return float(shapes.beta), np.ascontiguousarray(shapes.inertia, dtype=np.float64)


def _records(at: np.ndarray, ev_n: np.ndarray, states: np.ndarray) -> np.ndarray:
    """Log records of events at times ``at``: discs ``ev_n[:, 1:3]`` (j < 0: a wall or segment hit), the
    state after in ``states`` ``(E, 8)``."""
    i, j = ev_n[:, 1], ev_n[:, 2]
    records = np.empty(len(ev_n), dtype=EVENT_DTYPE)
    records["time"] = at
    records["kind"] = np.where(j < 0, WALL, COLLISION)
    records["i"] = i
    records["j"] = j
    for column, name in enumerate(_STATE):
        records[name] = states[:, column]
    return records


def _events(at: np.ndarray, ev_n: np.ndarray) -> list[Event]:
    """The :class:`~discsim.events.Event` list ``step()`` returns."""
    return [
        Event(t, "wall", a, b) if b < 0 else Event(t, "collision", a, b)
        for t, a, b in zip(at.tolist(), ev_n[:, 1].tolist(), ev_n[:, 2].tolist())
    ]


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
        self._scene = _scene_arrays(shapes)
        self._laws = _law_arrays(shapes)
        self._beta, self._inertia = _turning_arrays(shapes)
        self._lost = np.zeros(1)
        self._verlet = broad if isinstance(broad, VerletGrid) else None  # the "grid" broad phase keeps the list
        if isinstance(broad, VerletGrid):
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
        verlet = self._verlet
        if verlet is not None and verlet.list_positions is not None:
            listed = (False, verlet.list_positions, verlet.list_i, verlet.list_j, *self._list_args)
        else:
            listed = (verlet is None, self._no_list, self._no_pairs, self._no_pairs, *self._list_args)
        counts = self._counts
        counts[:] = 0
        state = (paths.ref_positions, paths.velocities, paths.ref_times, paths.images, paths.frame_positions)
        lost = self._lost
        lost[0] = tally.dissipated
        laws = (*self._laws, paths.last_collision, lost)
        turning = (self._beta, self._inertia, paths.spins, paths.angles, paths.angle_times)
        ev_n, ev_f, paths.frame_positions, list_pos, list_i, list_j, overlap, virial = kernels.frames(
            self._code, times, self._scene, state, listed, counts, tally.max_overlap, tally.virial, laws, turning
        )
        tally.max_overlap = overlap
        tally.virial = virial
        tally.dissipated = float(lost[0])
        steps = counts.tolist()
        for name, step in zip(_COUNTERS, steps):
            tally.counts[name] += step
        if verlet is not None and steps[kernels.C_LIST_BUILDS]:
            verlet.list_positions, verlet.list_i, verlet.list_j = list_pos, list_i, list_j
        if not len(ev_n):
            return [] if events else None
        at = times[ev_n[:, 0]]
        if tally.log is not None:
            tally.log.extend(_records(at, ev_n, ev_f))
        return _events(at, ev_n) if events else None


class CompiledSubFrame(Policy):
    """The frame of ``"bisect"`` or ``"swept"``, compiled: the same frames, bit for bit.

    Args:
        name: ``"bisect"`` or ``"swept"``. shapes: the scene as arrays. broad: the broad phase (its kind
            only: the sub-frame policies keep no Verlet list). tol: ``bisect_tol``.
    """

    def __init__(self, name: str, shapes: Shapes, broad: BroadPhase, tol: float):
        super().__init__(shapes, broad)
        self.name = name
        self._code = sub_frame.SUB_FRAME_CODES[name]
        n = len(shapes.scene)
        self._scene = _scene_arrays(shapes)
        moving = np.isfinite(shapes.scene.discs.masses)
        # The float 2.0 comes from here, so that the compiled code cannot fold pow(x, 2.0) into x * x.
        self._sub = (moving, float(shapes.diameter), float(tol), 2.0, isinstance(broad, AllPairs))
        self._counts = np.zeros(5, dtype=np.int64)
        self._acc = np.zeros(3)
        self._laws = _law_arrays(shapes)[4:]  # the restitution (the sub-frame policies refuse gravity and drag)
        self._beta, self._inertia = _turning_arrays(shapes)
        self._jam = np.zeros(3, dtype=np.int64)
        self._swept = Swept(shapes, broad) if name == "swept" else None
        self._batch = max(1, BATCH_WORK // max(n, 1))

    def check(self, paths: Paths, dt: float) -> None:
        """``Swept.check`` for ``"swept"`` (the same refusal, word for word); nothing for ``"bisect"``."""
        if self._swept is not None:
            self._swept.check(paths, dt)

    def batch(self, paths: Paths, dt: float) -> int:
        """Frames one compiled call may do from the state ``paths`` on.

        ``"swept"`` in a periodic box refuses a frame whose sweeps could reach a second image
        (:meth:`check`, before each frame). A batch is safe when no disc can ever get fast enough: the
        kinetic energy is conserved there (no walls, no segments), so a disc of mass ``m`` stays under
        ``sqrt(2 E / m)``, unless an obstacle moves (it would pump energy in). Otherwise the frames go one
        by one, each checked first, and the refusal comes at the frame that Python's frame refuses.
        """
        if self._swept is None or not self.shapes.box.periodic:
            return self._batch
        vel = paths.velocities
        moving = self._sub[0]
        if np.any(vel[~moving] != 0.0):
            return 1
        masses = self._scene[1][moving]
        energy = 0.5 * float(np.sum(masses * np.einsum("ij,ij->i", vel[moving], vel[moving])))
        bound = math.sqrt(2.0 * energy / float(masses.min())) * (1.0 + 1e-6) if len(masses) else 0.0
        box = self.shapes.box
        if 2.0 * bound * dt + 2.0 * self.shapes.max_radius >= 0.5 * min(box.width, box.height):
            return 1
        return self._batch

    def frame(self, paths: Paths, tally: Tally, t0: float, t: float) -> list[Event]:
        """Advance every disc from the frame at ``t0`` to ``t``, answering each contact at its time.

        Returns:
            The :class:`~discsim.events.Event` of each response, in the order of their contact times.
        """
        return self.frames(paths, tally, t0, np.array([t]), events=True)

    def frames(self, paths: Paths, tally: Tally, t0: float, times: np.ndarray, events: bool = False):
        """The frames at ``times`` ``(F,)`` one after the other (the last frame was at ``t0``).

        Returns:
            With ``events``, the :class:`~discsim.events.Event` of each response, frame by frame;
            else None.

        Raises:
            JammedError: as ``SubFrame.run``, with everything before the jammed contact kept.
        """
        counts, acc = self._counts, self._acc
        counts[:] = 0
        acc[0], acc[1], acc[2] = tally.max_overlap, tally.virial, tally.dissipated
        state = (paths.ref_positions, paths.velocities, paths.ref_times, paths.images, paths.frame_positions)
        laws = (*self._laws, paths.last_collision)
        turning = (self._beta, self._inertia, paths.spins, paths.angles, paths.angle_times)
        status, _, ev_n, ev_f, paths.frame_positions, jam_time = sub_frame.sub_frames(
            self._code, times, float(t0), self._scene, self._sub, state, counts, acc, self._jam, laws, turning
        )
        tally.max_overlap, tally.virial, tally.dissipated = float(acc[0]), float(acc[1]), float(acc[2])
        for name, step in zip(_SUB_COUNTERS, counts.tolist()):
            tally.counts[name] += step
        at = ev_f[:, 0]
        if len(ev_n) and tally.log is not None:
            tally.log.extend(_records(at, ev_n, ev_f[:, 1:]))
        if status == sub_frame.JAMMED:
            a, b, kind = self._jam.tolist()
            cap = SubFrame.MAX_RESPONSES + SubFrame.MAX_RESPONSES_PER_DISC * len(paths.velocities)
            partner = f"disc {b}" if kind == sub_frame.COLLISION else "a wall or segment"
            msg = (
                f"disc {a} and {partner} are jammed at time {float(jam_time)!r}: this frame answered more "
                f"than {cap} contacts; give the discs room (a gap), or use a shorter frame"
            )
            raise JammedError(msg)
        return _events(at, ev_n) if events else None
