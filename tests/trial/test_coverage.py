"""Coverage measures against the true world: a bent SLAM map still counts as mapped when aligned locally."""

from __future__ import annotations

import math

import numpy as np

from slamtrials.record import OccupancyGrid
from slamtrials.trial.coverage import local_mapped_fraction, mapped_fraction
from slamtrials.worlds.world import World, world_to_cell

RES = 0.05
PIVOT = np.array([10.0, 1.0])
BEND = math.radians(4.0)


def corridor() -> World:
    """A 20 x 2 m corridor (walls around), start at its left end."""
    occ = np.zeros((int(2.0 / RES), int(20.0 / RES)), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return World(occ, RES, start=[1.0, 1.0, 0.0])


def bend(points: np.ndarray, sign: float = 1.0) -> np.ndarray:
    """World points ``[N, 2]`` as a SLAM map bent by BEND about PIVOT beyond x = 10 m has them (sign -1: back)."""
    out = np.array(points, dtype=float)
    far = out[:, 0] > PIVOT[0]
    c, s = math.cos(sign * BEND), math.sin(sign * BEND)
    d = out[far] - PIVOT
    out[far] = PIVOT + np.column_stack([c * d[:, 0] - s * d[:, 1], s * d[:, 0] + c * d[:, 1]])
    return out


def bent_map(world: World) -> OccupancyGrid:
    """The world as a SLAM map that bends by BEND half way: every map cell looks up the world cell it came from."""
    height, width = int(6.0 / RES), int(22.0 / RES)
    origin = np.array([-1.0, -2.0, 0.0])
    rows, cols = np.mgrid[0:height, 0:width]
    centres = np.column_stack([origin[0] + (cols.ravel() + 0.5) * RES, origin[1] + (height - rows.ravel() - 0.5) * RES])
    source = bend(centres, -1.0)  # (approximately) the inverse of the bend near the corridor
    r, c = world_to_cell(world, source)
    inside = (r >= 0) & (r < world.height) & (c >= 0) & (c < world.width)
    grid = np.full(height * width, -1, dtype=np.int8)
    grid[inside] = np.where(world.occupied[r[inside], c[inside]], 100, 0)
    return OccupancyGrid(grid.reshape(height, width), RES, origin)


def test_a_bent_map_is_mapped_when_aligned_locally_but_not_through_the_first_pose():
    world = corridor()
    grid = bent_map(world)
    x = np.linspace(1.0, 19.0, 400)
    truth = np.column_stack([x, np.full_like(x, 1.0), np.zeros_like(x)])
    estimate = truth.copy()
    estimate[:, :2] = bend(truth[:, :2])
    estimate[x > PIVOT[0], 2] = BEND
    reachable = world.reachable_by_disc(0.15)
    globally = mapped_fraction(world, grid, estimate[0], truth[0], reachable)
    locally = local_mapped_fraction(world, grid, estimate, truth, reachable)
    assert globally < 0.95  # cells of the far half fall off the bent corridor
    assert locally > 0.99


def test_unmapped_places_stay_unmapped_when_aligned_locally():
    world = corridor()
    grid = bent_map(world)
    grid.grid[:, grid.grid.shape[1] // 2 :] = -1  # the map knows nothing beyond x = 10 m
    x = np.linspace(1.0, 19.0, 400)
    truth = np.column_stack([x, np.full_like(x, 1.0), np.zeros_like(x)])
    fraction = local_mapped_fraction(world, grid, truth.copy(), truth, world.reachable_by_disc(0.15))
    assert 0.4 < fraction < 0.6
