"""Parameter sweeps: one task over a grid of parameters and seeds, on a local process pool or a dask cluster.

:func:`sweep` runs ``task(**point, seed=s)`` for every point of a grid and every seed, and gathers the
results in a tidy table (a pandas DataFrame). It brings no scheduler of its own: the tasks go to a
:class:`concurrent.futures.ProcessPoolExecutor` on this machine, or to whatever cluster a
``dask.distributed.Client`` reaches, and the loop here only submits, waits, retries, caches and counts.

- **Seeds.** ``seeds=k`` gives the task the seeds of ``numpy.random.SeedSequence(root_seed).spawn(k)``
  (each child's first 63 bits): the ``j``-th seed is the same at every point and for any ``k > j``, so adding
  points or seeds never changes the seeds, or the results, of the tasks already there.
- **Cache.** With ``cache=FOLDER`` each finished task's result is stored under the hash of the task's name,
  its parameters, its seed and discsim's version (:mod:`discsim.run.cache`), as soon as it finishes; a
  sweep that was killed, or whose cluster was lost, resumes by running only the tasks whose results are
  missing.
- **Failures.** A task that raises is run again, up to ``retries`` more times; if it still fails, the sweep
  finishes the others, and the table keeps its row with the error (``error`` column) while
  ``table.attrs["failures"]`` holds its parameters, seed, error, traceback and attempts. A local worker
  that dies (``os._exit``, a crash, a kill) counts a failed attempt (``WorkerDied``, naming the parameters)
  of the task it was running, and of no other: the pool is started again and the other tasks it held are
  sent again. On dask, the cluster decides (it retries tasks whose worker it lost, then reports them).
- **Stopping.** Ctrl-C stops the local pool's workers (a hung task included) and raises
  :class:`~discsim.errors.Interrupted` at once; the workers ignore Ctrl-C themselves (no tracebacks of
  theirs). A worker whose sweep is killed (kill -9) exits too, instead of waiting for tasks forever.
- **Determinism.** The table does not depend on where, in which order or how many at a time the tasks ran:
  rows are in grid order (the last parameter varying fastest), then seed order, and wall-clock figures are
  kept out of it (they are in ``table.attrs["sweep"]``).
"""

from __future__ import annotations

import functools
import inspect
import itertools
import json
import os
import pickle
import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from discsim._validate import is_count
from discsim.errors import InvalidArgumentError, WrongTypeError
from discsim.run.executors import ERROR_COLUMN, SEED_COLUMN, LocalPool, json_scalar, make_executor, outcome_of

if TYPE_CHECKING:
    from types import ModuleType

    from pandas import DataFrame

    from discsim.run.cache import SweepCache
    from discsim.run.executors import Executor

__all__ = ["ERROR_COLUMN", "SEED_COLUMN", "grid_points", "seed_streams", "sweep", "task_name"]


@dataclass
class _Job:
    """One task of the sweep: a grid point and a seed, and what became of it."""

    row: int
    params: dict
    seed: int
    result: dict | None = None
    cached: bool = False
    attempts: int = 0
    error: str | None = None
    traceback: str | None = None
    seconds: float = 0.0


# --- what the user gave ----------------------------------------------------------------------------------


def task_name(task) -> str:
    """The name a task's results are stored under: ``module:qualname`` (a partial adds its arguments).

    Example:
        >>> from discsim import tasks
        >>> task_name(tasks.equation_of_state)
        'discsim.run.tasks:equation_of_state'
    """
    if isinstance(task, functools.partial):
        bound = {"args": [repr(a) for a in task.args], "keywords": task.keywords}
        return f"{task_name(task.func)}{json.dumps(bound, sort_keys=True, default=repr)}"
    module = getattr(task, "__module__", None) or "?"
    qualname = getattr(task, "__qualname__", None) or getattr(task, "__name__", None) or type(task).__qualname__
    return f"{module}:{qualname}"


