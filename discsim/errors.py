"""Exceptions raised by discsim.

Every error raised for bad user input is a :class:`DiscsimError`; most are also
:class:`ValueError` so that generic ``except ValueError`` handlers still work.
Each message names the offending disc (by index) and the offending value.
"""

from __future__ import annotations

__all__ = [
    "BoxTooSmallError",
    "CacheWarning",
    "CheckpointError",
    "DiscsimError",
    "EquilibrationWarning",
    "Interrupted",
    "InvalidArgumentError",
    "InvalidDiscsError",
    "JammedError",
    "OutsideBoxError",
    "OverlapError",
    "PackingError",
    "TimeError",
    "UnitsError",
    "WrongTypeError",
]


class DiscsimError(Exception):
    """Base class of every error discsim raises on purpose."""


class InvalidArgumentError(DiscsimError, ValueError):
    """An argument out of its range: a run limit, a step, an option's name, a scene parameter."""


class WrongTypeError(InvalidArgumentError, TypeError):
    """An argument of the wrong type (a tuple where a Segment belongs, a list where Discs do); also a TypeError."""


class InvalidDiscsError(DiscsimError, ValueError):
    """Wrong shape, non-finite value, bad radius or mass, or a moving obstacle."""


class OutsideBoxError(DiscsimError, ValueError):
    """A disc lies outside the box or is cut by a wall."""


class OverlapError(DiscsimError, ValueError):
    """Two discs overlap; the message names the pair and the depth."""


class BoxTooSmallError(DiscsimError, ValueError):
    """The box cannot hold the cell grid the engine needs (3 cells a side when periodic)."""


class PackingError(DiscsimError, ValueError):
    """A requested packing fraction cannot be reached."""


class TimeError(DiscsimError, ValueError):
    """A time that lies in the simulated past, or is not finite."""


class JammedError(DiscsimError, RuntimeError):
    """Discs wedged against each other (or a wall) collide for ever without the clock moving.

    Raised by a run after many events in a row at one instant, or while the clock creeps towards an instant it
    never reaches (an unbounded cascade: see ``EventDriven.jam_events`` and ``EventDriven.jam_time``); the message
    names the jammed discs and the time. The engine is consistent at its last whole event.
    """


class UnitsError(DiscsimError, ValueError):
    """A length or speed outside the range the exact time of impact supports (see ``discsim.model.SCALE_RANGE``)."""


class CheckpointError(DiscsimError, ValueError):
    """A checkpoint or event-log file that is damaged, foreign or incompatible."""


class CacheWarning(UserWarning):
    """A sweep's cache entry that was damaged or changed: reported, not served, and computed again."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C stopped a run at the end of a whole event (or frame): the engine is consistent and can go on.

    A ``KeyboardInterrupt``, so ``except KeyboardInterrupt`` catches it, and ``except Exception`` does not.
    """


class EquilibrationWarning(UserWarning):
    """A time average over a series that is not at equilibrium: it still drifts, or is too short to tell
    (:func:`discsim.thermo`). A warning, not an error: the numbers are returned, with the reason."""
