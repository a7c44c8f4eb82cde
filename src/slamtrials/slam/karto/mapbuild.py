"""The published map: every node's scan traced from its optimized laser pose (Karto's OccupancyGrid).

Rebuilt from the graph, not updated scan by scan: when the optimizer moves nodes, their scans are taken
out at the old poses (weight -1, exact on the integer counts) and put back at the new ones, or, when more
than half of them moved (after a loop closure nearly all do), the counts are cleared and every scan is
traced again, whichever traces fewer scans; either way the grid equals a rebuild from scratch. Rays are those of :mod:`slamtrials.slam.gridmap`, with Karto's
range threshold as the usable range. Cells follow Karto's rule: unknown until more than
``min_pass_through`` beams crossed them, then occupied when hits / crossings exceeds
``occupancy_threshold``, else free.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials.record import FREE, OCCUPIED, UNKNOWN, LaserGeometry, OccupancyGrid
from slamtrials.slam.gridmap import GridMap

__all__ = ["NodeMap"]


@njit(cache=True, nogil=True)
def _classify(hits, visits, min_pass_through, threshold):  # pragma: no cover - compiled
    height, width = visits.shape
    grid = np.empty((height, width), dtype=np.int8)
    for r in range(height):
        out = height - 1 - r
        for c in range(width):
            v = visits[r, c]
            if v <= min_pass_through:
                grid[out, c] = UNKNOWN
            elif hits[r, c] > threshold * v:
                grid[out, c] = OCCUPIED
            else:
                grid[out, c] = FREE
    return grid


class NodeMap:
    """A :class:`~slamtrials.slam.gridmap.GridMap` of node scans that follows the nodes' poses.

    Parameters
    ----------
    resolution:
        Cell size (m).
    laser:
        The laser's geometry.
    max_urange:
        Beams are cut here (m) and then mark only free cells.
    min_pass_through, occupancy_threshold:
        Karto's cell rule (module docstring).
    """

    def __init__(
        self,
        resolution: float,
        laser: LaserGeometry,
        *,
        max_urange: float,
        min_pass_through: int,
        occupancy_threshold: float,
    ):
        self.grid = GridMap(resolution)
        self.laser = laser
        self.max_urange = float(max_urange)
        self.min_pass_through = int(min_pass_through)
        self.occupancy_threshold = float(occupancy_threshold)
        self._poses = np.zeros((0, 3))  # laser pose each traced scan was traced from
        self._occupancy: OccupancyGrid | None = None

    def update(self, laser_poses: NDArray[np.float64], scans: list[NDArray[np.float32]]) -> int:
        """Make the grid that of ``scans[k]`` traced from ``laser_poses[k]`` (``[N, 3]``, map frame).

        ``scans`` must extend the list given last time. Returns the number of scans traced or taken out.
        """
        laser_poses = np.asarray(laser_poses, dtype=np.float64).reshape(-1, 3)
        traced = self._poses.shape[0]
        moved = np.flatnonzero(np.any(self._poses != laser_poses[:traced], axis=1)).tolist()
        poses, ranges, weights = [], [], []
        if 2 * len(moved) > traced:
            # moving them would trace more scans than tracing every scan again on cleared counts: the same
            # integer counts, and the same window (it only grows, the scans' new boxes come in the same
            # order, and the boxes of the scans that stay were inside it already)
            self.grid.hits[:] = 0
            self.grid.visits[:] = 0
            traced = 0
        else:
            for k in moved:
                poses += [self._poses[k], laser_poses[k]]
                ranges += [scans[k], scans[k]]
                weights += [-1, 1]
        for k in range(traced, len(scans)):
            poses.append(laser_poses[k])
            ranges.append(scans[k])
            weights.append(1)
        self.grid.integrate_scans(poses, ranges, weights, self.laser, max_urange=self.max_urange)
        self._poses = laser_poses[: len(scans)].copy()
        self._occupancy = OccupancyGrid(
            grid=_classify(self.grid.hits, self.grid.visits, self.min_pass_through, self.occupancy_threshold),
            resolution=self.grid.resolution,
            origin=self.grid.origin,
        )
        return len(ranges)

    def occupancy(self) -> OccupancyGrid:
        """The grid as of the last :meth:`update` (an empty 0 x 0 grid before the first)."""
        if self._occupancy is None:
            return OccupancyGrid(
                grid=np.zeros((0, 0), dtype=np.int8), resolution=self.grid.resolution, origin=np.zeros(3)
            )
        return self._occupancy
