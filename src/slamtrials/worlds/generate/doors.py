"""Doors: find the straight boundaries between rooms, give every room a way in, cut the openings.

A *segment* is a maximal straight run of cell edges separating the same two labels. Every room gets
a door on a segment it shares with the circulation or, failing that, with a room already reached, so
that every room can be reached from the corridors; large rooms get a second door, and a few
neighbouring rooms get a connecting door. A door is a gap of ``n`` cells cut through the whole wall;
``n * resolution`` is at least the door width drawn, which is at least 0.9 m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.worlds.generate.kinds import STYLES
from slamtrials.worlds.generate.raster import CIRCULATION, Grid

__all__ = ["Segments", "Door", "interface_segments", "plan_doors", "carve_doors", "door_box", "door_record", "MIN_DOOR"]

#: Narrowest door opening (m).
MIN_DOOR = 0.9


@dataclass(frozen=True)
class Segments:
    """Straight boundary runs between two labels (all arrays ``[S]``).

    ``orient`` 0: the boundary lies between columns ``line`` and ``line + 1`` and runs down rows
    ``start .. stop - 1``; ``orient`` 1: between rows ``line`` and ``line + 1``, along columns.
    ``lo < hi`` are the two labels.
    """

    orient: NDArray[np.int8]
    line: NDArray[np.int64]
    start: NDArray[np.int64]
    stop: NDArray[np.int64]
    lo: NDArray[np.int32]
    hi: NDArray[np.int32]


@dataclass(frozen=True)
class Door:
    """A door opening: ``n`` cells from ``start`` along a boundary (see :class:`Segments`)."""

    orient: int
    line: int
    start: int
    n: int
    lo: int
    hi: int


def _runs(first: NDArray, second: NDArray, a: NDArray, b: NDArray) -> tuple[NDArray, ...]:
    """Group boundary cells sorted by (first, second) into runs of consecutive ``second``."""
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    if len(first) == 0:
        return first, second, second, lo, hi
    brk = np.ones(len(first), dtype=bool)
    brk[1:] = (first[1:] != first[:-1]) | (second[1:] != second[:-1] + 1) | (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])
    starts = np.flatnonzero(brk)
    ends = np.append(starts[1:], len(first))
    return first[starts], second[starts], second[ends - 1] + 1, lo[starts], hi[starts]


def interface_segments(labels: NDArray[np.int32]) -> Segments:
    """All straight boundary runs between two labels that are both inside the building (> 0)."""
    left, right = labels[:, :-1], labels[:, 1:]
    mask = (left != right) & (left > 0) & (right > 0)
    rows, cols = np.nonzero(mask)
    order = np.lexsort((rows, cols))  # by column, then row
    rows, cols = rows[order], cols[order]
    v = _runs(cols, rows, left[rows, cols], right[rows, cols])
    top, bottom = labels[:-1, :], labels[1:, :]
    mask = (top != bottom) & (top > 0) & (bottom > 0)
    rows, cols = np.nonzero(mask)  # sorted by row, then column
    h = _runs(rows, cols, top[rows, cols], bottom[rows, cols])
    return Segments(
        orient=np.concatenate([np.zeros(len(v[0]), np.int8), np.ones(len(h[0]), np.int8)]),
        line=np.concatenate([v[0], h[0]]).astype(np.int64),
        start=np.concatenate([v[1], h[1]]).astype(np.int64),
        stop=np.concatenate([v[2], h[2]]).astype(np.int64),
        lo=np.concatenate([v[3], h[3]]).astype(np.int32),
        hi=np.concatenate([v[4], h[4]]).astype(np.int32),
    )


def _door_cells(width: float, grid: Grid) -> int:
    return int(math.ceil(max(width, MIN_DOOR) / grid.resolution - 1e-6))


def _place(
    segs: Segments, s: int, n: int, margin: int, rng: np.random.Generator, avoid: list[tuple[int, int]] = ()
) -> Door | None:
    """A door of ``n`` cells on segment ``s``, ``margin`` cells clear of its ends and of ``avoid`` spans."""
    lo, hi = int(segs.start[s]) + margin, int(segs.stop[s]) - margin - n
    if hi < lo:
        return None
    for _ in range(6):
        draw = rng.random()
        if draw < 0.3:
            p = lo + int(rng.integers(0, max(1, min(hi - lo, n // 3) + 1)))
        elif draw < 0.6:
            p = hi - int(rng.integers(0, max(1, min(hi - lo, n // 3) + 1)))
        else:
            p = int(rng.integers(lo, hi + 1))
        if all(p + n + 2 * margin <= a or p >= b + 2 * margin for a, b in avoid):
            return Door(int(segs.orient[s]), int(segs.line[s]), p, n, int(segs.lo[s]), int(segs.hi[s]))
    return None


def plan_doors(
    labels: NDArray[np.int32],
    uses: list[tuple[str, str]],
    boxes: dict[int, tuple[slice, slice]],
    grid: Grid,
    wall_k: int,
    rng: np.random.Generator,
) -> tuple[list[Door], list[int]]:
    """Choose the doors of every room (``boxes``: label -> bounding box of the rooms present).

    Returns the doors and the rooms that could not be given a way in (to be merged by the caller).
    """
    segs = interface_segments(labels)
    margin = wall_k + 1 + grid.px(0.15)
    res2 = grid.resolution**2
    rooms = [k for k in sorted(boxes) if uses[k - 2][0] != "shaft"]
    areas = {k: float(np.count_nonzero(labels[boxes[k]] == k)) * res2 for k in rooms}
    by_room: dict[int, list[int]] = {k: [] for k in rooms}
    lengths_all = (segs.stop - segs.start).tolist()
    los, his = segs.lo.tolist(), segs.hi.tolist()
    for s, (a, b) in enumerate(zip(los, his)):
        if a in by_room:
            by_room[a].append(s)
        if b in by_room:
            by_room[b].append(s)

    def width_of(k: int) -> int:
        use, style = uses[k - 2]
        lo, hi = STYLES[style].door
        if use in ("hall", "big", "end") and areas[k] > 40.0:
            return _door_cells(float(rng.uniform(1.5, 2.0)), grid)
        return _door_cells(float(rng.uniform(lo, hi)), grid)

    def other(s: int, k: int) -> int:
        return his[s] if los[s] == k else los[s]

    doors: list[Door] = []
    used: dict[int, list[tuple[int, int]]] = {}
    connected = {CIRCULATION}
    pending = list(rooms)
    changed = True
    while pending and changed:
        changed = False
        for k in list(pending):
            n = width_of(k)
            options = [s for s in by_room[k] if other(s, k) in connected and lengths_all[s] >= n + 2 * margin]
            if not options:
                continue
            to_corridor = [s for s in options if other(s, k) == CIRCULATION]
            pool = to_corridor or options
            lengths = np.array([lengths_all[s] for s in pool], dtype=float)
            s = pool[int(rng.choice(len(pool), p=lengths / lengths.sum()))]
            door = _place(segs, s, n, margin, rng)
            if door is None:
                continue
            doors.append(door)
            used.setdefault(s, []).append((door.start, door.start + n))
            connected.add(k)
            pending.remove(k)
            changed = True
            if areas[k] > 40.0 and rng.random() < 0.7:
                second = _place(segs, s, n, margin, rng, used[s])
                if second is not None and abs(second.start - door.start) * grid.resolution > 3.0:
                    doors.append(second)
                    used[s].append((second.start, second.start + n))
    for s, (a, b) in enumerate(zip(los, his)):
        if a < 2 or a not in connected or b not in connected or s in used:
            continue
        style = STYLES[uses[a - 2][1]]
        if rng.random() < style.connect_prob:
            door = _place(segs, s, _door_cells(float(rng.uniform(*style.door)), grid), margin, rng)
            if door is not None:
                doors.append(door)
                used[s] = [(door.start, door.start + door.n)]
    return doors, sorted(pending)


def door_box(door: Door, wall_k: int, across: int = 0, along: int = 0) -> tuple[slice, slice]:
    """Cells of the opening (``across``/``along`` cells more on each side), unclipped."""
    a0, a1 = door.start - along, door.start + door.n + along
    c0, c1 = door.line - wall_k - across, door.line + wall_k + 2 + across
    if door.orient == 0:
        return slice(a0, a1), slice(c0, c1)
    return slice(c0, c1), slice(a0, a1)


def carve_doors(
    occupied: NDArray[np.bool_], doors: list[Door], grid: Grid, wall_k: int
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Open every door in ``occupied`` (in place).

    Returns the mask of door cells and the *reserved* mask: the opening plus 1.2 m on both sides of
    the wall and 0.2 m beside it, where no furniture may stand.
    """
    door_mask = np.zeros_like(occupied)
    reserved = np.zeros_like(occupied)
    deep, side = grid.px(1.2), grid.px(0.2)
    for door in doors:
        box = door_box(door, wall_k)
        occupied[box] = False
        door_mask[box] = True
        rows, cols = door_box(door, wall_k, across=deep, along=side)
        reserved[max(0, rows.start) : rows.stop, max(0, cols.start) : cols.stop] = True
    return door_mask, reserved


def door_record(door: Door, grid: Grid) -> list[float]:
    """``[x, y, width, axis]``: the opening's centre (m, world frame), width (m), and the axis the wall
    runs along (0: x, 1: y)."""
    mid = door.start + door.n / 2.0
    if door.orient == 0:
        x, y = grid.cell_centre(mid - 0.5, door.line + 0.5)
        axis = 1
    else:
        x, y = grid.cell_centre(door.line + 0.5, mid - 0.5)
        axis = 0
    return [round(x, 4), round(y, 4), round(door.n * grid.resolution, 4), axis]
