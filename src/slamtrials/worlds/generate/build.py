"""One generation pass: plan -> labels -> doors -> walls -> furniture -> one connected free region.

:func:`build_grid` runs the whole pipeline for a given gross footprint and returns the occupancy grid
with what the caller needs for the :class:`~slamtrials.worlds.World` (start pose, doors, counts).
All randomness comes from one ``numpy.random.Generator`` made from the seed, so a pass is a pure
function of its arguments.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from slamtrials.worlds.generate.corridors import furnish_circulation
from slamtrials.worlds.generate.doors import carve_doors, door_record, plan_doors
from slamtrials.worlds.generate.furniture import furnish_room
from slamtrials.worlds.generate.kinds import KindSpec
from slamtrials.worlds.generate.placement import Placer
from slamtrials.worlds.generate.raster import CIRCULATION, Grid, draw_walls, paint_labels, wall_pixels
from slamtrials.worlds.generate.rooms import clean_labels, merge_room, neighbour_of
from slamtrials.worlds.generate.skeleton import build_plan, choose_shape

__all__ = ["Built", "build_grid", "keep_largest_region"]

#: Clearance (m) the start pose is given from walls and furniture.
START_CLEARANCE = 0.6


@dataclass
class Built:
    """The result of one pass.

    Attributes
    ----------
    occupied:
        bool ``[H, W]``, row 0 at the top.
    grid:
        The raster (resolution, margin -> world origin).
    start:
        float64 ``[3]`` start pose in the world frame, or None to let :class:`World` choose.
    shape:
        Building shape name.
    rooms:
        Number of rooms that ended up with a door.
    doors:
        ``[x, y, width, wall_axis]`` per door (see :func:`~slamtrials.worlds.generate.doors.door_record`).
    footprint:
        Gross area of the building (m^2): everything inside the outer walls.
    corridors:
        ``[x0, y0, x1, y1]`` (m, world frame) centre line of every corridor piece.
    """

    occupied: NDArray[np.bool_]
    grid: Grid
    start: NDArray[np.float64] | None
    shape: str
    rooms: int
    doors: list[list[float]] = field(default_factory=list)
    footprint: float = 0.0
    corridors: list[list[float]] = field(default_factory=list)

    @property
    def free_area(self) -> float:
        """Free area (m^2)."""
        return float(np.count_nonzero(~self.occupied)) * self.grid.resolution**2


def keep_largest_region(occupied: NDArray[np.bool_]) -> int:
    """Fill every 4-connected free region but the largest as occupied (in place); return how many were filled."""
    regions, count = ndimage.label(~occupied)
    if count <= 1:
        return 0
    sizes = np.bincount(regions.ravel())
    sizes[0] = 0
    keep = int(np.argmax(sizes))
    occupied[(regions != keep) & (regions != 0)] = True
    return count - 1


def _start_pose(occupied: NDArray[np.bool_], labels: NDArray[np.int32], grid: Grid) -> NDArray[np.float64] | None:
    """A pose in the circulation nearest the building's centre, with START_CLEARANCE, along the corridor.

    The circulation cell nearest the centre is looked for on every ``step``-th row and column. The
    centre often falls half-way between such cells, so exact ties are common; they are broken by the
    distance at full resolution, then by row-major order, never by how a sort happens to order equal keys
    (numpy's default sort orders them differently on AVX-512 CPUs).
    """
    step = 4
    coarse = labels[::step, ::step]
    rows, cols = np.nonzero(coarse > 0)
    centre_r, centre_c = rows.mean(), cols.mean()
    fine_r, fine_c = np.nonzero(labels > 0)
    fine_centre_r, fine_centre_c = fine_r.mean(), fine_c.mean()
    rows, cols = np.nonzero(coarse == CIRCULATION)  # row-major order
    if len(rows) == 0:
        return None
    coarse_d2 = (rows - centre_r) ** 2 + (cols - centre_c) ** 2
    fine_d2 = (rows * step - fine_centre_r) ** 2 + (cols * step - fine_centre_c) ** 2
    nearest = np.lexsort((fine_d2, coarse_d2))[0]  # lexsort is stable: remaining ties keep row-major order
    centre_r, centre_c = int(rows[nearest]) * step, int(cols[nearest]) * step
    size = 2 * grid.px(START_CLEARANCE) + 1
    # Prefer the circulation near the centre; narrow hallways (houses) may have no such room, and then
    # any free cell will do.
    searches = [(reach, kind) for kind in (CIRCULATION, None) for reach in (grid.px(12.0), max(occupied.shape))]
    for reach, kind in searches:
        r0, c0 = max(0, centre_r - reach), max(0, centre_c - reach)
        window = (slice(r0, centre_r + reach), slice(c0, centre_c + reach))
        free = (~occupied[window]).view(np.uint8)
        # Outside the window counts as occupied: the default 'reflect' would mirror free cells over walls.
        strip = ndimage.minimum_filter1d(free, size, axis=0, mode="constant", cval=0)
        roomy = ndimage.minimum_filter1d(strip, size, axis=1, mode="constant", cval=0).view(bool)
        allowed = labels[window] == CIRCULATION if kind is not None else labels[window] > 0
        cand_r, cand_c = np.nonzero(roomy & allowed)
        if len(cand_r):
            break
    else:
        return None
    best = int(np.argmin((cand_r + r0 - centre_r) ** 2 + (cand_c + c0 - centre_c) ** 2))
    r, c = int(cand_r[best]) + r0, int(cand_c[best]) + c0
    run = []
    for line, i in ((occupied[r, :], c), (occupied[:, c], r)):
        walls = np.flatnonzero(line)
        after = walls[walls > i]
        before = walls[walls < i]
        run.append((after[0] if len(after) else len(line)) - (before[-1] if len(before) else -1))
    heading = 0.0 if run[0] >= run[1] else np.pi / 2
    x, y = grid.cell_centre(r, c)
    return np.array([x, y, heading])


def _plan_all_doors(labels, uses, boxes, grid, wall_k, rng):
    """Doors for every room; rooms that cannot get one are merged into a neighbour and we try again."""
    for _ in range(6):
        doors, pending = plan_doors(labels, uses, boxes, grid, wall_k, rng)
        if not pending:
            return doors
        for k in pending:
            if k in boxes:
                merge_room(labels, boxes, k, neighbour_of(labels, k, boxes[k]))
    for k in pending:
        uses[k - 2] = ("shaft", uses[k - 2][1])
    return doors


def build_grid(spec: KindSpec, shape_area: float, gross: float, seed: int, resolution: float) -> Built:
    """Run the whole pipeline once.

    Parameters
    ----------
    spec:
        The building kind.
    shape_area:
        Gross area (m^2) the shape and its structure are chosen for (kept fixed while ``gross`` is
        tuned, so that tuning changes lengths only).
    gross:
        Gross footprint (m^2) to lay out.
    seed:
        Seed of the pass's random generator.
    resolution:
        Cell size (m).
    """
    rng = np.random.default_rng(seed)
    shape = choose_shape(spec, shape_area, rng)
    plan = build_plan(spec, shape, shape_area, gross, rng)
    grid = Grid.for_plan(plan, resolution)
    labels, uses = paint_labels(plan, grid)
    boxes = clean_labels(labels, uses, grid)
    wall_k = wall_pixels(resolution)
    doors = _plan_all_doors(labels, uses, boxes, grid, wall_k, rng)
    occupied = draw_walls(labels, wall_k)
    for k in sorted(boxes):
        if uses[k - 2][0] == "shaft":
            occupied[boxes[k]] |= labels[boxes[k]] == k
    door_mask, reserved = carve_doors(occupied, doors, grid, wall_k)
    placer = Placer(occupied, labels, reserved, grid)
    furnish_circulation(placer, plan, rng)
    present = 0
    for k in sorted(boxes):
        use, style = uses[k - 2]
        box = boxes[k]
        inner = (labels[box] == k) & ~occupied[box] & ~door_mask[box]
        rows, cols = np.flatnonzero(inner.any(axis=1)), np.flatnonzero(inner.any(axis=0))
        if use == "shaft" or len(rows) == 0:
            continue
        present += 1
        r0, c0 = box[0].start, box[1].start
        furnish_room(
            placer,
            k,
            (r0 + int(rows[0]), r0 + int(rows[-1]) + 1, c0 + int(cols[0]), c0 + int(cols[-1]) + 1),
            use,
            style,
            rng,
        )
    keep_largest_region(occupied)
    start = _start_pose(occupied, labels, grid)
    footprint = float(np.count_nonzero(labels)) * resolution**2
    corridors = [_centre_line(rect, axis) for rect, axis, _style in plan.corridors]
    return Built(occupied, grid, start, shape, present, [door_record(d, grid) for d in doors], footprint, corridors)


def _centre_line(rect, axis: str) -> list[float]:
    """``[x0, y0, x1, y1]`` (m): the centre line of a corridor rectangle along its axis."""
    if axis == "x":
        y = 0.5 * (rect.y0 + rect.y1)
        return [round(rect.x0, 3), round(y, 3), round(rect.x1, 3), round(y, 3)]
    x = 0.5 * (rect.x0 + rect.x1)
    return [round(x, 3), round(rect.y0, 3), round(x, 3), round(rect.y1, 3)]
