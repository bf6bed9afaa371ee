"""Sensors and moving segments in the compiled event loop (:mod:`~discsim.engines.event_driven.numba.loop`, the loop
of the laws only).

- :func:`sense`: a disc's centre changes sides of a sensor: its side flips, and the change is logged (``ENTER`` or
  ``LEAVE``) unless it crossed a trip wire's line beyond the wire's ends;
- :func:`wrap_sense`: what a jump across a periodic box's edge crosses (below), one crossing at a time;
- :func:`resense`: a disc's sides of every sensor taken from where it is (after a jump across a periodic box);
- :func:`place_segments`: the moving segments' rows where they are at an epoch.

A disc's side of sensor ``s`` is ``rest[n + i S + s]`` (``n`` discs, ``S`` sensors: after the rest flags, in one
array); a sensor's row in ``seg`` holds its numbers, shape code and index (:class:`~discsim.sensors.Sensor`), a
segment's its end points now, code 0, its velocity and its end points at time 0.

A periodic box's edges x = 0 and x = W are one line (so are y = 0 and y = H), and a centre crosses it only by
jumping from one to the other, so the jump is where a sensor on that line is crossed (:func:`wrap_sense`):

- a trip wire along an edge (:func:`~discsim.sensors.edge_axis`: both ends on x = 0, both on x = W, or so in
  y) is crossed by every jump across that edge at a point of the wire (its ends included): entering when the
  centre moves to the wire's left, else leaving. No prediction sees such a wire (no cell lists it: the box exits
  are the jumps); a disc's side of it is the box's inside's, and the other side while the jump's crossing is
  reported and the jump waits (pushed again at the same time);
- a region lies inside the box: on the torus it is left (or entered) there if the disc's side of it differs from
  its side where the jump lands (a tie lost by roundoff to the jump; a region on the edge entered from the other);
- any other trip wire's side is the plane's: the jump changes it without a crossing (:func:`resense`).
"""

from __future__ import annotations

import numpy as np

from discsim._compiled import jit
from discsim.engines.event_driven.numba.support import VX, VY, T, W, X, Y, accel
from discsim.events import EventKind
from discsim.physics.compiled import advance, sensor_contains, sensor_on_wire
from discsim.sensors import edge_axis as _edge_axis

__all__ = ["edge_axis", "place_segments", "resense", "sense", "wrap_sense"]

ENTER, LEAVE = int(EventKind.ENTER), int(EventKind.LEAVE)
LINE = 3.0  # a trip wire's shape code (discsim.sensors.LINE)
#: :func:`discsim.sensors.edge_axis`, compiled: whether a sensor is a trip wire along the box's edge.
edge_axis = jit(_edge_axis)


@jit
def sense(
    i, t, other, epoch, gravity, gx, gy, drag, rough, recording, logged, rec, rest, seg, order, rot,
    ev_t, ev_kind, ev_i, ev_j, ev_f, ev_w,
):  # fmt: skip
    """Disc ``i``'s centre changes sides of the sensor of row ``other`` at ``t``: flip its side, and log the change
    in row ``logged`` when ``recording``. Returns the kind logged (``ENTER`` or ``LEAVE``), or -1 when a trip
    wire's line was crossed beyond the wire's ends (the side changes, nothing is reported)."""
    n = rec.shape[0]
    s = int(seg[other, 5])
    slot = n + i * ((rest.shape[0] - n) // n) + s
    entering = rest[slot] == 0
    rest[slot] = 1 if entering else 0
    axi, ayi = accel(i, gravity, gx, gy, rec, rest)
    xi, yi, vxi, vyi = advance(rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], t - rec[i, T], axi, ayi, drag)
    if seg[other, 4] == LINE and not sensor_on_wire(seg[other, 0], seg[other, 1], seg[other, 2], seg[other, 3], xi, yi):
        return -1
    sensed = ENTER if entering else LEAVE
    if recording:
        ev_t[logged] = t + epoch
        ev_kind[logged] = sensed
        ev_i[logged] = order[i]
        ev_j[logged] = s
        ev_f[logged, 0], ev_f[logged, 1], ev_f[logged, 2], ev_f[logged, 3] = xi, yi, vxi, vyi
        ev_f[logged, 4] = ev_f[logged, 5] = ev_f[logged, 6] = ev_f[logged, 7] = np.nan
        if rough:
            ev_w[logged, 0], ev_w[logged, 1] = rot[i, W], np.nan
    return sensed


