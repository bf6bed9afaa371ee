"""The event-driven engine (PIC): the front class, its public state and its backends."""

from discsim.engines.event_driven.engine import EventDriven

__all__ = ["EventDriven"]
