"""The fixed-step backends side by side: the same frames bit for bit, checkpoints that move between them, the choice.

The rest of the fixed-step suite runs once per backend (``every_backend``, autouse in this folder's conftest);
the tests here pit the compiled frame against the Python one and need both, so they skip without numba.
"""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys

import numpy as np
import pytest

import discsim as ds
from discsim import _numba
from discsim.engines.fixed_step.engine import COMPILED_POLICIES

needs_numba = pytest.mark.skipif(not _numba.available(), reason="numba is not installed (the fast extra)")


@pytest.fixture(autouse=True)
def _each_backend():
    """Overrides the folder's per-backend fixture: these tests pick their backends themselves."""


def _hide_numba(monkeypatch):
    monkeypatch.setattr(_numba, "_module", None)
    monkeypatch.setattr(_numba, "_tried", True)


def _mixture(n, packing, periodic, seed, obstacles=0):
    """Three radii, random masses, ``obstacles`` fixed discs, groups 0-2."""
    discs, box = ds.random_gas(n, packing, periodic=periodic, seed=seed)
    rng = np.random.default_rng(seed)
    radii = discs.radii * np.array([1.0, 0.6, 0.8])[np.arange(n) % 3]
    masses = rng.uniform(0.5, 3.0, n)
    velocities = np.array(discs.velocities) * 3.0
    masses[:obstacles] = np.inf
    velocities[:obstacles] = 0.0
    return ds.Discs(discs.positions, velocities, radii, masses, groups=np.arange(n) % 3), box


def walled():
    """A walled mixture with obstacles, a triangle of segments and two groups passing through each other."""
    discs, box = _mixture(150, 0.4, False, 1, obstacles=4)
    w, h = box.width, box.height
    segments = ds.polygon([(0.3 * w, 0.3 * h), (0.7 * w, 0.3 * h), (0.5 * w, 0.7 * h)])
    keep = np.ones(len(discs), dtype=bool)
    for segment in segments:
        keep &= segment.distance(discs.positions) > discs.radii * 1.01
    discs = ds.Discs(*(a[keep] for a in (discs.positions, discs.velocities, discs.radii, discs.masses, discs.groups)))
    return discs, box, {"segments": segments, "pass_through": {(0, 1)}, "dt": 0.05}


def periodic():
    """A dense periodic mixture with large frames: many pairs overlap at once, some discs in several."""
    discs, box = _mixture(300, 0.55, True, 2, obstacles=3)
    return discs, box, {"pass_through": {(2, 2)}, "dt": 0.04}


def large():
    """Enough discs for a grid of many cells (and a list longer than its first guess)."""
    discs, box = ds.random_gas(3000, 0.45, periodic=True, seed=3)
    return discs, box, {"dt": 0.02}


SCENES = {"walled": walled, "periodic": periodic, "large": large}


def assert_identical(a, b):
    """Same log, state and counters, bit for bit."""
    assert a.events.tobytes() == b.events.tobytes()
    assert a.time == b.time and a.frames == b.frames
    assert a.counts == b.counts and a.max_overlap == b.max_overlap
    assert a.positions.tobytes() == b.positions.tobytes()
    assert a.velocities.tobytes() == b.velocities.tobytes()
    assert a.unwrapped_positions.tobytes() == b.unwrapped_positions.tobytes()
    sa, sb = a.state(), b.state()
    for field in (f.name for f in dataclasses.fields(sa)):
        x, y = getattr(sa, field), getattr(sb, field)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes(), field
        else:
            assert x == y, field


# --- the same frames -----------------------------------------------------------------------------------
@needs_numba
@pytest.mark.parametrize("broad_phase", ["grid", "all-pairs"])
@pytest.mark.parametrize("policy", COMPILED_POLICIES)
@pytest.mark.parametrize("scene", ["walled", "periodic"])
def test_both_backends_give_the_same_frames_bit_for_bit(scene, policy, broad_phase):
    discs, box, options = SCENES[scene]()
    runs = [
        ds.FixedStep(discs, box, policy=policy, broad_phase=broad_phase, backend=backend, **options).run(frames=120)
        for backend in ("python", "numba")
    ]
    assert [sim.backend for sim in runs] == ["python", "numba"]
    assert runs[0].counts["detections"] > 100 and runs[0].max_overlap > 0.0
    if scene == "walled":
        assert runs[0].counts["wall_hits"] > 10
    assert_identical(*runs)


