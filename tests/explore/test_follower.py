"""Path follower: scan geometry, free travel along arcs, pure pursuit, turning in place, obstacles."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from slamtrials.explore import ExploreConfig, PathFollower, RobotLimits
from slamtrials.explore.follower import free_travel, scan_points, turn_rate
from slamtrials.record import LaserGeometry

ROBOT = RobotLimits()  # the defaults: the paper's robot, which the followers below drive
LASER = LaserGeometry.from_dict(
    {
        "angle_min": -math.radians(135),
        "angle_increment": math.radians(0.5),
        "range_min": 0.0,
        "range_max": 30.0,
        "mount": [0.0, 0.0, 0.0],
    }
)
BEAMS = 541


def empty_scan():
    return np.full(BEAMS, 30.0, dtype=np.float32)


def wall_scan(distance):
    """A wall across the robot's path, ``distance`` m ahead (robot frame x = distance)."""
    angles = LASER.angle_min + LASER.angle_increment * np.arange(BEAMS)
    with np.errstate(divide="ignore"):
        r = np.where(np.cos(angles) > 1e-6, distance / np.cos(angles), 30.0)
    return np.minimum(r, 30.0).astype(np.float32)


def test_scan_points_use_the_mount_and_drop_max_range():
    laser = dataclasses.replace(LASER, mount=(0.1, 0.0, math.pi / 2))
    r = empty_scan()
    r[270] = 2.0  # the middle beam: straight ahead of the laser, which looks left
    pts = scan_points(r, laser)
    assert pts.shape == (1, 2)
    assert np.allclose(pts[0], [0.1, 2.0], atol=1e-9)


def test_free_travel_straight_and_on_arcs():
    pts = np.array([[1.0, 0.0]])
    assert math.isclose(free_travel(pts, 0.0, 0.2), 0.8)
    assert free_travel(np.array([[1.0, 0.3]]), 0.0, 0.2) == 5.0  # beside the path
    assert free_travel(np.array([[-1.0, 0.0]]), 0.0, 0.2) == 5.0  # behind
    # on a left turn of radius 1 m, a point a quarter circle ahead, on the arc
    travel = free_travel(np.array([[1.0, 1.0]]), 1.0, 0.2)
    assert math.isclose(travel, math.pi / 2 - 0.2, abs_tol=1e-9)
    # the same point for a right turn is off the arc
    assert free_travel(np.array([[1.0, 1.0]]), -1.0, 0.2) == 5.0
    assert free_travel(np.array([[0.1, 0.0]]), 0.0, 0.2) == 0.0


def test_turn_rate_respects_limits():
    assert turn_rate(0.0, 1.2, 1.7) == 0.0
    assert turn_rate(3.0, 1.2, 1.7) == 1.2
    assert turn_rate(-3.0, 1.2, 1.7) == -1.2
    small = turn_rate(0.01, 1.2, 1.7)
    assert 0 < small <= math.sqrt(2 * 1.7 * 0.01)


def test_follows_a_straight_path_within_the_limits():
    cfg = ExploreConfig()
    follower = PathFollower(cfg)
    follower.set_path(np.column_stack([np.linspace(0, 5, 101), np.zeros(101)]))
    v_prev = 0.0
    for _ in range(30):
        out = follower.command([0.0, 0.0, 0.0], empty_scan(), LASER)
        assert abs(out.w) < 1e-9 and out.v <= ROBOT.max_linear_speed + 1e-12
        assert out.v - v_prev <= ROBOT.max_linear_accel * ROBOT.control_period + 1e-12
        v_prev = out.v
    assert math.isclose(v_prev, ROBOT.max_linear_speed)


def test_turns_in_place_towards_a_path_behind_when_not_backing_out():
    follower = PathFollower(ExploreConfig(max_reverse_distance=0.0))
    follower.set_path(np.column_stack([np.linspace(0, -3, 61), np.zeros(61)]))
    out = follower.command([0.0, 0.0, 0.0], empty_scan(), LASER)
    assert out.v == 0.0 and out.w != 0.0


def drive(follower, pose, steps, dt=0.1):
    """Unicycle robot obeying the follower's commands exactly; returns the poses [steps + 1, 3] and the
    commands [steps, 2]."""
    poses, commands = [np.array(pose, dtype=float)], []
    for _ in range(steps):
        x, y, theta = poses[-1]
        out = follower.command(poses[-1], empty_scan(), LASER)
        follower.remember(out.v, out.w)
        commands.append((out.v, out.w))
        poses.append(np.array([x + out.v * dt * math.cos(theta), y + out.v * dt * math.sin(theta), theta + out.w * dt]))
        if out.finished:
            break
    return np.array(poses), np.array(commands)


def l_path_behind():
    """Back 2 m the way the robot came (it faces +x at the origin), then 3 m to the left of that way."""
    back = np.column_stack([np.linspace(0, -2, 41), np.zeros(41)])
    up = np.column_stack([np.full(60, -2.0), np.linspace(0.05, 3, 60)])
    return np.vstack([back, up])


