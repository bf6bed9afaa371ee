"""Checks of arguments other than discs and boxes, shared by every engine and the driver.

Each raises a :class:`~discsim.errors.DiscsimError` naming the argument and the value, before anything changes.
"No limit" is spelled ``None`` everywhere in the public API; these checks turn a limit into a number once.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.errors import InvalidArgumentError, TimeError

__all__ = ["check_count", "check_until", "is_count", "positive_finite"]


def is_count(value) -> bool:
    """True for a whole number >= 0 (an int, or a float such as 5.0); False for bools, NaN and the rest.

    Example:
        >>> is_count(3), is_count(5.0), is_count(True), is_count(-1), is_count(1.5)
        (True, True, False, False, False)
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        return False
    return bool(math.isfinite(value) and value >= 0 and int(value) == value)  # a NumPy value compares to np.bool_


def check_count(name: str, value) -> int | None:
    """``value`` as an int >= 0, or None for no limit.

    Raises:
        InvalidArgumentError: if ``value`` is not None or a whole number >= 0.
    """
    if value is None:
        return None
    if not is_count(value):
        msg = f"{name} must be a non-negative integer, got {value!r}"
        raise InvalidArgumentError(msg)
    return int(value)


def positive_finite(name: str, value) -> float:
    """``value`` as a positive, finite float.

    Raises:
        InvalidArgumentError: naming ``name`` and the value otherwise.
    """
    msg = f"{name} must be a positive, finite number, got {value!r}"
    if isinstance(value, bool):
        raise InvalidArgumentError(msg)
    try:
        number = float(value)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(msg) from exc
    if not (math.isfinite(number) and number > 0.0):
        raise InvalidArgumentError(msg)
    return number


def check_until(until, now: float) -> float | None:
    """A run's stop time as a float (``inf`` allowed), or None for no time limit.

    Raises:
        TimeError: if ``until`` is not a number, is NaN, or lies before ``now``.
    """
    if until is None:
        return None
    if isinstance(until, (bool, str, bytes)):
        msg = f"until must be a number, got {until!r}"
        raise TimeError(msg)
    try:
        value = float(until)
    except (TypeError, ValueError) as exc:
        msg = f"until must be a number, got {until!r}"
        raise TimeError(msg) from exc
    if math.isnan(value):
        msg = "until must not be NaN"
        raise TimeError(msg)
    if value < now:
        msg = f"until={value!r} is before the current time {float(now)!r}"
        raise TimeError(msg)
    return value