def grid_points(grid) -> list[dict]:
    """The points of a grid: a dict of lists (every combination) or a list of dicts (those points).

    In a dict, a single value (a number, string, bool or None) stands for a list of one. The last
    parameter varies fastest.

    Example:
        >>> grid_points({"eta": [0.1, 0.2], "n": 100, "policy": ["a", "b"]})[:2]
        [{'eta': 0.1, 'n': 100, 'policy': 'a'}, {'eta': 0.1, 'n': 100, 'policy': 'b'}]
    """
    if isinstance(grid, Mapping):
        if not grid:
            msg = "the grid is empty: give a dict of lists, e.g. {'packing_fraction': [0.1, 0.2]}, or a list of dicts"
            raise InvalidArgumentError(msg)
        axes = {}
        for name, values in grid.items():
            _check_name(name)
            if values is None or isinstance(values, (str, bytes, int, float, bool, np.generic)):
                values = [values]
            elif isinstance(values, np.ndarray):
                values = values.reshape(-1).tolist()
            elif isinstance(values, (Sequence, range)):
                values = list(values)
            else:
                msg = f"grid[{name!r}] must be a list of values or a single value, got {values!r}"
                raise InvalidArgumentError(msg)
            if not values:
                msg = f"grid[{name!r}] is empty: give it at least one value"
                raise InvalidArgumentError(msg)
            axes[name] = [_check_value(name, v) for v in values]
        points = [dict(zip(axes, combo)) for combo in itertools.product(*axes.values())]
    elif isinstance(grid, Sequence) and not isinstance(grid, (str, bytes)):
        if not grid:
            msg = "the grid is empty: give at least one point"
            raise InvalidArgumentError(msg)
        points = []
        for k, point in enumerate(grid):
            if not isinstance(point, Mapping):
                msg = f"grid point {k} must be a dict of parameter values, got {point!r}"
                raise InvalidArgumentError(msg)
            if k and set(point) != set(points[0]):
                msg = (
                    f"grid point {k} has the parameters {sorted(point)}, point 0 has {sorted(points[0])}: "
                    f"give every point the same"
                )
                raise InvalidArgumentError(msg)
            for name in point:
                _check_name(name)
            order = list(points[0]) if points else list(point)
            points.append({name: _check_value(name, point[name]) for name in order})
    else:
        msg = f"grid must be a dict of lists or a list of dicts, got {type(grid).__name__}"
        raise WrongTypeError(msg)
    seen: dict[str, int] = {}  # each point as JSON -> its index
    for k, point in enumerate(points):
        key = json.dumps(point, sort_keys=True)
        if key in seen:
            msg = f"grid point {k} ({point}) repeats point {seen[key]}: every point must differ"
            raise InvalidArgumentError(msg)
        seen[key] = k
    return points


def _check_name(name) -> None:
    if not isinstance(name, str) or not name.isidentifier():
        msg = f"grid parameter names must be identifiers (the task's keyword arguments), got {name!r}"
        raise InvalidArgumentError(msg)
    if name in (SEED_COLUMN, ERROR_COLUMN):
        msg = f"grid parameter {name!r} is reserved: seeds come from seeds= (and root_seed=), not the grid"
        raise InvalidArgumentError(msg)


def _check_value(name: str, value):
    try:
        return json_scalar(value)
    except TypeError:
        msg = f"grid[{name!r}] holds {value!r}: parameter values must be numbers, strings, bools or None"
        raise InvalidArgumentError(msg) from None