def test_backs_out_of_a_dead_end_instead_of_turning_round():
    cfg = ExploreConfig()
    follower = PathFollower(cfg)
    follower.set_path(l_path_behind())
    poses, commands = drive(follower, [0.0, 0.0, 0.0], 400)
    assert np.hypot(poses[-1, 0] + 2.0, poses[-1, 1] - 3.0) < cfg.goal_tolerance  # got there
    v = commands[:, 0]
    assert v.min() >= -cfg.reverse_speed - 1e-12 and v.min() < -0.5 * cfg.reverse_speed
    speed = np.abs(np.concatenate([[0.0], v]))
    assert np.all(np.diff(speed) <= ROBOT.max_linear_accel * ROBOT.control_period + 1e-12)  # braking is the robot's
    assert not np.any((v[1:] < 0.0) & (v[:-1] > 0.0))  # never from forward straight to backward
    backed = poses[1:][v < 0.0]
    assert backed[:, 0].min() > -2.5 and np.all(np.abs(backed[:, 1]) < 0.6)  # only along the first leg
    turning = np.abs(np.diff(poses[:, 2])).sum()
    assert turning < math.radians(135.0)  # one quarter turn (and some steering), not a half turn first

    turning_round = PathFollower(ExploreConfig(max_reverse_distance=0.0))
    turning_round.set_path(l_path_behind())
    poses_fwd, commands_fwd = drive(turning_round, [0.0, 0.0, 0.0], 400)
    assert commands_fwd[:, 0].min() >= 0.0
    assert np.abs(np.diff(poses_fwd[:, 2])).sum() > math.radians(200.0)


def test_backing_out_stops_after_max_reverse_distance():
    cfg = ExploreConfig(max_reverse_distance=1.0)
    follower = PathFollower(cfg)
    follower.set_path(np.column_stack([np.linspace(0, -4, 81), np.zeros(81)]))
    poses, commands = drive(follower, [0.0, 0.0, 0.0], 600)
    backing = np.flatnonzero(commands[:, 0] < 0.0)
    assert backing.size and np.all(np.diff(backing) == 1)  # one stretch, then forward
    assert -poses[backing[-1] + 1, 0] <= 1.0 + 0.1
    assert np.hypot(poses[-1, 0] + 4.0, poses[-1, 1]) < cfg.goal_tolerance


def test_a_moving_robot_stops_before_backing_out():
    cfg = ExploreConfig()
    follower = PathFollower(cfg)
    follower.set_path(np.column_stack([np.linspace(0.2, -3, 65), np.zeros(65)]))
    follower.remember(0.5, 0.0)
    follower.command([0.15, 0.0, 0.0], empty_scan(), LASER)
    out = follower.command([0.2, 0.0, 0.0], empty_scan(), LASER)  # 0.05 m in 0.1 s: still rolling forward
    assert out.v == 0.0 and out.w == 0.0 and not follower.backing
    follower.remember(out.v, out.w)
    out = follower.command([0.2, 0.0, 0.0], empty_scan(), LASER)  # stopped
    assert out.v < 0.0 and follower.backing


def test_curves_towards_a_path_to_the_left():
    follower = PathFollower(ExploreConfig())
    follower.set_path(np.column_stack([np.linspace(0, 3, 61), np.linspace(0, 1.5, 61)]))
    for _ in range(10):
        out = follower.command([0.0, 0.0, 0.0], empty_scan(), LASER)
    assert out.v > 0.0 and out.w > 0.0


@pytest.mark.parametrize(("distance", "expect"), [(3.0, "full"), (0.6, "slow"), (0.25, "creep"), (0.155, "stopped")])
def test_slows_down_and_stops_for_obstacles_in_the_scan(distance, expect):
    cfg = ExploreConfig()
    follower = PathFollower(cfg)
    follower.set_path(np.column_stack([np.linspace(0, 5, 101), np.zeros(101)]))
    follower.remember(ROBOT.max_linear_speed, 0.0)
    out = follower.command([0.0, 0.0, 0.0], wall_scan(distance), LASER)
    if expect == "full":
        assert math.isclose(out.v, ROBOT.max_linear_speed)
    elif expect == "slow":
        assert 0.0 < out.v < ROBOT.max_linear_speed
        room = distance - ROBOT.radius - cfg.obstacle_margin - cfg.stop_distance
        assert out.v <= math.sqrt(2 * ROBOT.max_linear_accel * room) + 1e-6
    elif expect == "creep":  # too close for the normal margins: inch on slowly
        assert 0.0 < out.v <= 0.15 and not out.blocked
    else:
        assert out.v == 0.0 and out.blocked


def test_reports_the_end_of_the_path():
    follower = PathFollower(ExploreConfig())
    follower.set_path(np.array([[0.0, 0.0], [0.1, 0.0]]))
    out = follower.command([0.05, 0.0, 0.0], empty_scan(), LASER)
    assert out.finished and out.v == 0.0
    follower.clear()
    assert not follower.has_path and follower.command([0, 0, 0], empty_scan(), LASER).finished
