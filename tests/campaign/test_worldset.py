"""The campaign's world list: each world's reachable area is the one its trials measure coverage on."""

from __future__ import annotations

import numpy as np

from slamtrials.campaign.worldset import resolve_worlds
from slamtrials.worlds import World, load_world
from slamtrials.worlds.formats.rosmap_save import save_rosmap


def test_reachable_area_is_what_the_robot_disc_covers(tmp_path):
    """A room with a 0.2 m slot into a second room: the slot connects the free space, but a 0.15 m
    robot cannot pass it, so with the robot's radius the second room is not counted."""
    res = 0.05
    occupied = np.zeros((80, 160), dtype=bool)
    occupied[:2, :] = occupied[-2:, :] = occupied[:, :2] = occupied[:, -2:] = True
    occupied[:, 80:82] = True
    occupied[38:42, 80:82] = False  # 0.2 m slot
    world = World(occupied, res, name="slot", start=np.array([1.0, 2.0, 0.0]))
    path = tmp_path / "slot.yaml"
    save_rosmap(world, path)
    connected = float(np.count_nonzero(load_world(str(path)).reachable_free())) * res**2
    (plain,) = resolve_worlds([str(path)])
    (robot,) = resolve_worlds([str(path)], robot_radius=0.15)
    assert plain.reachable_area == connected
    assert robot.reachable_area < 0.55 * connected  # about the first room only
    assert robot.reachable_area == float(np.count_nonzero(world.reachable_by_disc(0.15))) * res**2
