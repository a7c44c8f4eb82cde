"""Where the cells of a map lie: the explore layer's one conversion between cells and map-frame points.

A map (any object with ``grid``, ``resolution`` and ``origin``, e.g.
:class:`slamtrials.slam.OccupancyGrid`) has ``grid`` int8 ``[H, W]`` with row 0 the TOP row (largest
y, as in ROS and PNG) and ``origin`` the map-frame pose (x, y, theta) of the lower-left corner of the
lower-left cell (row ``H - 1``, column 0). The layer rule keeps ``explore`` from importing the worlds'
or the SLAM layer's helpers, so this module is the only place in ``explore`` that does this arithmetic.

Map coordinates (u, v) are in cells: u along the columns from the left edge, v up from the bottom edge.
Cell ``(row, col)`` covers ``col <= u < col + 1`` and ``H - 1 - row <= v < H - row``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["FREE_BELOW", "GridFrame", "map_arrays"]

#: Cell values ``0 <= value < FREE_BELOW`` are free, ``>= FREE_BELOW`` occupied, negative unknown
#: (a trinary map holds 0, 100 and -1; a probability map 0..100 is split at 50).
FREE_BELOW = 50


def map_arrays(occupancy: Any) -> tuple[NDArray[np.int8], float, NDArray[np.float64]]:
    """``(grid int8 [H, W], resolution m, origin float64 [3])`` of a map object (duck typed)."""
    grid = np.asarray(occupancy.grid)
    if grid.ndim != 2:
        raise ValueError(f"map grid must be 2-D [H, W], got shape {grid.shape}")
    if grid.dtype != np.int8:
        grid = grid.astype(np.int8)
    resolution = float(occupancy.resolution)
    if not (math.isfinite(resolution) and resolution > 0):
        raise ValueError(f"map resolution must be positive metres, got {resolution!r}")
    origin = np.asarray(occupancy.origin, dtype=np.float64).reshape(-1)
    if origin.shape != (3,):
        raise ValueError(f"map origin must be (x, y, theta), got {occupancy.origin!r}")
    return grid, resolution, origin


@dataclass(frozen=True)
class GridFrame:
    """The placement of an ``height x width`` grid in the map frame.

    Attributes
    ----------
    height, width:
        Grid shape (cells).
    resolution:
        Cell size (m).
    origin:
        ``(x, y, theta)``: map-frame pose (m, m, rad) of the lower-left corner of cell ``(height - 1, 0)``.
    """

    height: int
    width: int
    resolution: float
    origin: tuple[float, float, float]

    @classmethod
    def of(cls, occupancy: Any) -> GridFrame:
        """The frame of a map object with ``grid``, ``resolution`` and ``origin``."""
        grid, resolution, origin = map_arrays(occupancy)
        return cls(
            int(grid.shape[0]), int(grid.shape[1]), resolution, (float(origin[0]), float(origin[1]), float(origin[2]))
        )

    def to_cell(self, xy: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """Integer cells ``(rows, cols)`` holding map-frame points ``[..., 2]`` (m); may lie outside the grid."""
        pts = np.asarray(xy, dtype=np.float64)
        ox, oy, th = self.origin
        dx, dy = pts[..., 0] - ox, pts[..., 1] - oy
        c, s = math.cos(th), math.sin(th)
        u = (c * dx + s * dy) / self.resolution
        v = (-s * dx + c * dy) / self.resolution
        cols = np.floor(u).astype(np.intp)
        rows = (self.height - 1 - np.floor(v)).astype(np.intp)
        return rows, cols

    def to_xy(self, rows: ArrayLike, cols: ArrayLike) -> NDArray[np.float64]:
        """Map-frame centres ``[..., 2]`` (m) of cells ``(rows, cols)``."""
        r = np.asarray(rows, dtype=np.float64)
        cc = np.asarray(cols, dtype=np.float64)
        u = (cc + 0.5) * self.resolution
        v = (self.height - r - 0.5) * self.resolution
        ox, oy, th = self.origin
        c, s = math.cos(th), math.sin(th)
        return np.stack([ox + c * u - s * v, oy + s * u + c * v], axis=-1)

    def inside(self, row: int, col: int) -> bool:
        """Whether cell ``(row, col)`` lies in the grid."""
        return 0 <= row < self.height and 0 <= col < self.width

    def sub(self, row0: int, col0: int, height: int, width: int) -> GridFrame:
        """The frame of the window whose top-left cell is ``(row0, col0)`` of this grid (may stick out)."""
        u = col0 * self.resolution
        v = (self.height - row0 - height) * self.resolution
        ox, oy, th = self.origin
        c, s = math.cos(th), math.sin(th)
        return GridFrame(int(height), int(width), self.resolution, (ox + c * u - s * v, oy + s * u + c * v, th))
