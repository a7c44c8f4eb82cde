"""The simulator: a differential-drive robot with a 2-D laser and biased odometry in a floor plan.

``Simulator(world, SimConfig(), rng)`` gives one :class:`~slamtrials.record.Frame` (laser scan,
odometry, ground truth) per ``dt`` step; :func:`simulate_waypoints` drives a scripted route and returns
a :class:`~slamtrials.record.RunRecord`. The laser is an exact grid ray caster accelerated by a distance
field (:mod:`slamtrials.sim.raycast`), the odometry error is the paper's per-run scale bias
(:mod:`slamtrials.sim.odometry`), collisions use the robot's disc footprint (:mod:`slamtrials.sim.robot`).
"""

from slamtrials.sim.config import LaserConfig, OdometryConfig, RobotConfig, SimConfig
from slamtrials.sim.simulator import Simulator
from slamtrials.sim.waypoints import simulate_waypoints

__all__ = ["Simulator", "SimConfig", "RobotConfig", "LaserConfig", "OdometryConfig", "simulate_waypoints"]
