"""Global path planning on a :class:`~slamtrials.explore.costmap.Costmap`: Dijkstra in numba, 8-connected.

Moving between neighbouring cells ``a`` and ``b`` costs ``step * (cost[a] + cost[b]) / 2`` (``step`` 1
or sqrt(2) cells), so a path's cost is its length weighted by the costmap. Edge costs are rounded to
multiples of 1/256 (cell cost factors capped at 512), so the search can use a circular bucket queue
(Dial's algorithm), several times faster than a binary heap on large grids. :func:`dijkstra` grows the
cost-to-come field from the robot's cell and can stop at the first goal cell it settles (the goal
closest by path cost), which keeps replanning cheap when a frontier is near.

Escape. When the robot's own cell is blocked (a SLAM error or a bump put it inside the inflated zone
of a wall), blocked cells within ``escape_radius`` cells of it may be crossed, at their ``escape`` cost
factor (:attr:`~slamtrials.explore.costmap.Costmap.escape`: high, and highest near walls), but only
from blocked cells: the search leaves the blocked region by the cheapest way and never re-enters it.

Hysteresis. A ``keep`` mask (the current goal's neighbourhood) can be given: the current goal is kept
unless some other goal cell is cheaper than ``ratio`` times its cost, so that the robot does not swing
between two frontiers of about the same cost.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

__all__ = ["UNREACHED", "PlanResult", "dijkstra", "extract_path"]

_SCALE = 256  # cost units per cell of unit cost
_CAP = 512.0  # largest cell cost factor
_BUCKETS = 1 << 18  # circular queue size: more than the largest edge weight, sqrt(2) * _CAP * _SCALE
_UNREACHED = np.iinfo(np.int64).max
#: :attr:`PlanResult.cost_to_come` of cells the search did not reach.
UNREACHED = _UNREACHED


@njit(cache=True, nogil=True)
def _dijkstra(
    cost, escape, sr, sc, goal, keep, use_goal, use_keep, ratio, escape_r2, max_cost, ir0, ir1, ic0, ic1
):  # pragma: no cover
    """Dijkstra with a circular bucket queue (Dial) over integer costs in units of 1 / 256.

    Each open cell sits in exactly one bucket (a doubly linked list threaded through per-cell arrays),
    and moves when its cost improves, so memory is fixed at a few arrays of the grid's size. Settling a
    cell outside rows [ir0, ir1) x columns [ic0, ic1) stops the search (the boundary was reached).
    Returns (dist int64 [H * W] with _UNREACHED where not reached, parent int64 [H * W], found, kept,
    cost of the first goal settled or -1, cost at which the boundary was reached or -1).
    """
    height, width = cost.shape
    n = height * width
    unreached = np.iinfo(np.int64).max
    dist = np.full(n, unreached, dtype=np.int64)
    parent = np.full(n, -1, dtype=np.int64)
    settled = np.zeros(n, dtype=np.bool_)
    nxt = np.empty(n, dtype=np.int32)
    prv = np.empty(n, dtype=np.int32)
    scale = float(_SCALE)
    cap = _CAP
    mask = _BUCKETS - 1
    head = np.full(mask + 1, -1, dtype=np.int32)
    drs = np.array([-1, 1, 0, 0, -1, -1, 1, 1])
    dcs = np.array([0, 0, -1, 1, -1, 1, -1, 1])
    start = sr * width + sc
    dist[start] = 0
    nxt[start] = -1
    prv[start] = -1
    head[0] = start
    pending = 1
    current = 0
    found = -1
    kept = False
    first = -1
    first_cost = -1
    boundary = -1
    bound = unreached
    if max_cost < 1e15:
        bound = int(max_cost * scale)
    while pending > 0:
        u = head[current & mask]
        if u < 0:
            current += 1
            continue
        following = nxt[u]
        head[current & mask] = following
        if following >= 0:
            prv[following] = -1
        pending -= 1
        if current > bound:
            break
        settled[u] = True
        r = u // width
        c = u - r * width
        if r < ir0 or r >= ir1 or c < ic0 or c >= ic1:
            boundary = current
            break
        if use_keep and keep[r, c]:
            found = u
            kept = True
            break
        if use_goal and first < 0 and goal[r, c]:
            first = u
            first_cost = current
            if not use_keep:
                break
            bound = min(bound, int(current / ratio) + 1)
        cf = cost[r, c]
        u_blocked = not (cf < np.inf)
        if u_blocked:
            cu = int(min(escape[r, c], cap) * scale + 0.5)
        else:
            cu = int(min(cf, cap) * scale + 0.5)
        for k in range(8):
            nr = r + drs[k]
            nc = c + dcs[k]
            if nr < 0 or nc < 0 or nr >= height or nc >= width:
                continue
            v = nr * width + nc
            if settled[v]:
                continue
            cvf = cost[nr, nc]
            if cvf < np.inf:
                cv = int(min(cvf, cap) * scale + 0.5)
            else:
                if not u_blocked:
                    continue
                if (nr - sr) * (nr - sr) + (nc - sc) * (nc - sc) > escape_r2:
                    continue
                ev = escape[nr, nc]
                if not (ev < np.inf):
                    continue
                cv = int(min(ev, cap) * scale + 0.5)
            if k < 4:
                nd = current + ((cu + cv) >> 1)
            else:
                nd = current + (((cu + cv) * 46341 + 32768) >> 16)  # (cu + cv) sqrt(2) / 2
            old = dist[v]
            if nd < old:
                if old != unreached:  # unlink from its bucket
                    a = prv[v]
                    z = nxt[v]
                    if a >= 0:
                        nxt[a] = z
                    else:
                        head[old & mask] = z
                    if z >= 0:
                        prv[z] = a
                else:
                    pending += 1
                dist[v] = nd
                parent[v] = u
                b = nd & mask
                z = head[b]
                nxt[v] = z
                prv[v] = -1
                if z >= 0:
                    prv[z] = v
                head[b] = v
    if found < 0:
        found = first
    return dist, parent, found, kept, first_cost, boundary


@njit(cache=True, nogil=True)
def _chain(parent, index):  # pragma: no cover - compiled
    count = 1
    i = index
    while parent[i] >= 0:
        i = parent[i]
        count += 1
    out = np.empty(count, dtype=np.int64)
    i = index
    for k in range(count - 1, -1, -1):
        out[k] = i
        i = parent[i]
    return out


@dataclass(frozen=True, eq=False)
class PlanResult:
    """What one Dijkstra search found.

    Attributes
    ----------
    cost_to_come:
        int64 ``[H * W]``: cost-to-come in units of 1/256 (cells x cost factor); a huge value where not
        reached. Cells beyond the stopping cost may hold upper bounds only. See :attr:`distance`.
    parent:
        int64 ``[H * W]``: flat index of each reached cell's predecessor, -1 for the start and unreached cells.
    goal:
        ``(row, col)`` of the goal cell found, or ``None``.
    kept:
        Whether the goal found lies in the ``keep`` mask (the current goal was kept).
    width:
        Grid width (cells), to unflatten indices.
    first_cost:
        Cost (cells x cost factor) of the cheapest goal cell, or ``None`` if none was settled.
    boundary_cost:
        Cost at which the search settled its first cell outside ``interior`` and stopped, or ``None``.
    """

    cost_to_come: NDArray[np.int64]
    parent: NDArray[np.int64]
    goal: tuple[int, int] | None
    kept: bool
    width: int
    first_cost: float | None = None
    boundary_cost: float | None = None

    @property
    def distance(self) -> NDArray[np.float64]:
        """float64 ``[H, W]``: cost-to-come (cells x cost factor), ``inf`` where not reached."""
        d = self.cost_to_come
        out = np.where(d == _UNREACHED, np.inf, d / _SCALE)
        return out.reshape(-1, self.width)

    def reached(self, row: int, col: int) -> bool:
        """Whether the search reached cell ``(row, col)``."""
        return bool(self.cost_to_come[row * self.width + col] != _UNREACHED)

    def path_to(self, row: int, col: int) -> NDArray[np.int64]:
        """int64 ``[L, 2]`` cells (row, col) from the start to ``(row, col)``; empty if it was not reached."""
        return extract_path(self.parent, row * self.width + col, self.width, self.reached(row, col))


def extract_path(parent: NDArray[np.int64], index: int, width: int, reached: bool = True) -> NDArray[np.int64]:
    """int64 ``[L, 2]`` cells (row, col) from the search's start to flat cell ``index`` by following ``parent``."""
    if not reached:
        return np.zeros((0, 2), dtype=np.int64)
    chain = _chain(parent, int(index))
    return np.column_stack([chain // width, chain % width])


def dijkstra(
    cost: NDArray[np.float32],
    start: tuple[int, int],
    *,
    goal: NDArray[np.bool_] | None = None,
    keep: NDArray[np.bool_] | None = None,
    ratio: float = 1.0,
    escape: NDArray[np.float32] | None = None,
    escape_radius: float = 0.0,
    max_cost: float = math.inf,
    interior: tuple[int, int, int, int] | None = None,
) -> PlanResult:
    """Cost-to-come from ``start`` over the costmap, optionally stopping at the cheapest goal cell.

    Parameters
    ----------
    cost:
        float32 ``[H, W]`` cost factor per unit length (:attr:`Costmap.cost`); ``inf`` = blocked.
    start:
        ``(row, col)`` of the robot's cell; must lie in the grid.
    goal:
        bool ``[H, W]`` goal cells; the search stops when it settles the first one (subject to ``keep``).
        ``None`` searches the whole reachable grid.
    keep:
        bool ``[H, W]`` cells of the current goal: returned unless another goal cell costs less than
        ``ratio`` times as much (see the module docstring).
    escape:
        float32 ``[H, W]`` cost factors of blocked cells when escaping (:attr:`Costmap.escape`; ``inf``
        = never); ``None`` disables escaping.
    escape_radius:
        Radius (cells) around ``start`` within which blocked cells may be crossed from blocked cells.
    max_cost:
        Stop when the cheapest open cell costs more than this (cells x cost factor).
    interior:
        ``(row0, row1, col0, col1)``: stop as soon as a cell outside rows ``[row0, row1)`` and columns
        ``[col0, col1)`` is settled (a search in a window around the robot, whose outer rim is only
        there to make the costs right: see :attr:`PlanResult.boundary_cost`). ``None``: the whole grid.
    """
    height, width = cost.shape
    sr, sc = int(start[0]), int(start[1])
    if not (0 <= sr < height and 0 <= sc < width):
        raise ValueError(f"start cell {start} lies outside the {height} x {width} grid")
    use_goal = goal is not None
    use_keep = keep is not None and bool(keep.any()) and use_goal
    dummy = np.zeros((1, 1), dtype=np.bool_)
    if escape is None:
        escape, escape_radius = cost, -1.0
    ir0, ir1, ic0, ic1 = (-1, height + 1, -1, width + 1) if interior is None else (int(v) for v in interior)
    dist, parent, found, kept, first_cost, boundary = _dijkstra(
        np.ascontiguousarray(cost, dtype=np.float32),
        np.ascontiguousarray(escape, dtype=np.float32),
        sr,
        sc,
        np.ascontiguousarray(goal) if use_goal else dummy,
        np.ascontiguousarray(keep) if use_keep else dummy,
        use_goal,
        use_keep,
        float(ratio),
        math.copysign(float(escape_radius) ** 2, escape_radius),
        float(max_cost),
        ir0,
        ir1,
        ic0,
        ic1,
    )
    where = None if found < 0 else (int(found // width), int(found % width))
    return PlanResult(
        cost_to_come=dist,
        parent=parent,
        goal=where,
        kept=bool(kept),
        width=width,
        first_cost=None if first_cost < 0 else first_cost / _SCALE,
        boundary_cost=None if boundary < 0 else boundary / _SCALE,
    )
