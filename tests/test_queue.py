"""Model-based tests of the event queues in discsim.queue: every class pops exactly what a dict would."""

from __future__ import annotations

import inspect
import math
import random
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, precondition, rule

from discsim.queue import CalendarEventQueue, EventQueue, EventQueueProtocol, HeapEventQueue

# A calendar with tiny bins, so that small queues already use many bins, dead entries,
# the overflow and the drift re-binning (the default needs some 20 events per bin).
SmallBinCalendar = type("SmallBinCalendar", (CalendarEventQueue,), {"PER_BIN": 2, "SPAN": 2.0})

QUEUES = [EventQueue, HeapEventQueue, CalendarEventQueue]
ALL_QUEUES = [*QUEUES, SmallBinCalendar]


class Model:
    """The specification: a dict ``owner -> (time, payload)``."""

    def __init__(self, n_owners: int):
        self.events: dict[int, tuple[float, object]] = {}
        self.payload: list = [None] * n_owners

    def push(self, owner, time, payload):
        self.payload[owner] = payload
        if time == math.inf:
            self.events.pop(owner, None)
        else:
            self.events[owner] = (time, payload)

    def earliest(self):
        if not self.events:
            return None
        owner = min(self.events, key=lambda o: (self.events[o][0], o))
        return self.events[owner][0], owner

    def pop_before(self, until):
        first = self.earliest()
        if first is None or first[0] > until:
            return None
        time, owner = first
        del self.events[owner]
        payload, self.payload[owner] = self.payload[owner], None
        return time, owner, payload

    def pending(self, owner):
        if owner in self.events:
            return self.events[owner]
        return math.inf, None  # no pending event, whatever was pushed with time inf

    def shift_times(self, delta):
        self.events = {o: (t - delta, p) for o, (t, p) in self.events.items()}


# Times with many exact ties, a few far ones, and inf (no event).
TIES = st.sampled_from([0.0, 0.5, 1.0, 1.0, 2.0, 3.0, 1e6, math.inf])
FLOATS = st.floats(min_value=-1e3, max_value=1e6, allow_nan=False, allow_infinity=False)
# Offsets from the last popped time: exactly now, just after, spread over 1e-6 .. 1e3.
OFFSETS = st.one_of(
    st.just(0.0),
    st.sampled_from([5e-324, 1e-12, 1e-6, 0.25, 1.0]),
    st.floats(min_value=-6, max_value=3).map(lambda e: 10.0**e),
)


