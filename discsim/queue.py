"""Priority queues of predicted events, at most one pending event per owner.

An *owner* is an integer in ``range(n_owners)`` (the engine uses disc indices).
``push`` replaces the owner's previous event, so the queue never holds more
than ``n_owners`` live events, over any horizon. Entries are ordered by
``(time, owner)``, which is unique, so payloads are never compared and ties
break deterministically. The queue knows nothing of discs: validating an event
(its collision counters) is the engine's job.

Three implementations meet one protocol, :class:`EventQueueProtocol`, so that an
engine takes any of them and a benchmark can compare them: :class:`EventQueue`
(a ``sortedcontainers.SortedList``, exact removal), :class:`HeapEventQueue`
(``heapq`` with lazy deletion and compaction) and :class:`CalendarEventQueue` (a
calendar of time bins in front of a small ``SortedList``, O(1) amortised, after
Paul 2007). They meet it structurally, without inheriting from it: the hot loop
calls their methods directly, and ``isinstance(q, EventQueueProtocol)`` checks a
queue at run time.
"""

from __future__ import annotations

import heapq
import math
from typing import TYPE_CHECKING, Generic, Protocol, TypeVar, runtime_checkable

from sortedcontainers import SortedList

_INF = math.inf

__all__ = ["CalendarEventQueue", "EventQueue", "EventQueueProtocol", "HeapEventQueue", "sift_down", "sift_up"]

#: What an event carries, opaque to the queue (the engines push ``(kind, other, stamp)`` tuples of ints).
Payload = TypeVar("Payload")


@runtime_checkable
class EventQueueProtocol(Protocol[Payload]):
    """Earliest-first queue of at most one pending event per owner in ``range(n_owners)``.

    Entries are ordered by ``(time, owner)``; ``push`` replaces the owner's event, and a time of
    ``math.inf`` means no event. Every implementation pops the same events in the same order, bit for bit.

    Example:
        >>> isinstance(CalendarEventQueue(3), EventQueueProtocol)
        True
    """

    def push(self, owner: int, time: float, payload: Payload) -> None:
        """Schedule ``payload`` for ``owner`` at ``time``, replacing its pending event (``math.inf``: none)."""
        ...

    def pop_before(self, until: float) -> tuple[float, int, Payload] | None:
        """Pop the earliest ``(time, owner, payload)`` if its time is <= ``until``, else return None."""
        ...

    def pop(self) -> tuple[float, int, Payload]:
        """Remove and return the earliest ``(time, owner, payload)``; IndexError if empty."""
        ...

    def peek(self) -> float:
        """Time of the earliest event, ``math.inf`` if the queue is empty."""
        ...

    def discard(self, owner: int) -> None:
        """Drop ``owner``'s pending event, if any."""
        ...

    def pending(self, owner: int) -> tuple[float, Payload | None]:
        """``(time, payload)`` of ``owner``'s pending event (``inf, None`` if none)."""
        ...

    def shift_times(self, delta: float) -> None:
        """Subtract ``delta`` from every pending time (a new time origin)."""
        ...

    def __len__(self) -> int:
        """Pending events."""
        ...

    def storage(self) -> int:
        """Entries held in memory, replaced (dead) ones included; at least ``len``."""
        ...

    def _check(self) -> None:
        """Assert every invariant; O(n). For tests."""
        ...


# --- an indexed binary heap over arrays, for the compiled loops ---------------------------------------------
# ``heap[k]`` is the owner at position k and ``ht[k]`` its time (kept beside it, so that a comparison reads no
# other array); ``hpos[owner]`` is the owner's position. Ordered by ``(time, owner)``, as every queue here. Plain
# Python on anything indexable: the compiled event loop and the compression loop jit these very functions.
def sift_up(k, heap, ht, hpos):
    """Move the entry at position ``k`` towards the root until its parent is earlier."""
    owner = heap[k]
    t = ht[k]
    while k > 0:
        parent = (k - 1) >> 1
        pt = ht[parent]
        p = heap[parent]
        if t < pt or (t == pt and owner < p):
            heap[k] = p
            ht[k] = pt
            hpos[p] = k
            k = parent
        else:
            break
    heap[k] = owner
    ht[k] = t
    hpos[owner] = k


