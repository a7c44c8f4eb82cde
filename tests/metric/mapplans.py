"""A small two-room floor plan, maps of it built by hand, and a brute-force scorer to check map_quality against.

The plan (0.1 m cells, 30 x 40): a building of two rooms, walls one cell thick (rows 5 and 24, columns 5,
20 and 34), a doorway in the middle wall (rows 13 to 15), and occupied cells all around it, as the bundled
floor plans have. The perfect map holds the walls the robot can see as occupied and the reachable space
as free, in the plan's own frame.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from slamtrials.metric.mapquality import FloorPlan
from slamtrials.record import FREE, OCCUPIED, UNKNOWN, OccupancyGrid

RES = 0.1
H, W = 30, 40
ORIGIN = np.array([-1.0, 2.0, 0.0])
START = (10, 10)  # a cell of the left room
DOOR = range(13, 16)
RIGHT_ROOM = (slice(5, 25), slice(21, 35))  # the right room and its outer wall, not the middle wall


def plan_walls() -> np.ndarray:
    walls = np.ones((H, W), dtype=bool)
    walls[6:24, 6:34] = False
    walls[6:24, 20] = True
    walls[DOOR.start : DOOR.stop, 20] = False
    return walls


def reachable_by_flood(walls: np.ndarray, start: tuple[int, int] = START) -> np.ndarray:
    """Free cells 4-connected to ``start``, by breadth-first search."""
    seen = np.zeros_like(walls)
    queue = deque([start])
    seen[start] = True
    while queue:
        r, c = queue.popleft()
        for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            rr, cc = r + dr, c + dc
            if 0 <= rr < walls.shape[0] and 0 <= cc < walls.shape[1] and not walls[rr, cc] and not seen[rr, cc]:
                seen[rr, cc] = True
                queue.append((rr, cc))
    return seen


def plan() -> FloorPlan:
    walls = plan_walls()
    return FloorPlan(walls, reachable_by_flood(walls), RES, ORIGIN)


def faces_by_loop(walls: np.ndarray, reachable: np.ndarray) -> np.ndarray:
    out = np.zeros_like(walls)
    for r in range(walls.shape[0]):
        for c in range(walls.shape[1]):
            if walls[r, c]:
                for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                    rr, cc = r + dr, c + dc
                    if 0 <= rr < walls.shape[0] and 0 <= cc < walls.shape[1] and reachable[rr, cc]:
                        out[r, c] = True
    return out


def perfect_grid(truth: FloorPlan) -> np.ndarray:
    """int8 ``[H, W]``: the walls the robot can see occupied, the reachable space free, the rest unknown."""
    grid = np.full(truth.walls.shape, UNKNOWN, dtype=np.int8)
    grid[truth.reachable] = FREE
    grid[faces_by_loop(truth.walls, truth.reachable)] = OCCUPIED
    return grid


def as_map(grid: np.ndarray, origin=ORIGIN) -> OccupancyGrid:
    return OccupancyGrid(grid.astype(np.int8), RES, np.asarray(origin, dtype=np.float64))


def brute_force(grid: np.ndarray, truth: FloorPlan) -> dict[str, float | None]:
    """The figures by their definitions, for a map on the plan's own grid (identity alignment): loops over
    cells, distances between cell centres in cells."""
    faces = list(zip(*np.nonzero(faces_by_loop(truth.walls, truth.reachable))))
    occupied = list(zip(*np.nonzero(grid >= 50)))
    free = list(zip(*np.nonzero((grid >= 0) & (grid < 50))))
    reach = list(zip(*np.nonzero(truth.reachable)))

    def nearest(cell, cells):
        return min((math.hypot(cell[0] - r, cell[1] - c) for r, c in cells), default=math.inf)

    out: dict[str, float | None] = {}
    for k in (1, 2):
        out[f"occupied_precision_{k}"] = (
            sum(nearest(cell, faces) <= k for cell in occupied) / len(occupied) if occupied else None
        )
        out[f"occupied_recall_{k}"] = (
            sum(nearest(cell, occupied) <= k for cell in faces) / len(faces) if faces else None
        )
    on = sum(bool(truth.reachable[cell]) for cell in free)
    union = len(free) + len(reach) - on
    out["free_iou"] = on / union if union else None
    out["ghost_free_m2"] = sum(nearest(cell, reach) > 1 for cell in free) * RES * RES
    return out
