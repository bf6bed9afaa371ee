"""The compiled backend of the event-driven engine (numba, from the ``fast`` extra)."""

from discsim.engines.event_driven.numba.backend import NumbaBackend

__all__ = ["NumbaBackend"]
