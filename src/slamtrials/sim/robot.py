"""Differential-drive kinematics with speed and acceleration limits, and disc-footprint collisions.

Motion model
------------
Each step the commanded velocity ``(v, w)`` is clipped to the speed limits, then moved towards from
the current velocity by at most ``max_linear_accel * dt`` and ``max_angular_accel * dt``. The resulting
velocity is held constant over the step, so the robot moves along an exact circular arc of length
``L = v dt`` and heading change ``phi = w dt``; in the robot frame at the start of the step that arc
ends at::

    dx = L sin(phi) / phi,   dy = L (1 - cos(phi)) / phi = 2 L sin^2(phi / 2) / phi,   dtheta = phi

(``dx = L, dy = 0`` when ``phi = 0``), computed without cancellation (Taylor series for tiny ``phi``).

Collision rule
--------------
The footprint is a disc of radius ``r``; cells are closed squares and cells outside the grid count as
occupied. A step is allowed when the disc swept along the step never overlaps an occupied cell
(touching is allowed). The check is exact against the *capsule* of radius ``r + s`` around the step's
chord, where ``s = |L| (1 - cos(phi / 2)) / |phi|`` is the arc's sagitta (the largest distance between
the arc and its chord, below a millimetre at 0.7 m/s and 70 deg/s over 0.1 s), so it is conservative
by at most ``s``. A fast path skips the exact test when the world's clearance (cell-centre distance
transform) proves the whole capsule free: for the point p in cell c, every occupied cell is at least
``clearance(c) - |p - centre(c)| - half a cell diagonal`` away. Otherwise the exact test measures the
distance from the chord to every occupied cell in the capsule's bounding box (a small numba kernel).

A step that would overlap does not translate the robot: it turns in place by ``phi`` (a disc is
rotation invariant, so that is always possible), its linear speed is set to 0 (so it accelerates again
from rest) and the step is flagged stalled, like Stage's stall flag.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from slamtrials.geometry import compose1, wrap_angle1
from slamtrials.sim.config import RobotConfig
from slamtrials.worlds.world import World, world_to_map

__all__ = ["sinc", "cosc", "arc_increment", "arc_sagitta", "limit_velocity", "CollisionChecker", "Robot"]


def sinc(x: float) -> float:
    """``sin(x) / x`` (1 at 0), accurate for tiny and subnormal ``x`` (Taylor series below 1e-3)."""
    if abs(x) < 1e-3:
        x2 = x * x
        return 1.0 - x2 / 6.0 + x2 * x2 / 120.0
    return math.sin(x) / x


def cosc(x: float) -> float:
    """``(1 - cos(x)) / x`` (0 at 0), without cancellation (Taylor series below 1e-3)."""
    if abs(x) < 1e-3:
        x2 = x * x
        return x * (0.5 - x2 / 24.0 + x2 * x2 / 720.0)
    half = math.sin(0.5 * x)
    return 2.0 * half * half / x


def arc_increment(v: float, w: float, dt: float) -> NDArray[np.float64]:
    """Relative pose ``[3]`` (robot frame at the start) after moving at constant ``(v, w)`` for ``dt``.

    Parameters
    ----------
    v:
        Linear speed (m/s), negative backwards.
    w:
        Angular speed (rad/s), counter-clockwise positive.
    dt:
        Duration (s).

    Returns
    -------
    float64 ``[3]`` (dx, dy, dtheta) in metres and radians; dtheta is ``w dt``, not wrapped.
    """
    length = v * dt
    phi = w * dt
    return np.array([length * sinc(phi), length * cosc(phi), phi])


def arc_sagitta(length: float, phi: float) -> float:
    """Largest distance (m) between an arc of signed length ``length`` turning ``phi`` (rad) and its chord."""
    if phi == 0.0 or length == 0.0:
        return 0.0
    half = 0.5 * abs(phi)
    return abs(length) * 2.0 * math.sin(0.5 * half) ** 2 / abs(phi)  # |L| (1 - cos(phi/2)) / |phi|


def limit_velocity(
    velocity: tuple[float, float], command: tuple[float, float], config: RobotConfig, dt: float
) -> tuple[float, float]:
    """The velocity ``(v, w)`` the robot reaches after one step towards ``command``.

    Parameters
    ----------
    velocity:
        Current (v, w) in m/s and rad/s.
    command:
        Commanded (v, w).
    config:
        Speed and acceleration limits.
    dt:
        Step (s).

    Returns
    -------
    (v, w) with ``-reverse_limit <= v <= max_linear_speed``, ``|w| <= max_angular_speed``,
    ``|v - v0| <= max_linear_accel dt`` and ``|w - w0| <= max_angular_accel dt``.
    """
    v0, w0 = velocity
    v = min(max(float(command[0]), -config.reverse_speed_limit), config.max_linear_speed)
    w = min(max(float(command[1]), -config.max_angular_speed), config.max_angular_speed)
    dv = config.max_linear_accel * dt
    dw = config.max_angular_accel * dt
    v = min(max(v, v0 - dv), v0 + dv)
    w = min(max(w, w0 - dw), w0 + dw)
    return v, w


@njit(cache=True, fastmath=False, nogil=True)
def _segment_box_dist2(ax, ay, bx, by, x0, y0, x1, y1):  # pragma: no cover - compiled
    """Squared distance between segment AB and the closed box [x0, x1] x [y0, y1]."""
    # Does the segment meet the box? (Liang-Barsky clipping.)
    t0 = 0.0
    t1 = 1.0
    ex = bx - ax
    ey = by - ay
    meets = True
    for k in range(4):
        if k == 0:
            p, q = -ex, ax - x0
        elif k == 1:
            p, q = ex, x1 - ax
        elif k == 2:
            p, q = -ey, ay - y0
        else:
            p, q = ey, y1 - ay
        if p == 0.0:
            if q < 0.0:
                meets = False
                break
        else:
            r = q / p
            if p < 0.0:
                if r > t1:
                    meets = False
                    break
                if r > t0:
                    t0 = r
            else:
                if r < t0:
                    meets = False
                    break
                if r < t1:
                    t1 = r
    if meets:
        return 0.0
    # Disjoint convex sets in the plane: the closest pair involves a vertex of one of them.
    best = np.inf
    for k in range(2):
        px = ax if k == 0 else bx
        py = ay if k == 0 else by
        ddx = max(x0 - px, 0.0, px - x1)
        ddy = max(y0 - py, 0.0, py - y1)
        d2 = ddx * ddx + ddy * ddy
        if d2 < best:
            best = d2
    seg2 = ex * ex + ey * ey
    for k in range(4):
        cx = x0 if (k & 1) == 0 else x1
        cy = y0 if (k & 2) == 0 else y1
        s = 0.0
        if seg2 > 0.0:
            s = ((cx - ax) * ex + (cy - ay) * ey) / seg2
            s = min(max(s, 0.0), 1.0)
        qx = ax + s * ex - cx
        qy = ay + s * ey - cy
        d2 = qx * qx + qy * qy
        if d2 < best:
            best = d2
    return best


@njit(cache=True, fastmath=False, nogil=True)
def _capsule_free(occupied, clearance, resolution, au, av, bu, bv, radius):  # pragma: no cover - compiled
    """True when the capsule of ``radius`` (cells) around segment A-B (map coords, cells) overlaps no
    occupied cell. ``occupied`` and ``clearance`` (m) are indexed [row, col] with row 0 at the top."""
    height, width = occupied.shape
    iu = int(math.floor(au))
    iv = int(math.floor(av))
    if iu < 0 or iv < 0 or iu >= width or iv >= height:
        return False
    row = height - 1 - iv
    if occupied[row, iu]:
        return False
    # Fast path: a lower bound of A's distance to every occupied cell, from the clearance field.
    offset = math.hypot(au - (iu + 0.5), av - (iv + 0.5))
    lower = clearance[row, iu] / resolution - offset - math.sqrt(0.5)
    travel = math.hypot(bu - au, bv - av)
    if lower > radius + travel:
        return True
    r2 = radius * radius
    u_lo = int(math.floor(min(au, bu) - radius))
    u_hi = int(math.floor(max(au, bu) + radius))
    v_lo = int(math.floor(min(av, bv) - radius))
    v_hi = int(math.floor(max(av, bv) + radius))
    for j in range(v_lo, v_hi + 1):
        for i in range(u_lo, u_hi + 1):
            if 0 <= i < width and 0 <= j < height and not occupied[height - 1 - j, i]:
                continue
            if _segment_box_dist2(au, av, bu, bv, float(i), float(j), i + 1.0, j + 1.0) < r2:
                return False
    return True


class CollisionChecker:
    """Exact disc-footprint collision tests against a world's occupancy grid.

    Parameters
    ----------
    world:
        The world; its ``occupied`` grid and cached ``clearance`` are used as they are.
    radius:
        Footprint radius (m).
    """

    def __init__(self, world: World, radius: float):
        self.world = world
        self.radius = float(radius)
        self._occupied = world.occupied
        self._clearance = np.ascontiguousarray(world.clearance)

    def path_free(self, start: ArrayLike, end: ArrayLike, inflate: float = 0.0) -> bool:
        """True when the disc moved straight from ``start`` to ``end`` (world xy, m) overlaps no occupied cell.

        ``inflate`` (m) is added to the radius (the arc's sagitta, for curved steps).
        """
        pts = np.empty((2, 2))
        pts[0] = np.asarray(start, dtype=np.float64)[:2]
        pts[1] = np.asarray(end, dtype=np.float64)[:2]
        (a, b) = world_to_map(self.world, pts).tolist()
        res = self.world.resolution
        return bool(
            _capsule_free(self._occupied, self._clearance, res, a[0], a[1], b[0], b[1], (self.radius + inflate) / res)
        )

    def disc_free(self, xy: ArrayLike) -> bool:
        """True when the footprint disc centred at ``xy`` (world, m) overlaps no occupied cell."""
        return self.path_free(xy, xy)


class Robot:
    """The true state of the simulated robot: pose (world frame) and velocity.

    Parameters
    ----------
    world:
        The world it drives in.
    config:
        Footprint and limits.
    dt:
        Step (s).
    pose:
        float64 ``[3]`` initial pose (world frame); it is not checked here (see :meth:`pose_free`).
    """

    def __init__(self, world: World, config: RobotConfig, dt: float, pose: ArrayLike):
        self.config = config
        self.dt = float(dt)
        self.collision = CollisionChecker(world, config.radius)
        self.pose: NDArray[np.float64] = np.array(pose, dtype=np.float64).reshape(3)
        self.velocity: tuple[float, float] = (0.0, 0.0)

    def pose_free(self) -> bool:
        """True when the footprint at the current pose overlaps no occupied cell."""
        return self.collision.disc_free(self.pose[:2])

    def step(self, command: tuple[float, float]) -> bool:
        """Drive one step towards velocity ``command`` = (v m/s, w rad/s); return True if stalled."""
        v, w = limit_velocity(self.velocity, command, self.config, self.dt)
        delta = arc_increment(v, w, self.dt)
        moved = compose1(self.pose, delta)
        stalled = False
        if v != 0.0 and not self.collision.path_free(self.pose[:2], moved[:2], arc_sagitta(v * self.dt, w * self.dt)):
            # Blocked: turn in place only, stop the linear motion.
            moved = self.pose.copy()
            moved[2] = wrap_angle1(float(self.pose[2]) + float(delta[2]))
            v = 0.0
            stalled = True
        self.pose = moved
        self.velocity = (v, w)
        return stalled
