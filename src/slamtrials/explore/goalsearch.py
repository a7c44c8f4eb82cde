"""Finding the next goal: costmap and frontiers of a window of the map, candidate cells, Dijkstra.

:class:`GoalSearch` holds what one search needs besides the explorer's state: the costmaps and
frontiers of the latest windows (cached per map object and window, so a caller who passes the same
map object again only pays for Dijkstra) and the relaxed configuration. :meth:`GoalSearch.search`
looks for the cheapest goal cell by path cost in one window:

* normal goals are passable frontier cells away from reached goals;
* with ``relaxed``, the costmap's lethal zone shrinks to ``robot_radius + relaxed_margin`` and the goals
  are frontier cells that are passable in the normal costmap too (frontier cells in the open behind a
  passage that only looks too narrow, not the many frontier bits close to walls); the explorer uses
  this only when the robot is shut in (:attr:`GoalSearch.reachable_share`);
* with ``views``, the goals are *view points*: passable cells within ``view_distance`` of frontier
  cells inside the lethal zone (frontiers the robot cannot reach, such as a room seen through a gap
  narrower than the robot) that were not yet looked at from a reached goal.

Cells near failed goals (the blacklist) are never goals. The search can keep the current goal unless
another is clearly cheaper (``goal_hysteresis``), and can be limited to the interior of a window (see
:func:`slamtrials.explore.planner.dijkstra`). With ``smooth_paths``, the path found is straightened
where that costs no more (:mod:`slamtrials.explore.smoothing`). With ``turn_penalty``, the turn the robot
needs to set off towards the closest goal counts as extra path length, and a goal ahead of it that is
cheaper by that count is taken instead: the robot does not turn round for a frontier barely closer
than the one it faces (every 0.25 rad of turning costs the SLAM algorithm an update).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from slamtrials import stablemath
from slamtrials.explore.config import ExploreConfig, RobotLimits
from slamtrials.explore.costmap import (
    OCCUPIED,
    PASSABLE,
    UNKNOWN,
    Costmap,
    build_costmap,
    squared_distance_transform,
)
from slamtrials.explore.frontiers import Frontiers, find_frontiers
from slamtrials.explore.goals import exclude_discs
from slamtrials.explore.gridframe import GridFrame
from slamtrials.explore.planner import UNREACHED, PlanResult, dijkstra
from slamtrials.explore.smoothing import resample_polyline, shortcut_path
from slamtrials.explore.window import coarsen, crop, known_box

__all__ = ["CROP_MARGIN", "Found", "GoalSearch", "Prepared"]

#: Unknown cells kept around the known part of the map.
CROP_MARGIN = 2

Box = tuple[int, int, int, int]


@dataclass(frozen=True, eq=False)
class Prepared:
    """Costmap and frontiers of one window of a map."""

    frame: GridFrame  # of the window
    costmap: Costmap
    frontiers: Frontiers


@dataclass(frozen=True, eq=False)
class Found:
    """A goal and the path to it.

    Attributes
    ----------
    path:
        float64 ``[N, 2]`` map-frame points (m) from the robot's cell centre to the goal cell's.
    clearance:
        float64 ``[N]`` the costmap's clearance (m) at each point.
    target:
        float64 ``[2]`` the frontier cell the goal is for (map frame, m): the goal itself, or the
        frontier cell a view point looks at.
    kept:
        The goal lies near the current goal (the current goal was kept).
    """

    path: NDArray[np.float64]
    clearance: NDArray[np.float64]
    target: NDArray[np.float64]
    kept: bool

    @property
    def goal(self) -> NDArray[np.float64]:
        """float64 ``[2]`` the goal point (map frame, m)."""
        return self.path[-1]


class GoalSearch:
    """Costmaps, frontiers and goal searches for the explorer (see the module docstring).

    Attributes
    ----------
    latest:
        The latest prepared window, or ``None``.
    reachable_share:
        After a whole-map search that found no goal: the share of the passable cells the robot can
        reach (small when it is shut in, e.g. by a door frame mapped after it went through).
    """

    def __init__(self, config: ExploreConfig, robot: RobotLimits | None = None):
        self.config = config
        self.robot = RobotLimits() if robot is None else robot
        self._relaxed = config.model_copy(update={"inflation_margin": config.relaxed_margin})
        self.reset()

    def reset(self) -> None:
        """Forget the cached windows."""
        self._cache: dict[tuple[bool, int], tuple[Box, Any, Prepared]] = {}  # (relaxed, coarse) -> (box, map, prepared)
        self._box_for: Any = None
        self._box: Box | None = None
        self.latest: Prepared | None = None
        self.reachable_share = 1.0

    def known_box(self, occupancy: Any, grid: NDArray[np.int8]) -> Box | None:
        """``(row0, row1, col0, col1)`` of the known cells plus a margin (cached per map object)."""
        if occupancy is not self._box_for:
            self._box_for = occupancy
            self._box = known_box(grid, CROP_MARGIN)
        return self._box

    def prepare(
        self, occupancy: Any, grid: NDArray[np.int8], box: Box, relaxed: bool = False, coarse: int = 1
    ) -> Prepared:
        """Costmap and frontiers of the window ``box`` of the map (cached per map object and window).

        ``relaxed`` uses ``relaxed_margin`` instead of ``inflation_margin``; ``coarse`` > 1 works on a
        copy of the window with cells ``coarse`` times larger (:func:`~slamtrials.explore.window.coarsen`).
        """
        key = (relaxed, coarse)
        cached = self._cache.get(key)
        if cached is not None and cached[0] == box and cached[1] is occupancy:
            return cached[2]
        cfg = self._relaxed if relaxed else self.config
        r0, r1, c0, c1 = box
        window = crop(grid, r0, r1, c0, c1)
        resolution = float(occupancy.resolution)
        frame = GridFrame.of(occupancy).sub(r0, c0, r1 - r0, c1 - c0)
        if coarse > 1:
            window = coarsen(window, coarse)
            resolution *= coarse
            frame = GridFrame(window.shape[0], window.shape[1], resolution, frame.origin)
        costmap = build_costmap(window, resolution, cfg, self.robot)
        frontiers = find_frontiers(
            window,
            min_cells=max(1, math.ceil(cfg.min_frontier_length / resolution - 1e-9)),
            min_unknown_cells=math.ceil(cfg.min_unknown_area / resolution**2 - 1e-9),
        )
        prepared = Prepared(frame, costmap, frontiers)
        self._cache[key] = (box, occupancy, prepared)
        if coarse == 1:
            self.latest = prepared
        return prepared

    def search(
        self,
        pose: NDArray[np.float64],
        occupancy: Any,
        grid: NDArray[np.int8],
        box: Box,
        inner: Box | None,
        *,
        visited: list[NDArray[np.float64]],
        blacklist: list[NDArray[np.float64]],
        current: NDArray[np.float64] | None,
        views: bool = False,
        relaxed: bool = False,
        coarse: int = 1,
    ) -> tuple[str, Found | None]:
        """Look for a goal in window ``box`` of the map; with ``inner``, only as far as that part of it.

        Parameters
        ----------
        pose:
            float64 ``[3]`` the robot's pose (map frame).
        occupancy, grid:
            The map object and its grid.
        box:
            ``(row0, row1, col0, col1)`` the window (grid cells; may stick out of the grid).
        inner:
            ``(row0, row1, col0, col1)`` in window cells: stop where the search leaves it; ``None``
            searches the whole window.
        visited, blacklist:
            Reached and failed goals (map frame, m).
        current:
            float64 ``[2]`` the current goal, kept unless another is clearly cheaper; or ``None``.
        views, relaxed:
            The kind of goal (module docstring).
        coarse:
            Search a copy of the window with cells this many times larger (cheaper; conservative: a
            passage may close, so a search that finds nothing must be repeated at full resolution).

        Returns
        -------
        (outcome, found)
            ``"goal"`` with the goal found; ``"undecided"`` with the cheapest goal in the window
            interior, when the current goal lies beyond it and might still be the better one;
            ``"edge"`` when the search reached the edge of ``inner`` before any goal; ``"none"``
            when no goal is reachable; ``"lost"`` when the robot is off the window.
        """
        cfg = self.config
        normal = self.prepare(occupancy, grid, box, coarse=coarse) if relaxed else None
        prepared = self.prepare(occupancy, grid, box, relaxed, coarse)
        frame, costmap = prepared.frame, prepared.costmap
        row, col = (int(v) for v in frame.to_cell(pose[:2]))
        if not frame.inside(row, col):
            return "lost", None
        candidates, unreachable = self._candidates(prepared, visited, views)
        if normal is not None:
            candidates &= normal.costmap.kind == PASSABLE
        exclude_discs(candidates, frame, blacklist, cfg.blacklist_radius)
        keep = None
        if current is not None:
            near = candidates.copy()
            exclude_discs(near, frame, [current], cfg.blacklist_radius)
            keep = candidates & ~near
        result = dijkstra(
            costmap.cost,
            (row, col),
            goal=candidates,
            keep=keep,
            ratio=cfg.goal_hysteresis,
            escape=costmap.escape,
            escape_radius=cfg.escape_radius / frame.resolution,
            interior=inner,
        )
        outcome = "goal"
        if result.boundary_cost is not None:  # the window's edge came first
            if result.goal is None:
                return "edge", None
            if result.first_cost is not None and result.first_cost >= cfg.goal_hysteresis * result.boundary_cost:
                outcome = "undecided"
        elif result.goal is None:
            if inner is None:
                passable = (costmap.kind == PASSABLE).ravel()
                reached = result.cost_to_come[passable] != UNREACHED
                self.reachable_share = float(reached.mean()) if reached.size else 0.0
            return ("edge" if inner is not None else "none"), None
        assert result.goal is not None
        cells, path = self._path(prepared, result, pose)
        if cfg.turn_penalty > 0.0 and not views and not result.kept and result.first_cost is not None:
            better = self._ahead(prepared, pose, (row, col), candidates, inner, result.first_cost, path)
            if better is not None:
                result, cells, path = better
        path[0] = pose[:2]
        target = path[-1].copy()
        if views:
            if result.goal is None:  # both searches above return only results with a goal
                raise RuntimeError("goal search: the chosen search result has no goal cell")
            target = _nearest_cell(unreachable, frame, result.goal, cfg.view_distance)
        clearance = costmap.clearance[cells[:, 0], cells[:, 1]].astype(np.float64)
        return outcome, Found(path=path, clearance=clearance, target=target, kept=result.kept)

    def _path(
        self, prepared: Prepared, result: PlanResult, pose: NDArray[np.float64]
    ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """The cells (int64 ``[N, 2]``) and map-frame points (float64 ``[N, 2]``) of the path to the
        goal of ``result``, straightened if ``smooth_paths``."""
        costmap, frame = prepared.costmap, prepared.frame
        assert result.goal is not None
        cells = result.path_to(*result.goal)
        if self.config.smooth_paths and cells.shape[0] > 2:
            corners = cells[shortcut_path(cells, costmap.cost)].astype(np.float64)
            along = resample_polyline(corners, 1.0)  # (row, col), at most one cell apart
            cells = np.clip(np.floor(along + 0.5).astype(np.int64), 0, np.array(costmap.cost.shape) - 1)
            return cells, frame.to_xy(along[:, 0], along[:, 1])
        return cells, frame.to_xy(cells[:, 0], cells[:, 1])

    def _turn_cost(self, path: NDArray[np.float64], pose: NDArray[np.float64], resolution: float) -> float:
        """Path-cost equivalent (cells x cost factor) of the turn the robot needs to set off along
        ``path``: ``turn_penalty`` m per radian between its heading and the direction to the path point
        ``lookahead_distance`` ahead."""
        cfg = self.config
        ahead = stablemath.hypot(path[:, 0] - pose[0], path[:, 1] - pose[1])
        index = np.flatnonzero(ahead >= cfg.lookahead_distance)
        if index.size == 0:
            return 0.0
        tx, ty = path[int(index[0])]
        turn = abs(math.remainder(math.atan2(ty - pose[1], tx - pose[0]) - pose[2], 2.0 * math.pi))
        return cfg.turn_penalty * turn / resolution

    def _ahead(
        self,
        prepared: Prepared,
        pose: NDArray[np.float64],
        start: tuple[int, int],
        candidates: NDArray[np.bool_],
        inner: Box | None,
        first_cost: float,
        path: NDArray[np.float64],
    ) -> tuple[PlanResult, NDArray[np.int64], NDArray[np.float64]] | None:
        """A goal in front of the robot that beats the closest one once turning is paid for, or ``None``.

        The closest goal's cost plus its turn cost bounds a second search among the goal cells in the
        half-plane ahead of the robot; its goal wins if its own cost plus turn cost is lower. So the
        robot does not turn round for a frontier barely closer than one it is facing.
        """
        cfg = self.config
        frame, costmap = prepared.frame, prepared.costmap
        current = first_cost + self._turn_cost(path, pose, frame.resolution)
        if current <= first_cost + 1e-9:
            return None
        rows, cols = np.nonzero(candidates)
        xy = frame.to_xy(rows, cols)
        front = (xy[:, 0] - pose[0]) * math.cos(pose[2]) + (xy[:, 1] - pose[1]) * math.sin(pose[2]) > 0.0
        if not front.any():
            return None
        ahead = np.zeros_like(candidates)
        ahead[rows[front], cols[front]] = True
        result = dijkstra(
            costmap.cost,
            start,
            goal=ahead,
            escape=costmap.escape,
            escape_radius=cfg.escape_radius / frame.resolution,
            interior=inner,
            max_cost=current,
        )
        if result.goal is None or result.first_cost is None or result.boundary_cost is not None:
            return None
        cells, path_ahead = self._path(prepared, result, pose)
        if result.first_cost + self._turn_cost(path_ahead, pose, frame.resolution) >= current:
            return None
        return result, cells, path_ahead

    def path_clear(self, path: NDArray[np.float64], pose: NDArray[np.float64]) -> bool:
        """Whether the robot still fits along ``path`` (map frame) in the latest full-resolution costmap:
        no point on an occupied or unknown cell or closer than ``robot_radius`` to an obstacle (points
        within ``escape_radius`` of the robot aside: it may be escaping from the lethal zone). Paths
        from a coarse search may come closer to walls than the lethal distance; that is allowed."""
        prepared = self.latest
        if prepared is None or path.shape[0] == 0:
            return False
        frame = prepared.frame
        rows, cols = frame.to_cell(path)
        inside = (rows >= 0) & (rows < frame.height) & (cols >= 0) & (cols < frame.width)
        far = stablemath.hypot(path[:, 0] - pose[0], path[:, 1] - pose[1]) > self.config.escape_radius
        check = inside & far
        kind = prepared.costmap.kind[rows[check], cols[check]]
        clearance = prepared.costmap.clearance[rows[check], cols[check]]
        blocked = (kind == OCCUPIED) | (kind == UNKNOWN) | (clearance < self.robot.radius)
        return not bool(blocked.any())

    def _candidates(
        self, prepared: Prepared, visited: list[NDArray[np.float64]], views: bool
    ) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
        """Goal cells before the blacklist, and the unreachable frontier cells (for view points)."""
        cfg = self.config
        frame, costmap, frontiers = prepared.frame, prepared.costmap, prepared.frontiers
        passable = costmap.kind == PASSABLE
        if not views:
            candidates = frontiers.mask & passable
            exclude_discs(candidates, frame, visited, cfg.blacklist_radius)
            return candidates, np.zeros_like(candidates)
        unreachable = frontiers.mask & ~passable
        exclude_discs(unreachable, frame, visited, cfg.view_distance)
        if not unreachable.any():
            return np.zeros_like(unreachable), unreachable
        reach = cfg.view_distance / frame.resolution
        candidates = (squared_distance_transform(unreachable) <= reach * reach) & passable
        exclude_discs(candidates, frame, visited, cfg.blacklist_radius)
        return candidates, unreachable


def _nearest_cell(
    mask: NDArray[np.bool_], frame: GridFrame, cell: tuple[int, int], radius: float
) -> NDArray[np.float64]:
    """Map-frame centre of the True cell of ``mask`` nearest ``cell`` within ``radius`` m (else ``cell``'s)."""
    n = math.ceil(radius / frame.resolution)
    r, c = cell
    r0, c0 = max(r - n, 0), max(c - n, 0)
    rows, cols = np.nonzero(mask[r0 : r + n + 1, c0 : c + n + 1])
    if rows.size == 0:
        return frame.to_xy(r, c)
    k = int(np.argmin((rows + r0 - r) ** 2 + (cols + c0 - c) ** 2))
    return frame.to_xy(rows[k] + r0, cols[k] + c0)
