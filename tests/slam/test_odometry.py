"""The odometry baseline: its trajectory is the recorded odometry, and its map from true poses fits the walls."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.ndimage import binary_dilation

from slamtrials.geometry import wrap_angle
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.slamrun import run_slam
from slamtrials.worlds import World
from slamtrials.worlds.world import world_to_cell


def small_world() -> World:
    """A 6 m x 4 m room with a pillar and a wall stub, 0.05 m cells."""
    occ = np.ones((100, 140), bool)
    occ[10:90, 10:130] = False
    occ[40:60, 60:70] = True  # pillar
    occ[10:35, 100:103] = True  # wall stub from the top
    return World(occ, 0.05, name="room", start=np.array([1.5, 1.5, 0.0]))


@pytest.fixture(scope="module")
def world_and_record():
    world = small_world()
    record = simulate_waypoints(
        world, [[5.0, 1.2], [5.6, 2.5], [4.3, 3.4], [1.2, 3.5], [1.0, 1.5]], SimConfig.paper(), seed=5, max_time=120
    )
    assert record.metadata["outcome"] == "completed"
    return world, record


def test_trajectory_is_the_recorded_odometry(world_and_record):
    _, record = world_and_record
    result = run_slam(record, "odometry")
    np.testing.assert_array_equal(result.trajectory.t, record.t)
    np.testing.assert_allclose(result.trajectory.poses[:, :2], record.odometry[:, :2], atol=1e-9)
    np.testing.assert_allclose(wrap_angle(result.trajectory.poses[:, 2] - record.odometry[:, 2]), 0.0, atol=1e-9)
    assert result.updates == len(record)  # the default maps every frame


def test_update_rule_maps_fewer_frames(world_and_record):
    _, record = world_and_record
    result = run_slam(record, "odometry", preset="gmapping")
    assert 2 <= result.updates < len(record) / 10


def test_map_from_true_poses_matches_the_walls(world_and_record):
    world, record = world_and_record
    perfect = replace(record, odometry=record.truth.copy())
    result = run_slam(perfect, "odometry", overrides={"initial_pose": [float(v) for v in record.truth[0]]})
    grid = result.occupancy
    rows, cols = np.nonzero(grid.grid == 100)
    assert len(rows) > 200
    h = grid.grid.shape[0]
    xy = np.column_stack(
        [grid.origin[0] + (cols + 0.5) * grid.resolution, grid.origin[1] + (h - rows - 0.5) * grid.resolution]
    )
    wr, wc = world_to_cell(world, xy)
    near_wall = binary_dilation(world.occupied, np.ones((3, 3), bool))
    inside = (wr >= 0) & (wr < world.height) & (wc >= 0) & (wc < world.width)
    hits = np.zeros(len(xy), bool)
    hits[inside] = near_wall[wr[inside], wc[inside]]
    assert hits.mean() >= 0.9
    # and the free cells are free in the world
    frows, fcols = np.nonzero(grid.grid == 0)
    fxy = np.column_stack(
        [grid.origin[0] + (fcols + 0.5) * grid.resolution, grid.origin[1] + (h - frows - 0.5) * grid.resolution]
    )
    fr, fc = world_to_cell(world, fxy)
    assert np.mean(~world.occupied[fr, fc]) > 0.98
