"""discsim._compiled: what the compiled loops share (prefetch, inline, the compiled segment kernels).

``prefetch`` is only a hint to the CPU: compiled, it must accept every array the loops pass (1-D and 2-D,
float64, int64, int32, int8, offsets up to the last element) and change nothing; without numba it is a
no-op and ``jit`` returns the function itself. The compiled segment kernels give the pure-Python kernels'
results bit for bit (the event loop and the sub-frame policies share them).
"""

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from discsim import _numba, kernels

needs_numba = pytest.mark.skipif(not _numba.available(), reason="numba is not installed or is hidden (the fast extra)")


@needs_numba
def test_prefetch_compiles_for_every_array_the_loops_pass_and_changes_nothing():
    from discsim._compiled import inline, jit, prefetch

    @inline
    def ask(array, offset):
        prefetch(array, offset)

    @jit
    def touch_all(rec, counts, links, kinds):
        for k in range(rec.shape[0]):
            prefetch(rec, k * 8)
            ask(counts, k)
            prefetch(links, k)
            prefetch(kinds, k)
        return rec.sum() + counts.sum() + links.sum() + kinds.sum()

    rng = np.random.default_rng(1)
    rec = rng.normal(size=(50, 8))
    counts = np.arange(50, dtype=np.int64)
    links = np.arange(50, dtype=np.int32)
    kinds = (np.arange(50) % 4).astype(np.int8)
    before = [a.copy() for a in (rec, counts, links, kinds)]
    total = touch_all(rec, counts, links, kinds)
    assert total == rec.sum() + counts.sum() + links.sum() + kinds.sum()
    for a, b in zip((rec, counts, links, kinds), before):
        np.testing.assert_array_equal(a, b)


def test_without_numba_jit_is_the_function_and_prefetch_does_nothing():
    code = (
        "import numpy as np\n"
        "from discsim import _compiled\n"
        "f = lambda x: x + 1\n"
        "assert _compiled.jit(f) is f and _compiled.inline(f) is f\n"
        "assert _compiled.prefetch(np.zeros(3), 1) is None\n"
        "from discsim.physics import compiled, dynamics\n"
        "assert compiled.segment_time_of_impact is dynamics.segment_time_of_impact\n"
        "assert compiled.segment_time_of_impact(0.0, 2.0, 0.0, -1.0, 0.5, -1.0, 0.0, 1.0, 0.0) == 1.5\n"
        "print('ok')\n"
    )
    env = {"DISCSIM_NO_NUMBA": "1", "PATH": "/usr/bin:/bin"}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok"


coordinate = st.floats(-5.0, 5.0, allow_nan=False, allow_subnormal=False)
speed = st.floats(-3.0, 3.0, allow_nan=False, allow_subnormal=False)


@needs_numba
@settings(max_examples=300, deadline=None)
@given(coordinate, coordinate, speed, speed, st.floats(0.01, 2.0), coordinate, coordinate, coordinate, coordinate)
def test_the_compiled_segment_kernels_equal_the_python_ones_bit_for_bit(px, py, vx, vy, radius, ax, ay, bx, by):
    from discsim.physics.compiled import reflect_off_segment, segment_time_of_impact

    if math.hypot(bx - ax, by - ay) < 1e-3:
        bx += 1.0
    expected = kernels.segment_time_of_impact(px, py, vx, vy, radius, ax, ay, bx, by)
    got = segment_time_of_impact(px, py, vx, vy, radius, ax, ay, bx, by)
    assert got == expected or (math.isinf(got) and math.isinf(expected))
    cx, cy = kernels.closest_point_on_segment(px, py, ax, ay, bx, by)
    if math.hypot(px - cx, py - cy) > 1e-6:  # a disc's centre is never on a segment it bounces off
        expected = kernels.reflect_off_segment(px, py, vx, vy, ax, ay, bx, by)
        assert reflect_off_segment(px, py, vx, vy, ax, ay, bx, by) == expected


def test_the_cache_stamp_of_a_compiled_module_covers_the_parts_compiled_into_it(tmp_path, monkeypatch):
    # numba checks a cached function against its own file only; the loops compile the physics parts into
    # themselves, so their stamp must change when a part does (else an edited law runs the old machine code).
    from discsim import _compiled

    package = tmp_path / "pkg"
    for folder in ("physics", "engine", "other"):
        (package / folder).mkdir(parents=True)
    part, loop, sibling, unrelated = (
        package / "physics" / "dynamics.py",
        package / "engine" / "loop.py",
        package / "engine" / "kernels.py",
        package / "other" / "plot.py",
    )
    for path in (part, loop, sibling, unrelated):
        path.write_text("x = 1\n")
    monkeypatch.setattr(_compiled, "_PACKAGE", package)
    stamps = [_compiled.source_stamp(loop)]
    part.write_text("x = 22\n")  # a part the loop compiles in
    stamps.append(_compiled.source_stamp(loop))
    sibling.write_text("x = 333\n")  # a module of the loop's own folder
    stamps.append(_compiled.source_stamp(loop))
    unrelated.write_text("x = 4444\n")  # neither
    stamps.append(_compiled.source_stamp(loop))
    assert stamps[0] != stamps[1] != stamps[2] == stamps[3]


@needs_numba
def test_discsim_files_get_the_discsim_cache_stamp():
    from numba.core import caching

    import discsim._compiled  # noqa: F401  (installs the locators)

    names = [k.__name__ for k in caching.CacheImpl._locator_classes]
    assert names[:2] == ["DiscsimUserProvidedCacheLocator", "DiscsimInTreeCacheLocator"]
    locator = caching.CacheImpl._locator_classes[1]
    assert locator.from_function(caching.CacheImpl.__init__, caching.__file__) is None  # not discsim's: numba's
