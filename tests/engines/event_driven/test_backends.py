"""The backends side by side: the same events bit for bit, checkpoints that move between them, the choice.

The rest of the engine's suite runs once per backend (``every_backend``, autouse in this folder's
conftest); the tests here pit the two against each other and need both, so they skip without numba.
"""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys

import numpy as np
import pytest
from paths import GOLDEN, ROOT

import discsim as ds
from discsim import _numba

needs_numba = pytest.mark.skipif(not _numba.available(), reason="numba is not installed (the fast extra)")


@pytest.fixture(autouse=True)
def _each_backend():
    """Overrides the folder's per-backend fixture: these tests pick their backends themselves."""


def _both(discs, box, run, **options):
    """The same scene run under both backends."""
    a = ds.EventDriven(discs, box, backend="python", **options)
    b = ds.EventDriven(discs, box, backend="numba", **options)
    return run(a), run(b)


def assert_identical(a, b):
    """Same events, state and counters, bit for bit."""
    assert a.events.tobytes() == b.events.tobytes()
    assert a.time == b.time and a.counts == b.counts and a.max_queue == b.max_queue
    assert a.positions.tobytes() == b.positions.tobytes()
    assert a.velocities.tobytes() == b.velocities.tobytes()
    assert a.unwrapped_positions.tobytes() == b.unwrapped_positions.tobytes()
    sa, sb = a.state(), b.state()
    for field in (f.name for f in dataclasses.fields(sa)):
        x, y = getattr(sa, field), getattr(sb, field)
        assert np.array_equal(x, y, equal_nan=True) if isinstance(x, np.ndarray) else x == y, field


# --- the choice of backend ----------------------------------------------------------------------------
def test_auto_takes_numba_when_it_imports(monkeypatch):
    discs, box = ds.random_gas(30, 0.3, seed=1)
    expected = "numba" if _numba.available() else "python"
    monkeypatch.setattr(_numba, "AUTO_PYTHON_EVENTS", 0)  # (a short run's "auto": see the tests below)
    assert ds.EventDriven(discs, box).backend == expected
    monkeypatch.setattr(_numba, "_module", None)
    monkeypatch.setattr(_numba, "_tried", True)
    assert ds.EventDriven(discs, box).backend == "python"
    with pytest.raises(ds.InvalidArgumentError, match=r'backend=.numba. needs numba.*pip install "discsim\[fast\]"'):
        ds.EventDriven(discs, box, backend="numba")


def test_hiding_numba_by_the_environment_gives_the_python_backend():
    code = (
        "import discsim as ds\n"
        "print(ds.EventDriven(*ds.random_gas(20, 0.3, seed=1)).backend)\n"
        "try:\n    ds.EventDriven(*ds.random_gas(20, 0.3, seed=1), backend='numba')\n"
        "except ds.InvalidArgumentError as e:\n    print(e)\n"
    )
    env = {**os.environ, "DISCSIM_NO_NUMBA": "1"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT, check=True)
    first, second = out.stdout.splitlines()
    assert first == "python"
    assert "hidden by DISCSIM_NO_NUMBA" in second and "discsim[fast]" in second


