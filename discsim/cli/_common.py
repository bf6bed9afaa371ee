"""Helpers that several subcommands share: argument types and the output folder."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def _argument(text: str, convert, accept, expected: str):
    """``convert(text)`` when ``accept(value, text)`` holds, else argparse's error naming ``expected``."""
    try:
        value = convert(text)
    except ValueError:
        value = None
    if value is None or not accept(value, text):
        msg = f"expected {expected}, got {text!r}"
        raise argparse.ArgumentTypeError(msg)
    return value


def positive_int(text: str) -> int:
    """An argument type: a positive integer written as one (``"12"``, ``"+12"``; not ``"1.5"`` nor ``"0"``).

    Example:
        >>> positive_int("12")
        12
    """
    return _argument(text, int, lambda v, t: v >= 1 and str(v) == t.strip().lstrip("+"), "a positive integer")


def positive_float(text: str) -> float:
    """An argument type: a positive finite number (not ``"0"``, ``"nan"`` nor ``"inf"``).

    Example:
        >>> positive_float("0.5")
        0.5
    """
    return _argument(text, float, lambda v, t: 0 < v < float("inf"), "a positive finite number")


def non_negative_int(text: str) -> int:
    """An argument type: an integer, 0 or more (a seed: ``"0"``, ``"12"``; not ``"-3"`` nor ``"1.5"``).

    Example:
        >>> non_negative_int("0")
        0
    """
    return _argument(text, int, lambda v, t: v >= 0, "an integer, 0 or more")


def non_negative_float(text: str) -> float:
    """An argument type: a finite number, 0 or more (not ``"-1"``, ``"nan"`` nor ``"inf"``).

    Example:
        >>> non_negative_float("0")
        0.0
    """
    return _argument(text, float, lambda v, t: 0 <= v < float("inf"), "a finite number, 0 or more")


def make_output_folder(command: str, out: Path) -> bool:
    """Create the folder ``out`` (and its parents); on failure say why on stderr, naming ``command``, and return
    False."""
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        print(f"discsim {command}: cannot create the output folder {str(out)!r}: {exc}", file=sys.stderr)
        return False
    return True
