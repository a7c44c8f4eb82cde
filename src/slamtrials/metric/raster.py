"""Where the cells of a grid lie: the metric layer's one conversion between cells and frame points.

A grid (a SLAM map or a floor plan) has ``H x W`` cells of ``resolution`` m with row 0 the TOP row
(largest y, as in ROS and PNG) and ``origin`` the pose (x, y, theta) of the lower-left corner of the
lower-left cell (row ``H - 1``, column 0) in the grid's frame, as in a ROS map_server YAML and as
:class:`slamtrials.record.OccupancyGrid` and :class:`slamtrials.worlds.World` hold them. The layer rule
keeps ``metric`` from importing the worlds' helpers, so this module is the only place in ``metric`` that
does this arithmetic (the same as :func:`slamtrials.worlds.world.cell_to_world`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials.geometry import inverse, transform_points

__all__ = ["Raster"]


@dataclass(frozen=True, eq=False)
class Raster:
    """The placement of an ``H x W`` grid in its frame.

    Attributes
    ----------
    shape:
        ``(H, W)`` cells.
    resolution:
        Cell size (m).
    origin:
        float64 ``[3]``: pose (x m, y m, theta rad) of the grid's lower-left corner in its frame.
    """

    shape: tuple[int, int]
    resolution: float
    origin: NDArray[np.float64]

    @classmethod
    def of(cls, shape: tuple[int, ...], resolution: float, origin: ArrayLike) -> Raster:
        """A checked raster: a 2-D ``shape``, a positive finite ``resolution`` and an ``origin`` of three numbers."""
        if len(shape) != 2:
            raise ValueError(f"a grid must be 2-D [H, W], got shape {tuple(shape)}")
        resolution = float(resolution)
        if not (math.isfinite(resolution) and resolution > 0):
            raise ValueError(f"grid resolution must be positive metres, got {resolution!r}")
        pose = np.asarray(origin, dtype=np.float64).reshape(-1)
        if pose.shape == (2,):
            pose = np.append(pose, 0.0)
        if pose.shape != (3,) or not np.all(np.isfinite(pose)):
            raise ValueError(f"grid origin must be three finite numbers (x, y, theta), got {origin!r}")
        return cls((int(shape[0]), int(shape[1])), resolution, pose)

    def padded(self, cells: int) -> Raster:
        """The raster of this grid with ``cells`` more cells on every side (same frame, same cells)."""
        corner = transform_points(self.origin, np.array([-cells * self.resolution, -cells * self.resolution]))
        return Raster(
            (self.shape[0] + 2 * cells, self.shape[1] + 2 * cells),
            self.resolution,
            np.array([corner[0], corner[1], self.origin[2]]),
        )

    def centres(self, rows: ArrayLike, cols: ArrayLike) -> NDArray[np.float64]:
        """float64 ``[..., 2]``: frame coordinates (m) of the centres of cells ``(rows, cols)``."""
        rows = np.asarray(rows, dtype=np.float64)
        cols = np.asarray(cols, dtype=np.float64)
        local = np.stack([(cols + 0.5) * self.resolution, (self.shape[0] - rows - 0.5) * self.resolution], axis=-1)
        return transform_points(self.origin, local)

    def cells(self, points: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.bool_]]:
        """``(rows, cols, inside)`` of the cells holding frame points ``[..., 2]`` (m); ``inside`` is False
        for points off the grid (their rows and columns are then 0)."""
        local = transform_points(inverse(self.origin), points)
        cols = np.floor(local[..., 0] / self.resolution)
        rows = self.shape[0] - 1 - np.floor(local[..., 1] / self.resolution)
        inside = (rows >= 0) & (rows < self.shape[0]) & (cols >= 0) & (cols < self.shape[1])
        return np.where(inside, rows, 0).astype(np.intp), np.where(inside, cols, 0).astype(np.intp), inside

    def sample(self, values: NDArray, points: ArrayLike, outside: float | bool) -> NDArray:
        """``values[H, W]`` at the cells holding frame points ``[K, 2]``; ``outside`` for points off the grid."""
        if values.shape != self.shape:
            raise ValueError(f"values of shape {values.shape} do not fit a {self.shape} raster")
        rows, cols, inside = self.cells(points)
        return np.where(inside, values[rows, cols], outside)
