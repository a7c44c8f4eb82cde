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
