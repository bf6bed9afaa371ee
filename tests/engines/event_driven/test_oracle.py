"""The engine against a brute-force O(N^2) oracle, in lock-step, event by event."""

import math

import numpy as np
import pytest
from oracle import next_event

import discsim as ds


def _lockstep_times(sim, steps):
    d = sim.discs
    just_collided = set()
    for _ in range(steps):
        t0 = sim.time
        dt, kind, i, j = next_event(sim.positions, sim.velocities, d.radii, d.masses, sim.box, just_collided)
        event = sim.step()
        if event is None:
            assert dt == math.inf
            return
        assert event.time == pytest.approx(t0 + dt, rel=1e-9, abs=1e-9), (event, t0 + dt, kind, i, j)
        assert event.kind == kind, (event, kind, i, j)
        assert {event.i, event.j} == {i, j}, (event, kind, i, j)
        sim._check()
        just_collided = {frozenset((event.i, event.j))} if event.kind == "collision" else set()


@pytest.mark.slow_on_python  # (4 s interpreted; the numba case stays quick)
@pytest.mark.parametrize("periodic", [False, pytest.param(True, marks=pytest.mark.slow)])  # (periodic: 4 s)
@pytest.mark.parametrize("seed", [0, pytest.param(1, marks=pytest.mark.slow), pytest.param(2, marks=pytest.mark.slow)])
def test_equal_discs_follow_the_oracle(periodic, seed):  # seed 0 quick; 1 and 2 (3 s each) repeat it: slow
    discs, box = ds.random_gas(40, 0.35, periodic=periodic, seed=seed)
    _lockstep_times(ds.EventDriven(discs, box), 300)


@pytest.mark.slow_on_python
@pytest.mark.parametrize("periodic", [False, True])
def test_mixed_radii_masses_and_obstacles_follow_the_oracle(periodic):
    rng = np.random.default_rng(7)
    side = 30.0
    # Place discs of random radii by rejection, a few of them fixed obstacles.
    pos, rad = [], []
    while len(pos) < 30:
        r = rng.uniform(0.4, 1.5)
        p = rng.uniform(r, side - r, size=2)
        if all(np.hypot(*(p - q)) > r + s + 1e-6 for q, s in zip(pos, rad)):
            pos.append(p)
            rad.append(r)
    rad = np.array(rad)
    masses = rng.uniform(0.5, 3.0, size=30)
    masses[:4] = np.inf
    vel = rng.normal(size=(30, 2))
    vel[:4] = 0.0
    discs = ds.Discs(np.array(pos), vel, rad, masses)
    _lockstep_times(ds.EventDriven(discs, ds.Box(side, side, periodic=periodic)), 300)


@pytest.mark.slow_on_python  # (the pure-Python loop's oracle runs cover it: test_equal_discs_follow_the_oracle)
@pytest.mark.parametrize(
    "queue", [pytest.param(q, marks=pytest.mark.slow) for q in ("heap", "sorted")]
)  # (the compiled loop
# has one queue of its own: its two cases run the same events)
def test_dense_gas_follows_the_oracle_with_the_other_queues(queue):
    discs, box = ds.random_gas(36, 0.6, periodic=True, seed=3)
    _lockstep_times(ds.EventDriven(discs, box, queue=queue), 300)


@pytest.mark.slow  # (4 s; the oracle runs above cover the default cells)
def test_large_cells_follow_the_oracle():
    discs, box = ds.random_gas(50, 0.2, periodic=True, seed=4)
    _lockstep_times(ds.EventDriven(discs, box, cell_size=box.width / 3.5), 200)
