"""The correlation kernel's sums over the search lattice equal the point-by-point response of each pose,
and points are read at Karto's flat index (a point beyond a row's end reads the padding or the next row)."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.slam.karto.correlation import _evenly_spaced, _nonzero_rows, _response, _totals, _totals_sparse


@pytest.mark.parametrize("even", [True, False])
def test_lattice_sums_equal_each_poses_response(even):
    rng = np.random.default_rng(7)
    grid = rng.integers(0, 101, size=(60, 70)).astype(np.uint8)
    grid[rng.random(grid.shape) < 0.7] = 0  # mostly empty, as a smeared scan grid
    n_angles, n_points = 3, 40
    # offsets reaching past every edge of the array from some of the positions
    drow = rng.integers(-35, 36, size=(n_angles, n_points))
    dcol = rng.integers(-40, 41, size=(n_angles, n_points))
    rows = np.arange(5, 55, 5, dtype=np.int64)
    cols = np.arange(3, 67, 4, dtype=np.int64)
    if not even:
        cols[4:] += 1  # a rounding step off the stride
    totals = _totals(grid, rows, cols, dcol, drow)
    expected = np.array(
        [[[_response(grid, r, c, dcol, drow, a, 1.0) for c in cols] for r in rows] for a in range(n_angles)]
    )
    assert np.array_equal(totals, expected)
    off_rows = (rows[:, None] + drow.ravel() < 0) | (rows[:, None] + drow.ravel() >= grid.shape[0])
    off_cols = (cols[:, None] + dcol.ravel() < 0) | (cols[:, None] + dcol.ravel() >= grid.shape[1])
    inside = (~off_cols).all(axis=0)  # points whose columns are all on the array, from every position
    assert off_rows.any() and inside.any() and not inside.all()  # both paths of the kernel
    assert (totals > 0).mean() > 0.9


def test_the_nonzero_cells_walk_gives_the_same_sums():
    rng = np.random.default_rng(11)
    grid = rng.integers(1, 101, size=(50, 80)).astype(np.uint8)
    grid[rng.random(grid.shape) < 0.85] = 0
    grid[20] = 0  # an empty row
    drow = rng.integers(-30, 31, size=(4, 25))
    dcol = rng.integers(-45, 46, size=(4, 25))
    rows = np.arange(4, 46, 3, dtype=np.int64)
    cols = np.arange(2, 78, 2, dtype=np.int64)
    assert _evenly_spaced(cols) and not _evenly_spaced(np.array([3, 5, 8], dtype=np.int64))
    starts, nonzero_cols, values = _nonzero_rows(grid)
    assert starts[-1] == np.count_nonzero(grid) and np.array_equal(values, grid[grid != 0])
    sparse = _totals_sparse(starts, nonzero_cols, values, grid.shape[1], rows, cols, dcol, drow)
    assert np.array_equal(sparse, _totals(grid, rows, cols, dcol, drow)) and sparse.any()


def test_a_point_beyond_a_rows_end_reads_the_padding_or_the_next_row_as_karto_does():
    # Karto's grid rows are stored with a stride rounded up to a multiple of 8, and GetResponse reads
    # data[position index + point offset] with only the flat index checked: a column past the row's end
    # lands in the zero padding, or, past the stride, on the next row
    grid = np.zeros((10, 16), dtype=np.uint8)  # 13 columns in use, padded to 16
    grid[5, 2] = 100  # on the row after the position's
    grid[4, 12] = 40  # the last column in use, on the position's row
    drow = np.array([[0, 0, 0]])
    dcol = np.array([[1, 4, 7]])  # from column 11: column 12, padding column 15, next row's column 2
    assert _response(grid, 4, 11, dcol, drow, 0, 1.0) == 140.0
    rows = np.array([4], dtype=np.int64)
    cols = np.array([11], dtype=np.int64)
    assert _totals(grid, rows, cols, dcol, drow)[0, 0, 0] == 140
    starts, nonzero_cols, values = _nonzero_rows(grid)
    wide_cols = np.arange(1, 13, 2, dtype=np.int64)  # a row of positions whose cells run onto the next row
    sparse = _totals_sparse(starts, nonzero_cols, values, grid.shape[1], rows, wide_cols, dcol, drow)
    assert np.array_equal(sparse, _totals(grid, rows, wide_cols, dcol, drow))
    assert sparse[0, 0, 5] == 140  # position column 11
    # off the whole array (before the first cell, after the last) nothing is read
    assert _response(grid, 0, 0, np.array([[-1]]), np.array([[0]]), 0, 1.0) == 0.0
    assert _response(grid, 9, 15, np.array([[1]]), np.array([[0]]), 0, 1.0) == 0.0
