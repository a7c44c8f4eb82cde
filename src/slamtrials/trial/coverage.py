"""How much of a world a trial mapped and observed, measured against the true world.

Both measures count the world's reachable free cells at the world map's resolution: by default the
free cells the robot's disc footprint can cover from the start (:meth:`World.reachable_by_disc`; space
behind gaps narrower than the robot is not reachable), so 1.0 means every place the robot could reach
was covered:

* :func:`mapped_fraction`: cells whose centre falls on a known (free or occupied) cell of the SLAM
  map, after carrying the world into the map frame through the first frame (estimate vs truth);
* :func:`local_mapped_fraction`: the same, but each cell is carried through the pose of the
  trajectory nearest to it (truth vs estimate at that moment). A SLAM map that is slightly rotated or
  bent as a whole (a long building, a small heading error) still knows the places the robot mapped;
  the first-frame alignment would count the cells along far walls as unmapped;
* :func:`observed_fraction`: cells crossed or hit by the laser, traced at the TRUE poses of every
  ``stride``-th scan; what the exploration let the robot see, whatever SLAM made of it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from slamtrials.geometry import compose, compose1, inverse, transform_points
from slamtrials.record import UNKNOWN, LaserGeometry, OccupancyGrid
from slamtrials.slam import GridMap
from slamtrials.worlds import World
from slamtrials.worlds.world import cell_to_world

__all__ = [
    "known_cells",
    "known_free_area",
    "known_share",
    "local_map_points",
    "local_mapped_fraction",
    "mapped_fraction",
    "observed_fraction",
    "reachable_cell_centres",
]


def reachable_cell_centres(world: World, reachable: NDArray[np.bool_] | None = None) -> NDArray[np.float64]:
    """float64 ``[K, 2]``: world-frame centres (m) of the cells of the bool ``[H, W]`` mask ``reachable``
    (default: :meth:`World.reachable_free`, every free cell connected to the start)."""
    rows, cols = np.nonzero(world.reachable_free() if reachable is None else reachable)
    return cell_to_world(world, rows, cols)


def _lookup(grid: OccupancyGrid, xy: NDArray[np.float64]) -> NDArray[np.int8]:
    """Cell values of map-frame points ``[K, 2]`` in ``grid`` (UNKNOWN outside it; origin theta 0)."""
    height, width = grid.grid.shape
    col = np.floor((xy[:, 0] - grid.origin[0]) / grid.resolution).astype(np.int64)
    row_up = np.floor((xy[:, 1] - grid.origin[1]) / grid.resolution).astype(np.int64)
    inside = (col >= 0) & (col < width) & (row_up >= 0) & (row_up < height)
    values = np.full(xy.shape[0], UNKNOWN, dtype=np.int8)
    values[inside] = grid.grid[height - 1 - row_up[inside], col[inside]]
    return values


def mapped_fraction(
    world: World,
    grid: OccupancyGrid,
    estimate0: NDArray[np.float64],
    truth0: NDArray[np.float64],
    reachable: NDArray[np.bool_] | None = None,
) -> float:
    """Fraction of the ``reachable`` world cells (bool ``[H, W]``, see :func:`reachable_cell_centres`)
    that the SLAM map ``grid`` knows.

    ``estimate0`` and ``truth0`` are the first frame's pose in the map frame and in the world frame;
    together they place the world in the map frame.
    """
    centres = reachable_cell_centres(world, reachable)
    if centres.shape[0] == 0 or grid.grid.size == 0:
        return 0.0
    map_from_world = compose1(estimate0, inverse(truth0))
    return float(np.mean(_lookup(grid, transform_points(map_from_world, centres)) != UNKNOWN))


def local_map_points(
    world: World,
    estimate: NDArray[np.float64],
    truth: NDArray[np.float64],
    reachable: NDArray[np.bool_] | None = None,
    stride: int = 5,
) -> NDArray[np.float64]:
    """float64 ``[K, 2]``: the centres of the ``reachable`` world cells carried into the map frame, each
    through the trajectory pose nearest to it (``[0, 2]`` without poses).

    ``estimate`` and ``truth`` are float64 ``[T, 3]``: the SLAM trajectory (map frame) and the true one
    (world frame) at the same frames; every ``stride``-th pose is a candidate. For a cell nearest to true
    pose ``k``, the map-frame point is ``estimate[k] (+) (truth[k] (-) cell)``.
    """
    centres = reachable_cell_centres(world, reachable)
    truth = np.asarray(truth, dtype=np.float64)[:: max(int(stride), 1)]
    estimate = np.asarray(estimate, dtype=np.float64)[:: max(int(stride), 1)]
    if centres.shape[0] == 0 or truth.shape[0] == 0:
        return np.zeros((0, 2), dtype=np.float64)
    _, nearest = cKDTree(truth[:, :2]).query(centres)
    map_from_world = compose(estimate, inverse(truth))[nearest]  # [K, 3], one transform per cell
    return compose(map_from_world, np.column_stack([centres, np.zeros(centres.shape[0])]))[:, :2]


def known_cells(grid: OccupancyGrid, points: NDArray[np.float64]) -> NDArray[np.bool_]:
    """bool ``[K]``: whether the map ``grid`` knows (free or occupied) the cell under each map-frame point
    of ``points`` ``[K, 2]`` (m); False outside it."""
    return _lookup(grid, points) != UNKNOWN


def known_share(known: NDArray[np.bool_]) -> float:
    """The share of True in ``known`` ``[K]``; 0.0 for ``K = 0``."""
    return float(np.mean(known)) if known.shape[0] else 0.0


def local_mapped_fraction(
    world: World,
    grid: OccupancyGrid,
    estimate: NDArray[np.float64],
    truth: NDArray[np.float64],
    reachable: NDArray[np.bool_] | None = None,
    stride: int = 5,
) -> float:
    """Fraction of the ``reachable`` world cells that the SLAM map ``grid`` knows, each cell carried into
    the map frame through the trajectory pose nearest to it (:func:`local_map_points`).

    ``estimate`` and ``truth`` are float64 ``[T, 3]``: the SLAM trajectory (map frame) and the true one
    (world frame) at the same frames; every ``stride``-th pose is a candidate.
    """
    return known_share(known_cells(grid, local_map_points(world, estimate, truth, reachable, stride)))


def observed_fraction(
    world: World,
    truth: NDArray[np.float64],
    scans: NDArray[np.float32],
    laser: LaserGeometry,
    stride: int,
    reachable: NDArray[np.bool_] | None = None,
) -> float:
    """Fraction of the ``reachable`` world cells the laser saw (scans traced at their true poses)."""
    centres = reachable_cell_centres(world, reachable)
    if centres.shape[0] == 0:
        return 0.0
    seen = GridMap(world.resolution)
    for k in range(0, truth.shape[0], stride):
        seen.integrate_frame(truth[k], scans[k], laser)
    return float(np.mean(_lookup(seen.occupancy(0.5), centres) != UNKNOWN))


def known_free_area(grid: OccupancyGrid) -> float:
    """Free area (m^2) of a SLAM map."""
    return float(np.count_nonzero(grid.grid == 0)) * grid.resolution**2