def sift_down(k, size, heap, ht, hpos):
    """Move the entry at position ``k`` away from the root (the heap holds ``size`` entries) until its children
    are later."""
    owner = heap[k]
    t = ht[k]
    while True:
        child = 2 * k + 1
        if child >= size:
            break
        c = heap[child]
        ct = ht[child]
        if child + 1 < size:
            d = heap[child + 1]
            dt = ht[child + 1]
            if dt < ct or (dt == ct and d < c):
                child += 1
                c = d
                ct = dt
        if ct < t or (ct == t and c < owner):
            heap[k] = c
            ht[k] = ct
            hpos[c] = k
            k = child
        else:
            break
    heap[k] = owner
    ht[k] = t
    hpos[owner] = k


class EventQueue(Generic[Payload]):
    """Earliest-first queue backed by a ``SortedList`` of ``(time, owner)`` keys.

    Runtime complexity: ``push`` and ``pop`` O(log n), ``peek`` and ``len`` O(1).

    Example:
        >>> q = EventQueue(3)
        >>> q.push(0, 2.0, "a"); q.push(1, 1.0, "b"); q.push(0, 0.5, "c")
        >>> len(q), q.pop()
        (2, (0.5, 0, 'c'))
    """

    #: Sublist size of the SortedList (its default is 1000). Smaller sublists make
    #: the insertions and deletions at the front cheaper (measured in
    #: docs/performance.md). ``SortedList._reset`` is the documented way to set it.
    LOAD = 100

    def __init__(self, n_owners: int):
        self._keys = SortedList()
        self._keys._reset(self.LOAD)
        self._add, self._remove = self._keys.add, self._keys.remove
        self._time = [math.inf] * n_owners
        self._payload: list[Payload | None] = [None] * n_owners  # None where the owner has no event

    def push(self, owner: int, time: float, payload: Payload) -> None:
        """Schedule ``payload`` for ``owner`` at ``time``, replacing its pending event."""
        old = self._time[owner]
        if old != math.inf:
            self._remove((old, owner))
        if time != math.inf:
            self._add((time, owner))
        self._time[owner] = time
        self._payload[owner] = payload if time != math.inf else None

    def shift_times(self, delta: float) -> None:
        """Subtract ``delta`` from every pending time (a new time origin). O(n log n)."""
        self._time = [t - delta for t in self._time]
        self._keys.clear()
        self._keys.update((t, o) for o, t in enumerate(self._time) if t != math.inf)

    def pop_before(self, until: float) -> tuple[float, int, Payload] | None:
        """Pop the earliest ``(time, owner, payload)`` if its time is <= ``until``, else return None."""
        keys = self._keys
        if not keys or keys[0][0] > until:
            return None
        time, owner = keys.pop(0)
        self._time[owner] = math.inf
        payload = self._payload[owner]
        self._payload[owner] = None
        return time, owner, payload

    def pop(self) -> tuple[float, int, Payload]:
        """Remove and return the earliest ``(time, owner, payload)``; IndexError if empty."""
        time, owner = self._keys.pop(0)
        self._time[owner] = math.inf
        payload = self._payload[owner]
        self._payload[owner] = None
        return time, owner, payload

    def peek(self) -> float:
        """Time of the earliest event, ``math.inf`` if the queue is empty."""
        keys = self._keys
        return keys[0][0] if keys else math.inf

    def discard(self, owner: int) -> None:
        """Drop ``owner``'s pending event, if any."""
        self.push(owner, math.inf, None)  # type: ignore[arg-type]  # at time inf the payload is dropped

    def pending(self, owner: int) -> tuple[float, Payload | None]:
        """``(time, payload)`` of ``owner``'s pending event (``inf, None`` if none)."""
        return self._time[owner], self._payload[owner]

    def __len__(self) -> int:
        return len(self._keys)

    def storage(self) -> int:
        """Entries held in memory (equals ``len`` here; the heap may hold more)."""
        return len(self._keys)

    def _check(self) -> None:
        """Assert every invariant; O(n). For tests."""
        self._keys._check()
        live = [(t, o) for o, t in enumerate(self._time) if t != math.inf]
        assert sorted(live) == list(self._keys), "keys and per-owner times disagree"


