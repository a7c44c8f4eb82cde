"""The frontier explorer: one velocity command per control period, from the SLAM pose, scan and map.

Each call of :meth:`Explorer.command` runs, in this order:

1. a manoeuvre under way (the initial full turn, a look-around turn, a recovery) gives the command;
2. stuck or blocked (:mod:`slamtrials.explore.recovery`): start a recovery; after
   ``max_recoveries_per_goal`` recoveries on the way to one goal, blacklist the goal;
3. goal bookkeeping: a goal within ``goal_tolerance`` is reached (and remembered, so its frontier
   cells are skipped from now on: a frontier still there once the robot stands on it cannot be seen
   from there); a goal whose remaining path length did not shrink by ``progress_distance`` for
   ``goal_timeout`` is blacklisted; a goal that no longer borders unknown space triggers a replan;
4. planning, every ``replan_period`` and on the events above (at most every ``min_replan_interval``):
   crop the map to its known part, build the costmap and the frontiers, and run Dijkstra from the
   robot to the closest frontier cell by path cost, skipping cells near failed or reached goals and
   keeping the current goal unless another is clearly cheaper (``goal_hysteresis``);
5. the path follower gives the command.

When no frontier is left the explorer first clears the failed-goal blacklist (up to
``blacklist_resets`` times), then turns a full circle where it stands (once per place), and then is
done (``reason == "no_frontiers"``).

The costmap and frontiers are cached per map object: if the caller passes the same map object again
(because its SLAM map was not updated), replanning only reruns Dijkstra. Everything is deterministic.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials.explore.config import ExploreConfig
from slamtrials.explore.costmap import PASSABLE, Costmap, build_costmap
from slamtrials.explore.follower import PathFollower
from slamtrials.explore.frontiers import Frontiers, find_frontiers
from slamtrials.explore.goals import GoalRecord, exclude_discs
from slamtrials.explore.gridframe import FREE_BELOW, GridFrame, map_arrays
from slamtrials.explore.planner import dijkstra
from slamtrials.explore.recovery import Recovery, StuckMonitor, segment_clear

__all__ = ["Explorer", "ExploreStats", "crop_known"]

_CROP_MARGIN = 2  # unknown cells kept around the known part of the map
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
    plan_seconds:
        Wall-clock seconds spent planning (costmaps, frontiers, Dijkstra).
    """

    replans: int = 0
    goals_reached: int = 0
    goals_blacklisted: int = 0
    recoveries: int = 0
    blacklist_resets: int = 0
    look_arounds: int = 0
    plan_seconds: float = 0.0


@dataclass(frozen=True, eq=False)
class _Prepared:
    """Costmap and frontiers of the known part of one map."""

    frame: GridFrame  # of the cropped window
    costmap: Costmap
    frontiers: Frontiers


def crop_known(grid: NDArray[np.int8], margin: int = _CROP_MARGIN) -> tuple[NDArray[np.int8], int, int] | None:
    """The bounding box of the known cells of ``grid`` plus ``margin`` unknown cells all round.

    Returns ``(window int8 [h, w], row0, col0)`` with ``(row0, col0)`` the grid cell of the window's
    top-left cell (negative when the margin sticks out of the grid), or ``None`` if no cell is known.
    """
    known = grid >= 0
    rows = np.flatnonzero(known.any(axis=1))
    if rows.size == 0:
        return None
    cols = np.flatnonzero(known.any(axis=0))
    r0, r1 = int(rows[0]) - margin, int(rows[-1]) + 1 + margin
    c0, c1 = int(cols[0]) - margin, int(cols[-1]) + 1 + margin
    window = np.full((r1 - r0, c1 - c0), -1, dtype=np.int8)
    sr0, sr1 = max(r0, 0), min(r1, grid.shape[0])
    sc0, sc1 = max(c0, 0), min(c1, grid.shape[1])
    window[sr0 - r0:sr1 - r0, sc0 - c0:sc1 - c0] = grid[sr0:sr1, sc0:sc1]
    return window, r0, c0


