"""The paper's termination rule: stop when two consecutive map snapshots are nearly the same.

:class:`SnapshotTermination` is polled every step with the simulated time and the current map. Every
snapshot period it takes a snapshot: the map as a grey image (occupied 0, free 255, unknown
``unknown_grey``), and compares it with the previous one (spec/simulation.md):

* alignment: maps grow, so the older image is placed inside the newer one's extent using the two map
  origins (same resolution; the offset is rounded to whole cells, origin rotations are ignored, they
  are 0 in slamtrials' maps); what the older image does not cover reads as unknown;
* both images are downscaled by ``downscale`` (block mean, the edges padded with unknown grey);
* the mean square error over pixels, times ``channels`` (the seed system summed it over the three
  channels of colour images whose channels are equal), is compared with ``mse_threshold``.

Period: ``small_period`` (120 s) for small environments, ``large_period`` (600 s) for large ones. An
environment is large when its free area is at least ``size_threshold`` m^2; that area is the one given
to the constructor if any, else the known free area of the map at the time of the snapshot (so the
period can change from one snapshot to the next while a large building is being discovered). The first
snapshot is taken one period after the start, so the earliest stop is after two periods.

Reasons returned by :meth:`SnapshotTermination.check`: ``"map_converged"``, ``"max_snapshots"``,
``"time_cap"``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials.explore.config import TerminationConfig
from slamtrials.explore.gridframe import FREE_BELOW, map_arrays

__all__ = ["Snapshot", "SnapshotTermination", "align_into", "downscale", "free_area", "map_image", "snapshot_mse"]


def map_image(grid: NDArray[np.int8], unknown_grey: int = 205) -> NDArray[np.uint8]:
    """uint8 ``[H, W]`` grey image of a map: occupied (>= 50) 0, free 255, unknown (< 0) ``unknown_grey``."""
    grid = np.asarray(grid)
    image = np.full(grid.shape, unknown_grey, dtype=np.uint8)
    image[(grid >= 0) & (grid < FREE_BELOW)] = 255
    image[grid >= FREE_BELOW] = 0
    return image


def free_area(grid: NDArray[np.int8], resolution: float) -> float:
    """Known free area (m^2) of a map grid."""
    grid = np.asarray(grid)
    return float(np.count_nonzero((grid >= 0) & (grid < FREE_BELOW))) * resolution * resolution


@dataclass(frozen=True, eq=False)
class Snapshot:
    """One snapshot of the map.

    Attributes
    ----------
    t:
        Time taken (s).
    image:
        uint8 ``[H, W]`` grey image (:func:`map_image`), row 0 at the top.
    resolution:
        Cell size (m).
    origin:
        float64 ``[3]`` map-frame pose of the lower-left corner of the image's lower-left cell.
    area:
        Known free area (m^2).
    """

    t: float
    image: NDArray[np.uint8]
    resolution: float
    origin: NDArray[np.float64]
    area: float


def align_into(older: Snapshot, newer: Snapshot, fill: int = 205) -> NDArray[np.uint8]:
    """The older snapshot's image resampled onto the newer one's cells, ``fill`` where it has none.

    The offset between the two grids is rounded to whole cells. Both must have the same resolution.
    """
    if not math.isclose(older.resolution, newer.resolution, rel_tol=1e-9):
        raise ValueError(f"snapshots differ in resolution: {older.resolution} m vs {newer.resolution} m")
    res = newer.resolution
    dc = round((older.origin[0] - newer.origin[0]) / res)  # older column 0 in newer columns
    dv = round((older.origin[1] - newer.origin[1]) / res)  # older bottom row, in rows up from newer's bottom
    oh, ow = older.image.shape
    nh, nw = newer.image.shape
    dr = nh - oh - dv  # older row 0 in newer rows (from the top)
    out = np.full((nh, nw), fill, dtype=np.uint8)
    r0, r1 = max(dr, 0), min(dr + oh, nh)
    c0, c1 = max(dc, 0), min(dc + ow, nw)
    if r0 < r1 and c0 < c1:
        out[r0:r1, c0:c1] = older.image[r0 - dr : r1 - dr, c0 - dc : c1 - dc]
    return out


def downscale(image: NDArray[np.uint8], factor: int, fill: int = 205) -> NDArray[np.float64]:
    """float64 ``[ceil(H / f), ceil(W / f)]`` block means of ``image``; the edges are padded with ``fill``."""
    if factor <= 1:
        return image.astype(np.float64)
    h, w = image.shape
    ph, pw = -h % factor, -w % factor
    padded = np.pad(image, ((0, ph), (0, pw)), constant_values=fill).astype(np.float64)
    return padded.reshape((h + ph) // factor, factor, (w + pw) // factor, factor).mean(axis=(1, 3))


@njit(cache=True, nogil=True)
def _block_squared_error(older, dr, dc, newer, factor, fill):  # pragma: no cover - compiled
    """Sum over the ``factor`` x ``factor`` blocks of ``newer`` (uint8 ``[H, W]``, padded with ``fill``) of
    the squared difference of the block means of ``older`` (uint8, its row 0 at ``newer``'s row ``dr``,
    its column 0 at column ``dc``; ``fill`` where it has no cell) and ``newer``; and the block count.

    One pass, no images allocated: the same numbers as :func:`downscale` of :func:`align_into` and of
    the newer image, block by block (each block mean is a sum of integers divided by ``factor^2``)."""
    nh, nw = newer.shape
    oh, ow = older.shape
    rows = (nh + factor - 1) // factor
    cols = (nw + factor - 1) // factor
    cells = float(factor * factor)
    total = 0.0
    for bi in range(rows):
        for bj in range(cols):
            sum_old = 0
            sum_new = 0
            for r in range(bi * factor, bi * factor + factor):
                for c in range(bj * factor, bj * factor + factor):
                    if r < nh and c < nw:
                        sum_new += newer[r, c]
                        orow, ocol = r - dr, c - dc
                        if 0 <= orow < oh and 0 <= ocol < ow:
                            sum_old += older[orow, ocol]
                        else:
                            sum_old += fill
                    else:
                        sum_new += fill
                        sum_old += fill
            d = sum_old / cells - sum_new / cells
            total += d * d
    return total, rows * cols


def snapshot_mse(older: Snapshot, newer: Snapshot, *, factor: int = 4, channels: int = 3, fill: int = 205) -> float:
    """Mean square error (grey levels^2, summed over ``channels``) between two snapshots (module docstring):
    the mean over the blocks of :func:`downscale` of :func:`align_into` and of the newer image, computed in
    one compiled pass (a snapshot of a building with long free rays holds tens of millions of cells)."""
    if not math.isclose(older.resolution, newer.resolution, rel_tol=1e-9):
        raise ValueError(f"snapshots differ in resolution: {older.resolution} m vs {newer.resolution} m")
    if newer.image.size == 0:
        return 0.0
    res = newer.resolution
    dc = round((older.origin[0] - newer.origin[0]) / res)  # as align_into
    dv = round((older.origin[1] - newer.origin[1]) / res)
    dr = newer.image.shape[0] - older.image.shape[0] - dv
    if factor <= 1:
        factor = 1
    total, blocks = _block_squared_error(
        np.ascontiguousarray(older.image), int(dr), int(dc), np.ascontiguousarray(newer.image), int(factor), int(fill)
    )
    return total / blocks * channels


class SnapshotTermination:
    """The paper's termination rule (see the module docstring).

    Parameters
    ----------
    config:
        Periods, threshold, downscaling, caps; ``None`` means the defaults.
    area:
        Free area of the environment (m^2), if known, to choose the snapshot period once and for all.

    Attributes
    ----------
    snapshots:
        Number of snapshots taken.
    history:
        ``[(t, mse)]`` one entry per comparison.
    reason:
        The reason returned once the rule fired, else ``None``.
    """

    def __init__(self, config: TerminationConfig | None = None, *, area: float | None = None):
        self.config = TerminationConfig() if config is None else config
        if area is not None and not (math.isfinite(area) and area >= 0):
            raise ValueError(f"area must be a non-negative number of m^2, got {area!r}")
        self.area = area
        self.reset()

    def reset(self) -> None:
        """Forget all snapshots."""
        self.snapshots = 0
        self.history: list[tuple[float, float]] = []
        self.reason: str | None = None
        self._last: Snapshot | None = None
        self._next: float | None = None
        self._t0: float | None = None

    def period(self, area: float) -> float:
        """Snapshot period (s) of an environment with ``area`` m^2 of free space."""
        cfg = self.config
        size = self.area if self.area is not None else area
        return cfg.large_period if size >= cfg.size_threshold else cfg.small_period

    @property
    def last_snapshot(self) -> Snapshot | None:
        """The latest snapshot, or ``None``."""
        return self._last

    def check(self, t: float, occupancy: Any) -> str | None:
        """Poll the rule at time ``t`` (s) with the current map; return a reason to stop, or ``None``.

        ``occupancy`` is any object with ``grid``, ``resolution`` and ``origin`` (see
        :class:`slamtrials.explore.Explorer`). Once a reason was returned it is returned again.
        """
        if self.reason is not None:
            return self.reason
        cfg = self.config
        if self._t0 is None:
            self._t0 = float(t)
        if t - self._t0 >= cfg.max_time:
            self.reason = "time_cap"
            return self.reason
        if self._next is None:
            self._next = self._t0 + self.period(self._area_of(occupancy))
        if t < self._next - 1e-9:
            return None
        grid, resolution, origin = map_arrays(occupancy)
        snap = Snapshot(
            float(t), map_image(grid, cfg.unknown_grey), resolution, origin.copy(), free_area(grid, resolution)
        )
        self.snapshots += 1
        if self._last is not None:
            mse = snapshot_mse(self._last, snap, factor=cfg.downscale, channels=cfg.channels, fill=cfg.unknown_grey)
            self.history.append((float(t), mse))
            if mse < cfg.mse_threshold:
                self.reason = "map_converged"
        self._last = snap
        self._next = float(t) + self.period(snap.area)
        if self.reason is None and self.snapshots >= cfg.max_snapshots:
            self.reason = "max_snapshots"
        return self.reason

    def _area_of(self, occupancy: Any) -> float:
        if self.area is not None:
            return self.area
        grid, resolution, _ = map_arrays(occupancy)
        return free_area(grid, resolution)
