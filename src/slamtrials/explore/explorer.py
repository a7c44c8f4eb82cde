"""The frontier explorer: one velocity command per control period, from the SLAM pose, scan and map.

Each call of :meth:`Explorer.command` first filters the scan and corrects the map: returns inside the
robot's disc are dropped; the rest go into the evidence layer (:mod:`slamtrials.explore.evidence`),
which corrects each new SLAM map once (free space that no return vouches for made unknown, gaps that
beams without a return wore into walls closed) and the explorer plans on that map; for the reactive
checks below, returns within ``scan_filter_range`` must be confirmed by neighbouring beams and by the
previous scans (:mod:`slamtrials.explore.scanfilter`). Then, in this order:

1. a manoeuvre under way (the initial full turn, a look-around turn, a recovery) gives the command;
2. stuck, idle, bumped or blocked (:mod:`slamtrials.explore.recovery`): start a recovery; after
   ``max_recoveries_per_goal`` recoveries on the way to one goal, blacklist the goal. A robot held still
   by returns the map does not show (a thing standing in its way) keeps them as obstacles to plan
   around until its own scans show them gone (:mod:`slamtrials.explore.transient`), and that recovery
   does not count against the goal; when they leave no frontier reachable, they are forgotten (the
   way is tried again) before anything else is given up;
3. goal bookkeeping: a goal within ``goal_tolerance`` is reached (and remembered, so its frontier
   cells are skipped from now on: a frontier still there once the robot stands on it cannot be seen
   from there); a goal whose remaining path length did not shrink by ``progress_distance`` for
   ``goal_timeout`` is blacklisted; a goal whose frontier no longer borders unknown space triggers a
   replan;
4. planning (:mod:`slamtrials.explore.goalsearch`), every ``replan_period`` and on the events above (at
   most every ``min_replan_interval``): first in a window around the robot (``local_radius`` plus a
   rim where obstacles still change costs): a goal that Dijkstra settles before reaching the window's
   edge is the closest in the whole map too. Otherwise, if the robot is heading for a goal beyond the
   window and its path is still clear, it keeps going (searching the whole map every
   ``global_replan_period``); else the whole known map is searched, first on a copy with cells
   ``global_coarsening`` times larger (four times cheaper for a factor of 2), then, if that finds
   nothing, at full resolution. The cost of a step thus stays about the same however large the
   building;
5. the path follower (:mod:`slamtrials.explore.follower`) gives the command.

When no reachable frontier is left and the robot can reach less than ``shut_in_share`` of the map's
passable cells, the explorer plans again with the lethal zone shrunk to ``robot_radius +
relaxed_margin`` (frontiers in the open behind a passage that only looks too narrow, e.g. the way out
of a room whose door the robot went through before the door frame was mapped), then,
if ``view_distance`` > 0, heads for view points of the frontiers it cannot reach (each looked at once).
When none is left either, it clears the failed-goal blacklist (up to ``blacklist_resets`` times), then
turns a full circle where it stands (once per place), and then is done (``reason == "no_frontiers"``).

Everything is deterministic: the same calls give the same commands.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials import stablemath
from slamtrials.explore.config import ExploreConfig, RobotLimits
from slamtrials.explore.costmap import influence_distance
from slamtrials.explore.evidence import EvidenceLayer
from slamtrials.explore.follower import PathFollower
from slamtrials.explore.frontiers import frontier_near
from slamtrials.explore.goals import GoalRecord
from slamtrials.explore.goalsearch import Found, GoalSearch
from slamtrials.explore.gridframe import GridFrame, map_arrays
from slamtrials.explore.recovery import Recovery, StuckMonitor
from slamtrials.explore.scanfilter import ScanMemory, confirmed_ranges, inside_footprint
from slamtrials.explore.transient import TransientObstacles
from slamtrials.record import LaserGeometry

__all__ = ["ExploreStats", "Explorer"]

_LOOK_SPACING = 1.0  # m: a look-around turn is done at most once within this distance
_REROUTE_SLACK = 1.0  # m: a new path this much longer than the best restarts the goal's progress count


@dataclass
class ExploreStats:
    """Counters for diagnostics.

    Attributes
    ----------
    replans:
        Plans computed.
    goals_reached, goals_blacklisted:
        Goals reached; goals given up (no progress, or too many recoveries).
    recoveries:
        Recovery manoeuvres started.
    blacklist_resets:
        Times the blacklist was cleared because nothing else was left.
    look_arounds:
        Full turns made (the initial one included).
    backing_outs:
        Times the robot backed out along its path instead of turning round
        (:mod:`slamtrials.explore.follower`).
    transient_obstacles:
        Returns taken for obstacles the map does not show (:mod:`slamtrials.explore.transient`).
    plan_seconds:
        Wall-clock seconds spent planning (costmaps, frontiers, Dijkstra).
    """

    replans: int = 0
    goals_reached: int = 0
    goals_blacklisted: int = 0
    recoveries: int = 0
    blacklist_resets: int = 0
    look_arounds: int = 0
    backing_outs: int = 0
    transient_obstacles: int = 0
    plan_seconds: float = 0.0


class Explorer:
    """Frontier exploration on an online occupancy map (see the module docstring).

    Parameters
    ----------
    config:
        Explorer settings; ``None`` means the defaults.
    robot:
        The robot's footprint, motion limits and control period; ``None`` means the paper's robot.

    Examples
    --------
    >>> explorer = Explorer()                                             # doctest: +SKIP
    >>> v, w = explorer.command(frame.t, pose, frame.ranges, laser, slam.occupancy())   # doctest: +SKIP
    >>> explorer.done, explorer.reason                                    # doctest: +SKIP
    """

    def __init__(self, config: ExploreConfig | None = None, robot: RobotLimits | None = None):
        self.config = ExploreConfig() if config is None else config
        self.robot = RobotLimits() if robot is None else robot
        self._search = GoalSearch(self.config, self.robot)
        self._follower = PathFollower(self.config, self.robot)
        self._monitor = StuckMonitor(self.config)
        self._recovery = Recovery(self.config, self.robot)
        cfg = self.config
        step = self.robot.max_linear_speed * self.robot.control_period
        self._memory = ScanMemory(cfg.scan_filter_distance, cfg.scan_filter_range, cfg.scan_filter_scans, step)
        self._evidence = EvidenceLayer(
            cfg.evidence_min_hits, cfg.evidence_occupied_ratio, cfg.evidence_free_distance, cfg.evidence_no_return_range
        )
        self._transient = TransientObstacles(cfg.transient_reach, cfg.transient_lifetime)
        self.reset()

    # --- state -------------------------------------------------------------------------------------------

    def reset(self) -> None:
        """Forget everything: goals, blacklist, map cache, counters."""
        self.stats = ExploreStats()
        self._done = False
        self._reason: str | None = None
        self._goal: GoalRecord | None = None
        self._blacklist: list[NDArray[np.float64]] = []
        self._visited: list[NDArray[np.float64]] = []
        self._looked: list[NDArray[np.float64]] = []
        self._resets_left = self.config.blacklist_resets
        self._started = False
        self._spin_until: float | None = None
        self._spin_rate = 0.0
        self._last_plan = -math.inf
        self._want_plan = True
        self._stuck = False
        self._stalls = 0
        self._following = False
        self._blocked_since: float | None = None
        self._last_global = -math.inf
        self._checked_for: Any = None
        self._view_of: Any = None
        self._view: Any = None
        self._evidence.reset()
        self._transient.reset()
        self._stamped_for: Any = None
        self._stamped: Any = None
        self._traced_at: NDArray[np.float64] | None = None
        self._memory.reset()
        self._search.reset()
        self._follower.reset()
        self._monitor.reset()
        self._recovery.reset()

    @property
    def done(self) -> bool:
        """True once exploration is over (no reachable frontier left)."""
        return self._done

    @property
    def reason(self) -> str | None:
        """Why exploration is over (``"no_frontiers"``), or ``None`` while it goes on."""
        return self._reason

    @property
    def goal(self) -> NDArray[np.float64] | None:
        """float64 ``[2]`` the current goal (map frame, m), or ``None``."""
        return None if self._goal is None else self._goal.xy.copy()

    @property
    def path(self) -> NDArray[np.float64]:
        """float64 ``[N, 2]`` the path being followed (map frame, m); empty if none."""
        return self._follower.path.copy()

    @property
    def blacklist(self) -> list[NDArray[np.float64]]:
        """Failed goals (map frame, m)."""
        return [p.copy() for p in self._blacklist]

    @property
    def mode(self) -> str:
        """What the robot is doing: ``"done"``, ``"turning"``, ``"recovering"``, ``"following"`` or ``"waiting"``."""
        if self._done:
            return "done"
        if self._spin_until is not None:
            return "turning"
        if self._recovery.active:
            return "recovering"
        return "following" if self._follower.has_path else "waiting"

    # --- the control step --------------------------------------------------------------------------------

    def command(
        self,
        t: float,
        pose: ArrayLike,
        ranges: ArrayLike,
        laser: LaserGeometry,
        occupancy: Any,
        *,
        stalled: bool = False,
    ) -> tuple[float, float]:
        """The velocity command ``(v m/s, w rad/s)`` for the next control period.

        Parameters
        ----------
        t:
            Time (s), non-decreasing from call to call.
        pose:
            float64 ``[3]`` the robot base's pose estimate (x, y, theta) in the map frame.
        ranges:
            float32 ``[B]`` the current laser scan (m), as the laser gives it (the explorer filters it).
        laser:
            The laser's geometry (beam angles, valid ranges, pose in the base frame).
        occupancy:
            The current map: an object with ``grid`` (int8 ``[H, W]``, 100 occupied, 0 free, -1
            unknown, row 0 at the top), ``resolution`` (m) and ``origin`` (float64 ``[3]``, the map-frame
            pose of the lower-left corner of cell ``(H - 1, 0)``).
        stalled:
            Whether the robot bumped into something during the last step (the simulator's
            :attr:`~slamtrials.record.Frame.stalled`, Stage's stall flag), if the caller knows. After
            ``stall_steps`` such steps in a row while following a path, the robot recovers at once
            instead of waiting for the stuck test.
        """
        self._stalls = self._stalls + 1 if stalled else 0
        self._following = False
        pose_array = np.asarray(pose, dtype=np.float64)
        cfg = self.config
        if cfg.scan_filter_window > 0:
            ranges = inside_footprint(ranges, laser, self.robot.radius)
        if cfg.evidence_layer:  # every return: a stray one marks no wall (evidence_min_hits, evidence_occupied_ratio)
            last = self._traced_at
            if (
                last is None
                or math.hypot(pose_array[0] - last[0], pose_array[1] - last[1]) >= cfg.evidence_linear_step
                or abs(math.remainder(pose_array[2] - last[2], 2.0 * math.pi)) >= cfg.evidence_angular_step
            ):
                self._evidence.add_scan(pose_array, ranges, laser, float(occupancy.resolution))
                self._traced_at = pose_array[:3].copy()
            occupancy = self._corrected(occupancy)
        if cfg.scan_filter_window > 0:
            ranges = confirmed_ranges(
                ranges, laser, cfg.scan_filter_window, cfg.scan_filter_distance, cfg.scan_filter_range
            )
            ranges = self._memory.persistent(ranges, pose_array, laser)
        if len(self._transient):
            self._transient.forget_seen(float(t), pose_array, ranges, laser)
            occupancy = self._stamped_view(occupancy)
        v, w = self._decide(float(t), pose_array, ranges, laser, occupancy)
        self._follower.remember(v, w)
        self._stuck = self._monitor.update(float(t), pose_array, v, self.robot.control_period, self._following)
        return v, w

    def _corrected(self, occupancy: Any) -> Any:
        """The map the explorer plans on: ``occupancy`` corrected by the evidence layer, computed once
        per map object (the SLAM algorithm publishes a new one every few seconds), so the costmaps and
        frontiers cached per map object stay valid in between."""
        if occupancy is not self._view_of:
            self._view_of = occupancy
            self._view = self._evidence.view(occupancy)
        return self._view

    def _stamped_view(self, occupancy: Any) -> Any:
        """``occupancy`` with the transient obstacles marked, computed once per map object and set of
        obstacles (so the costmaps cached per map object stay valid in between)."""
        key = (id(occupancy), self._transient.version)
        if self._stamped_for != key or self._stamped is None:
            self._stamped_for = key
            self._stamped = (occupancy, self._transient.stamp(occupancy))
        return self._stamped[1]

    def _decide(
        self, t: float, pose: NDArray[np.float64], ranges: ArrayLike, laser: LaserGeometry, occupancy: Any
    ) -> tuple[float, float]:
        cfg = self.config
        if self._done:
            return 0.0, 0.0
        if not self._started:
            self._started = True
            if cfg.initial_spin:
                self._start_spin(t, pose)
        # 1. manoeuvres under way
        if self._spin_until is not None:
            if t < self._spin_until - 1e-9:
                return 0.0, self._spin_rate
            self._spin_until = None
            self._want_plan = True
        if self._recovery.active:
            cmd = self._recovery.command(t)
            if cmd is not None:
                return cmd
            self._monitor.reset()
            self._want_plan = True
        # 2. stuck or blocked
        blocked_long = self._blocked_since is not None and t - self._blocked_since >= cfg.blocked_time
        bumped = self._stalls >= cfg.stall_steps and self._follower.has_path
        if self._stuck or blocked_long or bumped:
            return self._start_recovery(t, pose, ranges, laser, occupancy, blocked=blocked_long and not bumped)
        # 3. goal bookkeeping
        if self._goal is not None:
            dist = math.hypot(pose[0] - self._goal.xy[0], pose[1] - self._goal.xy[1])
            if dist < cfg.goal_tolerance:
                self._visited.append(self._goal.xy.copy())
                self.stats.goals_reached += 1
                self._drop_goal()
            elif t - self._goal.last_progress > cfg.goal_timeout:
                self._give_up_goal()
            elif occupancy is not self._checked_for:
                self._checked_for = occupancy
                grid, _, _ = map_arrays(occupancy)
                row, col = (int(v) for v in GridFrame.of(occupancy).to_cell(self._goal.target))
                if not frontier_near(grid, row, col):
                    self._want_plan = True
        # 4. planning
        since = t - self._last_plan
        if (
            since >= cfg.replan_period
            or (self._want_plan and since >= cfg.min_replan_interval)
            or (self._goal is None and since >= cfg.min_replan_interval)
        ):
            self._plan(t, pose, occupancy)
            if self._done:
                return 0.0, 0.0
            if self._spin_until is not None:
                return 0.0, self._spin_rate
        # 5. follow
        if not self._follower.has_path:
            self._blocked_since = None
            return 0.0, 0.0
        backing = self._follower.backing
        out = self._follower.command(pose, ranges, laser)
        self.stats.backing_outs += int(self._follower.backing and not backing)
        self._following = True
        if out.blocked:
            if self._blocked_since is None:
                self._blocked_since = t
        else:
            self._blocked_since = None
        if self._goal is not None:
            self._goal.update(t, self._follower.remaining(pose), cfg.progress_distance)
        return out.v, out.w

    # --- manoeuvres ----------------------------------------------------------------------------------------

    def _start_spin(self, t: float, pose: NDArray[np.float64]) -> None:
        robot = self.robot
        self._spin_rate = robot.max_angular_speed
        self._spin_until = (
            t + 2.0 * math.pi / robot.max_angular_speed + robot.max_angular_speed / robot.max_angular_accel
        )
        self._looked.append(pose[:2].copy())
        self.stats.look_arounds += 1
        self._follower.clear()

    def _start_recovery(
        self,
        t: float,
        pose: NDArray[np.float64],
        ranges: ArrayLike,
        laser: LaserGeometry,
        occupancy: Any,
        *,
        blocked: bool = False,
    ) -> tuple[float, float]:
        self.stats.recoveries += 1
        self._stuck = False
        self._stalls = 0
        self._blocked_since = None
        self._monitor.reset()
        unmapped = 0
        if blocked and self.config.transient_reach > 0.0:
            unmapped = self._transient.add(t, pose, ranges, laser, self.robot.radius, occupancy)
        if unmapped:
            # held by something the map does not show: plan around it; the goal is not at fault
            self.stats.transient_obstacles += unmapped
            self._want_plan = True
        elif self._goal is not None:
            self._goal.recoveries += 1
            if self._goal.recoveries >= self.config.max_recoveries_per_goal:
                self._give_up_goal()
        self._follower.reset()
        self._recovery.start(t, pose, ranges, laser, occupancy)
        cmd = self._recovery.command(t)
        return (0.0, 0.0) if cmd is None else cmd

    def _drop_goal(self) -> None:
        self._goal = None
        self._follower.clear()
        self._want_plan = True

    def _give_up_goal(self) -> None:
        assert self._goal is not None
        self._blacklist.append(self._goal.xy.copy())
        self.stats.goals_blacklisted += 1
        self._drop_goal()

    # --- planning ------------------------------------------------------------------------------------------

    def _plan(self, t: float, pose: NDArray[np.float64], occupancy: Any) -> None:
        started = time.perf_counter()
        try:
            self._plan_inner(t, pose, occupancy)
        finally:
            self.stats.plan_seconds += time.perf_counter() - started

    def _plan_inner(self, t: float, pose: NDArray[np.float64], occupancy: Any) -> None:
        cfg = self.config
        self._last_plan = t
        self._want_plan = False
        self.stats.replans += 1
        grid, resolution, _ = map_arrays(occupancy)
        whole = self._search.known_box(occupancy, grid)
        if whole is None:
            self._nothing_found(t, pose, any_frontier=True)
            return
        row, col = (int(v) for v in GridFrame.of(occupancy).to_cell(pose[:2]))
        half = math.ceil(cfg.local_radius / resolution)
        rim = math.ceil(influence_distance(cfg, self.robot, resolution) / resolution) + 1
        local = (row - half - rim, row + half + rim + 1, col - half - rim, col + half + rim + 1)
        if local[0] <= whole[0] and local[1] >= whole[1] and local[2] <= whole[2] and local[3] >= whole[3]:
            outcome = self._try(t, pose, occupancy, grid, whole, None)  # the window holds the whole map
        else:
            inner = (rim, local[1] - local[0] - rim, rim, local[3] - local[2] - rim)
            outcome = self._try(t, pose, occupancy, grid, local, inner)
            if outcome == "edge":
                if t - self._last_global < cfg.global_replan_period and self._can_keep_goal(pose):
                    return  # keep heading for the far goal
                if cfg.global_coarsening > 1:
                    outcome = self._try(t, pose, occupancy, grid, whole, None, coarse=cfg.global_coarsening)
                if outcome != "goal":
                    outcome = self._try(t, pose, occupancy, grid, whole, None)
        if outcome == "none":
            outcome = self._last_resorts(t, pose, occupancy, grid, whole)
        if outcome in ("none", "lost") and len(self._transient):
            # the obstacles the map does not show may be all that is in the way: plan without them
            self._transient.reset()
            self._goal = None
            self._follower.clear()
            self._want_plan = True
            return
        if outcome == "none" and self._blacklist and self._resets_left > 0:
            self._resets_left -= 1
            self._blacklist.clear()
            self.stats.blacklist_resets += 1
            outcome = self._try(t, pose, occupancy, grid, whole, None)
            if outcome == "none":
                outcome = self._last_resorts(t, pose, occupancy, grid, whole)
        if outcome in ("none", "lost"):
            self._nothing_found(t, pose, any_frontier=outcome == "lost")

    def _last_resorts(
        self,
        t: float,
        pose: NDArray[np.float64],
        occupancy: Any,
        grid: NDArray[np.int8],
        box: tuple[int, int, int, int],
    ) -> str:
        """No frontier is reachable: try narrow passages (the relaxed costmap), then view points."""
        cfg = self.config
        outcome = "none"
        if cfg.relaxed_margin < cfg.inflation_margin and self._search.reachable_share < cfg.shut_in_share:
            outcome = self._try(t, pose, occupancy, grid, box, None, relaxed=True)
        if outcome == "none" and self.config.view_distance > 0.0:
            outcome = self._try(t, pose, occupancy, grid, box, None, views=True)
        return outcome

    def _try(
        self,
        t: float,
        pose: NDArray[np.float64],
        occupancy: Any,
        grid: NDArray[np.int8],
        box: tuple[int, int, int, int],
        inner: tuple[int, int, int, int] | None,
        *,
        views: bool = False,
        relaxed: bool = False,
        coarse: int = 1,
    ) -> str:
        """One goal search (:meth:`GoalSearch.search`); take its goal. Returns ``"goal"``, ``"edge"``,
        ``"none"`` or ``"lost"``."""
        if inner is None:
            self._last_global = t
        outcome, found = self._search.search(
            pose,
            occupancy,
            grid,
            box,
            inner,
            visited=self._visited,
            blacklist=self._blacklist,
            current=None if self._goal is None else self._goal.xy,
            views=views,
            relaxed=relaxed,
            coarse=coarse,
        )
        if outcome == "undecided" and self._can_keep_goal(pose):
            return "goal"  # the current goal beyond the window may still be the better one
        if found is None:
            return outcome
        self._take(t, found)
        return "goal"

    def _take(self, t: float, found: Found) -> None:
        """Make ``found`` the goal and follow its path."""
        path = found.path
        step = np.diff(path, axis=0)
        length = float(stablemath.hypot(step[:, 0], step[:, 1]).sum()) if len(path) > 1 else 0.0
        goal_xy = found.goal.copy()
        if self._goal is not None and (found.kept or math.dist(goal_xy, self._goal.xy) <= self.config.blacklist_radius):
            self._goal.xy = goal_xy
            self._goal.target = found.target
            self._goal.rerouted(t, length, _REROUTE_SLACK)
        else:
            self._goal = GoalRecord(xy=goal_xy, target=found.target, since=t, best=length, last_progress=t)
        self._follower.set_path(path, found.clearance)

    def _can_keep_goal(self, pose: NDArray[np.float64]) -> bool:
        """Whether the robot can keep following its path to the current goal."""
        return self._goal is not None and self._follower.has_path and self._search.path_clear(self._follower.path, pose)

    def _nothing_found(self, t: float, pose: NDArray[np.float64], *, any_frontier: bool) -> None:
        """No goal: look around once here, else (with a map) finish."""
        self._goal = None
        self._follower.clear()
        if all(math.dist(pose[:2], p) > _LOOK_SPACING for p in self._looked):
            self._start_spin(t, pose)
            return
        if not any_frontier:
            self._done = True
            self._reason = "no_frontiers"
