"""Tasks for the sweep tests: importable by name (``sweep_tasks:...``) in worker processes and the CLI."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np


def draw(a, b=1.0, *, seed, pause=0.0):
    """A deterministic function of its parameters and seed (a few draws of its own stream)."""
    if pause:
        time.sleep(pause)
    x = np.random.default_rng(seed).random(3)
    return {"sum": float(a * x.sum() + b), "first": float(x[0]), "label": f"a={a}", "big": bool(x[1] > 0.5)}


def fails_at(a, *, seed, bad=2):
    """Raises for ``a == bad``, on every attempt."""
    if a == bad:
        msg = f"no result at a={a}"
        raise ValueError(msg)
    return {"twice": 2 * a}


def flaky(a, *, seed, marks: str):
    """Fails the first attempt of each point (a file in ``marks`` remembers it across processes)."""
    mark = Path(marks) / f"{a}-{seed}"
    if not mark.exists():
        mark.write_text(str(os.getpid()))
        msg = f"first attempt at a={a}"
        raise RuntimeError(msg)
    return {"twice": 2 * a}


def logged(a, *, seed, log: str):
    """Appends a line to ``log`` each time it runs (to count the tasks that ran)."""
    with open(log, "a") as f:
        f.write(f"{a} {seed}\n")
    return {"a2": a * a}


def interrupts(a, *, seed):
    """Ctrl-C at a == 3 (in this process: a sweep with workers=0)."""
    if a == 3:
        raise KeyboardInterrupt
    return {"a2": a * a}


def dies(a, *, seed):
    """Kills its own worker process at a == 1."""
    if a == 1:
        os._exit(3)
    return {"a2": a * a}


def not_a_dict(a, *, seed):
    return [a]


def dies_beside_others(a, *, seed, pause=0.3):
    """Kills its own worker at a == 1, after ``pause`` seconds (while the other workers run tasks of their own)."""
    time.sleep(pause)
    if a == 1:
        os._exit(3)
    return {"a2": a * a}


def hangs(a, *, seed, pids: str, hang=60.0):
    """Writes its worker's pid into the folder ``pids`` (file ``a``), then hangs ``hang`` seconds at ``a >= 1``."""
    (Path(pids) / f"{a}").write_text(str(os.getpid()))
    if a >= 1:
        time.sleep(hang)
    return {"a2": a * a}
