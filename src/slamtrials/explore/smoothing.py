"""Any-angle shortcuts of an 8-connected grid path, kept only where the costmap says they are no worse.

Dijkstra on an 8-connected grid can only move in multiples of 45 degrees, so its paths zig-zag
between the two nearest directions and bend at cell scale; a pure-pursuit follower turns back and
forth along them, and every turn of 0.25 rad is an extra GMapping update. :func:`shortcut_path`
replaces runs of the path by straight segments, greedily from the start: from an anchor cell it
extends a segment over the following path cells as long as the straight segment

* crosses only finite-cost (passable) cells, every cell it touches, and
* costs no more than the part of the path it replaces: the segment's cost is the integral of the
  cell cost factor along it, the path's the planner's own edge costs (step length times the mean of
  the two cells' factors), which is the same integral along the grid path,

and stops at the first path cell that fails (or after ``max_span`` cells). The second rule keeps the
planner's preference for the middle of corridors and doors: a shortcut that cuts a corner close to a
wall pays the wall cost and is refused. A path that starts in a blocked cell (a robot escaping from
the lethal zone) keeps its cells unchanged until it reaches passable cells.

:func:`resample_polyline` then puts points back on the straight segments at a fixed spacing, because
the follower measures progress and look-ahead on path points.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials import stablemath

__all__ = ["resample_polyline", "shortcut_path"]


@njit(cache=True, nogil=True)
def _segment_cost(cost, r0, c0, r1, c1):  # pragma: no cover - compiled
    """Integral of the cost factor along the straight segment between two cell centres (cells x cost):
    each cell the segment passes through counts with the length inside it (Amanatides and Woo's grid
    traversal); inf if any of them is blocked. Where the segment passes exactly through a cell corner,
    the two cells beside the corner must be passable too."""
    dr = float(r1 - r0)
    dc = float(c1 - c0)
    length = math.sqrt(dr * dr + dc * dc)
    step_r = 1 if dr > 0 else -1
    step_c = 1 if dc > 0 else -1
    delta_r = 1.0 / abs(dr) if dr != 0.0 else math.inf
    delta_c = 1.0 / abs(dc) if dc != 0.0 else math.inf
    next_r = 0.5 * delta_r  # segment parameter of the next row border (starting at a cell centre)
    next_c = 0.5 * delta_c
    r = r0
    c = c0
    t = 0.0
    total = 0.0
    while True:
        value = cost[r, c]
        if not math.isfinite(value):
            return math.inf
        t_next = min(next_r, next_c, 1.0)
        total += value * (t_next - t) * length
        if t_next >= 1.0:
            return total
        t = t_next
        if next_r < next_c - 1e-12:
            r += step_r
            next_r += delta_r
        elif next_c < next_r - 1e-12:
            c += step_c
            next_c += delta_c
        else:  # through a corner
            if not (math.isfinite(cost[r + step_r, c]) and math.isfinite(cost[r, c + step_c])):
                return math.inf
            r += step_r
            c += step_c
            next_r += delta_r
            next_c += delta_c


@njit(cache=True, nogil=True)
def _shortcut(cost, rows, cols, max_span):  # pragma: no cover - compiled
    n = rows.shape[0]
    # cost of the path itself up to each cell, as the planner counts it
    along = np.zeros(n)
    for k in range(1, n):
        step = math.sqrt(float((rows[k] - rows[k - 1]) ** 2 + (cols[k] - cols[k - 1]) ** 2))
        along[k] = along[k - 1] + step * 0.5 * (cost[rows[k - 1], cols[k - 1]] + cost[rows[k], cols[k]])
    keep = np.zeros(n, dtype=np.int64)
    kept = 0
    keep[kept] = 0
    kept += 1
    i = 0
    while i < n - 1:
        best = i + 1
        if math.isfinite(cost[rows[i], cols[i]]) and math.isfinite(along[i + 1]):
            stop = min(n - 1, i + max_span)
            for j in range(i + 2, stop + 1):
                if not math.isfinite(along[j]):
                    break
                straight = _segment_cost(cost, rows[i], cols[i], rows[j], cols[j])
                if straight > (along[j] - along[i]) * (1.0 + 1e-9):
                    break
                best = j
        keep[kept] = best
        kept += 1
        i = best
    return keep[:kept]


def shortcut_path(cells: NDArray[np.integer], cost: NDArray[np.floating], max_span: int = 400) -> NDArray[np.int64]:
    """Indices of the path cells kept as corners when straight segments replace the rest.

    Parameters
    ----------
    cells:
        int ``[L, 2]`` the path as (row, col) cells, each a neighbour (8-connected) of the one before.
    cost:
        float ``[H, W]`` the costmap's cost factor per unit length; ``inf`` where blocked.
    max_span:
        Longest run of path cells one segment may replace.

    Returns
    -------
    NDArray[np.int64]
        ``[K]`` increasing indices into ``cells``, first 0 and last ``L - 1`` (empty for an empty path):
        the polyline through ``cells[indices]`` crosses only passable cells and costs no more than the
        path it replaces (module docstring).
    """
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if cells.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    return _shortcut(
        np.ascontiguousarray(cost, dtype=np.float64),
        np.ascontiguousarray(cells[:, 0]),
        np.ascontiguousarray(cells[:, 1]),
        int(max(max_span, 2)),
    )


def resample_polyline(points: NDArray[np.floating], spacing: float) -> NDArray[np.float64]:
    """float64 ``[M, 2]`` points along the polyline ``points`` (float ``[K, 2]``), at most ``spacing`` apart.

    Every corner of the polyline is kept; each segment is split into equal parts no longer than
    ``spacing`` (same unit as the points).
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if pts.shape[0] < 2:
        return pts.copy()
    if spacing <= 0.0:
        raise ValueError(f"spacing must be positive, got {spacing}")
    step = np.diff(pts, axis=0)
    seg = stablemath.hypot(step[:, 0], step[:, 1])
    parts = np.maximum(np.ceil(seg / spacing).astype(np.int64), 1)
    starts = np.repeat(pts[:-1], parts, axis=0)
    deltas = np.repeat(np.diff(pts, axis=0) / parts[:, None], parts, axis=0)
    steps = np.concatenate([np.arange(p) for p in parts])
    out = starts + deltas * steps[:, None]
    return np.vstack([out, pts[-1:]])
