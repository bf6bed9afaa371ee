"""The sensors and segments in discsim.plot's pictures (matplotlib): drawn as the viewer (:mod:`discsim.view`) draws
them (a moving segment where it is at the time drawn)."""

from __future__ import annotations

import math
from typing import Any

import matplotlib.colors
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Rectangle

__all__ = ["SENSOR_COLOUR", "draw_segments", "draw_sensors", "segment_lines"]

#: Dark goldenrod, the viewer's too: apart from tab10 (the discs) and viridis (speeds).
SENSOR_COLOUR = "#b8860b"


def draw_sensors(ax, sensors, box) -> None:
    """Draw ``sensors`` (:class:`~discsim.sensors.Sensor` s) on ``ax``, under the discs: circles and rectangles
    translucent and outlined, trip wires dashed with a small arrow from their middle to their inside (the left of
    ``p1 - p0``; at most 5% of the ``box``'s longer side long, None: a fifth of the wire). Each sensor's artist has
    the gid ``"sensor k"`` (a wire's arrow ``"sensor k inside"``)."""
    style: dict[str, Any] = {"facecolor": (*matplotlib.colors.to_rgb(SENSOR_COLOUR), 0.12), "edgecolor": SENSOR_COLOUR}
    for k, sensor in enumerate(sensors):
        a0, a1, a2, a3 = sensor.params.tolist()
        gid = f"sensor {k}"
        if sensor.shape == "circle":
            ax.add_patch(Circle((a0, a1), a2, linewidth=1.2, zorder=1, gid=gid, **style))
        elif sensor.shape == "rectangle":
            ax.add_patch(Rectangle((a0, a1), a2 - a0, a3 - a1, linewidth=1.2, zorder=1, gid=gid, **style))
        else:
            ax.add_line(
                Line2D([a0, a2], [a1, a3], color=SENSOR_COLOUR, linestyle="--", linewidth=1.4, zorder=1, gid=gid)
            )
            length = math.hypot(a2 - a0, a3 - a1)
            arrow = min(0.2 * length, 0.05 * max(box.width, box.height)) if box is not None else 0.2 * length
            mx, my = 0.5 * (a0 + a2), 0.5 * (a1 + a3)
            nx, ny = -(a3 - a1) / length, (a2 - a0) / length  # the left of p1 - p0: inside
            ax.annotate(
                "",
                xy=(mx + arrow * nx, my + arrow * ny),
                xytext=(mx, my),
                arrowprops={"arrowstyle": "-|>", "color": SENSOR_COLOUR, "linewidth": 1.2, "shrinkA": 0, "shrinkB": 0},
                zorder=1,
                gid=f"{gid} inside",
            )


def segment_lines(segments, time: float) -> list[np.ndarray]:
    """Each segment's end points ``(2, 2)`` at ``time``: a moving one where :meth:`Segment.at` puts it
    (``p0 + v t``, ``p1 + v t``), a fixed one where it is."""
    return [np.array([moved.p0, moved.p1]) for moved in (s.at(time) for s in segments)]


def draw_segments(ax, segments, time: float) -> LineCollection | None:
    """Draw ``segments`` (:class:`~discsim.model.Segment` s) on ``ax`` where they are at ``time``, as one
    ``LineCollection`` with the gid ``"segments"`` (returned: an animation moves it); None where there is none."""
    if not len(segments):
        return None
    lines = LineCollection(segment_lines(segments, time), colors="0.2", linewidths=2.0, zorder=2.5, gid="segments")
    ax.add_collection(lines)
    return lines
