"""``FixedStep.pressure()``: the virial of the impulses the frames apply, defined as ``EventDriven.pressure()``.

``P = (N kT + W / (2 t)) / A``, ``W`` the sum over the disc-disc impulses of ``dp_i . (r_i - r_j)`` where
the impulse is applied; wall hits are not counted (the bulk estimate, as for the event-driven engine).
Pinned by closed forms (one head-on collision per policy, an obstacle, an ideal gas bouncing off walls), by
the event log (``thermo()`` rebuilds ``W`` from the logged states on its own), across backends and
checkpoints (old files included), and statistically: at a small step every policy's ``Z`` agrees with the
event-driven engine's and with Henderson's equation of state.

Every test runs once per backend (this folder's conftest); those that pit backends or replicas against
each other pick their own.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from paths import ROOT

import discsim as ds
from discsim import _numba
from discsim.engines.fixed_step.engine import COMPILED_POLICIES, POLICIES, SUB_FRAME_POLICIES

FIXTURES = ROOT / "tests" / "fixtures"
needs_numba = pytest.mark.skipif(not _numba.available(), reason="numba is not installed (the fast extra)")


def head_on(masses=(1.0, 3.0)):
    """Two discs of radius 1, 6 apart, closing at speed 2 in a 20 x 10 box: contact at t = 2 exactly."""
    discs = ds.Discs([[6.0, 5.0], [12.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0, masses=list(masses))
    return discs, ds.Box(20.0, 10.0)


# --- closed forms ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("policy", POLICIES)
def test_one_head_on_collision_gives_the_pressure_in_closed_form(policy):
    discs, box = head_on()
    # Frames every 0.25: at t = 2.0 the discs just touch (no overlap); "resolve" finds them at 2.25, 1.5 apart,
    # and applies the impulse there; "revert" goes back to 2.0 (touching), "separate" pushes them to touch,
    # "bisect" and "swept" answer at the contact.
    sim = ds.FixedStep(discs, box, dt=0.25, policy=policy).run(until=4.0)
    assert sim.counts["detections"] == 1 and sim.counts["wall_hits"] == 0
    separation = 1.5 if policy == "resolve" else 2.0
    impulse = 2.0 * (1.0 * 3.0 / 4.0) * 2.0  # 2 mu v_n: reduced mass 3/4, closing speed 2
    energy = 0.5 * 1.0 + 0.5 * 3.0  # N kT: the kinetic energy, unchanged by the elastic impulse
    expected = (energy + impulse * separation / (2.0 * 4.0)) / box.area
    if policy == "bisect":  # the last time found without overlap: up to 2 * bisect_tol before the contact
        assert expected <= sim.pressure() <= expected * (1.0 + 1e-6)
    else:
        assert sim.pressure() == pytest.approx(expected, rel=1e-15, abs=0.0)
    assert ds.compressibility_factor(sim) == pytest.approx(expected * box.area / energy, rel=1e-6)
    assert ds.EventDriven(discs, box).run(until=4.0).pressure() == pytest.approx(
        (energy + impulse * 2.0 / 8.0) / box.area, rel=1e-15
    )


@pytest.mark.parametrize("policy", ["resolve", "separate"])
@pytest.mark.parametrize("obstacle_first", [True, False])
def test_a_disc_hitting_an_obstacle_gives_its_momentum_twice(policy, obstacle_first):
    """An obstacle (infinite mass) takes ``dp = 2 m v``; the virial is counted from the moving disc either way."""
    rows = [([12.0, 5.0], [0.0, 0.0], math.inf), ([6.0, 5.0], [1.0, 0.0], 2.0)]
    if not obstacle_first:
        rows.reverse()
    positions, velocities, masses = zip(*rows)
    discs = ds.Discs(list(positions), list(velocities), radii=1.0, masses=list(masses))
    box = ds.Box(20.0, 10.0)
    sim = ds.FixedStep(discs, box, dt=0.25, policy=policy).run(until=6.0)  # touching at 4.0, found at 4.25
    assert sim.counts["detections"] == 1
    separation = 1.75 if policy == "resolve" else 2.0
    assert sim.pressure() == pytest.approx((1.0 + 2.0 * 2.0 * 1.0 * separation / 12.0) / box.area, rel=1e-15)


@pytest.mark.parametrize("policy", POLICIES)
def test_wall_hits_add_nothing_so_an_ideal_gas_has_p_a_equal_to_n_kt(policy):
    discs = ds.Discs([[3.0, 3.0], [7.0, 6.0]], [[2.3, 1.1], [-1.7, 0.4]], radii=0.5, groups=[1, 1])
    sim = ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.1, policy=policy, pass_through={(1, 1)}).run(until=20.0)
    assert sim.counts["wall_hits"] > 10 and sim.counts["detections"] == 0
    assert sim.pressure() * 100.0 == pytest.approx(sim.kinetic_energy(), rel=1e-15)


def test_pressure_refuses_a_run_of_no_duration():
    discs, box = head_on()
    with pytest.raises(ds.InvalidArgumentError, match="positive duration"):
        ds.FixedStep(discs, box, dt=0.25).pressure()


# --- the log, the backends, checkpoints -----------------------------------------------------------------------
def gas(periodic: bool, seed: int = 3):
    """A mixture (radii 1 and 0.7, masses 0.5 to 3) with coarse frames: many overlaps, some deep."""
    discs, box = ds.random_gas(150, 0.4, periodic=periodic, seed=seed)
    rng = np.random.default_rng(seed)
    radii = discs.radii * np.where(np.arange(len(discs)) % 2, 0.7, 1.0)
    return ds.Discs(discs.positions, discs.velocities, radii, rng.uniform(0.5, 3.0, len(discs))), box


@pytest.mark.parametrize("policy", POLICIES)
@pytest.mark.parametrize("periodic", [True, False])
def test_the_virial_is_the_one_the_event_log_holds(policy, periodic):
    """``thermo()`` rebuilds ``W`` from the logged states alone (``2 mu (u_i - u_j) . (r_i - r_j)``)."""
    discs, box = gas(periodic)
    sim = ds.FixedStep(discs, box, dt=0.05, policy=policy).run(until=4.0)
    assert sim.counts["detections"] > 100
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ds.EquilibrationWarning)  # from t = 0: the start melts
        averages = ds.thermo(sim)
    # thermo's P is the canonical N kT + W / (2t) over A (issue 29); the mechanical one counts K instead, which
    # is (N - 1) kT plus the kinetic energy of the centre of mass where momentum is conserved.
    p, mass = sim.momentum(), float(np.sum(sim.discs.masses))
    shift = (ds.analysis.thermo.kinetic_temperature(sim) - p @ p / (2 * mass)) / box.area if periodic else 0.0
    assert averages.pressure == pytest.approx(sim.pressure() + shift, rel=1e-12)


def _pits_the_backends(case: str) -> None:
    if case == "python":  # this folder runs each test per backend; the python case hides numba
        pytest.skip("the numba case runs both backends")


@needs_numba
@pytest.mark.parametrize("policy", COMPILED_POLICIES)
@pytest.mark.parametrize("periodic", [True, False])
def test_both_backends_give_the_same_virial_bit_for_bit(policy, periodic, every_backend):
    _pits_the_backends(every_backend)
    discs, box = gas(periodic)
    runs = [ds.FixedStep(discs, box, dt=0.05, policy=policy, backend=b).run(until=4.0) for b in ("python", "numba")]
    assert [sim.backend for sim in runs] == ["python", "numba"]
    virials = [sim.state().virial for sim in runs]
    assert virials[0] > 0.0 and virials[0] == virials[1]
    assert runs[0].pressure() == runs[1].pressure()


@pytest.mark.parametrize("policy", POLICIES)
def test_the_virial_survives_save_load_and_resume(tmp_path, policy):
    discs, box = gas(periodic=policy != "revert")
    whole = ds.FixedStep(discs, box, dt=0.05, policy=policy).run(until=3.0)
    half = ds.FixedStep(discs, box, dt=0.05, policy=policy).run(until=1.4)
    loaded = ds.load(half.save(tmp_path / "half.dsc"))
    assert loaded.state().virial == half.state().virial > 0.0
    assert loaded.run(until=3.0).state().virial == whole.state().virial
    assert loaded.pressure() == whole.pressure()

    class Crash(Exception):
        pass

    def crash(sim, events):
        if sim.frames >= 37:
            raise Crash

    crashed = ds.FixedStep(discs, box, dt=0.05, policy=policy)
    with pytest.raises(Crash):
        crashed.run(until=3.0, checkpoint=tmp_path / "state.dsc", checkpoint_every=15, observers=[ds.Callback(crash)])
    resumed = ds.resume(tmp_path / "state.dsc")
    assert resumed.state().virial == whole.state().virial and resumed.pressure() == whole.pressure()


@needs_numba
@pytest.mark.parametrize(("first", "second"), [("python", "numba"), ("numba", "python")])
def test_a_checkpoint_carries_the_virial_from_one_backend_to_the_other(tmp_path, first, second, every_backend):
    _pits_the_backends(every_backend)
    discs, box = gas(periodic=True)
    whole = ds.FixedStep(discs, box, dt=0.05, policy="separate", backend=second).run(until=3.0)
    half = ds.FixedStep(discs, box, dt=0.05, policy="separate", backend=first).run(until=1.4)
    copy = ds.load(half.save(tmp_path / "half.dsc"), backend=second).run(until=3.0)
    assert copy.state().virial == whole.state().virial


def _fixture_run(name: str):
    """The run each version 1 fixture holds, redone by today's code (the frames have not changed since)."""
    if name == "logged":
        discs, box = ds.random_gas(60, 0.3, seed=11)
        return ds.FixedStep(discs, box, dt=0.02, policy="resolve")
    discs, box = ds.random_gas(60, 0.3, seed=12, periodic=False)
    return ds.FixedStep(discs, box, dt=0.02, policy="separate", record=False)


