"""Local control: follow a planned path with pure pursuit, within speed and acceleration limits,
slowing down and stopping for obstacles seen in the current laser scan.

Per call, with the robot at ``pose`` (map frame) and the path as map-frame points:

1. progress: the path point nearest the robot, searched forward from the last one;
2. target: the first path point at least ``lookahead_distance`` from the robot (else the last point);
3. heading error ``e`` to the target (robot frame). If ``|e| > rotate_in_place_angle`` the robot turns
   in place: ``w = sign(e) min(w_max, k |e|, sqrt(2 alpha |e|))`` with ``k = 2.5 /s`` (it can stop
   turning in time), ``v = 0``;
4. otherwise pure pursuit: curvature ``kappa = 2 sin(e) / l`` (``l`` the distance to the target),
   ``v = min(v_max, v_narrow, sqrt(2 a s_end), sqrt(2 a (s_free - stop_distance)), w_max / |kappa|)``
   with ``s_end`` the remaining path length, ``s_free`` how far the robot can go along the arc of
   curvature ``kappa`` before its disc (radius + ``obstacle_margin``) touches a scan point
   (:func:`free_travel`), and ``v_narrow`` a limit from the smallest clearance of the path in the next
   metre (``narrow_speed`` at the lethal distance, rising linearly to ``v_max`` at
   ``narrow_clearance`` beyond it; only when the path's clearances were given), and ``w = kappa v``;
5. acceleration: ``v`` may rise by at most ``max_linear_accel * dt`` per call (braking is left to the
   robot's own limits, which the speed caps above respect), ``w`` changes by at most
   ``max_angular_accel * dt``.

If the scan blocks the arc, steps 2 to 4 are tried again with a short look-ahead (0.25 m), which
tracks the path more tightly in narrow places. If that is blocked too, the robot *creeps*: it turns in
place to face the path point 0.15 m ahead, then inches straight towards it at 0.15 m/s at most,
keeping no margin beyond its radius from the scan's points (the path itself keeps off walls by the
costmap's lethal distance). If even that is impossible it reports itself *blocked* (the explorer
starts a recovery if this lasts). Once the short look-ahead or creeping was needed, it is kept (also
across new paths) until the robot has moved 0.4 m: switching back and forth between look-aheads would
make it turn back and forth on the spot.

Backing out: when the path first leads back the way the robot came (typically from a goal at a dead
end), the robot backs along it instead of turning round. The *leg* is the longest start of the path,
at most ``max_reverse_distance`` long, that runs straight from the robot (every point within
``_LEG_TOLERANCE`` of the line to its end); if it is at least ``_MIN_LEG`` long and its end lies at
least ``reverse_angle`` off the heading, the robot stops (without turning; its speed is measured from
its last two positions), then follows the leg backwards: steps 2 to 5 with the heading ``theta + pi``,
the target no further than the leg's end, the scan points mirrored (the laser's blind sector is behind
the robot; the path keeps off the mapped walls) and ``reverse_speed`` as the speed limit. At the leg's
end (a corner, or the way out of the dead end) it drives forward again, turning in place there if
needed; it also does when backing would need a turn in place or the scan blocks it. It backs out again
only after moving ``_REVERSE_REARM`` away from where it stopped backing. A new path while backing gets
a new leg from where the robot is (for the distance still allowed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from slamtrials import stablemath
from slamtrials.explore.config import ExploreConfig, RobotLimits, lethal_distance
from slamtrials.geometry import Pose1Like
from slamtrials.record import LaserGeometry

__all__ = ["FollowCommand", "PathFollower", "free_travel", "scan_points", "turn_rate"]

_K_TURN = 2.5
_SEARCH_AHEAD = 60  # path points searched for progress per call
_BLOCKED_SPEED = 0.03  # m/s: a speed cap below this from the scan means blocked
_SHORT_LOOKAHEAD = 0.25  # m: look-ahead tried when the normal one leads into an obstacle
_CREEP_LOOKAHEAD = 0.15  # m: target of the creeping mode
_CREEP_ALIGN = math.radians(8.0)  # heading error (rad) up to which the robot creeps straight
_CREEP_SPEED = 0.15  # m/s
_CREEP_MARGIN = 0.0  # m: clearance kept beyond the radius while creeping
_NARROW_AHEAD = 1.0  # m of path ahead whose clearance limits the speed
_TARGET_WINDOW = 3.0  # m of path ahead searched for the look-ahead target
_TIGHT_RELEASE = 0.4  # m: after a short look-ahead or creeping was needed, keep it up for this distance
_LEG_TOLERANCE = 0.05  # m: how far from a straight line the path may stray and still be backed along
_MIN_LEG = 0.3  # m: shorter legs are not worth backing along
_LEG_ARRIVED = 0.1  # m: the leg's end is reached within this distance
_STANDSTILL = 0.05  # m/s: below this speed the robot may start backing out
_REVERSE_REARM = 1.0  # m: after backing out, move this far before backing out again


def turn_rate(error: float, max_rate: float, max_accel: float) -> float:
    """Turn rate (rad/s) towards a heading error (rad) that can still stop in time: see the module docstring."""
    magnitude = min(max_rate, _K_TURN * abs(error), math.sqrt(2.0 * max_accel * abs(error)))
    return math.copysign(magnitude, error)


_ANGLE_CACHE: dict[tuple[int, float, float, float], tuple[NDArray[np.float64], NDArray[np.float64]]] = {}


def _beam_directions(beams: int, laser: LaserGeometry) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(cos, sin) of every beam's direction in the base frame, cached per laser geometry."""
    mth = laser.mount[2]
    key = (beams, laser.angle_min, laser.angle_increment, mth)
    found = _ANGLE_CACHE.get(key)
    if found is None:
        angles = key[1] + key[2] * np.arange(beams) + mth
        found = (stablemath.cos(angles), stablemath.sin(angles))
        if len(_ANGLE_CACHE) > 64:
            _ANGLE_CACHE.clear()
        _ANGLE_CACHE[key] = found
    return found


