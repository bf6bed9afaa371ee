"""discsim: exact, fast event-driven simulation of elastic hard discs in 2D.

The public API::

    import discsim as ds
    discs, box = ds.random_gas(1000, 0.3, seed=0)
    sim = ds.EventDriven(discs, box).run(until=10.0)      # PIC: exact collision times
    sim.counts, sim.kinetic_energy(), sim.pressure()

    case = ds.scenarios.wrong_direction()                 # the study's PIT failures
    pit = ds.FixedStep(case.discs, case.box, frame_rate=case.frame_rate).run(until=case.until)
    pic = ds.EventDriven(case.discs, case.box).run(until=case.until)
    print(ds.compare(pic, pit))                           # PIT against the truth
"""

from discsim import scenarios
from discsim.checkpoint import checkpoint_info, load, resume
from discsim.compare import Comparison, compare
from discsim.engine import Event
from discsim.errors import (
    BoxTooSmallError,
    CheckpointError,
    DiscsimError,
    InvalidArgumentError,
    InvalidDiscsError,
    OutsideBoxError,
    OverlapError,
    PackingError,
    TimeError,
)
from discsim.event_driven import EventDriven
from discsim.eventlog import StreamedEvents, read_events, trajectory_from_events
from discsim.fixed_step import FixedStep
from discsim.observables import compressibility_factor, enskog_collision_rate, henderson_z, speed_cdf, speed_pdf
from discsim.scenarios import Scenario, billiard_break, head_on, newtons_cradle, random_gas, study_cases
from discsim.state import Box, Discs, Segment, polygon

__version__ = "0.1.0"

__all__ = [
    "Box",
    "BoxTooSmallError",
    "CheckpointError",
    "Comparison",
    "Discs",
    "DiscsimError",
    "Event",
    "EventDriven",
    "FixedStep",
    "InvalidArgumentError",
    "InvalidDiscsError",
    "OutsideBoxError",
    "OverlapError",
    "PackingError",
    "Scenario",
    "Segment",
    "StreamedEvents",
    "TimeError",
    "billiard_break",
    "checkpoint_info",
    "compare",
    "compressibility_factor",
    "enskog_collision_rate",
    "head_on",
    "henderson_z",
    "load",
    "newtons_cradle",
    "polygon",
    "random_gas",
    "read_events",
    "resume",
    "scenarios",
    "speed_cdf",
    "speed_pdf",
    "study_cases",
    "trajectory_from_events",
]
