"""A large gas's construction holds no needless per-disc copies (issue 32: N = 10^7 discs in under 2 GB).

Figures of the whole path, stage by stage, come from ``benchmarks/memory.py``; these tests pin what the
constructor allocates, with ``tracemalloc`` (numpy's allocations are traced; the count is exact, not timed).
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import discsim as ds
from discsim import _numba
from discsim.engines.event_driven.numbering import fresh_state

N = 50_000  # above numbering.RENUMBER_MIN: the tile numbering runs, as at large N


def _traced_peak_per_disc(discs, box) -> float:
    """Peak bytes per disc that numpy and Python allocated while ``EventDriven`` built the gas."""
    tracemalloc.start()
    try:
        ds.EventDriven(discs, box, backend="numba", record=False)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return peak / len(discs)


@pytest.mark.skipif(not _numba.available(), reason="numba is not installed (the fast extra)")
def test_the_compiled_constructor_peaks_near_what_it_keeps():
    ds.EventDriven(*ds.random_gas(1_000, 0.3, seed=0), backend="numba").run(events=1)  # the loop loaded untraced
    discs, box = ds.random_gas(N, 0.3, seed=0)
    # The backend keeps about 250 bytes a disc (records, queue, cells, counters, the grid's tables). The start
    # state it loads from used to copy the discs and fill its constants (about 150 more), and the load's
    # temporaries came on top: a peak of 459 bytes a disc, 292 now (315 with the grid's table of shifts).
    assert _traced_peak_per_disc(discs, box) < 360


def test_a_read_only_fresh_state_shares_the_discs_and_equals_the_copied_one():
    sim = ds.EventDriven(*ds.random_gas(5_000, 0.3, seed=1), backend="python", record=False)
    shared = fresh_state(sim.scene, sim.grid, read_only=True)
    copied = fresh_state(sim.scene, sim.grid)
    discs = sim.scene.discs
    assert np.shares_memory(shared.ref_positions, discs.positions) and shared.kept_time.strides == (0,)
    assert not np.shares_memory(copied.ref_positions, discs.positions) and copied.kept_time.flags.writeable
    for name in ("ref_positions", "velocities", "ref_times", "images", "collision_counts", "cell", "cell_members"):
        assert np.array_equal(getattr(shared, name), getattr(copied, name)), name
    for name in ("kept_time", "kept_partner", "kept_stamp", "order", "resting", "last_collision", "spins", "angles"):
        assert np.array_equal(getattr(shared, name), getattr(copied, name)), name


@pytest.mark.skipif(not _numba.available(), reason="numba is not installed (the fast extra)")
def test_the_compiled_backend_builds_no_table_of_cell_shifts():
    # The pure-Python predictor's per-cell shifts cost 8 bytes a cell (about 21 a disc) and a Python loop over
    # every cell at construction; the compiled backend never reads them.
    sim = ds.EventDriven(*ds.random_gas(5_000, 0.3, seed=2), backend="numba", record=False)
    sim.run(events=1_000)
    assert "shifts" not in vars(sim.grid)
    assert len(sim.grid.shifts) == len(sim.grid)  # built when asked for
