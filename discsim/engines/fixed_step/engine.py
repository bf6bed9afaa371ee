"""The fixed-step engine (PIT): move every disc one frame, then test for interference.

This is the periodic interference test of the study: time advances in frames of length ``dt``; after
each move the engine looks for pairs of discs that overlap and discs that cross a wall or a segment, and
answers with one of five policies, chosen once when the engine is built:

- at the frame, after the fact (:mod:`~discsim.engines.fixed_step.frame`): ``"resolve"``, ``"revert"``,
  ``"separate"``;
- inside the frame, at the contact time (:mod:`~discsim.engines.fixed_step.sub_frame`): ``"bisect"``,
  ``"swept"``.

Between responses discs fly straight, so the event log (one record per response, with the state just
after it) rebuilds the exact path the engine took, and ``trajectory()`` works as for the event-driven
engine. The laws of :class:`~discsim.engines.event_driven.EventDriven` apply too (``gravity=``,
``restitution=``, ``tc=``, ``roughness=``, ``drag=``): under gravity every disc of finite mass follows the exact
parabola over a frame, under drag the exact exponential flight (:func:`~discsim.physics.dynamics.advance`;
``trajectory()`` adds the fall since each disc's last record),
and the responses apply the restitution, and the roughness that turns the discs (``spins``, ``angles``), through the
same collision law (:mod:`discsim.physics.laws`).
The broad phase (:mod:`~discsim.engines.fixed_step.broad_phase`) is a Verlet list on a cell grid or every
pair; both give identical runs. Collision filtering (``pass_through``) drops the pairs of groups that pass
through each other before the narrow phase, under every policy.

:class:`FixedStep` is the front: it validates the scene and the options, owns the public API, the event
log and the frame clock, and hands each frame to its policy, which works on the state arrays
(:class:`~discsim.engines.fixed_step.arrays.Paths`). The run state is exported and loaded as a
:class:`~discsim.engines.fixed_step.state.FixedStepState`.

Two backends run the frames: ``"python"`` (numpy; the modules above) and ``"numba"`` (every policy's frame
compiled, :mod:`discsim.engines.fixed_step.numba`), which give the same frames bit for bit and the same
state, so a run saved under one continues under the other.
"""

from __future__ import annotations

import math

import numpy as np

from discsim._interrupt import deferred_interrupt
from discsim._numba import resolve_backend
from discsim._validate import check_count, positive_finite
from discsim.cells import CellGrid
from discsim.engines.base import Engine, register_engine
from discsim.engines.fixed_step.arrays import Shapes
from discsim.engines.fixed_step.broad_phase import BROAD_PHASE_CLASSES
from discsim.engines.fixed_step.frame import FRAME_POLICY_CLASSES
from discsim.engines.fixed_step.readout import FrameReadout
from discsim.engines.fixed_step.run_state import FixedStepRun
from discsim.engines.fixed_step.sensing import FrameSensing
from discsim.engines.fixed_step.state import FixedStepState
from discsim.engines.fixed_step.sub_frame import SUB_FRAME_POLICY_CLASSES, Bisect
from discsim.engines.record import collision_virials
from discsim.errors import CheckpointError, Interrupted, InvalidArgumentError
from discsim.events import Event
from discsim.laws import Laws
from discsim.model import Box, Discs
from discsim.scene import Scene, check_unsteered
from discsim.sensors import Sensor, check_sensors

__all__ = ["BACKENDS", "BROAD_PHASES", "COMPILED_POLICIES", "POLICIES", "SUB_FRAME_POLICIES", "FixedStep"]

_POLICY_CLASSES = {**FRAME_POLICY_CLASSES, **SUB_FRAME_POLICY_CLASSES}
#: Response policies of :class:`FixedStep`.
POLICIES = tuple(_POLICY_CLASSES)
#: The policies that respond at the contact time inside the frame.
SUB_FRAME_POLICIES = tuple(SUB_FRAME_POLICY_CLASSES)
#: Broad phases of :class:`FixedStep`.
BROAD_PHASES = tuple(BROAD_PHASE_CLASSES)
#: Backends of :class:`FixedStep`'s frame.
BACKENDS = ("python", "numba")
#: The policies whose frame the ``"numba"`` backend compiles: all of them.
COMPILED_POLICIES = ("resolve", "revert", "separate", "bisect", "swept")

