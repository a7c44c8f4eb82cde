"""Map windows, local costmaps agreeing with the whole map's, goal bookkeeping helpers."""

from __future__ import annotations

import math

import numpy as np

from slamtrials.explore import ExploreConfig, GridFrame, RobotLimits, build_costmap
from slamtrials.explore.costmap import influence_distance
from slamtrials.explore.frontiers import frontier_near
from slamtrials.explore.goals import GoalRecord, exclude_discs
from slamtrials.explore.window import crop, known_box


def test_known_box_and_crop():
    grid = np.full((10, 12), -1, dtype=np.int8)
    assert known_box(grid) is None
    grid[3:5, 4:9] = 0
    assert known_box(grid, 2) == (1, 7, 2, 11)
    window = crop(grid, -2, 3, 10, 14)  # sticks out at the top and on the right
    assert window.shape == (5, 4)
    assert (window == -1).all()
    assert np.array_equal(crop(grid, 3, 5, 4, 9), np.zeros((2, 5), np.int8))


def test_a_window_costmap_matches_the_whole_map_inside_its_rim():
    rng = np.random.default_rng(3)
    grid = np.zeros((200, 220), dtype=np.int8)
    grid[rng.random(grid.shape) < 0.01] = 100
    grid[:, 100] = 100
    grid[rng.random(grid.shape) < 0.05] = -1
    cfg = ExploreConfig()
    res = 0.05
    whole = build_costmap(grid, res, cfg)
    r0, r1, c0, c1 = 40, 170, 60, 190
    local = build_costmap(crop(grid, r0, r1, c0, c1), res, cfg)
    rim = math.ceil(influence_distance(cfg, RobotLimits(), res) / res)
    inner = (slice(rim, r1 - r0 - rim), slice(rim, c1 - c0 - rim))
    outer = (slice(r0 + rim, r1 - rim), slice(c0 + rim, c1 - rim))
    assert np.array_equal(local.kind[inner], whole.kind[outer])
    assert np.allclose(local.cost[inner], whole.cost[outer])


def test_frontier_near():
    grid = np.zeros((20, 20), dtype=np.int8)
    grid[:, 15:] = -1
    assert frontier_near(grid, 10, 14)
    assert frontier_near(grid, 10, 12)  # two cells away
    assert not frontier_near(grid, 10, 11)
    assert not frontier_near(grid, 10, 11, reach=1)
    assert frontier_near(grid, 0, 16)  # at the grid edge
    assert not frontier_near(grid, 0, 19)


def test_exclude_discs():
    frame = GridFrame(height=40, width=40, resolution=0.1, origin=(0.0, 0.0, 0.0))
    mask = np.ones((40, 40), dtype=bool)
    exclude_discs(mask, frame, [np.array([2.05, 2.05]), np.array([-5.0, -5.0])], 0.5)
    assert (~mask).sum() == 81  # cells within 5 cells of one centre
    rows, cols = np.nonzero(~mask)
    assert np.hypot(rows - 19, cols - 20).max() <= 5.0
    exclude_discs(mask, frame, [], 0.5)
    assert (~mask).sum() == 81


def test_goal_progress_and_reroutes():
    goal = GoalRecord(xy=np.zeros(2), target=np.zeros(2), since=0.0, best=10.0, last_progress=0.0)
    goal.update(1.0, 9.9, 0.25)
    assert goal.last_progress == 0.0  # not enough
    goal.update(2.0, 9.7, 0.25)
    assert (goal.best, goal.last_progress) == (9.7, 2.0)
    goal.rerouted(3.0, 10.0, 1.0)
    assert goal.last_progress == 2.0  # about the same length: the clock keeps running
    goal.rerouted(4.0, 15.0, 1.0)
    assert (goal.best, goal.last_progress) == (15.0, 4.0)  # a much longer way round: a fresh start


def test_coarsen_is_conservative_and_keeps_the_origin():
    from slamtrials.explore.window import coarsen

    grid = np.zeros((5, 6), dtype=np.int8)
    grid[4, 0] = 100  # bottom-left cell occupied
    grid[0, 5] = -1
    coarse = coarsen(grid, 2)
    assert coarse.shape == (3, 3)
    assert coarse[2, 0] == 100  # the block of the bottom-left cell: the origin corner is kept
    assert coarse[0, :].tolist() == [-1, -1, -1]  # the padding row at the top is unknown
    assert coarse[1, 2] == 0 and coarse[2, 2] == 0
    assert np.array_equal(coarsen(grid, 1), grid)
