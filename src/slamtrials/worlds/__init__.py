"""Floor plans: the :class:`World` type, its file formats, the procedural generator and the bundled catalog."""

from slamtrials.worlds.loading import WORLD_FORMATS, load_world
from slamtrials.worlds.world import World, cell_to_world, choose_start_pose, world_to_cell, world_to_map

__all__ = [
    "World",
    "load_world",
    "WORLD_FORMATS",
    "world_to_cell",
    "cell_to_world",
    "world_to_map",
    "choose_start_pose",
]
