"""Exact grid ray casting for the simulated laser, accelerated by a distance field.

The laser sees the world's occupancy grid as a set of closed unit squares (cells). A beam is a ray in
continuous map coordinates (u, v) in cells (:func:`slamtrials.worlds.world_to_map`: u to the right
along the columns, v up from the bottom edge). Its range is the exact distance at which the ray first
enters an occupied cell, capped at the laser's max range; cells outside the grid count as occupied, so
every ray stops at the image border.

Two kernels compute the same thing:

* :func:`cast_scan_dda`: the plain voxel traversal of Amanatides and Woo (1987), which visits every
  cell the ray crosses. The crossing distances are computed directly as ``(boundary - origin) / dir``
  for the integer cell boundary, not accumulated step by step, so a crossing's distance depends only
  on the boundary and the ray: no drift over long rays.
* :func:`cast_scan`: the same traversal, but it skips empty space by sphere tracing on a precomputed
  distance field (the Euclidean distance transform of the grid, in cells). If the cell the ray is in
  has distance ``d`` to the nearest occupied cell (centre to centre), every point of that cell is
  farther than ``d - sqrt(2)`` from every point of every occupied cell, so the ray can advance
  ``d - 1.5`` cells (``sqrt(2)`` plus a margin for float32 storage and rounding) without entering an
  occupied cell. Near walls it falls back to the exact traversal. Because the distance reported for a
  hit is always the crossing distance of the boundary through which the traversal enters the
  occupied cell, computed by the same formula, the accelerated kernel returns results bit-for-bit
  identical to the plain one (tests check this on random worlds).

Each kernel does a whole scan (all beams) in one call, on one core.
"""

from __future__ import annotations

import math
import weakref

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials.geometry import Pose1Like, compose1
from slamtrials.record import LaserGeometry
from slamtrials.sim.config import LaserConfig
from slamtrials.sim.unmapped import UnmappedScan, UnmappedThings
from slamtrials.worlds.world import World, world_to_map

__all__ = ["RaycastMap", "LaserModel", "cast_scan", "cast_scan_dda", "as_no_returns", "SAFETY_CELLS"]

#: Margin (cells) subtracted from the distance field before a jump: sqrt(2) (a point anywhere in the
#: current cell, an occupied square anywhere around its centre) plus slack for float32 storage.
SAFETY_CELLS = 1.5
#: Smallest jump (cells) worth taking; below it the exact traversal steps cell by cell.
_MIN_JUMP = 1.0


@njit(cache=True, fastmath=False, nogil=True)
def _crossing(gap, inverse):  # pragma: no cover - compiled
    """Ray parameter ``gap * inverse`` of the next boundary; 0 when the ray starts on it (``gap == 0``), also
    when the direction component is subnormal and its inverse overflowed to infinity (0 * inf is NaN)."""
    return 0.0 if gap == 0.0 else gap * inverse


@njit(cache=True, fastmath=False, nogil=True)
def _trace_beam(dist, ox, oy, dx, dy, max_t, accelerate):  # pragma: no cover - compiled
    """Distance (cells) along the ray ``o + t (dx, dy)`` at which it enters the first occupied cell.

    Returns ``max_t`` or more when nothing is entered before ``max_t``. The origin cell must be free.
    """
    height, width = dist.shape
    ix = int(math.floor(ox))
    iy = int(math.floor(oy))
    if dx > 0.0:
        step_x = 1
        off_x = 1.0
        inv_dx = 1.0 / dx
    elif dx < 0.0:
        step_x = -1
        off_x = 0.0
        inv_dx = 1.0 / dx
    else:
        step_x = 0
        off_x = 0.0
        inv_dx = 0.0
    if dy > 0.0:
        step_y = 1
        off_y = 1.0
        inv_dy = 1.0 / dy
    elif dy < 0.0:
        step_y = -1
        off_y = 0.0
        inv_dy = 1.0 / dy
    else:
        step_y = 0
        off_y = 0.0
        inv_dy = 0.0
    t = 0.0
    while True:
        if accelerate:
            # Sphere tracing: the ray at parameter t lies in cell (ix, iy); jump while that is safe.
            jump = dist[iy, ix] - SAFETY_CELLS
            while jump >= _MIN_JUMP:
                t = t + jump
                if t >= max_t:
                    return max_t
                # The cell of the new point. The ray is monotone in u and v, so the cell never moves
                # back against the direction of travel; rounding of the point could say otherwise
                # (e.g. a ray along a cell boundary), and following it would loop.
                jx = int(math.floor(ox + t * dx))
                jy = int(math.floor(oy + t * dy))
                ix = max(ix, jx) if step_x >= 0 else min(ix, jx)
                iy = max(iy, jy) if step_y >= 0 else min(iy, jy)
                if ix < 0 or iy < 0 or ix >= width or iy >= height:  # cannot happen (safe margin)
                    return t
                jump = dist[iy, ix] - SAFETY_CELLS
        # One exact traversal step: cross the nearer of the two next cell boundaries.
        tx = _crossing(ix + off_x - ox, inv_dx) if step_x != 0 else np.inf
        ty = _crossing(iy + off_y - oy, inv_dy) if step_y != 0 else np.inf
        if tx < ty:
            ix += step_x
            t = tx
        else:
            iy += step_y
            t = ty
        if t >= max_t:
            return max_t
        if ix < 0 or iy < 0 or ix >= width or iy >= height:
            return t
        if dist[iy, ix] <= 0.0:
            return t


