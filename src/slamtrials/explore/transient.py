"""Obstacles the map does not show that held the robot still: planned around until the laser sees them gone.

Why. Real clutter (a person standing, a chair, a bag) stays for tens of seconds where the SLAM map
shows free space. The path follower stops for it (it reacts to the scan), but the planner, which plans
on the map, keeps sending the robot the same way: the robot recovers, comes back, is held again, and
after ``max_recoveries_per_goal`` recoveries gives the goal (and with it the frontier) up. A ROS
costmap's obstacle layer marks what the laser sees and clears it by ray tracing; this is that, for the
few points that matter.

What. When the scan has held the robot still for ``blocked_time`` (:mod:`slamtrials.explore.recovery`),
:meth:`TransientObstacles.add` keeps the confirmed returns within ``reach`` m of the robot's edge that
end on a cell the planning map calls free with no occupied cell within ``clear_cells`` cells (so a
wall the map shows, or shows a little off, adds nothing), if there are at least ``min_returns`` of
them and their beams cover at most ``max_angle`` of the scan (else it is the map that is off, see the
class). :meth:`TransientObstacles.stamp` marks their
cells occupied in the map the explorer plans on (the costmap inflates them like any wall), so the new
path goes around them if there is room. Each scan, :meth:`TransientObstacles.forget_seen` drops the
points that a beam now passes (its return lies more than ``pass_margin`` beyond the point, on the beam
nearest the point's bearing, within the laser's range): the robot's own later scans show the thing
gone. A point no scan looked at is dropped after ``lifetime`` s, so a path it blocked is retried.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials import stablemath
from slamtrials.explore.evidence import MapView
from slamtrials.explore.follower import scan_points
from slamtrials.explore.gridframe import FREE_BELOW, GridFrame, map_arrays
from slamtrials.record import LaserGeometry

__all__ = ["TransientObstacles"]


class TransientObstacles:
    """Points (map frame, m) of obstacles the map does not show, with the time each was added.

    Parameters
    ----------
    reach:
        Returns within this distance (m) of the robot's edge are taken when the robot is held still.
    lifetime:
        Seconds after which a point is dropped even if no scan showed it gone.
    clear_cells:
        A return is taken only if no cell within this many cells (Chebyshev) of its cell is occupied.
    pass_margin:
        A beam whose return lies this far (m) beyond a point passes it (the point is gone).
    min_returns, max_angle:
        Returns are taken only if at least ``min_returns`` qualify and their beams cover at most
        ``max_angle`` (rad) of the scan together: one or two returns are more likely a corner the map
        shows a little off, and that many returns a stretch of wall the map misplaced (with ``realistic``,
        school_medium_01 held the robot by 66 to 110 degrees of such returns; the things that stay by 46
        at most, often several small ones round the robot).
    """

    def __init__(
        self,
        reach: float,
        lifetime: float,
        clear_cells: int = 2,
        pass_margin: float = 0.1,
        min_returns: int = 3,
        max_angle: float = math.radians(50.0),
    ):
        self.min_returns = int(min_returns)
        self.max_angle = float(max_angle)
        self.reach = float(reach)
        self.lifetime = float(lifetime)
        self.clear_cells = int(clear_cells)
        self.pass_margin = float(pass_margin)
        self.reset()

    def reset(self) -> None:
        """Forget every point."""
        self.points = np.zeros((0, 2), dtype=np.float64)
        self.added = np.zeros(0, dtype=np.float64)
        self.version = (
            getattr(self, "version", -1) + 1
        )  # changes whenever the points do (a stamped map is cached per version)

    def __len__(self) -> int:
        return int(self.points.shape[0])

    def _set(self, points: NDArray[np.float64], added: NDArray[np.float64]) -> None:
        self.points, self.added = points, added
        self.version += 1

    def add(
        self, t: float, pose: ArrayLike, ranges: ArrayLike, laser: LaserGeometry, radius: float, occupancy: Any
    ) -> int:
        """Keep the returns of ``ranges`` (``[B]`` m, NaN for dropped beams) seen from ``pose`` (float64
        ``[3]``, map frame) that end within ``reach`` of the robot's edge (``radius`` m) on free cells of
        ``occupancy`` away from its occupied ones (module docstring). Returns how many were added."""
        pts = scan_points(ranges, laser)  # [N, 2] robot frame
        if pts.shape[0] == 0:
            return 0
        near = stablemath.hypot(pts[:, 0], pts[:, 1]) <= radius + self.reach
        pts = pts[near]
        if pts.shape[0] == 0:
            return 0
        x, y, th = (float(v) for v in np.asarray(pose, dtype=np.float64)[:3])
        c, s = math.cos(th), math.sin(th)
        world = np.stack([x + c * pts[:, 0] - s * pts[:, 1], y + s * pts[:, 0] + c * pts[:, 1]], axis=1)
        grid, _, _ = map_arrays(occupancy)
        rows, cols = GridFrame.of(occupancy).to_cell(world)
        height, width = grid.shape
        k = self.clear_cells
        keep = np.zeros(world.shape[0], dtype=np.bool_)
        for i in range(world.shape[0]):
            r, col = int(rows[i]), int(cols[i])
            if not (0 <= r < height and 0 <= col < width) or not 0 <= grid[r, col] < FREE_BELOW:
                continue
            patch = grid[max(r - k, 0) : r + k + 1, max(col - k, 0) : col + k + 1]
            keep[i] = not bool((patch >= FREE_BELOW).any())
        count = int(keep.sum())
        if count < self.min_returns:
            return 0
        if count * abs(laser.angle_increment) > self.max_angle:
            return 0  # a wall round the robot that the map does not show: the map is off, not a thing there
        new = world[keep]
        self._set(np.concatenate([self.points, new]), np.concatenate([self.added, np.full(new.shape[0], float(t))]))
        return int(new.shape[0])

    def forget_seen(self, t: float, pose: ArrayLike, ranges: ArrayLike, laser: LaserGeometry) -> None:
        """Drop the points a beam of this scan (``ranges`` ``[B]`` m, NaN for dropped beams, from ``pose``)
        passes, and those older than ``lifetime`` (module docstring)."""
        if self.points.shape[0] == 0:
            return
        keep = t - self.added < self.lifetime
        r = np.asarray(ranges, dtype=np.float64)
        beams = r.shape[0]
        if beams:
            x, y, th = (float(v) for v in np.asarray(pose, dtype=np.float64)[:3])
            c, s = math.cos(th), math.sin(th)
            mx, my, mth = laser.mount
            lx, ly = x + c * mx - s * my, y + s * mx + c * my
            dx, dy = self.points[:, 0] - lx, self.points[:, 1] - ly
            dist = stablemath.hypot(dx, dy)
            bearing = stablemath.arctan2(dy, dx) - th - mth
            bearing = np.remainder(bearing - laser.angle_min, 2.0 * math.pi)  # from the first beam, [0, 2 pi)
            index = np.rint(bearing / laser.angle_increment).astype(np.intp)
            inside = (index >= 0) & (index < beams) & (dist < laser.range_max)
            seen = np.where(inside, r[np.clip(index, 0, beams - 1)], np.nan)
            # a return beyond the point, or no return at all (the beam went on past it)
            passed = inside & ((seen > dist + self.pass_margin) | (seen >= laser.range_max))
            keep &= ~passed
        if not keep.all():
            self._set(self.points[keep], self.added[keep])

    def stamp(self, occupancy: Any) -> Any:
        """``occupancy`` with the points' cells occupied (a :class:`MapView`), or itself if there are none."""
        if self.points.shape[0] == 0:
            return occupancy
        grid, resolution, origin = map_arrays(occupancy)
        rows, cols = GridFrame.of(occupancy).to_cell(self.points)
        height, width = grid.shape
        inside = (rows >= 0) & (rows < height) & (cols >= 0) & (cols < width)
        if not inside.any():
            return occupancy
        out = np.array(grid, dtype=np.int8, copy=True)
        out[rows[inside], cols[inside]] = 100
        return MapView(out, resolution, np.asarray(origin, dtype=np.float64))