class HeapEventQueue(Generic[Payload]):
    """Earliest-first queue backed by ``heapq`` with lazy deletion.

    A replaced event stays in the heap as a dead entry, recognised by its
    version number and skipped on ``pop``; the heap is rebuilt when dead
    entries outnumber live ones, so storage stays at most ``2 n_owners + 16`` entries.

    Runtime complexity: ``push`` O(log n) amortised, ``pop`` O(log n) amortised.

    Example:
        >>> q = HeapEventQueue(3)
        >>> q.push(0, 2.0, "a"); q.push(1, 1.0, "b"); q.push(0, 0.5, "c")
        >>> len(q), q.pop()
        (2, (0.5, 0, 'c'))
    """

    def __init__(self, n_owners: int):
        self._heap: list[tuple[float, int, int]] = []  # (time, owner, version); dead where the version is old
        self._time = [math.inf] * n_owners
        self._version = [0] * n_owners
        self._payload: list[Payload | None] = [None] * n_owners  # None where the owner has no event
        self._live = 0

    def push(self, owner: int, time: float, payload: Payload) -> None:
        """Schedule ``payload`` for ``owner`` at ``time``, replacing its pending event."""
        if self._time[owner] != math.inf:
            self._live -= 1
        version = self._version[owner] + 1
        self._version[owner] = version
        self._time[owner] = time
        self._payload[owner] = payload if time != math.inf else None
        if time != math.inf:
            self._live += 1
            heapq.heappush(self._heap, (time, owner, version))
            if len(self._heap) > 2 * self._live + 16:
                self._compact()

    def shift_times(self, delta: float) -> None:
        """Subtract ``delta`` from every pending time (a new time origin). O(n)."""
        self._time = [t - delta for t in self._time]
        self._compact()

    def _compact(self) -> None:
        self._heap = [(t, o, self._version[o]) for o, t in enumerate(self._time) if t != math.inf]
        heapq.heapify(self._heap)

    def _drop_dead(self) -> None:
        heap, version = self._heap, self._version
        while heap and heap[0][2] != version[heap[0][1]]:
            heapq.heappop(heap)

    def pop_before(self, until: float) -> tuple[float, int, Payload] | None:
        """Pop the earliest ``(time, owner, payload)`` if its time is <= ``until``, else return None."""
        heap, version = self._heap, self._version
        while heap and heap[0][2] != version[heap[0][1]]:
            heapq.heappop(heap)
        if not heap or heap[0][0] > until:
            return None
        time, owner, _ = heapq.heappop(heap)
        self._time[owner] = math.inf
        version[owner] += 1
        self._live -= 1
        payload = self._payload[owner]
        self._payload[owner] = None
        return time, owner, payload  # type: ignore[return-value]  # an owner with an event holds its payload

    def pop(self) -> tuple[float, int, Payload]:
        """Remove and return the earliest ``(time, owner, payload)``; IndexError if empty."""
        self._drop_dead()
        time, owner, _ = heapq.heappop(self._heap)
        self._time[owner] = math.inf
        self._version[owner] += 1
        self._live -= 1
        payload = self._payload[owner]
        self._payload[owner] = None
        return time, owner, payload  # type: ignore[return-value]  # an owner with an event holds its payload

    def peek(self) -> float:
        """Time of the earliest event, ``math.inf`` if the queue is empty."""
        self._drop_dead()
        return self._heap[0][0] if self._heap else math.inf

    def discard(self, owner: int) -> None:
        """Drop ``owner``'s pending event, if any."""
        self.push(owner, math.inf, None)  # type: ignore[arg-type]  # at time inf the payload is dropped

    def pending(self, owner: int) -> tuple[float, Payload | None]:
        """``(time, payload)`` of ``owner``'s pending event (``inf, None`` if none)."""
        return self._time[owner], self._payload[owner]

    def __len__(self) -> int:
        return self._live

    def storage(self) -> int:
        """Entries held in memory, dead ones included."""
        return len(self._heap)

    def _check(self) -> None:
        """Assert every invariant; O(n). For tests."""
        live = sorted((t, o) for o, t in enumerate(self._time) if t != math.inf)
        in_heap = sorted((t, o) for t, o, v in self._heap if v == self._version[o])
        assert live == in_heap, "heap and per-owner times disagree"
        assert self._live == len(live)
        # Compaction runs on push only, so discards and pops can leave more than 2 live + 16
        # entries; since pushes compact past 2 live + 16 and live <= n_owners, this bound holds.
        assert len(self._heap) <= 2 * len(self._time) + 16