class Explorer:
    """Frontier exploration on an online occupancy map (see the module docstring).

    Parameters
    ----------
    config:
        Explorer settings; ``None`` means the defaults.

    Examples
    --------
    >>> explorer = Explorer()                                             # doctest: +SKIP
    >>> v, w = explorer.command(frame.t, pose, frame.ranges, laser, slam.occupancy())   # doctest: +SKIP
    >>> explorer.done, explorer.reason                                    # doctest: +SKIP
    """

    def __init__(self, config: ExploreConfig | None = None):
        self.config = ExploreConfig() if config is None else config
        self._follower = PathFollower(self.config)
        self._monitor = StuckMonitor(self.config)
        self._recovery = Recovery(self.config)
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
        self._blocked_since: float | None = None
        self._prepared_for: Any = None
        self._prepared: _Prepared | None = None
        self._checked_for: Any = None
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

    def command(self, t: float, pose: ArrayLike, ranges: ArrayLike, laser: dict[str, Any], occupancy: Any) -> tuple[float, float]:
        """The velocity command ``(v m/s, w rad/s)`` for the next control period.

        Parameters
        ----------
        t:
            Time (s), non-decreasing from call to call.
        pose:
            float64 ``[3]`` the robot base's pose estimate (x, y, theta) in the map frame.
        ranges:
            float32 ``[B]`` the current laser scan (m).
        laser:
            Laser geometry: ``angle_min``, ``angle_increment`` (rad), ``range_min``, ``range_max`` (m),
            ``mount`` (laser pose in the base frame).
        occupancy:
            The current map: an object with ``grid`` (int8 ``[H, W]``, 100 occupied, 0 free, -1
            unknown, row 0 at the top), ``resolution`` (m) and ``origin`` (float64 ``[3]``, the map-frame
            pose of the lower-left corner of cell ``(H - 1, 0)``).
        """
        v, w = self._decide(float(t), np.asarray(pose, dtype=np.float64), ranges, laser, occupancy)
        self._follower.remember(v, w)
        self._stuck = self._monitor.update(float(t), pose, v, self.config.control_period)
        return v, w

    def _decide(self, t: float, pose: NDArray[np.float64], ranges: ArrayLike, laser: dict[str, Any],
                occupancy: Any) -> tuple[float, float]:
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
        if self._stuck or blocked_long:
            return self._start_recovery(t, pose, ranges, laser, occupancy)
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
                if not _borders_unknown(occupancy, self._goal.xy):
                    self._want_plan = True
        # 4. planning
        since = t - self._last_plan
        if since >= cfg.replan_period or (self._want_plan and since >= cfg.min_replan_interval) or (
                self._goal is None and since >= cfg.min_replan_interval):
            self._plan(t, pose, occupancy)
            if self._done:
                return 0.0, 0.0
            if self._spin_until is not None:
                return 0.0, self._spin_rate
        # 5. follow
        if not self._follower.has_path:
            self._blocked_since = None
            return 0.0, 0.0
        out = self._follower.command(pose, ranges, laser)
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
        cfg = self.config
        self._spin_rate = cfg.max_angular_speed
        self._spin_until = t + 2.0 * math.pi / cfg.max_angular_speed + cfg.max_angular_speed / cfg.max_angular_accel
        self._looked.append(pose[:2].copy())
        self.stats.look_arounds += 1
        self._follower.clear()

    def _start_recovery(self, t: float, pose: NDArray[np.float64], ranges: ArrayLike, laser: dict[str, Any],
                        occupancy: Any) -> tuple[float, float]:
        self.stats.recoveries += 1
        self._stuck = False
        self._blocked_since = None
        self._monitor.reset()
        if self._goal is not None:
            self._goal.recoveries += 1
            if self._goal.recoveries >= self.config.max_recoveries_per_goal:
                self._give_up_goal()
        self._follower.clear()
        cfg = self.config
        behind = pose[:2] - (cfg.backoff_distance + 0.05) * np.array([math.cos(pose[2]), math.sin(pose[2])])
        self._recovery.start(t, ranges, laser, back_off=segment_clear(occupancy, pose[:2], behind, cfg.robot_radius))
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

    def _prepare(self, occupancy: Any) -> _Prepared | None:
        if occupancy is self._prepared_for and self._prepared is not None:
            return self._prepared
        cfg = self.config
        grid, resolution, _ = map_arrays(occupancy)
        cropped = crop_known(grid)
        if cropped is None:
            return None
        window, r0, c0 = cropped
        frame = GridFrame.of(occupancy).sub(r0, c0, window.shape[0], window.shape[1])
        costmap = build_costmap(window, resolution, cfg)
        frontiers = find_frontiers(window, min_cells=max(1, int(math.ceil(cfg.min_frontier_length / resolution - 1e-9))),
                                   min_unknown_cells=int(math.ceil(cfg.min_unknown_area / resolution**2 - 1e-9)))
        self._prepared_for = occupancy
        self._prepared = _Prepared(frame, costmap, frontiers)
        return self._prepared

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
        prepared = self._prepare(occupancy)
        if prepared is None:
            self._nothing_found(t, pose, any_frontier=True)
            return
        frame, costmap = prepared.frame, prepared.costmap
        row, col = (int(v) for v in frame.to_cell(pose[:2]))
        if not frame.inside(row, col):
            self._nothing_found(t, pose, any_frontier=True)
            return
        base = prepared.frontiers.mask & (costmap.kind == PASSABLE)
        candidates = base.copy()
        exclude_discs(candidates, frame, self._visited, cfg.blacklist_radius)
        open_candidates = candidates.copy()
        exclude_discs(candidates, frame, self._blacklist, cfg.blacklist_radius)
        keep = None
        if self._goal is not None:
            near = candidates.copy()
            exclude_discs(near, frame, [self._goal.xy], cfg.blacklist_radius)
            keep = candidates & ~near
        escape = cfg.escape_radius / frame.resolution
        result = dijkstra(costmap.cost, costmap.kind, (row, col), goal=candidates, keep=keep, ratio=cfg.goal_hysteresis,
                          escape_radius=escape, escape_cost=cfg.escape_cost)
        if result.goal is None:
            if self._blacklist and self._resets_left > 0 and open_candidates.any():
                reachable = dijkstra(costmap.cost, costmap.kind, (row, col), goal=open_candidates,
                                     escape_radius=escape, escape_cost=cfg.escape_cost)
                if reachable.goal is not None:
                    self._resets_left -= 1
                    self._blacklist.clear()
                    self.stats.blacklist_resets += 1
                    result = reachable
            if result.goal is None:
                self._nothing_found(t, pose, any_frontier=False)
                return
        cells = result.path_to(*result.goal)
        path = frame.to_xy(cells[:, 0], cells[:, 1])
        path[0] = pose[:2]
        goal_xy = path[-1].copy()
        length = float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0
        if self._goal is not None and (result.kept or math.dist(goal_xy, self._goal.xy) <= cfg.blacklist_radius):
            self._goal.xy = goal_xy
            self._goal.rerouted(t, length, _REROUTE_SLACK)
        else:
            self._goal = GoalRecord(xy=goal_xy, since=t, best=length, last_progress=t)
        self._follower.set_path(path)

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


