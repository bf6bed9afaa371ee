"""Sensors: regions that report when a disc's centre enters or leaves them, and never touch the motion.

A :class:`Sensor` is a circle, a rectangle or a line (a trip wire). ``EventDriven`` finds the exact time each
disc's centre crosses a sensor's edge and logs it (kinds ``"enter"`` and ``"leave"``, ``j`` the sensor's index),
and calls ``sim.on("enter" | "leave", fn)``; ``FixedStep`` reports the crossings it sees at its frames.

What "inside" means, the one definition every engine uses (:meth:`Sensor.contains`):

- a circle: ``|p - centre| < radius``;
- a rectangle: ``x0 < x < x1`` and ``y0 < y < y1``;
- a line from ``p0`` to ``p1``: the left side of the direction ``p1 - p0``
  (``cross(p1 - p0, p - p0) > 0``). A disc *enters* a line when its centre crosses the segment from its right
  to its left, and *leaves* it when it crosses back; passing beyond an end of the segment reports nothing.

In a periodic box the edges x = 0 and x = W are one line (so are y = 0 and y = H): a line along an edge
(:func:`edge_axis`) is crossed each time a centre wraps across that edge at a point of the line, and a centre's side
of it is the side of the box's inside (:func:`inside_table`).

Example:
    >>> pocket = Sensor.circle((0.0, 0.0), 1.0)
    >>> pocket.contains([[0.5, 0.0], [2.0, 0.0]]).tolist()
    [True, False]
    >>> Sensor.line((0, 0), (0, 1)).contains([[-1.0, 0.5], [1.0, 0.5]]).tolist()
    [True, False]
"""

from __future__ import annotations

import numpy as np

from discsim.errors import InvalidArgumentError
from discsim.model import _readonly, _real_array

__all__ = [
    "CIRCLE",
    "LINE",
    "RECTANGLE",
    "Sensor",
    "check_sensors",
    "edge_axis",
    "inside_table",
    "on_periodic_edge",
    "sensor_rows",
]

#: The shape codes of :func:`sensor_rows` (what the compiled loop reads).
CIRCLE, RECTANGLE, LINE = 1, 2, 3
_NAMES = {CIRCLE: "circle", RECTANGLE: "rectangle", LINE: "line"}


def _point(name: str, value) -> np.ndarray:
    p = _real_array(name, value, InvalidArgumentError)
    if p.shape != (2,) or not np.isfinite(p).all():
        msg = f"{name} must be 2 finite numbers, got {p.tolist() if p.ndim else p!r}"
        raise InvalidArgumentError(msg)
    return p


