"""The explorer's own evidence of free and occupied space, from the laser returns it saw itself.

Why. The explorer plans on the map the SLAM algorithm returns, and an algorithm under test may trace
beams without a return as free space out to its usable range (the built-in ones skip them, as
slam_gmapping does: :mod:`slamtrials.slam.gridmap`). A real laser returns nothing from some surfaces in
reach (dark, glossy or glass; 3.6 % of the beams in the MIT CSAIL log, and the ``realistic`` profile's
dropouts), so every such beam would paint a line of free cells *through* the wall it missed: a halo of
free space around the building, full of frontier cells, and walls worn into gaps. A frontier explorer
would chase the halo through the gaps. This layer keeps exploration sane on such maps.

What. :class:`EvidenceLayer` counts, on a grid anchored at the map frame's origin with the map's
resolution, the cells each *return* of the explorer's scans crossed (passes) and ended in (hits),
traced from the SLAM pose the explorer drove by. Beams with no return count for nothing, and the
scans are those of :func:`~slamtrials.explore.scanfilter.confirmed_ranges` (isolated returns
dropped). :meth:`EvidenceLayer.view` then corrects the SLAM map for planning and frontiers, as the
obstacle layer of a ROS costmap corrects a static map:

* a cell the map calls free but the explorer's returns hit at least ``min_hits`` times and in more
  than ``occupied_ratio`` of the times it was crossed or hit, and that a beam of the explorer's
  without a return between two beams that returned crossed (within ``no_return_range`` of the
  laser), is occupied: a gap such beams wore into a wall. Without the last condition the layer would also put walls where the map has
  none because the pose the explorer drove by and the map's best particle differ (by 0.1 to 0.2 m
  at times, even with ``paper``: office_small_01, seed 3, changed its run); with a noise-free laser
  a beam goes without a return only where it looks into the open, with its neighbours (runs of such
  beams down school_medium_01's long corridors changed its ``paper`` runs until they were left
  out), so ``paper``'s maps are left alone;
* a cell the map calls free with no cell the explorer's returns crossed or hit within
  ``free_distance`` is unknown (free space that only rays without a return vouch for).

Cells the map calls unknown or occupied are left as they are, so with a noise-free laser (``paper``)
the view is the map itself except where the two disagree, which is rare (``docs/exploration.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from slamtrials.explore.follower import _beam_directions
from slamtrials.explore.gridframe import map_arrays
from slamtrials.record import LaserGeometry

__all__ = ["EvidenceLayer", "MapView"]

_CHUNK = 64  # cells added on a side when the layer grows


@dataclass(frozen=True, eq=False)
class MapView:
    """A map as the explorer plans on it: ``grid`` int8 ``[H, W]`` (row 0 at the top), ``resolution``
    (m) and ``origin`` float64 ``[3]`` (map-frame pose of the lower-left corner), like the SLAM map."""

    grid: NDArray[np.int8]
    resolution: float
    origin: NDArray[np.float64]


@njit(cache=True, nogil=True)
def _trace(hits, passes, seen, near, gx0, gy0, sx, sy, ex, ey, reach):  # pragma: no cover - compiled
    """Add the beams from (sx, sy) to the endpoints (ex[k], ey[k]) (cell units, global): every cell a beam
    crosses before its endpoint's gets a pass, the endpoint's a hit (exact traversal, Amanatides and
    Woo). A cell first crossed or hit marks ``near`` within ``reach`` cells (Chebyshev) as seen."""
    height, width = hits.shape
    for k in range(ex.shape[0]):
        cx = int(math.floor(sx))
        cy = int(math.floor(sy))
        tx = int(math.floor(ex[k]))
        ty = int(math.floor(ey[k]))
        dx = ex[k] - sx
        dy = ey[k] - sy
        step_x = 1 if dx > 0 else -1
        step_y = 1 if dy > 0 else -1
        t_dx = abs(1.0 / dx) if dx != 0.0 else np.inf
        t_dy = abs(1.0 / dy) if dy != 0.0 else np.inf
        if dx > 0:
            t_x = (cx + 1 - sx) * t_dx
        elif dx < 0:
            t_x = (sx - cx) * t_dx
        else:
            t_x = np.inf
        if dy > 0:
            t_y = (cy + 1 - sy) * t_dy
        elif dy < 0:
            t_y = (sy - cy) * t_dy
        else:
            t_y = np.inf
        steps = abs(tx - cx) + abs(ty - cy)
        for _ in range(steps + 1):
            r = cy - gy0
            c = cx - gx0
            last = cx == tx and cy == ty
            if 0 <= r < height and 0 <= c < width:
                if last:
                    hits[r, c] += 1
                else:
                    passes[r, c] += 1
                if not seen[r, c]:
                    seen[r, c] = True
                    for rr in range(max(r - reach, 0), min(r + reach + 1, height)):
                        for cc in range(max(c - reach, 0), min(c + reach + 1, width)):
                            near[rr, cc] = True
            if last:
                break
            if t_x < t_y:
                t_x += t_dx
                cx += step_x
            else:
                t_y += t_dy
                cy += step_y


@njit(cache=True, nogil=True)
def _trace_open(crossed, gx0, gy0, sx, sy, ex, ey):  # pragma: no cover - compiled
    """Mark every cell the segments from (sx, sy) to (ex[k], ey[k]) (cell units, global) cross."""
    height, width = crossed.shape
    for k in range(ex.shape[0]):
        cx = int(math.floor(sx))
        cy = int(math.floor(sy))
        tx = int(math.floor(ex[k]))
        ty = int(math.floor(ey[k]))
        dx = ex[k] - sx
        dy = ey[k] - sy
        step_x = 1 if dx > 0 else -1
        step_y = 1 if dy > 0 else -1
        t_dx = abs(1.0 / dx) if dx != 0.0 else np.inf
        t_dy = abs(1.0 / dy) if dy != 0.0 else np.inf
        t_x = (cx + 1 - sx) * t_dx if dx > 0 else ((sx - cx) * t_dx if dx < 0 else np.inf)
        t_y = (cy + 1 - sy) * t_dy if dy > 0 else ((sy - cy) * t_dy if dy < 0 else np.inf)
        for _ in range(abs(tx - cx) + abs(ty - cy) + 1):
            r = cy - gy0
            c = cx - gx0
            if 0 <= r < height and 0 <= c < width:
                crossed[r, c] = True
            if cx == tx and cy == ty:
                break
            if t_x < t_y:
                t_x += t_dx
                cx += step_x
            else:
                t_y += t_dy
                cy += step_y


@njit(cache=True, nogil=True, inline="always")
def _unknown_if_free(grid, out, row, start, stop):  # pragma: no cover - compiled
    """``out[row, start:stop]`` = ``grid``'s cells there with the free ones (0 <= value < 50) made unknown;
    returns how many were free. Without branches, so that the compiler vectorizes it (an integer
    count: the same in any order)."""
    count = 0
    start = max(start, 0)
    if stop <= start:
        return 0
    r = np.uint64(row)
    for col in range(np.uint64(start), np.uint64(stop)):  # unsigned: no negative-index wrap-around
        value = grid[r, col]
        free = value >= 0 and value < 50
        out[r, col] = -1 if free else value
        count += 1 if free else 0
    return count


@njit(cache=True, nogil=True)
def _correct(
    grid, hits, passes, near, crossed, r_off, c_off, row0, row1, col0, col1, min_hits, ratio
):  # pragma: no cover - compiled
    """int8 copy of the whole map ``grid`` (row 0 at the top) corrected by the layer (module docstring),
    the number of cells changed inside the layer's window (rows ``row0:row1``, columns ``col0:col1``) and
    the number of free cells outside it (made unknown). Window cell (row, col) is layer cell
    (r_off - (row - row0), c_off + (col - col0)). One pass over the map: a building mapped with long
    free rays holds millions of cells, almost all outside the layer."""
    height, width = grid.shape
    lh, lw = hits.shape
    out = np.empty_like(grid)
    changed = 0
    outside = 0
    for row in range(height):
        if not row0 <= row < row1:
            outside += _unknown_if_free(grid, out, row, 0, width)
            continue
        outside += _unknown_if_free(grid, out, row, 0, min(col0, width))
        outside += _unknown_if_free(grid, out, row, max(col1, col0), width)
        lr = r_off - (row - row0)
        for col in range(max(col0, 0), min(col1, width)):
            value = grid[row, col]
            out[row, col] = value
            if value < 0 or value >= 50:
                continue
            lc = c_off + (col - col0)
            if not (0 <= lr < lh and 0 <= lc < lw) or not near[lr, lc]:
                out[row, col] = -1
                changed += 1
                continue
            h = hits[lr, lc]
            if h >= min_hits and h > ratio * (h + passes[lr, lc]) and crossed[lr, lc]:
                out[row, col] = 100
                changed += 1
    return out, changed, outside


class EvidenceLayer:
    """Passes and hits of the explorer's own laser returns, and the map corrected by them (module docstring).

    Parameters
    ----------
    min_hits, occupied_ratio, free_distance, no_return_range:
        See the module docstring (counts, share, metres, metres).
    """

    def __init__(self, min_hits: int, occupied_ratio: float, free_distance: float, no_return_range: float = 8.0):
        self.no_return_range = float(no_return_range)
        self.min_hits = int(min_hits)
        self.occupied_ratio = float(occupied_ratio)
        self.free_distance = float(free_distance)
        self.reset()

    def reset(self) -> None:
        """Forget every scan."""
        self.resolution: float | None = None
        self.hits = np.zeros((0, 0), dtype=np.int32)
        self.passes = np.zeros((0, 0), dtype=np.int32)
        self.seen = np.zeros((0, 0), dtype=np.bool_)
        self.near = np.zeros((0, 0), dtype=np.bool_)
        self.crossed = np.zeros((0, 0), dtype=np.bool_)  # by a beam without a return
        self.gx0 = 0  # global column of layer column 0
        self.gy0 = 0  # global row (from the bottom) of layer row 0
        self.scans = 0  # scans with at least one return; the map is corrected only once there was one

    def _grow(self, gx_lo: int, gx_hi: int, gy_lo: int, gy_hi: int) -> None:
        """Make the layer cover global cells ``gx_lo..gx_hi`` x ``gy_lo..gy_hi`` (inclusive)."""
        height, width = self.hits.shape
        if (
            height
            and gx_lo >= self.gx0
            and gy_lo >= self.gy0
            and gx_hi < self.gx0 + width
            and gy_hi < self.gy0 + height
        ):
            return
        if height:
            gx_lo, gy_lo = min(gx_lo, self.gx0), min(gy_lo, self.gy0)
            gx_hi, gy_hi = max(gx_hi, self.gx0 + width - 1), max(gy_hi, self.gy0 + height - 1)
        gx_lo, gy_lo, gx_hi, gy_hi = gx_lo - _CHUNK, gy_lo - _CHUNK, gx_hi + _CHUNK, gy_hi + _CHUNK
        shape = (gy_hi - gy_lo + 1, gx_hi - gx_lo + 1)
        r, c = self.gy0 - gy_lo, self.gx0 - gx_lo
        names = (
            ("hits", np.int32),
            ("passes", np.int32),
            ("seen", np.bool_),
            ("near", np.bool_),
            ("crossed", np.bool_),
        )
        for name, dtype in names:
            old = getattr(self, name)
            new = np.zeros(shape, dtype=dtype)
            new[r : r + height, c : c + width] = old
            setattr(self, name, new)
        self.gx0, self.gy0 = gx_lo, gy_lo

    def add_scan(self, pose: ArrayLike, ranges: ArrayLike, laser: LaserGeometry, resolution: float) -> None:
        """Count the returns of one scan (``ranges`` ``[B]`` m, NaN for dropped beams) seen from ``pose``
        (float64 ``[3]``, the robot base in the map frame) on a grid of ``resolution`` m."""
        if self.resolution is None or not math.isclose(self.resolution, resolution, rel_tol=1e-9):
            self.reset()
            self.resolution = float(resolution)
        r = np.ascontiguousarray(ranges, dtype=np.float64)
        cos, sin = _beam_directions(r.shape[0], laser)
        valid = (r > laser.range_min) & (r < laser.range_max)  # False for NaN
        none = r >= laser.range_max  # no return (False for NaN: a dropped beam says nothing)
        # only a beam without a return between two that returned can have worn a gap into a wall: a
        # laser looking into the open (a corridor longer than its range) loses runs of beams
        isolated = np.zeros_like(none)
        isolated[1:-1] = none[1:-1] & valid[:-2] & valid[2:]
        none = isolated
        if not valid.any() and not none.any():
            return
        x, y, th = (float(v) for v in np.asarray(pose, dtype=np.float64)[:3])
        ct, st = math.cos(th), math.sin(th)
        mx, my = laser.mount[0], laser.mount[1]
        sx, sy = x + ct * mx - st * my, y + st * mx + ct * my
        length = np.where(valid, r, min(self.no_return_range, laser.range_max))
        use = valid | none
        bx, by = mx + length[use] * cos[use], my + length[use] * sin[use]
        ex = (x + ct * bx - st * by) / resolution
        ey = (y + st * bx + ct * by) / resolution
        sx, sy = sx / resolution, sy / resolution
        self._grow(
            math.floor(min(sx, float(ex.min()))),
            math.floor(max(sx, float(ex.max()))),
            math.floor(min(sy, float(ey.min()))),
            math.floor(max(sy, float(ey.max()))),
        )
        reach = max(math.ceil(self.free_distance / resolution - 1e-9), 0)
        returns = valid[use]
        _trace(
            self.hits, self.passes, self.seen, self.near, self.gx0, self.gy0, sx, sy, ex[returns], ey[returns], reach
        )
        if self.no_return_range > 0.0 and not returns.all():
            _trace_open(self.crossed, self.gx0, self.gy0, sx, sy, ex[~returns], ey[~returns])
        self.scans += int(returns.any())

    def view(self, occupancy: Any) -> Any:
        """The map corrected by the layer (a :class:`MapView` on the map's own cells and origin), or
        ``occupancy`` itself when nothing changes (or the layer cannot be placed on it)."""
        grid, resolution, origin = map_arrays(occupancy)
        if self.resolution is None or self.scans == 0 or origin[2] != 0.0:
            return occupancy
        if not math.isclose(self.resolution, resolution, rel_tol=1e-9):
            return occupancy
        height = grid.shape[0]
        # map cell (row, col) covers global column gcol0 + col and global row grow0 + height - 1 - row
        gcol0 = math.floor(origin[0] / resolution + 0.5)
        grow0 = math.floor(origin[1] / resolution + 0.5)
        if (
            abs(gcol0 * resolution - origin[0]) > 1e-6 * resolution
            or abs(grow0 * resolution - origin[1]) > 1e-6 * resolution
        ):
            return occupancy  # the map's cells do not line up with the layer's
        lh, lw = self.hits.shape
        # the layer's extent in map cells, clipped to the map; free cells outside it are unvouched
        col0 = max(self.gx0 - gcol0, 0)
        col1 = min(self.gx0 + lw - gcol0, grid.shape[1])
        row1 = min(height - (self.gy0 - grow0), height)
        row0 = max(height - (self.gy0 + lh - grow0), 0)
        r_off = grow0 + height - 1 - row0 - self.gy0
        c_off = gcol0 + col0 - self.gx0
        out, changed, outside = _correct(
            np.ascontiguousarray(grid, dtype=np.int8),
            self.hits,
            self.passes,
            self.near,
            self.crossed,
            r_off,
            c_off,
            row0,
            max(row1, row0),
            col0,
            max(col1, col0),
            self.min_hits,
            self.occupied_ratio,
        )
        if changed == 0 and outside == 0:
            return occupancy
        return MapView(out, resolution, origin)