def seed_streams(seeds, root_seed: int = 0) -> list[int]:
    """The seeds a sweep gives its tasks.

    Args:
        seeds: a count ``k`` (the first 63 bits of each child of
            ``numpy.random.SeedSequence(root_seed).spawn(k)``), or the seeds themselves (distinct ints >= 0).
        root_seed: the root of the spawned seeds (an int >= 0).

    Example:
        >>> seed_streams(3)[:2] == seed_streams(2)  # more seeds keep the first ones
        True
        >>> seed_streams([5, 7])
        [5, 7]
    """
    if not is_count(root_seed) or root_seed < 0:
        msg = f"root_seed must be an integer >= 0, got {root_seed!r}"
        raise InvalidArgumentError(msg)
    if is_count(seeds) and not isinstance(seeds, bool):
        if seeds < 1:
            msg = f"seeds must be at least 1 (seeds per grid point), got {seeds!r}"
            raise InvalidArgumentError(msg)
        children = np.random.SeedSequence(int(root_seed)).spawn(int(seeds))
        return [int(c.generate_state(1, np.uint64)[0] >> np.uint64(1)) for c in children]
    if isinstance(seeds, (Sequence, np.ndarray)) and not isinstance(seeds, (str, bytes)):
        values = list(seeds)
        if not values or not all(is_count(s) and not isinstance(s, bool) and s >= 0 for s in values):
            msg = f"seeds must be a count >= 1 or a non-empty list of integers >= 0, got {seeds!r}"
            raise InvalidArgumentError(msg)
        values = [int(s) for s in values]
        if len(set(values)) != len(values):
            msg = f"seeds repeat a value: {seeds!r}"
            raise InvalidArgumentError(msg)
        return values
    msg = f"seeds must be a count >= 1 or a list of integers >= 0, got {seeds!r}"
    raise InvalidArgumentError(msg)


def _check_task(task, names: list[str], name: str) -> None:
    """The task takes every grid parameter and ``seed``, and needs nothing else."""
    if not callable(task):
        msg = f"task must be a function, got {task!r}"
        raise WrongTypeError(msg)
    try:
        signature = inspect.signature(task)
    except (TypeError, ValueError):
        return  # a builtin without a signature: it will say so itself
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    takes = {p for p, spec in signature.parameters.items() if spec.kind in kinds}
    open_kw = any(spec.kind is inspect.Parameter.VAR_KEYWORD for spec in signature.parameters.values())
    if not open_kw:
        unknown = [p for p in names if p not in takes]
        if unknown:
            msg = f"task {name} takes no parameter {unknown[0]!r} (it takes {sorted(takes)}): check the grid"
            raise InvalidArgumentError(msg)
        if SEED_COLUMN not in takes:
            msg = f"task {name} takes no seed= argument: a sweep gives every task its seed"
            raise InvalidArgumentError(msg)
    needed = [
        p
        for p, spec in signature.parameters.items()
        if spec.kind in kinds and spec.default is inspect.Parameter.empty and p not in names and p != SEED_COLUMN
    ]
    if needed:
        msg = f"task {name} needs the parameter {needed[0]!r}, which the grid does not give"
        raise InvalidArgumentError(msg)


# --- the sweep -------------------------------------------------------------------------------------------