#: Default frames per unit of time.
DEFAULT_FRAME_RATE = 30.0
#: Default bisection tolerance of the ``"bisect"`` policy, as a fraction of ``dt``.
DEFAULT_BISECT_FRACTION = 1e-6


#: The policies that answer a moving segment (at the frame, in the segment's frame).
MOVING_SEGMENT_POLICIES = ("resolve", "revert", "separate")


def _frame_step(frame_rate, dt) -> tuple[float, float, bool]:
    """``(dt, frame rate, whether the rate was given)`` from ``frame_rate`` or ``dt`` (the default rate if neither),
    refusing both when they disagree."""
    if dt is None:
        rate = DEFAULT_FRAME_RATE if frame_rate is None else positive_finite("frame_rate", frame_rate)
        return 1.0 / rate, rate, True
    step = positive_finite("dt", dt)
    if frame_rate is not None:
        rate = positive_finite("frame_rate", frame_rate)
        if not math.isclose(rate * step, 1.0, rel_tol=1e-12):
            msg = f"give frame_rate or dt, not both: frame_rate={frame_rate!r} but dt={dt!r}"
            raise InvalidArgumentError(msg)
    return step, 1.0 / step, False


def _moving_segments(scene: Scene, laws: Laws, policy: str) -> Scene:
    """``scene``, unless a segment moves where this engine cannot move it: under gravity, drag or roughness (as
    ``EventDriven`` refuses them), or with a policy other than :data:`MOVING_SEGMENT_POLICIES` (``"bisect"`` and
    ``"swept"`` test fixed segments inside a frame).

    Raises:
        InvalidArgumentError: naming the first moving segment and the law or the policy.
    """
    if not scene.moving:
        return scene
    k = next(k for k, segment in enumerate(scene.segments) if segment.moving)
    if laws.falls or laws.drag != 0.0 or laws.rough:
        msg = (
            f"segments[{k}] {scene.segments[k]!r} moves: moving segments run under the default laws or "
            f"restitution only, not yet with gravity={laws.gravity}, drag={laws.drag}, roughness={laws.roughness}"
        )
        raise InvalidArgumentError(msg)
    if policy not in MOVING_SEGMENT_POLICIES:
        msg = (
            f"segments[{k}] {scene.segments[k]!r} moves: policy {policy!r} cannot answer a moving segment; "
            f"use one of {list(MOVING_SEGMENT_POLICIES)} (or EventDriven)"
        )
        raise InvalidArgumentError(msg)
    return scene


