"""A scripted run: drive the simulated robot through a list of waypoints using its true pose.

This is not exploration (that is :mod:`slamtrials.explore`): the controller sees the ground truth, so
the path is the same whatever the odometry bias. It is meant for tests, demos and recorded tours.

Controller (per step, towards the current waypoint at distance ``d`` and bearing error ``e`` in the
robot frame):

* turn rate ``w = sign(e) min(max_angular_speed, k_w |e|, sqrt(2 max_angular_accel |e|))`` with
  ``k_w = 2.5 /s``: proportional, and slow enough near ``e = 0`` to stop turning in time;
* if ``|e| > 45 deg`` turn in place (``v = 0``); otherwise
  ``v = min(max_linear_speed, sqrt(2 max_linear_accel d)) cos(e)``: full speed, braking so as to
  arrive at each waypoint slowly, and slower while still turning.

A waypoint counts as reached when the robot's centre is within ``tolerance`` of it. The run ends when
all waypoints are reached (``"completed"``), when ``max_time`` has passed (``"timeout"``), or when the
robot has been stalled against a wall for more than 5 s in a row (``"stalled"``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from slamtrials.errors import SimulationError
from slamtrials.record import Frame, RunRecord
from slamtrials.sim.config import RobotConfig, SimConfig
from slamtrials.sim.simulator import Simulator, as_generator
from slamtrials.worlds.world import World

__all__ = ["simulate_waypoints", "waypoint_command", "STALL_TIMEOUT"]

#: Seconds of uninterrupted stalling after which a waypoint run gives up.
STALL_TIMEOUT = 5.0
_TURN_IN_PLACE = math.radians(45.0)
_K_TURN = 2.5


def waypoint_command(pose: ArrayLike, target: ArrayLike, robot: RobotConfig) -> tuple[float, float]:
    """Velocity command (v m/s, w rad/s) that drives from ``pose`` ``[3]`` towards ``target`` ``[2]`` (world frame)."""
    x, y, theta = (float(v) for v in np.asarray(pose, dtype=np.float64))
    tx, ty = (float(v) for v in np.asarray(target, dtype=np.float64))
    dist = math.hypot(tx - x, ty - y)
    err = math.remainder(math.atan2(ty - y, tx - x) - theta, 2.0 * math.pi)
    w = math.copysign(
        min(robot.max_angular_speed, _K_TURN * abs(err), math.sqrt(2.0 * robot.max_angular_accel * abs(err))), err
    )
    if abs(err) > _TURN_IN_PLACE:
        return 0.0, w
    v = min(robot.max_linear_speed, math.sqrt(2.0 * robot.max_linear_accel * dist)) * math.cos(err)
    return v, w


def simulate_waypoints(
    world: World,
    waypoints: ArrayLike,
    config: SimConfig | None = None,
    *,
    seed: int | np.random.Generator,
    max_time: float = 3600.0,
    tolerance: float = 0.2,
) -> RunRecord:
    """Drive through ``waypoints`` in order and record every frame.

    Parameters
    ----------
    world:
        The world; the robot starts at ``world.start``.
    waypoints:
        float ``[N, 2]`` waypoint positions (m, world frame).
    config:
        Simulation settings; ``None`` means ``SimConfig()``: the default error profile, ``realistic``
        (:meth:`SimConfig.paper` for the paper's set-up).
    seed:
        Seed (or Generator) of the run's random stream (odometry bias, optional noise).
    max_time:
        Largest simulated duration (s).
    tolerance:
        Distance (m) at which a waypoint counts as reached.

    Returns
    -------
    RunRecord
        Frames from t = 0 to the end; ``metadata`` holds ``outcome`` (``"completed"``, ``"timeout"``
        or ``"stalled"``), ``waypoints_reached``, ``waypoints``, ``seed`` (``None`` when a Generator
        was given), the drawn ``bias``, the world name and the full simulation config.
    """
    points = np.asarray(waypoints, dtype=np.float64)
    if points.size == 0:
        points = points.reshape(0, 2)
    if points.ndim != 2 or points.shape[1] != 2 or not np.all(np.isfinite(points)):
        raise SimulationError(f"waypoints must be a finite [N, 2] array of (x, y) in metres, got shape {points.shape}")
    if not (math.isfinite(max_time) and max_time >= 0.0):
        raise SimulationError(f"max_time must be a non-negative number of seconds, got {max_time!r}")
    if not (math.isfinite(tolerance) and tolerance > 0.0):
        raise SimulationError(f"tolerance must be a positive distance in metres, got {tolerance!r}")
    recorded_seed = int(seed) if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) else None
    sim = Simulator(world, config, as_generator(seed))
    robot = sim.config.robot
    dt = sim.config.dt
    max_steps = int(math.floor(max_time / dt + 1e-9))
    frames: list[Frame] = [sim.observe()]
    reached = 0
    stalled_steps = 0
    stall_limit = int(math.floor(STALL_TIMEOUT / dt + 1e-9))
    outcome = "completed"
    while True:
        truth = sim.truth
        while reached < len(points) and math.hypot(*(points[reached] - truth[:2])) < tolerance:
            reached += 1
        if reached == len(points):
            outcome = "completed"
            break
        if sim.steps >= max_steps:
            outcome = "timeout"
            break
        frame = sim.step(waypoint_command(truth, points[reached], robot))
        frames.append(frame)
        stalled_steps = stalled_steps + 1 if frame.stalled else 0
        if stalled_steps > stall_limit:
            outcome = "stalled"
            break
    metadata = {
        **sim.metadata,
        "controller": "waypoints",
        "seed": recorded_seed,
        "outcome": outcome,
        "waypoints_reached": reached,
        "waypoints": points.tolist(),
        "max_time": float(max_time),
        "tolerance": float(tolerance),
    }
    return RunRecord.from_frames(frames, sim.laser, metadata)
