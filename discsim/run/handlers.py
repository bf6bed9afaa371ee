"""``sim.on(kind, fn)``: callbacks after each collision, wall hit or segment hit, as an observer of the run.

While callbacks are registered, ``run()`` adds an :class:`EventHandlers` observer that asks the driver for
chunks of one unit of work (one physical event for ``EventDriven``, one frame for ``FixedStep``), so each
callback sees the engine just after its event and may change it (``set_velocities``, ``apply_impulse``,
``set_positions``): the next chunk starts from the changed state, exactly. Contact data come from
:func:`discsim.analysis.contacts.contacts_of`, with each disc's velocity before the chunk kept here (updated
from the chunk's records, the user's changes included).
"""

from __future__ import annotations

import numpy as np

from discsim.analysis.contacts import contacts_of
from discsim.run.observers import Observer

__all__ = ["EventHandlers"]


class EventHandlers(Observer):
    """Calls the engine's ``sim.on(...)`` callbacks, one chunk of one event (or frame) at a time."""

    wants_events = True

    def __init__(self, handlers: dict[str, list]):
        self.handlers = handlers

    def start(self, engine, plan) -> None:
        self._velocities = np.array(engine.velocities)  # each disc's velocity before the next chunk
        self._masses, self._radii = engine.discs.masses, engine.discs.radii

    def next_stop(self, engine) -> int:
        return 1

    def update(self, engine, events, done, finishing) -> None:
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
            for fn in self.handlers.get(str(found.kind[k]), ()):
                fn(engine, found[k])
