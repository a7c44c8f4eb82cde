"""Frontier detection on hand-made maps, and the numba kernel against a numpy/scipy reference."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy import ndimage

from slamtrials.explore import find_frontiers
from slamtrials.explore.frontiers import effective_unknown, frontier_mask

F, OCC, U = 0, 100, -1


def test_half_known_room_has_one_straight_frontier():
    grid = np.full((10, 12), U, dtype=np.int8)
    grid[:, :6] = F
    grid[0, :6] = grid[-1, :6] = grid[:, 0] = OCC
    fr = find_frontiers(grid)
    assert fr.count == 1
    assert fr.mask[:, 5].sum() == 8 and fr.mask.sum() == 8  # rows 1..8 of the last free column
    assert fr.sizes.tolist() == [8]
    assert np.allclose(fr.centroids[0], [4.5, 5.0])


def test_occupied_cells_are_never_frontiers_and_walls_close_frontiers():
    grid = np.full((6, 6), U, dtype=np.int8)
    grid[1:5, 1:5] = F
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OCC
    assert find_frontiers(grid).count == 0
    grid[2, -1] = U  # a gap in the wall
    fr = find_frontiers(grid)
    assert fr.count == 1 and fr.mask[2, 4] and fr.mask.sum() == 1


def test_small_frontiers_are_dropped():
    grid = np.full((20, 20), F, dtype=np.int8)
    grid[:, 15:] = U  # a long frontier at column 14
    grid[5, 5] = U  # one unknown cell: its four free neighbours form a small frontier
    fr = find_frontiers(grid, min_cells=1)
    assert fr.count == 2
    fr = find_frontiers(grid, min_cells=5)
    assert fr.count == 1 and fr.sizes.tolist() == [20]


def test_enclosed_unknown_pockets_below_the_area_are_ignored():
    grid = np.full((30, 30), F, dtype=np.int8)
    grid[5:7, 5:7] = U  # 4 cells, enclosed
    grid[15:25, 15:25] = U  # 100 cells, enclosed
    grid[0:2, 28:30] = U  # 4 cells touching the border: open space beyond the map
    fr = find_frontiers(grid, min_cells=1, min_unknown_cells=10)
    assert not fr.mask[4, 5] and not fr.mask[7, 6]
    assert fr.mask[14, 20] and fr.mask[25, 20]
    assert fr.mask[2, 28] and fr.mask[1, 27]
    assert find_frontiers(grid, min_cells=1, min_unknown_cells=0).mask[4, 5]


def reference_mask(grid, min_cells, min_unknown_cells):
    cells = frontier_mask(grid, effective_unknown(grid, min_unknown_cells))
    labels, count = ndimage.label(cells, structure=np.ones((3, 3), bool))
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    keep = sizes >= min_cells
    keep[0] = False
    return keep[labels]


@settings(max_examples=80, deadline=None)
@given(
    arrays(np.int8, st.tuples(st.integers(1, 25), st.integers(1, 25)), elements=st.sampled_from([U, F, F, OCC])),
    st.integers(1, 6),
    st.integers(0, 15),
)
def test_kernel_matches_the_reference(grid, min_cells, min_unknown_cells):
    fr = find_frontiers(grid, min_cells=min_cells, min_unknown_cells=min_unknown_cells)
    assert (fr.mask == reference_mask(grid, min_cells, min_unknown_cells)).all()
    assert fr.sizes.sum() == fr.mask.sum()
    assert set(np.unique(fr.labels)) <= set(range(fr.count + 1))
