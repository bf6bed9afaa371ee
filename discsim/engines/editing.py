"""Changing a simulation between events: :class:`DiscEditing`, the part of every engine behind
``set_velocities``, ``apply_impulse``, ``set_positions``, ``add_discs``, ``remove_discs``, ``ids`` and ``on``.

Each change is checked whole before anything changes (the errors name the disc and the value), then made by
the engine's own ``_set_discs(indices, positions, velocities)`` or ``_restructure(keep, added, scene)``
(:class:`~discsim.engines.base.Engine`'s abstract methods), logged (``SET``, ``ADD``, ``REMOVE`` records)
and counted. A mixin of :class:`~discsim.engines.base.Engine`: it reads the engine's ``discs``, ``box``,
``scene``, ``time``, ``positions``, ``velocities`` and log, and holds nothing of its own.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar, NoReturn

import numpy as np

from discsim.cells import neighbour_pair_chunks
from discsim.engines.context import LookOnly, RunContext, readonly_ids
from discsim.errors import DiscsimError, InvalidArgumentError, OutsideBoxError, OverlapError, UnitsError, WrongTypeError
from discsim.model import OVERLAP_TOLERANCE, SPEED_RANGE, Box, Discs, _real_array
from discsim.scene import Scene, check_added

__all__ = ["DiscEditing", "Uneditable"]

#: What a :class:`~discsim.model.Discs` holds, in its constructor's order: every disc keeps all of it when discs
#: are added or removed (its spin and moment of inertia too).
_DISC_FIELDS = ("positions", "velocities", "radii", "masses", "groups", "spins", "inertia")


class SegmentEditing:
    """``set_segment_velocity``: a segment steered during a run (a mixin of the engines, through
    :class:`DiscEditing`)."""

    segments: tuple
    time: float
    _edits: int

    def _gave(self, masses: np.ndarray, velocities: np.ndarray) -> None:
        """An edit gave discs of ``masses`` ``(K,)`` these ``velocities`` ``(K, 2)`` (nothing here; an engine that
        watches the energy its discs were given takes it)."""

    def _check_editable(self, what: str) -> None:
        """Refuse ``what`` before anything changes, where the engine cannot take it."""

    def set_segment_velocity(self, k: int, velocity):
        """Move segment ``k`` at ``velocity`` ``(2,)`` (length / time) from now on, from where it is now: a paddle
        the player steers, a pusher that starts or stops (``(0, 0)``). The run goes on from here exactly (every
        disc is predicted again: O(N)). ``EventDriven`` only, under the laws moving segments take (see
        :class:`~discsim.model.Segment`). Returns ``self``.

        Raises:
            InvalidArgumentError: ``k`` that is not a segment's index, or ``velocity`` that is not 2 finite numbers
                (naming it), or laws under which segments may not move; nothing changes.
        """
        self._check_editable("change a segment's velocity")
        n = len(self.segments)
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < n:
            msg = f"segment index {k!r} does not exist (this simulation has segments 0 to {n - 1})"
            raise InvalidArgumentError(msg)
        v = _real_array("velocity", velocity, InvalidArgumentError)
        if v.shape != (2,) or not np.isfinite(v).all():
            msg = f"segment {k}'s velocity must be 2 finite numbers, got {v.tolist()}"
            raise InvalidArgumentError(msg)
        moved = self.segments[int(k)].steered(self.time, v)  # where it is now, at time now (drawn where it was)
        self._moved_segments((*self.segments[:k], moved, *self.segments[k + 1 :]))
        self._edits += 1
        return self

    def _moved_segments(self, segments: tuple) -> None:
        """Go on over ``segments`` from now (an engine that moves segments says how); refused here."""
        msg = f"{type(self).__name__} cannot change a segment's velocity yet (EventDriven can)"
        raise InvalidArgumentError(msg)


class DiscEditing(SegmentEditing):
    """The disc-editing methods every engine shares (see the module docstring)."""

    # What the engine gives these methods (declared for type checkers; Engine sets or defines each).
    scene: Scene
    discs: Discs
    box: Box
    segments: tuple
    time: float
    run_context: RunContext
    _edits: int
    _logging: bool

    if TYPE_CHECKING:

        @property
        def positions(self) -> np.ndarray: ...
        @property
        def velocities(self) -> np.ndarray: ...
        def snapshot(self) -> Discs: ...
        def _check_usable(self) -> None: ...
        def _log_origin(self) -> tuple[Discs, np.ndarray | None]: ...
        def _set_discs(self, indices: np.ndarray, positions: np.ndarray | None, velocities: np.ndarray) -> None: ...
        def _restructure(self, keep: np.ndarray, added: Discs | None, scene: Scene) -> None: ...

    def _check_editable(self, what: str) -> None:
        """Refuse ``what`` (an edit, or a callback) before anything changes, where the engine cannot take it."""

    #: Event kinds a callback can follow with :meth:`on`.
    CALLBACK_KINDS: ClassVar[tuple[str, ...]] = ("collision", "wall", "segment", "enter", "leave")

    def set_velocities(self, indices, velocities):
        """Give discs ``indices`` new ``velocities`` ``(K, 2)`` (or one ``(2,)`` for all) at ``time``.

        Each change is an event of its own in the log (kind ``"set"``), so :meth:`trajectory` stays exact;
        only the discs changed are re-predicted. Returns ``self``.

        Raises:
            InvalidArgumentError: an index that is not a disc, a repeated index, a wrong shape, a NaN or
                infinite velocity, or an obstacle (infinite mass; obstacles stay where they are).
            UnitsError: a speed outside the supported range. Nothing changes then.

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[0.0, 0.0], [0.0, 0.0]], 1.0), ds.Box(10, 10))
            >>> sim.set_velocities([0], [[1.0, 0.0]]).run(until=4.5).velocities.tolist()
            [[0.0, 0.0], [1.0, 0.0]]
        """
        self._check_editable("set velocities")
        idx = self._disc_indices(indices)
        self._change(idx, None, self._rows("velocities", velocities, idx))
        return self

    def apply_impulse(self, indices, impulses):
        """Push discs ``indices`` with ``impulses`` ``(K, 2)`` (momentum, or one ``(2,)`` for all): ``dv = J / m``.

        Returns ``self``. Raises as :meth:`set_velocities` (obstacles refuse to be pushed).

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], 1.0, masses=2.0), ds.Box(10, 10))
            >>> sim.apply_impulse([0], [0.0, 4.0]).velocities.tolist()
            [[1.0, 2.0]]
        """
        self._check_editable("apply impulses")
        idx = self._disc_indices(indices)
        impulses = self._rows("impulses", impulses, idx)
        self._refuse_obstacles(idx)
        velocities = self.velocities[idx] + impulses / self.discs.masses[idx][:, None]
        self._change(idx, None, velocities)
        return self

    def set_positions(self, indices, positions):
        """Move discs ``indices`` to ``positions`` ``(K, 2)`` at ``time``, keeping their velocities.

        Validated as the constructor validates: each disc must lie in the box (in ``[0, width) x
        [0, height)`` when periodic), clear of the walls, the segments and every other disc (pairs that
        pass through each other excepted). Returns ``self``.

        Raises:
            OutsideBoxError, OverlapError: naming the disc (and the disc it would overlap).
            InvalidArgumentError: as :meth:`set_velocities`. Nothing changes then.
        """
        self._check_editable("set positions")
        idx = self._disc_indices(indices)
        self._change(idx, self._rows("positions", positions, idx), None)
        return self

    def add_discs(self, discs: Discs) -> np.ndarray:
        """Add ``discs`` (a :class:`~discsim.model.Discs` of ``K`` discs: positions in the box, velocities, radii,
        masses, groups, spins and inertia) at ``time``. Returns their indices ``N, ..., N + K - 1`` ``(K,)`` int64.

        Validated as the constructor validates the discs: each new disc must lie in the box (in ``[0, width)
        x [0, height)`` when periodic), clear of the walls, the segments, every disc already there and every
        other new one (pairs whose groups pass through each other excepted); NaN, non-positive radii or
        negative masses are refused by ``Discs`` itself. Each new disc gets the next disc id (:attr:`ids`)
        and an ``ADD`` record in the log (:meth:`~discsim.events.EventLog.add`), so :meth:`trajectory` and
        the log's readers know where it came from.

        The run goes on from a fresh start at ``time``: every disc is re-predicted (O(N), the cost of
        building the engine), so ``EventDriven`` then gives, event for event and bit for bit, what a new
        ``EventDriven(sim.snapshot(), box)`` would give from the same discs (its times shifted by ``time``).
        Add many discs in one call rather than one by one.

        Raises:
            WrongTypeError: ``discs`` is not a ``Discs``.
            OutsideBoxError: a new disc is outside the box or cut by a wall or segment, named by the index it
                would get. Nothing changes then, for this error and every one below.
            OverlapError: a new disc would overlap a disc (named, with the other disc and the depth).
            UnitsError: a radius or speed outside what discsim resolves.
            BoxTooSmallError: the larger discs no longer fit a periodic box's cell grid (3 cells of the
                largest diameter a side).
            InvalidArgumentError: the larger discs no longer fit the engine's ``cell_size``.

        Example:
            >>> import discsim as ds
            >>> sim = ds.EventDriven(ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], 1.0), ds.Box(10, 10)).run(until=1.0)
            >>> sim.add_discs(ds.Discs([[8.0, 5.0]], [[-1.0, 0.0]], 1.0)).tolist()
            [1]
            >>> sim.run(until=3.0).counts["collisions"], sim.velocities.tolist()
            (1, [[-1.0, 0.0], [1.0, 0.0]])
        """
        self._check_editable("add discs")
        self._check_usable()
        if not isinstance(discs, Discs):
            msg = f"add_discs needs a discsim.Discs, got {type(discs).__name__} {str(discs)[:60]}"
            raise WrongTypeError(msg)
        n, k = len(self.discs), len(discs)
        if k == 0:
            return np.zeros(0, dtype=np.int64)
        speed = np.hypot(discs.velocities[:, 0], discs.velocities[:, 1])
        lo, hi = SPEED_RANGE
        bad = (speed > hi) | ((speed < lo) & (speed != 0.0))
        if bad.any():
            b = int(np.flatnonzero(bad)[0])
            msg = (
                f"new disc {n + b} would have speed {float(speed[b])!r}, outside the range discsim supports "
                f"([{lo:g}, {hi:g}] or 0; discsim.model.SPEED_RANGE)"
            )
            raise UnitsError(msg)
        now = self.snapshot()
        everyone = Discs(*(np.concatenate([getattr(now, name), getattr(discs, name)]) for name in _DISC_FIELDS))
        scene = self.scene
        check_added(everyone, self.box, n, [s.at(self.time) for s in scene.segments], scene.pass_through)
        new_scene = scene.but(everyone)
        context = self.run_context
        ids = np.arange(context.next_id, context.next_id + k, dtype=np.int64)
        ids_after, origin = np.concatenate([self.ids, ids]), self._log_origin()
        resting = _resting_ids(self)
        self._restructure(np.arange(n), discs, new_scene)
        self._new_discs(new_scene, ids_after, context.next_id + k, origin)
        if self._logging or context.streamed:
            context.log.add(self.time, ids, discs.positions, discs.velocities, discs.radii, discs.masses, discs.groups)
        _log_woken(self, resting)
        self._gave(discs.masses, discs.velocities)
        self._edits += k
        return np.arange(n, n + k, dtype=np.int64)

    def remove_discs(self, indices):
        """Remove discs ``indices`` (a list of distinct indices, or one) at ``time``. Returns ``self``.

        The discs after them move down to fill the gaps, as ``np.delete`` does: with ``N`` discs,
        removing disc ``i`` makes disc ``k > i`` disc ``k - 1``. Indices always number the discs there
        now (``positions``, ``velocities``, ``discs``, ``step()``'s events, callbacks' contacts), while the
        log names every disc by its id, which never changes (:attr:`ids` gives the id of each disc now).
        Each removed disc gets a ``REMOVE`` record (:meth:`~discsim.events.EventLog.remove`); its column of
        :meth:`trajectory` is NaN from then on. The run goes on from a fresh start at ``time``, as after
        :meth:`add_discs`.

        Raises:
            InvalidArgumentError: an index that is not a disc, a repeated index, or one that is not an
                integer. Nothing changes then.

        Example:
            >>> import discsim as ds
            >>> discs = ds.Discs([[2.0, 5.0], [5.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [0.0, 0.0], [-1.0, 0.0]], 0.5)
            >>> sim = ds.EventDriven(discs, ds.Box(10, 10)).remove_discs([1])
            >>> sim.ids.tolist(), sim.run(until=2.9).counts["collisions"], sim.velocities.tolist()
            ([0, 2], 1, [[-1.0, 0.0], [1.0, 0.0]])
        """
        self._check_editable("remove discs")
        idx = self._disc_indices(indices)
        self._check_usable()
        if not len(idx):
            return self
        n = len(self.discs)
        keep = np.delete(np.arange(n), idx)
        now = self.snapshot()
        gone_positions, gone_velocities = now.positions[np.sort(idx)], now.velocities[np.sort(idx)]
        rest = Discs(*(getattr(now, name)[keep] for name in _DISC_FIELDS))
        scene = self.scene
        new_scene = scene.but(rest)
        gone, ids_after, origin = self.ids[np.sort(idx)], self.ids[keep], self._log_origin()
        resting = _resting_ids(self)
        self._restructure(keep, None, new_scene)
        self._new_discs(new_scene, ids_after, self.run_context.next_id, origin)
        if self._logging or self.run_context.streamed:
            self.run_context.log.remove(self.time, gone, gone_positions, gone_velocities)
        _log_woken(self, resting)
        self._edits += len(idx)
        return self

    def _new_discs(self, scene: Scene, ids: np.ndarray, next_id: int, origin: tuple) -> None:
        """After :meth:`_restructure`: the new scene and ids (the log's rows so far renamed by the old ones), and
        ``origin``, the discs where the log starts (:meth:`_log_origin` before the change)."""
        context = self.run_context
        context.log.flush()
        self.scene, self.discs = scene, scene.discs
        context.set_ids(ids, next_id, origin)
        context.structure += 1

    @property
    def ids(self) -> np.ndarray:
        """``(N,)`` int64, read-only: the id of each disc, the name the event log and :meth:`trajectory` give it.

        A disc's id is its index until some disc is removed (:meth:`remove_discs`): indices then shift down
        while ids never change; a disc added later gets the next id never used.
        """
        ids = self.run_context.ids
        return readonly_ids(np.arange(len(self.discs), dtype=np.int64)) if ids is None else ids

    @property
    def _origin(self) -> tuple[Discs, np.ndarray | None] | None:
        """``run_context.origin`` (read-only here)."""
        return self.run_context.origin

    @property
    def _next_id(self) -> int:
        """``run_context.next_id`` (read-only here)."""
        return self.run_context.next_id

    def on(self, kind: str, fn, *, changes: bool = True):
        """Call ``fn(sim, contact)`` after each event of ``kind`` (``"collision"``, ``"wall"``, ``"segment"``, or a
        sensor's ``"enter"`` and ``"leave"``).

        ``contact`` is a :class:`~discsim.analysis.contacts.Contact` (time, kind, discs, contact point,
        unit normal, impulse, normal speed), or for a sensor a :class:`~discsim.events.Crossing` (time, kind,
        disc, sensor, the disc's centre and velocity). A pocket is a sensor whose callback removes the disc:
        ``sim.on("enter", lambda sim, c: sim.remove_discs([c.i]))``. Returns ``self``.

        - ``changes=True`` (the default): the callback may change the simulation (``set_velocities``,
          ``apply_impulse``, ``set_positions``, ``add_discs``, ``remove_discs``) and the run goes on exactly
          from there: ``run()`` advances one physical event (or frame) at a time, so each callback sees the
          state just after its event (about 0.1-0.2 ms per event on top of the loop: see the README).
        - ``changes=False``: the callback only looks (plays a sound, counts, draws). ``run()`` then goes on in
          chunks (``progress_chunk`` events or frames) and calls it for every event of a chunk after the chunk,
          in order, with that event's ``contact``, while ``sim`` is already at the chunk's end: a few
          microseconds per event. A callback given ``changes=False`` that changes the simulation anyway raises
          ``InvalidArgumentError`` (the change is kept, and it applies from the chunk's end, not its event).

        With callbacks of both kinds, the run stops after each event and calls them in the order given.

        Raises:
            InvalidArgumentError: an unknown kind (naming it), a ``fn`` that is not callable, or ``changes`` that
                is not True or False.
        """
        self._check_editable("follow events with on()")
        if not isinstance(kind, str) or kind not in self.CALLBACK_KINDS:
            msg = f"on() follows one of {list(self.CALLBACK_KINDS)}, got {kind!r}"
            raise InvalidArgumentError(msg)
        if not callable(fn):
            msg = f"on({kind!r}, fn) needs a callable fn(sim, contact), got {type(fn).__name__}"
            raise InvalidArgumentError(msg)
        if not isinstance(changes, (bool, np.bool_)):
            msg = f"on({kind!r}, fn, changes=...) takes True or False, got {changes!r}"
            raise InvalidArgumentError(msg)
        if not changes:
            fn = LookOnly(fn)
        self.run_context.handlers.setdefault(kind, []).append(fn)
        return self

    def _disc_indices(self, indices) -> np.ndarray:
        """``indices`` as a ``(K,)`` int array of distinct existing discs."""
        n = len(self.discs)
        try:
            idx = np.atleast_1d(np.asarray(indices))
        except (TypeError, ValueError) as exc:
            msg = f"indices must be integers in [0, {n}), got {indices!r}"
            raise InvalidArgumentError(msg) from exc
        if idx.ndim != 1 or (idx.size and not np.issubdtype(idx.dtype, np.integer)):
            msg = f"indices must be a list of integers in [0, {n}), got {indices!r}"
            raise InvalidArgumentError(msg)
        outside = [i for i in idx.tolist() if not 0 <= i < n]  # Python ints: 2**64 - 1 stays itself, not -1
        if outside:
            msg = f"disc index {outside[0]} does not exist (this simulation has discs 0 to {n - 1})"
            raise InvalidArgumentError(msg)
        idx = idx.astype(np.int64)
        unique, counts = np.unique(idx, return_counts=True)
        if (counts > 1).any():
            msg = f"disc index {int(unique[counts > 1][0])} is given twice"
            raise InvalidArgumentError(msg)
        return idx

    @staticmethod
    def _rows(name: str, values, idx: np.ndarray) -> np.ndarray:
        """``values`` as a finite ``(K, 2)`` float array (one ``(2,)`` row is repeated for every disc)."""
        rows = _real_array(name, values, InvalidArgumentError)  # no strings, booleans or complex numbers, as Discs
        if rows.shape == (2,):
            rows = np.tile(rows, (len(idx), 1))
        if rows.shape != (len(idx), 2):
            msg = f"{name} must have shape ({len(idx)}, 2) for {len(idx)} discs, got shape {rows.shape}"
            raise InvalidArgumentError(msg)
        bad = ~np.isfinite(rows).all(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            msg = f"disc {int(idx[k])} would get non-finite {name} {rows[k].tolist()}"
            raise InvalidArgumentError(msg)
        return rows

    def _refuse_obstacles(self, idx: np.ndarray) -> None:
        fixed = np.isinf(self.discs.masses[idx])
        if fixed.any():
            msg = f"disc {int(idx[fixed][0])} is an obstacle (infinite mass): it cannot be moved or pushed"
            raise InvalidArgumentError(msg)

    def _change(self, idx: np.ndarray, positions: np.ndarray | None, velocities: np.ndarray | None) -> None:
        """Check every change first, then make them all, log them, and count them."""
        self._check_usable()
        self._refuse_obstacles(idx)
        if velocities is None:
            velocities = self.velocities[idx]
        speed = np.hypot(velocities[:, 0], velocities[:, 1])
        lo, hi = SPEED_RANGE
        bad = (speed > hi) | ((speed < lo) & (speed != 0.0))
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            msg = (
                f"disc {int(idx[k])} would get speed {float(speed[k])!r}, outside the range discsim supports "
                f"([{lo:g}, {hi:g}] or 0; discsim.model.SPEED_RANGE)"
            )
            raise UnitsError(msg)
        if positions is not None:
            self._check_places(idx, positions)
        resting = _resting_ids(self)
        if len(idx):
            self._set_discs(idx, positions, velocities)
            self._gave(self.discs.masses[idx], np.asarray(velocities, dtype=float).reshape(-1, 2))
        self._edits += len(idx)
        if (self._logging or self.run_context.streamed) and len(idx):  # a streamed log takes it at the next run
            t, pos, vel, ids = self.time, self.positions[idx], self.velocities[idx], self.ids[idx]
            for k, i in enumerate(ids.tolist()):
                self.run_context.log.set(t, i, pos[k, 0], pos[k, 1], vel[k, 0], vel[k, 1])
        _log_woken(self, np.setdiff1d(resting, self.ids[idx]))

    def _check_places(self, idx: np.ndarray, positions: np.ndarray) -> None:
        """Refuse positions outside the box, cut by a wall or a segment, or overlapping another disc."""
        box, radii = self.box, self.discs.radii
        size = box.size
        for k, i in enumerate(idx.tolist()):
            p, r = positions[k], radii[i]
            if box.periodic:
                outside, what = bool(((p < 0) | (p >= size)).any()), "outside the periodic box [0, width) x [0, height)"
            else:
                slack = OVERLAP_TOLERANCE * r
                outside, what = (
                    bool(((p - r < -slack) | (p + r > size + slack)).any()),
                    "outside the box or cut by a wall",
                )
            if outside:
                msg = f"disc {i} at {p.tolist()} with radius {r:g} would be {what} (box {box.width:g} x {box.height:g})"
                raise OutsideBoxError(msg)
            for s, segment in enumerate(self.segments):
                segment = segment.at(self.time)  # (where a moving one is now)
                if float(segment.distance(p[None, :])[0]) < r * (1.0 - OVERLAP_TOLERANCE):
                    msg = f"disc {i} at {p.tolist()} with radius {r:g} would be cut by segment {s} {segment!r}"
                    raise OutsideBoxError(msg)
        places = np.array(self.positions)  # a writable copy
        places[idx] = positions
        n = len(radii)
        rank = np.full(n, n, dtype=np.int64)  # each moved disc's place in idx (n: not moved)
        rank[idx] = np.arange(len(idx))
        # The cell grid's candidate pairs that hold a moved disc, in pieces (O(N) work and memory, not O(K N)):
        # every overlapping one, as (mover, other), until a pathological crowd has given 2^20 of them.
        found: list[tuple[np.ndarray, ...]] = []
        kept = 0
        for i, j, d in neighbour_pair_chunks(places, 2.0 * float(radii.max()), box):
            keep = (rank[i] < n) | (rank[j] < n)
            if self.scene.filtering:
                keep &= ~self.scene.passes(i, j)
            i, j, d = i[keep], j[keep], d[keep]
            contact = radii[i] + radii[j]
            dist = np.hypot(d[:, 0], d[:, 1])
            bad = contact - dist > OVERLAP_TOLERANCE * contact
            i, j, contact, dist = i[bad], j[bad], contact[bad], dist[bad]
            for mover, other in ((i, j), (j, i)):
                moved = rank[mover] < n
                found.append((mover[moved], other[moved], contact[moved], dist[moved]))
                kept += int(moved.sum())
            if kept > 1 << 20:
                break
        if kept:
            mover, other, contact, dist = (np.concatenate(part) for part in zip(*found))
            # The first disc of idx that overlaps, and its deepest overlap (the lowest index among equals).
            first = int(np.lexsort((other, -(contact - dist) / contact, rank[mover]))[0])
            i, j, k = int(mover[first]), int(other[first]), int(rank[mover[first]])
            msg = (
                f"disc {i} at {positions[k].tolist()} would overlap disc {j} by {contact[first] - dist[first]:.6g} "
                f"(distance {dist[first]:.6g}, contact distance {contact[first]:.6g})"
            )
            raise OverlapError(msg)


class Uneditable:
    """For engines whose discs cannot be changed mid-run (a compression, an event chain): the edits, the
    callbacks and ``trajectory`` are refused before anything changes, naming the engine and, from
    ``EDIT_REFUSAL``, what to do instead. Put it before :class:`~discsim.engines.base.Engine` in the bases."""

    #: What a refusal suggests instead.
    EDIT_REFUSAL: ClassVar[str] = "start a new engine from sim.snapshot() instead"

    def _check_editable(self, what: str) -> None:
        self._refuse(what)

    def _set_discs(self, indices, positions, velocities) -> None:
        self._refuse("change discs")

    def _moved_segments(self, segments) -> None:
        self._refuse("change a segment's velocity")

    def _restructure(self, keep, added, scene) -> None:
        self._refuse("add or remove discs")

    def trajectory(self, times, *, unwrapped: bool = False) -> np.ndarray:
        """Refused: this engine keeps no log of paths."""
        self._refuse("give trajectories")

    def _refuse(self, what: str) -> NoReturn:
        msg = f"a {type(self).__name__} cannot {what}: {self.EDIT_REFUSAL}"
        raise DiscsimError(msg)


def _resting_ids(engine) -> np.ndarray:
    """The ids of ``engine``'s discs at rest now (under gravity; none for engines without rest)."""
    laws = getattr(engine, "laws", None)
    if laws is None or not laws.falls or not hasattr(engine, "resting"):
        return np.zeros(0, dtype=np.int64)
    return engine.ids[engine.resting]


def _log_woken(engine, resting: np.ndarray) -> None:
    """A ``SET`` record (where it is, velocity zero) for each disc of ``resting`` (ids, at rest before an edit of
    ``engine``) that the edit woke: it falls from here, which the log must say (its last record says it rests), so
    that ``trajectory()``, the viewer and replays follow its fall. The compiled loop logs the discs a hit wakes the
    same way."""
    if not len(resting) or not (engine._logging or engine.run_context.streamed):
        return
    ids = engine.ids
    woken = np.flatnonzero(np.isin(ids, resting) & ~engine.resting)
    t, pos = engine.time, engine.positions
    for k in woken.tolist():
        engine.run_context.log.set(t, int(ids[k]), pos[k, 0], pos[k, 1], 0.0, 0.0)