def sweep(
    task,
    grid,
    *,
    seeds=1,
    root_seed: int = 0,
    client=None,
    workers: int | None = None,
    cache=None,
    retries: int = 0,
    progress: bool = False,
):
    """Run ``task(**point, seed=s)`` for every grid point and seed; gather the results in a table.

    Args:
        task: a function of the grid's parameters and ``seed`` (an int) returning a dict of results
            (numbers, strings, bools or None: the table's columns). It runs in another process: define it
            at module level (for the local pool it is pickled by name; dask also sends closures).
            Ready-made tasks are in :mod:`discsim.tasks`.
        grid: a dict of lists (every combination; a single value stands for a list of one) or a list of
            dicts (those points). Values are numbers, strings, bools or None.
        seeds: seeds per point (a count: independent streams spawned from ``root_seed``, see
            :func:`seed_streams`), or the list of seeds itself.
        root_seed: the root of the spawned seeds.
        client: None for a local process pool, or a ``dask.distributed.Client`` (a ``LocalCluster``, a
            dask-jobqueue cluster, a scheduler's address): the same sweep runs on its workers.
        workers: processes of the local pool (default: this machine's cores); 0 runs the tasks in this
            process, one after another (for debugging). Not with ``client``.
        cache: a folder for finished tasks' results (see :mod:`discsim.run.cache`): nothing finished is
            run twice, and a killed sweep resumes where it stopped. None: no cache. The key holds the
            task's name and discsim's version, not their code: after changing the task (or discsim
            without a new version), give the sweep a new folder, or its old results are served.
        retries: more attempts for a task that raised (or whose worker died while running it) before it
            counts as failed.
        progress: show a bar over the tasks (tqdm when installed).

    Returns:
        A ``pandas.DataFrame``, one row per point and seed (grid order, then seed order): the parameters,
        ``seed``, the task's results, and ``error`` (None, or the error of a task that failed every
        attempt). ``table.attrs["failures"]`` lists the failed tasks (``params``, ``seed``, ``error``,
        ``traceback``, ``attempts``); ``table.attrs["sweep"]`` counts the tasks (``tasks``, ``ran``,
        ``cached``, ``failed``, ``retries``) and gives the wall-clock ``seconds`` and where they ran;
        ``table.attrs["seconds"]`` holds each row's task time (of its last attempt; as stored for a row
        from the cache). Times stay out of the table, so that the table repeats bit for bit.
        A sweep with failures also warns (``RuntimeWarning``).

    Raises:
        InvalidArgumentError: before any task runs, for an empty grid, a parameter the task does not
            take (or one it needs that the grid lacks), bad seeds, retries or workers, a closed client,
            a cache folder that holds another task's results or files of its own, or one that cannot be
            created or written.
        WrongTypeError: if ``task`` is not callable, ``grid`` is neither a dict nor a list, or ``client``
            is not a dask client.
        Interrupted: on Ctrl-C, after the pool's workers are stopped (a hung task too); every finished
            result is in the cache.

    Example:
        >>> import discsim as ds
        >>> table = ds.sweep(ds.tasks.equation_of_state, {"packing_fraction": [0.1, 0.2], "n": 64,
        ...                  "equilibrate": 2, "measure": 4}, seeds=2, workers=0)
        >>> table.shape[0], list(table.columns[:3])
        (4, ['packing_fraction', 'n', 'equilibrate'])
        >>> bool((table.z > 1).all()), table.attrs["sweep"]["ran"]
        (True, 4)
    """
    pd = _pandas()
    name = task_name(task)
    points = grid_points(grid)
    _check_task(task, list(points[0]), name)
    seed_list = seed_streams(seeds, root_seed)
    if not is_count(retries) or isinstance(retries, bool) or retries < 0:
        msg = f"retries must be an integer >= 0 (more attempts for a task that failed), got {retries!r}"
        raise InvalidArgumentError(msg)
    executor = make_executor(client, workers)
    if isinstance(executor, LocalPool):
        try:
            pickle.dumps(task)
        except Exception as exc:
            msg = (
                f"task {name} cannot be sent to worker processes ({type(exc).__name__}: {exc}): define it at "
                f"module level, or run it in this process (workers=0), or on dask (which sends closures)"
            )
            raise InvalidArgumentError(msg) from None
    store = None
    if cache is not None:
        if not isinstance(cache, (str, os.PathLike)):
            msg = f"cache must be a folder (a path), got {cache!r}"
            raise WrongTypeError(msg)
        if "<lambda>" in name or "<locals>" in name:
            msg = f"a cached sweep needs a task with a stable name (defined at module level), not {name}"
            raise InvalidArgumentError(msg)
        from discsim import _version
        from discsim.run.cache import SweepCache

        store = SweepCache(cache, name, _version.__version__)
    jobs = [_Job(row, dict(point), seed) for row, (point, seed) in enumerate(itertools.product(points, seed_list))]
    return _run(pd, task, name, jobs, executor, store, int(retries), progress)


def _pandas():
    try:
        import pandas as pd
    except ImportError:
        msg = 'ds.sweep needs pandas for its table: pip install "discsim[sweep]"'
        raise InvalidArgumentError(msg) from None
    return pd


