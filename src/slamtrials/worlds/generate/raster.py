"""From plan metres to grid cells: the :class:`Grid`, painting room labels, and drawing walls.

The label image is int32 ``[H, W]`` (row 0 at the top): 0 outside the building, 1 circulation
(corridors, lobbies, recesses), 2 and up one label per room. Walls are drawn on every boundary between
two labels, ``wall_px`` cells thick and centred on the boundary.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.worlds.generate.plan import Plan, Rect

__all__ = ["Grid", "CIRCULATION", "OUTSIDE", "paint_labels", "draw_walls", "wall_pixels"]

OUTSIDE = 0
CIRCULATION = 1


@dataclass(frozen=True)
class Grid:
    """The raster of a plan: ``rows x cols`` cells of ``resolution`` m, with ``margin`` m around the plan.

    Plan point (x, y) lies at map coordinates ``u = (x + margin) / resolution`` (columns, rightwards)
    and ``v = (y + margin) / resolution`` (upwards from the bottom edge), the frame of
    :func:`slamtrials.worlds.world.world_to_map` for a world whose origin is ``(-margin, -margin, 0)``.
    """

    rows: int
    cols: int
    resolution: float
    margin: float

    @classmethod
    def for_plan(cls, plan: Plan, resolution: float, margin: float = 1.0) -> Grid:
        """A grid covering the plan's bounds (which start at 0, 0) plus the margin."""
        box = plan.bounds()
        cols = int(math.ceil((box.x1 + 2 * margin) / resolution))
        rows = int(math.ceil((box.y1 + 2 * margin) / resolution))
        return cls(rows, cols, resolution, margin)

    @property
    def origin(self) -> NDArray[np.float64]:
        """World pose of the lower-left grid corner."""
        return np.array([-self.margin, -self.margin, 0.0])

    def px(self, metres: float) -> int:
        """A length in metres as a whole number of cells (rounded, at least 1)."""
        return max(1, int(round(metres / self.resolution)))

    def slices(self, rect: Rect) -> tuple[slice, slice]:
        """(row slice, column slice) of the cells whose centres lie in the rectangle, clipped to the grid."""
        res, m = self.resolution, self.margin
        c0 = int(round((rect.x0 + m) / res))
        c1 = int(round((rect.x1 + m) / res))
        r0 = self.rows - int(round((rect.y1 + m) / res))
        r1 = self.rows - int(round((rect.y0 + m) / res))
        return slice(max(0, r0), min(self.rows, r1)), slice(max(0, c0), min(self.cols, c1))

    def cell_centre(self, row: float, col: float) -> tuple[float, float]:
        """Plan coordinates (m) of the centre of cell (row, col); fractional indices allowed."""
        x = (col + 0.5) * self.resolution - self.margin
        y = (self.rows - row - 0.5) * self.resolution - self.margin
        return x, y


def paint_labels(plan: Plan, grid: Grid) -> tuple[NDArray[np.int32], list[tuple[str, str]]]:
    """Paint the plan: rooms first (label 2, 3, ... in order), then circulation (label 1) over them.

    Returns the label image and, for label ``k >= 2``, ``uses[k - 2] = (use, style)``.
    """
    labels = np.zeros((grid.rows, grid.cols), dtype=np.int32)
    uses: list[tuple[str, str]] = []
    for index, room in enumerate(plan.rooms):
        labels[grid.slices(room.rect)] = index + 2
        uses.append((room.use, room.style))
    for rect in plan.recesses:
        labels[grid.slices(rect)] = CIRCULATION
    for rect, _axis, _style in plan.corridors:
        labels[grid.slices(rect)] = CIRCULATION
    for rect, _style in plan.lobbies:
        labels[grid.slices(rect)] = CIRCULATION
    return labels, uses


def wall_pixels(resolution: float, thickness: float = 0.2) -> int:
    """Half-width k of the wall dilation: walls are ``2 + 2k`` cells thick, about ``thickness`` metres."""
    return max(0, int(round((thickness / resolution - 2.0) / 2.0)))


def draw_walls(labels: NDArray[np.int32], k: int) -> NDArray[np.bool_]:
    """bool ``[H, W]`` occupied: outside the building, plus walls ``2 + 2k`` cells thick on label boundaries."""
    boundary = np.zeros(labels.shape, dtype=bool)
    horizontal = labels[:, 1:] != labels[:, :-1]
    boundary[:, 1:] |= horizontal
    boundary[:, :-1] |= horizontal
    vertical = labels[1:, :] != labels[:-1, :]
    boundary[1:, :] |= vertical
    boundary[:-1, :] |= vertical
    boundary = _dilate(boundary, k)
    occupied = boundary | (labels == OUTSIDE)
    occupied[0, :] = occupied[-1, :] = True
    occupied[:, 0] = occupied[:, -1] = True
    return occupied


def _dilate(mask: NDArray[np.bool_], k: int) -> NDArray[np.bool_]:
    """Dilate by a ``(2k + 1)`` square, by shifting (fast for the small k of walls)."""
    for axis in (0, 1):
        out = mask.copy()
        src = mask
        for step in range(1, k + 1):
            if axis == 0:
                out[step:, :] |= src[:-step, :]
                out[:-step, :] |= src[step:, :]
            else:
                out[:, step:] |= src[:, :-step]
                out[:, :-step] |= src[:, step:]
        mask = out
    return mask
