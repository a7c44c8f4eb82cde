"""Matplotlib figures drawn on a given Axes: floor plans (and, later, error plots).

Functions here never pick a backend and never show a window; they draw on the Axes they are given.
:func:`save_world_figure` makes its own :class:`matplotlib.figure.Figure` (no pyplot), so it works
under any backend.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from slamtrials.worlds.world import World

__all__ = ["draw_world", "save_world_figure", "world_picture", "nice_length"]

FREE_RGB = (1.0, 1.0, 1.0)
WALL_RGB = (0.0, 0.0, 0.0)
SOLID_RGB = (0.78, 0.78, 0.78)


def nice_length(span: float) -> float:
    """A round length (1, 2 or 5 times a power of ten) of about a fifth of ``span`` metres."""
    target = max(span / 5.0, 1e-3)
    power = 10.0 ** math.floor(math.log10(target))
    for factor in (5.0, 2.0, 1.0):
        if factor * power <= target:
            return factor * power
    return power


def world_picture(world: World, max_pixels: int = 2000) -> tuple[NDArray[np.float64], int]:
    """RGB image ``[h, w, 3]`` of the world for display, and the block size it was reduced by.

    Blocks of ``f x f`` cells are shown as occupied if any cell is, so thin walls survive the
    reduction. Occupied cells are black (walls, furniture), except the solid mass outside the
    building (more than 0.25 m from free space and connected to the image border), which is grey.
    """
    occ = world.occupied
    factor = max(1, math.ceil(max(occ.shape) / max_pixels))
    if factor > 1:
        h, w = occ.shape
        padded = np.pad(occ, ((0, (-h) % factor), (0, (-w) % factor)), constant_values=True)
        occ = padded.reshape(padded.shape[0] // factor, factor, padded.shape[1] // factor, factor).any(axis=(1, 3))
    cell = world.resolution * factor
    deep = ndimage.distance_transform_edt(occ) * cell > max(0.25, 1.5 * cell)
    parts, _count = ndimage.label(deep)
    border = np.unique(np.concatenate([parts[0], parts[-1], parts[:, 0], parts[:, -1]]))
    outside = np.isin(parts, border[border > 0])
    rgb = np.empty(occ.shape + (3,))
    rgb[...] = FREE_RGB
    rgb[occ] = WALL_RGB
    rgb[outside] = SOLID_RGB
    return rgb, factor


def draw_world(
    ax, world: World, *, start: bool = True, scale_bar: bool = True, title: str | None = None, max_pixels: int = 2000
) -> None:
    """Draw a world on ``ax`` in world coordinates (metres): walls black, free white, outside grey,
    the start pose as an arrow, a scale bar in metres, and a title with the name and the free area.

    Parameters
    ----------
    ax:
        A matplotlib Axes.
    world:
        The world to draw.
    start:
        Draw the start pose.
    scale_bar:
        Draw a scale bar in the lower right corner.
    title:
        Title; default ``"<name>: <free area> m^2 free, <w> x <h> m"``; ``""`` for none.
    max_pixels:
        Largest image side drawn; bigger grids are reduced (keeping every wall).
    """
    from matplotlib.transforms import Affine2D

    rgb, _factor = world_picture(world, max_pixels)
    width, height = world.size_m
    ox, oy, theta = (float(v) for v in world.origin)
    image = ax.imshow(rgb, extent=(0.0, width, 0.0, height), origin="upper", interpolation="nearest", zorder=0)
    image.set_transform(Affine2D().rotate(theta).translate(ox, oy) + ax.transData)
    corners = Affine2D().rotate(theta).translate(ox, oy).transform([[0, 0], [width, 0], [0, height], [width, height]])
    ax.set_xlim(corners[:, 0].min(), corners[:, 0].max())
    ax.set_ylim(corners[:, 1].min(), corners[:, 1].max())
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    span = max(width, height)
    if start and world.start is not None:
        x, y, heading = (float(v) for v in world.start)
        length = max(0.8, 0.04 * span)
        ax.plot([x], [y], "o", color="tab:green", ms=5, zorder=3)
        ax.annotate(
            "",
            xy=(x + length * math.cos(heading), y + length * math.sin(heading)),
            xytext=(x, y),
            arrowprops={"arrowstyle": "-|>", "color": "tab:green", "lw": 2},
            zorder=3,
        )
    if scale_bar:
        _scale_bar(ax, nice_length(width))
    if title is None:
        title = f"{world.name}: {world.free_area:,.0f} m\u00b2 free, {width:.0f} \u00d7 {height:.0f} m"
    if title:
        ax.set_title(title, fontsize=10)


def _scale_bar(ax, length: float) -> None:
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

    label = f"{length:g} m"
    bar = AnchoredSizeBar(
        ax.transData,
        length,
        label,
        loc="lower right",
        pad=0.4,
        borderpad=0.6,
        sep=3,
        frameon=True,
        size_vertical=0,
        color="tab:blue",
    )
    bar.patch.set_alpha(0.85)
    ax.add_artist(bar)


def save_world_figure(world: World, path: str | Path, *, dpi: int = 120, title: str | None = None) -> Path:
    """Render :func:`draw_world` into an image file (format by suffix, PNG by default) and return its path."""
    from matplotlib.figure import Figure

    from slamtrials.atomicfile import atomic_write

    width, height = world.size_m
    aspect = height / width if width > 0 else 1.0
    fig_w = 9.0
    fig = Figure(figsize=(fig_w, max(3.0, min(14.0, fig_w * aspect)) + 0.7), dpi=dpi)
    ax = fig.add_subplot()
    draw_world(ax, world, title=title, max_pixels=int(fig_w * dpi * 1.2))
    fig.tight_layout()
    path = Path(path)
    fmt = path.suffix.lstrip(".").lower() or "png"
    atomic_write(path, lambda handle: fig.savefig(handle, format=fmt))
    return path