@njit(cache=True, nogil=True)
def _scan_points(ranges, cos, sin, mx, my, range_min, range_max):  # pragma: no cover - compiled
    out = np.empty((ranges.shape[0], 2), dtype=np.float64)
    k = 0
    for b in range(ranges.shape[0]):
        r = ranges[b]
        if r > range_min and r < range_max:  # False for NaN
            out[k, 0] = mx + r * cos[b]
            out[k, 1] = my + r * sin[b]
            k += 1
    return out[:k]


def scan_points(ranges: ArrayLike, laser: LaserGeometry) -> NDArray[np.float64]:
    """float64 ``[K, 2]`` scan returns in the robot base frame (m).

    Beams with NaN, ``r <= range_min`` or ``r >= range_max`` (no return) are left out.
    """
    r = np.ascontiguousarray(ranges, dtype=np.float64)
    cos, sin = _beam_directions(r.shape[0], laser)
    return _scan_points(r, cos, sin, laser.mount[0], laser.mount[1], laser.range_min, laser.range_max)


@njit(cache=True, nogil=True)
def _free_travel(points, curvature, half_width, horizon):  # pragma: no cover - compiled
    best = horizon
    h2 = half_width * half_width
    if abs(curvature) < 0.05:
        for k in range(points.shape[0]):
            x = points[k, 0]
            y = points[k, 1]
            if x > 0.0 and abs(y) < half_width:
                travel = x - math.sqrt(h2 - y * y)
                best = min(best, travel)
    else:
        radius = 1.0 / abs(curvature)
        for k in range(points.shape[0]):
            x = points[k, 0]
            ys = points[k, 1] if curvature > 0.0 else -points[k, 1]  # mirror right turns into left ones
            rho = math.hypot(x, ys - radius)
            gap = rho - radius
            if abs(gap) >= half_width:
                continue
            beta = math.atan2(ys - radius, x)  # angle around the turning centre
            swept = (beta + 0.5 * math.pi) % (2.0 * math.pi)  # from the robot's position, counter-clockwise
            if swept >= math.pi:
                continue
            travel = radius * swept - math.sqrt(h2 - gap * gap)
            best = min(best, travel)
    return min(max(best, 0.0), horizon)