@register_engine
class FixedStep(FrameReadout, FixedStepRun, FrameSensing, Engine):
    """Fixed-step simulation with a periodic interference test (PIT).

    Args:
        discs: the discs at ``time = 0``.
        box: the box (reflecting walls or periodic).
        frame_rate: frames per unit of time (default 30). Give this or ``dt``.
        dt: the frame interval (time units), instead of ``frame_rate``.
        policy: the response to a detected overlap: ``"resolve"`` (default),
            ``"revert"``, ``"separate"``, ``"bisect"`` or ``"swept"`` (see
            :mod:`~discsim.engines.fixed_step.frame` and
            :mod:`~discsim.engines.fixed_step.sub_frame`).
        broad_phase: ``"grid"`` (a Verlet list of the pairs within ``2 r_max + skin``,
            skin half a radius, rebuilt with the cell grid when a disc has moved
            half the skin: O(N) per frame) or ``"all-pairs"`` (every pair tested,
            O(N^2) per frame). Both give identical results.
        record: keep the event log (needed by ``events`` and ``trajectory``).
        segments: :class:`~discsim.model.Segment` walls (walled boxes
            only), tested against every disc at each frame (few segments). A moving segment is tested where it is
            at the frame's time (``p0 + velocity * t``) and bounces a disc in its own frame (the velocity relative to
            it reflected, the restitution applied, its velocity added back; what the bounce takes, in its frame, in
            :attr:`dissipated`; ``"revert"`` puts the disc back where it was at the previous frame and tests it
            against the segment where it is at the frame): the policies that answer at the frame only, under the
            default laws or restitution (as ``EventDriven``).
        pass_through: pairs of group labels (``discs.groups``) whose discs do
            not collide with each other, as for
            :class:`~discsim.engines.event_driven.EventDriven`. Free when empty.
        bisect_tol: the ``"bisect"`` policy's tolerance on contact times (time
            units; default ``1e-6 * dt``).
        backend: what runs the frames: ``"auto"`` (the default: ``"numba"`` when numba
            imports, else ``"python"``),
            ``"numba"`` (the frame compiled, from the ``fast`` extra: ``pip install
            "discsim[fast]"``) or ``"python"`` (numpy). Both give the same frames bit for bit.
        gravity, restitution, tc: the laws of :class:`~discsim.engines.event_driven.EventDriven`, alike:
            ``(gx, gy)`` (length / time^2; None: none) moves each disc of finite mass along the exact parabola
            over a frame (``x += v dt + g dt^2 / 2``, ``v += g dt``; the frame policies only: ``"bisect"`` and
            ``"swept"`` follow straight paths inside a frame and refuse it); ``e`` in [0, 1] (or per pair of
            groups) at every response, the energy taken in :attr:`dissipated`; the TC time (0: none).
        roughness: the tangential restitution ``beta`` in [-1, 1] of every response, as for ``EventDriven``:
            -1 (the default) smooth, today's frames bit for bit; above -1 each response adds the tangential
            impulse at the contact point (:func:`~discsim.physics.laws.rough_impulse`, arms the radii; walls and
            segments as rough as the discs) that turns the discs (``discs.spins``, ``discs.inertia``;
            :attr:`spins`, :attr:`angles`), every policy alike; the energy taken in :attr:`dissipated`.
        rest_speed: checked as ``EventDriven`` checks it, and ignored: PIT has no rest (a disc on a floor
            keeps bouncing from frame to frame).
        drag: the linear drag ``gamma`` >= 0 (1 / time; 0, the default: none, today's frames bit for bit), as for
            ``EventDriven``: over a frame and between frames each disc of finite mass follows the exact exponential
            flight (velocity ``v e^(-gamma t) + g tau(t)``, ``tau = (1 - e^(-gamma t)) / gamma``; the frame
            policies only: ``"bisect"`` and ``"swept"`` refuse it); what it takes counts in :attr:`dissipated`.
        sensors: :class:`~discsim.sensors.Sensor` regions and trip wires (default none), seen at the frames: one
            ``"enter"`` or ``"leave"`` record (``j`` the sensor's index) per change since the last frame, at the
            frame's time (:mod:`~discsim.engines.fixed_step.sensing`); one passed clean through between two frames
            is not seen.

    Raises:
        InvalidArgumentError: on a frame rate, ``dt`` or ``bisect_tol`` that is
            not a positive finite number, a law refused as ``EventDriven`` refuses it (a negative or non-finite
            ``drag`` too), gravity or drag with a sub-frame policy, both of ``frame_rate`` and ``dt`` given
            and disagreeing, an unknown policy, broad phase or backend, segments in
            a periodic box, a moving segment under gravity, drag or roughness or with ``"bisect"`` or
            ``"swept"`` (naming the segment), ``backend="numba"`` without numba (naming the extra to
            install), ``sensors`` not a list of :class:`~discsim.sensors.Sensor` (naming the item).
        TypeError: if ``discs``, ``box`` or a segment is of the wrong type.
        InvalidDiscsError: on a malformed ``pass_through``.
        OutsideBoxError, OverlapError: if the discs do not fit in the box (or
            are cut by a segment).
        BoxTooSmallError: if a periodic box is under three disc diameters a
            side (as for :class:`~discsim.engines.event_driven.EventDriven`).

    Attributes:
        time (float): the current time; frame ``k`` falls at ``start_time + k * dt``.
        backend (str): the backend that runs the frames, ``"python"`` or ``"numba"``.
        dt (float): the frame interval. frame_rate (float): ``1 / dt``.
        frames (int): frames done since the start.
        counts (dict[str, int]): ``frames``; ``pair_tests`` (narrow-phase
            disc-disc checks: distances at the frame, swept-volume tests, and
            the tests again after a response inside a frame); ``segment_tests``
            (disc-segment checks); ``bisection_tests`` (interference tests
            spent by ``"bisect"``, one at the start of each interval and one
            per halving); ``detections`` (pairs that got an impulse);
            ``wall_hits`` (discs reflected by a wall or a segment);
            ``list_builds`` (rebuilds of the grid's Verlet list); ``sensed`` (sensor records).
        sensors (tuple): the :class:`~discsim.sensors.Sensor` objects (empty: none).
        max_overlap (float): deepest disc-disc overlap seen, as a fraction of
            the pair's contact distance (0 if discs never overlapped): at the
            frames for the first three policies; on the path kept (at contacts
            and frames) for ``"bisect"`` and ``"swept"``, which undo the
            overlaps they find.

    Example:
        >>> import discsim as ds
        >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
        >>> sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), frame_rate=4.0).run(until=2.5)
        >>> sim.counts["detections"], sim.velocities.tolist(), sim.max_overlap
        (1, [[-1.0, 0.0], [1.0, 0.0]], 0.25)
        >>> exact = ds.FixedStep(discs, ds.Box(10.0, 10.0), frame_rate=4.0, policy="bisect").run(until=2.5)
        >>> round(float(exact.events["time"][0]), 6), exact.counts["bisection_tests"], exact.max_overlap
        (2.0, 21, 0.0)
        >>> case = ds.scenarios.missed_collision()  # a small fast disc crosses another between frames
        >>> [ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate, policy=p).run(until=case.until)
        ...  .counts["detections"] for p in ("resolve", "bisect", "swept")]
        [0, 0, 1]
    """

    unit = "frames"
    rate_count = "detections"
    progress_chunk = 1000
    STATE = FixedStepState

    def __init__(
        self,
        discs: Discs,
        box: Box,
        *,
        frame_rate: float | None = None,
        dt: float | None = None,
        policy: str = "resolve",
        broad_phase: str = "grid",
        record: bool = True,
        segments=(),
        pass_through=(),
        bisect_tol: float | None = None,
        backend: str = "auto",
        gravity=None,
        restitution=1.0,
        tc: float = 0.0,
        rest_speed: float | None = None,
        roughness: float = -1.0,
        drag: float = 0.0,
        sensors=None,
    ):
        step, rate, by_rate = _frame_step(frame_rate, dt)
        if policy not in POLICIES:
            msg = f"policy must be one of {list(POLICIES)}, got {policy!r}"
            raise InvalidArgumentError(msg)
        if broad_phase not in BROAD_PHASES:
            msg = f"broad_phase must be one of {list(BROAD_PHASES)}, got {broad_phase!r}"
            raise InvalidArgumentError(msg)
        tol = DEFAULT_BISECT_FRACTION * step if bisect_tol is None else positive_finite("bisect_tol", bisect_tol)
        laws = _check_laws(Laws.build(gravity, restitution, tc, rest_speed, roughness, drag), policy)
        backend, sensors = _choose_backend(backend, policy), check_sensors(sensors)
        segments = check_unsteered(segments)  # (a checkpoint's, loaded, keeps where they were)
        scene = _moving_segments(Scene(discs, box, segments, pass_through, sensors=sensors), laws, policy)
        laws = laws.checked(scene)
        self._configure(scene, record, rate, step, by_rate, policy, broad_phase, tol, backend, laws, sensors)
        self._load(self._initial_state())

    def _configure(
        self, scene, record, frame_rate, dt, by_rate, policy, broad_phase, bisect_tol, backend, laws, sensors=()
    ) -> None:
        """Build the parts the options choose (checked already; ``backend`` resolved); the run state comes
        from :meth:`_load`.
        """
        super().__init__(scene, record)
        self.laws = laws
        self.frame_rate = frame_rate
        self.dt = dt
        self._by_rate = by_rate  # frame k at k / frame_rate, else at k * dt
        self.policy = policy
        self.broad_phase = broad_phase
        self.bisect_tol = bisect_tol
        self.backend = backend
        self._watch(sensors, scene.box)
        self._shapes, self._broad, self._policy = self._parts(scene)

    def _parts(self, scene: Scene) -> tuple:
        """``(shapes, broad phase, policy)`` for the discs of ``scene`` (options set already)."""
        shapes = Shapes(scene, self.laws)
        # The same box check as EventDriven's cell grid (a periodic box needs 3 cells a side);
        # max_cells=9 keeps the throw-away grid tiny.
        CellGrid(scene.box, shapes.diameter, max_cells=9)
        broad = BROAD_PHASE_CLASSES[self.broad_phase](shapes)
        if self.backend == "numba":
            from discsim.engines.fixed_step.numba.policy import compiled_policy  # numba loads only when asked for

            return shapes, broad, compiled_policy(self.policy, shapes, broad, self.bisect_tol)
        if self.policy == "bisect":
            return shapes, broad, Bisect(shapes, broad, self.bisect_tol)
        return shapes, broad, _POLICY_CLASSES[self.policy](shapes, broad)  # type: ignore[call-arg]  # not Bisect (above)

    def _restructure(self, keep: np.ndarray, added: Discs | None, scene: Scene) -> None:
        """Go on with discs ``keep`` and then ``added`` (new at ``time``, as if set there: their frame
        positions are where they are added), on the frame grid as before; the Verlet list is rebuilt at the
        next frame."""
        parts = self._parts(scene)  # may refuse the new discs: nothing changed
        state = self._kept_state(keep, added)
        self._shapes, self._broad, self._policy = parts
        self.scene, self.discs = scene, scene.discs
        self._load(state)
        self._broad.load(state.list_positions, state.list_i, state.list_j, built=False)

    # --- the checkpoint's protocol (state() and _load are FixedStepRun's) -----------------
    def _settings(self) -> dict:
        return {
            "record": self.record,
            "frame_rate": self.frame_rate,
            "dt": self.dt,
            "by_rate": self._by_rate,
            "policy": self.policy,
            "broad_phase": self.broad_phase,
            "bisect_tol": self.bisect_tol,
            "backend": self.backend,
            "edits": self._edits,
            **({} if self.laws.default and self.laws.tc == 0.0 else {"laws": self.laws.settings()}),
            **self._sensor_settings(),
        }

    @classmethod
    def _restore(cls, scene, settings, state, events, start_time) -> FixedStep:
        sim = cls.__new__(cls)
        if settings["policy"] not in POLICIES or settings["broad_phase"] not in BROAD_PHASES:
            msg = f"unknown policy {settings['policy']!r} or broad phase {settings['broad_phase']!r}"
            raise CheckpointError(msg)
        backend = settings.get("backend", "auto")
        if settings["policy"] not in COMPILED_POLICIES:  # no compiled frame: every backend runs it in Python
            backend = "python"
        backend = _choose_backend(backend, settings["policy"])
        sim._configure(
            scene,
            settings["record"],
            float(settings["frame_rate"]),
            float(settings["dt"]),
            bool(settings["by_rate"]),
            settings["policy"],
            settings["broad_phase"],
            float(settings["bisect_tol"]),
            backend,
            _restored_laws(settings),
            _restored_sensors(settings),
        )
        sim.start_time = start_time
        sim._edits = int(settings.get("edits", 0))
        if math.isnan(state.virial) and len(events) == state.detections + state.wall_hits + sim._edits:
            # A version 1 state (no virial) whose log holds the whole run: the virial is in the log.
            state.virial = float(np.sum(collision_virials(events, scene.discs.masses, scene.box)[1]))
        sim._load(state)
        if len(events):
            sim._log.extend(events)
        return sim

    # --- the driver's protocol -----------------------------------------------------------
    def _advance(self, until: float, limit: int | None) -> int:
        todo = self._frames_due(until)
        if limit is not None:
            todo = limit if todo is None else min(todo, limit)
        if todo is None:
            msg = "a fixed-step run needs a finite until or a frame count"
            raise InvalidArgumentError(msg)
        done = 0
        # Frames per call: the compiled frame does many at once (one with sensors: they look at every frame).
        batch = getattr(self._policy, "batch", 1) if self._sensing is None else 1
        if callable(batch):  # as many as the policy can vouch for without a check before each frame
            batch = batch(self._paths, self.dt)
        while done < todo:
            # Ctrl-C ends the run at a whole frame; a handler of the program's own may let it go on.
            with deferred_interrupt() as interrupted:
                while done < todo and not interrupted[0]:
                    count = min(batch, todo - done)
                    if count > 1:
                        self._frames(count)
                    else:
                        self._frame()
                    done += count
        return todo

    def _event_count(self) -> int:
        """Log records produced since the start: one per detection, wall or segment hit, edit and sensor crossing."""
        counts = self._tally.counts
        return counts["detections"] + counts["wall_hits"] + self._edits + counts["sensor_events"]

    def _set_discs(self, indices: np.ndarray, positions: np.ndarray | None, velocities: np.ndarray) -> None:
        paths, t = self._paths, self.time
        flown = paths.flown(t)
        if paths.drag != 0.0 and paths.falls is not None:  # what the drag took over the flights the edit ends
            rows = indices[paths.falls[indices]]
            self._tally.lose(paths.drag_loss(t, self._shapes.mass, rows))
        for k, i in enumerate(indices.tolist()):
            x, y = (flown[i] if positions is None else positions[k]).tolist()
            vx, vy = velocities[k].tolist()
            x, y = paths.turn(i, t, x, y, vx, vy)
            if positions is not None or t == self._frame_time:
                paths.frame_positions[i] = (x, y)  # a disc set somewhere counts as having been there at the frame

    def _settle(self, until: float) -> None:
        """Move the clock to ``until``: the discs drift straight from the last frame; the frame grid stays."""
        self.time = max(until, self._frame_time)

    # --- the user's protocol -------------------------------------------------------------
    def run(
        self,
        until: float | None = None,
        *,
        frames: int | None = None,
        events: int | None = None,
        observers=(),
        progress: bool = False,
        record_to=None,
        checkpoint=None,
        checkpoint_every: int | None = None,
    ):
        """Advance frame by frame up to time ``until`` and/or for ``frames`` frames.

        Every frame at or before ``until`` is done; then ``time`` is set to ``until`` (discs drift
        straight from the last frame, and the next frame still falls at its usual time), unless the
        frame count stopped the run first. See :func:`discsim.run.driver.drive` for the rest.

        Args:
            until: stop time.
            frames: stop after this many frames (None: no limit).
            events: another name for ``frames`` (the name :func:`discsim.resume` uses).
            observers, progress, record_to, checkpoint, checkpoint_every: as for
                :meth:`discsim.engines.base.Engine.run` (``checkpoint_every`` counts frames).

        Returns:
            ``self``, so calls chain.

        Raises:
            TimeError: if ``until`` is before ``time`` or NaN, or infinite without ``frames``.
            InvalidArgumentError: if neither limit is given, ``frames`` is not a whole number
                >= 0, or ``frames`` and ``events`` are both given and differ.
        """
        if events is not None:
            if frames is not None and check_count("frames", frames) != check_count("events", events):
                msg = f"give frames=... or events=..., not both: frames={frames!r} but events={events!r}"
                raise InvalidArgumentError(msg)
            frames = events
        return super().run(
            until,
            events=frames,
            observers=observers,
            progress=progress,
            record_to=record_to,
            checkpoint=checkpoint,
            checkpoint_every=checkpoint_every,
        )

    def step(self) -> list[Event]:
        """Do one frame: move, test, respond.

        Returns:
            The :class:`~discsim.events.Event` of each response in the frame,
            empty if nothing touched: for ``"resolve"``, ``"revert"`` and
            ``"separate"`` wall hits first, then segment hits, then disc pairs
            in the order they were handled, all at the frame time; for
            ``"bisect"`` and ``"swept"`` in the order of their contact times; then the sensors' ``"enter"``
            and ``"leave"`` at the frame, by disc then sensor.

        Example:
            >>> import discsim as ds
            >>> sim = ds.FixedStep(ds.Discs([[3.0, 1.0]], [[2.0, 0.0]], 0.5), ds.Box(4.0, 2.0), dt=0.5)
            >>> sim.step()  # x = 4.0: past the wall at 3.5
            [Event(time=0.5, kind='wall', i=0, j=-1)]
            >>> sim.velocities.tolist()
            [[-2.0, 0.0]]
        """
        self._check_can_advance()
        return self._frame()

    def _frame(self) -> list[Event]:
        paths, tally = self._paths, self._tally
        self._policy.check(paths, self.dt)
        k = tally.counts["frames"] + 1
        t = self.frame_time(k)
        tally.log = self._log if self._logging else None
        last = None if self._sensing is None else self._sensing.look(paths, self._frame_time)  # the last frame
        try:
            events = self._policy.frame(paths, tally, self._frame_time, t)
        except Interrupted:  # raised only between frames (deferred_interrupt): the state is consistent
            raise
        except BaseException as exc:  # half-way through a frame: the state cannot be trusted
            self._broken = f"{type(exc).__name__} in frame {k}"
            raise
        self._frame_time = t
        self.time = t
        tally.counts["frames"] = k
        return events if last is None else events + self._sensed(last, t)

    def _frames(self, count: int) -> None:
        """Do ``count`` frames in one call of the compiled frame (the same frames as ``count`` calls of
        :meth:`_frame`; a policy without :meth:`frames` never gets here).
        """
        paths, tally = self._paths, self._tally
        k = tally.counts["frames"]
        times = self.frame_time(np.arange(k + 1, k + count + 1))
        tally.log = self._log if self._logging else None
        try:
            self._policy.frames(paths, tally, self._frame_time, times)
        except Interrupted:  # pragma: no cover - raised only between calls (deferred_interrupt)
            raise
        except BaseException as exc:  # half-way through the frames: the state cannot be trusted
            self._broken = f"{type(exc).__name__} in frames {k + 1} to {k + count}"
            raise
        self._frame_time = self.time = float(times[-1])
        tally.counts["frames"] = k + count