@njit(cache=True, fastmath=False, nogil=True)
def _cast_scan(dist, ox, oy, theta, angles, max_t, resolution, max_range, accelerate, out):  # pragma: no cover
    height, width = dist.shape
    ix = int(math.floor(ox))
    iy = int(math.floor(oy))
    if ix < 0 or iy < 0 or ix >= width or iy >= height or dist[iy, ix] <= 0.0:
        for b in range(angles.shape[0]):
            out[b] = 0.0
        return
    for b in range(angles.shape[0]):
        a = theta + angles[b]
        t = _trace_beam(dist, ox, oy, math.cos(a), math.sin(a), max_t, accelerate)
        if t >= max_t:
            out[b] = max_range
        else:
            out[b] = min(t * resolution, max_range) + 0.0  # + 0.0 turns a -0.0 into 0.0


def _run(
    dist: NDArray[np.float32],
    origin_uv: Pose1Like,
    theta: float,
    angles: NDArray[np.float64],
    max_range: float,
    resolution: float,
    accelerate: bool,
    out: NDArray[np.float32] | None,
) -> NDArray[np.float32]:
    angles = np.ascontiguousarray(angles, dtype=np.float64)
    if out is None:
        out = np.empty(angles.shape[0], dtype=np.float32)
    ox, oy = float(origin_uv[0]), float(origin_uv[1])
    max_range = float(max_range)
    _cast_scan(
        dist, ox, oy, float(theta), angles, max_range / resolution, float(resolution), max_range, accelerate, out
    )
    return out


def cast_scan(
    dist: NDArray[np.float32],
    origin_uv: Pose1Like,
    theta: float,
    angles: NDArray[np.float64],
    max_range: float,
    resolution: float = 1.0,
    out: NDArray[np.float32] | None = None,
) -> NDArray[np.float32]:
    """Ranges of all beams of one scan, with distance-field acceleration.

    Parameters
    ----------
    dist:
        float32 ``[H, W]`` distance field of a :class:`RaycastMap` (index ``[iy, ix]``, iy up from the
        bottom edge; 0 = occupied).
    origin_uv:
        Laser origin (u, v) in map coordinates (cells).
    theta:
        Heading (rad) of the laser in the map frame (world heading minus the world origin's heading).
    angles:
        float64 ``[B]`` beam angles (rad) relative to ``theta``.
    max_range:
        Range cap in metres.
    resolution:
        Metres per cell (ranges are returned in metres; with 1.0 they are in cells).
    out:
        Optional float32 ``[B]`` output buffer.

    Returns
    -------
    float32 ``[B]`` ranges (m): the exact distance to the first occupied cell's boundary, or exactly
    ``max_range`` when no occupied cell is entered before it; 0 for every beam if the origin itself is
    in an occupied cell or outside the grid.
    """
    return _run(dist, origin_uv, theta, angles, max_range, resolution, True, out)


def cast_scan_dda(
    dist: NDArray[np.float32],
    origin_uv: Pose1Like,
    theta: float,
    angles: NDArray[np.float64],
    max_range: float,
    resolution: float = 1.0,
    out: NDArray[np.float32] | None = None,
) -> NDArray[np.float32]:
    """Same as :func:`cast_scan` with the plain cell-by-cell traversal (the reference; slower)."""
    return _run(dist, origin_uv, theta, angles, max_range, resolution, False, out)


def as_no_returns(readings: NDArray[np.float32], max_range: float) -> NDArray[np.float32]:
    """``readings`` float32 ``[B]`` (m) with every reading at or beyond ``max_range`` (m) set to ``+inf``, in place.

    The simulated laser reports a beam with no return as ROS REP 117 asks of a driver: ``+inf``, not a
    range (Stage reports its maximum, which a mapper cannot tell from a wall at that distance). Inside
    the simulator (the raycast and :mod:`slamtrials.sim.laser_errors`) a no-return is ``max_range``;
    this is the one place where it becomes ``+inf``. Every consumer takes a reading ``>= range_max`` or
    ``+inf`` for a no-return and skips it (:mod:`slamtrials.slam.gridmap`).
    """
    readings[readings >= np.float32(max_range)] = np.inf
    return readings


