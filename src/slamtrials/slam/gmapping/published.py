"""The published map: the best particle's path and stored scans traced into a counting grid.

GMapping rebuilds this map from scratch every ``map_update_interval``. Here the grid keeps the scans
of the path it was last built from; a new path usually shares a long head with the old one (the
particles' common ancestry), so only the scans after the first differing pose are taken out (counted
with weight -1, which is exact on integer counts) and put back at their new poses. The result is the
same grid a rebuild from scratch would give.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from slamtrials.record import LaserGeometry
from slamtrials.slam.base import OccupancyGrid
from slamtrials.slam.gridmap import GridMap

__all__ = ["PublishedMap"]


class PublishedMap:
    """An incrementally rebuilt :class:`~slamtrials.slam.gridmap.GridMap` of one path of laser poses.

    Parameters
    ----------
    resolution:
        Cell size (m).
    laser:
        The laser's geometry.
    max_urange:
        Beams longer than this are cut there and mark only free cells (m).
    occ_thresh:
        Occupied where hits / visits exceeds this.
    """

    def __init__(self, resolution: float, laser: LaserGeometry, *, max_urange: float, occ_thresh: float):
        self.grid = GridMap(resolution)
        self.laser = laser
        self.max_urange = float(max_urange)
        self.occ_thresh = float(occ_thresh)
        self._path = np.zeros((0, 3))
        self._scans: list[NDArray[np.float32]] = []
        self._occupancy: OccupancyGrid | None = None

    def _trace(self, poses: list[NDArray[np.float64]], scans: list[NDArray[np.float32]], weights: list[int]) -> None:
        """Trace scans ``scans[k]`` from laser poses ``poses[k]`` with weights ``weights[k]``, in runs of
        equal beam count (one compiled call per run)."""
        self.grid.integrate_scans(poses, scans, weights, self.laser, max_urange=self.max_urange)

    def rebuild(self, path: NDArray[np.float64], scans: list[NDArray[np.float32]]) -> int:
        """Make the grid that of laser poses ``path`` ``[U, 3]`` with ``scans[u]`` taken at ``path[u]``.

        ``scans`` must extend the list given last time (scans are stored once and never change).
        Returns the number of scans traced or taken out.
        """
        old = self._path
        common = min(len(old), len(path))
        differs = np.flatnonzero(np.any(old[:common] != path[:common], axis=1))
        keep = int(differs[0]) if differs.size else common
        removed = range(len(old) - 1, keep - 1, -1)
        added = range(keep, len(path))
        self._trace(
            [old[u] for u in removed] + [path[u] for u in added],
            [self._scans[u] for u in removed] + [scans[u] for u in added],
            [-1] * len(removed) + [1] * len(added),
        )
        self._path = np.array(path, dtype=np.float64)
        self._scans = scans
        self._occupancy = self.grid.occupancy(self.occ_thresh)
        return len(removed) + len(added)

    def occupancy(self) -> OccupancyGrid:
        """The grid as of the last :meth:`rebuild` (an empty 0 x 0 grid before the first)."""
        if self._occupancy is None:
            return OccupancyGrid(
                grid=np.zeros((0, 0), dtype=np.int8), resolution=self.grid.resolution, origin=np.zeros(3)
            )
        return self._occupancy
