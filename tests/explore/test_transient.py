"""Obstacles the map does not show (slamtrials.explore.transient): taken, planned around, forgotten when gone."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from slamtrials.explore import ExploreConfig, Explorer
from slamtrials.explore.transient import TransientObstacles
from slamtrials.record import LaserGeometry

LASER = LaserGeometry.from_dict(
    {
        "angle_min": -math.radians(135),
        "angle_increment": math.radians(0.5),
        "range_min": 0.0,
        "range_max": 30.0,
        "mount": [0.0, 0.0, 0.0],
    }
)
AHEAD = 270  # the beam straight ahead
RES = 0.05


def occupancy(grid):
    return SimpleNamespace(grid=np.asarray(grid, dtype=np.int8), resolution=RES, origin=np.zeros(3))


def room(n=100):
    """A known 5 x 5 m room (walls on the border)."""
    grid = np.zeros((n, n), dtype=np.int8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 100
    return grid


def scan_with(beams, distance, far=2.0):
    """Every beam reads ``far`` m, those in ``beams`` ``distance`` m."""
    scan = np.full(541, far, dtype=np.float64)
    scan[list(beams)] = distance
    return scan


def cell_value(view, x, y):
    grid = np.asarray(view.grid)
    return int(grid[grid.shape[0] - 1 - math.floor(y / RES), math.floor(x / RES)])


def test_takes_returns_near_the_robot_in_free_space_only():
    obstacles = TransientObstacles(reach=0.25, lifetime=60.0)
    pose = np.array([2.5, 2.5, 0.0])
    occ = occupancy(room())
    assert obstacles.add(0.0, pose, scan_with(range(AHEAD - 2, AHEAD + 3), 0.3), LASER, 0.15, occ) == 5
    assert np.all(np.abs(obstacles.points[:, 0] - 2.8) < 0.01)
    three = range(AHEAD - 1, AHEAD + 2)
    # too far from the robot's edge: nothing
    assert obstacles.add(0.0, pose, scan_with(three, 0.6), LASER, 0.15, occ) == 0
    # next to a wall the map shows (x = 4.95 m): a wall seen a little off, nothing new
    assert obstacles.add(0.0, np.array([4.6, 2.5, 0.0]), scan_with(three, 0.33), LASER, 0.15, occ) == 0
    # fewer than three returns: more likely a corner the map shows a little off
    assert obstacles.add(0.0, pose, scan_with([AHEAD, AHEAD + 1], 0.3), LASER, 0.15, occ) == 0
    # returns on more than 50 degrees' worth of beams: a wall the map misplaced, not a thing
    assert obstacles.add(0.0, pose, scan_with(range(AHEAD - 55, AHEAD + 56), 0.3), LASER, 0.15, occ) == 0
    assert obstacles.add(0.0, pose, scan_with(range(AHEAD - 45, AHEAD + 46), 0.3), LASER, 0.15, occ) == 91
    # several small things round the robot, however far apart in bearing
    sides = [*range(AHEAD - 182, AHEAD - 178), *range(AHEAD + 178, AHEAD + 182)]
    assert obstacles.add(0.0, pose, scan_with(sides, 0.3), LASER, 0.15, occ) == 8
    assert len(obstacles) == 104


def test_stamped_into_the_map_the_explorer_plans_on():
    obstacles = TransientObstacles(reach=0.25, lifetime=60.0)
    occ = occupancy(room())
    assert obstacles.stamp(occ) is occ
    obstacles.add(0.0, np.array([2.5, 2.5, 0.0]), scan_with(range(AHEAD - 1, AHEAD + 2), 0.3), LASER, 0.15, occ)
    view = obstacles.stamp(occ)
    assert cell_value(view, 2.8, 2.5) == 100
    assert cell_value(occ, 2.8, 2.5) == 0  # the map itself is left alone


def test_forgotten_once_a_beam_passes_or_after_its_lifetime():
    occ = occupancy(room())
    pose = np.array([2.5, 2.5, 0.0])
    obstacles = TransientObstacles(reach=0.25, lifetime=60.0)
    obstacles.add(0.0, pose, scan_with(range(AHEAD - 1, AHEAD + 2), 0.3), LASER, 0.15, occ)
    # still there: the beams end on it, or short of it; dropped beams say nothing
    obstacles.forget_seen(1.0, pose, scan_with(range(AHEAD - 1, AHEAD + 2), 0.3), LASER)
    obstacles.forget_seen(1.1, pose, scan_with([], 0.0, far=0.2), LASER)
    dropped = scan_with([], 0.0)
    dropped[AHEAD - 1 : AHEAD + 2] = np.nan
    obstacles.forget_seen(1.2, pose, dropped, LASER)
    assert len(obstacles) == 3
    # seen from elsewhere, the beam towards it goes on past it: gone
    side = np.array([2.8, 2.0, math.pi / 2])
    obstacles.forget_seen(2.0, side, scan_with([], 0.0, far=2.0), LASER)
    assert len(obstacles) == 0
    # not looked at (behind the laser's field of view): dropped after its lifetime only
    obstacles.add(10.0, pose, scan_with(range(AHEAD - 1, AHEAD + 2), 0.3), LASER, 0.15, occ)
    behind = np.array([3.3, 2.5, 0.0])
    obstacles.forget_seen(69.0, behind, scan_with([], 0.0), LASER)
    assert len(obstacles) == 3
    obstacles.forget_seen(70.0, behind, scan_with([], 0.0), LASER)
    assert len(obstacles) == 0


def corridor():
    """A known 1.2 m wide corridor (rows 38-61) from x = 0 to 3.5 m, unknown beyond: the frontier is at its end."""
    grid = np.full((100, 100), -1, dtype=np.int8)
    grid[37:63, :70] = 100
    grid[38:62, 1:70] = 0
    return grid


def thing_scan(pose, x_thing=1.4, half_width=0.06, far=2.0):
    """The scan from ``pose`` of a thing the map does not show: a segment across the corridor's middle at
    ``x = x_thing``, ``2 half_width`` m wide; every other beam reads ``far`` m."""
    angles = pose[2] + LASER.angle_min + LASER.angle_increment * np.arange(541)
    c = np.cos(angles)
    t = np.where(np.abs(c) > 1e-9, (x_thing - pose[0]) / np.where(np.abs(c) > 1e-9, c, 1.0), -1.0)
    y = pose[1] + t * np.sin(angles)
    hit = (t > 0.0) & (np.abs(y - 2.5) <= half_width)
    return np.where(hit, t, far)


def test_a_thing_the_map_does_not_show_is_planned_around_and_the_goal_kept():
    # a thing in the middle of a corridor that the map does not show: the scan holds the robot still in
    # front of it, it recovers, and the new path goes around the thing (the recovery does not count
    # against the goal). Without the layer the path keeps running into the thing and the goal is given up.
    def run(config):
        explorer = Explorer(config)
        occ = occupancy(corridor())
        pose = np.array([1.0, 2.5, 0.0])
        for k in range(400):
            v, w = explorer.command(0.1 * k, pose, thing_scan(pose), LASER, occ)
            pose = pose + 0.1 * np.array([v * math.cos(pose[2]), v * math.sin(pose[2]), w])
            if pose[0] > 2.0:
                break
        return explorer, pose

    kept, pose = run(ExploreConfig(initial_spin=False, evidence_layer=False))
    assert kept.stats.recoveries >= 1 and kept.stats.transient_obstacles > 0
    assert kept.stats.goals_blacklisted == 0 and pose[0] > 2.0  # got past it
    plain, pose = run(ExploreConfig(initial_spin=False, evidence_layer=False, transient_reach=0.0))
    assert plain.stats.transient_obstacles == 0
    assert plain.stats.goals_blacklisted >= 1 and pose[0] < 1.4
