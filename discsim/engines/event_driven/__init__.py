"""The event-driven engine (PIC): the front class, its public state and its backends."""

from discsim.engines.event_driven.engine import BACKENDS, EventDriven
from discsim.engines.event_driven.state import EventDrivenState

__all__ = ["BACKENDS", "EventDriven", "EventDrivenState"]