@jit
def wrap_sense(
    i, t, epoch, wrap_x, wrap_y, width, height, gravity, gx, gy, drag, rough, recording, logged, rec, rest, seg,
    order, rot, ev_t, ev_kind, ev_i, ev_j, ev_f, ev_w,
):  # fmt: skip
    """Disc ``i`` is about to jump across the periodic box's edge at ``t`` (``wrap_x`` or ``wrap_y`` its direction,
    +-1): the first sensor that jump crosses and that is not reported yet (see the module), its side flipped and
    the crossing logged in row ``logged`` when ``recording``. Returns ``(kind, sensor)`` (``ENTER`` or ``LEAVE``),
    or ``(-1, -1)`` when nothing is left to report and the jump may go on."""
    n = rec.shape[0]
    n_sensors = (rest.shape[0] - n) // n
    axi, ayi = accel(i, gravity, gx, gy, rec, rest)
    xi, yi, vxi, vyi = advance(rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], t - rec[i, T], axi, ayi, drag)
    # Where it lands, as the loop will find it after the jump (the same operations on the same numbers).
    px, py, _, _ = advance(
        rec[i, X] - wrap_x * width, rec[i, Y] - wrap_y * height, rec[i, VX], rec[i, VY], t - rec[i, T], axi, ayi, drag
    )
    for k in range(seg.shape[0] - n_sensors, seg.shape[0]):
        shape, a0, a1, a2, a3 = seg[k, 4], seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3]
        slot = n + i * n_sensors + int(seg[k, 5])
        axis = edge_axis(shape, a0, a1, a2, a3, width, height)
        if axis >= 0:
            if (axis == 0) != (wrap_x != 0):  # along the other edges
                continue
            usual = 1 if sensor_contains(shape, a0, a1, a2, a3, 0.5 * width, 0.5 * height) else 0
            if rest[slot] != usual:  # reported already: the jump goes on
                continue
            if not sensor_on_wire(a0, a1, a2, a3, a0 if axis == 0 else xi, yi if axis == 0 else a1):
                continue
            inside = (a2 - a0) * vyi - (a3 - a1) * vxi > 0.0  # to the wire's left
            rest[slot] = 1 - usual
        else:
            if shape == LINE:
                continue
            inside = sensor_contains(shape, a0, a1, a2, a3, px, py)
            if (rest[slot] != 0) == inside:
                continue
            rest[slot] = 1 if inside else 0
        sensed = ENTER if inside else LEAVE
        if recording:
            ev_t[logged] = t + epoch
            ev_kind[logged] = sensed
            ev_i[logged] = order[i]
            ev_j[logged] = int(seg[k, 5])
            ev_f[logged, 0], ev_f[logged, 1], ev_f[logged, 2], ev_f[logged, 3] = xi, yi, vxi, vyi
            ev_f[logged, 4] = ev_f[logged, 5] = ev_f[logged, 6] = ev_f[logged, 7] = np.nan
            if rough:
                ev_w[logged, 0], ev_w[logged, 1] = rot[i, W], np.nan
        return sensed, int(seg[k, 5])
    return -1, -1


@jit
def resense(i, t, gravity, gx, gy, drag, rec, rest, seg, width, height):
    """Take disc ``i``'s side of every sensor from where its centre is at ``t`` (after a jump across the box; a
    trip wire along an edge: its side inside the box)."""
    n = rec.shape[0]
    n_sensors = (rest.shape[0] - n) // n
    axi, ayi = accel(i, gravity, gx, gy, rec, rest)
    xi, yi, _, _ = advance(rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], t - rec[i, T], axi, ayi, drag)
    for k in range(seg.shape[0] - n_sensors, seg.shape[0]):
        px, py = xi, yi
        if edge_axis(seg[k, 4], seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3], width, height) >= 0:
            px, py = 0.5 * width, 0.5 * height
        inside = sensor_contains(seg[k, 4], seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3], px, py)
        rest[n + i * n_sensors + int(seg[k, 5])] = 1 if inside else 0


@jit
def place_segments(seg, epoch):
    """Each moving segment's row where it is at ``epoch`` (from where it was at time 0: the same at every call)."""
    for k in range(seg.shape[0]):
        if seg[k, 6] != 0.0 or seg[k, 7] != 0.0:
            seg[k, 0] = seg[k, 8] + seg[k, 6] * epoch
            seg[k, 1] = seg[k, 9] + seg[k, 7] * epoch
            seg[k, 2] = seg[k, 10] + seg[k, 6] * epoch
            seg[k, 3] = seg[k, 11] + seg[k, 7] * epoch
