"""The Explorer's behaviour on synthetic maps (no simulator): turning, goals, escape, giving up, done."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from slamtrials.explore import ExploreConfig, Explorer
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
SCAN = np.full(541, 30.0, dtype=np.float32)
RES = 0.05


def occupancy(grid):
    return SimpleNamespace(grid=np.asarray(grid, dtype=np.int8), resolution=RES, origin=np.zeros(3))


def closed_room(n=100):
    """A fully known 5 x 5 m room (walls on the border)."""
    grid = np.zeros((n, n), dtype=np.int8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 100
    return grid


def open_room(n=100):
    """The same room, but its right half is still unknown."""
    grid = closed_room(n)
    grid[:, n // 2 :] = -1
    return grid


def drive(explorer, grid, pose, seconds, t0=0.0):
    """Call the explorer every 0.1 s with a fixed pose; return the commands."""
    occ = occupancy(grid)
    out = []
    for k in range(round(seconds / 0.1)):
        out.append(explorer.command(t0 + 0.1 * k, pose, SCAN, LASER, occ))
        if explorer.done:
            break
    return out


def test_starts_with_a_full_turn():
    explorer = Explorer()
    commands = drive(explorer, open_room(), [1.0, 2.5, 0.0], 1.0)
    assert explorer.mode == "turning"
    assert all(v == 0.0 and w > 0.0 for v, w in commands)


def test_empty_map_is_not_the_end():
    explorer = Explorer()
    drive(explorer, np.full((50, 50), -1, np.int8), [1.0, 1.0, 0.0], 20.0)
    assert not explorer.done


def test_finds_a_goal_at_the_frontier():
    explorer = Explorer(ExploreConfig(initial_spin=False))
    pose = np.array([1.0, 2.5, 0.0])
    commands = drive(explorer, open_room(), pose, 0.5)
    goal = explorer.goal
    assert goal is not None
    assert 2.3 < goal[0] < 2.6  # the frontier: the last known column, x in [2.45, 2.5)
    path = explorer.path
    assert np.allclose(path[0], pose[:2]) and np.allclose(path[-1], goal)
    assert commands[-1][0] > 0.0  # facing the goal: drives


def test_closed_room_ends_after_a_look_around():
    explorer = Explorer(ExploreConfig(initial_spin=False))
    drive(explorer, closed_room(), [2.5, 2.5, 0.0], 30.0)
    assert explorer.done and explorer.reason == "no_frontiers"
    assert explorer.stats.look_arounds == 1
    assert explorer.command(99.0, [2.5, 2.5, 0.0], SCAN, LASER, occupancy(closed_room())) == (0.0, 0.0)


def test_escapes_when_the_pose_is_inside_the_inflated_zone():
    explorer = Explorer(ExploreConfig(initial_spin=False))
    pose = np.array([0.12, 2.5, 0.0])  # 0.07 m from the wall's edge: lethal
    drive(explorer, open_room(), pose, 0.5)
    assert explorer.goal is not None and len(explorer.path) > 0


def test_a_robot_that_does_not_move_recovers_then_gives_up_the_goal():
    explorer = Explorer(ExploreConfig(initial_spin=False))
    drive(explorer, open_room(), [1.0, 2.5, 0.0], 60.0)
    assert explorer.stats.recoveries >= 1
    assert explorer.stats.goals_blacklisted >= 1


def test_deterministic_and_reset():
    a, b = Explorer(), Explorer()
    ca = drive(a, open_room(), [1.0, 2.5, 0.3], 12.0)
    cb = drive(b, open_room(), [1.0, 2.5, 0.3], 12.0)
    assert ca == cb
    a.reset()
    assert a.goal is None and a.stats.replans == 0 and not a.done
    assert drive(a, open_room(), [1.0, 2.5, 0.3], 12.0) == ca


def test_reported_bumps_start_a_recovery():
    explorer = Explorer(ExploreConfig(initial_spin=False))
    occ = occupancy(open_room())
    pose = [1.0, 2.5, 0.0]
    for k in range(5):
        explorer.command(0.1 * k, pose, SCAN, LASER, occ)
    assert explorer.mode == "following"
    for k in range(5, 8):
        explorer.command(0.1 * k, pose, SCAN, LASER, occ, stalled=True)
    assert explorer.mode == "recovering" and explorer.stats.recoveries == 1


def room_with_door(gap_cells, wall=50):
    """A known room whose right wall (column ``wall``) has a door ``gap_cells`` cells wide, leading to
    known free space up to x = 3.5 m, with unknown space beyond it."""
    grid = np.full((100, 100), -1, dtype=np.int8)
    grid[:, :70] = 0
    grid[0, :70] = grid[-1, :70] = grid[:, 0] = 100
    grid[:, wall] = 100
    top = 50 - gap_cells // 2
    grid[top : top + gap_cells, wall] = 0
    return grid


def test_a_robot_shut_in_behind_a_narrow_door_takes_it():
    grid = room_with_door(8, wall=20)  # 0.40 m: too narrow for the normal lethal zone, not for the robot
    explorer = Explorer(ExploreConfig(initial_spin=False))
    drive(explorer, grid, [0.5, 2.5, 0.0], 0.5)
    assert not explorer.done
    assert explorer.goal is not None and explorer.goal[0] > 1.0
    strict = Explorer(ExploreConfig(initial_spin=False, relaxed_margin=0.05))  # no relaxed plan
    drive(strict, grid, [0.5, 2.5, 0.0], 20.0)
    assert strict.done


def test_a_robot_not_shut_in_ignores_narrow_doors():
    explorer = Explorer(ExploreConfig(initial_spin=False))
    drive(explorer, room_with_door(8), [1.0, 2.5, 0.0], 20.0)  # the room is most of the map
    assert explorer.done


def test_view_points_of_frontiers_behind_a_gap():
    grid = room_with_door(6)  # 0.30 m: the robot cannot pass, but the laser can see through
    grid[:, 51:] = -1  # unknown right behind the gap: its cells are a frontier in the lethal zone
    # the frontier is the gap's 6 cells: let frontiers that short count
    explorer = Explorer(ExploreConfig(initial_spin=False, view_distance=1.0, min_frontier_length=0.3))
    drive(explorer, grid, [1.0, 2.5, 0.0], 0.5)
    goal = explorer.goal
    assert goal is not None and goal[0] < 2.5 and math.dist(goal, (2.5, 2.5)) <= 1.1
    plain = Explorer(ExploreConfig(initial_spin=False, min_frontier_length=0.3))
    drive(plain, grid, [1.0, 2.5, 0.0], 20.0)
    assert plain.done


def test_a_phantom_return_in_front_does_not_stop_the_robot():
    # one beam straight ahead reads 0.20 to 0.24 m in every scan, at a range that jumps about (a short
    # reading of something not in the map); with the scan filter the robot drives to its goal, without
    # it stops. (The scan shows nothing else, so the evidence layer, which would find the map's free
    # space vouched for by no return, is off.)
    def run(config):
        explorer = Explorer(config)
        pose = np.array([1.0, 2.5, 0.0])
        occ = occupancy(open_room())
        v = 0.0
        for k in range(15):
            scan = SCAN.copy()
            scan[270] = 0.2 + 0.02 * (k % 3)
            v, _ = explorer.command(0.1 * k, pose, scan, LASER, occ)
        return v

    assert run(ExploreConfig(initial_spin=False, evidence_layer=False)) > 0.0
    assert run(ExploreConfig(initial_spin=False, evidence_layer=False, scan_filter_window=0)) == 0.0
