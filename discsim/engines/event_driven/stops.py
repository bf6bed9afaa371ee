"""How an event-driven run stops: at a time, after a count, when no disc can ever hit anything again, or jammed.

:class:`RunStops` is the part of :class:`~discsim.engines.event_driven.engine.EventDriven` between the driver
and the backend: ``_advance(until, limit)`` asks the backend for events in chunks, watching the clock for a
jam (:class:`~discsim.errors.JammedError`, naming the wedged discs), and ends an open-ended run in a periodic
box once it proves no pair will ever meet (``_never_again``), putting the clock and the cells back
(``_rewind``). Any other exception inside the loop marks the engine unusable.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from discsim.cells import neighbour_pairs
from discsim.engines.context import LookOnly
from discsim.engines.event_driven.piston import check_room
from discsim.engines.event_driven.protocol import Backend
from discsim.engines.event_driven.squeeze import Crush, lid_crush, squeeze
from discsim.errors import Interrupted, InvalidArgumentError, JammedError
from discsim.model import Box, Discs
from discsim.scene import Scene

if TYPE_CHECKING:
    from discsim.events import EventLog

__all__ = ["RunStops"]

INF = math.inf


def check_parts(scene: Scene, laws) -> None:
    """Refuse, by name, what the loop does not run yet under ``laws`` (a :class:`~discsim.laws.Laws`): moving
    segments under gravity with restitution below 1 (a disc settling on a moving support would need to rest in its
    frame), and a piston with what it does not take (:func:`check_piston`)."""
    elastic = laws.restitution == 1.0 and not laws._pairs
    if scene.moving and laws.falls and not elastic:
        k = next(k for k, segment in enumerate(scene.segments) if segment.moving)
        msg = (
            f"segments[{k}] {scene.segments[k]!r} moves: under gravity={laws.gravity} moving segments run with "
            f"elastic bounces only (restitution=1), not restitution={laws.restitution!r} (a disc would settle on "
            "the moving segment, and rest in its frame is not built yet)"
        )
        raise InvalidArgumentError(msg)
    if scene.piston is not None:
        check_piston(scene, laws)


def check_piston(scene: Scene, laws) -> None:
    """Refuse, by name, a piston with what it does not take yet (restitution, roughness, drag, gravity other than
    down along y, obstacles, moving segments), a piston of finite mass over no disc, and one the gas could lift out
    of the box (:func:`check_room`)."""
    piston, discs = scene.piston, scene.discs
    elastic = laws.restitution == 1.0 and not laws._pairs
    if not elastic or laws.rough or laws.drag or laws.gravity[0] != 0.0 or laws.gravity[1] > 0.0:
        msg = (
            "a piston runs with elastic, smooth discs without drag, under no gravity or gravity down along y, not "
            f"restitution={laws.restitution!r}, roughness={laws.roughness!r}, drag={laws.drag!r}, "
            f"gravity={laws.gravity!r}"
        )
        raise InvalidArgumentError(msg)
    if scene.moving:
        k = next(k for k, segment in enumerate(scene.segments) if segment.moving)
        msg = f"segments[{k}] moves: a piston and moving segments do not run together yet"
        raise InvalidArgumentError(msg)
    fixed = np.flatnonzero(discs.masses == INF)
    if len(fixed):
        msg = f"disc {int(fixed[0])} is an obstacle (infinite mass): a piston does not run with obstacles yet"
        raise InvalidArgumentError(msg)
    if not piston.kinematic and not len(discs):
        msg = "a piston of finite mass needs discs under it (it would fall for ever)"
        raise InvalidArgumentError(msg)
    check_room(piston, scene.box, discs, scene.piston_height, piston.velocity, piston.pressure, -laws.gravity[1])


class RunStops:
    """The stops of an event-driven run (a mixin of :class:`~discsim.engines.event_driven.engine.EventDriven`)."""

    # What the engine provides (declared for readers and the type checker).
    _backend: Backend
    _auto_events: int | None
    _broken: str | None
    _logging: bool
    _log: EventLog
    box: Box
    laws: Any  # the engine's Laws
    discs: Discs
    scene: Scene
    time: float

    _edits: int
    run_context: Any

    if TYPE_CHECKING:  # the engine's own methods, named for the type checker only (at run time they would
        # come before the engine's in the method order)

        def _units(self) -> int: ...
        def _take_compiled(self) -> None: ...
        def snapshot(self) -> Discs: ...
        def _restructure(self, keep: np.ndarray, added: Discs | None, scene: Scene, last=None) -> None: ...
        def _piston_now(self) -> tuple[float, float, int, float]: ...

        @property
        def positions(self) -> np.ndarray: ...

        @property
        def velocities(self) -> np.ndarray: ...

    def _advance(self, until: float, limit: int | None) -> int:
        log = self._log if self._logging else None
        if self._given is None and self._kinematic:  # (before the walls squeeze anything)
            self._given = _energy(self.discs.masses, self.velocities)
        try:
            if until != INF:
                return self._chunked(until, limit, log)
            return self._advance_open(limit, log)
        except (Interrupted, JammedError):  # raised between two whole events: the state is consistent
            raise
        except BaseException as exc:  # half-way through an event: the state cannot be trusted
            self._broken = f"{type(exc).__name__} at time {self.time!r}"
            raise

    def _advance_open(self, limit: int | None, log) -> int:
        """:meth:`_advance` with no time limit: also stop when no disc can ever hit anything again.

        In a periodic box, discs that never meet cross cells forever. The loop
        therefore returns after ``budget`` cell crossings in a row of calls;
        when a whole budget passed without a collision or wall hit,
        :meth:`_never_again` looks for a proof that none will ever come, and
        the budget doubles if it finds none (so the check costs O(log) calls).
        When it finds one, ``time`` goes back to the last collision or wall hit
        (or to where the call started): the crossings after it changed nothing.
        """
        done, start = 0, self.time
        budget = 64 + 16 * len(self.discs)
        while True:  # (self._backend each time: "auto" may have taken the compiled loop inside _chunked)
            crossings = self._backend.counts()["cell_crossings"]
            k = self._chunked(INF, None if limit is None else limit - done, log, budget)
            done += k
            if done == limit or self._backend.counts()["cell_crossings"] - crossings < budget:
                return done  # the event limit, or nothing left in the queue
            if k == 0:
                if self._never_again():
                    last = self._backend.last_event() if done else None  # done > 0: there is one
                    self._rewind(start if last is None else last[0])
                    return done
                budget *= 2

    def _moved_segments(self, segments: tuple) -> None:
        """The segments from now on are ``segments`` (one's velocity changed, where it is now): the backend starts
        afresh here from the discs as they are (as :meth:`_rewind` does), over the new segments. O(N)."""
        scene = self.scene.but(segments=segments)
        check_parts(scene, self.laws)  # before anything changes
        last = self._backend.last_event()
        now = self.snapshot()
        here = scene.but(now)
        self._restructure(np.arange(len(now)), None, here, last)
        self.scene, self.segments = scene, scene.segments

    def _rewind(self, time: float) -> None:
        """Back to ``time``, after a proof that no disc will ever hit anything again (:meth:`_never_again`).

        The discs have crossed cells since ``time``, so the clock alone cannot go back: each disc's cell would
        be one it reaches only later, and after a change of course (``set_velocities``) the predictions would
        scan the wrong neighbours and miss collisions. The backend starts afresh at ``time`` from the discs as
        they are then (what ``EventDriven(sim.snapshot(), box)`` would do), keeping the counters, the virial,
        the periodic images and the last event. O(N), once per proof.
        """
        old = self._backend
        last = old.last_event()
        old.time = time
        now = self.snapshot()
        scene = self.scene.but(now)
        self._restructure(np.arange(len(now)), None, scene, last)

    #: A run raises :class:`~discsim.errors.JammedError` after ``jam_events + jam_events_per_disc * N``
    #: physical events in a row at one instant (or within ``jam_time`` of the time scale, below), plus room for
    #: the longest finite cascade the touching discs could make (:meth:`_cascade`): wedged discs collide there
    #: for ever, while a finite cascade of simultaneous collisions ends (``M (M - 1) / 2`` collisions at most for
    #: a touching row of M discs of one mass, ``M (sqrt(M) - 1)`` for a touching square lattice with room).
    jam_events: int = 10_000
    jam_events_per_disc: int = 100
    #: ... and those events count as "at one instant" while the clock moves by less than ``jam_time`` times the
    #: time scale ``sqrt(sum m r^2 / sum m v^2)`` (discs of finite mass: the time a disc at the mass-weighted
    #: rms speed takes to cross its radius): an unbounded cascade creeps towards an instant it never reaches
    #: (a light disc squeezed between a wall and a disc 10^200 times heavier: its speed grows by twice the
    #: heavy one's at each of some 10^100 bounces). A free gas takes about 100 collision times per disc for
    #: that many events, so only discs closer than about 10^-10 radii to wedged, for ever, qualify.
    jam_time: float = 1e-8
    _jam_mark: tuple[float, int, int, bool] | None = None  # (time, physical events, events allowed, extended)
    _jam_counts: tuple[int, np.ndarray] | None = None  # (physical events, each disc's counter) half-way there
    _jam_scale: tuple[int, int, float] | None = None  # (edits, physical events, time scale) when last taken
    _squeeze_units: int = 0  # physical events at the last look for a disc squeezed by a kinematic wall

    def _chunked(self, until: float, limit: int | None, log, crossings: int | None = None) -> int:
        """``backend.advance(until, limit, log, crossings)`` in chunks, watching the clock between them.

        The same result as one call (chunks change nothing in the dynamics), for every backend. Each chunk
        holds at most half the jam threshold of physical events; when that many pass, over any number of
        calls (a driver's chunks, ``step()`` after ``step()``), with the clock standing still (or moving by
        less than ``jam_time`` of the time scale), the discs are jammed. Half-way there the discs' counters
        are taken, so that the error names the discs the cascade moved.

        Raises:
            JammedError: naming the jammed discs; the engine is consistent at its last whole event.
        """
        backend = self._backend
        chunk = self.jam_events + self.jam_events_per_disc * len(self.discs)
        done, left = 0, crossings
        while True:
            window = self.jam_time * self._time_scale(chunk)
            mark, units = self._jam_mark, self._units()
            if mark is None or backend.time - mark[0] > window:
                mark = self._jam_mark = (backend.time, units, chunk, False)
                self._jam_counts = None
            seen, half = units - mark[1], mark[2] // 2
            room = half - seen if seen < half else mark[2] - seen  # stop half-way, and at the threshold
            ask = room if limit is None else min(room, limit - done)
            if self._auto_events is not None:  # backend="auto": the Python loop until the compiled one pays
                ask = min(ask, max(self._auto_events, 1))
            crossed = backend.counts()["cell_crossings"] if crossings is not None else 0
            k = backend.advance(until, ask, log, left)
            done += k
            if self._auto_events is not None:
                self._auto_events -= k
                if self._auto_events <= 0:
                    self._take_compiled()
                    backend = self._backend
            units = self._units()
            if backend.time - mark[0] > window:
                self._jam_mark, self._jam_counts = (backend.time, units, chunk, False), None
            elif units - mark[1] >= mark[2]:
                self._jammed(mark, units, chunk)
            elif units - mark[1] >= half and self._jam_counts is None:
                self._jam_counts = (units, backend.disc_counts())
            if not 0 <= units - self._squeeze_units < half and self._kinematic:
                self._squeeze_units = units
                self._check_squeeze(until)
            if k < ask or done == limit:
                return done  # the time or event limit, an empty queue, or the crossings asked for
            if left is not None:
                left -= backend.counts()["cell_crossings"] - crossed
                if left <= 0:
                    return done

    @property
    def _kinematic(self) -> bool:
        """Whether a wall moves whatever hits it (a moving segment, a kinematic lid): it may crush a disc."""
        piston = self.scene.piston
        return self.scene.moving or (piston is not None and piston.kinematic)

    def _check_squeeze(self, until: float) -> None:
        """Raise when a kinematic wall crushes a disc for certain before ``until``: a kinematic lid that leaves no
        room for the discs (:func:`~discsim.engines.event_driven.squeeze.lid_crush`), or a wall that squeezes the
        last event's disc against a wall facing it (:func:`~discsim.engines.event_driven.squeeze.squeeze`; not
        under drag or roughness, nor in a periodic box). O(N + walls^2), once per half a jam threshold of events,
        so that it looks at the walls as observers left them. With a callback that may change the run
        (``sim.on(kind, fn)`` without ``changes=False``: it may steer the walls before the crush) only the backstop
        (:meth:`_check_speedup`) looks."""
        piston, laws = self.scene.piston, self.laws
        steerable = any(not isinstance(fn, LookOnly) for fns in self.run_context.handlers.values() for fn in fns)
        lid = None
        if piston is not None and piston.kinematic:
            height, velocity, _, _ = self._piston_now()
            lid = (height, velocity)
            crush = lid_crush(self.discs.radii, self.box.width, height, velocity, apart=not self.scene.pass_through)
            if crush is not None and self.time + crush.after <= until and not steerable:
                raise JammedError(self._crush_message(crush, "set_piston(velocity=...)"))
        last = self._backend.last_event()
        if last is None or (lid is None and not self.scene.moving):
            return
        velocities, segments = self.velocities, [segment.at(self.time) for segment in self.scene.segments]
        if not (laws.drag or laws.rough or self.box.periodic or steerable):
            args = (self.positions, velocities, self.discs.radii, laws.gravity, last[2], until - self.time)
            crush = squeeze(self.box, segments, lid, *args)
            if crush is not None:
                raise JammedError(self._crush_message(crush, "set_segment_velocity"))
        self._check_speedup(velocities)

    #: A run with kinematic walls raises :class:`~discsim.errors.JammedError` when a disc moves this many times
    #: faster than the energy the discs were given (at the start and by edits) and the walls' speeds allow: a crush
    #: that :func:`~discsim.engines.event_driven.squeeze.squeeze` cannot prove (several discs squeezed together;
    #: drag, roughness, a periodic box, a callback that may steer), whose speeds grow by about the walls' speed
    #: at every bounce.
    squeeze_speedup: float = 1e4
    #: ``sum m v^2`` over the discs of finite mass when the walls became kinematic, plus what each edit gave the
    #: discs it set (never taken afresh from the discs, whose speeds the walls may have pumped up); None before.
    _given: float | None = None

    def _gave(self, masses: np.ndarray, velocities: np.ndarray) -> None:
        """An edit set discs of ``masses`` ``(K,)`` to ``velocities`` ``(K, 2)``: the backstop's energy takes it."""
        if self._given is not None:
            self._given += _energy(masses, velocities)

    def _check_speedup(self, velocities: np.ndarray) -> None:
        """The backstop of :meth:`_check_squeeze`: raise on a disc faster than ``squeeze_speedup`` times the speed
        scale: ``sqrt(given / min m)`` (what the energy the discs were given allows one disc), the speed of a fall
        across the box, and the kinematic walls' speeds now."""
        masses = self.discs.masses
        finite = np.isfinite(masses)
        if not finite.any():
            return
        speeds = np.where(finite, np.hypot(velocities[:, 0], velocities[:, 1]), 0.0)
        fall = 2.0 * float(np.hypot(*self.laws.gravity)) * float(self.box.width + self.box.height)
        walls = [float(np.hypot(*segment.velocity)) for segment in self.scene.segments]
        piston = self.scene.piston
        if piston is not None and piston.kinematic:
            walls.append(abs(self._piston_now()[1]))
        given = self._given if self._given is not None else _energy(masses, velocities)
        scale = max(math.sqrt(given / float(masses[finite].min()) + fall), *walls)
        k = int(np.argmax(speeds))
        if scale > 0.0 and speeds[k] > self.squeeze_speedup * scale:
            msg = (
                f"disc {k} moves at {float(speeds[k]):.6g}, {self.squeeze_speedup:g} times the speed scale of the "
                f"run ({scale:.6g}: the energy the discs were given, a fall across the box and the kinematic "
                f"walls' speeds) at time {self.time!r}: kinematic walls squeeze it against others or a wall, and "
                "its bounces pile up before they close on it; steer the walls (set_segment_velocity, "
                "set_piston(velocity=...)) or stop the run earlier"
            )
            raise JammedError(msg)

    def _crush_message(self, crush: Crush, steer: str) -> str:
        at = self.time + crush.after
        return (
            f"{crush.what} at time {at!r}: the bounces come faster and faster before then (infinitely many), so "
            f"no run can pass it (the clock is at {self.time!r}); steer the wall ({steer}) or run until an earlier "
            "time"
        )

    def _jammed(self, mark: tuple[float, int, int, bool], units: int, chunk: int) -> None:
        """The threshold is reached: give a finite cascade of the touching discs its room once, else raise (or
        start afresh, when the time scale taken now, after the user's edits, says that the clock did move)."""
        scale = self._time_scale(chunk, fresh=True)
        if self.time - mark[0] > self.jam_time * scale:
            self._jam_mark, self._jam_counts = (self.time, units, chunk, False), None
            return
        discs, room = self._cascade()
        if not mark[3] and room > 0:
            self._jam_mark = (mark[0], mark[1], mark[2] + room, True)
            return
        raise JammedError(self._jam_message(discs, units - mark[1], self.time - mark[0], scale))

    def _time_scale(self, chunk: int, fresh: bool = False) -> float:
        """``sqrt(sum m r^2 / sum m v^2)`` over the discs of finite mass (0.0 when none moves).

        O(N) to take, so kept (elastic collisions keep the energy) until the user's edits changed the discs and
        ``chunk / 2`` physical events passed since (a callback that edits after every event costs O(N) per
        ``chunk / 2`` events, not per event), or when asked ``fresh`` (before a :class:`JammedError`).
        """
        kept = self._jam_scale
        if kept is not None and not fresh and (kept[0] == self._edits or self._units() - kept[1] < chunk // 2):
            return kept[2]
        masses, radii = self.discs.masses, self.discs.radii
        finite = np.isfinite(masses)
        scale = 0.0
        if finite.any():
            weight = masses[finite] / masses[finite].max()  # no overflow: masses reach 1e100, speeds too
            speed2 = (self.velocities[finite] ** 2).sum(axis=1)
            energy = float(weight @ speed2)
            if energy > 0.0:
                scale = math.sqrt(float(weight @ radii[finite] ** 2) / energy)
        self._jam_scale = (self._edits, self._units(), scale)
        return scale

    def _cascade(self) -> tuple[np.ndarray, int]:
        """The discs of a suspected jam, and the room a finite cascade of theirs might still need.

        The discs: those of the last event and those the cascade moved (their counters changed since half-way
        to the threshold), and every disc touching them, transitively (sorted, caller's numbering). Touching:
        centres within the contact distance plus 1e-9 of it, minimum image, collision filter obeyed.

        The room: ``M e`` events, with ``M`` the moving discs touching the last event's disc through moving
        discs, transitively, and ``e`` the most contacts from that disc to another of them (``e`` is at least
        half the contacts across the cluster, ``D``): a touching row or square lattice of discs of one mass,
        with room around it, ends its cascade within ``M D / 2`` collisions (each row and each column sorts its
        velocities). Obstacles pass no velocity on: they are not counted, nor crossed.
        """
        last = self._backend.last_event()
        if last is None:
            return np.zeros(0, dtype=np.int64), 0
        n = len(self.discs)
        radii, masses = self.discs.radii, self.discs.masses
        i, j, d = neighbour_pairs(self.positions, 2.0 * float(radii.max()), self.box)
        touch = np.hypot(d[:, 0], d[:, 1]) <= (radii[i] + radii[j]) * (1.0 + 1e-9)
        if self.scene.filtering:
            touch &= ~self.scene.passes(i, j)
        i, j = i[touch], j[touch]

        def grow(seeds: np.ndarray, i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, int]:
            """The cluster of contacts ``(i, j)`` around ``seeds`` (a mask) and the steps it took."""
            steps = 0
            while True:
                grown = seeds.copy()
                grown[j[seeds[i]]] = True
                grown[i[seeds[j]]] = True
                if grown.sum() == seeds.sum():
                    return seeds, steps
                seeds, steps = grown, steps + 1

        first = np.zeros(n, dtype=bool)
        first[last[2]] = True  # a moving disc: the owner of the event
        moving = np.isfinite(masses[i]) & np.isfinite(masses[j])  # obstacles pass no velocity on
        cluster, reach = grow(first, i[moving], j[moving])
        room = int(cluster.sum()) * reach
        seeds = first.copy()
        seeds[[k for k in last[2:] if k >= 0]] = True
        if self._jam_counts is not None:
            seeds |= self._backend.disc_counts() != self._jam_counts[1]
        return np.flatnonzero(grow(seeds, i, j)[0]), room

    def _jam_message(self, discs: np.ndarray, events: int, moved: float, scale: float) -> str:
        listed = discs.tolist()
        named = ", ".join(map(str, listed[:20])) + (f", ... ({len(listed)} discs)" if len(listed) > 20 else "")
        laws = getattr(self, "laws", None)
        if laws is not None and not laws.default and laws.restitution != 1.0 and laws.tc == 0.0:
            return (
                f"discs {named} collapsed at time {self.time!r}: with restitution {laws.restitution!r} they made "
                f"{events} collisions and wall hits while the clock moved by {moved:.3g} (inelastic collapse: "
                "infinitely many collisions in a finite time); set tc= (the TC model: a collision within tc of a "
                "disc's previous one is elastic) to prevent it"
            )
        if moved == 0.0:
            return (
                f"discs {named} are jammed at time {self.time!r}: wedged against each other or a wall, they made "
                f"{events} collisions and wall hits without the clock moving; give them room (a gap) or velocities "
                "that part them"
            )
        return (
            f"discs {named} are jammed at time {self.time!r}: squeezed against each other or a wall, they made "
            f"{events} collisions and wall hits while the clock moved by {moved:.3g}, under jam_time = "
            f"{self.jam_time:g} of the time a disc takes to cross its radius ({scale:.3g}): a cascade "
            "that would go on for ever (a light disc squeezed between a wall and a far heavier disc, say); give "
            "them room, or masses closer to each other's"
        )

    def _never_again(self) -> bool:
        """True if, from now on, no pair of discs can ever meet and no disc hits a wall or segment.

        Only periodic boxes (a moving disc always reaches a wall). A pair can
        never meet when its relative velocity is exactly zero, when its groups
        pass through each other, or when it moves relative to itself only along
        x (or only along y) and its minimum-image gap across that motion exceeds
        the contact distance. Any other pair might meet some day, and the answer is False.
        """
        box, scene = self.box, self.scene
        if not box.periodic or len(self.discs) < 2:
            return box.periodic or not self.velocities.any()
        pos, vel, radii = self.positions, self.velocities, self.discs.radii
        # Discs that drift alike never meet: only pairs of different velocities need a look, so N discs
        # drifting alike cost O(N log N), not O(N^2).
        label = np.unique(vel, axis=0, return_inverse=True)[1].reshape(-1)
        groups = [np.flatnonzero(label == g) for g in range(int(label.max()) + 1)]
        tol = 1e-12 * box.size.max()
        for g, a in enumerate(groups[:-1]):
            b = np.concatenate(groups[g + 1 :])
            dv = vel[b] - vel[a[0]]  # the same for every disc of group a
            still = (dv == 0.0).all(axis=1)  # rows of -0.0 and 0.0 land in two groups
            block = max(1, (1 << 22) // len(b))  # bounds memory: block x |b| pairs at a time
            for start in range(0, len(a), block):
                rows = a[start : start + block]
                gap = box.minimum_image(pos[b][None, :, :] - pos[rows][:, None, :])
                reach = (radii[rows][:, None] + radii[b][None, :]) * (1.0 + 1e-9) + tol
                along_y = (dv[:, 0] == 0.0) & (np.abs(gap[..., 0]) > reach)  # x gap fixed for good
                along_x = (dv[:, 1] == 0.0) & (np.abs(gap[..., 1]) > reach)
                never = still | along_y | along_x
                if scene.filtering:
                    never |= scene.blocked[scene.group[rows][:, None], scene.group[b][None, :]]
                if not never.all():
                    return False
        return True


def _energy(masses: np.ndarray, velocities: np.ndarray) -> float:
    """``sum m v^2`` over the discs of finite mass."""
    finite = np.isfinite(masses)
    return float(np.sum(masses[finite] * np.sum(velocities[finite] ** 2, axis=1)))