def free_travel(points: NDArray[np.float64], curvature: float, half_width: float, horizon: float = 5.0) -> float:
    """How far (m) the robot centre can move forward along an arc before touching a point.

    Parameters
    ----------
    points:
        float64 ``[K, 2]`` obstacle points in the robot base frame (m), x forward, y left.
    curvature:
        Curvature of the arc (1/m), positive turning left; 0 (below 0.05 in magnitude) is straight ahead.
    half_width:
        Radius (m) of the disc swept along the arc.
    horizon:
        Largest distance reported (m).

    Returns
    -------
    float
        Arc length (m), in ``[0, horizon]``: for each point within ``half_width`` of the arc (and ahead,
        on the first half turn), the arc length to it minus the disc's half chord there; 0 when a point
        is already inside the disc ahead of the centre.
    """
    pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    return float(_free_travel(pts, float(curvature), float(half_width), float(horizon)))


@dataclass(frozen=True)
class FollowCommand:
    """One command of the follower.

    Attributes
    ----------
    v, w:
        Linear (m/s) and angular (rad/s) velocity.
    blocked:
        The scan keeps the robot from driving on.
    finished:
        The robot is within ``goal_tolerance`` of the path's last point.
    """

    v: float
    w: float
    blocked: bool = False
    finished: bool = False