class QueueMachine(RuleBasedStateMachine):
    """Runs every queue class side by side against :class:`Model`."""

    @initialize(n=st.integers(min_value=1, max_value=40))
    def setup(self, n):
        self.n = n
        self.model = Model(n)
        self.queues = [cls(n) for cls in ALL_QUEUES]
        self.now = 0.0
        self.counter = 0

    def _push(self, owner, time):
        self.counter += 1
        payload = ("p", self.counter)
        self.model.push(owner, time, payload)
        for q in self.queues:
            q.push(owner, time, payload)

    @rule(data=st.data(), time=st.one_of(TIES, FLOATS))
    def push_anywhere(self, data, time):
        self._push(data.draw(st.integers(0, self.n - 1)), time)

    @rule(data=st.data(), offset=OFFSETS)
    def push_after_now(self, data, offset):
        self._push(data.draw(st.integers(0, self.n - 1)), self.now + offset)

    @rule(data=st.data(), count=st.integers(1, 12), offset=OFFSETS)
    def burst_of_ties(self, data, count, offset):
        owners = data.draw(st.lists(st.integers(0, self.n - 1), min_size=1, max_size=count))
        for owner in owners:
            self._push(owner, self.now + offset)

    @rule(data=st.data())
    def discard(self, data):
        owner = data.draw(st.integers(0, self.n - 1))
        self.model.push(owner, math.inf, None)
        for q in self.queues:
            q.discard(owner)

    @rule(until=st.one_of(TIES, FLOATS, OFFSETS))
    def pop_before(self, until):
        expected = self.model.pop_before(until)
        for q in self.queues:
            assert q.pop_before(until) == expected, type(q).__name__
        if expected is not None:
            self.now = expected[0]

    @rule(data=st.data())
    def pop_before_exact_limit(self, data):
        first = self.model.earliest()
        limit = first[0] if first else 0.0
        limit = data.draw(st.sampled_from([limit, math.nextafter(limit, -math.inf)]))
        self.pop_before(limit)

    @precondition(lambda self: self.model.events)
    @rule()
    def pop(self):
        expected = self.model.pop_before(math.inf)
        for q in self.queues:
            assert q.pop() == expected, type(q).__name__
        self.now = expected[0]

    @precondition(lambda self: not self.model.events)
    @rule()
    def pop_empty(self):
        for q in self.queues:
            with pytest.raises(IndexError):
                q.pop()

    @rule(count=st.integers(1, 30))
    def drain_some(self, count):
        for _ in range(count):
            self.pop_before(math.inf)

    @rule(data=st.data())
    def pending(self, data):
        owner = data.draw(st.integers(0, self.n - 1))
        expected = self.model.pending(owner)
        for q in self.queues:
            assert q.pending(owner) == expected, type(q).__name__

    @rule(delta=st.one_of(st.just(0.0), st.sampled_from([0.5, 1.0, -2.0]), FLOATS))
    def shift_times(self, delta):
        delta = min(delta, self.now) if delta > 0 else delta
        self.model.shift_times(delta)
        for q in self.queues:
            q.shift_times(delta)
        self.now -= delta

    @invariant()
    def agree(self):
        first = self.model.earliest()
        expected_peek = first[0] if first else math.inf
        for q in self.queues:
            q._check()
            assert len(q) == len(self.model.events), type(q).__name__
            assert q.peek() == expected_peek, type(q).__name__
            q._check()


TestQueueMachine = QueueMachine.TestCase
TestQueueMachine.settings = settings(
    max_examples=80, stateful_step_count=60, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)


def _random_delay(rng: random.Random, mode: str, n: int, now: float) -> float:
    """Delays of the engine's kind (about n pops ahead) and some harder ones."""
    if mode == "engine":
        return rng.expovariate(1.0) * n
    if mode == "loguniform":
        return n * 10.0 ** rng.uniform(-6, 3)
    if mode == "ties":
        return float(rng.randrange(3)) * n
    if mode == "now":
        return 0.0 if rng.random() < 0.5 else rng.expovariate(1.0) * n
    if mode == "bursts":
        return math.floor(now + rng.expovariate(1.0) * n) + 1.0 - now
    if mode == "drift":
        return rng.expovariate(1.0) * n * (1.0 + rng.random() * 100.0)
    raise ValueError(mode)


@pytest.mark.parametrize("mode", ["engine", "loguniform", "ties", "now", "bursts", "drift"])
@pytest.mark.parametrize("n", [1, 7, 300])
def test_engine_like_workloads_agree(mode, n):
    """Long engine-like runs (pop, push back, replace another owner's event): every queue agrees."""
    rng = random.Random(f"{mode}-{n}")
    queues = [cls(n) for cls in ALL_QUEUES]
    for o in range(n):
        t = rng.random() * n
        for q in queues:
            q.push(o, t, o)
    now = 0.0
    for step in range(6000):
        if rng.random() < 0.02:
            until = now + rng.random() * n
            popped = [q.pop_before(until) for q in queues]
        else:
            popped = [q.pop_before(math.inf) for q in queues]
        assert all(p == popped[0] for p in popped), (step, popped)
        if popped[0] is not None:
            now, owner, _ = popped[0]
            t = now + _random_delay(rng, mode, n, now)
            for q in queues:
                q.push(owner, t, step)
        if rng.random() < 0.35:  # replace another owner's event, later than now
            other = rng.randrange(n)
            t = now + _random_delay(rng, mode, n, now) * rng.choice([0.5, 1.0, 1e-9])
            if rng.random() < 0.05:
                t = math.inf
            for q in queues:
                q.push(other, t, -step)
        if rng.random() < 0.01:  # earlier than anything in the bins, later than now
            other = rng.randrange(n)
            t = math.nextafter(now, math.inf)
            for q in queues:
                q.push(other, t, step)
        if step % 1500 == 1499:
            delta = now
            for q in queues:
                q.shift_times(delta)
            now -= delta
        lengths = {len(q) for q in queues}
        assert len(lengths) == 1
        if step % 250 == 0:
            for q in queues:
                q._check()
    for o in range(n):
        assert len({q.pending(o) for q in queues}) == 1
    drained = [[q.pop() for _ in range(len(q))] for q in queues]
    assert all(d == drained[0] for d in drained)
    assert drained[0] == sorted(drained[0], key=lambda e: (e[0], e[1]))


