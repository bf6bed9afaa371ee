"""Jammed scenes shared by the jam tests of both engines (issue 18, part 2), and a watchdog against hangs."""

from __future__ import annotations

import contextlib
import signal

import numpy as np

import discsim as ds


class Hung(Exception):
    pass


@contextlib.contextmanager
def watchdog(seconds: int = 60):
    """Fail instead of hanging: raise :class:`Hung` after ``seconds``."""

    def fire(signum, frame):
        raise Hung(f"still running after {seconds} s")

    previous = signal.signal(signal.SIGALRM, fire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def wall_and_obstacle():
    """A disc moving into a wall, a fixed obstacle touching its other side."""
    return ds.Discs([[0.5, 5.0], [1.5, 5.0]], [[-1.0, 0.0], [0, 0]], 0.5, masses=[1.0, np.inf]), ds.Box(10, 10), [0, 1]


def row_filling_the_box():
    """Ten discs of radius 0.5 in a row exactly filling a box 10 wide."""
    x = 0.5 + np.arange(10)
    v = np.column_stack([np.random.default_rng(0).normal(size=10), np.zeros(10)])
    return ds.Discs(np.column_stack([x, np.full(10, 5.0)]), v, 0.5), ds.Box(10, 10), list(range(10))


def between_two_obstacles():
    """A disc between two fixed obstacles, touching both."""
    discs = ds.Discs([[2.0, 5.0], [3.0, 5.0], [4.0, 5.0]], [[0, 0], [1.0, 0], [0, 0]], 0.5, masses=[np.inf, 1, np.inf])
    return discs, ds.Box(10, 10), [0, 1, 2]


def hexagonal_lattice():
    """An exactly touching hexagonal lattice filling a periodic box."""
    n = 6
    pts = np.array([[c + 0.5 * (r % 2), r * np.sqrt(3) / 2] for r in range(n) for c in range(n)])
    v = np.random.default_rng(1).normal(size=(n * n, 2))
    return ds.Discs(pts, v, 0.5), ds.Box(n, n * np.sqrt(3) / 2, periodic=True), list(range(n * n))


def square_lattice_filling_a_periodic_box():
    """A touching square lattice filling a periodic box (packing pi / 4), random velocities (issue 30, item 10).

    Not rigid (whole rows and columns may slide), yet jammed for these velocities: each row is a ring of touching
    discs as long as the box, so its discs cannot part along it; their x velocities differ, so some pair of each
    ring always approaches, and equal discs swap velocities round the ring for ever at t = 0 (as do the columns'
    y velocities). No elastic outcome exists: the rows' relative energy has nowhere to go.
    """
    n = 6
    pts = np.array([[c + 0.5, r + 0.5] for r in range(n) for c in range(n)])
    v = np.random.default_rng(1).normal(size=(n * n, 2))
    return ds.Discs(pts, v, 0.5), ds.Box(n, n, periodic=True), list(range(n * n))


JAMS = {
    f.__name__: f
    for f in (
        wall_and_obstacle,
        row_filling_the_box,
        between_two_obstacles,
        hexagonal_lattice,
        square_lattice_filling_a_periodic_box,
    )
}
