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
from discsim.engines.fixed_step.engine import COMPILED_POLICIES, SUB_FRAME_POLICIES
from discsim.events import SENSED
from discsim.sensors import Sensor

#: The policies that answer at the frame (the rest answer inside it).
FRAME_POLICIES = tuple(p for p in COMPILED_POLICIES if p not in SUB_FRAME_POLICIES)

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
BOTH = ("python", "numba")


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
@pytest.mark.parametrize("policy", FRAME_POLICIES)
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
@pytest.mark.parametrize("broad_phase", ["grid", "all-pairs"])
@pytest.mark.parametrize("policy", SUB_FRAME_POLICIES)
@pytest.mark.parametrize("scene", ["walled", pytest.param("periodic", marks=pytest.mark.slow)])  # periodic: 6 s
def test_the_sub_frame_policies_give_the_same_frames_bit_for_bit(scene, policy, broad_phase):
    """Chains of contacts inside frames, walls, a triangle of segments, obstacles, three radii and masses,
    groups passing through each other: the same log, state and counters (bisection tests too)."""
    discs, box, options = SCENES[scene]()
    runs = [
        ds.FixedStep(discs, box, policy=policy, broad_phase=broad_phase, backend=backend, **options).run(frames=120)
        for backend in ("python", "numba")
    ]
    assert [sim.backend for sim in runs] == ["python", "numba"]
    counts = runs[0].counts
    assert counts["detections"] > 900 and counts["pair_tests"] > counts["detections"]
    assert (counts["bisection_tests"] > 10 * counts["detections"]) == (policy == "bisect")
    if scene == "walled":
        assert counts["wall_hits"] > 300 and counts["segment_tests"] > 0
        # Some disc met a segment: a hit that left it off every wall of the box.
        hits = runs[0].events[runs[0].events["j"] < 0]
        x, y = hits["xi"], hits["yi"]
        r = discs.radii[hits["i"]]
        inside = (x - r > 1e-9) & (x + r < box.width - 1e-9) & (y - r > 1e-9) & (y + r < box.height - 1e-9)
        assert inside.any()
    assert_identical(*runs)


@needs_numba
@pytest.mark.parametrize("policy", COMPILED_POLICIES)
@pytest.mark.parametrize("scene", ["walled", "periodic"])
def test_both_backends_give_the_same_frames_under_gravity_and_restitution(scene, policy):
    """Restitution per pair of groups, the TC model, gravity (the frame policies: the sub-frame ones refuse it):
    the same log, state (the last responses too) and energy dissipated, bit for bit."""
    discs, box, options = SCENES[scene]()
    laws = {"restitution": {(0, 0): 0.7, (0, 1): 0.5, (1, 2): 0.9, (2, 2): 0.95}, "tc": 0.01}
    if policy in FRAME_POLICIES:
        laws["gravity"] = (0.3, -2.0)
    runs = [ds.FixedStep(discs, box, policy=policy, backend=b, **options, **laws).run(frames=120) for b in BOTH]
    assert runs[0].counts["detections"] > 500 and runs[0].dissipated > 0.0
    assert np.isfinite(runs[0].state().last_collision).sum() > 10
    assert_identical(*runs)
    assert runs[0].dissipated == runs[1].dissipated and runs[0].energy() == runs[1].energy()


@needs_numba
@pytest.mark.parametrize("policy", FRAME_POLICIES)
@pytest.mark.parametrize("scene", ["walled", "periodic"])
def test_both_backends_give_the_same_frames_under_drag(scene, policy):
    """Drag with gravity and restitution (the frame policies: the sub-frame ones refuse it), and an edit between
    frames: the same log, state and energy dissipated (the drag's included, added in the same order), bit for bit."""
    discs, box, options = SCENES[scene]()
    laws = {"drag": 0.7, "restitution": 0.9, "gravity": (0.3, -2.0) if scene == "walled" else (0.3, 0.0)}
    runs = []
    for b in BOTH:
        sim = ds.FixedStep(discs, box, policy=policy, backend=b, **options, **laws).run(frames=60)
        sim.run(until=sim.time + 0.3 * sim.dt)
        sim.set_velocities([5, 9], [[1.0, 2.0], [-3.0, 0.5]])
        runs.append(sim.run(frames=60))
    assert runs[0].counts["detections"] > 100 and runs[0].dissipated > 0.0
    assert_identical(*runs)
    assert runs[0].dissipated == runs[1].dissipated and runs[0].energy() == runs[1].energy()


