"""The pure-Python backend of the event-driven engine."""

from discsim.engines.event_driven.python.backend import QUEUES, PythonBackend

__all__ = ["QUEUES", "PythonBackend"]
