"""The fixed-step frame's plain float parts (``fixed_step/parts.py``, ``model.frame_count``, ``image_step``,
``cells.grid_counts``): exact values, the rules they replace, and the compiled versions equal to the Python
ones bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

import discsim as ds
from discsim import _numba
from discsim.cells import grid_counts, grid_shape
from discsim.engines.fixed_step.parts import box_image, cell_span, nearest_image, table_shape, wrap
from discsim.errors import BoxTooSmallError
from discsim.model import frame_count, image_step, image_steps, minimum_image_1d

needs_numba = pytest.mark.skipif(not _numba.available(), reason="numba is not installed (the fast extra)")


def _values(size: float) -> list[float]:
    """Edge cases of a box ``size`` long (zeros of both signs, half and whole lengths, huge values), and many
    random ones within a few lengths."""
    rng = np.random.default_rng(7)
    edges = [0.0, -0.0, size, -size, 0.5 * size, -0.5 * size, 1.5 * size, -2.5 * size, 1e300, -1e300, 1e-300]
    edges += [np.nextafter(0.5 * size, 0), np.nextafter(0.5 * size, size), 2.0**60 * size, 2.0**52 * size]
    return [*map(float, edges), *rng.uniform(-5 * size, 5 * size, 3000).tolist()]


def _bits(values) -> bytes:
    return np.array(values, dtype=np.float64).tobytes()


@pytest.mark.parametrize("size", [7.3, 1.0, 3.0000000000000004, 1e-3])
def test_nearest_image_is_minimum_image_1d_and_box_image_is_the_boxs(size):
    """The fast path and the guard for huge values change no bit: ``nearest_image`` is the scalar rule
    (a ``-0.0`` kept), ``box_image`` is ``Box.minimum_image`` (a zero as ``+0.0``)."""
    values = _values(size)
    assert _bits([nearest_image(v, size) for v in values]) == _bits([minimum_image_1d(v, size) for v in values])
    box = ds.Box(size, size, periodic=True)
    every = _values(size)
    pairs = np.stack([every, every], axis=1)
    assert _bits([box_image(v, size) for v in every]) == box.minimum_image(pairs)[:, 0].tobytes()
    assert _bits([wrap(v, size) for v in every]) == box.wrap(pairs)[:, 0].tobytes()
    assert math.copysign(1.0, nearest_image(-0.0, size)) == -1.0
    assert math.copysign(1.0, box_image(-0.0, size)) == 1.0


@needs_numba
@pytest.mark.parametrize("size", [7.3, 1e-3])
def test_the_compiled_parts_are_the_python_ones_to_the_bit(size):
    """numba compiles the same source: its ``round`` gives an int64, so past 2**63 box lengths the guard
    in ``nearest_image`` is what keeps the two equal."""
    from discsim.engines.fixed_step.numba.kernels import _image, _image_step, _nearest_image, _wrap

    values = _values(size)
    assert _bits([_nearest_image(v, size) for v in values]) == _bits([nearest_image(v, size) for v in values])
    assert _bits([_image(v, size) for v in values]) == _bits([box_image(v, size) for v in values])
    assert _bits([_wrap(v, size) for v in values]) == _bits([wrap(v, size) for v in values])
    finite = [v for v in values if abs(v / size) < 1e15]
    assert [_image_step(v, wrap(v, size), size) for v in finite] == [image_step(v, wrap(v, size), size) for v in finite]


def test_image_steps_count_whole_box_lengths():
    assert image_step(12.5, 2.5, 10.0) == 1
    assert image_step(-0.5, 9.5, 10.0) == -1
    assert image_step(35.0 + 1e-12, 5.0, 10.0) == 3  # roundoff of the flight does not matter
    flown = np.array([[12.5, -0.5], [np.nan, 3.0]])
    steps = image_steps(flown, np.array([[2.5, 9.5], [1.0, 3.0]]), np.array([10.0, 10.0]))
    assert steps[0].tolist() == [1.0, -1.0] and np.isnan(steps[1, 0]) and steps[1, 1] == 0.0


@pytest.mark.parametrize(
    ("start", "end", "dt", "count"),
    [(0.0, 0.3, 0.1, 3), (0.0, 0.29, 0.1, 2), (1.0, 1.25, 0.1, 2), (0.0, 1.0, 1 / 3, 3), (0.0, 0.0, 0.1, 0)],
)
def test_frame_count_allows_for_the_roundoff_of_k_dt(start, end, dt, count):
    """``0.3 / 0.1`` is ``2.9999999999999996``: the third frame is due all the same."""
    assert frame_count(start, end, dt) == count


def test_grid_counts_is_grid_shapes_rule():
    assert grid_counts(10.0, 4.0, False, 1.0, 0) == (10, 4)
    assert grid_counts(10.0, 4.0, False, 1.0, 10) == (5, 2)
    assert grid_counts(0.3, 0.3, False, 0.1, 0) == (3, 3)  # the slack of 1e-12
    assert grid_counts(100.0, 100.0, True, 1.0, 50) == (7, 7)
    assert grid_counts(100.0, 100.0, True, 1.0, 4) == (3, 3)  # never under 3 a side when periodic
    assert grid_counts(10.0, 2.5, True, 1.0, 0) == (1, 1)
    assert grid_shape(ds.Box(10.0, 2.5, periodic=True), 1.0) == (1, 1)
    with pytest.raises(BoxTooSmallError, match="y-extent 2.5"):
        grid_shape(ds.Box(10.0, 2.5, periodic=True), 1.0, what="the contact distance")


def test_the_cell_tables_shape_and_spans():
    assert table_shape(10, 1.0, 10.0, 4.5) == (10, 4)
    assert table_shape(10, 1.0, 1000.0, 1000.0) == (256, 256)  # at most 65536 cells: 1000 / sqrt(1e6 / 65536)
    assert cell_span(-1.5, 2.5, 1.0, 10, True) == (-2, 2, True)
    assert cell_span(-1.5, 2.5, 1.0, 10, False) == (0, 2, False)
    assert cell_span(-1.5, 20.0, 1.0, 10, True) == (0, 9, False)  # the whole axis
    assert cell_span(12.0, 13.0, 1.0, 10, False) == (9, 9, False)