@needs_numba
@pytest.mark.parametrize("policy", COMPILED_POLICIES)
@pytest.mark.parametrize("scene", ["walled", "periodic"])
def test_both_backends_give_the_same_frames_under_roughness(scene, policy):
    """Rough discs (spins, given inertia; walls, segments and obstacles as rough as them) with restitution: the same
    log, state (the spins and angles too) and energy dissipated, bit for bit."""
    discs, box, options = SCENES[scene]()
    rng = np.random.default_rng(11)
    n = len(discs)
    inertia = np.where(np.isfinite(discs.masses), rng.uniform(0.2, 0.6, n) * discs.masses * discs.radii**2, np.inf)
    spins = rng.normal(size=n)
    discs = ds.Discs(discs.positions, discs.velocities, discs.radii, discs.masses, discs.groups, spins, inertia)
    runs = [
        ds.FixedStep(discs, box, policy=policy, backend=b, restitution=0.9, roughness=0.4, **options).run(frames=120)
        for b in BOTH
    ]
    assert runs[0].counts["detections"] > 300 and runs[0].dissipated > 0.0
    assert not np.array_equal(runs[0].spins, spins)
    assert_identical(*runs)
    assert runs[0].dissipated == runs[1].dissipated and runs[0].kinetic_energy() == runs[1].kinetic_energy()


@needs_numba
@pytest.mark.parametrize("policy", FRAME_POLICIES)
def test_both_backends_give_the_same_frames_with_moving_segments(policy):
    """Two paddles sweeping a walled gas (with a fixed segment and restitution): the segments where they are at
    each frame, the bounces in their frames, the energy they take: the same log, state and losses, bit for bit."""
    discs, box = _mixture(60, 0.3, False, 5, obstacles=2)
    w, h = box.width, box.height
    segments = [
        ds.Segment((0.2 * w, 0.1 * h), (0.8 * w, 0.1 * h), velocity=(0.0, 0.05 * h)),
        ds.Segment((0.9 * w, 0.3 * h), (0.9 * w, 0.7 * h), velocity=(-0.04 * w, 0.01 * h)),
        ds.Segment((0.4 * w, 0.5 * h), (0.6 * w, 0.55 * h)),
    ]
    keep = np.ones(len(discs), dtype=bool)
    for segment in segments:
        keep &= segment.distance(discs.positions) > discs.radii * 1.01
    discs = ds.Discs(*(a[keep] for a in (discs.positions, discs.velocities, discs.radii, discs.masses, discs.groups)))
    runs = [
        ds.FixedStep(discs, box, dt=0.05, policy=policy, backend=b, segments=segments, restitution=0.8).run(frames=200)
        for b in BOTH
    ]
    assert [run.backend for run in runs] == list(BOTH)
    assert runs[0].counts["wall_hits"] > 20 and runs[0].counts["detections"] > 20
    assert_identical(*runs)
    assert runs[0].dissipated == runs[1].dissipated and runs[0].kinetic_energy() == runs[1].kinetic_energy()


@needs_numba
@pytest.mark.parametrize("policy", COMPILED_POLICIES)
def test_a_large_gas_gives_the_same_frames_and_the_same_verlet_list(policy):
    discs, box, options = large()
    runs = [ds.FixedStep(discs, box, policy=policy, backend=b, **options).run(frames=40) for b in ("python", "numba")]
    assert (runs[0].counts["list_builds"] >= 2) == (policy in FRAME_POLICIES)
    assert runs[0].counts["detections"] > 500
    assert_identical(*runs)


@needs_numba
@pytest.mark.parametrize("policy", ["separate", "bisect", "swept"])
def test_step_gives_the_python_frames_events_and_a_batch_of_frames_equals_single_frames(policy):
    discs, box, options = walled()
    python = ds.FixedStep(discs, box, policy=policy, backend="python", **options)
    numba = ds.FixedStep(discs, box, policy=policy, backend="numba", **options)
    batched = ds.FixedStep(discs, box, policy=policy, backend="numba", **options)
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
@pytest.mark.parametrize("policy", COMPILED_POLICIES)
def test_one_disc_and_two_discs_run_alike(policy):
    for discs in (
        ds.Discs([[3.0, 1.0]], [[2.0, 0.7]], 0.5),
        ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [0.0, 0.0]], radii=1.0, masses=[1.0, math.inf]),
    ):
        runs = [
            ds.FixedStep(discs, ds.Box(10.0, 10.0), dt=0.3, policy=policy, backend=b).run(until=20.0)
            for b in ("python", "numba")
        ]
        assert runs[0].counts["wall_hits"] > 0
        assert_identical(*runs)


