"""The event-driven engine's public run state, its backend protocol, and unwrapped coordinates."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import discsim as ds
from discsim.errors import CheckpointError
from discsim.events import EVENT_DTYPE
from discsim.trajectory import reconstruct


def test_the_state_is_plain_arrays_and_scalars_and_round_trips():
    sim = ds.EventDriven(*ds.random_gas(300, 0.5, seed=4), queue="heap").run(events=2000)
    state = sim.state()
    scalars, arrays = state.to_arrays()
    assert all(isinstance(v, (int, float)) for v in scalars.values())
    assert all(a.dtype.kind in "fi" and a.dtype.itemsize == 8 for a in arrays.values())
    assert arrays["ref_positions"].shape == (300, 2) and arrays["order"].shape == (300,)
    again = ds.EventDrivenState.from_arrays(scalars, arrays, ds.EventDrivenState.VERSION)
    copy = ds.EventDriven._restore(sim.scene, sim._settings(), again, sim.events, sim.start_time)
    sim.run(events=3000)
    copy.run(events=3000)
    assert copy.events.tobytes() == sim.events.tobytes() and copy.counts == sim.counts
    copy._check()


def test_a_state_of_another_version_or_shape_is_refused():
    scalars, arrays = ds.EventDriven(*ds.random_gas(20, 0.3, seed=1)).state().to_arrays()
    with pytest.raises(CheckpointError, match="version 99"):
        ds.EventDrivenState.from_arrays(scalars, arrays, 99)
    del arrays["images"]
    with pytest.raises(CheckpointError, match="missing \\['images'\\]"):
        ds.EventDrivenState.from_arrays(scalars, arrays, 1)


def test_backends_are_named_and_checked():
    from discsim._numba import available
    from discsim.engines.event_driven import BACKENDS
    from discsim.engines.event_driven.protocol import Backend

    discs, box = ds.random_gas(20, 0.3, seed=1)
    sim = ds.EventDriven(discs, box, backend="python")
    assert sim.backend == "python"
    for name, make_backend in BACKENDS.items():  # each meets the protocol the front class uses, once started
        if name == "numba" and not available():
            continue
        backend = make_backend(sim.scene, sim.grid, "calendar")
        backend.start()
        assert isinstance(backend, Backend)
    with pytest.raises(ds.InvalidArgumentError, match="backend must be 'auto' or one of"):
        ds.EventDriven(discs, box, backend=["python"])
    with pytest.raises(ds.InvalidArgumentError, match="one of \\['numba', 'python'\\], got 'fortran'"):
        ds.EventDriven(discs, box, backend="fortran")


@pytest.mark.parametrize("n", [60, 5000])
def test_unwrapped_positions_follow_the_discs_across_the_edges(n):
    discs, box = ds.random_gas(n, 0.3, seed=5)
    sim = ds.EventDriven(discs, box).run(events=4 * n)
    unwrapped = sim.unwrapped_positions
    assert np.array_equal(box.wrap(unwrapped) % box.size, sim.positions % box.size) or np.allclose(
        box.minimum_image(box.wrap(unwrapped) - sim.positions), 0.0, atol=1e-9
    )
    assert (np.abs(unwrapped - sim.positions) > 0.5 * box.size).any()  # some disc went round
    from_log = sim.trajectory([sim.time], unwrapped=True)[0]
    assert np.allclose(from_log, unwrapped, rtol=0, atol=1e-9)
    # Continuous: between samples a disc moves at most (its fastest speed) x (the spacing).
    times = np.linspace(0.0, sim.time, 400)
    path = sim.trajectory(times, unwrapped=True)
    log = sim.events
    speed = max(np.abs(log[name]).max() for name in ("vxi", "vyi", "vxj", "vyj"))
    speed = max(speed, np.abs(discs.velocities).max())
    assert np.abs(np.diff(path, axis=0)).max() <= speed * (times[1] - times[0]) * (1 + 1e-9) + 1e-9


def test_unwrapped_positions_survive_save_and_load(tmp_path):
    sim = ds.EventDriven(*ds.random_gas(80, 0.3, seed=6)).run(until=30.0)
    copy = ds.load(sim.save(tmp_path / "s.dsc"))
    assert copy.unwrapped_positions.tobytes() == sim.unwrapped_positions.tobytes()


def test_walled_boxes_have_nothing_to_unwrap():
    sim = ds.EventDriven(*ds.random_gas(60, 0.3, periodic=False, seed=7)).run(until=5.0)
    assert np.array_equal(sim.unwrapped_positions, sim.positions)
    assert np.array_equal(sim.trajectory([1.0, 5.0], unwrapped=True), sim.trajectory([1.0, 5.0]))


def test_a_position_a_hair_below_zero_wraps_into_the_box_not_onto_its_far_edge():
    box = ds.Box(10.0, 10.0, periodic=True)
    events = np.zeros(0, dtype=EVENT_DTYPE)
    at = reconstruct(events, np.array([[0.0, 5.0]]), np.array([[-1.0, 0.0]]), 0.0, [1e-17], box)
    assert 0.0 <= at[0, 0, 0] < box.width


@settings(max_examples=25, deadline=None)
@given(x=st.floats(-1e3, 1e3), y=st.floats(-1e3, 1e3))
def test_box_wrap_lands_in_the_half_open_box(x, y):
    box = ds.Box(3.0, 7.0, periodic=True)
    wrapped = box.wrap(np.array([[x, y]]))[0]
    assert 0.0 <= wrapped[0] < 3.0 and 0.0 <= wrapped[1] < 7.0
    assert np.allclose(box.minimum_image(wrapped - [x, y]), 0.0, atol=1e-9)
