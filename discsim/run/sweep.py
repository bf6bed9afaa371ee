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
import sys
import time
import traceback
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from discsim._validate import is_count
from discsim.errors import InvalidArgumentError, WrongTypeError

if TYPE_CHECKING:
    from concurrent.futures import Future, ProcessPoolExecutor
    from types import ModuleType

    from pandas import DataFrame

    from discsim.run.cache import SweepCache

__all__ = ["ERROR_COLUMN", "SEED_COLUMN", "grid_points", "seed_streams", "sweep", "task_name"]

#: The column of the seed each task was given, after the grid's parameters.
SEED_COLUMN = "seed"
#: The last column: None where the task finished, else its error (``"ValueError: ..."``).
ERROR_COLUMN = "error"


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


def _plain(value):
    """A parameter or result value as a JSON scalar (bool, int, float, str or None), or raise TypeError."""
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    raise TypeError(type(value).__name__)


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
        return _plain(value)
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


# --- where the tasks run ---------------------------------------------------------------------------------


def attempt(task, params: dict, seed: int):
    """Run one task once (in a worker): ``("ok", result, seconds)`` or ``("error", text, traceback, seconds)``.

    The result must be a dict of scalars (numbers, strings, bools, None): the table's columns.
    """
    start = time.perf_counter()
    try:
        out = task(**params, seed=seed)
        if not isinstance(out, Mapping):
            msg = f"the task returned {type(out).__name__}, not a dict of results (the table's columns)"
            raise TypeError(msg)
        result = {}
        for key, value in out.items():
            if not isinstance(key, str) or key in params or key in (SEED_COLUMN, ERROR_COLUMN):
                msg = f"the task returned the result {key!r}, which is no name or clashes with a parameter or column"
                raise ValueError(msg)
            try:
                result[key] = _plain(value)
            except TypeError:
                msg = f"the task returned {key}={value!r}: results must be numbers, strings, bools or None"
                raise TypeError(msg) from None
    except Exception as exc:
        return ("error", f"{type(exc).__name__}: {exc}", traceback.format_exc(), time.perf_counter() - start)
    return ("ok", result, time.perf_counter() - start)


class _Deferred:
    """A task of ``workers=0``: it runs when the sweep waits for it."""

    def __init__(self, args):
        self.args = args
        self.outcome = None

    def result(self):
        if self.outcome is None:
            self.outcome = attempt(*self.args)
        return self.outcome


class _InProcess:
    """``workers=0``: the tasks run here, one after another (for debugging: breakpoints work)."""

    label = "this process"

    def __init__(self):
        self._pending = []

    def submit(self, *args):
        task = _Deferred(args)
        self._pending.append(task)
        return task

    def next_done(self):
        task = self._pending.pop(0)
        task.result()
        return task

    def close(self, cancel: bool = False) -> None:
        self._pending.clear()


class _Finished:
    """Futures as they finish, in O(1) each: every future puts itself in a queue when done.

    (Waiting on all unfinished futures after each completion would cost O(tasks) each time.)
    """

    label: str  # where the tasks run, for the table's attrs (set by each subclass)

    def __init__(self) -> None:
        import queue

        self._done: queue.SimpleQueue[Future] = queue.SimpleQueue()

    def track(self, future):
        future.add_done_callback(self._done.put)
        return future

    def next_done(self):
        import queue

        while True:  # a timeout, so that Ctrl-C is seen while waiting
            try:
                return self._done.get(timeout=0.2)
            except queue.Empty:
                continue


#: Seconds between a worker's checks that the sweep that started it is still alive.
PARENT_CHECK_SECONDS = 0.5
#: Deaths of workers outside any task that a pool survives before the tasks it holds count as failed.
UNATTRIBUTED_DEATHS = 3


def _worker_start(parent: int) -> None:
    """Set up a worker of the local pool (its initializer): it ignores Ctrl-C and dies with its sweep.

    Ctrl-C in a terminal reaches every process of the group: the sweep stops its workers itself, so that
    they print no traceback. A worker whose sweep died (kill -9) would wait for tasks forever: on Linux the
    kernel kills it (``PR_SET_PDEATHSIG``), elsewhere a thread of its own sees its parent change and exits.
    """
    import signal
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):
            pass  # the thread below does it
    if os.getppid() != parent:  # the sweep died while this worker started
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(PARENT_CHECK_SECONDS)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, name="discsim-sweep-parent-watch", daemon=True).start()