@needs_numba
@pytest.mark.parametrize("policy", SUB_FRAME_POLICIES)
@pytest.mark.parametrize("scene", ["walled", "periodic"])
def test_no_disc_runs_alike(policy, scene):
    box = ds.Box(10.0, 10.0, periodic=scene == "periodic")
    discs = ds.Discs(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))
    runs = [ds.FixedStep(discs, box, dt=0.3, policy=policy, backend=b).run(frames=5) for b in ("python", "numba")]
    assert_identical(*runs)


@needs_numba
def test_pythons_square_is_the_c_librarys_pow_and_the_compiled_bisect_squares_alike():
    """``x ** 2`` in Python is ``pow(x, 2.0)``, which differs from ``x * x`` in the last bit now and then;
    the compiled ``bisect`` squares with ``pow`` and an exponent LLVM cannot see, so the tests agree."""
    from discsim.engines.fixed_step.numba.sub_frame import BISECT, SEGMENT, _overlapping

    rng = np.random.default_rng(3)
    x = (rng.uniform(-1, 1, 20_000) * 10.0 ** rng.uniform(-6, 6, 20_000)).tolist()
    assert any(v**2 != v * v for v in x)  # the test can tell the two apart
    p = np.zeros(12)
    for v in x[:3000]:
        # A disc at rest at (v, 0), a segment along x = 0: overlapping when v ** 2 < r ** 2 = p[5].
        p[:] = (v, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0)
        p[5] = v**2  # exactly at the edge under Python's square: no overlap
        assert not _overlapping(SEGMENT, 0.0, p, False, 1.0, 1.0, 2.0), v
        p[5] = np.nextafter(v**2, math.inf)
        assert _overlapping(SEGMENT, 0.0, p, False, 1.0, 1.0, 2.0), v
    assert BISECT == 3


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
@pytest.mark.parametrize("policy", ["revert", "bisect", "swept"])
@pytest.mark.parametrize(("first", "second"), [("python", "numba"), ("numba", "python")])
def test_a_run_saved_under_one_backend_goes_on_under_the_other(tmp_path, first, second, policy):
    discs, box, options = walled()
    whole = ds.FixedStep(discs, box, policy=policy, backend=second, **options).run(until=6.0)
    half = ds.FixedStep(discs, box, policy=policy, backend=first, **options).run(until=3.0)
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


# --- refusals: the same error, at the same frame, the engine as usable ---------------------------------------
def _fast_light_disc(dt):
    """A periodic box where a heavy disc hits a light one at rest: the light one leaves at nearly twice
    the heavy one's speed, too fast for ``"swept"`` at ``dt`` (2 v dt + 2 r >= half the box side)."""
    discs = ds.Discs([[2.0, 5.0], [5.0, 5.0]], [[1.0, 0.0], [0.0, 0.0]], radii=0.5, masses=[100.0, 1.0])
    return discs, ds.Box(10.0, 10.0, periodic=True)


@needs_numba
def test_swept_refuses_a_frame_that_could_reach_a_second_image_alike():
    dt = 1.6  # 2 * 1.0 * 1.6 + 1 = 4.2 < 5 before the hit; 2 * 1.98 * 1.6 + 1 > 5 after it
    discs, box = _fast_light_disc(dt)
    runs, errors = [], []
    for backend in ("python", "numba"):
        sim = ds.FixedStep(discs, box, dt=dt, policy="swept", backend=backend)
        with pytest.raises(ds.InvalidArgumentError, match=r"policy 'swept' in a periodic box needs") as caught:
            sim.run(frames=10)
        runs.append(sim)
        errors.append(str(caught.value))
    assert errors[0] == errors[1]
    assert runs[0].frames == 2 and runs[0].counts["detections"] == 1  # the hit at t = 2, in frame 2
    assert_identical(*runs)
    for sim in runs:  # refused before the frame: the engine is still usable
        assert sim.state() is not None and sim._broken is None
    # Fast from the start: refused at the first frame, under either backend.
    fast = ds.Discs([[2.0, 5.0]], [[4.0, 0.0]], radii=0.5)
    messages = []
    for backend in ("python", "numba"):
        with pytest.raises(ds.InvalidArgumentError) as caught:
            ds.FixedStep(fast, box, dt=dt, policy="swept", backend=backend).step()
        messages.append(str(caught.value))
    assert messages[0] == messages[1] and "use a smaller dt or a larger box" in messages[0]


