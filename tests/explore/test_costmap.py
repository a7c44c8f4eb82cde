"""Costmap: exact distance transform, lethal inflation, decaying cost, unknown cells."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy import ndimage

from slamtrials.explore import ExploreConfig, RobotLimits, build_costmap
from slamtrials.explore.config import lethal_distance
from slamtrials.explore.costmap import (
    LETHAL,
    OCCUPIED,
    PASSABLE,
    UNKNOWN,
    squared_distance_transform,
)


@settings(max_examples=60, deadline=None)
@given(arrays(np.bool_, st.tuples(st.integers(1, 30), st.integers(1, 30)), elements=st.booleans()))
def test_distance_transform_matches_scipy(target):
    d2 = squared_distance_transform(target)
    if target.any():
        assert np.allclose(d2, ndimage.distance_transform_edt(~target) ** 2)
    else:
        assert (d2 >= 1e12).all()


def single_obstacle(n=41, value=0):
    grid = np.full((n, n), value, dtype=np.int8)
    grid[n // 2, n // 2] = 100
    return grid


def test_lethal_radius_around_one_obstacle():
    cfg = ExploreConfig(inflation_margin=0.05)  # with a 0.15 m robot: lethal below 0.20 m from the cell's edge
    res = 0.05
    costmap = build_costmap(single_obstacle(), res, cfg, RobotLimits(radius=0.15))
    c = 20
    assert costmap.kind[c, c] == OCCUPIED
    # clearance = centre distance - half a cell: 4 cells -> 0.175 m (lethal), 5 cells -> 0.225 m (free)
    assert costmap.kind[c, c + 4] == LETHAL and costmap.kind[c + 4, c] == LETHAL
    assert costmap.kind[c, c + 5] == PASSABLE and costmap.kind[c - 5, c] == PASSABLE
    assert costmap.kind[c + 3, c + 3] == LETHAL  # 4.24 cells
    assert costmap.kind[c + 4, c + 3] == PASSABLE  # 5 cells
    assert np.isclose(costmap.clearance[c, c + 5], 5 * res - res / 2)
    rows, cols = np.nonzero(costmap.kind == LETHAL)
    dist = np.hypot(rows - c, cols - c) * res - res / 2
    assert dist.max() < lethal_distance(cfg, RobotLimits(radius=0.15))
    assert np.isinf(costmap.cost[costmap.kind != PASSABLE]).all()


def test_cost_decays_away_from_walls():
    cfg = ExploreConfig()
    costmap = build_costmap(single_obstacle(81), 0.05, cfg)
    row = costmap.cost[40, 45:]
    assert np.all(np.diff(row) <= 0)
    assert row[0] > 5.0  # just outside the lethal zone: about 1 + wall_cost
    assert np.isclose(row[-1], 1.0, atol=0.05)
    assert costmap.cost[costmap.kind == PASSABLE].min() >= 1.0


def test_unknown_cells_blocked_unless_traversable():
    grid = np.zeros((20, 20), dtype=np.int8)
    grid[:, 10:] = -1
    blocked = build_costmap(grid, 0.05, ExploreConfig())
    assert (blocked.kind[:, 10:] == UNKNOWN).all() and np.isinf(blocked.cost[:, 10:]).all()
    open_ = build_costmap(grid, 0.05, ExploreConfig(unknown_traversable=True, unknown_cost=3.0))
    assert (open_.kind == PASSABLE).all()
    assert np.allclose(open_.cost[:, 10:], 3.0 * open_.cost[:, :10].max())


def test_no_obstacle_means_unit_cost():
    costmap = build_costmap(np.zeros((10, 10), np.int8), 0.05, ExploreConfig())
    assert np.allclose(costmap.cost, 1.0) and (costmap.kind == PASSABLE).all()
