"""The :class:`World`: a floor plan as a boolean occupancy grid placed in the world frame.

Grid convention (DESIGN.md): cell index ``(row, col)`` with row 0 at the top of the image, as in the
PNG. World coordinates have y up. ``origin`` is the world pose ``(x, y, theta)`` of the lower-left
corner of the lower-left pixel, exactly as in a ROS map_server YAML. :func:`world_to_cell` and
:func:`cell_to_world` are the only conversions between the two; nothing else may do this arithmetic.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from slamtrials import stablemath
from slamtrials.errors import WorldError

__all__ = ["World", "world_to_map", "world_to_cell", "cell_to_world", "DEFAULT_START_CLEARANCE"]

#: Clearance (m) the automatic start pose asks for: the 0.15 m robot footprint radius plus a margin.
DEFAULT_START_CLEARANCE = 0.5


@dataclass(frozen=True, eq=False)
class World:
    """A floor plan ready to simulate in.

    Attributes
    ----------
    occupied:
        bool ``[H, W]``, True where the cell is a wall or obstacle (or unknown). Row 0 is the top row.
    resolution:
        Cell size in metres per pixel (> 0).
    origin:
        float64 ``[3]`` world pose (x, y, theta) of the lower-left corner of the grid.
    name:
        Short name used in run folders and reports.
    start:
        float64 ``[3]`` robot start pose in the world frame. ``None`` at construction picks a free cell
        near the centre of the largest free region with room for the robot (:func:`choose_start_pose`).
    metadata:
        Facts about the source (file, format, building type, generator seed, ...). JSON-serialisable.
    """

    occupied: NDArray[np.bool_]
    resolution: float
    origin: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    name: str = "world"
    start: NDArray[np.float64] | None = None
    metadata: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        occupied = np.asarray(self.occupied)
        if occupied.ndim != 2 or occupied.shape[0] < 2 or occupied.shape[1] < 2:
            raise WorldError(
                f"world {self.name!r}: occupancy grid must be 2-D and at least 2x2, got shape {occupied.shape}"
            )
        resolution = float(self.resolution)
        if not np.isfinite(resolution) or resolution <= 0:
            raise WorldError(
                f"world {self.name!r}: resolution must be a positive number of metres per pixel, got {self.resolution!r}"
            )
        origin = np.array(self.origin, dtype=np.float64).reshape(
            -1
        )  # copies: the flags below must not touch the caller's arrays
        if origin.shape == (2,):
            origin = np.append(origin, 0.0)
        if origin.shape != (3,) or not np.all(np.isfinite(origin)):
            raise WorldError(
                f"world {self.name!r}: origin must be three finite numbers (x, y, theta), got {self.origin!r}"
            )
        occupied = np.array(occupied, dtype=bool, order="C")
        occupied.setflags(write=False)
        origin.setflags(write=False)
        object.__setattr__(self, "occupied", occupied)
        object.__setattr__(self, "resolution", resolution)
        object.__setattr__(self, "origin", origin)
        if occupied.all():
            raise WorldError(f"world {self.name!r}: the floor plan has no free space")
        start = choose_start_pose(self) if self.start is None else np.array(self.start, dtype=np.float64).reshape(-1)
        if start.shape != (3,) or not np.all(np.isfinite(start)):
            raise WorldError(
                f"world {self.name!r}: start pose must be three finite numbers (x, y, theta), got {self.start!r}"
            )
        row, col = world_to_cell(self, start[:2])
        if not (0 <= row < self.height and 0 <= col < self.width) or occupied[row, col]:
            raise WorldError(f"world {self.name!r}: start pose ({start[0]:.2f}, {start[1]:.2f}) is not in free space")
        start.setflags(write=False)
        object.__setattr__(self, "start", start)

    @property
    def height(self) -> int:
        """Number of rows of the grid."""
        return int(self.occupied.shape[0])

    @property
    def width(self) -> int:
        """Number of columns of the grid."""
        return int(self.occupied.shape[1])

    @property
    def size_m(self) -> tuple[float, float]:
        """(width, height) of the grid in metres."""
        return self.width * self.resolution, self.height * self.resolution

    @property
    def free_area(self) -> float:
        """Area of all free cells in square metres."""
        return self.area_of(~self.occupied)

    def area_of(self, cells: NDArray[np.bool_]) -> float:
        """Area (m^2) of the cells set in the bool ``[H, W]`` mask ``cells``."""
        return float(np.count_nonzero(cells)) * self.resolution**2

    @cached_property
    def clearance(self) -> NDArray[np.float64]:
        """float64 ``[H, W]``: distance (m) from each cell centre to the nearest occupied cell centre.

        Cells outside the grid count as occupied, so free cells on the image border have clearance
        of one cell. Occupied cells have clearance 0.
        """
        # Only the bounding box of the free cells (plus a ring of occupied cells) needs the transform:
        # everything outside it is occupied, and the ring is nearer than any occupied cell beyond it.
        rows = np.flatnonzero((~self.occupied).any(axis=1))
        cols = np.flatnonzero((~self.occupied).any(axis=0))
        r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
        padded = np.pad(~self.occupied[r0:r1, c0:c1], 1, constant_values=False)
        out = np.zeros(self.occupied.shape, dtype=np.float64)
        out[r0:r1, c0:c1] = ndimage.distance_transform_edt(padded)[1:-1, 1:-1] * self.resolution
        out.setflags(write=False)
        return out

    @cached_property
    def free_regions(self) -> tuple[NDArray[np.int32], int]:
        """4-connected labelling of free cells: (labels ``[H, W]``, 0 = occupied; number of regions)."""
        labels, count = ndimage.label(~self.occupied)
        return labels.astype(np.int32), int(count)

    def reachable_free(self, pose: ArrayLike | None = None) -> NDArray[np.bool_]:
        """bool ``[H, W]``: free cells 4-connected to the cell under ``pose`` (default: the start pose)."""
        pose = self.start if pose is None else np.asarray(pose, dtype=np.float64)
        row, col = world_to_cell(self, pose[:2])
        labels, _ = self.free_regions
        if not (0 <= row < self.height and 0 <= col < self.width) or labels[row, col] == 0:
            return np.zeros_like(self.occupied)
        return labels == labels[row, col]

    def reachable_by_disc(self, radius: float, pose: ArrayLike | None = None) -> NDArray[np.bool_]:
        """bool ``[H, W]``: free cells a robot with a disc footprint of ``radius`` m can cover, starting at
        ``pose`` (default: the start pose).

        The disc's centre may stand on a cell whose distance to the nearest occupied cell's edge
        (:attr:`clearance` minus half a cell) is at least ``radius``; those cells 8-connected to the
        start's cell are where the robot can go, and every free cell within ``radius`` of one of them is
        covered by its body. Free space behind gaps narrower than the robot (a doorway drawn too
        narrow, the streaks of laser rays in a map made by a real robot) is left out, which
        :meth:`reachable_free` keeps. Exact to within a cell. If the start's cell itself does not pass
        the test (the footprint touches a wall only by a fraction of a cell), the nearest cell that
        does within ``radius`` stands in for it; if there is none, the result is empty.
        """
        pose = self.start if pose is None else np.asarray(pose, dtype=np.float64)
        row, col = world_to_cell(self, pose[:2])
        if not (0 <= row < self.height and 0 <= col < self.width):
            return np.zeros_like(self.occupied)
        fits = (self.clearance - 0.5 * self.resolution >= radius - 1e-9) & ~self.occupied
        if not fits[row, col]:
            reach = int(np.ceil(radius / self.resolution))
            r0, c0 = max(row - reach, 0), max(col - reach, 0)
            window = fits[r0 : row + reach + 1, c0 : col + reach + 1]
            candidates = np.argwhere(window)
            if candidates.size == 0:
                return np.zeros_like(self.occupied)
            nearest = candidates[np.argmin(stablemath.hypot(candidates[:, 0] + r0 - row, candidates[:, 1] + c0 - col))]
            row, col = int(nearest[0] + r0), int(nearest[1] + c0)
        labels, _ = ndimage.label(fits, structure=np.ones((3, 3), dtype=bool))
        centres = labels == labels[row, col]
        # cells within `radius` of a reachable centre: distance transform of the complement, in the
        # bounding box of the centres grown by the radius (all other cells are farther)
        rows = np.flatnonzero(centres.any(axis=1))
        cols = np.flatnonzero(centres.any(axis=0))
        grow = int(np.ceil(radius / self.resolution)) + 1
        r0, r1 = max(rows[0] - grow, 0), min(rows[-1] + grow + 1, self.height)
        c0, c1 = max(cols[0] - grow, 0), min(cols[-1] + grow + 1, self.width)
        out = np.zeros_like(self.occupied)
        cells = ndimage.distance_transform_edt(~centres[r0:r1, c0:c1])
        out[r0:r1, c0:c1] = (cells <= radius / self.resolution + 1e-9) & ~self.occupied[r0:r1, c0:c1]
        return out

    def with_start(self, start: ArrayLike) -> World:
        """A copy of this world with another start pose."""
        return World(
            self.occupied, self.resolution, self.origin, self.name, np.asarray(start, float), dict(self.metadata)
        )

    def __repr__(self) -> str:
        w, h = self.size_m
        return (
            f"World(name={self.name!r}, {self.width}x{self.height} px, {self.resolution:g} m/px, "
            f"{w:.1f}x{h:.1f} m, free {self.free_area:.0f} m^2)"
        )


def world_to_map(world: World, xy: ArrayLike) -> NDArray[np.float64]:
    """World points ``[..., 2]`` (m) -> continuous map coordinates ``[..., 2]`` in cells.

    Map coordinates (u, v) have u along the columns (left to right) and v up from the bottom edge of
    the grid, so cell ``(row, col)`` covers ``col <= u < col + 1`` and ``H - 1 - row <= v < H - row``.
    """
    pts = np.asarray(xy, dtype=np.float64)
    ox, oy, oth = world.origin
    dx, dy = pts[..., 0] - ox, pts[..., 1] - oy
    c, s = stablemath.cos(oth), stablemath.sin(oth)
    out = np.empty(pts.shape)
    out[..., 0] = (c * dx + s * dy) / world.resolution
    out[..., 1] = (-s * dx + c * dy) / world.resolution
    return out


def world_to_cell(world: World, xy: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """World points ``[..., 2]`` (m) -> integer cell indices (rows, cols). May lie outside the grid."""
    uv = world_to_map(world, xy)
    cols = np.floor(uv[..., 0]).astype(np.intp)
    rows = (world.height - 1 - np.floor(uv[..., 1])).astype(np.intp)
    return rows, cols


def cell_to_world(world: World, rows: ArrayLike, cols: ArrayLike) -> NDArray[np.float64]:
    """Cell indices -> world coordinates ``[..., 2]`` (m) of the cell centres."""
    rows = np.asarray(rows, dtype=np.float64)
    cols = np.asarray(cols, dtype=np.float64)
    u = (cols + 0.5) * world.resolution
    v = (world.height - rows - 0.5) * world.resolution
    ox, oy, oth = world.origin
    c, s = stablemath.cos(oth), stablemath.sin(oth)
    return np.stack([ox + c * u - s * v, oy + s * u + c * v], axis=-1)


def choose_start_pose(world: World, clearance: float = DEFAULT_START_CLEARANCE) -> NDArray[np.float64]:
    """A start pose near the centre of the largest free region, with room for the robot.

    Takes the largest 4-connected free region, its centroid, and the cell of that region closest to the
    centroid whose clearance is at least ``clearance`` metres (or, if no cell has that much, at least
    half the region's best clearance). Heading 0. Deterministic.
    """
    labels, count = world.free_regions
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    sizes[0] = 0
    region = labels == int(np.argmax(sizes))
    rows, cols = np.nonzero(region)
    centre_r, centre_c = rows.mean(), cols.mean()
    room = world.clearance[rows, cols]
    needed = min(clearance, 0.5 * float(room.max()))
    ok = room >= needed
    d2 = (rows[ok] - centre_r) ** 2 + (cols[ok] - centre_c) ** 2
    best = int(np.argmin(d2))
    xy = cell_to_world(world, rows[ok][best], cols[ok][best])
    return np.array([xy[0], xy[1], 0.0])
