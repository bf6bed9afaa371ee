"""``sim.on(kind, fn)``: callbacks after each collision, wall hit, segment hit or sensor event, as an observer of
the run.

While callbacks are registered, ``run()`` adds an :class:`EventHandlers` observer that asks the driver for
chunks of one unit of work (one physical event for ``EventDriven``, one frame for ``FixedStep``), so each
callback sees the engine just after its event and may change it (``set_velocities``, ``apply_impulse``,
``set_positions``, ``add_discs``, ``remove_discs``): the next chunk starts from the changed state, exactly.
When every callback was given ``changes=False`` (:class:`~discsim.engines.context.LookOnly`), the chunks are
``engine.progress_chunk`` units long instead and the callbacks are called for each event of a chunk after it:
the contacts are built for the whole chunk at once, a few microseconds an event. Contact data come from
:func:`discsim.analysis.contacts.contacts_of`, with each disc's velocity before the
chunk kept here (updated from the chunk's records, the user's changes included). Contacts name the discs by
their index now (the log names them by id), so a callback can pass ``contact.j`` to ``remove_discs``.
"""

from __future__ import annotations

import numpy as np

from discsim.analysis.contacts import contact_of_record, contacts_of
from discsim.engines.context import LookOnly
from discsim.errors import InvalidArgumentError
from discsim.events import ADD, COLLISION, KIND_NAMES, REMOVE, SENSED, WALL, Crossing
from discsim.run.observers import Observer

__all__ = ["EventHandlers"]


class EventHandlers(Observer):
    """Calls the engine's ``sim.on(...)`` callbacks, one chunk of one event (or frame) at a time."""

    wants_events = True

    def __init__(self, handlers: dict[str, list]):
        self.handlers = handlers
        #: Whether some callback may change the simulation: then the run stops after every event.
        self.exact = any(not isinstance(fn, LookOnly) for fns in handlers.values() for fn in fns)

    def start(self, engine, plan) -> None:
        self._look(engine)

    def _look(self, engine) -> None:
        """Take each disc's velocity, mass and radius now, and the map from ids to indices."""
        self._velocities = np.array(engine.velocities)  # each disc's velocity before the next chunk
        self._masses, self._radii = engine.discs.masses, engine.discs.radii
        self._structure = engine.run_context.structure
        ids = engine.ids
        self._index = np.full(int(ids.max()) + 1 if len(ids) else 0, -1, dtype=np.int64)  # id -> index, -1: gone
        self._index[ids] = np.arange(len(ids))

    def next_stop(self, engine) -> int:
        return 1 if self.exact else engine.progress_chunk

    def update(self, engine, events, done, finishing) -> None:
        if not len(events):
            return
        if len(events) == 1 and int(events[0]["kind"]) in (COLLISION, WALL):  # one event, the common case
            self._one(engine, events[0])
            return
        # The user's additions and removals (made by the callbacks after the previous chunk) are already in
        # what _look took then; the rest is renamed from ids to today's indices.
        events = events[(events["kind"] != ADD) & (events["kind"] != REMOVE)]
        index = self._index
        events = events[events["i"] < len(index)]
        events = events[index[events["i"]] >= 0]
        if not len(events):
            return
        events = np.array(events)
        events["i"] = index[events["i"]]
        sensed = np.isin(events["kind"], SENSED)  # j: a sensor's index, not a disc
        if sensed.any():
            self._with_crossings(engine, events, sensed)
            return
        pair = events["j"] >= 0
        events["j"][pair] = index[events["j"][pair]]
        self._contacts(engine, events)

    def _with_crossings(self, engine, events, sensed) -> None:
        """A chunk with sensor events: the contacts between them, and each crossing in its turn."""
        cut = np.flatnonzero(sensed)
        start = 0
        for k in [*cut.tolist(), len(events)]:
            if k > start:
                piece = np.array(events[start:k])
                pair = piece["j"] >= 0
                piece["j"][pair] = self._index[piece["j"][pair]]
                self._contacts(engine, piece)
            if k < len(events):
                self._crossing(engine, events[k])
            start = k + 1

    def _crossing(self, engine, rec) -> None:
        """Call the callbacks of one sensor event (``rec["i"]`` already an index)."""
        kind = KIND_NAMES[int(rec["kind"])]
        fns = self.handlers.get(kind, ())
        if not fns:
            return
        crossing = Crossing(
            float(rec["time"]), kind, int(rec["i"]), int(rec["j"]),
            np.array([rec["xi"], rec["yi"]]), np.array([rec["vxi"], rec["vyi"]]),
        )  # fmt: skip
        for fn in fns:
            if isinstance(fn, LookOnly):
                self._look_only(engine, fn, kind, crossing)
            else:
                fn(engine, crossing)
        if engine.run_context.structure != self._structure:  # a callback added or removed discs
            self._look(engine)

    def _contacts(self, engine, events) -> None:
        """Call the callbacks of the collisions and wall hits of ``events`` (discs already indices)."""
        if not len(events):
            return
        found = contacts_of(events, self._velocities, self._masses, self._radii, engine.box, engine.segments)
        rows = np.concatenate([events["i"], events["j"][events["j"] >= 0]])
        after = np.concatenate(
            [
                np.column_stack([events["vxi"], events["vyi"]]),
                np.column_stack([events["vxj"], events["vyj"]])[events["j"] >= 0],
            ]
        ).reshape(-1, 2)
        order = np.concatenate([np.arange(len(events)), np.flatnonzero(events["j"] >= 0)])
        last = np.argsort(order, kind="stable")  # the later record of a disc wins
        self._velocities[rows[last]] = after[last]
        for k in range(len(found)):
            kind = str(found.kind[k])
            for fn in self.handlers.get(kind, ()):
                if isinstance(fn, LookOnly):
                    self._look_only(engine, fn, kind, found[k])
                else:
                    fn(engine, found[k])
        if engine.run_context.structure != self._structure:  # a callback added or removed discs
            self._look(engine)

    def _one(self, engine, rec) -> None:
        """The chunk of one collision or wall hit: its contact in plain floats (:func:`contact_of_record`)."""
        index = self._index
        a, b = int(rec["i"]), int(rec["j"])
        if a >= len(index) or index[a] < 0:
            return
        i, j = int(index[a]), (int(index[b]) if b >= 0 else -1)
        velocities = self._velocities
        contact = contact_of_record(
            rec, i, j, velocities[i], velocities[j] if j >= 0 else velocities[i], self._masses, self._radii,
            engine.box, engine.segments,
        )  # fmt: skip
        velocities[i] = (rec["vxi"], rec["vyi"])
        if j >= 0:
            velocities[j] = (rec["vxj"], rec["vyj"])
        for fn in self.handlers.get(contact.kind, ()):
            if isinstance(fn, LookOnly):
                self._look_only(engine, fn, contact.kind, contact)
            else:
                fn(engine, contact)
        if engine.run_context.structure != self._structure:  # a callback added or removed discs
            self._look(engine)

    def _look_only(self, engine, fn: LookOnly, kind: str, contact) -> None:
        """Call a ``changes=False`` callback; refuse it if it changed the simulation anyway."""
        before = (engine._edits, engine.run_context.structure)
        fn(engine, contact)
        if (engine._edits, engine.run_context.structure) != before:
            name = getattr(fn.fn, "__qualname__", repr(fn.fn))
            msg = (
                f"sim.on({kind!r}, {name}, changes=False) changed the simulation: a look-only callback runs after "
                "its chunk, so the change applies from the chunk's end, not from its event; register it with "
                "changes=True for an exact change"
            )
            raise InvalidArgumentError(msg)