class PathFollower:
    """Pure-pursuit path follower (see the module docstring).

    Parameters
    ----------
    config:
        Look-ahead, clearances, narrow-passage speed.
    robot:
        Footprint, speed and acceleration limits, control period.
    """

    def __init__(self, config: ExploreConfig, robot: RobotLimits | None = None):
        self.config = config
        self.robot = RobotLimits() if robot is None else robot
        self._path = np.zeros((0, 2))
        self._clearance: NDArray[np.float64] | None = None
        self._remaining = np.zeros(0)
        self._narrow_end = np.zeros(0, dtype=np.intp)
        self._window_end = np.zeros(0, dtype=np.intp)
        self._index = 0
        self._reverse_from: tuple[float, float] | None = None  # where backing out began, while backing
        self._leg_end = 0  # path index of the end of the leg being backed along
        self._reverse_ended: tuple[float, float] | None = None  # where the last backing out ended
        self._previous: tuple[float, float] | None = None  # the position at the previous call
        self._tight: tuple[int, float, float] | None = None  # (level, x, y) where tight following began
        self._v = 0.0
        self._w = 0.0

    @property
    def path(self) -> NDArray[np.float64]:
        """float64 ``[N, 2]`` the path being followed (map frame, m)."""
        return self._path

    @property
    def has_path(self) -> bool:
        """Whether a path is set."""
        return self._path.shape[0] > 0

    def set_path(self, path: ArrayLike, clearance: ArrayLike | None = None) -> None:
        """Follow ``path``, float ``[N, 2]`` map-frame points (m), from its start.

        ``clearance``, float ``[N]`` (m), is each point's distance to the nearest obstacle (the
        costmap's clearance); it lets the robot slow down in narrow places.
        """
        points = np.asarray(path, dtype=np.float64).reshape(-1, 2)
        self._path = points
        self._clearance = None if clearance is None else np.asarray(clearance, dtype=np.float64).reshape(-1)
        step = np.diff(points, axis=0)
        seg = stablemath.hypot(step[:, 0], step[:, 1]) if len(points) > 1 else np.zeros(0)
        self._remaining = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]]) if len(points) else np.zeros(0)
        # for each point, the index of the last point within _NARROW_AHEAD and _TARGET_WINDOW along the path
        along = self._remaining[0] - self._remaining if len(points) else np.zeros(0)
        self._narrow_end = np.searchsorted(along, along + _NARROW_AHEAD, side="right") - 1
        self._window_end = np.searchsorted(along, along + _TARGET_WINDOW, side="right") - 1
        self._index = 0
        if self._reverse_from is not None and not len(points):
            self._stop_backing(*(self._previous or self._reverse_from))
        elif self._reverse_from is not None:  # backing out: go on along the new path's leg, if it has one
            leg = self._leg(
                self.config.max_reverse_distance
                - math.hypot(points[0, 0] - self._reverse_from[0], points[0, 1] - self._reverse_from[1])
            )
            if leg is None:
                self._stop_backing(float(points[0, 0]), float(points[0, 1]))
            else:
                self._leg_end = leg

    def clear(self) -> None:
        """Forget the path."""
        self.set_path(np.zeros((0, 2)))

    def reset(self) -> None:
        """Forget the path, the remembered velocity, the tight-following and the backing-out state."""
        self.clear()
        self._tight = None
        self._reverse_from = None
        self._reverse_ended = None
        self._previous = None
        self._v = 0.0
        self._w = 0.0

    def remaining(self, pose: Pose1Like) -> float:
        """Path length (m) still ahead: from ``pose`` to the nearest path point (searched forward from the
        current one), then along the path; ``inf`` without a path."""
        if not self.has_path:
            return math.inf
        x, y = float(pose[0]), float(pose[1])
        stop = min(self._index + _SEARCH_AHEAD, len(self._path))
        d = stablemath.hypot(self._path[self._index : stop, 0] - x, self._path[self._index : stop, 1] - y)
        k = int(np.argmin(d))
        return float(d[k] + self._remaining[self._index + k])

    def remember(self, v: float, w: float) -> None:
        """Record a command given by someone else (e.g. a recovery), for the acceleration limits."""
        self._v, self._w = float(v), float(w)

    def command(self, pose: ArrayLike, ranges: ArrayLike, laser: LaserGeometry) -> FollowCommand:
        """Velocity command towards the path from ``pose`` (float64 ``[3]``, map frame) given the current scan."""
        cfg, robot = self.config, self.robot
        x, y, theta = (float(v) for v in np.asarray(pose, dtype=np.float64)[:3])
        if not self.has_path:
            return self._limited(0.0, 0.0, finished=True)
        path = self._path
        stop = min(self._index + _SEARCH_AHEAD, len(path))
        d = stablemath.hypot(path[self._index : stop, 0] - x, path[self._index : stop, 1] - y)
        self._index += int(np.argmin(d))
        to_end = float(self._remaining[self._index]) + float(d.min())
        end_dist = math.hypot(path[-1, 0] - x, path[-1, 1] - y)
        if end_dist < cfg.goal_tolerance:
            return self._limited(0.0, 0.0, finished=True)
        points = scan_points(ranges, laser)
        speed = (
            math.inf
            if self._previous is None
            else math.hypot(x - self._previous[0], y - self._previous[1]) / robot.control_period
        )
        self._previous = (x, y)
        backing_out = self._backing_out(x, y, theta, speed)
        if backing_out is None:
            return self._limited(0.0, 0.0)  # come to a stop first, without turning
        if backing_out:
            backing = self._reverse(x, y, theta, points, to_end)
            if backing is not None:
                return backing
            self._stop_backing(x, y)
        if self._tight is not None and math.hypot(x - self._tight[1], y - self._tight[2]) >= _TIGHT_RELEASE:
            self._tight = None  # got through the tight spot: back to normal following
        level = 0 if self._tight is None else self._tight[0]
        lookaheads = (cfg.lookahead_distance, _SHORT_LOOKAHEAD)
        while level < len(lookaheads):
            error, curvature, v_scan = self._arc(x, y, theta, 0.0, self._target(x, y, lookaheads[level]), points)
            if abs(error) > cfg.rotate_in_place_angle:
                return self._limited(0.0, turn_rate(error, robot.max_angular_speed, robot.max_angular_accel))
            if v_scan >= _BLOCKED_SPEED:
                break
            level += 1
            self._tight = (level, x, y)
        if level >= len(lookaheads):
            return self._creep(x, y, theta, points, to_end)
        v = self._arc_speed(robot.max_linear_speed, v_scan, to_end, curvature)
        return self._limited(v, curvature * v, pure_pursuit=True, curvature=curvature)

    def _arc(
        self, x: float, y: float, theta: float, offset: float, target: tuple[float, float], points: NDArray[np.float64]
    ) -> tuple[float, float, float]:
        """Pure pursuit towards ``target`` with the heading ``theta + offset`` (``offset`` pi: backwards,
        ``points`` then mirrored): heading error (rad), curvature (1/m) and the largest speed (m/s) at which
        the robot can still stop before the scan's points on that arc."""
        cfg, robot = self.config, self.robot
        tx, ty = target
        error = math.remainder(math.atan2(ty - y, tx - x) - theta - offset, 2.0 * math.pi)
        dist = max(math.hypot(tx - x, ty - y), 1e-6)
        curvature = 2.0 * math.sin(error) / dist
        free = free_travel(points, curvature, robot.radius + cfg.obstacle_margin)
        return error, curvature, math.sqrt(2.0 * robot.max_linear_accel * max(free - cfg.stop_distance, 0.0))

    def _arc_speed(self, limit: float, v_scan: float, to_end: float, curvature: float) -> float:
        """Speed (m/s) on the arc: ``limit``, the scan's ``v_scan``, stopping at the path's end, the
        narrow-path limit and the turn-rate limit."""
        robot = self.robot
        v = min(limit, math.sqrt(2.0 * robot.max_linear_accel * to_end), v_scan, self._narrow_limit())
        if abs(curvature) > 1e-9:
            v = min(v, robot.max_angular_speed / abs(curvature))
        return v

    @property
    def backing(self) -> bool:
        """Whether the robot is backing out along the path."""
        return self._reverse_from is not None

    def _backing_out(self, x: float, y: float, theta: float, speed: float) -> bool | None:
        """Whether to drive backwards now (module docstring, "Backing out"), or ``None`` to stop first;
        starts and stops backing. ``speed`` (m/s) is the robot's, from its last two positions."""
        cfg = self.config
        if self._reverse_from is not None:
            ex, ey = self._path[self._leg_end]
            backed = math.hypot(x - self._reverse_from[0], y - self._reverse_from[1])
            if (
                self._index >= self._leg_end
                or math.hypot(ex - x, ey - y) < _LEG_ARRIVED
                or backed >= cfg.max_reverse_distance
            ):
                self._stop_backing(x, y)
                return False
            return True
        if cfg.max_reverse_distance <= 0.0:
            return False
        if (
            self._reverse_ended is not None
            and math.hypot(x - self._reverse_ended[0], y - self._reverse_ended[1]) < _REVERSE_REARM
        ):
            return False
        # cheap test first: most paths lead ahead
        soon = int(np.searchsorted(self._remaining[self._index] - self._remaining[self._index :], _MIN_LEG))
        sx, sy = self._path[min(self._index + soon, len(self._path) - 1)]
        if abs(math.remainder(math.atan2(sy - y, sx - x) - theta, 2.0 * math.pi)) < 0.5 * math.pi:
            return False
        leg = self._leg(cfg.max_reverse_distance, x, y)
        if leg is None:
            return False
        ex, ey = self._path[leg]
        if abs(math.remainder(math.atan2(ey - y, ex - x) - theta, 2.0 * math.pi)) < cfg.reverse_angle:
            return False
        if speed >= _STANDSTILL or self._v > 0.0:
            return None
        self._reverse_from = (x, y)
        self._leg_end = leg
        return True

    def _leg(self, limit: float, x: float | None = None, y: float | None = None) -> int | None:
        """Index of the end of the longest straight start of the path from (x, y) (default: the path's
        current point), at most ``limit`` m along the path; ``None`` if shorter than ``_MIN_LEG``."""
        path, i0 = self._path, self._index
        if x is None or y is None:
            x, y = (float(v) for v in path[i0])
        along = self._remaining[i0] - self._remaining[i0:]
        last = int(np.searchsorted(along, limit, side="right")) - 1
        for j in range(last, 0, -1):
            dx, dy = path[i0 + j, 0] - x, path[i0 + j, 1] - y
            length = math.hypot(dx, dy)
            if length < _MIN_LEG:
                return None
            stray = np.abs((path[i0 : i0 + j, 0] - x) * dy - (path[i0 : i0 + j, 1] - y) * dx) / length
            if stray.max() <= _LEG_TOLERANCE:
                return i0 + j
        return None

    def _stop_backing(self, x: float, y: float) -> None:
        if self._reverse_from is not None:
            self._reverse_from = None
            self._reverse_ended = (x, y)

    def _reverse(
        self, x: float, y: float, theta: float, points: NDArray[np.float64], to_end: float
    ) -> FollowCommand | None:
        """Pure pursuit backwards (heading ``theta + pi``), or ``None`` when that needs a turn in place
        or the scan blocks it."""
        cfg = self.config
        target = self._target(x, y, cfg.lookahead_distance, self._leg_end)
        # in the backward frame: positive curvature turns the tail left
        error, curvature, v_scan = self._arc(x, y, theta, math.pi, target, -points)
        if abs(error) > cfg.rotate_in_place_angle or v_scan < _BLOCKED_SPEED:
            return None
        speed = self._arc_speed(cfg.reverse_speed, v_scan, to_end, curvature)
        # the tail turning left at rate curvature * speed is the base turning left at that rate
        return self._limited(-speed, curvature * speed, pure_pursuit=True, curvature=-curvature)

    def _creep(self, x: float, y: float, theta: float, points: NDArray[np.float64], to_end: float) -> FollowCommand:
        """Tight manoeuvring: face the path a few centimetres ahead, then inch straight along it."""
        robot = self.robot
        tx, ty = self._target(x, y, _CREEP_LOOKAHEAD)
        error = math.remainder(math.atan2(ty - y, tx - x) - theta, 2.0 * math.pi)
        if abs(error) > _CREEP_ALIGN:
            return self._limited(0.0, turn_rate(error, robot.max_angular_speed, robot.max_angular_accel))
        free = free_travel(points, 0.0, robot.radius + _CREEP_MARGIN)
        v = min(
            _CREEP_SPEED,
            math.sqrt(2.0 * robot.max_linear_accel * max(free - 0.01, 0.0)),
            math.sqrt(2.0 * robot.max_linear_accel * to_end),
        )
        if v < _BLOCKED_SPEED:
            return self._limited(0.0, 0.0, blocked=True)
        return self._limited(v, 0.0)

    def _narrow_limit(self) -> float:
        """Speed limit (m/s) from the smallest clearance of the next metre of path."""
        cfg, robot = self.config, self.robot
        if self._clearance is None or self._clearance.shape[0] != self._path.shape[0] or cfg.narrow_clearance <= 0.0:
            return robot.max_linear_speed
        least = float(self._clearance[self._index : self._narrow_end[self._index] + 1].min())
        share = min(max((least - lethal_distance(cfg, robot)) / cfg.narrow_clearance, 0.0), 1.0)
        return cfg.narrow_speed + share * (robot.max_linear_speed - cfg.narrow_speed)

    def _target(self, x: float, y: float, lookahead: float, last: int | None = None) -> tuple[float, float]:
        """The first path point from the current one at least ``lookahead`` from (x, y), else the last
        within ``_TARGET_WINDOW`` along the path (and not beyond index ``last``)."""
        end = int(self._window_end[self._index]) + 1
        if last is not None:
            end = min(end, last + 1)
        path = self._path[self._index : end]
        ahead = stablemath.hypot(path[:, 0] - x, path[:, 1] - y)
        beyond = np.flatnonzero(ahead >= lookahead)
        tx, ty = path[int(beyond[0])] if beyond.size else path[-1]
        return float(tx), float(ty)

    def _limited(
        self,
        v: float,
        w: float,
        *,
        blocked: bool = False,
        finished: bool = False,
        pure_pursuit: bool = False,
        curvature: float = 0.0,
    ) -> FollowCommand:
        robot = self.robot
        dt = robot.control_period
        if v > 0.0:
            v = min(v, max(self._v, 0.0) + robot.max_linear_accel * dt)
        elif v < 0.0:
            v = max(v, min(self._v, 0.0) - robot.max_linear_accel * dt)
        if pure_pursuit:
            w = curvature * v  # stay on the arc while speeding up
        dw = robot.max_angular_accel * dt
        w = min(max(w, self._w - dw), self._w + dw)
        self._v, self._w = v, w
        return FollowCommand(v, w, blocked, finished)
