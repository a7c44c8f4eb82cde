"""Autonomous frontier exploration on an online SLAM map, and the paper's termination rule.

:class:`Explorer` turns the SLAM pose, the laser scan and the SLAM map into velocity commands: it finds
frontiers (:mod:`.frontiers`), plans to the closest one by path cost over an inflated costmap
(:mod:`.costmap`, :mod:`.planner`, :mod:`.goalsearch`), follows the path with pure pursuit while
watching the scan (:mod:`.follower`), and gets itself unstuck (:mod:`.recovery`). :class:`SnapshotTermination` stops a
run when two consecutive map snapshots barely differ (:mod:`.termination`).

Maps are duck typed: any object with ``grid`` (int8 ``[H, W]``, 100 occupied, 0 free, -1 unknown,
row 0 at the top), ``resolution`` (m) and ``origin`` (float64 ``[3]``, map-frame pose of the
lower-left corner of the lower-left cell), such as :class:`slamtrials.slam.OccupancyGrid`.
"""

from slamtrials.explore.config import ExploreConfig, RobotLimits, TerminationConfig
from slamtrials.explore.costmap import Costmap, build_costmap
from slamtrials.explore.explorer import Explorer, ExploreStats
from slamtrials.explore.follower import FollowCommand, PathFollower
from slamtrials.explore.frontiers import Frontiers, find_frontiers
from slamtrials.explore.gridframe import GridFrame
from slamtrials.explore.planner import PlanResult, dijkstra
from slamtrials.explore.termination import SnapshotTermination, snapshot_mse

__all__ = [
    "Costmap",
    "ExploreConfig",
    "RobotLimits",
    "ExploreStats",
    "Explorer",
    "FollowCommand",
    "Frontiers",
    "GridFrame",
    "PathFollower",
    "PlanResult",
    "SnapshotTermination",
    "TerminationConfig",
    "build_costmap",
    "dijkstra",
    "find_frontiers",
    "snapshot_mse",
]
