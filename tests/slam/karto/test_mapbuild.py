"""The published map follows the nodes' poses and equals a rebuild from scratch."""

from __future__ import annotations

import math

import numpy as np

from slamtrials.record import FREE, OCCUPIED, UNKNOWN
from slamtrials.slam.karto.mapbuild import NodeMap


def _map(laser):
    return NodeMap(0.05, laser, max_urange=laser.range_max, min_pass_through=2, occupancy_threshold=0.1)


def test_moving_nodes_gives_the_grid_of_a_rebuild(square_loop):
    laser = square_loop.laser
    scans = [f.ranges for f in square_loop.frames[:40:4]]
    poses = square_loop.truth[:40:4].copy()
    incremental = _map(laser)
    incremental.update(poses[:5], scans[:5])
    moved = poses.copy()
    moved[:, 0] += 0.3
    moved[:, 2] += 0.05
    incremental.update(moved, scans)
    fresh = _map(laser)
    fresh.update(moved, scans)
    a, b = incremental.occupancy(), fresh.occupancy()
    # the same counts in every global cell (the windows grew differently)
    for counts in ("visits", "hits"):
        cells = []
        for grid in (incremental.grid, fresh.grid):
            array = getattr(grid, counts)
            rows, cols = np.nonzero(array)
            cells.append(
                sorted(zip((rows + grid.row0).tolist(), (cols + grid.col0).tolist(), array[rows, cols].tolist()))
            )
        assert cells[0] == cells[1] and len(cells[0]) > 1000
    assert set(np.unique(a.grid)) <= {FREE, OCCUPIED, UNKNOWN} and (b.grid == OCCUPIED).any()


def test_cells_crossed_fewer_than_min_pass_through_times_stay_unknown(square_loop):
    laser = square_loop.laser
    single = _map(laser)
    single.update(square_loop.truth[:1], [square_loop.frames[0].ranges])
    counts = single.grid.visits
    grid = single.occupancy().grid[::-1]  # row 0 at the bottom, as the counts
    assert (grid[(counts > 0) & (counts <= 2)] == UNKNOWN).all()
    assert math.isclose(single.occupancy().resolution, 0.05)
