"""The published map (:class:`PublishedMap`): an incremental rebuild equals a from-scratch GridMap.

Scans of a rectangular room (exact ranges, with NaN, zero, no-return and too-long readings mixed in,
and maxUrange below the laser's range so that beams are cut) are taken along a random path. The map is
rebuilt for a sequence of paths in which the tail changes (as when the best particle changes), the
path grows, a pose jumps far away (the grid grows) and the head changes; after each rebuild its
hits and visits, aligned on global cells, equal those of a fresh GridMap that traced the same path, and
so do the published occupancy grids. The rebuild's return value counts the scans it traced or took
out, so a changed tail costs only that tail.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.record import LaserGeometry
from slamtrials.slam.gmapping.published import PublishedMap
from slamtrials.slam.gridmap import GridMap

RES = 0.05
BEAMS = 181
LASER = LaserGeometry.from_dict(
    {"angle_min": -math.pi / 2, "angle_increment": math.pi / (BEAMS - 1), "range_min": 0.05, "range_max": 8.0}
)
MAX_URANGE = 5.0
HALF_X, HALF_Y = 3.1, 2.2  # walls of the room (m)


def room_scan(pose: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Exact ranges to the room's walls, some readings replaced by NaN, 0 and no-return (range_max)."""
    x, y, theta = pose
    heading = theta + LASER.beam_angles(BEAMS)
    c, s = np.cos(heading), np.sin(heading)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (HALF_X - x) / c, (-HALF_X - x) / c)
        ty = np.where(s > 0, (HALF_Y - y) / s, (-HALF_Y - y) / s)
    r = np.minimum(np.abs(tx), np.abs(ty))
    r = np.where(r > LASER.range_max, LASER.range_max, r)
    special = rng.random(BEAMS)
    r[special < 0.03] = np.nan
    r[(special >= 0.03) & (special < 0.05)] = 0.0
    r[(special >= 0.05) & (special < 0.08)] = LASER.range_max
    return r.astype(np.float32)


def scratch(path: np.ndarray, scans: list[np.ndarray]) -> GridMap:
    grid = GridMap(RES)
    for pose, ranges in zip(path, scans):
        grid.integrate(
            pose,
            ranges,
            LASER.beam_angles(ranges.shape[0]),
            range_min=LASER.range_min,
            range_max=LASER.range_max,
            max_urange=MAX_URANGE,
        )
    return grid


def aligned(a: GridMap, b: GridMap) -> tuple[np.ndarray, ...]:
    """hits and visits of both grids on the union of their windows (global cells)."""
    c0, r0 = min(a.col0, b.col0), min(a.row0, b.row0)
    c1 = max(a.col0 + a.visits.shape[1], b.col0 + b.visits.shape[1])
    r1 = max(a.row0 + a.visits.shape[0], b.row0 + b.visits.shape[0])
    out = []
    for g in (a, b):
        for counts in (g.hits, g.visits):
            big = np.zeros((r1 - r0, c1 - c0), dtype=np.int64)
            big[g.row0 - r0 : g.row0 - r0 + counts.shape[0], g.col0 - c0 : g.col0 - c0 + counts.shape[1]] = counts
            out.append(big)
    return tuple(out)


def assert_same_grid(published: PublishedMap, path: np.ndarray, scans: list[np.ndarray]) -> None:
    fresh = scratch(path, scans)
    hits_a, visits_a, hits_b, visits_b = aligned(published.grid, fresh)
    np.testing.assert_array_equal(hits_a, hits_b)
    np.testing.assert_array_equal(visits_a, visits_b)
    assert visits_b.sum() > 0 and hits_b.sum() > 0
    # and the published occupancy grid is the fresh one's, on the same cells
    mine, theirs = published.occupancy(), fresh.occupancy(0.25)
    ha, wa = mine.grid.shape
    hb, wb = theirs.grid.shape
    # bring both into bottom-up arrays indexed by global cell
    a = mine.grid[::-1]
    b = theirs.grid[::-1]
    ca, ra = round(mine.origin[0] / RES), round(mine.origin[1] / RES)
    cb, rb = round(theirs.origin[0] / RES), round(theirs.origin[1] / RES)
    c0, r0 = max(ca, cb), max(ra, rb)
    c1, r1 = min(ca + wa, cb + wb), min(ra + ha, rb + hb)
    overlap_a = a[r0 - ra : r1 - ra, c0 - ca : c1 - ca]
    overlap_b = b[r0 - rb : r1 - rb, c0 - cb : c1 - cb]
    np.testing.assert_array_equal(overlap_a, overlap_b)
    # outside the overlap both grids are unknown
    assert (a != -1).sum() == (overlap_a != -1).sum() and (b != -1).sum() == (overlap_b != -1).sum()


