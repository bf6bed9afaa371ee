"""``sim.on(kind, fn)``: callbacks after each collision, wall hit or segment hit, as an observer of the run.

While callbacks are registered, ``run()`` adds an :class:`EventHandlers` observer that asks the driver for
chunks of one unit of work (one physical event for ``EventDriven``, one frame for ``FixedStep``), so each
callback sees the engine just after its event and may change it (``set_velocities``, ``apply_impulse``,
``set_positions``, ``add_discs``, ``remove_discs``): the next chunk starts from the changed state, exactly.
Contact data come from :func:`discsim.analysis.contacts.contacts_of`, with each disc's velocity before the
chunk kept here (updated from the chunk's records, the user's changes included). Contacts name the discs by
their index now (the log names them by id), so a callback can pass ``contact.j`` to ``remove_discs``.
"""

from __future__ import annotations

import numpy as np

from discsim.analysis.contacts import contacts_of
from discsim.events import ADD, REMOVE
from discsim.run.observers import Observer

__all__ = ["EventHandlers"]


class EventHandlers(Observer):
    """Calls the engine's ``sim.on(...)`` callbacks, one chunk of one event (or frame) at a time."""

    wants_events = True

    def __init__(self, handlers: dict[str, list]):
        self.handlers = handlers

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
        return 1

    def update(self, engine, events, done, finishing) -> None:
        if not len(events):
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
        pair = events["j"] >= 0
        events["j"][pair] = index[events["j"][pair]]
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
            for fn in self.handlers.get(str(found.kind[k]), ()):
                fn(engine, found[k])
        if engine.run_context.structure != self._structure:  # a callback added or removed discs
            self._look(engine)