@needs_numba
def test_swept_does_a_batch_of_frames_only_when_no_disc_can_get_too_fast():
    from discsim.engines.fixed_step.numba.policy import BATCH_WORK

    discs, box, options = periodic()
    sim = ds.FixedStep(discs, box, policy="swept", backend="numba", **options)
    assert sim._policy.batch(sim._paths, sim.dt) == BATCH_WORK // len(discs)  # energy bounds every speed
    slow, box2 = _fast_light_disc(1.6)
    risky = ds.FixedStep(slow, box2, dt=1.6, policy="swept", backend="numba")
    assert risky._policy.batch(risky._paths, risky.dt) == 1  # the light disc could reach sqrt(2 E / m)
    walled_sim = ds.FixedStep(*walled()[:2], policy="swept", backend="numba", dt=0.05)
    assert walled_sim._policy.batch(walled_sim._paths, walled_sim.dt) > 1  # no images in a walled box


@needs_numba
@pytest.mark.parametrize("policy", SUB_FRAME_POLICIES)
def test_a_jammed_frame_raises_the_same_error_with_the_same_log(policy):
    from jams import JAMS, watchdog

    discs, box, _ = JAMS["hexagonal_lattice"]()
    runs, errors = [], []
    for backend in ("python", "numba"):
        sim = ds.FixedStep(discs, box, frame_rate=30, policy=policy, backend=backend)
        with watchdog(60), pytest.raises(ds.JammedError, match=r"disc \d+ and disc \d+ are jammed") as caught:
            sim.run(until=1.0)
        runs.append(sim)
        errors.append(str(caught.value))
    assert errors[0] == errors[1]
    python, numba = runs
    assert len(python.events) > 1000
    assert python.events.tobytes() == numba.events.tobytes()
    # The counters of every response made, the frame count aside: a batch of compiled frames counts its
    # frames at its end, and a broken engine's state is not to be trusted (it refuses to go on).
    counts = [{k: v for k, v in sim.counts.items() if k != "frames"} for sim in runs]
    assert counts[0] == counts[1] and python.max_overlap == numba.max_overlap
    assert numba._broken is not None  # half-way through a frame, as under Python
    with pytest.raises(ds.DiscsimError, match="interrupted inside its event loop"):
        numba.run(frames=1)


# --- the choice of backend -------------------------------------------------------------------------------
def test_auto_takes_numba_when_it_imports_for_every_policy(monkeypatch):
    discs, box = ds.random_gas(30, 0.3, seed=1)
    expected = "numba" if _numba.available() else "python"
    assert ds.FixedStep(discs, box).backend == expected
    assert ds.FixedStep(discs, box, policy="bisect").backend == expected
    assert ds.FixedStep(discs, box, policy="swept", backend="auto").backend == expected
    assert ds.FixedStep(discs, box, policy="swept", backend="python").backend == "python"
    assert ds.FixedStep(discs, box, backend="python").backend == "python"
    _hide_numba(monkeypatch)
    assert ds.FixedStep(discs, box).backend == "python"
    with pytest.raises(ds.InvalidArgumentError, match=r'backend=.numba. needs numba.*pip install "discsim\[fast\]"'):
        ds.FixedStep(discs, box, backend="numba")


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


@needs_numba
@pytest.mark.parametrize("policy", COMPILED_POLICIES)
@pytest.mark.parametrize("periodic", [True, False])
def test_both_backends_report_the_same_sensor_records(policy, periodic):
    discs, box = ds.random_gas(40, 0.25, periodic=periodic, seed=11, temperature=4.0)
    w = box.width
    # Sensors at the frames (issue 28): the records come from the frames both backends share.
    sensors = [Sensor.circle((0.5 * w, 0.5 * w), 0.2 * w), Sensor.line((0.05 * w, 0.6 * w), (0.95 * w, 0.55 * w))]
    runs = [
        ds.FixedStep(discs, box, dt=0.05, policy=policy, sensors=sensors, backend=backend).run(frames=80)
        for backend in ("python", "numba")
    ]
    assert np.isin(runs[0].events["kind"], SENSED).sum() > 10
    assert runs[0].events.tobytes() == runs[1].events.tobytes() and runs[0].counts == runs[1].counts
