"""The replicas of the paper's validation worlds: the stated sizes, closed, one free region, room for the robot."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.errors import WorldError
from slamtrials.explore import ExploreConfig
from slamtrials.sim import SimConfig
from slamtrials.worlds import load_world, world_to_cell
from slamtrials.worlds.replicas import REPLICAS, build_replica, replica_names

NAMES = replica_names()
#: The paper's outer bounds (m): the hall is 10 x 12 m, the lab 9 x 9 m.
BOUNDS = {"paper_hall_empty": (10.0, 12.0), "paper_hall_furnished": (10.0, 12.0), "paper_lab": (9.0, 9.0)}


def _free_extent(world) -> tuple[float, float]:
    rows = np.flatnonzero((~world.occupied).any(axis=1))
    cols = np.flatnonzero((~world.occupied).any(axis=0))
    return (cols[-1] - cols[0] + 1) * world.resolution, (rows[-1] - rows[0] + 1) * world.resolution


def test_the_replicas_are_the_three_settings_of_tables_ii_and_iii():
    assert NAMES == ["paper_hall_empty", "paper_hall_furnished", "paper_lab"]


@pytest.mark.parametrize("name", NAMES)
def test_replica_loads_by_name_with_the_paper_s_outer_bounds(name):
    world = load_world(name)
    assert world.resolution == 0.05
    assert _free_extent(world) == pytest.approx(BOUNDS[name], abs=1e-9)
    assert world.metadata["kind"] == "replica"
    assert "guess" in world.metadata["layout"] and "Table" in world.metadata["source"]


@pytest.mark.parametrize("name", NAMES)
def test_replica_is_closed_and_one_free_region(name):
    world = load_world(name)
    border = np.concatenate([world.occupied[0], world.occupied[-1], world.occupied[:, 0], world.occupied[:, -1]])
    assert border.all()
    assert world.free_regions[1] == 1
    assert world.reachable_free().sum() == np.count_nonzero(~world.occupied)
    # the walls are at least 0.5 m of occupied cells around the floor: no beam leaves the building
    assert world.clearance[world.occupied].max() == 0.0
    assert _free_extent(world)[0] <= world.size_m[0] - 1.0 + 1e-9


@pytest.mark.parametrize("name", NAMES)
def test_start_pose_is_free_and_the_robot_fits_everywhere(name):
    world = load_world(name)
    lethal = SimConfig().robot.radius + ExploreConfig().inflation_margin
    row, col = world_to_cell(world, world.start[:2])
    assert not world.occupied[row, col]
    assert world.clearance[row, col] >= lethal + 0.5  # room to turn on the spot, away from furniture
    # every aisle lets the robot through: the cells where its centre may go form one region, and every
    # free cell is within the footprint's reach of it (a room's corner is sqrt(2) times the radius away)
    passable = world.clearance >= lethal + world.resolution
    from scipy import ndimage

    labels, count = ndimage.label(passable)
    assert count == 1
    assert labels[row, col] == 1
    reach = ndimage.distance_transform_edt(~passable) * world.resolution
    assert reach[~world.occupied].max() <= np.sqrt(2) * (lethal + world.resolution) + world.resolution


def test_the_hall_is_an_l_and_the_furnished_one_is_the_empty_one_with_furniture():
    empty, furnished = build_replica("paper_hall_empty"), build_replica("paper_hall_furnished")
    assert empty.free_area == pytest.approx(10 * 12 - 5 * 6)  # the L: 10 x 12 m less a 5 x 6 m corner
    assert not (~furnished.occupied & empty.occupied).any()  # furniture only takes floor away
    assert 0.7 * empty.free_area < furnished.free_area < 0.95 * empty.free_area
    assert np.array_equal(empty.start, furnished.start)
    # the cut-away corner: the top-right 5 x 6 m (x > 5, y > 6) is outside the hall
    row, col = world_to_cell(empty, np.array([7.5, 9.0]))
    assert empty.occupied[row, col]


def test_the_lab_is_a_furnished_nine_metre_square():
    lab = build_replica("paper_lab")
    assert lab.metadata["floor_area_m2"] == pytest.approx(81.0)
    assert 0.6 * 81 < lab.free_area < 0.9 * 81


def test_replicas_are_drawn_the_same_every_time():
    for spec in REPLICAS:
        a, b = build_replica(spec.name), build_replica(spec.name)
        assert np.array_equal(a.occupied, b.occupied) and np.array_equal(a.start, b.start)


def test_unknown_replica_is_one_clear_error():
    with pytest.raises(WorldError, match="paper_hall_empty"):
        build_replica("paper_hall")