def test_a_checkpoint_from_before_the_virial_gets_it_back_from_its_log():
    """``fs_state_v1_*.dsc``: FixedStep runs to t = 1 saved by discsim at commit 02c78e8 (state version 1)."""
    old = ds.load(FIXTURES / "fs_state_v1_logged.dsc")
    fresh = _fixture_run("logged").run(until=1.0)
    assert old.time == fresh.time == 1.0 and old.counts == fresh.counts
    assert old.state().virial == pytest.approx(fresh.state().virial, rel=1e-12)  # from the log's states
    old.run(until=2.0)
    fresh.run(until=2.0)
    assert old.positions.tobytes() == fresh.positions.tobytes()
    assert old.pressure() == pytest.approx(fresh.pressure(), rel=1e-12)


def test_a_checkpoint_from_before_the_virial_without_a_log_goes_on_but_names_the_unknown_pressure(tmp_path):
    old = ds.load(FIXTURES / "fs_state_v1_unlogged.dsc")
    assert math.isnan(old.state().virial)
    fresh = _fixture_run("unlogged").run(until=2.0)
    old.run(until=2.0)
    assert old.positions.tobytes() == fresh.positions.tobytes() and old.counts == fresh.counts
    again = ds.load(old.save(tmp_path / "again.dsc"))  # written as version 2, the virial still unknown
    for sim in (old, again):
        with pytest.raises(ds.InvalidArgumentError, match="before FixedStep counted its collision virial"):
            sim.pressure()
        with pytest.raises(ds.InvalidArgumentError, match="before FixedStep counted"):
            ds.compressibility_factor(sim)


