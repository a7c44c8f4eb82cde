"""The published map follows the nodes' poses and equals a rebuild from scratch."""

from __future__ import annotations

import math

import numpy as np

from slamtrials.record import FREE, OCCUPIED, UNKNOWN
from slamtrials.slam.gridmap import GridMap
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


def _take_out_and_put_back(laser, poses, moved, scans, n_first):
    """The counts of tracing ``scans[:n_first]`` from ``poses``, then every scan moved from ``poses`` to
    ``moved`` taken out and put back, then the rest traced from ``moved``: the incremental rule by hand."""
    grid = GridMap(0.05)
    grid.integrate_scans(list(poses[:n_first]), scans[:n_first], [1] * n_first, laser, max_urange=laser.range_max)
    out, weights, ranges = [], [], []
    for k in range(n_first):
        if (poses[k] != moved[k]).any():
            out += [poses[k], moved[k]]
            ranges += [scans[k], scans[k]]
            weights += [-1, 1]
    for k in range(n_first, len(scans)):
        out.append(moved[k])
        ranges.append(scans[k])
        weights.append(1)
    grid.integrate_scans(out, ranges, weights, laser, max_urange=laser.range_max)
    return grid


def test_tracing_every_scan_again_gives_the_counts_and_window_of_moving_them(square_loop):
    # most nodes moved: NodeMap clears the counts and traces every scan again; the result must be the
    # take-out-and-put-back grid cell for cell, window included (the published map's size and origin)
    laser = square_loop.laser
    scans = [f.ranges for f in square_loop.frames[:60:3]]
    poses = square_loop.truth[:60:3].copy()
    moved = poses.copy()
    moved[:8, 0] += np.linspace(0.5, 4.0, 8)  # 8 of the 12 traced scans move, some far (the window grows)
    moved[:8, 2] += 0.1
    nodes = _map(laser)
    nodes.update(poses[:12], scans[:12])
    assert nodes.update(moved, scans) == len(scans)  # every scan traced once, none taken out
    by_hand = _take_out_and_put_back(laser, poses, moved, scans, 12)
    assert (nodes.grid.col0, nodes.grid.row0) == (by_hand.col0, by_hand.row0)
    assert np.array_equal(nodes.grid.visits, by_hand.visits) and np.array_equal(nodes.grid.hits, by_hand.hits)
    assert nodes.grid.visits.sum() > 10_000


def test_moving_few_nodes_takes_only_them_out_and_back(square_loop):
    laser = square_loop.laser
    scans = [f.ranges for f in square_loop.frames[:60:3]]
    poses = square_loop.truth[:60:3].copy()
    moved = poses.copy()
    moved[[2, 7], 1] -= 0.4
    nodes = _map(laser)
    nodes.update(poses[:12], scans[:12])
    assert nodes.update(moved, scans) == 2 * 2 + 8  # two moved scans out and back in, eight new ones
    by_hand = _take_out_and_put_back(laser, poses, moved, scans, 12)
    assert (nodes.grid.col0, nodes.grid.row0) == (by_hand.col0, by_hand.row0)
    assert np.array_equal(nodes.grid.visits, by_hand.visits) and np.array_equal(nodes.grid.hits, by_hand.hits)


def test_cells_crossed_fewer_than_min_pass_through_times_stay_unknown(square_loop):
    laser = square_loop.laser
    single = _map(laser)
    single.update(square_loop.truth[:1], [square_loop.frames[0].ranges])
    counts = single.grid.visits
    grid = single.occupancy().grid[::-1]  # row 0 at the bottom, as the counts
    assert (grid[(counts > 0) & (counts <= 2)] == UNKNOWN).all()
    assert math.isclose(single.occupancy().resolution, 0.05)
