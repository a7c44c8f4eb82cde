"""A real run's replica in the simulator: the world, the true path, the frame times and the laser.

The replica of a real log is built from a reference SLAM run on it (its best estimate of what happened):

* **world**: the reference run's final occupancy map. Occupied cells are walls. Unknown cells are walls
  too (:data:`UNKNOWN_AS_WALL`): no beam of the real laser came back through them, so a simulated beam
  must not escape through unmapped space (behind a wall, beyond a door the robot never looked through,
  outside the building) and return nothing where the real one would have hit something. Free cells
  are free.
* **path**: the reference run's final trajectory, one pose per frame, taken as the truth.
* **times**: the log's laser timestamps (its real rate).
* **laser**: the log's laser geometry as a :class:`~slamtrials.sim.config.LaserConfig` that casts the
  same beams (:func:`laser_config_for`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import ConfigError
from slamtrials.geometry import compose, compose1
from slamtrials.record import OCCUPIED, UNKNOWN, LaserGeometry, OccupancyGrid
from slamtrials.sim.config import LaserConfig
from slamtrials.worlds.world import World, world_to_cell

__all__ = ["Replica", "UNKNOWN_AS_WALL", "laser_config_for", "world_from_map", "blocked_frames"]

#: Largest offset (rad) of a log's beams from symmetry that is taken as rounding.
_SYMMETRIC = 1e-9
#: How a replica's world treats the unknown cells of the reference map (see the module docstring).
UNKNOWN_AS_WALL = True


@dataclass(frozen=True, eq=False)
class Replica:
    """What a replica run is recorded from.

    Attributes
    ----------
    world:
        The world the simulated laser scans.
    t:
        float64 ``[T]`` frame times (s), the real log's.
    truth:
        float64 ``[T, 3]`` true poses of the robot base (world frame), one per frame.
    laser:
        The simulated laser's geometry (``fov``, ``angular_resolution``, ``max_range``, ``min_range``,
        ``mount``); the error fields are the profile's and are set later.
    """

    world: World
    t: NDArray[np.float64]
    truth: NDArray[np.float64]
    laser: LaserConfig

    def __post_init__(self) -> None:
        if self.t.ndim != 1 or self.truth.shape != (len(self.t), 3):
            raise ValueError(f"Replica needs t [T] and truth [T, 3], got {self.t.shape} and {self.truth.shape}")


def laser_config_for(geometry: LaserGeometry, beams: int) -> LaserConfig:
    """A :class:`LaserConfig` whose ``beams`` beams point where ``geometry``'s do.

    The simulator's beams are symmetric about the laser's x axis (``angle_min = -fov / 2``); a log's
    may not be, so the offset ``angle_min + fov / 2`` is turned into the mount's heading. When the
    offset is below 1e-9 rad the beams are taken as symmetric and ``fov = -2 angle_min``.

    Raises
    ------
    ConfigError
        Fewer than 2 beams, or a geometry the simulator cannot reproduce with this beam count.
    """
    if beams < 2:
        raise ConfigError(f"the log's scans have {beams} beam(s); a replica needs at least 2")
    fov = geometry.angle_increment * (beams - 1)
    offset = geometry.angle_min + 0.5 * fov
    if abs(offset) < _SYMMETRIC:
        # symmetric beams (a simulator's, most logs'): -2 angle_min is the field of view the recorded
        # geometry came from, so the simulated beams are the recorded ones to the last bit
        fov, offset = -2.0 * geometry.angle_min, 0.0
    mount = compose1(np.asarray(geometry.mount, dtype=np.float64), np.array([0.0, 0.0, offset]))
    try:
        config = LaserConfig(
            fov=fov,
            angular_resolution=geometry.angle_increment,
            max_range=geometry.range_max,
            min_range=geometry.range_min,
            mount=(float(mount[0]), float(mount[1]), float(mount[2])),
        )
    except ValueError as exc:  # pydantic's ValidationError is one
        raise ConfigError(f"the log's laser geometry cannot be simulated: {str(exc).splitlines()[-1]}") from None
    if config.num_beams != beams:
        raise ConfigError(f"the log's laser geometry gives {config.num_beams} simulated beams instead of {beams}")
    return config


def world_from_map(grid: OccupancyGrid, *, name: str = "replica", start: NDArray[np.float64] | None = None) -> World:
    """The replica's world: occupied (and, with :data:`UNKNOWN_AS_WALL`, unknown) cells of ``grid`` are walls.

    ``start`` (world frame ``[3]``) becomes the world's start pose when it lies in a free cell.

    Raises
    ------
    ConfigError
        An empty map, or a map without free cells.
    """
    if grid.grid.size == 0:
        raise ConfigError("the reference SLAM run published no map; nothing to build a replica from")
    occupied = grid.grid == OCCUPIED
    if UNKNOWN_AS_WALL:
        occupied |= grid.grid == UNKNOWN
    if occupied.all():
        raise ConfigError("the reference SLAM run's map has no free cell; nothing to build a replica from")
    world = World(occupied, grid.resolution, np.asarray(grid.origin, dtype=np.float64), name=name, start=None)
    if start is not None:
        row, col = world_to_cell(world, np.asarray(start, dtype=np.float64)[:2])
        if 0 <= row < world.height and 0 <= col < world.width and not world.occupied[row, col]:
            world = world.with_start(start)
    return world


def blocked_frames(replica: Replica) -> int:
    """Number of frames whose laser sits in a wall (or outside the map): those scans read 0 everywhere."""
    mount = np.asarray(replica.laser.mount, dtype=np.float64)
    lasers = compose(replica.truth, mount)
    rows, cols = world_to_cell(replica.world, lasers[:, :2])
    world = replica.world
    inside = (rows >= 0) & (rows < world.height) & (cols >= 0) & (cols < world.width)
    blocked = ~inside
    blocked[inside] = world.occupied[rows[inside], cols[inside]]
    return int(np.count_nonzero(blocked))
