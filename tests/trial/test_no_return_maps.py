"""Beams without a return draw no free space: a trial's map stays inside the building.

A laser misses returns (dark, glossy or glass surfaces: the ``realistic`` profile's dropouts). If such a
beam were traced as free space up to the usable range, every map would be a starburst of free space
around the building, through its walls (issue 32). These tests run whole trials and look at the map.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from slamtrials.geometry import compose, inverse, transform_points
from slamtrials.record import FREE, RunRecord
from slamtrials.trial import TrialConfig, run_trial
from slamtrials.worlds import World, load_world, world_to_cell

#: How far (m) a free map cell may lie from the building's free space: the SLAM map's misalignment with
#: the world at its far ends plus a cell or two of rasterisation. A beam through a wall reaches metres.
TOLERANCE_M = 0.5


def free_cells_in_world(record: RunRecord) -> np.ndarray:
    """float64 ``[K, 2]``: world-frame centres (m) of the final SLAM map's free cells, carried from the map
    frame into the world through the first frame (the map frame starts at the first estimate)."""
    grid = record.map
    assert grid is not None
    rows, cols = np.nonzero(grid.grid == FREE)
    xy_map = np.column_stack(
        [
            grid.origin[0] + (cols + 0.5) * grid.resolution,
            grid.origin[1] + (grid.grid.shape[0] - rows - 0.5) * grid.resolution,
        ]
    )
    world_from_map = compose(record.truth[0], inverse(record.estimate[0]))
    return transform_points(world_from_map, xy_map)


def distance_to_building(world: World, xy: np.ndarray) -> np.ndarray:
    """float64 ``[K]``: distance (m) from each world point to the nearest free cell the robot can reach
    (inf outside the world's grid)."""
    to_free = ndimage.distance_transform_edt(~world.reachable_free()) * world.resolution
    rows, cols = world_to_cell(world, xy)
    inside = (rows >= 0) & (rows < world.height) & (cols >= 0) & (cols < world.width)
    out = np.full(xy.shape[0], np.inf)
    out[inside] = to_free[rows[inside], cols[inside]]
    return out


@pytest.fixture(scope="module")
def office() -> World:
    return load_world("office_small_01")


@pytest.fixture(scope="module")
def realistic_run(office) -> RunRecord:
    return run_trial(office, TrialConfig.from_dict({"sim": {"profile": "realistic"}}), seed=2)


@pytest.mark.slow
def test_a_realistic_trial_maps_at_most_a_tenth_more_than_the_reachable_free_area(realistic_run, office):
    info = realistic_run.metadata["trial"]
    reachable = office.area_of(office.reachable_free())
    assert info["connected_free_area_m2"] == pytest.approx(reachable)
    assert info["mapped_free_area_m2"] <= 1.1 * reachable
    assert info["mapped_free_area_m2"] >= 0.8 * reachable  # and it did map the building
    # the laser did miss returns: the test would see the starburst if they were traced
    assert np.isposinf(realistic_run.scans).mean() > 0.005


@pytest.mark.slow
def test_no_free_map_cell_lies_outside_the_building(realistic_run, office):
    distance = distance_to_building(office, free_cells_in_world(realistic_run))
    assert distance.size > 1000
    outside = distance > TOLERANCE_M
    assert not outside.any(), f"{outside.sum()} free cells up to {distance.max():.1f} m outside the building"


def test_the_building_check_sees_free_space_through_a_wall(office):
    # the check itself: a point 2 m beyond the outer wall is outside, the start is inside
    start = office.start[:2]
    xy = np.array([start, [office.origin[0] - 2.0, start[1]]])
    distance = distance_to_building(office, xy)
    assert distance[0] == 0.0 and distance[1] > TOLERANCE_M
