"""The map a trajectory implies: the scans traced at the estimated poses.

For an algorithm that gives no map of its own (an external program evaluated offline), slamtrials draws
the map from its estimate, so the map figures show what the estimate makes of the building. Frames are
traced on slam_gmapping's update rule (the first frame, then after 1 m of travel or 0.5 rad of turning
of the estimate), as the ``odometry`` baseline's ``gmapping`` preset does.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from slamtrials.geometry import ominus
from slamtrials.record import LaserGeometry, OccupancyGrid
from slamtrials.slam.gridmap import GridMap

__all__ = ["map_of_estimate"]


def map_of_estimate(
    estimate: NDArray[np.float64],
    scans: NDArray[np.floating],
    laser: LaserGeometry,
    *,
    resolution: float = 0.05,
    linear_update: float = 1.0,
    angular_update: float = 0.5,
    max_urange: float | None = None,
) -> OccupancyGrid:
    """Trace ``scans[k]`` at ``estimate[k]`` for every frame due by the update rule.

    Parameters
    ----------
    estimate:
        float64 ``[T, 3]`` base poses (map frame, m and rad).
    scans:
        ``[T, B]`` ranges (m; inf for no return).
    laser:
        The laser's geometry.
    resolution:
        Cell size (m).
    linear_update, angular_update:
        Travel (m) and turning (rad) of the estimate since the last traced frame that make a frame due.
    max_urange:
        Usable range (m); None: the laser's ``range_max``.
    """
    estimate = np.asarray(estimate, dtype=np.float64)
    grid = GridMap(resolution)
    if len(estimate) == 0:
        return grid.occupancy()
    steps = ominus(estimate[:-1], estimate[1:])
    moved, turned = 0.0, 0.0
    for k in range(len(estimate)):
        if k > 0:
            moved += math.hypot(steps[k - 1, 0], steps[k - 1, 1])
            turned += abs(float(steps[k - 1, 2]))
        if k == 0 or moved >= linear_update or turned >= angular_update:
            grid.integrate_frame(estimate[k], scans[k], laser, max_urange=max_urange)
            moved = turned = 0.0
    return grid.occupancy()