def _restored_laws(settings: dict) -> Laws:
    """The laws a checkpoint's settings hold (none: the defaults), checked as the constructor checks them.

    Raises:
        CheckpointError: naming what the constructor would refuse.
    """
    try:
        return _check_laws(Laws.from_settings(settings.get("laws", {})), settings["policy"])
    except InvalidArgumentError as exc:
        msg = f"the checkpoint's laws cannot be used: {exc}"
        raise CheckpointError(msg) from exc


def _restored_sensors(settings: dict) -> tuple[Sensor, ...]:
    """The sensors a checkpoint's settings hold (none: none), built and checked as the constructor's.

    Raises:
        CheckpointError: naming the entry that cannot be a sensor.
    """
    sensors = []
    for k, entry in enumerate(settings.get("sensors", [])):
        try:
            shape, a = entry[0], [float(x) for x in entry[1:]]
            if len(a) != 4:
                raise ValueError("a shape and 4 numbers expected")
            if shape == "circle":
                sensors.append(Sensor.circle(a[:2], a[2]))
            elif shape in ("rectangle", "line"):
                sensors.append(getattr(Sensor, shape)(a[:2], a[2:]))
            else:
                raise ValueError(f"unknown shape {shape!r}")
        except (TypeError, ValueError, IndexError, InvalidArgumentError) as exc:
            msg = f"the checkpoint's sensors[{k}] cannot be used: {entry!r} ({exc})"
            raise CheckpointError(msg) from None
    return tuple(sensors)