class Sensor:
    """A region that reports a disc's centre entering or leaving it (build one with :meth:`circle`,
    :meth:`rectangle` or :meth:`line`).

    Attributes:
        shape (str): ``"circle"``, ``"rectangle"`` or ``"line"``.
        params ((4,) float64, read-only): centre x, y, radius, 0 (a circle); lower-left x, y, upper-right x, y
            (a rectangle); ``p0`` x, y, ``p1`` x, y (a line). Lengths.
    """

    __slots__ = ("code", "params")

    def __init__(self, code: int, params):
        self.code = int(code)
        self.params = _readonly(np.asarray(params, dtype=np.float64).reshape(4))

    @classmethod
    def circle(cls, centre, radius: float) -> Sensor:
        """A disc of ``radius`` (length, positive and finite) around ``centre`` ``(2,)``.

        Raises:
            InvalidArgumentError: on a radius that is not positive and finite, or a centre that is not 2 finite
                numbers.
        """
        c = _point("sensor centre", centre)
        r = _real_array("sensor radius", radius, InvalidArgumentError)
        if r.shape != () or not (np.isfinite(r) and r > 0.0):
            msg = f"sensor radius must be a positive finite number, got {r.tolist()!r}"
            raise InvalidArgumentError(msg)
        return cls(CIRCLE, [c[0], c[1], float(r), 0.0])

    @classmethod
    def rectangle(cls, lower_left, upper_right) -> Sensor:
        """The axis-aligned rectangle from ``lower_left`` ``(2,)`` to ``upper_right`` ``(2,)`` (length).

        Raises:
            InvalidArgumentError: unless both are 2 finite numbers and ``upper_right`` lies above and to the
                right of ``lower_left``.
        """
        lo = _point("sensor lower_left", lower_left)
        hi = _point("sensor upper_right", upper_right)
        if not (hi[0] > lo[0] and hi[1] > lo[1]):
            msg = f"sensor upper_right {hi.tolist()} must lie above and right of lower_left {lo.tolist()}"
            raise InvalidArgumentError(msg)
        return cls(RECTANGLE, [lo[0], lo[1], hi[0], hi[1]])

    @classmethod
    def line(cls, p0, p1) -> Sensor:
        """A trip wire from ``p0`` ``(2,)`` to ``p1`` ``(2,)`` (length; distinct): crossing it to the left of
        ``p1 - p0`` is entering, back is leaving.

        Raises:
            InvalidArgumentError: unless both are 2 finite numbers and they differ.
        """
        a = _point("sensor p0", p0)
        b = _point("sensor p1", p1)
        if np.array_equal(a, b):
            msg = f"sensor line end points must differ, got {a.tolist()} twice"
            raise InvalidArgumentError(msg)
        return cls(LINE, [a[0], a[1], b[0], b[1]])

    @property
    def shape(self) -> str:
        return _NAMES[self.code]

    def contains(self, points) -> np.ndarray:
        """``(P,)`` bool: whether each of ``points`` ``(P, 2)`` (or one ``(2,)``) is inside (see the module)."""
        p = np.atleast_2d(np.asarray(points, dtype=np.float64))
        x, y = p[:, 0], p[:, 1]
        a0, a1, a2, a3 = self.params.tolist()
        if self.code == CIRCLE:
            dx, dy = x - a0, y - a1
            return dx * dx + dy * dy < a2 * a2
        if self.code == RECTANGLE:
            return (a0 < x) & (x < a2) & (a1 < y) & (y < a3)
        return (a2 - a0) * (y - a1) - (a3 - a1) * (x - a0) > 0.0

    def crossed(self, before, after) -> np.ndarray:
        """``(P,)`` bool: whether the straight step from each of ``before`` to ``after`` (``(P, 2)``) crosses a
        line sensor's segment (a region's crossings are changes of :meth:`contains`)."""
        p, q = np.atleast_2d(before).astype(np.float64), np.atleast_2d(after).astype(np.float64)
        if self.code != LINE:
            return self.contains(p) != self.contains(q)
        a0, a1, a2, a3 = self.params.tolist()
        ex, ey = a2 - a0, a3 - a1
        sp = ex * (p[:, 1] - a1) - ey * (p[:, 0] - a0)
        sq = ex * (q[:, 1] - a1) - ey * (q[:, 0] - a0)
        flips = (sp > 0.0) != (sq > 0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            f = sp / (sp - sq)  # where along the step it meets the line
            mx, my = p[:, 0] + f * (q[:, 0] - p[:, 0]), p[:, 1] + f * (q[:, 1] - p[:, 1])
            u = ((mx - a0) * ex + (my - a1) * ey) / (ex * ex + ey * ey)
        return flips & (u >= 0.0) & (u <= 1.0)

    def bounds(self) -> tuple[float, float, float, float]:
        """The smallest axis-aligned rectangle holding the sensor: ``(x0, y0, x1, y1)``."""
        a0, a1, a2, a3 = self.params.tolist()
        if self.code == CIRCLE:
            return a0 - a2, a1 - a2, a0 + a2, a1 + a2
        return min(a0, a2), min(a1, a3), max(a0, a2), max(a1, a3)

    def __eq__(self, other) -> bool:
        return isinstance(other, Sensor) and other.code == self.code and bool(np.all(other.params == self.params))

    def __hash__(self) -> int:
        return hash((self.code, self.params.tobytes()))

    def __repr__(self) -> str:
        a0, a1, a2, a3 = self.params.tolist()
        if self.code == CIRCLE:
            return f"Sensor.circle(({a0!r}, {a1!r}), {a2!r})"
        if self.code == RECTANGLE:
            return f"Sensor.rectangle(({a0!r}, {a1!r}), ({a2!r}, {a3!r}))"
        return f"Sensor.line(({a0!r}, {a1!r}), ({a2!r}, {a3!r}))"


def check_sensors(sensors) -> tuple[Sensor, ...]:
    """``sensors`` as a tuple of :class:`Sensor` (None: none).

    Raises:
        InvalidArgumentError: naming the first item that is not a Sensor.
    """
    if sensors is None:
        return ()
    if isinstance(sensors, Sensor):
        sensors = [sensors]
    try:
        sensors = tuple(sensors)
    except TypeError:
        msg = f"sensors must be a list of discsim.Sensor, got {type(sensors).__name__} {sensors!r}"
        raise InvalidArgumentError(msg) from None
    for k, sensor in enumerate(sensors):
        if not isinstance(sensor, Sensor):
            msg = f"sensors[{k}] must be a discsim.Sensor (Sensor.circle, .rectangle, .line), got {sensor!r}"
            raise InvalidArgumentError(msg)
    return sensors


def sensor_rows(sensors) -> np.ndarray:
    """``(S, 5)`` float64: each sensor's four numbers (:attr:`Sensor.params`) and its shape code."""
    rows = np.zeros((len(sensors), 5))
    for k, sensor in enumerate(sensors):
        rows[k, :4] = sensor.params
        rows[k, 4] = sensor.code
    return rows


def edge_axis(code: float, a0: float, a1: float, a2: float, a3: float, width: float, height: float) -> int:
    """0 if a sensor (``code`` its shape code, ``a0 .. a3`` its :attr:`Sensor.params`) is a trip wire along a box's
    edge x = 0 or x = ``width``, 1 along y = 0 or y = ``height``, else -1 (plain floats: the compiled loop's too).

    In a periodic box the edges x = 0 and x = ``width`` are one line (so are y = 0 and y = ``height``): a centre
    crosses such a wire only by jumping across the box's edge, and its side of the wire is the side of the box's
    inside wherever it is (on the edge too).

    Example:
        >>> edge_axis(LINE, 0.0, 2.0, 0.0, 5.0, 10.0, 10.0), edge_axis(LINE, 1.0, 2.0, 1.0, 5.0, 10.0, 10.0)
        (0, -1)
    """
    if code != LINE:
        return -1
    if a0 == a2 and (a0 == 0.0 or a0 == width):
        return 0
    if a1 == a3 and (a1 == 0.0 or a1 == height):
        return 1
    return -1


def on_periodic_edge(sensor: Sensor, box) -> bool:
    """Whether ``sensor`` is a trip wire along the edge of ``box`` (a :class:`~discsim.model.Box`), a periodic one
    (:func:`edge_axis`)."""
    a0, a1, a2, a3 = sensor.params.tolist()
    return bool(box.periodic) and edge_axis(sensor.code, a0, a1, a2, a3, box.width, box.height) >= 0


def inside_table(sensors, positions, box=None) -> np.ndarray:
    """``(N, S)`` int64: 1 where each of ``positions`` ``(N, 2)`` is inside each sensor (:meth:`Sensor.contains`);
    in a periodic ``box`` (a :class:`~discsim.model.Box`), a trip wire along its edge (:func:`edge_axis`) takes the
    side of the box's inside."""
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    table = np.zeros((len(positions), len(sensors)), dtype=np.int64)
    for k, sensor in enumerate(sensors):
        if box is not None and on_periodic_edge(sensor, box):
            table[:, k] = sensor.contains([0.5 * box.width, 0.5 * box.height])[0]
        else:
            table[:, k] = sensor.contains(positions) if len(positions) else 0
    return table
