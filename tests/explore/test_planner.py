"""Dijkstra planner: known path lengths on mazes, wall avoidance, goal search, escape, hysteresis."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from slamtrials.explore import ExploreConfig, RobotLimits, build_costmap, dijkstra
from slamtrials.explore.config import lethal_distance
from slamtrials.explore.costmap import PASSABLE

DIAG = math.sqrt(2.0)
TOL = 1e-3  # the planner rounds edge costs to 1/256


def uniform(mask):
    """Unit cost where True, blocked elsewhere."""
    return np.where(mask, 1.0, np.inf).astype(np.float32)


def reference(cost, start):
    """Plain heap Dijkstra with the planner's edge costs."""
    h, w = cost.shape
    dist = np.full((h, w), np.inf)
    dist[start] = 0.0
    heap = [(0.0, start)]
    while heap:
        d, (r, c) = heapq.heappop(heap)
        if d > dist[r, c]:
            continue
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                nr, nc = r + dr, c + dc
                if (dr or dc) and 0 <= nr < h and 0 <= nc < w and np.isfinite(cost[nr, nc]):
                    step = 1.0 if dr == 0 or dc == 0 else DIAG
                    nd = d + step * 0.5 * (cost[r, c] + cost[nr, nc])
                    if nd < dist[nr, nc] - 1e-12:
                        dist[nr, nc] = nd
                        heapq.heappush(heap, (nd, (nr, nc)))
    return dist


MAZE = """
#########
#S..#...#
###.#.#.#
#...#.#.#
#.###.#.#
#.....#G#
#########
"""


def parse(text):
    rows = [line for line in text.strip().splitlines()]
    grid = np.array([[ch != "#" for ch in row] for row in rows])

    def find(ch):
        return next((r, c) for r, row in enumerate(rows) for c, x in enumerate(row) if x == ch)

    return grid, find("S"), find("G")


def test_maze_path_has_the_known_length_and_stays_in_the_corridors():
    free, start, goal = parse(MAZE)
    cost = uniform(free)
    result = dijkstra(cost, start)
    # by hand: 8 straight and 7 diagonal moves (diagonal moves may pass between two blocked cells;
    # on a real costmap the inflation keeps paths away from such corners)
    ref = reference(cost, start)
    assert math.isclose(ref[goal], 8 + 7 * DIAG, rel_tol=1e-6)
    assert math.isclose(result.distance[goal], ref[goal], rel_tol=TOL)
    path = result.path_to(*goal)
    assert tuple(path[0]) == start and tuple(path[-1]) == goal
    assert free[path[:, 0], path[:, 1]].all()
    steps = np.abs(np.diff(path, axis=0))
    assert steps.max() == 1
    length = sum(DIAG if a and b else 1.0 for a, b in steps)
    assert math.isclose(length, result.distance[goal], rel_tol=TOL)


def test_straight_and_diagonal_lengths():
    cost = uniform(np.ones((30, 30), bool))
    result = dijkstra(cost, (0, 0))
    assert result.distance[0, 20] == 20.0
    assert math.isclose(result.distance[20, 20], 20 * DIAG, rel_tol=TOL)
    assert math.isclose(result.distance[29, 9], 9 * DIAG + 20, rel_tol=TOL)


@settings(max_examples=40, deadline=None)
@given(arrays(np.float32, (12, 15), elements=st.sampled_from([1.0, 1.5, 2.0, 7.25, np.inf])))
def test_matches_a_reference_dijkstra(cost):
    cost[0, 0] = 1.0
    result = dijkstra(cost, (0, 0))
    ref = reference(cost, (0, 0))
    assert np.array_equal(np.isfinite(result.distance), np.isfinite(ref))
    finite = np.isfinite(ref)
    assert np.allclose(result.distance[finite], ref[finite], rtol=1e-3, atol=1e-2)


def test_paths_keep_off_walls_on_a_real_costmap():
    grid = np.zeros((60, 60), dtype=np.int8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 100
    grid[30, :45] = 100  # a wall with a 0.7 m gap at the right end
    costmap = build_costmap(grid, 0.05, ExploreConfig())
    result = dijkstra(costmap.cost, (10, 10))
    path = result.path_to(50, 10)
    assert len(path) > 0
    assert (costmap.kind[path[:, 0], path[:, 1]] == PASSABLE).all()
    assert (costmap.clearance[path[:, 0], path[:, 1]] >= lethal_distance(ExploreConfig(), RobotLimits())).all()
    crossing = path[path[:, 0] == 30]
    assert crossing[:, 1].min() >= 45 + 4  # through the gap, away from the wall's end


def test_stops_at_the_closest_goal():
    cost = uniform(np.ones((40, 40), bool))
    goal = np.zeros((40, 40), bool)
    goal[5, 30] = goal[20, 25] = True
    result = dijkstra(cost, (20, 10), goal=goal)
    assert result.goal == (20, 25)
    assert not np.isfinite(result.distance[5, 30]) or result.distance[5, 30] > result.distance[20, 25]


def test_no_goal_reachable():
    free = np.ones((10, 10), bool)
    free[:, 5] = False
    cost = uniform(free)
    goal = np.zeros_like(free)
    goal[5, 8] = True
    assert dijkstra(cost, (5, 1), goal=goal).goal is None


def test_hysteresis_keeps_the_current_goal_unless_clearly_worse():
    cost = uniform(np.ones((50, 50), bool))
    goal = np.zeros((50, 50), bool)
    goal[25, 35] = True  # 10 away
    goal[25, 12] = True  # 13 away: the current goal
    keep = np.zeros_like(goal)
    keep[25, 12] = True
    assert dijkstra(cost, (25, 25), goal=goal, keep=keep, ratio=0.7).goal == (25, 12)
    assert dijkstra(cost, (25, 25), goal=goal, keep=keep, ratio=0.7).kept
    assert dijkstra(cost, (25, 25), goal=goal, keep=keep, ratio=0.8).goal == (25, 35)


def test_escape_from_an_inflated_start():
    grid = np.zeros((40, 40), dtype=np.int8)
    grid[:, 20] = 100
    costmap = build_costmap(grid, 0.05, ExploreConfig())
    start = (20, 18)  # 2 cells from the wall: lethal
    assert costmap.kind[start] != PASSABLE
    goal = np.zeros((40, 40), bool)
    goal[20, 5] = True
    assert dijkstra(costmap.cost, start, goal=goal).goal is None
    assert dijkstra(costmap.cost, start, goal=goal, escape=costmap.escape, escape_radius=1).goal is None
    result = dijkstra(costmap.cost, start, goal=goal, escape=costmap.escape, escape_radius=12)
    assert result.goal == (20, 5)
    path = result.path_to(20, 5)
    blocked = costmap.kind[path[:, 0], path[:, 1]] != PASSABLE
    # the blocked cells come first (leaving the inflated zone), then never again
    assert blocked[0] and not blocked[np.argmin(blocked) :].any()
    assert (path[:, 1] <= 18).all()  # it leaves away from the wall, not through it
    assert path[1, 1] == 17 and path[1, 0] == 20  # straight away from the wall: the cheapest escape


def test_start_outside_the_grid_is_an_error():
    cost = uniform(np.ones((5, 5), bool))
    with pytest.raises(ValueError, match="outside"):
        dijkstra(cost, (5, 0))
