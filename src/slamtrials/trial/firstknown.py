"""When the SLAM map first knew each place: :class:`FirstKnown`, behind the coverage curve of a trial.

A trial shows :meth:`FirstKnown.update` the SLAM map it has at chosen frames (the samples). It keeps one
raster in the map frame holding, per cell, the first sample at which a map knew that cell (free or
occupied). The raster grows with the maps (their origins differ by whole cells; the offset is rounded,
origin rotations are ignored, they are 0 in slamtrials' maps). An update costs one pass over the map's
cells (a compiled loop), so a sample every few simulated seconds costs nothing next to the SLAM update
that made the map.

At the end, :func:`coverage_curve` reads the raster at the reachable world cells carried into the map
frame (:func:`~slamtrials.trial.coverage.local_map_points`) and counts, per sample, the cells that the
final map knows and that were known by that sample.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials.record import UNKNOWN, OccupancyGrid

__all__ = ["FirstKnown", "coverage_curve", "sample_period", "SAMPLE_PERIOD", "SECONDS_PER_CELL"]

#: The least simulated time (s) between two samples: a trial samples the map it has when a new one was
#: published (GMapping's every ``map_update_interval``), at most once in this time...
SAMPLE_PERIOD = 1.0
#: ... or in this time per map cell (s), whichever is longer: 4 s per million cells keeps the samples'
#: cost below about 0.4 % of a trial however large the building (a sample reads every cell once).
SECONDS_PER_CELL = 4e-6

#: Raster value of a cell no map has known yet.
_NEVER = np.iinfo(np.int32).max
#: Cells added on each side when the raster grows, so that a growing map does not reallocate it each time.
_MARGIN = 64


def sample_period(occupancy: OccupancyGrid) -> float:
    """The least simulated time (s) from a sample of ``occupancy`` to the next: :data:`SAMPLE_PERIOD`, or
    :data:`SECONDS_PER_CELL` times its cells when longer."""
    return max(SAMPLE_PERIOD, occupancy.grid.size * SECONDS_PER_CELL)


class FirstKnown:
    """Per map-frame cell, the first sample whose map knew it.

    Attributes
    ----------
    frames:
        The frame index of each sample, in the order of :meth:`update` calls.
    last_map:
        The map of the latest sample, or None.
    """

    def __init__(self) -> None:
        self.frames: list[int] = []
        self.last_map: OccupancyGrid | None = None
        self._raster = np.zeros((0, 0), dtype=np.int32)  # [rows up, cols]: row 0 is the BOTTOM row
        self._anchor: NDArray[np.float64] | None = None  # map-frame (x, y) of lattice cell (0, 0)'s corner
        self._resolution = math.nan
        self._low = (0, 0)  # lattice (row up, col) of raster cell (0, 0)

    def update(self, frame: int, occupancy: OccupancyGrid) -> None:
        """Record ``occupancy`` (the map at frame index ``frame``) as the next sample."""
        self.frames.append(int(frame))
        self.last_map = occupancy
        sample = len(self.frames) - 1
        grid = occupancy.grid
        if grid.size == 0:
            return
        resolution = float(occupancy.resolution)
        if self._anchor is None:
            self._anchor = np.array(occupancy.origin[:2], dtype=np.float64)
            self._resolution = resolution
        elif not math.isclose(resolution, self._resolution, rel_tol=1e-9):
            raise ValueError(f"maps differ in resolution: {resolution} m vs {self._resolution} m")
        height, width = grid.shape
        v0 = round((float(occupancy.origin[1]) - self._anchor[1]) / resolution)  # lattice row of the map's bottom
        c0 = round((float(occupancy.origin[0]) - self._anchor[0]) / resolution)
        self._cover(v0, c0, v0 + height, c0 + width)
        _mark(self._raster, v0 - self._low[0], c0 - self._low[1], grid, sample, UNKNOWN, _NEVER)

    def _cover(self, v0: int, c0: int, v1: int, c1: int) -> None:
        """Grow the raster to hold lattice rows ``[v0, v1)`` and columns ``[c0, c1)``."""
        rows, cols = self._raster.shape
        low_v, low_c = self._low
        if rows and v0 >= low_v and c0 >= low_c and v1 <= low_v + rows and c1 <= low_c + cols:
            return
        if rows:
            new_low = (min(v0, low_v) - _MARGIN, min(c0, low_c) - _MARGIN)
            new_high = (max(v1, low_v + rows) + _MARGIN, max(c1, low_c + cols) + _MARGIN)
        else:
            new_low, new_high = (v0 - _MARGIN, c0 - _MARGIN), (v1 + _MARGIN, c1 + _MARGIN)
        raster = np.full((new_high[0] - new_low[0], new_high[1] - new_low[1]), _NEVER, dtype=np.int32)
        if rows:
            r, c = low_v - new_low[0], low_c - new_low[1]
            raster[r : r + rows, c : c + cols] = self._raster
        self._raster, self._low = raster, new_low

    def first_sample(self, points: NDArray[np.float64]) -> NDArray[np.int64]:
        """int64 ``[K]``: the first sample whose map knew the cell under each map-frame point of ``points``
        ``[K, 2]`` (m); ``len(frames)`` for a point no map knew."""
        never = len(self.frames)
        out = np.full(points.shape[0], never, dtype=np.int64)
        if self._anchor is None or self._raster.size == 0:
            return out
        rows, cols = self._raster.shape
        v = np.floor((points[:, 1] - self._anchor[1]) / self._resolution).astype(np.int64) - self._low[0]
        c = np.floor((points[:, 0] - self._anchor[0]) / self._resolution).astype(np.int64) - self._low[1]
        inside = (v >= 0) & (v < rows) & (c >= 0) & (c < cols)
        values = self._raster[v[inside], c[inside]].astype(np.int64)
        out[inside] = np.where(values == _NEVER, never, values)
        return out


@njit(cache=True, nogil=True)
def _mark(raster, r0, c0, grid, sample, unknown, never):  # pragma: no cover - compiled
    """Set ``raster`` cells (int32, row 0 at the BOTTOM) still ``never`` to ``sample`` where ``grid`` (int8
    ``[H, W]``, row 0 at the top) is not ``unknown``; the grid's bottom-left cell is raster cell
    ``(r0, c0)``. One pass over the grid, nothing allocated."""
    height, width = grid.shape
    for i in range(height):
        row = r0 + height - 1 - i
        for j in range(width):
            if grid[i, j] != unknown and raster[row, c0 + j] == never:
                raster[row, c0 + j] = sample


def coverage_curve(first_sample: NDArray[np.int64], known: NDArray[np.bool_], samples: int) -> NDArray[np.float64]:
    """float64 ``[samples]``: per sample, the share of the ``K`` cells that the final map knows (bool ``[K]``
    ``known``) and whose ``first_sample`` (int ``[K]``, :meth:`FirstKnown.first_sample`) is at or before
    that sample. The final map is the last sample, so a cell it knows counts there at the latest (the last
    value is ``known``'s mean, whatever the raster's rounding). All zeros for ``K = 0``."""
    count = first_sample.shape[0]
    if count == 0 or samples == 0:
        return np.zeros(samples, dtype=np.float64)
    firsts = np.minimum(first_sample[np.asarray(known, dtype=bool)], samples - 1)
    return np.cumsum(np.bincount(firsts, minlength=samples)) / count
