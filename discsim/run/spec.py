"""A sweep described in a TOML file, for ``discsim sweep SPEC.toml``.

::

    # eos.toml: the equation of state over packing fractions, four seeds each
    task = "equation_of_state"      # a ready-made task (discsim.tasks), or "package.module:function"
    seeds = 4                       # seeds per point, or the list of seeds: [1, 2, 3]
    root_seed = 0                   # optional (default 0): the root the seeds are spawned from
    retries = 1                     # optional (default 0)

    [grid]                          # every combination; a single value is a list of one
    packing_fraction = [0.1, 0.2, 0.3, 0.4]
    n = 1000

A list of points is written ``[[grid]]`` tables instead, one per point.
"""

from __future__ import annotations

import importlib
import sys
from dataclasses import dataclass
from pathlib import Path

from discsim.errors import InvalidArgumentError

__all__ = ["SweepSpec", "read_spec", "resolve_task"]

#: The keys a spec may hold.
KEYS = ("task", "grid", "seeds", "root_seed", "retries")


@dataclass(frozen=True)
class SweepSpec:
    """What ``discsim sweep`` runs: ``ds.sweep(task, grid, seeds=, root_seed=, retries=)``.

    Attributes:
        task: the function. task_text: how the spec named it. grid: a dict of lists or a list of dicts.
        seeds: a count or a list. root_seed, retries: ints.
    """

    task: object
    task_text: str
    grid: object
    seeds: object = 1
    root_seed: int = 0
    retries: int = 0


def resolve_task(text: str):
    """The task a spec names: a ready-made one (``"equation_of_state"``) or ``"package.module:function"``.

    Example:
        >>> resolve_task("pit_accuracy").__name__
        'pit_accuracy'
    """
    from discsim.run import tasks

    if not isinstance(text, str) or not text:
        msg = f"task must name a function, got {text!r}"
        raise InvalidArgumentError(msg)
    if ":" not in text:
        if text in tasks.__all__:
            return getattr(tasks, text)
        msg = f"task {text!r} is not a ready-made task ({', '.join(tasks.__all__)}); name yours 'module:function'"
        raise InvalidArgumentError(msg)
    module_name, _, qualname = text.partition(":")
    try:
        target = importlib.import_module(module_name)
    except ImportError as exc:
        msg = f"task {text!r}: cannot import {module_name!r} ({exc})"
        raise InvalidArgumentError(msg) from exc
    for part in qualname.split("."):
        if not hasattr(target, part):
            msg = f"task {text!r}: {module_name!r} has no {qualname!r}"
            raise InvalidArgumentError(msg)
        target = getattr(target, part)
    if not callable(target):
        msg = f"task {text!r} is not a function"
        raise InvalidArgumentError(msg)
    return target


def read_spec(path) -> SweepSpec:
    """Read and check a sweep's TOML spec (the task is imported, the grid is checked by :func:`discsim.sweep`).

    Raises:
        InvalidArgumentError: naming the file and the key, for a file that cannot be read or parsed, an
            unknown key, or a missing task or grid.
    """
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # Python 3.10
        import tomli as tomllib
    path = Path(path)
    try:
        spec = tomllib.loads(path.read_text())
    except (OSError, UnicodeDecodeError) as exc:
        msg = f"cannot read the sweep spec {str(path)!r}: {exc}"
        raise InvalidArgumentError(msg) from exc
    except tomllib.TOMLDecodeError as exc:
        msg = f"the sweep spec {str(path)!r} is not valid TOML: {exc}"
        raise InvalidArgumentError(msg) from exc
    unknown = sorted(set(spec) - set(KEYS))
    if unknown:
        msg = f"the sweep spec {str(path)!r} has unknown key(s) {unknown}; it may hold {list(KEYS)}"
        raise InvalidArgumentError(msg)
    for key in ("task", "grid"):
        if key not in spec:
            msg = f"the sweep spec {str(path)!r} has no {key!r}"
            raise InvalidArgumentError(msg)
    return SweepSpec(
        task=resolve_task(spec["task"]),
        task_text=spec["task"],
        grid=spec["grid"],
        seeds=spec.get("seeds", 1),
        root_seed=spec.get("root_seed", 0),
        retries=spec.get("retries", 0),
    )
