"""Where a sweep's tasks run: this process, a local process pool, or a dask cluster (see :func:`discsim.sweep`).

Each executor takes tasks (``submit``), hands them back as they finish (``next_done``), and stops
(``close``). The local pool survives its workers: a worker that dies fails only the task it was running
(:class:`LocalPool`); its workers ignore Ctrl-C (the sweep stops them) and exit when the sweep that started
them dies, even by kill -9.
"""

from __future__ import annotations

import itertools
import os
import sys
import time
import traceback
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from discsim._validate import is_count
from discsim.errors import InvalidArgumentError, WrongTypeError

if TYPE_CHECKING:
    from concurrent.futures import Future, ProcessPoolExecutor

__all__ = ["ERROR_COLUMN", "SEED_COLUMN", "LocalPool", "attempt", "json_scalar", "make_executor", "outcome_of"]

#: The column of the seed each task was given, after the grid's parameters.
SEED_COLUMN = "seed"
#: The last column: None where the task finished, else its error (``"ValueError: ..."``).
ERROR_COLUMN = "error"


def json_scalar(value):
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
                result[key] = json_scalar(value)
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


def _worker_start(sweep: int) -> None:
    """Set up a worker of the local pool (its initializer): it ignores Ctrl-C and dies with its sweep.

    Ctrl-C in a terminal reaches every process of the group: the sweep stops its workers itself, so that
    they print no traceback. A worker whose sweep died (kill -9) would wait for tasks forever: on Linux the
    kernel kills it (``PR_SET_PDEATHSIG``); on every system a thread of its own exits when its parent goes
    (on POSIX its parent pid changes; on Windows the parent's process handle is signalled).

    Args:
        sweep: the pid of the sweep's process (the parent, under ``fork`` and ``spawn``).
    """
    import multiprocessing
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
    parent = os.getppid()
    parent_process = multiprocessing.parent_process()

    def orphaned() -> bool:
        if os.name == "nt":  # no reparenting there (and os.kill(pid, 0) would end the process)
            return parent_process is not None and not parent_process.is_alive()
        return os.getppid() != parent

    if os.name != "nt" and parent != sweep:  # the sweep died while this worker started (or a forkserver forked it)
        try:
            os.kill(sweep, 0)
        except ProcessLookupError:
            os._exit(1)
        except OSError:
            pass

    def watch() -> None:
        while not orphaned():
            time.sleep(PARENT_CHECK_SECONDS)
        os._exit(1)

    threading.Thread(target=watch, name="discsim-sweep-parent-watch", daemon=True).start()


#: A worker's mark: the token of the task it runs, or blanks between tasks (fixed width, rewritten in place).
MARK_WIDTH = 20
_mark: list = [None, -1]  # in a worker: the marks folder its file is in, and the file's descriptor


def _attempt_marked(marks: str, token: int, task, params: dict, seed: int):
    """:func:`attempt` in a worker of the local pool, marked: while the task runs, the worker's file in
    ``marks`` (named by its pid) holds the task's token.

    A worker that dies leaves its task's token there: that tells the sweep which task was running. (One
    file per worker, rewritten in place: two small writes per task, no file created or removed.)
    """
    if _mark[0] != marks:
        _mark[:] = [marks, os.open(os.path.join(marks, str(os.getpid())), os.O_WRONLY | os.O_CREAT, 0o600)]
    fd = _mark[1]
    os.lseek(fd, 0, os.SEEK_SET)
    os.write(fd, str(token).rjust(MARK_WIDTH).encode())
    try:
        return attempt(task, params, seed)
    finally:
        os.lseek(fd, 0, os.SEEK_SET)
        os.write(fd, b" " * MARK_WIDTH)


def _marked_tokens(marks: str) -> set[int]:
    """The tokens the workers' files in ``marks`` hold: the tasks that were running when they stopped."""
    tokens = set()
    for name in os.listdir(marks):
        try:
            with open(os.path.join(marks, name), "rb") as f:
                text = f.read(MARK_WIDTH).strip()
        except OSError:
            continue
        if text.isdigit():
            tokens.add(int(text))
    return tokens


class _Attempt:
    """One attempt of a task on the local pool, whichever pool (and future) runs it now."""

    future: Future  # set when it is sent to a pool, as is:
    pool: ProcessPoolExecutor

    def __init__(self, args: tuple):
        self.token = -1  # set, afresh, each time it is sent to a pool
        self.args = args
        self.outcome: tuple | None = None

    def result(self):
        return self.outcome


class LocalPool(_Finished):
    """A process pool on this machine (``fork`` on Linux, so tasks defined in a notebook or script run).

    A worker that dies (``os._exit``, a crash, the kernel's OOM killer) breaks a
    ``ProcessPoolExecutor``: every task it holds fails with ``BrokenProcessPool``. Here only the task that
    was running in the dead worker counts a failed attempt; the others are sent again to a new pool, as if
    nothing happened. Each worker writes the task it runs into a file of its own (in a temporary folder),
    so after a break the tasks that were running are known: when only one was, it is the one. When several
    were (one per busy worker), the dead one is not known: those tasks run again one at a time on a pool of
    one worker, where a death can only be the running task's.
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
        job = _Attempt(args)
        self._send(job, solo=False)
        return job

    def _send(self, job: _Attempt, solo: bool) -> None:
        from concurrent.futures.process import BrokenProcessPool

        for _ in range(2):
            pool = self._executor(solo)
            try:
                job.token = next(self._tokens)
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
            job.outcome = outcome_of(future)
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
        running = _marked_tokens(marks)  # each send has a token of its own: a dead pool's marks never match again
        started = [job for job in held if job.token in running]
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


def make_executor(client, workers):
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
    return _InProcess() if workers == 0 else LocalPool(int(workers))


def outcome_of(future):
    """What a finished future holds, with a lost worker or cluster as an error of the attempt."""
    try:
        return future.result()
    except Exception as exc:  # the worker died, or the cluster lost the task (not the task's own error)
        text = f"{type(exc).__name__}: the worker running the task was lost ({exc})"
        return ("error", text, traceback.format_exc(), float("nan"))


#: What :func:`make_executor` gives.
Executor = _InProcess | LocalPool | _Dask