def _check_laws(laws: Laws, policy: str) -> Laws:
    """``laws``, unless ``policy`` cannot follow them: gravity or drag inside a frame (the sub-frame policies'
    paths are straight).

    Raises:
        InvalidArgumentError: naming the gravity (or the drag) and the policy.
    """
    if policy in SUB_FRAME_POLICIES:
        law = f"gravity={laws.gravity}" if laws.falls else f"drag={laws.drag!r}" if laws.drag != 0.0 else None
        if law is not None:
            msg = (
                f"{law} needs a policy that answers at the frame ('resolve', 'revert' or 'separate'): "
                f"policy {policy!r} finds contacts inside a frame along straight paths"
            )
            raise InvalidArgumentError(msg)
    return laws


def _choose_backend(backend, policy: str) -> str:
    """The backend that runs the frames for the argument ``backend`` and ``policy`` (checked already).

    Raises:
        InvalidArgumentError: an unknown backend, ``"numba"`` without numba, or ``"numba"`` with a
            policy that has no compiled frame.
    """
    chosen = resolve_backend(backend, BACKENDS, "FixedStep")
    if chosen == "numba" and policy not in COMPILED_POLICIES:
        if backend == "numba":
            msg = (
                f"policy {policy!r} has no compiled frame (backend='numba' compiles {list(COMPILED_POLICIES)}); "
                "use backend='auto' or 'python'"
            )
            raise InvalidArgumentError(msg)
        return "python"
    return chosen
