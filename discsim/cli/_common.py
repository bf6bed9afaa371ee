"""Helpers that several subcommands share: argument types and the output folder."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def positive_int(text: str) -> int:
    """An argument type: a positive integer written as one (``"12"``, ``"+12"``; not ``"1.5"`` nor ``"0"``).

    Example:
        >>> positive_int("12")
        12
    """
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1 or str(value) != text.strip().lstrip("+"):
        msg = f"expected a positive integer, got {text!r}"
        raise argparse.ArgumentTypeError(msg)
    return value


def positive_float(text: str) -> float:
    """An argument type: a positive finite number (not ``"0"``, ``"nan"`` nor ``"inf"``).

    Example:
        >>> positive_float("0.5")
        0.5
    """
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        msg = f"expected a positive finite number, got {text!r}"
        raise argparse.ArgumentTypeError(msg)
    return value


def non_negative_int(text: str) -> int:
    """An argument type: an integer, 0 or more (a seed: ``"0"``, ``"12"``; not ``"-3"`` nor ``"1.5"``).

    Example:
        >>> non_negative_int("0")
        0
    """
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        msg = f"expected an integer, 0 or more, got {text!r}"
        raise argparse.ArgumentTypeError(msg)
    return value


def non_negative_float(text: str) -> float:
    """An argument type: a finite number, 0 or more (not ``"-1"``, ``"nan"`` nor ``"inf"``).

    Example:
        >>> non_negative_float("0")
        0.0
    """
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value >= 0 or value == float("inf"):
        msg = f"expected a finite number, 0 or more, got {text!r}"
        raise argparse.ArgumentTypeError(msg)
    return value


def make_output_folder(command: str, out: Path) -> bool:
    """Create the folder ``out`` (and its parents); on failure say why on stderr, naming ``command``, and return
    False."""
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        print(f"discsim {command}: cannot create the output folder {str(out)!r}: {exc}", file=sys.stderr)
        return False
    return True