def _attempt_marked(marks: str, token: int, task, params: dict, seed: int):
    """:func:`attempt` in a worker of the local pool, with a file in ``marks`` while the task runs.

    A worker that dies leaves its task's mark behind: that tells the sweep which task was running.
    """
    mark = os.path.join(marks, str(token))
    with open(mark, "w"):
        pass
    try:
        return attempt(task, params, seed)
    finally:
        try:
            os.unlink(mark)
        except OSError:
            pass


class _Attempt:
    """One attempt of a task on the local pool, whichever pool (and future) runs it now."""

    future: Future  # set when it is sent to a pool, as is:
    pool: ProcessPoolExecutor

    def __init__(self, token: int, args: tuple):
        self.token = token
        self.args = args
        self.outcome: tuple | None = None

    def result(self):
        return self.outcome


class _LocalPool(_Finished):
    """A process pool on this machine (``fork`` on Linux, so tasks defined in a notebook or script run).

    A worker that dies (``os._exit``, a crash, the kernel's OOM killer) breaks a
    ``ProcessPoolExecutor``: every task it holds fails with ``BrokenProcessPool``. Here only the task that
    was running in the dead worker counts a failed attempt; the others are sent again to a new pool, as if
    nothing happened. Each worker marks (a file in a temporary folder) the task it runs, so after a break
    the tasks that were running are known: when only one was, it is the one. When several were (one per
    busy worker), the dead one is not known: those tasks run again one at a time on a pool of one worker,
    where a death can only be the running task's.
    """

    def __init__(self, workers: int):
        super().__init__()
        self.workers = workers
        self.label = f"{workers} local process{'es' if workers > 1 else ''}"
        self._pools: dict[bool, ProcessPoolExecutor] = {}  # solo (one worker, for suspects) -> its pool
        self._marks: str | None = None
        self._tokens = itertools.count()
        self._running: dict[Future, _Attempt] = {}
        self._ready: list[_Attempt] = []  # attempts whose outcome is known without their future (a death)
        self._unattributed = 0  # deaths outside any task

    def _executor(self, solo: bool = False) -> ProcessPoolExecutor:
        pool = self._pools.get(solo)
        if pool is None:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            context = multiprocessing.get_context("fork") if sys.platform.startswith("linux") else None
            pool = ProcessPoolExecutor(
                max_workers=1 if solo else self.workers,
                mp_context=context,
                initializer=_worker_start,
                initargs=(os.getpid(),),
            )
            self._pools[solo] = pool
        return pool

    def _marks_folder(self) -> str:
        if self._marks is None:
            import tempfile

            self._marks = tempfile.mkdtemp(prefix="discsim-sweep-")
        return self._marks

    def submit(self, *args):
        job = _Attempt(next(self._tokens), args)
        self._send(job, solo=False)
        return job

    def _send(self, job: _Attempt, solo: bool) -> None:
        from concurrent.futures.process import BrokenProcessPool

        for _ in range(2):
            pool = self._executor(solo)
            try:
                future = pool.submit(_attempt_marked, self._marks_folder(), job.token, *job.args)
            except BrokenProcessPool:  # it broke since: its tasks come back through next_done; a new pool here
                self._pools.pop(solo, None)
                pool.shutdown(wait=False, cancel_futures=True)
                continue
            job.future, job.pool = future, pool
            self._running[future] = job
            self.track(future)
            return
        msg = "the local process pool breaks as soon as it starts"
        raise RuntimeError(msg)

    def next_done(self):
        from concurrent.futures.process import BrokenProcessPool

        while True:
            if self._ready:
                return self._ready.pop(0)
            future = super().next_done()
            job = self._running.pop(future, None)
            if job is None:
                continue  # a task of a broken pool, already sent again
            if isinstance(future.exception(), BrokenProcessPool):
                self._broken(job)
                continue
            job.outcome = _outcome(future)
            return job

    def _broken(self, first: _Attempt) -> None:
        """A worker of ``first``'s pool died: find the task it ran, send the others again."""
        import concurrent.futures

        pool = first.pool
        held = [first, *(job for job in self._running.values() if job.pool is pool)]
        for job in held[1:]:
            del self._running[job.future]
        concurrent.futures.wait([job.future for job in held], timeout=10.0)  # the pool fails them all at once
        for solo, kept in list(self._pools.items()):
            if kept is pool:
                del self._pools[solo]
        pool.shutdown(wait=False, cancel_futures=True)
        marks = self._marks_folder()
        started = [job for job in held if os.path.exists(os.path.join(marks, str(job.token)))]
        for job in started:
            os.unlink(os.path.join(marks, str(job.token)))
        if len(started) == 1:
            (dead,) = started
            params, seed = dead.args[1], dead.args[2]
            error = (
                f"WorkerDied: the worker process died while running the task {params}, seed={seed} (it ended "
                f"without an exception: os._exit, a crash, or a kill, such as the kernel's when memory runs out)"
            )
            dead.outcome = ("error", error, f"{error}\n(no traceback: the process ended at once)\n", float("nan"))
            self._ready.append(dead)
            for job in held:
                if job is not dead:
                    self._send(job, solo=False)
            return
        if started:  # one of them died, the others were stopped with it: each runs again alone
            for job in held:
                self._send(job, solo=job in started)
            return
        self._unattributed += 1  # a worker died between tasks (or before it could mark one)
        if self._unattributed < UNATTRIBUTED_DEATHS:
            for job in held:
                self._send(job, solo=False)
            return
        for job in held:
            params, seed = job.args[1], job.args[2]
            error = (
                f"WorkerDied: the pool's worker processes died {self._unattributed} times outside any task; the "
                f"task {params}, seed={seed} was waiting"
            )
            job.outcome = ("error", error, f"{error}\n", float("nan"))
            self._ready.append(job)

    def close(self, cancel: bool = False) -> None:
        import shutil

        pools, self._pools = list(self._pools.values()), {}
        for pool in pools:
            if cancel:
                _stop_workers(pool)
            pool.shutdown(wait=not cancel, cancel_futures=cancel)
        self._running.clear()
        self._ready.clear()
        if self._marks is not None:
            shutil.rmtree(self._marks, ignore_errors=True)
            self._marks = None


