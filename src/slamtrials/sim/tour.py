"""Scripted tours: a waypoint path that visits the far corners of a world's reachable free space.

Used to script a drive before autonomous exploration exists, and for demos. Goals are picked by
farthest-point sampling of geodesic distance over the free space the robot can fit in; consecutive goals
are joined by shortest paths on a coarse grid whose edge costs grow near walls, so the path keeps to the
middle of corridors and doors.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage, sparse
from scipy.sparse import csgraph

from slamtrials.errors import SimulationError
from slamtrials.worlds.world import World, cell_to_world, world_to_cell

__all__ = ["tour_waypoints"]

_NEIGHBOURS = ((0, 1, 1.0), (1, 0, 1.0), (1, 1, np.sqrt(2.0)), (1, -1, np.sqrt(2.0)))


def _coarse_grid(world: World, cell: float, clearance: float) -> tuple[NDArray[np.bool_], NDArray[np.float64], int]:
    """Block-reduce the clearance map to ``cell``-sized blocks: (passable [h, w], block clearance [h, w], factor)."""
    factor = max(1, int(round(cell / world.resolution)))
    h, w = world.height // factor, world.width // factor
    block = world.clearance[: h * factor, : w * factor].reshape(h, factor, w, factor).min(axis=(1, 3))
    return block >= clearance, block, factor


def _graph(passable: NDArray[np.bool_], block_clearance: NDArray[np.float64], cell: float) -> sparse.csr_matrix:
    """8-connected graph over passable blocks; edge cost = length x (1 + 0.5 m / clearance)."""
    h, w = passable.shape
    index = np.arange(h * w).reshape(h, w)
    penalty = 1.0 + 0.5 / np.maximum(block_clearance, 1e-3)
    rows: list[NDArray[np.intp]] = []
    cols: list[NDArray[np.intp]] = []
    costs: list[NDArray[np.float64]] = []
    for dr, dc, length in _NEIGHBOURS:
        r0, r1 = max(0, -dr), h - max(0, dr)
        c0, c1 = max(0, -dc), w - max(0, dc)
        a = (slice(r0, r1), slice(c0, c1))
        b = (slice(r0 + dr, r1 + dr), slice(c0 + dc, c1 + dc))
        both = passable[a] & passable[b]
        rows.append(index[a][both])
        cols.append(index[b][both])
        costs.append(length * cell * 0.5 * (penalty[a][both] + penalty[b][both]))
    edges = (np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols)))
    return sparse.csr_matrix(edges, shape=(h * w, h * w))


def tour_waypoints(
    world: World,
    *,
    num_goals: int = 8,
    clearance: float = 0.4,
    cell: float = 0.2,
    spacing: float = 1.0,
) -> NDArray[np.float64]:
    """Waypoints ``[N, 2]`` (m, world frame) of a tour from the start pose through ``num_goals`` far goals.

    Parameters
    ----------
    world:
        The world; the tour starts at ``world.start``.
    num_goals:
        How many goals to visit (farthest-point sampling of geodesic distance, starting from the start).
    clearance:
        Minimum distance (m) from walls of every point of the path.
    cell:
        Planning grid cell size (m); the world's clearance map is block-reduced to it.
    spacing:
        Approximate distance (m) between consecutive waypoints.

    Raises
    ------
    SimulationError
        The start pose has no room to move with the asked clearance.
    """
    passable, block_clearance, factor = _coarse_grid(world, cell, clearance)
    cell = factor * world.resolution
    labels, _ = ndimage.label(passable, structure=np.ones((3, 3)))
    if world.start is None:  # World.__post_init__ always sets it
        raise SimulationError(f"world {world.name!r} has no start pose")
    row, col = world_to_cell(world, world.start[:2])
    # The start block may be too close to a wall: use the nearest passable block.
    rows, cols = np.nonzero(passable)
    if len(rows) == 0:
        raise SimulationError(f"world {world.name!r}: no free space with {clearance} m clearance for a tour")
    nearest = int(np.argmin((rows - row // factor) ** 2 + (cols - col // factor) ** 2))
    start_block = (rows[nearest], cols[nearest])
    region = labels == labels[start_block]
    graph = _graph(region, block_clearance, cell)
    width = passable.shape[1]
    start_node = start_block[0] * width + start_block[1]

    goals = [start_node]
    nearest_goal_distance = csgraph.dijkstra(graph, directed=False, indices=start_node)
    for _ in range(num_goals):
        far = int(np.argmax(np.where(np.isfinite(nearest_goal_distance), nearest_goal_distance, -1.0)))
        if nearest_goal_distance[far] < 2.0:  # everything is already within 2 m of a goal
            break
        goals.append(far)
        nearest_goal_distance = np.minimum(nearest_goal_distance, csgraph.dijkstra(graph, directed=False, indices=far))

    # Visit the goals in nearest-neighbour order of geodesic distance.
    distances, predecessors = csgraph.dijkstra(graph, directed=False, indices=goals, return_predecessors=True)
    order, remaining = [0], set(range(1, len(goals)))
    while remaining:
        here = order[-1]
        nxt = min(remaining, key=lambda g: (distances[here, goals[g]], g))  # equal distances: the lower goal index
        order.append(nxt)
        remaining.remove(nxt)

    nodes: list[int] = [start_node]
    for a, b in zip(order[:-1], order[1:]):
        leg, node = [], goals[b]
        while node != goals[a] and node >= 0:
            leg.append(node)
            node = predecessors[a, node]
        nodes.extend(reversed(leg))
    node_rows, node_cols = np.divmod(np.asarray(nodes), width)
    points = cell_to_world(world, node_rows * factor + (factor - 1) / 2.0, node_cols * factor + (factor - 1) / 2.0)
    step = max(1, int(round(spacing / cell)))
    keep = np.r_[np.arange(0, len(points), step), len(points) - 1]
    return points[np.unique(keep)]
