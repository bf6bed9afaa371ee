"""discsim: exact, fast event-driven simulation of elastic hard discs in 2D.

The public API::

    import discsim as ds
    discs, box = ds.random_gas(1000, 0.3, seed=0)
    sim = ds.EventDriven(discs, box).run(until=10.0)      # PIC: exact collision times
    sim.counts, sim.kinetic_energy(), sim.pressure()
"""

from discsim.engine import Event
from discsim.errors import (
    BoxTooSmallError,
    CheckpointError,
    DiscsimError,
    InvalidDiscsError,
    OutsideBoxError,
    OverlapError,
    PackingError,
    TimeError,
)
from discsim.event_driven import EventDriven
from discsim.observables import compressibility_factor, enskog_collision_rate, henderson_z
from discsim.scenarios import random_gas
from discsim.state import Box, Discs

__version__ = "0.1.0"

__all__ = [
    "Box",
    "BoxTooSmallError",
    "CheckpointError",
    "Discs",
    "DiscsimError",
    "Event",
    "EventDriven",
    "InvalidDiscsError",
    "OutsideBoxError",
    "OverlapError",
    "PackingError",
    "TimeError",
    "compressibility_factor",
    "enskog_collision_rate",
    "henderson_z",
    "random_gas",
]