def _stop_workers(pool: ProcessPoolExecutor) -> None:
    """Kill the worker processes of ``pool`` and reap them: a hung task must not keep the sweep alive."""
    kill = getattr(pool, "kill_workers", None)  # Python 3.14
    if kill is not None:
        kill()
        return
    processes = list((getattr(pool, "_processes", None) or {}).values())  # no public list before 3.14
    for process in processes:
        process.kill()
    for process in processes:
        process.join(timeout=5.0)


class _Dask(_Finished):
    """A ``dask.distributed.Client``: the tasks go to its cluster; nothing is started or closed here."""

    def __init__(self, client):
        super().__init__()
        self.client = client
        self._futures = []
        workers = len(client.scheduler_info().get("workers", {}))
        self.label = f"dask at {client.scheduler.address} ({workers} worker{'s' if workers != 1 else ''})"

    def submit(self, *args):
        future = self.client.submit(attempt, *args, pure=False)
        self._futures.append(future)
        return self.track(future)

    def close(self, cancel: bool = False) -> None:
        if cancel and self._futures:
            self.client.cancel(self._futures)
        self._futures.clear()


def _executor(client, workers):
    if client is not None:
        if workers is not None:
            msg = f"workers={workers!r} is for the local pool: a dask client brings its own workers"
            raise InvalidArgumentError(msg)
        if not (callable(getattr(client, "submit", None)) and hasattr(client, "status")):
            msg = f"client must be a dask.distributed.Client (or None for a local pool), got {client!r}"
            raise WrongTypeError(msg)
        if str(getattr(client, "status", "")) in ("closed", "closing", "failed"):
            msg = f"the dask client is {client.status}: connect a new one (dask.distributed.Client(...))"
            raise InvalidArgumentError(msg)
        return _Dask(client)
    if workers is None:
        workers = os.cpu_count() or 1
    if not is_count(workers) or isinstance(workers, bool) or workers < 0:
        msg = f"workers must be an integer >= 0 (0 runs the tasks in this process), got {workers!r}"
        raise InvalidArgumentError(msg)
    return _InProcess() if workers == 0 else _LocalPool(int(workers))


def _outcome(future):
    """What a finished future holds, with a lost worker or cluster as an error of the attempt."""
    try:
        return future.result()
    except Exception as exc:  # the worker died, or the cluster lost the task (not the task's own error)
        text = f"{type(exc).__name__}: the worker running the task was lost ({exc})"
        return ("error", text, traceback.format_exc(), float("nan"))


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
            or a cache folder that holds another task's results or files of its own.
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
    executor = _executor(client, workers)
    if isinstance(executor, _LocalPool):
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
        from discsim import __version__
        from discsim.run.cache import SweepCache

        store = SweepCache(cache, name, __version__)
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
            outcome = _outcome(future)
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
    executor: _InProcess | _Finished,
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
