"""discsim.plot's GIF writer: an animation's frames blitted onto its still parts, written by Pillow."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["save_gif"]


def save_gif(fig, update, dynamic, count: int, path: Path, fps: float, dpi: int) -> None:
    """Write the animation as a GIF by blitting: the still parts (axes, ticks, box, titles) are drawn once,
    and each frame redraws only the moving artists onto a copy of them (Pillow writes the file)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    for artist in dynamic:
        artist.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    images: list[Any] = []
    for k in range(count):
        update(k)
        canvas.restore_region(background)
        for artist in dynamic:
            fig.draw_artist(artist)
        rgb = np.asarray(canvas.buffer_rgba())[..., :3]
        image = Image.fromarray(np.ascontiguousarray(rgb))
        # One palette for the whole movie (the first frame's): quantising each frame alone costs more.
        images.append(image.quantize(256) if not images else image.quantize(palette=images[0]))
    for artist in dynamic:
        artist.set_animated(False)
    images[0].save(path, save_all=True, append_images=images[1:], duration=round(1000.0 / fps), loop=0)