class CalendarEventQueue(Generic[Payload]):
    """Earliest-first calendar queue: a small ``SortedList`` for the current time bin, plain lists beyond.

    After G. Paul, J. Comput. Phys. 221 (2007) 615. Time is cut into bins of
    width ``w`` from an origin ``base``; a ring of ``B`` bins covers one *lap*
    ``[base, base + B w)``. Live events of the bins already reached (index <=
    the current bin) sit in a ``SortedList`` (exact removal, exact order);
    later events of the lap are appended, O(1), to their bin's list; events
    beyond the lap go to an overflow list. When the ``SortedList`` runs dry,
    the live entries of the next non-empty bin are bulk-loaded into it; when
    the lap ends, the overflow (then every live event) is re-binned from a new
    origin, the earliest pending time, with new ``w`` and ``B``.

    An entry is the tuple ``(time, owner, payload)``: ``(time, owner)`` is
    unique among live entries, so payloads are never compared, and a pop
    hands the entry itself back. A replaced event that sits in a bin or in
    the overflow stays there as a
    dead entry (the owner's current entry is another tuple), dropped when its
    bin is loaded or the lap is re-binned. Bin index, membership of the
    ``SortedList`` and lap end all derive from the one float ``(t - base) * (1 / w)``,
    which is monotone in ``t``, so the pop order is exactly ascending
    ``(time, owner)``, bit for bit the order of the other queues. Times must be
    finite or ``math.inf`` (no event).

    Adaptive bins: ``w = PER_BIN / rate``, ``rate`` being the events per unit
    time that went through the ``SortedList`` over the last lap (on the first
    lap, the density of the earliest pending times), and ``B = SPAN n / PER_BIN``
    for ``n`` live events, so a lap lasts about ``SPAN n`` pops and events due
    in up to ``SPAN`` times the mean interval between an owner's events fit in
    the ring. If the bins turn out far too wide (more than ``4 PER_BIN`` events
    per bin over a quarter of the queue), every event is re-binned at once.

    Storage: dead entries are counted and every live event is re-binned when
    they exceed ``2 n_owners + 64``, so at most ``3 n_owners + 64`` entries are
    held (``_check`` asserts it).

    Runtime complexity: ``push`` O(1) (O(log k) when the event falls into the
    current bin of ``k`` events), ``pop`` O(log k) amortised, re-binning
    included (O(n) every ``SPAN n`` or so pops).

    Example:
        >>> q = CalendarEventQueue(3)
        >>> q.push(0, 2.0, "a"); q.push(1, 1.0, "b"); q.push(0, 0.5, "c")
        >>> len(q), q.pop()
        (2, (0.5, 0, 'c'))
    """

    #: Target number of events per bin (32 to 128 measured alike; see docs/performance.md).
    PER_BIN = 64
    #: Lap length in pops per live event: 2 to 4 measured alike; shorter laps re-bin more often.
    SPAN = 3.0

    def __init__(self, n_owners: int):
        self._n_owners = n_owners
        self._near = SortedList()
        self._near._reset(EventQueue.LOAD)  # helps when many events share the current bin (ties, bursts)
        self._near_add, self._near_remove = self._near.add, self._near.remove
        self._entry: list[tuple[float, int, Payload] | None] = [None] * n_owners  # the owner's live entry, or None
        self._live = 0
        self._dead = 0
        self._max_dead = 2 * n_owners + 64
        self._overflow: list[tuple[float, int, Payload]] = []
        self._rate = 0.0  # events per unit time measured over the last lap (0: unknown)
        self._start(0.0, 1.0, 0)

    def _start(self, base: float, width: float, n_bins: int) -> None:
        """Begin a lap at ``base`` with empty bins; the caller re-bins the live entries."""
        self._base = base
        self._width = width
        self._inv_w = 1.0 / width
        self._bins: list[list[tuple[float, int, Payload]]] = [[] for _ in range(n_bins)]
        self._n_bins = n_bins
        if n_bins:
            self._span = float(n_bins)  # x = (t - base) / w at the end of the lap
            self._cur = 0
            self._next = 1.0  # x at the end of the current bin
        else:  # no lap: every push goes to the overflow, the next pop starts a lap
            self._span = self._next = -math.inf
            self._cur = -1
        self._loaded = 0  # live entries loaded from bins during this lap
        self._direct = 0  # events pushed straight into the SortedList during this lap

    def _rebin(self, live: list[tuple[float, int, Payload]]) -> None:
        """Start a new lap holding exactly the live entries ``live`` (the SortedList must be empty)."""
        self._dead = 0
        if not live:
            self._overflow = []
            self._start(0.0, 1.0, 0)
            return
        n = len(live)
        base = min(live)[0]
        # Events per unit time: measured over the last lap, else the density of the earliest pending times.
        rate = self._rate
        if rate <= 0.0:
            k = min(n, 4 * self.PER_BIN)
            spread = heapq.nsmallest(k, [e[0] for e in live])[-1] - base
            rate = (k - 1) / spread if spread > 0.0 else 0.0
        width = self.PER_BIN / rate if rate > 0.0 else 1.0
        if not width > 1e-300:  # any width works; keep 1 / width finite so that x = 0 stays 0
            width = 1e-300
        elif not width < 1e300:
            width = 1e300
        self._start(base, width, int(self.SPAN * n / self.PER_BIN) + 1)
        near, bins, overflow = [], self._bins, []
        inv_w, top = self._inv_w, self._span
        for e in live:
            x = (e[0] - base) * inv_w
            if x < 1.0:
                near.append(e)
            elif x < top:
                bins[int(x)].append(e)
            else:
                overflow.append(e)
        self._overflow = overflow
        self._loaded = len(near)
        self._near.update(near)

    def _compact(self) -> None:
        """Re-bin every live event now (drops all dead entries)."""
        self._near.clear()
        self._rebin([e for e in self._entry if e is not None])

    def _advance(self) -> None:
        """Refill the empty SortedList from the next non-empty bin, or from the overflow at the end of the lap."""
        entry, bins = self._entry, self._bins
        cur, last = self._cur, self._n_bins - 1
        while cur < last:
            cur += 1
            b = bins[cur]
            if b:
                bins[cur] = []
                live = [e for e in b if entry[e[1]] is e]
                self._dead -= len(b) - len(live)
                if live:
                    # Events that went through the SortedList so far this lap, over the bins passed.
                    seen = self._loaded + self._direct
                    if seen > 4 * self.PER_BIN * cur and seen > self._live // 4:  # bins far too wide
                        self._rate = seen / (cur * self._width)
                        self._rebin([e for e in entry if e is not None])
                        return
                    self._cur, self._next = cur, float(cur + 1)
                    self._loaded += len(live)
                    self._near.update(live)
                    return
        # End of the lap: every live event is in the overflow.
        overflow = self._overflow
        if not overflow:
            self._start(0.0, 1.0, 0)  # empty: the next pushes go to the overflow
            return
        if self._n_bins:
            self._rate = max(self._loaded + self._direct, 1) / (self._span * self._width)
        self._rebin([e for e in overflow if entry[e[1]] is e])

    def push(self, owner: int, time: float, payload: Payload) -> None:
        """Schedule ``payload`` for ``owner`` at ``time``, replacing its pending event."""
        entries = self._entry
        old = entries[owner]
        if old is not None:
            # The old event leaves the SortedList, or stays behind in its bin as a dead entry.
            if (old[0] - self._base) * self._inv_w < self._next:
                self._near_remove(old)
            else:
                self._dead += 1
                if self._dead > self._max_dead:
                    entries[owner] = None
                    self._compact()
            if time == _INF:
                entries[owner] = None
                self._live -= 1
                return
        elif time == _INF:
            return
        else:
            self._live += 1
        e = entries[owner] = (time, owner, payload)
        x = (time - self._base) * self._inv_w
        if x < self._next:
            self._near_add(e)
            self._direct += 1
        elif x < self._span:
            self._bins[int(x)].append(e)
        else:
            self._overflow.append(e)

    def shift_times(self, delta: float) -> None:
        """Subtract ``delta`` from every pending time (a new time origin). O(n)."""
        entries = self._entry
        for o, e in enumerate(entries):
            if e is not None:
                entries[o] = (e[0] - delta, o, e[2])
        self._near.clear()
        self._rebin([e for e in entries if e is not None])

    def pop_before(self, until: float) -> tuple[float, int, Payload] | None:
        """Pop the earliest ``(time, owner, payload)`` if its time is <= ``until``, else return None."""
        near = self._near
        if not near:
            self._advance()
            if not near:
                return None
        e = near.pop(0)  # cheaper than near[0] and then pop: the engine's limit is rarely reached
        if e[0] > until:
            near.add(e)
            return None
        self._entry[e[1]] = None
        self._live -= 1
        return e

    def pop(self) -> tuple[float, int, Payload]:
        """Remove and return the earliest ``(time, owner, payload)``; IndexError if empty."""
        if not self._near:
            self._advance()
        e = self._near.pop(0)
        self._entry[e[1]] = None
        self._live -= 1
        return e

    def peek(self) -> float:
        """Time of the earliest event, ``math.inf`` if the queue is empty."""
        near = self._near
        if not near:
            self._advance()
        return near[0][0] if near else math.inf

    def discard(self, owner: int) -> None:
        """Drop ``owner``'s pending event, if any."""
        self.push(owner, math.inf, None)  # type: ignore[arg-type]  # at time inf the payload is dropped

    def pending(self, owner: int) -> tuple[float, Payload | None]:
        """``(time, payload)`` of ``owner``'s pending event (``inf, None`` if none)."""
        e = self._entry[owner]
        return (math.inf, None) if e is None else (e[0], e[2])

    def __len__(self) -> int:
        return self._live

    def storage(self) -> int:
        """Entries held in memory, dead ones included."""
        return self._live + self._dead

    def _check(self) -> None:
        """Assert every invariant; O(n). For tests."""
        self._near._check()
        entries, base, inv_w = self._entry, self._base, self._inv_w
        live = [e for e in entries if e is not None]
        assert all(e[1] == o for o, e in enumerate(entries) if e is not None)
        assert all(e[0] != math.inf for e in live)
        assert self._live == len(live)
        for e in self._near:
            assert entries[e[1]] is e, "dead entry in the SortedList"
            assert (e[0] - base) * inv_w < self._next
        held = len(self._near)
        for k, b in enumerate(self._bins):
            assert k > self._cur or not b, "entries in a bin already loaded"
            for e in b:
                assert self._next <= (e[0] - base) * inv_w < self._span and int((e[0] - base) * inv_w) == k
            held += len(b)
        for e in self._overflow:
            assert (e[0] - base) * inv_w >= self._span
        held += len(self._overflow)
        held_live = [id(e) for b in [*self._bins, self._overflow, self._near] for e in b if entries[e[1]] is e]
        assert len(set(held_live)) == len(held_live) == len(live), "a live event is missing or held twice"
        assert held == self._live + self._dead == self.storage()
        assert self._dead <= self._max_dead
        assert self.storage() <= 3 * self._n_owners + 64


if TYPE_CHECKING:  # nothing runs here: mypy checks that each queue meets the protocol, method by method
    from collections.abc import Callable

    _QUEUES: tuple[Callable[[int], EventQueueProtocol[object]], ...] = (
        EventQueue,
        HeapEventQueue,
        CalendarEventQueue,
    )