def test_a_short_auto_run_does_not_load_numba():
    """The README's five-liner under "auto" in a fresh process: importing numba and loading the compiled loop
    from its cache cost it about a second (more than the run), so its 10,000 events run in pure Python."""
    code = (
        "import sys, discsim as ds\n"
        "sim = ds.EventDriven(*ds.random_gas(1000, 0.4, periodic=True, seed=0)).run(until=10.0)\n"
        "print(sim.backend, 'numba' in sys.modules, sim.counts['collisions'] < 20_000)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "DISCSIM_NO_NUMBA"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT, check=True)
    assert out.stdout.split() == ["python", "False", "True"]


@pytest.fixture
def fresh_auto(monkeypatch):
    """A process that has not loaded the compiled loop, with "auto" switching after 3,000 events."""
    monkeypatch.setattr(_numba, "_loaded", False)
    monkeypatch.setattr(_numba, "AUTO_PYTHON_EVENTS", 3000)


@needs_numba
@pytest.mark.parametrize("periodic", [True, False])
@pytest.mark.parametrize("how", ["until", "events", "steps"])
def test_auto_takes_the_compiled_loop_mid_run_with_the_same_events(fresh_auto, periodic, how):
    discs, box = ds.random_gas(400, 0.5, periodic=periodic, seed=8)
    auto = ds.EventDriven(discs, box)
    assert auto.backend == "python"
    reference = ds.EventDriven(discs, box, backend="python")
    for sim in (auto, reference):
        if how == "until":
            sim.run(until=12.0)  # about 10,000 events
        elif how == "events":
            sim.run(events=10_000)  # no time limit: the open-ended loop
        else:
            sim.run(events=2990)
            for _ in range(20):  # one event at a time across the switch
                sim.step()
            sim.run(events=5000)
    assert auto.backend == "numba" and auto.counts["collisions"] > 3000
    assert_identical(auto, reference)
    auto._check()
    # the process has loaded the compiled loop now: the next "auto" engine takes it at once
    assert ds.EventDriven(discs, box).backend == "numba"


@needs_numba
def test_auto_takes_the_compiled_loop_at_once_for_many_discs(fresh_auto, monkeypatch):
    discs, box = ds.random_gas(400, 0.5, seed=8)
    assert ds.EventDriven(discs, box).backend == "python"
    monkeypatch.setattr(_numba, "AUTO_NUMBA_DISCS", 400)
    assert ds.EventDriven(discs, box).backend == "numba"


def test_an_auto_run_saved_and_loaded_stays_auto(fresh_auto, tmp_path):
    discs, box = ds.random_gas(400, 0.5, seed=8)
    whole = ds.EventDriven(discs, box, backend="python").run(events=8000)
    half = ds.EventDriven(discs, box).run(events=2000)
    copy = ds.load(half.save(tmp_path / "half.dsc"))
    assert copy._settings()["backend"] == "auto" and copy.backend == "python"
    copy.run(events=6000)  # 3,000 more in Python, then compiled where numba is installed
    assert copy.backend == ("numba" if _numba.available() else "python")
    assert_identical(whole, copy)


# --- the same events -----------------------------------------------------------------------------------
@needs_numba
@pytest.mark.parametrize("periodic", [True, False])
@pytest.mark.parametrize("packing", [0.3, 0.7])
def test_the_first_ten_thousand_events_of_a_gas_are_identical(periodic, packing):
    discs, box = ds.random_gas(1000, packing, periodic=periodic, seed=11)
    a, b = _both(discs, box, lambda s: s.run(events=10_000))
    assert_identical(a, b)
    b._check()


@needs_numba
@pytest.mark.parametrize("periodic", [True, False])
def test_a_one_to_ten_mixture_gives_identical_events(periodic):
    """Cells a large disc wide hold ten small discs each: the compiled scan's early test of a hit."""
    discs, box = ds.random_gas(1000, 0.08, periodic=periodic, seed=5, radii=[1.0, 10.0], fractions=[0.9, 0.1])
    a, b = _both(discs, box, lambda s: s.run(events=10_000))
    assert a.counts["collisions"] > 5000
    assert_identical(a, b)
    b._check()


@needs_numba
def test_every_feature_gives_identical_events():
    """Segments, pass-through groups, obstacles, radii and masses of any mix, in one walled scene."""
    rng = np.random.default_rng(3)
    gas, box = ds.random_gas(400, 0.25, periodic=False, seed=4)
    w, h = box.width, box.height
    segments = [ds.Segment((0.2 * w, 0.5 * h), (0.45 * w, 0.5 * h)), ds.Segment((0.7 * w, 0.1 * h), (0.7 * w, 0.3 * h))]
    clear = np.all([s.distance(gas.positions) > gas.radii + 1e-9 for s in segments], axis=0)
    n = int(clear.sum())
    radii = np.where(np.arange(n) % 3 == 0, 0.5 * gas.radii[clear], gas.radii[clear])
    masses = rng.uniform(0.5, 3.0, n)
    masses[::37] = np.inf
    velocities = np.where(np.isinf(masses)[:, None], 0.0, gas.velocities[clear])
    discs = ds.Discs(gas.positions[clear], velocities, radii, masses, np.arange(n) % 4)
    run = lambda s: s.run(events=20_000)  # noqa: E731
    a, b = _both(discs, box, run, segments=segments, pass_through={(1, 1), (2, 3)})
    assert a.counts["collisions"] > 1000 and a.counts["wall_hits"] > 100
    assert_identical(a, b)


@needs_numba
def test_a_large_renumbered_system_and_epoch_moves_are_identical():
    discs, box = ds.random_gas(5000, 0.4, periodic=True, seed=2)
    a = ds.EventDriven(discs, box, backend="python")
    b = ds.EventDriven(discs, box, backend="numba")
    a._backend._rebase_every = b._backend._rebase_every = 3001
    for sim in (a, b):
        sim.run(events=20_000)
    assert not np.array_equal(a.state().order, np.arange(5000))
    assert a.state().epoch > 0
    assert_identical(a, b)


@needs_numba
@pytest.mark.parametrize("name", sorted(n for n in os.listdir(GOLDEN) if n.startswith("ed_") and "5000" not in n))
def test_golden_scenes_under_numba(name, monkeypatch):
    """The golden logs recorded before the redesign, replayed by the compiled loop."""
    import importlib.util

    monkeypatch.setattr(_numba, "AUTO_PYTHON_EVENTS", 0)  # "auto" compiled from the first event

    spec = importlib.util.spec_from_file_location("make_golden", GOLDEN / "make_golden.py")
    make_golden = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make_golden)
    engine, build, how = make_golden.all_scenes()[name.removesuffix(".npz")]
    sim = make_golden.run_scene(engine, build, how)  # backend="auto": numba here
    assert sim.backend == "numba"
    golden = np.load(GOLDEN / name)
    assert sim.positions.tobytes() == golden["positions"].tobytes()
    assert sim.time == float(golden["time"]) and len(sim.events) == int(golden["n_events"])