def _run(pd, task, name, jobs, executor, store, retries, progress):
    from discsim.errors import Interrupted
    from discsim.run.progress import progress_bar

    start = time.perf_counter()
    if store is not None:
        store.open()
        for job in jobs:
            entry = store.get(job.params, job.seed)
            if entry is not None:
                job.result, job.cached = entry["result"], True
                job.attempts = int(entry.get("attempts", 1))
                job.seconds = entry.get("seconds") or float("nan")
    todo = [job for job in jobs if not job.cached]
    resubmitted = 0
    bar = progress_bar(len(jobs), by_time=False, unit="tasks", rate=None) if progress else None
    meter = bar.__enter__() if bar is not None else None
    finished = len(jobs) - len(todo)
    if meter is not None and finished:
        meter.update(finished, finished)
    inflight = {}
    try:
        for job in todo:
            inflight[executor.submit(task, job.params, job.seed)] = job
        while inflight:
            future = executor.next_done()
            job = inflight.pop(future)
            outcome = outcome_of(future)
            job.attempts += 1
            if outcome[0] == "ok":
                job.result, job.seconds = outcome[1], outcome[2]
                job.error = job.traceback = None
                if store is not None:
                    store.put(job.params, job.seed, job.result, job.seconds, job.attempts)
            else:
                job.error, job.traceback, job.seconds = outcome[1], outcome[2], outcome[3]
                if job.attempts <= retries:
                    resubmitted += 1
                    inflight[executor.submit(task, job.params, job.seed)] = job
                    continue
            finished += 1
            if meter is not None:
                meter.update(1, finished)
    except KeyboardInterrupt:
        executor.close(cancel=True)
        if bar is not None:
            bar.__exit__(None, None, None)
        done = sum(1 for j in jobs if j.result is not None)
        where = f"; the {done} finished are in the cache {str(store.folder)!r}" if store is not None else ""
        msg = f"sweep interrupted with {len(jobs) - done} of {len(jobs)} tasks unfinished{where}"
        raise Interrupted(msg) from None
    except BaseException:
        executor.close(cancel=True)
        raise
    executor.close()
    if bar is not None:
        bar.__exit__(None, None, None)
    return _table(pd, name, jobs, executor, store, resubmitted, time.perf_counter() - start, retries)


def _table(
    pd: ModuleType,
    name: str,
    jobs: list[_Job],
    executor: Executor,
    store: SweepCache | None,
    resubmitted: int,
    seconds: float,
    retries: int,
) -> DataFrame:
    columns = [*jobs[0].params, SEED_COLUMN]
    results: dict[str, None] = {}  # the result keys of every job, in the order first seen
    for job in jobs:
        for key in job.result or ():
            results.setdefault(key, None)
    rows = []
    for job in jobs:
        row = {**job.params, SEED_COLUMN: job.seed}
        row.update({key: (job.result or {}).get(key, np.nan) for key in results})
        row[ERROR_COLUMN] = job.error if job.result is None else None
        rows.append(row)
    table = pd.DataFrame(rows, columns=[*columns, *results, ERROR_COLUMN])
    failed = [job for job in jobs if job.result is None]
    table.attrs["failures"] = [
        {
            "params": dict(job.params),
            "seed": job.seed,
            "error": job.error,
            "traceback": job.traceback,
            "attempts": job.attempts,
        }
        for job in failed
    ]
    table.attrs["seconds"] = [float(job.seconds) for job in jobs]
    table.attrs["sweep"] = {
        "task": name,
        "tasks": len(jobs),
        "ran": sum(1 for job in jobs if not job.cached),
        "cached": sum(1 for job in jobs if job.cached),
        "failed": len(failed),
        "retries": resubmitted,
        "seconds": seconds,
        "task_seconds": float(np.nansum([job.seconds for job in jobs if not job.cached] or [0.0])),
        "where": executor.label,
        "cache": str(store.folder) if store is not None else None,
    }
    if failed:
        first = failed[0]
        warnings.warn(
            f"sweep: {len(failed)} of {len(jobs)} tasks failed after {retries + 1} attempt(s) each (first: "
            f"{first.params}, seed={first.seed}: {first.error}); see the table's 'error' column and "
            f"table.attrs['failures'] for the tracebacks",
            RuntimeWarning,
            stacklevel=4,  # _table <- _run <- sweep <- the caller
        )
    return table
