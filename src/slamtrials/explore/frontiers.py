"""Frontiers (Yamauchi 1997): known-free cells next to unknown cells, grouped into connected sets.

A frontier cell is a free cell 4-adjacent to an unknown cell. Unknown pockets enclosed by known cells
and smaller than ``min_unknown_cells`` do not count as unknown here: at long range the diverging beams
of a laser leave thin unknown gaps inside rooms that are in fact seen, and sending the robot to them
wastes time. Frontier cells are grouped by 8-connectivity; groups of fewer than ``min_cells`` cells are
dropped.

:func:`find_frontiers` is numba (flood fills only around the free space's edge, so its cost grows with
the map's known area, not with the unknown space around it); :func:`effective_unknown` and
:func:`frontier_mask` are plain numpy versions of its first steps, for reference and tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray
from scipy import ndimage

from slamtrials.explore.gridframe import FREE_BELOW

__all__ = ["Frontiers", "effective_unknown", "find_frontiers", "frontier_mask", "frontier_near"]

_FOUR = ndimage.generate_binary_structure(2, 1)
_EIGHT = ndimage.generate_binary_structure(2, 2)


def effective_unknown(grid: NDArray[np.int8], min_unknown_cells: int = 0) -> NDArray[np.bool_]:
    """bool ``[H, W]``: unknown cells (value < 0), minus enclosed 4-connected pockets of fewer than
    ``min_unknown_cells`` cells. A pocket touching the grid border is never dropped."""
    unknown = np.asarray(grid) < 0
    if min_unknown_cells <= 1 or not unknown.any():
        return unknown
    labels, count = ndimage.label(unknown, structure=_FOUR)
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    border = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
    small = sizes < min_unknown_cells
    small[0] = False
    small[border] = False
    if not small.any():
        return unknown
    return unknown & ~small[labels]


def frontier_mask(grid: NDArray[np.int8], unknown: NDArray[np.bool_] | None = None) -> NDArray[np.bool_]:
    """bool ``[H, W]``: free cells (``0 <= value < 50``) with a 4-neighbour in ``unknown`` (default: value < 0).

    Cells outside the grid do not count as unknown.
    """
    grid = np.asarray(grid)
    if unknown is None:
        unknown = grid < 0
    free = (grid >= 0) & (grid < FREE_BELOW)
    near = np.zeros_like(unknown)
    near[1:, :] |= unknown[:-1, :]
    near[:-1, :] |= unknown[1:, :]
    near[:, 1:] |= unknown[:, :-1]
    near[:, :-1] |= unknown[:, 1:]
    return free & near


@njit(cache=True, nogil=True)
def _classify_unknown(grid, min_unknown_cells):  # pragma: no cover - compiled
    """int8 [H, W]: 0 known, 1 unknown, 2 unknown in a small enclosed pocket (see effective_unknown).

    Only pockets that touch a free cell are examined: a flood fill (4-connected) from each unknown cell
    next to a free cell, stopped as soon as it exceeds ``min_unknown_cells`` cells or meets the border
    or a cell already known to belong to a large region.
    """
    height, width = grid.shape
    status = np.zeros((height, width), dtype=np.int8)
    for r in range(height):
        for c in range(width):
            if grid[r, c] < 0:
                status[r, c] = 1
    if min_unknown_cells <= 1:
        return status
    big = np.zeros((height, width), dtype=np.bool_)
    mark = np.zeros((height, width), dtype=np.bool_)
    stack = np.empty(min_unknown_cells + 8, dtype=np.int64)
    seen = np.empty(min_unknown_cells + 8, dtype=np.int64)
    drs = (-1, 1, 0, 0)
    dcs = (0, 0, -1, 1)
    for r in range(height):
        for c in range(width):
            if status[r, c] != 1 or big[r, c]:
                continue
            near_free = False
            for k in range(4):
                nr = r + drs[k]
                nc = c + dcs[k]
                if 0 <= nr < height and 0 <= nc < width and 0 <= grid[nr, nc] < 50:
                    near_free = True
            if not near_free:
                continue
            # flood fill
            top = 0
            count = 0
            large = False
            stack[0] = r * width + c
            top = 1
            mark[r, c] = True
            seen[0] = r * width + c
            count = 1
            while top > 0 and not large:
                top -= 1
                u = stack[top]
                ur = u // width
                uc = u - ur * width
                for k in range(4):
                    nr = ur + drs[k]
                    nc = uc + dcs[k]
                    if nr < 0 or nc < 0 or nr >= height or nc >= width:
                        large = True  # touches the border
                        break
                    if status[nr, nc] != 1 or mark[nr, nc]:
                        continue
                    if big[nr, nc]:
                        large = True
                        break
                    mark[nr, nc] = True
                    seen[count] = nr * width + nc
                    count += 1
                    stack[top] = nr * width + nc
                    top += 1
                    if count >= min_unknown_cells:
                        large = True
                        break
            for i in range(count):
                u = seen[i]
                ur = u // width
                uc = u - ur * width
                mark[ur, uc] = False
                if large:
                    big[ur, uc] = True
                else:
                    status[ur, uc] = 2
    return status


@njit(cache=True, nogil=True)
def _label_frontiers(grid, status, min_cells):  # pragma: no cover - compiled
    """Frontier cells (free, 4-adjacent to status 1), 8-connected groups of >= min_cells.

    Returns (labels int32 [H, W] with 1..K on kept groups, sizes int64 [K], row sums, column sums).
    """
    height, width = grid.shape
    cell = np.zeros((height, width), dtype=np.bool_)
    drs = (-1, 1, 0, 0, -1, -1, 1, 1)
    dcs = (0, 0, -1, 1, -1, 1, -1, 1)
    total = 0
    for r in range(height):
        for c in range(width):
            value = grid[r, c]
            if value < 0 or value >= 50:
                continue
            for k in range(4):
                nr = r + drs[k]
                nc = c + dcs[k]
                if 0 <= nr < height and 0 <= nc < width and status[nr, nc] == 1:
                    cell[r, c] = True
                    total += 1
                    break
    labels = np.zeros((height, width), dtype=np.int32)
    stack = np.empty(max(total, 1), dtype=np.int64)
    members = np.empty(max(total, 1), dtype=np.int64)
    sizes = np.empty(max(total, 1), dtype=np.int64)
    sum_r = np.empty(max(total, 1), dtype=np.float64)
    sum_c = np.empty(max(total, 1), dtype=np.float64)
    kept = 0
    for r in range(height):
        for c in range(width):
            if not cell[r, c] or labels[r, c] != 0:
                continue
            label = kept + 1
            stack[0] = r * width + c
            top = 1
            labels[r, c] = label
            count = 0
            sr = 0.0
            sc = 0.0
            while top > 0:
                top -= 1
                u = stack[top]
                ur = u // width
                uc = u - ur * width
                members[count] = u
                count += 1
                sr += ur
                sc += uc
                for k in range(8):
                    nr = ur + drs[k]
                    nc = uc + dcs[k]
                    if 0 <= nr < height and 0 <= nc < width and cell[nr, nc] and labels[nr, nc] == 0:
                        labels[nr, nc] = label
                        stack[top] = nr * width + nc
                        top += 1
            if count >= min_cells:
                sizes[kept] = count
                sum_r[kept] = sr
                sum_c[kept] = sc
                kept += 1
            else:
                for i in range(count):
                    u = members[i]
                    labels[u // width, u % width] = -1
    for r in range(height):
        for c in range(width):
            labels[r, c] = max(labels[r, c], 0)
    return labels, sizes[:kept].copy(), sum_r[:kept].copy(), sum_c[:kept].copy()


@dataclass(frozen=True, eq=False)
class Frontiers:
    """The frontiers of one grid (same shape and orientation as the grid).

    Attributes
    ----------
    mask:
        bool ``[H, W]``: cells of the kept frontiers.
    labels:
        int32 ``[H, W]``: 0 off the kept frontiers, ``k + 1`` on frontier ``k``.
    sizes:
        int64 ``[K]``: cells per frontier.
    centroids:
        float64 ``[K, 2]``: mean (row, col) of each frontier's cells (may lie off the frontier).
    """

    mask: NDArray[np.bool_]
    labels: NDArray[np.int32]
    sizes: NDArray[np.int64]
    centroids: NDArray[np.float64]

    @property
    def count(self) -> int:
        """Number of kept frontiers."""
        return int(self.sizes.shape[0])


def find_frontiers(grid: NDArray[np.int8], *, min_cells: int = 1, min_unknown_cells: int = 0) -> Frontiers:
    """The frontiers of ``grid`` (int8 ``[H, W]``, row 0 at the top) with at least ``min_cells`` cells.

    Parameters
    ----------
    grid:
        Occupancy values: < 0 unknown, 0..49 free, >= 50 occupied.
    min_cells:
        Smallest frontier kept (cells, 8-connected).
    min_unknown_cells:
        Enclosed unknown pockets smaller than this (cells, 4-connected) make no frontier.
    """
    grid = np.ascontiguousarray(grid, dtype=np.int8)
    status = _classify_unknown(grid, int(min_unknown_cells))
    labels, sizes, sum_r, sum_c = _label_frontiers(grid, status, max(int(min_cells), 1))
    centroids = np.column_stack([sum_r / sizes, sum_c / sizes]) if sizes.size else np.zeros((0, 2))
    return Frontiers(labels > 0, labels, sizes, centroids)


def frontier_near(grid: NDArray[np.int8], row: int, col: int, reach: int = 2) -> bool:
    """Whether a free cell within ``reach`` cells (Chebyshev) of cell ``(row, col)`` has an unknown
    4-neighbour: a cheap check, done every step, that a goal still lies on a frontier."""
    height, width = grid.shape
    r0, r1 = max(row - reach - 1, 0), min(row + reach + 2, height)
    c0, c1 = max(col - reach - 1, 0), min(col + reach + 2, width)
    if r0 >= r1 or c0 >= c1:
        return False
    patch = frontier_mask(grid[r0:r1, c0:c1])
    # only the cells within reach count (the patch has one more ring, for their neighbours)
    lo_r, lo_c = max(row - reach, 0) - r0, max(col - reach, 0) - c0
    hi_r, hi_c = min(row + reach + 1, height) - r0, min(col + reach + 1, width) - c0
    return bool(patch[lo_r:hi_r, lo_c:hi_c].any())