@needs_numba
@pytest.mark.parametrize("policy", COMPILED_POLICIES)
def test_a_large_gas_gives_the_same_frames_and_the_same_verlet_list(policy):
    discs, box, options = large()
    runs = [ds.FixedStep(discs, box, policy=policy, backend=b, **options).run(frames=40) for b in ("python", "numba")]
    assert runs[0].counts["list_builds"] >= 2
    assert_identical(*runs)


@needs_numba
def test_step_gives_the_python_frames_events_and_a_batch_of_frames_equals_single_frames():
    discs, box, options = walled()
    python = ds.FixedStep(discs, box, policy="separate", backend="python", **options)
    numba = ds.FixedStep(discs, box, policy="separate", backend="numba", **options)
    batched = ds.FixedStep(discs, box, policy="separate", backend="numba", **options)
    seen = 0
    for _ in range(60):
        events = python.step()
        assert numba.step() == events
        seen += len(events)
    assert seen > 20
    batched.run(frames=60)  # many frames per compiled call
    assert_identical(python, numba)
    assert_identical(python, batched)


@needs_numba
def test_one_disc_and_two_discs_run_alike():
    for discs in (
        ds.Discs([[3.0, 1.0]], [[2.0, 0.7]], 0.5),
        ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [0.0, 0.0]], radii=1.0, masses=[1.0, math.inf]),
    ):
        runs = [ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.3, backend=b).run(until=20.0) for b in ("python", "numba")]
        assert_identical(*runs)


@needs_numba
def test_the_compiled_hypot_is_pythons_math_hypot():
    """``"separate"`` uses ``math.hypot``, which is not the C library's: the compiled frame carries CPython's."""
    from discsim.engines.fixed_step.numba.kernels import cpython_hypot

    rng = np.random.default_rng(0)
    x = rng.normal(size=20_000) * 10.0 ** rng.integers(-12, 12, 20_000)
    y = rng.normal(size=20_000) * 10.0 ** rng.integers(-12, 12, 20_000)
    x[:5], y[:5] = [0.0, -0.0, 5e-320, 1e308, 3.0], [0.0, 2.0, 3e-321, 1e308, 4.0]
    for a, b in zip(x.tolist(), y.tolist()):
        assert cpython_hypot(a, b) == math.hypot(a, b), (a, b)
    assert math.isinf(cpython_hypot(math.inf, math.nan)) and math.isnan(cpython_hypot(1.0, math.nan))


@needs_numba
@pytest.mark.parametrize("size", [7.3, 1.0, 3.0000000000000004, 1e-3])
def test_the_compiled_wrap_and_minimum_image_are_the_boxs(size):
    """Their shortcuts for the usual cases give ``Box.wrap`` and ``Box.minimum_image`` to the bit, zeros' signs too."""
    from discsim.engines.fixed_step.numba.kernels import _image, _wrap

    rng = np.random.default_rng(1)
    edges = [0.0, -0.0, size, -size, 2 * size, -2 * size, 0.5 * size, -0.5 * size, 1.5 * size, -1e-300, 1e300]
    edges += [np.nextafter(size, 0), np.nextafter(-size, 0), np.nextafter(2 * size, 0), np.nextafter(0.5 * size, 1)]
    values = np.concatenate([edges, rng.uniform(-3 * size, 4 * size, 5000), rng.normal(0, size, 500) * 1e-12])
    box = ds.Box(size, size, periodic=True)
    pairs = np.stack([values, values], axis=1)
    wrapped, image = box.wrap(pairs)[:, 0], box.minimum_image(pairs)[:, 0]
    assert np.array([_wrap(v, size) for v in values.tolist()]).tobytes() == wrapped.tobytes()
    assert np.array([_image(v, size) for v in values.tolist()]).tobytes() == image.tobytes()


