"""Automatic tours: connected, clear of walls, reaching the far parts of the free space."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.errors import SimulationError
from slamtrials.sim.tour import tour_waypoints
from slamtrials.worlds.world import World, world_to_cell


def _s_shaped_world() -> World:
    """15 m x 10 m, two inner walls making an S: three bays joined at opposite ends."""
    occ = np.zeros((200, 300), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[:150, 100:102] = True
    occ[50:, 200:202] = True
    return World(occ, 0.05, name="s", start=np.array([7.5, 5.0, 0.0]))


def test_tour_visits_all_three_bays_with_clearance():
    world = _s_shaped_world()
    points = tour_waypoints(world, clearance=0.4)
    np.testing.assert_allclose(points[0], world.start[:2], atol=0.3)
    rows, cols = world_to_cell(world, points)
    assert np.all(world.clearance[rows, cols] >= 0.4 - world.resolution)
    assert {int(x // 5) for x in points[:, 0]} == {0, 1, 2}
    # consecutive waypoints are short hops (no jumps through walls)
    assert np.linalg.norm(np.diff(points, axis=0), axis=1).max() < 1.5


def test_segments_between_waypoints_stay_in_free_space():
    world = _s_shaped_world()
    points = tour_waypoints(world)
    fractions = np.linspace(0, 1, 20)[None, :, None]
    samples = points[:-1, None, :] + fractions * (points[1:, None, :] - points[:-1, None, :])
    rows, cols = world_to_cell(world, samples.reshape(-1, 2))
    assert not world.occupied[rows, cols].any()


def test_no_room_to_move_is_an_error():
    occ = np.ones((40, 40), bool)
    occ[18:22, 18:22] = False
    world = World(occ, 0.05)
    with pytest.raises(SimulationError, match="clearance"):
        tour_waypoints(world, clearance=0.4)