class RaycastMap:
    """A world's grid prepared for ray casting: a float32 distance field, flipped so rows go up.

    ``dist[iy, ix]`` is the distance (in cells) from the centre of the cell covering
    ``ix <= u < ix + 1, iy <= v < iy + 1`` to the centre of the nearest occupied cell, cells outside
    the grid counting as occupied; 0 for occupied cells. It comes from the world's cached
    :attr:`~slamtrials.worlds.World.clearance`, so the transform is computed once per world; it takes
    4 bytes per cell (64 MB for a 4000 x 4000 grid). Use :meth:`for_world` to share one map between
    simulators of the same world.

    Attributes
    ----------
    dist:
        float32 ``[H, W]`` distance field in cells, C-contiguous, read-only.
    resolution:
        Metres per cell.
    """

    _cache: weakref.WeakKeyDictionary[World, RaycastMap] = weakref.WeakKeyDictionary()

    def __init__(self, world: World):
        cells = np.asarray(world.clearance, dtype=np.float64) / world.resolution
        # Free cells are at least one cell from any occupied cell centre; guard against rounding.
        dist = np.where(world.occupied, 0.0, np.maximum(cells, 1.0)).astype(np.float32)
        self.dist: NDArray[np.float32] = np.ascontiguousarray(dist[::-1])
        self.dist.setflags(write=False)
        self.resolution = float(world.resolution)
        # No reference back to the world: the per-world cache holds the world weakly.

    @classmethod
    def for_world(cls, world: World) -> RaycastMap:
        """The (cached) map of ``world``; built on first use and kept while the world lives."""
        rmap = cls._cache.get(world)
        if rmap is None:
            rmap = cls(world)
            cls._cache[world] = rmap
        return rmap

    @property
    def shape(self) -> tuple[int, int]:
        """(H, W) of the grid."""
        return self.dist.shape


class LaserModel:
    """The simulated laser of one world: beam geometry, mount, max range and range noise.

    Parameters
    ----------
    world:
        The world to scan.
    config:
        Laser settings.
    """

    def __init__(self, world: World, config: LaserConfig):
        self.world = world
        self.config = config
        self.map = RaycastMap.for_world(world)
        self.angles: NDArray[np.float64] = np.ascontiguousarray(config.angles)
        self._mount = np.asarray(config.mount, dtype=np.float64)
        self._things = UnmappedThings()  # things not in the map that stay (``short_lifetime``)

    @property
    def num_beams(self) -> int:
        """Number of beams B."""
        return int(self.angles.shape[0])

    def laser_pose(self, pose: Pose1Like) -> NDArray[np.float64]:
        """float64 ``[3]`` world pose of the laser when the robot base is at ``pose`` (world frame)."""
        return compose1(pose, self._mount)

    def true_ranges(self, pose: Pose1Like) -> NDArray[np.float32]:
        """Noise-free ranges float32 ``[B]`` (m) seen from robot base pose ``pose`` (world frame, ``[3]``)."""
        lp = self.laser_pose(pose)
        uv = world_to_map(self.world, lp[:2])
        theta = float(lp[2] - self.world.origin[2])
        return cast_scan(self.map.dist, uv, theta, self.angles, self.config.max_range, self.map.resolution)

    def scan(self, pose: Pose1Like, rng: np.random.Generator, t: float | None = None) -> NDArray[np.float32]:
        """A laser reading float32 ``[B]`` (m) from robot base pose ``pose`` (world frame).

        With any error model on (range noise, dropouts, short readings), the true ranges go through
        :func:`slamtrials.sim.laser_errors.apply_laser_errors`, which draws a fixed number of deviates
        per scan from ``rng``. Otherwise the readings are the true ranges, raised to ``min_range``, and
        ``rng`` is not used. A beam with no return (nothing hit within ``max_range``, or a dropout) reads
        ``+inf``, as ROS REP 117 asks of a laser driver (:func:`as_no_returns`). ``t`` (s), the scan's time, is needed when ``short_lifetime > 0``: the things
        not in the map that earlier scans saw stay in this model (:mod:`slamtrials.sim.unmapped`).
        """
        from slamtrials.sim.laser_errors import apply_laser_errors, incidence_cosines

        cfg = self.config
        lp = self.laser_pose(pose)
        uv = world_to_map(self.world, lp[:2])
        theta = float(lp[2] - self.world.origin[2])
        ranges = cast_scan(self.map.dist, uv, theta, self.angles, cfg.max_range, self.map.resolution)
        if cfg.has_errors:
            incidence = None
            if cfg.dropout_grazing > 0.0:
                cells = ranges.astype(np.float64) / self.map.resolution
                incidence = incidence_cosines((float(uv[0]), float(uv[1])), theta, self.angles, cells)
            unmapped = None
            if cfg.short_lifetime > 0.0 and cfg.short_rate > 0.0:
                if t is None:
                    raise ValueError("a laser with short_lifetime > 0 needs each scan's time t")
                unmapped = UnmappedScan(self._things, lp, self.angles, cfg.angular_resolution, float(t))
            return as_no_returns(apply_laser_errors(ranges, cfg, rng, incidence, unmapped), cfg.max_range)
        if cfg.min_range > 0.0:
            np.maximum(ranges, np.float32(cfg.min_range), out=ranges)
        return as_no_returns(ranges, cfg.max_range)

    def geometry(self) -> LaserGeometry:
        """The laser's geometry, as :class:`~slamtrials.record.RunRecord` records it."""
        return self.config.geometry()