@pytest.mark.parametrize("cls", ALL_QUEUES)
def test_storage_stays_bounded(cls):
    """10^5 random operations, many of them replacements without pops: storage <= 4 n + 64."""
    n = 50
    rng = random.Random(1)
    q = cls(n)
    now = 0.0
    most = 0
    for step in range(100_000):
        r = rng.random()
        if step // 20_000 == 2:  # a stretch of replacements only: dead entries pile up
            r = 0.0
        if r < 0.6:
            q.push(rng.randrange(n), now + rng.expovariate(1.0) * rng.choice([1e-3, 1.0, 1e3]), None)
        elif r < 0.65:
            q.discard(rng.randrange(n))
        else:
            popped = q.pop_before(math.inf)
            if popped is not None:
                now = popped[0]
        most = max(most, q.storage())
        assert q.storage() <= 4 * n + 64
        if step % 5000 == 0:
            q._check()
    q._check()
    assert most >= len(q)


def test_calendar_rebins_when_bins_are_too_wide():
    """Events suddenly crowding the next few bins trigger a re-binning; the order stays exact."""
    n = 2000
    cal, ref = CalendarEventQueue(n), EventQueue(n)
    rng = random.Random(3)
    for o in range(n):
        t = rng.random()
        cal.push(o, t, None)
        ref.push(o, t, None)
    width = None
    for _ in range(20_000):
        popped = cal.pop_before(math.inf)
        assert popped == ref.pop_before(math.inf)
        if width is None:
            width = cal._width
        t = popped[0] + width * 3.0 * rng.random()  # 2000 events within a few bins
        cal.push(popped[1], t, None)
        ref.push(popped[1], t, None)
    cal._check()
    assert cal._width < width / 2


@pytest.mark.parametrize("cls", QUEUES)
def test_empty_queue(cls):
    q = cls(2)
    assert len(q) == 0 and q.peek() == math.inf and q.pop_before(math.inf) is None
    assert q.pending(1) == (math.inf, None)
    with pytest.raises(IndexError):
        q.pop()
    q.push(1, 5.0, "x")
    q.discard(1)
    q.shift_times(1.0)
    assert len(q) == 0 and q.pop_before(math.inf) is None
    q.push(0, 2.0, "y")
    assert q.pop_before(1.0) is None and q.pop_before(2.0) == (2.0, 0, "y")
    q._check()


# --- the protocol the three queues meet -----------------------------------------------------------------------
def _methods(cls: type) -> set[str]:
    """The methods ``cls`` defines in its own body, ``__init__`` and the protocol machinery left out."""
    return {n for n, v in vars(cls).items() if inspect.isfunction(v)} - {"__init__", "__subclasshook__"}


def _drain(queue: EventQueueProtocol[str], until: float) -> list[tuple[float, int, str]]:
    """Pop every event up to ``until``, through the protocol only (mypy checks the calls against it)."""
    popped = []
    while (event := queue.pop_before(until)) is not None:
        popped.append(event)
    return popped


