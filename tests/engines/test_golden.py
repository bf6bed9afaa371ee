"""Golden event logs: both engines give, bit for bit, the events recorded before the redesign (issue 14).

The logs were written by ``tests/golden/make_golden.py`` on the pre-redesign engine; every scene is replayed
here and every field of the log, the final positions, velocities, time, counters and deepest overlap are
compared exactly. Checkpoint files in the pre-redesign format (``tests/fixtures/v0_*.dsc``) must still load
and continue to the recorded end.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from paths import FIXTURES, GOLDEN

import discsim as ds
from discsim import _numba
from discsim.engines.fixed_step.engine import COMPILED_POLICIES

_spec = importlib.util.spec_from_file_location("make_golden", GOLDEN / "make_golden.py")
make_golden = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(make_golden)

SCENES = make_golden.all_scenes()
SLOW = {"ed_rebase", "ed_periodic_5000", "ed_walled_5000"}


def assert_matches(sim, path: Path) -> None:
    """Every stored field of the golden file equals the engine's, bit for bit."""
    golden = np.load(path)
    events = sim.events
    assert len(events) == int(golden["n_events"])
    if "events" in golden:
        expected = golden["events"]
        assert events.dtype == expected.dtype
        for field in expected.dtype.names:
            got, want = events[field], expected[field]
            same = (got == want) | (np.isnan(got) & np.isnan(want)) if got.dtype.kind == "f" else got == want
            assert same.all(), f"field {field!r} differs first at event {int(np.flatnonzero(~same)[0])}"
    else:
        assert events[: len(golden["events_head"])].tobytes() == golden["events_head"].tobytes()
        assert events[-len(golden["events_tail"]) :].tobytes() == golden["events_tail"].tobytes()
    assert hashlib.sha256(events.tobytes()).hexdigest() == str(golden["events_sha256"])
    assert sim.time == float(golden["time"])
    assert sim.positions.tobytes() == golden["positions"].tobytes()
    assert sim.velocities.tobytes() == golden["velocities"].tobytes()
    assert sim.max_overlap == float(golden["max_overlap"])
    expected_counts = json.loads(str(golden["counts"]))
    assert {k: sim.counts[k] for k in expected_counts} == expected_counts


@pytest.mark.parametrize(
    "name", [pytest.param(name, marks=pytest.mark.slow) if name in SLOW else name for name in SCENES]
)
def test_golden_log(name):
    engine, build, how = SCENES[name]
    sim = make_golden.run_scene(engine, build, how)
    assert_matches(sim, GOLDEN / f"{name}.npz")


#: The fixed-step scenes whose policy has a compiled frame ("fs_<policy>_<scene>"): all of them.
FS_COMPILED = [name for name in SCENES if name.startswith("fs_") and name.split("_")[1] in COMPILED_POLICIES]


@pytest.mark.parametrize("backend", ["python", "numba"])
@pytest.mark.parametrize("name", FS_COMPILED)
def test_golden_log_of_each_fixed_step_backend(name, backend):
    """The fixed-step scenes under each backend by name (``test_golden_log`` runs the default, ``"auto"``)."""
    if backend == "numba" and not _numba.available():
        pytest.skip("numba is not installed or is hidden (the fast extra)")
    _, build, (key, value) = SCENES[name]
    discs, box, kwargs = build()
    sim = ds.FixedStep(discs, box, backend=backend, **kwargs).run(**{key: value})
    assert sim.backend == backend
    assert_matches(sim, GOLDEN / f"{name}.npz")


def test_every_scene_has_a_golden_file():
    assert {p.stem for p in GOLDEN.glob("*.npz")} == set(SCENES)


@pytest.mark.parametrize(
    ("fixture", "how"),
    [("v0_walled_segments", {"until": 4.0}), ("v0_periodic_4200", {"events": 4000})],
)
def test_pre_redesign_checkpoint_continues_bit_for_bit(tmp_path, fixture, how):
    path = tmp_path / f"{fixture}.dsc"
    shutil.copy(FIXTURES / f"{fixture}.dsc", path)
    sim = ds.load(path)
    sim.run(**how)
    assert_matches(sim, FIXTURES / f"{fixture}.npz")


def test_a_first_layout_file_with_its_log_rebuilds_the_image_counters(tmp_path):
    """A periodic run saved before the redesign, with its whole log: unwrapped positions come back exact."""
    path = tmp_path / "logged.dsc"
    shutil.copy(FIXTURES / "v0_periodic_logged.dsc", path)
    sim = ds.load(path)
    from_log = sim.trajectory([sim.time], unwrapped=True)[0]
    assert np.abs(sim.unwrapped_positions - from_log).max() < 1e-9
    assert (np.abs(sim.unwrapped_positions - sim.positions) > 1.0).any()  # some disc went round
    sim.run(until=40.0)
    assert np.abs(sim.unwrapped_positions - sim.trajectory([40.0], unwrapped=True)[0]).max() < 1e-9