@needs_numba
def test_the_compiled_sort_of_the_overlapping_pairs_is_numpys():
    from discsim.engines.fixed_step.numba.kernels import _heapsort

    rng = np.random.default_rng(2)
    for m in (0, 1, 2, 3, 10, 257, 5000):
        keys = rng.integers(0, max(m // 2, 1), m + 5)  # duplicates too; the tail past m stays as it is
        expected = np.concatenate([np.sort(keys[:m]), keys[m:]])
        _heapsort(keys, m)
        assert keys.tolist() == expected.tolist()


# --- checkpoints move between backends -----------------------------------------------------------------
@needs_numba
@pytest.mark.parametrize(("first", "second"), [("python", "numba"), ("numba", "python")])
def test_a_run_saved_under_one_backend_goes_on_under_the_other(tmp_path, first, second):
    discs, box, options = walled()
    whole = ds.FixedStep(discs, box, policy="revert", backend=second, **options).run(until=6.0)
    half = ds.FixedStep(discs, box, policy="revert", backend=first, **options).run(until=3.0)
    copy = ds.load(half.save(tmp_path / "half.dsc"), backend=second)
    assert copy.backend == second
    copy.run(until=6.0)
    assert_identical(whole, copy)


@needs_numba
def test_a_checkpoint_of_the_compiled_frame_loads_where_numba_is_missing(tmp_path, monkeypatch):
    discs, box, options = periodic()
    whole = ds.FixedStep(discs, box, **options).run(frames=80)
    half = ds.FixedStep(discs, box, **options).run(frames=40)
    assert half.backend == "numba" and half._settings()["backend"] == "numba"
    path = half.save(tmp_path / "half.dsc")
    _hide_numba(monkeypatch)
    copy = ds.load(path)
    assert copy.backend == "python"
    assert_identical(whole, copy.run(frames=40))


@needs_numba
def test_a_sub_frame_run_loads_under_numba_in_python(tmp_path):
    discs, box = ds.random_gas(40, 0.3, seed=4)
    sim = ds.FixedStep(discs, box, dt=0.05, policy="bisect").run(frames=10)
    copy = ds.load(sim.save(tmp_path / "bisect.dsc"), backend="numba")
    assert copy.backend == "python" and copy.run(frames=10).frames == 20


# --- the choice of backend -------------------------------------------------------------------------------
def test_auto_takes_numba_when_it_imports_and_the_policy_has_a_compiled_frame(monkeypatch):
    discs, box = ds.random_gas(30, 0.3, seed=1)
    expected = "numba" if _numba.available() else "python"
    assert ds.FixedStep(discs, box).backend == expected
    assert ds.FixedStep(discs, box, policy="bisect").backend == "python"
    assert ds.FixedStep(discs, box, policy="swept", backend="auto").backend == "python"
    assert ds.FixedStep(discs, box, backend="python").backend == "python"
    _hide_numba(monkeypatch)
    assert ds.FixedStep(discs, box).backend == "python"
    with pytest.raises(ds.InvalidArgumentError, match=r'backend=.numba. needs numba.*pip install "discsim\[fast\]"'):
        ds.FixedStep(discs, box, backend="numba")


@needs_numba
def test_numba_with_a_sub_frame_policy_says_which_policies_it_compiles():
    discs, box = ds.random_gas(30, 0.3, seed=1)
    for policy in ("bisect", "swept"):
        with pytest.raises(ds.InvalidArgumentError, match=rf"policy '{policy}' has no compiled frame.*'resolve'"):
            ds.FixedStep(discs, box, policy=policy, backend="numba")


@pytest.mark.parametrize("backend", ["fast", None, "Numba", ["numba"]])
def test_an_unknown_backend_is_refused_by_name(backend):
    discs, box = ds.random_gas(30, 0.3, seed=1)
    with pytest.raises(ds.InvalidArgumentError, match=r"FixedStep backend must be 'auto' or one of"):
        ds.FixedStep(discs, box, backend=backend)


def test_importing_discsim_does_not_load_the_compiled_frame():
    code = (
        "import sys, discsim as ds\n"
        "sim = ds.FixedStep(*ds.random_gas(20, 0.3, seed=1), backend='python').run(frames=3)\n"
        "print(sorted(m for m in sys.modules if m == 'numba' or m.startswith('discsim.engines.fixed_step.numba')))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
