"""The energy each logged event took (``sim.event_losses()``, issue 27 item 2's "the log"): closed forms, and
summed, ``dissipated`` (both backends), under gravity and rest, roughness and drag."""

import numpy as np
import pytest

import discsim as ds
from discsim.errors import InvalidArgumentError

BOX = ds.Box(10.0, 10.0)


@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_a_head_on_collision_loses_one_minus_e_squared_of_the_relative_energy(every_backend, e):
    discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.5, 0.0], [-0.5, 0.0]], radii=1.0, masses=[1.0, 3.0])
    sim = ds.EventDriven(discs, BOX, restitution=e).run(until=2.5)
    mu, w = 3.0 / 4.0, 2.0  # reduced mass, closing speed
    assert sim.event_losses() == pytest.approx([0.5 * mu * w * w * (1 - e * e)], abs=1e-14)


def test_summed_they_are_what_a_settling_inelastic_pile_dissipated(every_backend):
    rng = np.random.default_rng(2)
    xs, ys = np.meshgrid(np.arange(1.5, 9.0, 2.1), np.arange(1.5, 9.0, 2.1))
    pos = np.column_stack([xs.ravel(), ys.ravel()])
    discs = ds.Discs(pos, rng.normal(size=pos.shape), radii=0.9)
    sim = ds.EventDriven(discs, BOX, gravity=(0.0, -9.81), restitution=0.6, tc=1e-4).run(until=20.0)
    losses = sim.event_losses()
    assert sim.resting.all()
    assert losses.shape == sim.events.shape and (losses >= -1e-12).all()
    assert losses.sum() == pytest.approx(sim.dissipated, rel=1e-9)


def test_summed_they_count_the_spins_of_a_rough_gas(every_backend):
    discs, box = ds.random_gas(40, 0.3, seed=3, periodic=False)
    sim = ds.EventDriven(discs, box, roughness=0.3, restitution=0.9).run(events=800)
    assert sim.event_losses().sum() == pytest.approx(sim.dissipated, rel=1e-9)


def test_under_drag_they_leave_out_what_the_drag_took(every_backend):
    discs, box = ds.random_gas(40, 0.3, seed=3, periodic=False)
    elastic = ds.EventDriven(discs, box, drag=0.1).run(events=500)
    assert np.abs(elastic.event_losses()).max() < 1e-12 and elastic.dissipated > 0.1
    inelastic = ds.EventDriven(discs, box, drag=0.1, restitution=0.8).run(events=500)
    assert 0.0 < inelastic.event_losses().sum() < inelastic.dissipated


def test_they_need_the_log():
    sim = ds.EventDriven(ds.Discs([[5.0, 5.0]], [[1.0, 0.0]], 1.0), BOX, record=False).run(until=1.0)
    with pytest.raises(InvalidArgumentError, match="record=True"):
        sim.event_losses()
