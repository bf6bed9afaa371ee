"""Sensors and moving segments in the compiled event loop (:mod:`~discsim.engines.event_driven.numba.loop`, the loop
of the laws only).

- :func:`sense`: a disc's centre changes sides of a sensor: its side flips, and the change is logged (``ENTER`` or
  ``LEAVE``) unless it crossed a trip wire's line beyond the wire's ends;
- :func:`resense`: a disc's sides of every sensor taken from where it is (after a jump across a periodic box);
- :func:`place_segments`: the moving segments' rows where they are at an epoch.

A disc's side of sensor ``s`` is ``rest[n + i S + s]`` (``n`` discs, ``S`` sensors: after the rest flags, in one
array); a sensor's row in ``seg`` holds its numbers, shape code and index (:class:`~discsim.sensors.Sensor`), a
segment's its end points now, code 0, its velocity and its end points at time 0.
"""

from __future__ import annotations

import numpy as np

from discsim._compiled import jit
from discsim.engines.event_driven.numba.support import VX, VY, T, W, X, Y, accel
from discsim.events import EventKind
from discsim.physics.compiled import advance, sensor_contains, sensor_on_wire

__all__ = ["place_segments", "resense", "sense"]

ENTER, LEAVE = int(EventKind.ENTER), int(EventKind.LEAVE)
LINE = 3.0  # a trip wire's shape code (discsim.sensors.LINE)


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
def resense(i, t, gravity, gx, gy, drag, rec, rest, seg):
    """Take disc ``i``'s side of every sensor from where its centre is at ``t`` (after a jump across the box)."""
    n = rec.shape[0]
    n_sensors = (rest.shape[0] - n) // n
    axi, ayi = accel(i, gravity, gx, gy, rec, rest)
    xi, yi, _, _ = advance(rec[i, X], rec[i, Y], rec[i, VX], rec[i, VY], t - rec[i, T], axi, ayi, drag)
    for k in range(seg.shape[0] - n_sensors, seg.shape[0]):
        inside = sensor_contains(seg[k, 4], seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3], xi, yi)
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