# --- checkpoints move between backends -----------------------------------------------------------------
@needs_numba
@pytest.mark.parametrize(("first", "second"), [("python", "numba"), ("numba", "python")])
def test_a_run_saved_under_one_backend_goes_on_under_the_other(tmp_path, first, second):
    discs, box = ds.random_gas(800, 0.5, periodic=True, seed=6)
    whole = ds.EventDriven(discs, box, backend=second).run(until=6.0)
    half = ds.EventDriven(discs, box, backend=first).run(until=3.0)
    copy = ds.load(half.save(tmp_path / "half.dsc"), backend=second)
    assert copy.backend == second
    copy.run(until=6.0)
    assert_identical(whole, copy)
    assert ds.load(tmp_path / "half.dsc").backend == first  # by default, the backend that wrote it


def test_load_refuses_an_unknown_backend(tmp_path):
    discs, box = ds.random_gas(50, 0.3, seed=6)
    path = ds.EventDriven(discs, box).run(events=10).save(tmp_path / "a.dsc")
    with pytest.raises(ds.InvalidArgumentError, match="got 'fortran'"):
        ds.load(path, backend="fortran")


# --- exact analytic cases at scale ---------------------------------------------------------------------
def _pi_billiard(k: int, backend: str) -> int:
    """Galperin's billiard: collisions of a unit block between a wall and a block 100^k times heavier."""
    discs = ds.Discs([[2.0, 1.0], [4.0, 1.0]], [[0.0, 0.0], [-1.0, 0.0]], radii=0.5, masses=[1.0, 100.0**k])
    sim = ds.EventDriven(discs, ds.Box(1e4, 2.0), backend=backend, record=False).run(until=200.0)
    assert sim.velocities[1, 0] > sim.velocities[0, 0] >= 0.0  # both leave the wall, the heavy one faster
    return sim.counts["collisions"] + sim.counts["wall_hits"]


@pytest.mark.parametrize("k", [0, 1, 2, 3, 4])
def test_galperin_counts_the_digits_of_pi(k, every_backend):
    assert _pi_billiard(k, every_backend) == int(str(314159265)[: k + 1])


@needs_numba
def test_galperin_counts_314159_with_the_compiled_backend():
    assert _pi_billiard(5, "numba") == 314159
