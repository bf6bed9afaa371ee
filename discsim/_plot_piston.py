"""A run's piston in discsim.plot's pictures (matplotlib): drawn as the viewer (:mod:`discsim.view`) draws it, a thick
bar across the box at its height with the box above it shaded (no gas there)."""

from __future__ import annotations

from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle

__all__ = ["PISTON_COLOUR", "draw_piston", "piston_mover"]

#: Blue grey, the viewer's too: apart from tab10 (the discs), viridis (speeds) and the sensors' gold.
PISTON_COLOUR = "#37474f"


def draw_piston(ax, sim, height: float | None = None) -> tuple[Line2D, Rectangle] | None:
    """Draw the piston of ``sim`` (an engine; None without a piston) on ``ax`` at ``height`` (default where it is
    now, ``sim.piston.height``): a bar (gid ``"piston"``) and the shaded box above it (gid ``"piston above"``).
    Returns ``(bar, shade)``, or None when there is no piston."""
    piston = getattr(sim, "piston", None)
    if piston is None:
        return None
    box = sim.box
    h = float(piston.height if height is None else height)
    shade = Rectangle((0.0, h), box.width, box.height - h, facecolor=PISTON_COLOUR, alpha=0.18, linewidth=0)
    shade.set(zorder=1, gid="piston above")
    bar = Line2D([0.0, box.width], [h, h], color=PISTON_COLOUR, linewidth=4, solid_capstyle="butt", zorder=4)
    bar.set_gid("piston")
    ax.add_patch(shade)
    ax.add_line(bar)
    return bar, shade


def piston_mover(ax, sim, times, dynamic: list):
    """Draw the piston of ``sim`` at ``times[0]`` and return ``move(k)``, which puts it where it was at ``times[k]``
    (from :func:`~discsim.analysis.piston_path.piston_path`); its artists join ``dynamic`` (those an animation
    redraws). Without a piston nothing is drawn and ``move`` does nothing."""
    if getattr(sim, "piston", None) is None:
        return lambda k: None
    from discsim.analysis.piston_path import piston_path

    heights = piston_path(sim).height(times)
    bar, shade = draw_piston(ax, sim, float(heights[0]))  # type: ignore[misc]  # (it has a piston)
    dynamic += [bar, shade]
    top = float(sim.box.height)

    def move(k: int) -> None:
        h = float(heights[k])
        bar.set_ydata([h, h])
        shade.set_y(h)
        shade.set_height(top - h)

    return move