def random_path(rng: np.random.Generator, n: int) -> np.ndarray:
    return np.column_stack([rng.uniform(-2.5, 2.5, n), rng.uniform(-1.7, 1.7, n), rng.uniform(-np.pi, np.pi, n)])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_incremental_rebuilds_equal_rebuilds_from_scratch(seed):
    rng = np.random.default_rng(seed)
    scans: list[np.ndarray] = []
    path = random_path(rng, 12)
    for pose in path:
        scans.append(room_scan(pose, rng))
    published = PublishedMap(RES, LASER, max_urange=MAX_URANGE, occ_thresh=0.25)

    work = published.rebuild(path[:6], scans[:6])
    assert work == 6
    assert_same_grid(published, path[:6], scans[:6])

    # the path grows by three poses and its last two old poses change (another particle became best)
    second = path[:9].copy()
    second[4:6] += rng.normal(0.0, 0.02, size=(2, 3))
    work = published.rebuild(second, scans[:9])
    assert work == 2 + 5  # took out old poses 4, 5; traced poses 4..8
    assert_same_grid(published, second, scans[:9])

    # a pose far away (the grid grows), then the tail changes again: scans inserted before the growth
    # are taken out after it
    third = np.vstack([second, [[30.0, -25.0, 0.3]], path[10:12]])
    third_scans = scans[:9] + [room_scan(np.array([0.0, 0.0, 0.3]), rng)] + scans[10:12]
    published.rebuild(third, third_scans)
    assert_same_grid(published, third, third_scans)
    fourth = third.copy()
    fourth[7:] += rng.normal(0.0, 0.05, size=(len(fourth) - 7, 3))
    work = published.rebuild(fourth, third_scans)
    assert work == 2 * (len(fourth) - 7)
    assert_same_grid(published, fourth, third_scans)

    # the head changes: everything is redone; a shorter path takes scans out
    fifth = fourth[:8].copy()
    fifth[0] += [0.01, 0.0, 0.0]
    work = published.rebuild(fifth, third_scans)
    assert work == len(fourth) + len(fifth)
    assert_same_grid(published, fifth, third_scans)

    # the same path again: nothing to do
    assert published.rebuild(fifth, third_scans) == 0
    assert_same_grid(published, fifth, third_scans)


def test_occupancy_before_any_rebuild_is_empty():
    published = PublishedMap(RES, LASER, max_urange=MAX_URANGE, occ_thresh=0.25)
    grid = published.occupancy()
    assert grid.grid.shape == (0, 0) and grid.resolution == RES


def test_taking_out_a_scan_traced_before_the_grid_grew_cancels_it_exactly():
    """A 45-degree beam of 4.7 m from a cell centre crosses cell corners exactly; traced, then (after
    the window grew to hold a far point) traced again with weight -1, it must leave all counts 0 (when
    tracing depended on the window's corner, 132 cells kept a visit of +1 or -1). PublishedMap.rebuild
    relies on this cancellation (its docstring: "the same grid a rebuild from scratch would give")."""
    grid = GridMap(RES)
    pose = np.array([0.025, 0.025, 0.0])
    kwargs = dict(range_min=0.0, range_max=30.0, max_urange=30.0)
    grid.integrate(pose, np.array([4.7]), np.array([math.pi / 4]), **kwargs)
    grid.ensure(np.array([[-20.0, -20.0]]))
    grid.integrate(pose, np.array([4.7]), np.array([math.pi / 4]), weight=-1, **kwargs)
    assert not np.any(grid.visits) and not np.any(grid.hits)