# --- statistics: a small step gives the hard-disc pressure ------------------------------------------------------
N, PACKING, REPLICAS = 400, 0.3, 8


def _replica_z(engine, seed: int, until: float, **options) -> float:
    discs, box = ds.random_gas(N, PACKING, seed=seed)
    return ds.compressibility_factor(engine(discs, box, record=False, **options).run(until=until))


_EVENT_DRIVEN: dict[float, np.ndarray] = {}


def _event_driven_z(until: float) -> np.ndarray:
    if until not in _EVENT_DRIVEN:
        _EVENT_DRIVEN[until] = np.array([_replica_z(ds.EventDriven, 500 + k, until) for k in range(REPLICAS)])
    return _EVENT_DRIVEN[until]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("policy", "dt", "until"),
    [(p, 0.002, 100.0) for p in POLICIES if p not in SUB_FRAME_POLICIES]
    + [("bisect", 0.05, 50.0), ("swept", 0.05, 50.0)],
)
def test_a_small_step_gives_the_event_driven_z_and_hendersons(policy, dt, until, every_backend):
    """N = 400 at packing 0.3, periodic: ``REPLICAS`` independent gases per engine (the same seeds), each
    ``Z`` over its whole run; the error bar is the spread between replicas (independent by construction,
    unlike batch means, which the box's slow sound modes fool), and the test allows 4 standard errors of
    the difference plus the policy's own bias (``"resolve"`` applies its impulses at the overlap depth of
    detection, ``v dt / 2`` or about 0.1 % of ``W`` here).
    """
    if every_backend == "python" and policy in COMPILED_POLICIES:
        pytest.skip("the numba case measures it (the backends give the same frames bit for bit)")
    replicas = REPLICAS if policy not in SUB_FRAME_POLICIES else 6  # the sub-frame policies: fewer, shorter
    fixed = np.array([_replica_z(ds.FixedStep, 500 + k, until, dt=dt, policy=policy) for k in range(replicas)])
    exact = _event_driven_z(until)[:replicas]
    se = math.hypot(fixed.std(ddof=1), exact.std(ddof=1)) / math.sqrt(replicas)
    assert se < 0.01  # the replicas measure Z to better than 0.5 %: the test can fail
    bias = 0.003
    assert abs(fixed.mean() - exact.mean()) < 4.0 * se + bias, (fixed, exact)
    henderson = ds.henderson_z(PACKING)
    assert abs(fixed.mean() - henderson) < 4.0 * fixed.std(ddof=1) / math.sqrt(replicas) + bias + 0.005, fixed
