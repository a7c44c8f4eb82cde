"""The planning costmap of an occupancy grid: lethal cells around obstacles, a cost that decays away from them.

For every cell, ``clearance`` is the distance (m) from its centre to the nearest occupied cell's edge,
taken as the centre-to-centre distance (exact Euclidean distance transform) minus half a cell. Then

* occupied cells and cells with ``clearance < lethal_distance`` (robot radius + inflation margin) are
  blocked: the robot centred there would touch, or come too close to, an obstacle;
* a free cell costs ``1 + wall_cost * exp(-(clearance - lethal_distance) / cost_decay_distance)`` per
  unit of path length, so paths keep to the middle of corridors and doors;
* unknown cells are blocked unless ``unknown_traversable``, then they cost ``unknown_cost`` times the
  free cost.

The distance transform is the separable exact algorithm of Felzenszwalb and Huttenlocher (2012) in
numba (the same result as ``scipy.ndimage.distance_transform_edt``, several times faster on large maps,
which matters because the explorer rebuilds its costmap at every replan). Squared distances are whole
numbers of cells^2, so clearance and cost come from a table indexed by them (the wall term is dropped
where it falls below 0.01, i.e. beyond :func:`influence_distance`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials import stablemath
from slamtrials.explore.config import ExploreConfig, RobotLimits, lethal_distance
from slamtrials.explore.gridframe import FREE_BELOW

__all__ = [
    "LETHAL",
    "OCCUPIED",
    "PASSABLE",
    "UNKNOWN",
    "Costmap",
    "build_costmap",
    "influence_distance",
    "squared_distance_transform",
]

#: Cell kinds of :attr:`Costmap.kind`.
PASSABLE, LETHAL, UNKNOWN, OCCUPIED = 0, 1, 2, 3

_FAR = 1.0e12  # squared distance (cells^2) standing for "no obstacle"


@njit(cache=True, nogil=True)
def _row_envelope(f, out, v, z):  # pragma: no cover - compiled
    """1-D squared distance transform of sampled function ``f`` (Felzenszwalb-Huttenlocher)."""
    n = f.shape[0]
    k = 0
    v[0] = 0
    z[0] = -np.inf
    z[1] = np.inf
    for q in range(1, n):
        fq = f[q] + q * q
        while True:
            p = v[k]
            s = (fq - (f[p] + p * p)) / (2.0 * (q - p))
            if s <= z[k] and k > 0:
                k -= 1
            else:
                break
        if s <= z[k]:  # k == 0 and the new parabola hides the first one
            v[0] = q
            z[0] = -np.inf
            z[1] = np.inf
            continue
        k += 1
        v[k] = q
        z[k] = s
        z[k + 1] = np.inf
    k = 0
    for q in range(n):
        while z[k + 1] < q:
            k += 1
        p = v[k]
        out[q] = (q - p) * (q - p) + f[p]


@njit(cache=True, nogil=True)
def squared_distance_transform(target):  # pragma: no cover - compiled
    """float64 ``[H, W]``: squared distance (cells^2) from each cell centre to the nearest True cell centre.

    ``target`` is bool ``[H, W]``. Where there is no True cell at all the result is 1e12 or more.
    """
    height, width = target.shape
    g = np.empty((height, width), dtype=np.float64)
    run = np.full(width, -1.0)
    for r in range(height):  # distance along the column to the nearest target above (or at) r
        for c in range(width):
            if target[r, c]:
                run[c] = 0.0
            elif run[c] >= 0.0:
                run[c] += 1.0
            g[r, c] = run[c] if run[c] >= 0.0 else _FAR
    run[:] = -1.0
    for r in range(height - 1, -1, -1):  # ... or below
        for c in range(width):
            if target[r, c]:
                run[c] = 0.0
            elif run[c] >= 0.0:
                run[c] += 1.0
                g[r, c] = min(g[r, c], run[c])
    for r in range(height):
        for c in range(width):
            if g[r, c] < _FAR:
                g[r, c] = g[r, c] * g[r, c]
    out = np.empty((height, width), dtype=np.float64)
    v = np.empty(width, dtype=np.int64)
    z = np.empty(width + 1, dtype=np.float64)
    for r in range(height):
        _row_envelope(g[r], out[r], v, z)
    return out


#: The wall term of the cost is dropped where it falls below this.
_NEGLIGIBLE = 0.01


def influence_distance(config: ExploreConfig, robot: RobotLimits, resolution: float) -> float:
    """Distance (m) from an obstacle beyond which it changes no cost: cells farther than this from the
    edge of a window of the map have the same costs in the window's costmap as in the whole map's."""
    cfg = config
    return (
        lethal_distance(cfg, robot)
        + cfg.cost_decay_distance * max(math.log(max(cfg.wall_cost, 1e-12) / _NEGLIGIBLE), 0.0)
        + 2 * resolution
    )


def _cost_table(
    resolution: float, lethal: float, wall_cost: float, decay: float
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """Clearance (m) and cost factor for every squared centre distance ``d2 = 0, 1, ..., n - 1`` (cells^2).

    ``n`` is chosen so that beyond it the wall term is below ``_NEGLIGIBLE``; the last entry stands for
    every larger distance. Lethal entries cost ``inf``.
    """
    reach = lethal + decay * max(math.log(max(wall_cost, 1e-12) / _NEGLIGIBLE), 0.0) + resolution
    n = math.ceil(reach / resolution + 1.0) ** 2 + 1
    d = np.sqrt(np.arange(n, dtype=np.float64)) * resolution - 0.5 * resolution
    d = np.maximum(d, 0.0)
    cost = 1.0 + wall_cost * stablemath.exp(-(d - lethal) / decay)
    cost[d < lethal] = np.inf
    cost[-1] = 1.0
    return d.astype(np.float32), cost.astype(np.float32)


@njit(cache=True, nogil=True)
def _costs(
    grid, d2, resolution, clear_table, cost_table, unknown_traversable, unknown_cost, free_below, lethal, escape_cost
):  # pragma: no cover
    height, width = grid.shape
    n = cost_table.shape[0]
    cost = np.empty((height, width), dtype=np.float32)
    escape = np.empty((height, width), dtype=np.float32)
    kind = np.empty((height, width), dtype=np.int8)
    clearance = np.empty((height, width), dtype=np.float32)
    for r in range(height):
        for c in range(width):
            value = grid[r, c]
            e = d2[r, c]
            if e < n - 1:
                i = int(e)
                clearance[r, c] = clear_table[i]
                base = cost_table[i]
            else:
                clearance[r, c] = math.sqrt(e) * resolution - 0.5 * resolution
                base = cost_table[n - 1]
            if value >= free_below:
                cost[r, c] = np.inf
                kind[r, c] = 3
                escape[r, c] = 4.0 * escape_cost
            elif not (base < np.inf):
                cost[r, c] = np.inf
                kind[r, c] = 1
                escape[r, c] = escape_cost * (1.0 + 2.0 * (lethal - clearance[r, c]) / lethal)
            elif value < 0:
                if unknown_traversable:
                    cost[r, c] = base * unknown_cost
                    kind[r, c] = 0
                    escape[r, c] = cost[r, c]
                else:
                    cost[r, c] = np.inf
                    kind[r, c] = 2
                    escape[r, c] = escape_cost
            else:
                cost[r, c] = base
                kind[r, c] = 0
                escape[r, c] = base
    return cost, kind, clearance, escape


@dataclass(frozen=True, eq=False)
class Costmap:
    """Planning costs of one grid (same shape and orientation as the grid: row 0 at the top).

    Attributes
    ----------
    cost:
        float32 ``[H, W]``: cost factor (>= 1) per unit of path length; ``inf`` where blocked.
    kind:
        int8 ``[H, W]``: :data:`PASSABLE`, :data:`LETHAL`, :data:`UNKNOWN` (blocked unknown) or
        :data:`OCCUPIED`.
    clearance:
        float32 ``[H, W]``: distance (m) from the cell centre to the nearest occupied cell's edge
        (about 1e6 m when the grid has no occupied cell).
    resolution:
        Cell size (m).
    escape:
        float32 ``[H, W]``: cost factor of each cell for a robot escaping from a blocked cell (see
        :mod:`slamtrials.explore.planner`): ``cost`` where passable; ``escape_cost`` for unknown cells;
        from ``escape_cost`` at the lethal zone's edge to three times that at a wall for lethal cells,
        so that an escape heads for open space; ``4 escape_cost`` for occupied cells.
    """

    cost: NDArray[np.float32]
    kind: NDArray[np.int8]
    clearance: NDArray[np.float32]
    resolution: float
    escape: NDArray[np.float32]


def build_costmap(
    grid: NDArray[np.int8], resolution: float, config: ExploreConfig, robot: RobotLimits | None = None
) -> Costmap:
    """Costmap of ``grid`` (int8 ``[H, W]``: >= 50 occupied, 0..49 free, < 0 unknown) with cells of ``resolution`` m."""
    lethal = lethal_distance(config, RobotLimits() if robot is None else robot)
    grid = np.ascontiguousarray(grid, dtype=np.int8)
    d2 = squared_distance_transform(grid >= FREE_BELOW)
    clear_table, cost_table = _cost_table(
        float(resolution), float(lethal), float(config.wall_cost), float(config.cost_decay_distance)
    )
    cost, kind, clearance, escape = _costs(
        grid,
        d2,
        float(resolution),
        clear_table,
        cost_table,
        bool(config.unknown_traversable),
        float(config.unknown_cost),
        FREE_BELOW,
        float(lethal),
        float(config.escape_cost),
    )
    return Costmap(cost=cost, kind=kind, clearance=clearance, resolution=float(resolution), escape=escape)
