"""The particles' maps: endpoint-mean grids stored as shared, copy-on-write tiles.

Every particle sees its own map, but the maps live in one pool of ``TILE x TILE``-cell tiles
(:data:`~slamtrials.slam.gmapping.kernels.TILE` = 32, 1.6 m at 5 cm). A particle's map is a directory
of tile ids; particles descended from the same parent point at the same tiles until one of them writes,
and only then is that one tile copied. Resampling therefore copies directories (4 bytes per tile),
never cells, and 40 particles cost little more than one map plus what each saw since their paths split.

Cells hold what GMapping's particle maps hold (spec/gmapping.md, section 3): the number of laser
endpoints in the cell and their mean position (as an offset from the cell's corner).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from slamtrials.slam.gmapping.kernels import EMPTY, EMPTY_TILE, TILE, TILE_SHIFT, register_endpoints

__all__ = ["TileMaps"]

#: Directory tiles added on each side when the directories grow.
_GROW_TILES = 8


class TileMaps:
    """``N`` particle maps sharing a pool of copy-on-write tiles.

    Parameters
    ----------
    particles:
        Number of maps ``N``.
    resolution:
        Cell size (m).
    initial_tiles:
        Starting pool capacity (tiles); it doubles whenever it runs short.

    Attributes
    ----------
    directories:
        int32 ``[N, TR, TC]``: tile id per directory cell, -1 where the particle has no tile.
    tile_col0, tile_row0:
        Global tile index of directory cell (0, 0) (tiles are anchored at the map frame's origin).
    count, mean:
        The pool: int32 ``[K, TILE, TILE]`` endpoint counts and float32 ``[K, TILE, TILE, 2]`` mean offsets
        (m) from each cell's lower-left corner (:data:`~slamtrials.slam.gmapping.kernels.EMPTY` where the
        count is 0). Tiles never handed out (from ``state[1]`` on) may hold anything once the pool grew.
    refs:
        int32 ``[K]``: directory entries pointing at each tile.

    Tile :data:`~slamtrials.slam.gmapping.kernels.EMPTY_TILE` (0) is never handed out: the scan matcher
    reads it for cells whose particle has no tile, so its windows need no branch per cell.
    """

    def __init__(self, particles: int, resolution: float, *, initial_tiles: int = 1024):
        initial_tiles = max(int(initial_tiles), EMPTY_TILE + 1)
        self.resolution = float(resolution)
        self.directories = np.full((particles, 0, 0), -1, dtype=np.int32)
        self.tile_col0 = 0
        self.tile_row0 = 0
        self.count = np.zeros((initial_tiles, TILE, TILE), dtype=np.int32)
        self.mean = np.full((initial_tiles, TILE, TILE, 2), EMPTY, dtype=np.float32)
        self.refs = np.zeros(initial_tiles, dtype=np.int32)
        self.free_stack = np.zeros(initial_tiles, dtype=np.int32)
        # (tiles on the free stack, tiles ever allocated); tile 0 stays empty for reading (EMPTY_TILE)
        self.state = np.array([0, EMPTY_TILE + 1], dtype=np.int64)

    @property
    def particles(self) -> int:
        return int(self.directories.shape[0])

    @property
    def tiles_in_use(self) -> int:
        """Distinct tiles held by at least one particle."""
        return int(np.count_nonzero(self.refs))

    def nbytes(self) -> int:
        """Bytes held by the pool and the directories."""
        return int(
            self.count.nbytes + self.mean.nbytes + self.refs.nbytes + self.free_stack.nbytes + self.directories.nbytes
        )

    def ensure(self, low: NDArray[np.float64], high: NDArray[np.float64]) -> None:
        """Grow every directory so it covers the box from ``low`` to ``high`` (map frame, (x, y), m)."""
        scale = 1.0 / (self.resolution * TILE)
        lo = np.floor(np.asarray(low) * scale).astype(np.int64)
        hi = np.floor(np.asarray(high) * scale).astype(np.int64)
        _, rows, cols = self.directories.shape
        if (
            rows
            and cols
            and lo[0] >= self.tile_col0
            and lo[1] >= self.tile_row0
            and hi[0] < self.tile_col0 + cols
            and hi[1] < self.tile_row0 + rows
        ):
            return
        if rows and cols:
            lo = np.minimum(lo, [self.tile_col0, self.tile_row0])
            hi = np.maximum(hi, [self.tile_col0 + cols - 1, self.tile_row0 + rows - 1])
        col0, row0 = int(lo[0]) - _GROW_TILES, int(lo[1]) - _GROW_TILES
        shape = (self.particles, int(hi[1]) + _GROW_TILES + 1 - row0, int(hi[0]) + _GROW_TILES + 1 - col0)
        grown = np.full(shape, -1, dtype=np.int32)
        r, c = self.tile_row0 - row0, self.tile_col0 - col0
        grown[:, r : r + rows, c : c + cols] = self.directories
        self.directories, self.tile_col0, self.tile_row0 = grown, col0, row0

    def _grow_pool(self, needed: int) -> None:
        """Make room for at least ``needed`` more tiles (the capacity at least doubles).

        Only the tiles handed out so far are copied, and the new ones are left uninitialised (no page of
        them is touched here): ``register_endpoints`` fills a tile when it hands it out.
        """
        capacity = self.count.shape[0]
        grown = capacity + max(capacity, needed)
        allocated = int(self.state[1])
        count = np.empty((grown, TILE, TILE), np.int32)
        count[:allocated] = self.count[:allocated]
        mean = np.empty((grown, TILE, TILE, 2), np.float32)
        mean[:allocated] = self.mean[:allocated]
        self.count, self.mean = count, mean
        self.refs = np.concatenate([self.refs, np.zeros(grown - capacity, np.int32)])
        self.free_stack = np.concatenate([self.free_stack, np.zeros(grown - capacity, np.int32)])

    def register(self, endpoints_x: NDArray[np.float64], endpoints_y: NDArray[np.float64]) -> None:
        """Add particle ``p``'s endpoints (row ``p`` of float64 ``[N, B]`` arrays, map frame, m) to its map."""
        ex = np.ascontiguousarray(endpoints_x, dtype=np.float64)
        ey = np.ascontiguousarray(endpoints_y, dtype=np.float64)
        if ex.size == 0:
            return
        self.ensure(np.array([ex.min(), ey.min()]), np.array([ex.max(), ey.max()]))
        done = 0
        while done < self.particles:
            done = register_endpoints(
                self.directories,
                self.count,
                self.mean,
                self.refs,
                self.free_stack,
                self.state,
                self.tile_col0,
                self.tile_row0,
                self.resolution,
                ex,
                ey,
                done,
            )
            if done < self.particles:
                self._grow_pool(ex.shape[1])

    def resample(self, indexes: NDArray[np.intp]) -> None:
        """Particle ``j`` takes the map of particle ``indexes[j]``; tiles no one holds are released."""
        self.directories = self.directories[np.asarray(indexes)]
        held = self.directories[self.directories >= 0]
        allocated = int(self.state[1])
        self.refs[:] = 0
        self.refs[:allocated] = np.bincount(held, minlength=allocated)[:allocated]
        released = np.flatnonzero(self.refs[:allocated] == 0).astype(np.int32)
        released = released[released != EMPTY_TILE]
        self.free_stack[: released.size] = released
        self.state[0] = released.size

    def cell_mean(self, particle: int, xy: NDArray[np.float64]) -> tuple[int, NDArray[np.float64]]:
        """Endpoint count and mean (m) of the cell holding map-frame point ``xy`` in ``particle``'s map."""
        gc, gr = (int(math.floor(v * (1.0 / self.resolution))) for v in xy)  # exactly as the kernels
        lc, lr = gc - (self.tile_col0 << TILE_SHIFT), gr - (self.tile_row0 << TILE_SHIFT)
        _, rows, cols = self.directories.shape
        if lc < 0 or lr < 0 or (lr >> TILE_SHIFT) >= rows or (lc >> TILE_SHIFT) >= cols:
            return 0, np.full(2, np.nan)
        tile = self.directories[particle, lr >> TILE_SHIFT, lc >> TILE_SHIFT]
        if tile < 0:
            return 0, np.full(2, np.nan)
        i, j = gr & (TILE - 1), gc & (TILE - 1)
        n = int(self.count[tile, i, j])
        if n == 0:
            return 0, np.full(2, np.nan)
        return n, np.array(
            [
                gc * self.resolution + float(self.mean[tile, i, j, 0]),
                gr * self.resolution + float(self.mean[tile, i, j, 1]),
            ]
        )
