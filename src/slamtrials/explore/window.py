"""Windows of a map: the bounding box of its known cells, crops that may stick out of the grid, and
coarser copies for cheap searches over large maps."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["crop", "known_box"]


def known_box(grid: NDArray[np.int8], margin: int = 2) -> tuple[int, int, int, int] | None:
    """``(row0, row1, col0, col1)``: the bounding box of the known cells of ``grid`` plus ``margin``
    cells all round (may stick out of the grid), or ``None`` if no cell is known."""
    known = grid >= 0
    rows = np.flatnonzero(known.any(axis=1))
    if rows.size == 0:
        return None
    cols = np.flatnonzero(known.any(axis=0))
    return int(rows[0]) - margin, int(rows[-1]) + 1 + margin, int(cols[0]) - margin, int(cols[-1]) + 1 + margin


def crop(grid: NDArray[np.int8], row0: int, row1: int, col0: int, col1: int) -> NDArray[np.int8]:
    """int8 ``[row1 - row0, col1 - col0]``: rows ``row0..row1-1`` and columns ``col0..col1-1`` of ``grid``,
    unknown (-1) where the window sticks out of the grid."""
    window = np.full((row1 - row0, col1 - col0), -1, dtype=np.int8)
    sr0, sr1 = max(row0, 0), min(row1, grid.shape[0])
    sc0, sc1 = max(col0, 0), min(col1, grid.shape[1])
    if sr0 < sr1 and sc0 < sc1:
        window[sr0 - row0 : sr1 - row0, sc0 - col0 : sc1 - col0] = grid[sr0:sr1, sc0:sc1]
    return window


def coarsen(grid: NDArray[np.int8], factor: int) -> NDArray[np.int8]:
    """int8 ``[ceil(H / f), ceil(W / f)]``: blocks of ``factor x factor`` cells merged conservatively.

    A block is occupied (100) if any of its cells is (>= 50), else unknown (-1) if any is unknown,
    else free (0). The grid is padded with unknown cells at the top and on the right, so that the
    coarse grid keeps the lower-left corner, i.e. the map origin, of the fine one.
    """
    if factor <= 1:
        return np.asarray(grid, dtype=np.int8)
    h, w = grid.shape
    ph, pw = -h % factor, -w % factor
    padded = np.pad(grid, ((ph, 0), (0, pw)), constant_values=-1)
    blocks = padded.reshape((h + ph) // factor, factor, (w + pw) // factor, factor)
    occupied = (blocks >= 50).any(axis=(1, 3))
    unknown = (blocks < 0).any(axis=(1, 3))
    out = np.zeros(occupied.shape, dtype=np.int8)
    out[unknown] = -1
    out[occupied] = 100
    return out