def _borders_unknown(occupancy: Any, xy: NDArray[np.float64], reach: int = 2) -> bool:
    """Whether a free cell within ``reach`` cells of map-frame point ``xy`` has an unknown 4-neighbour."""
    grid, _, _ = map_arrays(occupancy)
    frame = GridFrame.of(occupancy)
    row, col = (int(v) for v in frame.to_cell(xy))
    r0, r1 = max(row - reach - 1, 0), min(row + reach + 2, grid.shape[0])
    c0, c1 = max(col - reach - 1, 0), min(col + reach + 2, grid.shape[1])
    if r0 >= r1 or c0 >= c1:
        return False
    patch = grid[r0:r1, c0:c1]
    unknown = patch < 0
    free = (patch >= 0) & (patch < FREE_BELOW)
    near = np.zeros_like(unknown)
    near[1:, :] |= unknown[:-1, :]
    near[:-1, :] |= unknown[1:, :]
    near[:, 1:] |= unknown[:, :-1]
    near[:, :-1] |= unknown[:, 1:]
    hits = free & near
    # only the cells within reach of the goal's cell count (the patch has one extra ring for neighbours)
    lo_r, lo_c = max(row - reach, 0) - r0, max(col - reach, 0) - c0
    hi_r, hi_c = min(row + reach + 1, grid.shape[0]) - r0, min(col + reach + 1, grid.shape[1]) - c0
    return bool(hits[lo_r:hi_r, lo_c:hi_c].any())
