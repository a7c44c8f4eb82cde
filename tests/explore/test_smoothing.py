"""Path shortcuts: straight where free and no dearer, corners kept at walls, blocked cells never crossed."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from slamtrials.explore import ExploreConfig, build_costmap, dijkstra
from slamtrials.explore.smoothing import _segment_cost, resample_polyline, shortcut_path


def plan(cost, start, goal):
    goal_mask = np.zeros(cost.shape, dtype=bool)
    goal_mask[goal] = True
    result = dijkstra(cost, start, goal=goal_mask)
    return result.path_to(*goal)


def polyline_length(points):
    return float(np.hypot(*np.diff(points, axis=0).T).sum())


def crosses_blocked(cost, corners):
    """Whether any straight piece between corners passes a blocked cell (sampled finely)."""
    for (r0, c0), (r1, c1) in zip(corners[:-1], corners[1:]):
        for f in np.linspace(0.0, 1.0, 200):
            if not np.isfinite(
                cost[int(math.floor(r0 + f * (r1 - r0) + 0.5)), int(math.floor(c0 + f * (c1 - c0) + 0.5))]
            ):
                return True
    return False


def test_open_field_becomes_one_straight_segment():
    cost = np.ones((40, 40), dtype=np.float32)
    cells = plan(cost, (2, 3), (30, 37))  # a knight-like slope: 8-connected paths bend
    corners = shortcut_path(cells, cost)
    assert corners.tolist() == [0, len(cells) - 1]
    straight = math.hypot(28, 34)
    assert polyline_length(cells.astype(float)) > straight + 1.0  # the grid path bends: straight, then diagonal


def test_corner_around_a_wall_is_kept_and_never_cut():
    cost = np.ones((30, 30), dtype=np.float32)
    cost[5:30, 14:16] = np.inf  # a wall hanging from row 5 down; go around its top end
    cells = plan(cost, (25, 5), (25, 25))
    corners = shortcut_path(cells, cost)
    assert 3 <= len(corners) < len(cells) // 3
    assert not crosses_blocked(cost, cells[corners])
    # the polyline goes over the wall's end: some corner lies in rows above it
    assert cells[corners][:, 0].min() < 5


def test_shortcut_does_not_hug_walls_where_the_costmap_says_keep_off():
    grid = np.zeros((80, 80), dtype=np.int8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 100
    grid[20:80, 40] = 100  # a wall from the bottom to row 20: the path bends round its top
    config = ExploreConfig()
    costmap = build_costmap(grid, 0.05, config)
    cells = plan(costmap.cost, (70, 10), (70, 70))
    corners = cells[shortcut_path(cells, costmap.cost)]
    # along every shortcut, the integrated cost is no more than along the grid path it replaced
    index = shortcut_path(cells, costmap.cost)
    for a, b in zip(index[:-1], index[1:]):
        grid_cost = sum(
            math.hypot(*(cells[k + 1] - cells[k]))
            * 0.5
            * (costmap.cost[tuple(cells[k])] + costmap.cost[tuple(cells[k + 1])])
            for k in range(a, b)
        )
        assert (
            _segment_cost(costmap.cost.astype(np.float64), cells[a][0], cells[a][1], cells[b][0], cells[b][1])
            <= grid_cost + 1e-6
        )
    # the wall's top is passed with at least the clearance the grid path had there
    top_grid = min(costmap.clearance[tuple(c)] for c in cells if c[0] <= 22 and 38 <= c[1] <= 42)
    dense = resample_polyline(corners.astype(float), 0.25)
    near_top = [costmap.clearance[int(r + 0.5), int(c + 0.5)] for r, c in dense if r <= 22 and 38 <= c <= 42]
    assert near_top and min(near_top) >= top_grid - 0.05


def test_blocked_start_cells_are_kept_as_they_are():
    cost = np.ones((20, 20), dtype=np.float32)
    cost[9:12, 9:12] = np.inf  # the robot stands in a blocked patch (escaping)
    cells = np.array([[10, 10], [10, 11], [10, 12], [10, 13], [11, 14], [12, 15], [13, 16], [14, 17]])
    corners = shortcut_path(cells, cost)
    assert corners[:3].tolist() == [0, 1, 2]  # no segment starts in a blocked cell
    assert corners[-1] == len(cells) - 1


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_random_rooms_shortcuts_stay_passable_and_shorter(seed):
    rng = np.random.default_rng(seed)
    cost = np.ones((30, 30), dtype=np.float32)
    for _ in range(6):
        r, c = rng.integers(0, 28, size=2)
        cost[r : r + rng.integers(1, 4), c : c + rng.integers(1, 12)] = np.inf
    start, goal = (1, 1), (28, 28)
    cost[start] = cost[goal] = 1.0
    cells = plan(cost, start, goal)
    if len(cells) == 0:
        return
    index = shortcut_path(cells, cost)
    assert index[0] == 0 and index[-1] == len(cells) - 1 and np.all(np.diff(index) > 0)
    assert not crosses_blocked(cost, cells[index])
    assert polyline_length(cells[index].astype(float)) <= polyline_length(cells.astype(float)) + 1e-9


def test_resample_keeps_corners_and_spacing():
    pts = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 1.0]])
    out = resample_polyline(pts, 0.4)
    assert np.allclose(out[0], pts[0]) and np.allclose(out[-1], pts[-1])
    assert any(np.allclose(p, pts[1]) for p in out)
    steps = np.hypot(*np.diff(out, axis=0).T)
    assert steps.max() <= 0.4 + 1e-12 and steps.min() > 0.0
    assert polyline_length(out) == pytest.approx(4.0)
    with pytest.raises(ValueError):
        resample_polyline(pts, 0.0)
