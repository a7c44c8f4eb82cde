"""The World type: validation, conversions, start pose, and no side effects on the caller's arrays."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.errors import WorldError
from slamtrials.worlds.world import World, cell_to_world, world_to_cell


def _room(h=40, w=60):
    occ = np.zeros((h, w), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


def test_callers_arrays_stay_writable_and_unchanged():
    occ, origin, start = _room(), np.array([1.0, 2.0, 0.0]), np.array([2.0, 3.0, 0.0])
    World(occ, 0.05, origin, start=start)
    assert occ.flags.writeable and origin.flags.writeable and start.flags.writeable
    occ[5, 5] = True  # still ours to change


def test_cell_conversions_round_trip_with_rotated_origin():
    world = World(_room(), 0.1, origin=[3.0, -1.0, 0.4])
    rows, cols = np.mgrid[0:40, 0:60]
    r2, c2 = world_to_cell(world, cell_to_world(world, rows, cols))
    np.testing.assert_array_equal(r2, rows)
    np.testing.assert_array_equal(c2, cols)


def test_row_zero_is_the_top_of_the_image():
    world = World(_room(), 0.5)  # origin at the lower-left corner
    assert world_to_cell(world, [0.75, 0.25]) == (39, 1)
    assert world_to_cell(world, [0.75, 19.75]) == (0, 1)


def test_clearance_is_distance_to_nearest_wall_centre():
    world = World(_room(), 0.05)
    assert world.clearance[20, 30] == pytest.approx(19 * 0.05)
    assert world.clearance[1, 30] == pytest.approx(0.05)
    assert world.clearance[0, 30] == 0.0


def test_automatic_start_is_central_with_clearance():
    world = World(_room(), 0.05)
    row, col = world_to_cell(world, world.start[:2])
    assert abs(row - 19.5) <= 1 and abs(col - 29.5) <= 1
    assert world.clearance[row, col] >= 0.5


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"resolution": 0.0}, "resolution"),
        ({"resolution": float("nan")}, "resolution"),
        ({"resolution": 0.05, "origin": [0, 0, float("inf")]}, "origin"),
        ({"resolution": 0.05, "start": [0.0, 0.0, 0.0]}, "not in free space"),
    ],
)
def test_invalid_worlds_are_rejected(kwargs, message):
    with pytest.raises(WorldError, match=message):
        World(_room(), **kwargs)


def test_all_walls_has_no_free_space():
    with pytest.raises(WorldError, match="no free space"):
        World(np.ones((10, 10), bool), 0.05)


def _two_rooms(gap_cells: int) -> World:
    """Two 1.9 x 1.9 m rooms (0.05 m cells) joined by a doorway ``gap_cells`` cells wide in the middle wall."""
    occ = _room(40, 81)
    occ[:, 40] = True
    occ[20 - gap_cells // 2 : 20 - gap_cells // 2 + gap_cells, 40] = False
    return World(occ, 0.05, start=cell_to_world(World(occ, 0.05), 20, 20).tolist() + [0.0])


def test_reachable_by_disc_stops_at_gaps_narrower_than_the_robot():
    narrow = _two_rooms(4)  # 0.2 m: a 0.15 m radius robot cannot pass
    wide = _two_rooms(10)  # 0.5 m
    for world in (narrow, wide):
        assert world.reachable_free()[20, 60]  # both doorways connect the free space
    assert not narrow.reachable_by_disc(0.15)[20, 60]
    assert wide.reachable_by_disc(0.15)[20, 60]
    left = np.count_nonzero(narrow.reachable_by_disc(0.15))
    assert np.count_nonzero(wide.reachable_by_disc(0.15)) > 1.9 * left
    # the body covers cells next to walls, but not the corners a disc cannot get into
    mask = wide.reachable_by_disc(0.15)
    assert mask[1, 20] and mask[20, 1] and not mask[1, 1]
    assert not (mask & wide.occupied).any()


def test_reachable_by_disc_is_empty_when_the_robot_cannot_stand_anywhere():
    occ = np.ones((20, 20), bool)
    occ[8:12, 8:12] = False  # a 0.2 m pocket
    world = World(occ, 0.05, start=[0.5, 0.5, 0.0])
    assert world.reachable_free().any()
    assert not world.reachable_by_disc(0.15).any()
