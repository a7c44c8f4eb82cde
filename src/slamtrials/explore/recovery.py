"""Getting unstuck: notice that the robot does not move as commanded, then back off and turn.

:class:`StuckMonitor` keeps the last ``stuck_time`` seconds of commanded speed (forward, or backward
while backing out along a path; a change of direction starts the window afresh) and estimated
position. The robot is stuck when it was commanded to move at least ``stuck_min_command`` metres over
that window but moved (net) less than ``stuck_ratio`` of it: the simulator stops a robot that bumps
into a wall, and a robot wedged against an obstacle that the map does not show (or shows elsewhere,
after a SLAM error) does not move either. It is also stuck when it has been following a path for
``idle_time`` without getting ``idle_distance`` away from where it was (turning back and forth, or
held still by the scan).

:class:`Recovery` is a short open-loop manoeuvre, timed in simulated seconds. A robot touching an
obstacle (a scan point within 3 cm of its edge: it bumped into something) turns until the direction
away from that point is straight ahead or behind, and moves ``backoff_distance`` away at
``backoff_speed`` (less if the map shows less room). Otherwise it backs off ``backoff_distance`` (the laser sees nothing behind, so
this is blind, but it retraces where the robot came from; it is skipped when the map shows an
obstacle there, see :func:`segment_clear`), then turns in place by ``recovery_turn`` towards the side
where the scan sees more room. Either move is dropped when the map shows no room for it.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from slamtrials import stablemath
from slamtrials.explore.config import ExploreConfig, RobotLimits
from slamtrials.explore.follower import scan_points
from slamtrials.explore.gridframe import FREE_BELOW, GridFrame, map_arrays
from slamtrials.geometry import Pose1Like
from slamtrials.record import LaserGeometry

__all__ = ["Recovery", "StuckMonitor", "open_side", "segment_clear"]

_CONTACT = 0.03  # m: a scan point this close to the robot's edge means the robot touches an obstacle


class StuckMonitor:
    """Detects a robot that does not move as commanded (see the module docstring)."""

    def __init__(self, config: ExploreConfig):
        self.config = config
        self._samples: deque[tuple[float, float, float, float]] = deque()  # (t, x, y, commanded distance)
        self._commanded = 0.0
        self._anchor: tuple[float, float, float] | None = None  # (t, x, y) where idling began
        self._direction = 1.0  # sign of the last non-zero speed commanded

    def reset(self) -> None:
        """Forget the history."""
        self._samples.clear()
        self._commanded = 0.0
        self._anchor = None
        self._direction = 1.0

    def update(self, t: float, pose: Pose1Like, v_command: float, dt: float, following: bool = True) -> bool:
        """Record that at time ``t`` (s) the robot was at ``pose`` and was then commanded ``v_command``
        (m/s) for ``dt`` s, while following a path or not; return whether it is stuck."""
        x, y = float(pose[0]), float(pose[1])
        if not following:
            self._anchor = None
        elif self._anchor is None or math.hypot(x - self._anchor[1], y - self._anchor[2]) >= self.config.idle_distance:
            self._anchor = (t, x, y)
        elif t - self._anchor[0] >= self.config.idle_time:
            return True
        # backing out along a path counts; a recovery's backing off (not following) does not
        moved = (abs(float(v_command)) if following else max(float(v_command), 0.0)) * dt
        direction = math.copysign(1.0, v_command) if following and v_command != 0.0 else 0.0
        if direction != 0.0:
            if direction != self._direction:
                # the net displacement of a window in which the robot changed direction means nothing
                self._samples.clear()
                self._commanded = 0.0
            self._direction = direction
        self._samples.append((t, x, y, moved))
        self._commanded += moved
        window = self.config.stuck_time
        while self._samples and self._samples[0][0] < t - window - 1e-9:
            self._commanded -= self._samples.popleft()[3]
        if len(self._samples) < 2 or t - self._samples[0][0] < window - 1e-9:
            return False
        # the displacement since the oldest sample comes from the commands given before the newest one
        commanded = self._commanded - moved
        if commanded < self.config.stuck_min_command:
            return False
        _, x0, y0, _ = self._samples[0]
        return math.hypot(x - x0, y - y0) < self.config.stuck_ratio * commanded


def open_side(ranges: ArrayLike, laser: LaserGeometry) -> float:
    """+1.0 if the scan sees more room to the left (beam angle > 0) than to the right, else -1.0."""
    r = np.asarray(ranges, dtype=np.float64)
    angles = laser.beam_angles(r.shape[0])
    r = np.where(np.isnan(r), 0.0, np.minimum(r, laser.range_max))  # a no-return (+inf) looks into the open
    r = np.minimum(r, 5.0)  # what matters is the room nearby
    left = float(r[angles > 0.0].sum())
    right = float(r[angles < 0.0].sum())
    return 1.0 if left >= right else -1.0


def segment_clear(occupancy: Any, a: ArrayLike, b: ArrayLike, radius: float) -> bool:
    """Whether a disc of ``radius`` (m) moved from map-frame point ``a`` to ``b`` stays off the map's
    occupied cells (each taken as a disc of half a cell around its centre). Unknown cells count as free."""
    grid, resolution, _ = map_arrays(occupancy)
    frame = GridFrame.of(occupancy)
    pa = np.asarray(a, dtype=np.float64)[:2]
    pb = np.asarray(b, dtype=np.float64)[:2]
    reach = radius + resolution
    corners = np.array(
        [[min(pa[0], pb[0]) - reach, max(pa[1], pb[1]) + reach], [max(pa[0], pb[0]) + reach, min(pa[1], pb[1]) - reach]]
    )
    rows, cols = frame.to_cell(corners)
    r0, r1 = int(max(rows.min(), 0)), int(min(rows.max() + 1, grid.shape[0]))
    c0, c1 = int(max(cols.min(), 0)), int(min(cols.max() + 1, grid.shape[1]))
    if r0 >= r1 or c0 >= c1:
        return True
    rr, cc = np.nonzero(grid[r0:r1, c0:c1] >= FREE_BELOW)
    if rr.size == 0:
        return True
    centres = frame.to_xy(rr + r0, cc + c0)
    seg = pb - pa
    # written out rather than with `@`: BLAS picks its kernels by CPU, and their rounding differs
    length2 = float(seg[0] * seg[0] + seg[1] * seg[1])
    along = (centres[:, 0] - pa[0]) * seg[0] + (centres[:, 1] - pa[1]) * seg[1]
    s = np.zeros(len(centres)) if length2 == 0.0 else np.clip(along / length2, 0.0, 1.0)
    offset = centres - (pa + s[:, None] * seg)
    gap = stablemath.hypot(offset[:, 0], offset[:, 1])
    return bool(gap.min() >= radius + 0.5 * resolution)


class Recovery:
    """The recovery manoeuvre (see the module docstring): open-loop phases timed in simulated seconds."""

    def __init__(self, config: ExploreConfig, robot: RobotLimits | None = None):
        self.config = config
        self.robot = RobotLimits() if robot is None else robot
        self._phases: list[tuple[float, float, float]] = []  # (end time, v, w)

    @property
    def active(self) -> bool:
        """Whether a manoeuvre is under way."""
        return bool(self._phases)

    def reset(self) -> None:
        """Abort any manoeuvre."""
        self._phases = []

    def start(self, t: float, pose: ArrayLike, ranges: ArrayLike, laser: LaserGeometry, occupancy: Any) -> None:
        """Begin a manoeuvre at time ``t`` (s) from ``pose`` (map frame) with the current scan and map.

        If the scan shows an obstacle within ``_CONTACT`` of the robot's edge, the robot turns so
        that the direction away from that point is straight ahead (or straight behind, whichever
        needs the smaller turn) and moves ``backoff_distance`` that way, if the map shows room for it.
        Otherwise it backs off ``backoff_distance`` (if the map shows room behind) and turns
        ``recovery_turn`` towards the side where the scan sees more room.
        """
        cfg, robot = self.config, self.robot
        x, y, theta = (float(v) for v in np.asarray(pose, dtype=np.float64)[:3])
        rate = 0.8 * robot.max_angular_speed
        phases: list[tuple[float, float, float]] = []  # (duration, v, w) without the end times yet
        points = scan_points(ranges, laser)
        push = None
        if points.shape[0] and cfg.backoff_distance > 0.0:
            dist = stablemath.hypot(points[:, 0], points[:, 1])
            k = int(np.argmin(dist))
            if dist[k] < robot.radius + _CONTACT:
                away = math.atan2(-points[k, 1], -points[k, 0])  # robot frame
                direction = 1.0 if abs(away) <= 0.5 * math.pi else -1.0
                turn = away if direction > 0 else math.remainder(away - math.pi, 2.0 * math.pi)
                heading = theta + away
                ux, uy = math.cos(heading), math.sin(heading)
                # from a little way out: the obstacle being touched (as the map shows it) is left behind
                start = (x + _CONTACT * ux, y + _CONTACT * uy)
                for share in (1.0, 0.6, 0.3):  # as far as the map shows room for
                    length = share * cfg.backoff_distance
                    if segment_clear(occupancy, start, (x + length * ux, y + length * uy), robot.radius - _CONTACT):
                        push = (turn, direction, length)
                        break
        if push is not None:
            turn, direction, length = push
            phases.append((abs(turn) / rate, 0.0, math.copysign(rate, turn)))
            phases.append((length / cfg.backoff_speed, direction * cfg.backoff_speed, 0.0))
        else:
            behind = (
                x - (cfg.backoff_distance + 0.05) * math.cos(theta),
                y - (cfg.backoff_distance + 0.05) * math.sin(theta),
            )
            if cfg.backoff_distance > 0.0 and segment_clear(occupancy, (x, y), behind, robot.radius):
                phases.append((cfg.backoff_distance / cfg.backoff_speed, -cfg.backoff_speed, 0.0))
            if cfg.recovery_turn > 0.0:
                phases.append((cfg.recovery_turn / rate, 0.0, open_side(ranges, laser) * rate))
        end = t
        self._phases = []
        for duration, v, w in phases:
            end += duration
            self._phases.append((end, v, w))

    def command(self, t: float) -> tuple[float, float] | None:
        """The manoeuvre's command at time ``t``, or ``None`` once it is over."""
        while self._phases and t >= self._phases[0][0] - 1e-9:
            self._phases.pop(0)
        if not self._phases:
            return None
        _, v, w = self._phases[0]
        return v, w
