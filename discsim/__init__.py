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
from discsim._version import __version__ as __version__
from discsim.analysis.compare import Comparison, compare
from discsim.analysis.contacts import Contact, Contacts, contacts
from discsim.analysis.dynamics import free_times, msd, vacf
from discsim.analysis.frames import Frames, frames
from discsim.analysis.structure import psi6, rdf
from discsim.analysis.theory import (
    enskog_collision_rate,
    enskog_diffusion,
    henderson_z,
    speed_cdf,
    speed_pdf,
    virial_z,
)
from discsim.analysis.thermo import compressibility_factor, thermo
from discsim.engines.compress import Compression, CompressionReport, compress
from discsim.engines.event_chain import EventChain
from discsim.engines.event_driven import EventDriven, EventDrivenState
from discsim.engines.fixed_step import POLICIES, FixedStep, FixedStepState
from discsim.errors import (
    BoxTooSmallError,
    CacheWarning,
    CheckpointError,
    DiscsimError,
    EquilibrationWarning,
    Interrupted,
    InvalidArgumentError,
    InvalidDiscsError,
    JammedError,
    OutsideBoxError,
    OverlapError,
    PackingError,
    TimeError,
    UnitsError,
    WrongTypeError,
)
from discsim.events import EVENT_DTYPE, Event, EventKind
from discsim.io.checkpoints import checkpoint_info, load, resume
from discsim.io.gsd import read_gsd, write_gsd
from discsim.io.streams import StreamedEvents, iter_events, read_events, trajectory_from_events
from discsim.io.xyz import read_xyz, write_xyz
from discsim.model import Box, Discs, Segment, polygon
from discsim.piston import Piston
from discsim.run import driver as _driver  # noqa: F401 (it provides Engine.run: discsim.engines.base.provide)
from discsim.run import tasks
from discsim.run.observers import Callback, Checkpointer, EventStream, Observer, ProgressBar
from discsim.run.samplers import GSDWriter, Sampler
from discsim.run.sweep import sweep
from discsim.scenarios import Scenario, billiard_break, head_on, newtons_cradle, random_gas, study_cases
from discsim.sensors import Sensor
from discsim.spatial import RayHit
from discsim.view import View, view  # cheap (no matplotlib); binds ds.view to the function, not the module


def __getattr__(name: str):
    """``ds.plot``: the plotting module, imported (with matplotlib) on first use."""
    if name == "plot":
        import importlib

        return importlib.import_module("discsim.plot")
    msg = f"module 'discsim' has no attribute {name!r}"
    raise AttributeError(msg)


__all__ = [
    "EVENT_DTYPE",
    "POLICIES",
    "Box",
    "BoxTooSmallError",
    "CacheWarning",
    "Callback",
    "CheckpointError",
    "Checkpointer",
    "Comparison",
    "Compression",
    "CompressionReport",
    "Contact",
    "Contacts",
    "Discs",
    "DiscsimError",
    "EquilibrationWarning",
    "Event",
    "EventChain",
    "EventDriven",
    "EventDrivenState",
    "EventKind",
    "EventStream",
    "FixedStep",
    "FixedStepState",
    "Frames",
    "GSDWriter",
    "Interrupted",
    "InvalidArgumentError",
    "InvalidDiscsError",
    "JammedError",
    "Observer",
    "OutsideBoxError",
    "OverlapError",
    "PackingError",
    "Piston",
    "ProgressBar",
    "RayHit",
    "Sampler",
    "Scenario",
    "Segment",
    "Sensor",
    "StreamedEvents",
    "TimeError",
    "UnitsError",
    "View",
    "WrongTypeError",
    "billiard_break",
    "checkpoint_info",
    "compare",
    "compress",
    "compressibility_factor",
    "contacts",
    "enskog_collision_rate",
    "enskog_diffusion",
    "frames",
    "free_times",
    "head_on",
    "henderson_z",
    "iter_events",
    "load",
    "msd",
    "newtons_cradle",
    "polygon",
    "psi6",
    "random_gas",
    "rdf",
    "read_events",
    "read_gsd",
    "read_xyz",
    "resume",
    "scenarios",
    "speed_cdf",
    "speed_pdf",
    "study_cases",
    "sweep",
    "tasks",
    "thermo",
    "trajectory_from_events",
    "vacf",
    "view",
    "virial_z",
    "write_gsd",
    "write_xyz",
]