@pytest.mark.parametrize("cls", ALL_QUEUES)
def test_every_queue_meets_the_protocol(cls: Callable[[int], EventQueueProtocol[str]]) -> None:
    queue = cls(4)
    assert isinstance(queue, EventQueueProtocol)
    for owner, time, payload in [(0, 3.0, "a"), (1, 1.0, "b"), (2, 2.0, "c"), (3, 2.0, "d"), (1, 4.0, "e")]:
        queue.push(owner, time, payload)
    queue.discard(0)
    queue.shift_times(1.0)
    assert len(queue) == 3 and queue.storage() >= 3 and queue.peek() == 1.0
    assert queue.pending(1) == (3.0, "e") and queue.pending(0) == (math.inf, None)
    assert _drain(queue, 1.0) == [(1.0, 2, "c"), (1.0, 3, "d")]
    assert queue.pop() == (3.0, 1, "e") and len(queue) == 0
    queue._check()


def test_the_protocol_names_the_whole_shared_interface() -> None:
    """What all three queues define is in the protocol, and a class that lacks one method does not meet it."""
    shared = set.intersection(*(_methods(cls) for cls in QUEUES))
    assert _methods(EventQueueProtocol) == shared
    for missing in sorted(shared):
        lacking = type("Lacking", (), {n: getattr(EventQueue, n) for n in shared - {missing}})
        assert not isinstance(lacking(), EventQueueProtocol), missing


# --- the compiled event loop's queue: each disc's pending time and a heap of blocks of discs ----------------
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    n=st.integers(1, 200),
    ops=st.lists(
        st.tuples(st.integers(0, 199), st.sampled_from([*(k / 4 for k in range(13)), math.inf, -1.0]), st.booleans()),
        max_size=300,
    ),
)
def test_the_compiled_loops_queue_pops_the_earliest_time_then_the_lowest_disc(n, ops):
    """``push``, ``discard``, a pop and ``reblock`` (after the clock's origin moves) against a dict, with many
    equal times across and within blocks (compiled when numba is there, plain Python otherwise)."""
    from discsim.engines.event_driven.numba import loop as lp

    n_blocks = (n + lp.BLOCK - 1) >> lp.BLOCK_SHIFT
    qt = np.full(n_blocks << lp.BLOCK_SHIFT, np.inf)
    bheap, bht = np.zeros(n_blocks, np.int32), np.zeros(n_blocks)
    bpos, barg = np.zeros(n_blocks, np.int32), np.zeros(n_blocks, np.int32)
    qk, qo, qs, ints = np.zeros(n, np.int8), np.zeros(n, np.int32), np.zeros(n, np.int64), np.zeros(lp.N_INTS, np.int64)
    lp.reblock(qt, bheap, bht, bpos, barg)
    model: dict[int, float] = {}
    for owner, t, pop in ops:
        owner %= n
        if pop and model:
            first = min((time, o) for o, time in model.items())
            assert (float(bht[0]), int(barg[bheap[0]])) == first
            lp.discard(first[1], qt, bheap, bht, bpos, barg, ints)
            del model[first[1]]
        elif t == -1.0:  # the clock's origin moves: every time shifts, ties may appear
            qt -= 0.25
            model = {o: time - 0.25 for o, time in model.items()}
            lp.reblock(qt, bheap, bht, bpos, barg)
        elif t == math.inf:
            lp.discard(owner, qt, bheap, bht, bpos, barg, ints)
            model.pop(owner, None)
        else:
            lp.push(owner, t, 2, owner, 7, qt, bheap, bht, bpos, barg, qk, qo, qs, ints)
            model[owner] = t
            assert (qk[owner], qo[owner], qs[owner]) == (2, owner, 7)
        assert ints[lp.I_SIZE] == len(model)
        assert np.array_equal(np.flatnonzero(qt != np.inf), sorted(model))
        if model:
            assert (float(bht[0]), int(barg[bheap[0]])) == min((time, o) for o, time in model.items())
