"""Progress bars for long runs: tqdm when installed, a plain stderr line otherwise."""

from __future__ import annotations

import sys
import time
from contextlib import contextmanager

__all__ = ["progress_bar"]


class _Bar:
    """Wraps a tqdm bar (or prints plain lines) and shows a rate (collisions, or detections, per second)."""

    def __init__(self, total, by_time: bool, unit: str = "events", rate: str | None = "collisions"):
        self._start = time.perf_counter()
        self._rate_name = rate
        self._collisions0: int | None = None  # set by start(), or by the first update()
        self._by_time = by_time
        try:
            from tqdm.auto import tqdm
        except ImportError:  # tqdm is optional: pip install "discsim[progress]"
            self._tqdm = None
            self._done = 0.0
            self._total = total
            self._last_print = 0.0
        else:
            if by_time:  # simulated time is a float: show it with a few digits, not all 17
                bar_format = "{l_bar}{bar}| t = {n:.4g} / {total:.4g} [{elapsed}<{remaining}{postfix}]"
                self._tqdm = tqdm(total=total, dynamic_ncols=True, file=sys.stderr, bar_format=bar_format)
            else:
                scale = rate is not None  # whole tasks count one by one; events by the thousand
                self._tqdm = tqdm(total=total, unit=f" {unit}", unit_scale=scale, dynamic_ncols=True, file=sys.stderr)

    def start(self, collisions: int) -> None:
        """Count collisions per second from ``collisions`` (the engine's count when the run starts)."""
        self._collisions0 = collisions
        self._start = time.perf_counter()

    def update(self, amount, collisions: int) -> None:
        """Advance the bar by ``amount`` (time or events); ``collisions`` is the engine's running count."""
        if self._collisions0 is None:
            self._collisions0 = collisions
        elapsed = max(time.perf_counter() - self._start, 1e-9)
        rate = (collisions - self._collisions0) / elapsed
        if self._tqdm is not None:
            self._tqdm.update(amount)
            if self._rate_name is None:  # the bar's own rate is the one shown
                return
            self._tqdm.set_postfix_str(f"{rate:,.0f} {self._rate_name}/s", refresh=False)
            return
        self._done += amount
        if elapsed - self._last_print >= 1.0:
            self._last_print = elapsed
            per_second = f" ({rate:,.0f} {self._rate_name}/s)" if self._rate_name else ""
            print(f"{self._done:.6g} / {self._total:.6g}{per_second}", file=sys.stderr)

    def close(self) -> None:
        if self._tqdm is not None:
            self._tqdm.close()


@contextmanager
def progress_bar(total, by_time: bool, unit: str = "events", rate: str | None = "collisions"):
    """A bar over ``total`` units of simulated time (``by_time``) or of work (``unit``), with ``rate`` per second.

    ``rate=None``: whole units of work (e.g. a sweep's tasks), counted one by one at the bar's own rate.
    """
    bar = _Bar(total, by_time, unit, rate)
    try:
        yield bar
    finally:
        bar.close()
