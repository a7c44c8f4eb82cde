"""Counting occupancy-grid maps with free-space ray tracing, as GMapping publishes its map.

Each cell counts ``visits`` (beams that passed through it or ended in it) and ``hits`` (beams that
ended in it). The published map (:meth:`GridMap.occupancy`) says occupied where
``hits / visits > occ_thresh``, free where visited otherwise, unknown where never visited
(spec/gmapping.md, section 5).

How a beam of range ``r`` (m) is treated, with the laser's ``range_min``, ``range_max`` and the usable
range ``max_urange`` (<= ``range_max``):

* ``r`` NaN, ``-inf`` or ``r <= range_min`` (including 0): no information, the beam marks nothing;
* ``range_min < r < range_max`` and ``r <= max_urange``: a return. Every cell the segment from the
  laser to the endpoint crosses, before the endpoint's cell, gets a visit; the endpoint's cell gets a
  visit and a hit;
* ``max_urange < r < range_max`` (a return too far to trust): cut at ``max_urange``; the cells before
  the cut point's cell get a visit, nothing is marked occupied;
* ``r >= range_max`` or ``+inf`` (no return, ROS REP 117): nothing, like a NaN. A beam without a
  return says nothing about where the wall is, so it marks no free space either: slam_gmapping skips
  it (its ``maxRange`` defaults to the laser's ``range_max - 0.01``, and the seed paper's maxRange of
  60 m lay below its Stage laser's 80 m), as do slam_karto and slam_toolbox (readings at or beyond the
  sensor's maximum range). Tracing such beams as free space up to ``max_urange`` would draw free space
  through every wall the laser missed a return from (dark, glossy or glass surfaces).

Cells are traversed exactly (Amanatides and Woo): every cell the segment passes through, in order.

Coordinates. Cells are anchored at the map frame's origin: global cell ``(i, j)`` covers
``[i res, (i + 1) res) x [j res, (j + 1) res)``. The map holds a window of global cells that grows in
chunks of :attr:`GridMap.chunk` cells when a scan reaches outside, so a world point keeps its cell for
the whole run. Internally arrays are ``[row from the bottom, column]``; :meth:`GridMap.occupancy` flips
them into the ROS/PNG orientation (row 0 at the top). These conversions are the slam layer's own (it may
not import ``worlds``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from slamtrials import stablemath
from slamtrials.geometry import compose1
from slamtrials.record import LaserGeometry
from slamtrials.slam.base import FREE, OCCUPIED, UNKNOWN, OccupancyGrid

__all__ = ["GridMap", "scan_endpoints", "beam_endpoints", "classify", "DEFAULT_CHUNK"]

#: Cells added on a side when a map grows (plus what the scan needs).
DEFAULT_CHUNK = 64


@njit(cache=True, nogil=True)
def _integrate_scans(hits, visits, col0, row0, ou, ov, eu, ev, usable, hit, weights):  # pragma: no cover - compiled
    """Add the visits and hits of ``M`` scans, scan ``m`` counted ``weights[m]`` times (-1 takes a scan back out).

    ``(ou[m], ov[m])`` is scan ``m``'s laser in continuous GLOBAL cell coordinates (cells: u right, v up,
    from the map frame's origin); ``eu, ev`` float64 ``[M, B]`` the beam endpoints (already cut) in the same
    coordinates; ``usable`` bool ``[M, B]`` the beams that carry information (the others are skipped);
    ``hit`` bool ``[M, B]`` whether the endpoint's cell is an obstacle. The traversal is done in global
    cells and only the indexing subtracts the window's corner (``col0``, ``row0``), so a scan is traced
    the same way however the window grew in between (which is what makes taking it back out exact).
    Cells outside the window are skipped.
    """
    height, width = visits.shape
    for m in range(eu.shape[0]):
        weight = weights[m]
        x0 = int(math.floor(ou[m]))
        y0 = int(math.floor(ov[m]))
        for b in range(eu.shape[1]):
            if not usable[m, b]:
                continue
            dx = eu[m, b] - ou[m]
            dy = ev[m, b] - ov[m]
            jx = int(math.floor(eu[m, b]))
            jy = int(math.floor(ev[m, b]))
            ix = x0
            iy = y0
            step_x = 1 if dx > 0.0 else -1
            step_y = 1 if dy > 0.0 else -1
            if dx != 0.0:
                delta_x = abs(1.0 / dx)
                t_x = ((ix + 1.0 - ou[m]) if dx > 0.0 else (ou[m] - ix)) * delta_x
            else:
                delta_x = math.inf
                t_x = math.inf
            if dy != 0.0:
                delta_y = abs(1.0 / dy)
                t_y = ((iy + 1.0 - ov[m]) if dy > 0.0 else (ov[m] - iy)) * delta_y
            else:
                delta_y = math.inf
                t_y = math.inf
            steps = abs(jx - ix) + abs(jy - iy)
            for _ in range(steps):
                if 0 <= iy - row0 < height and 0 <= ix - col0 < width:
                    visits[iy - row0, ix - col0] += weight
                if ix == jx or (iy != jy and t_y <= t_x):
                    iy += step_y
                    t_y += delta_y
                else:
                    ix += step_x
                    t_x += delta_x
            if hit[m, b] and 0 <= jy - row0 < height and 0 <= jx - col0 < width:
                visits[jy - row0, jx - col0] += weight
                hits[jy - row0, jx - col0] += weight


@njit(cache=True, nogil=True)
def _classify(hits, visits, occ_thresh, flip):  # pragma: no cover - compiled
    """int8 cells of :func:`classify`; with ``flip`` in the ROS orientation (row 0 at the top). Without
    branches, so that the compiler vectorizes the row loop: GMapping's maps with long free rays hold
    millions of cells, classified on every map update."""
    height, width = visits.shape
    grid = np.empty((height, width), dtype=np.int8)
    unknown, occupied, free = np.int8(UNKNOWN), np.int8(OCCUPIED), np.int8(FREE)
    for r in range(height):
        out = height - 1 - r if flip else r
        for c in range(width):
            v = visits[r, c]
            seen = occupied if hits[r, c] > occ_thresh * v else free
            grid[out, c] = unknown if v <= 0 else seen
    return grid


def scan_endpoints(
    laser_poses: ArrayLike,
    ranges: ArrayLike,
    angles: ArrayLike,
    *,
    range_min: float,
    range_max: float,
    max_urange: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_]]:
    """Where the traced segment of every beam of ``M`` scans ends, and what it marks (module docstring).

    Parameters
    ----------
    laser_poses:
        ``[M, 3]`` poses of the laser in the map frame (m, rad).
    ranges:
        ``[M, B]`` ranges (m).
    angles:
        ``[B]`` beam angles in the laser frame (rad).
    range_min, range_max, max_urange:
        The laser's limits and the usable range (m).

    Returns
    -------
    x, y:
        float64 ``[M, B]`` map-frame end points (m); meaningful where ``usable``.
    usable:
        bool ``[M, B]``: the beam carries information.
    hit:
        bool ``[M, B]``: the end point is a return (marks a hit), not a cut; False where not usable.
    """
    r = np.asarray(ranges, dtype=np.float64)
    a = np.asarray(angles, dtype=np.float64)
    pose = np.asarray(laser_poses, dtype=np.float64)
    usable = (r > range_min) & (r < range_max)  # False for NaN and for no-returns (>= range_max, +inf)
    length = np.where(usable, np.minimum(r, max_urange), 0.0)
    hit = usable & (r <= max_urange)
    heading = pose[:, 2:3] + a
    return pose[:, 0:1] + length * stablemath.cos(heading), pose[:, 1:2] + length * stablemath.sin(heading), usable, hit


def beam_endpoints(
    laser_pose: ArrayLike,
    ranges: ArrayLike,
    angles: ArrayLike,
    *,
    range_min: float,
    range_max: float,
    max_urange: float,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """:func:`scan_endpoints` of one scan, only the beams that carry information.

    Returns float64 ``[K, 2]`` map-frame end points (m) of the ``K`` usable beams and bool ``[K]`` whether
    each is a return (marks a hit), not a cut.
    """
    x, y, usable, hit = scan_endpoints(
        np.asarray(laser_pose, dtype=np.float64).reshape(1, 3),
        np.asarray(ranges, dtype=np.float64).reshape(1, -1),
        angles,
        range_min=range_min,
        range_max=range_max,
        max_urange=max_urange,
    )
    return np.column_stack([x[usable], y[usable]]), hit[usable]


def classify(hits: NDArray[np.int32], visits: NDArray[np.int32], occ_thresh: float) -> NDArray[np.int8]:
    """Trinary cells from counts: 100 where ``hits / visits > occ_thresh``, 0 where visited, else -1."""
    return _classify(hits, visits, float(occ_thresh), False)


class GridMap:
    """A growable hit/visit counting grid in the map frame.

    Parameters
    ----------
    resolution:
        Cell size (m).
    chunk:
        Cells added beyond what a scan needs whenever the window grows.

    Attributes
    ----------
    hits, visits:
        int32 ``[H, W]`` counts, row 0 at the BOTTOM (global cell row :attr:`row0`).
    col0, row0:
        Global cell index of window column 0 and row 0.
    """

    def __init__(self, resolution: float, *, chunk: int = DEFAULT_CHUNK):
        if not (math.isfinite(resolution) and resolution > 0):
            raise ValueError(f"resolution must be positive metres, got {resolution!r}")
        self.resolution = float(resolution)
        self.chunk = int(chunk)
        self.col0 = 0
        self.row0 = 0
        self.hits = np.zeros((0, 0), dtype=np.int32)
        self.visits = np.zeros((0, 0), dtype=np.int32)

    @property
    def origin(self) -> NDArray[np.float64]:
        """Map-frame pose of the window's lower-left corner (m, m, 0)."""
        return np.array([self.col0 * self.resolution, self.row0 * self.resolution, 0.0])

    def cell_of(self, xy: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """Global cell indices (column, row from the bottom) of map-frame points ``[..., 2]`` (m)."""
        p = np.floor(np.asarray(xy, dtype=np.float64) * (1.0 / self.resolution)).astype(np.intp)  # as the kernel
        return p[..., 0], p[..., 1]

    def ensure(self, xy: ArrayLike) -> None:
        """Grow the window (keeping every cell's world position) so it holds every point ``[N, 2]`` (m)."""
        cols, rows = self.cell_of(np.asarray(xy, dtype=np.float64).reshape(-1, 2))
        if cols.size:
            self._grow_for([(int(cols.min()), int(cols.max()), int(rows.min()), int(rows.max()))])

    def _grow_for(self, boxes: Sequence[Sequence[int]]) -> None:
        """Grow the window as :meth:`ensure` would for each box ``(col min, col max, row min, row max)``
        (global cells) in turn, copying the counts once."""
        col0, row0 = self.col0, self.row0
        height, width = self.visits.shape
        for lo_c, hi_c, lo_r, hi_r in boxes:
            if height and width and lo_c >= col0 and hi_c < col0 + width and lo_r >= row0 and hi_r < row0 + height:
                continue
            if height and width:
                lo_c, hi_c = min(lo_c, col0), max(hi_c, col0 + width - 1)
                lo_r, hi_r = min(lo_r, row0), max(hi_r, row0 + height - 1)
            col0, row0 = lo_c - self.chunk, lo_r - self.chunk
            height, width = hi_r + self.chunk + 1 - row0, hi_c + self.chunk + 1 - col0
        if (col0, row0, height, width) == (self.col0, self.row0, *self.visits.shape):
            return
        hits, visits = np.zeros((height, width), np.int32), np.zeros((height, width), np.int32)
        r, c = self.row0 - row0, self.col0 - col0
        old_height, old_width = self.visits.shape
        hits[r : r + old_height, c : c + old_width] = self.hits
        visits[r : r + old_height, c : c + old_width] = self.visits
        self.hits, self.visits, self.col0, self.row0 = hits, visits, col0, row0

    def integrate(
        self,
        laser_pose: ArrayLike,
        ranges: ArrayLike,
        angles: ArrayLike,
        *,
        range_min: float,
        range_max: float,
        max_urange: float,
        weight: int = 1,
    ) -> None:
        """Trace one scan from ``laser_pose`` (map frame, ``[3]``) into the counts (see the module).

        ``weight`` -1 removes a scan integrated before from the same pose (counts are exact integers).
        """
        self.integrate_many(
            np.asarray(laser_pose, dtype=np.float64).reshape(1, 3),
            np.asarray(ranges, dtype=np.float64).reshape(1, -1),
            angles,
            np.array([int(weight)]),
            range_min=range_min,
            range_max=range_max,
            max_urange=max_urange,
        )

    def integrate_many(
        self,
        laser_poses: ArrayLike,
        ranges: ArrayLike,
        angles: ArrayLike,
        weights: ArrayLike,
        *,
        range_min: float,
        range_max: float,
        max_urange: float,
    ) -> None:
        """Trace ``M`` scans, scan ``m`` from ``laser_poses[m]`` (map frame, ``[M, 3]``) with ranges
        ``ranges[m]`` (``[M, B]``, m) counted ``weights[m]`` times (int ``[M]``; -1 removes it): the same
        counts and window as :meth:`integrate` called for each scan in turn, in one compiled call."""
        poses = np.asarray(laser_poses, dtype=np.float64).reshape(-1, 3)
        if poses.shape[0] == 0:
            return
        x, y, usable, hit = scan_endpoints(
            poses, ranges, angles, range_min=range_min, range_max=range_max, max_urange=max_urange
        )
        scale = 1.0 / self.resolution
        eu, ev = x * scale, y * scale
        ou, ov = poses[:, 0] * scale, poses[:, 1] * scale
        # each scan's box of cells (its laser and its usable end points), as ensure() computes it
        origin_c, origin_r = np.floor(ou)[:, None], np.floor(ov)[:, None]
        cols = np.hstack([origin_c, np.where(usable, np.floor(eu), origin_c)])
        rows = np.hstack([origin_r, np.where(usable, np.floor(ev), origin_r)])
        boxes = np.column_stack([cols.min(axis=1), cols.max(axis=1), rows.min(axis=1), rows.max(axis=1)])
        self._grow_for(boxes.astype(np.int64).tolist())
        _integrate_scans(
            self.hits,
            self.visits,
            self.col0,
            self.row0,
            ou,
            ov,
            eu,
            ev,
            usable,
            hit,
            np.asarray(weights, dtype=np.int64).reshape(-1),
        )

    def integrate_scans(
        self,
        laser_poses: Sequence[NDArray[np.float64]],
        scans: Sequence[NDArray[np.float32]],
        weights: Sequence[int],
        laser: LaserGeometry,
        *,
        max_urange: float,
    ) -> None:
        """Trace ``scans[k]`` taken from laser pose ``laser_poses[k]`` (map frame) with weight ``weights[k]``
        (+1 adds a scan, -1 takes it out again), in runs of equal beam count: one compiled call per run."""
        start = 0
        while start < len(scans):
            end = start + 1
            while end < len(scans) and scans[end].shape == scans[start].shape:
                end += 1
            self.integrate_many(
                np.array(laser_poses[start:end]),
                np.stack(scans[start:end]),
                laser.beam_angles(scans[start].shape[0]),
                np.array(weights[start:end]),
                range_min=laser.range_min,
                range_max=laser.range_max,
                max_urange=max_urange,
            )
            start = end

    def integrate_frame(
        self, base_pose: ArrayLike, ranges: ArrayLike, laser: LaserGeometry, *, max_urange: float | None = None
    ) -> None:
        """Trace a scan taken with the robot base at ``base_pose`` (map frame) by a laser of geometry ``laser``.

        ``max_urange`` defaults to the laser's ``range_max``.
        """
        r = np.asarray(ranges)
        laser_pose = compose1(np.asarray(base_pose, dtype=np.float64), np.asarray(laser.mount, dtype=np.float64))
        range_max = laser.range_max
        self.integrate(
            laser_pose,
            r,
            laser.beam_angles(r.shape[0]),
            range_min=laser.range_min,
            range_max=range_max,
            max_urange=range_max if max_urange is None else min(float(max_urange), range_max),
        )

    def occupancy(self, occ_thresh: float = 0.25) -> OccupancyGrid:
        """The trinary map (:func:`classify`), flipped to row 0 at the top, with the window's origin."""
        grid = _classify(self.hits, self.visits, float(occ_thresh), True)
        return OccupancyGrid(grid=grid, resolution=self.resolution, origin=self.origin)
