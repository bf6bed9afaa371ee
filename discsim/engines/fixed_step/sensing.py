"""The sensors at the frames: which discs' centres entered or left a sensor between two frames.

A fixed-step run sees its discs at its frames only, so it reports what changed from one frame to the next
(:class:`FrameSensors`): a circle or a rectangle when :meth:`~discsim.sensors.Sensor.contains` changed, a line
(a trip wire) when the straight step between the two frame positions crossed its segment
(:meth:`~discsim.sensors.Sensor.crossed`), ``ENTER`` when the step ended on the line's left side. A disc that
passes clean through a region between two frames is not seen (the exact engine sees it).

In a periodic box the regions are tested at the wrapped frame positions; a line is tested along the disc's
unwrapped step (a disc that left the box through one side during the frame did not jump across it), against
every image of the line the step reaches.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from discsim.engines.fixed_step.arrays import Paths, Tally
from discsim.events import ENTER, EVENT_DTYPE, LEAVE, Event, event_from_record
from discsim.model import Box
from discsim.sensors import LINE, Sensor

__all__ = ["FrameSensing", "FrameSensors"]

_NAN = float("nan")


class FrameSensing:
    """The sensors of a fixed-step run (a mixin of :class:`~discsim.engines.fixed_step.engine.FixedStep`): what it
    keeps of them, and the records of each frame.

    Attributes:
        sensors (tuple): the :class:`~discsim.sensors.Sensor` objects (empty: none).
    """

    # What the engine provides (declared for readers and the type checker).
    _paths: Paths
    _tally: Tally
    _log: Any
    sensors: tuple[Sensor, ...]
    _sensing: FrameSensors | None

    def _watch(self, sensors, box: Box) -> None:
        """Keep ``sensors`` (checked already: :func:`~discsim.sensors.check_sensors`)."""
        self.sensors = tuple(sensors)
        self._sensing = FrameSensors(self.sensors, box) if self.sensors else None

    def _sensor_settings(self) -> dict:
        """The sensors as a checkpoint's settings hold them: ``{"sensors": [[shape, 4 numbers], ...]}`` (none:
        ``{}``, as files written before the sensors)."""
        if not self.sensors:
            return {}
        return {"sensors": [[sensor.shape, *sensor.params.tolist()] for sensor in self.sensors]}

    def _sensed(self, last: tuple, t: float) -> list[Event]:
        """Count and log the crossings between the frame ``last`` (:meth:`FrameSensors.look`) and the frame just
        done at ``t``; returns their events."""
        sensing = self._sensing
        if sensing is None:
            return []
        records = sensing.records(t, last, self._paths)
        if not len(records):
            return []
        tally = self._tally
        tally.counts["sensor_events"] += len(records)
        if tally.log is not None:
            tally.log.extend(records)
        return [event_from_record(record) for record in records]


class FrameSensors:
    """The crossings of ``sensors`` between two frames, for every disc at once (numpy, one pass per sensor).

    Args:
        sensors: the :class:`~discsim.sensors.Sensor` tuple (checked already). box: the box.
    """

    def __init__(self, sensors: tuple[Sensor, ...], box: Box):
        self.sensors = sensors
        self.box = box
        # The sensors inside the box: a step that stays in it reaches none of their images.
        self._inside = [
            box.periodic and x0 >= 0.0 and y0 >= 0.0 and x1 < box.width and y1 < box.height
            for x0, y0, x1, y1 in (sensor.bounds() for sensor in sensors)
        ]

    def look(self, paths: Paths, frame_time: float) -> tuple[np.ndarray, np.ndarray | None]:
        """What :meth:`records` needs of the last frame, at ``frame_time``, before the next changes ``paths``:
        the frame positions (a copy) and, in a periodic box, the unwrapped positions (else None)."""
        return paths.frame_positions.copy(), paths.unwrapped(frame_time) if self.box.periodic else None

    def records(self, t: float, last: tuple[np.ndarray, np.ndarray | None], paths: Paths) -> np.ndarray:
        """The log records of the crossings between the frame ``last`` (:meth:`look`) and the frame at ``t``,
        ``paths`` at that frame (:meth:`crossings`)."""
        before, unwrapped = last
        moved = None if unwrapped is None else paths.unwrapped(t) - unwrapped
        return self.crossings(t, before, paths.frame_positions, moved, paths.velocities)

    def crossings(
        self, t: float, before: np.ndarray, after: np.ndarray, moved: np.ndarray | None, velocities: np.ndarray
    ) -> np.ndarray:
        """The log records of the crossings between the frame before and the frame at ``t``.

        Args:
            t: the frame's time.
            before, after ``(N, 2)``: the frame positions at the last frame and at ``t`` (wrapped into a periodic
                box).
            moved ``(N, 2)``: in a periodic box, each disc's unwrapped displacement between the two frames (None
                in a walled box).
            velocities ``(N, 2)``: the velocities at ``t``.

        Returns:
            ``(E,)`` :data:`~discsim.events.EVENT_DTYPE`: one ``ENTER`` or ``LEAVE`` per crossing, ``i`` the disc's
            index, ``j`` the sensor's, the disc's centre ``after`` and velocity at ``t``; by disc, then sensor.
        """
        end = after if moved is None else _unwrapped_end(before, after, moved, self.box.size)
        discs, sensors, kinds = [], [], []
        for k, sensor in enumerate(self.sensors):
            if sensor.code == LINE:
                rows, entered = self._line(sensor, before, end, images=end is not after or not self._inside[k])
            else:
                now = sensor.contains(after)
                rows = np.flatnonzero(sensor.contains(before) != now)
                entered = now[rows]
            discs.append(rows)
            sensors.append(np.full(len(rows), k, dtype=np.int64))
            kinds.append(np.where(entered, ENTER, LEAVE))
        disc = np.concatenate(discs) if discs else np.zeros(0, dtype=np.int64)
        if not len(disc):
            return np.zeros(0, dtype=EVENT_DTYPE)
        sensor_index, kind = np.concatenate(sensors), np.concatenate(kinds)
        order = np.lexsort((sensor_index, disc))  # by disc, then sensor (stable: a line's images in turn)
        disc, sensor_index, kind = disc[order], sensor_index[order], kind[order]
        out = np.empty(len(disc), dtype=EVENT_DTYPE)
        out["time"], out["kind"], out["i"], out["j"] = t, kind, disc, sensor_index
        out["xi"], out["yi"] = after[disc, 0], after[disc, 1]
        out["vxi"], out["vyi"] = velocities[disc, 0], velocities[disc, 1]
        for name in ("xj", "yj", "vxj", "vyj"):
            out[name] = _NAN
        return out

    def _line(self, sensor: Sensor, before: np.ndarray, end: np.ndarray, images: bool) -> tuple[np.ndarray, np.ndarray]:
        """``(discs, entered)``: the discs whose step from ``before`` to ``end`` crosses ``sensor`` (a line), one
        row per image of the line crossed in a periodic box (``images``: some step may reach another image than
        the line's own), and whether each ended on its left."""
        # The line itself first, for every disc: in a periodic box most steps reach no other image.
        rows = np.flatnonzero(sensor.crossed(before, end))
        hits, entered = [rows], [sensor.contains(end[rows])]
        if self.box.periodic and images:
            # The images m (whole boxes) of the line that the step's bounding box reaches, per axis; a disc whose
            # step reaches another image than the line's own is tested against each (few discs, few images).
            size = self.box.size
            x0, y0, x1, y1 = sensor.bounds()
            low, high = np.minimum(before, end), np.maximum(before, end)
            first = np.ceil((low - np.array([x1, y1])) / size).astype(np.int64)
            last = np.floor((high - np.array([x0, y0])) / size).astype(np.int64)
            odd = np.flatnonzero((first <= last).all(axis=1) & ((first != 0) | (last != 0)).any(axis=1))
            for d in odd.tolist():
                for mx in range(int(first[d, 0]), int(last[d, 0]) + 1):
                    for my in range(int(first[d, 1]), int(last[d, 1]) + 1):
                        if mx == 0 and my == 0:
                            continue  # tested above
                        shift = np.array([mx, my]) * size  # the step moved back by the image's offset
                        p, q = before[d : d + 1] - shift, end[d : d + 1] - shift
                        if sensor.crossed(p, q)[0]:
                            hits.append(np.array([d]))
                            entered.append(sensor.contains(q))
        return np.concatenate(hits), np.concatenate(entered)


def _unwrapped_end(before: np.ndarray, after: np.ndarray, moved: np.ndarray, size: np.ndarray) -> np.ndarray:
    """``after`` moved by the whole box lengths that put it ``moved`` from ``before`` (to roundoff)."""
    boxes = np.rint((before + moved - after) / size)
    return after + boxes * size if bool(np.any(boxes)) else after
