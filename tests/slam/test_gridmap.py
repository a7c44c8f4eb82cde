"""The occupancy-grid builder: a scan in a square room, max-range beams, growth with stable coordinates."""

from __future__ import annotations

import numpy as np

from slamtrials.record import LaserGeometry
from slamtrials.slam.gridmap import GridMap, _classify, beam_endpoints

RES = 0.05
HALF = 2.025  # walls through cell centres (cells are anchored at the origin), so no endpoint lies on a cell edge
LASER_XY = np.array([0.013, 0.021])


def _room_scan(beams: int = 1440) -> tuple[np.ndarray, np.ndarray]:
    """Exact ranges from LASER_XY to the walls x = +-HALF, y = +-HALF, all around."""
    angles = np.linspace(-np.pi, np.pi, beams, endpoint=False)
    c, s = np.cos(angles), np.sin(angles)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (HALF - LASER_XY[0]) / c, (-HALF - LASER_XY[0]) / c)
        ty = np.where(s > 0, (HALF - LASER_XY[1]) / s, (-HALF - LASER_XY[1]) / s)
    return np.minimum(np.abs(tx), np.abs(ty)).astype(np.float32), angles


def _cell_centres(grid) -> tuple[np.ndarray, np.ndarray]:
    """World x, y of every cell centre of an OccupancyGrid (row 0 at the top)."""
    h, w = grid.grid.shape
    cols, rows = np.meshgrid(np.arange(w), np.arange(h))
    x = grid.origin[0] + (cols + 0.5) * grid.resolution
    y = grid.origin[1] + (h - rows - 0.5) * grid.resolution
    return x, y


def test_scan_in_square_room_marks_walls_occupied_inside_free_outside_unknown():
    ranges, angles = _room_scan()
    gmap = GridMap(RES)
    gmap.integrate(np.array([*LASER_XY, 0.0]), ranges, angles, range_min=0.0, range_max=30.0, max_urange=30.0)
    grid = gmap.occupancy(0.25)
    x, y = _cell_centres(grid)
    m = np.maximum(np.abs(x), np.abs(y))
    wall = np.isclose(m, HALF)
    inside = m < HALF - 0.01
    outside = m > HALF + 0.01
    assert np.all(grid.grid[wall] == 100)
    assert np.all(grid.grid[inside] == 0)  # every interior cell is crossed by some beam
    assert np.all(grid.grid[outside] == -1)
    assert grid.grid.dtype == np.int8


def test_no_returns_mark_nothing_and_too_long_beams_mark_free_space_only_up_to_max_urange():
    gmap = GridMap(RES)
    angles = np.array([0.0, np.pi / 2, np.pi, -np.pi / 2, 0.1, 0.8])
    # no return at range_max, no return (REP 117), too long, nothing, nothing, beyond range_max
    ranges = np.array([30.0, np.inf, 5.0, np.nan, 0.0, 45.0])
    gmap.integrate(np.array([0.0, 0.0, 0.0]), ranges, angles, range_min=0.0, range_max=30.0, max_urange=2.0)
    grid = gmap.occupancy()
    assert not np.any(grid.grid == 100)
    x, y = _cell_centres(grid)
    free = grid.grid == 0
    on_minus_x = np.isclose(y, RES / 2) & (x < -RES)
    assert free[on_minus_x & (x > -1.95)].all()  # the 5 m return is cut at 2 m: free, no hit
    assert not free[on_minus_x & (x < -2.05)].any()
    # only that beam marked anything: every free cell lies along the -x axis, within 2 m
    assert np.all(np.abs(y[free]) < RES) and np.all(x[free] < RES) and np.all(x[free] > -2.0 - RES)


def test_a_no_return_beside_walls_draws_no_free_space_through_them():
    # a laser in the middle of a 4 m room sees its walls; one beam missed a return (+inf) and one read
    # the sensor's maximum (how Stage reports it): beyond the walls nothing may be free
    angles = np.linspace(-np.pi, np.pi, 720, endpoint=False)
    ranges = np.minimum(2.0 / np.maximum(np.abs(np.cos(angles)), np.abs(np.sin(angles))), 30.0)
    ranges[100], ranges[400] = np.inf, 30.0
    gmap = GridMap(RES)
    gmap.integrate(np.zeros(3), ranges, angles, range_min=0.0, range_max=30.0, max_urange=30.0)
    grid = gmap.occupancy()
    x, y = _cell_centres(grid)
    free = grid.grid == 0
    assert free.sum() > 1000
    assert np.all(np.maximum(np.abs(x[free]), np.abs(y[free])) < 2.0)


def test_endpoints_classify_returns_cuts_and_ignored_beams():
    ends, hit = beam_endpoints(
        [1.0, 2.0, np.pi / 2],
        [1.0, 0.05, 40.0, 3.0, np.inf],
        [0.0, 0.0, 0.0, 0.0, 0.0],
        range_min=0.1,
        range_max=40.0,
        max_urange=2.5,
    )
    # 1 m: a return; 0.05 m: below range_min; 40 m and inf: no returns; 3 m: cut at 2.5 m
    np.testing.assert_allclose(ends, [[1.0, 3.0], [1.0, 4.5]], atol=1e-12)
    assert hit.tolist() == [True, False]


def test_growing_keeps_world_coordinates():
    ranges, angles = _room_scan(720)
    small = GridMap(RES, chunk=2)
    small.integrate(np.array([*LASER_XY, 0.0]), ranges, angles, range_min=0.0, range_max=30.0, max_urange=30.0)
    before = small.occupancy()
    small.ensure(np.array([[20.0, -15.0]]))  # far outside: the window grows left/up/down
    after = small.occupancy()
    assert after.grid.shape[0] > before.grid.shape[0] and after.grid.shape[1] > before.grid.shape[1]
    bx, by = _cell_centres(before)
    ax, ay = _cell_centres(after)
    occupied_before = set(zip(np.round(bx[before.grid == 100], 6), np.round(by[before.grid == 100], 6)))
    occupied_after = set(zip(np.round(ax[after.grid == 100], 6), np.round(ay[after.grid == 100], 6)))
    assert occupied_before == occupied_after and occupied_before
    # a second scan from elsewhere adds to the same cells
    big = GridMap(RES, chunk=200)
    big.integrate(np.array([*LASER_XY, 0.0]), ranges, angles, range_min=0.0, range_max=30.0, max_urange=30.0)
    assert big.occupancy().grid.shape != before.grid.shape
    cx, cy = _cell_centres(big.occupancy())
    occupied_big = set(zip(np.round(cx[big.occupancy().grid == 100], 6), np.round(cy[big.occupancy().grid == 100], 6)))
    assert occupied_big == occupied_before


def test_mount_and_pose_are_applied():
    ranges, angles = _room_scan(720)
    laser = LaserGeometry.from_dict(
        {
            "angle_min": float(angles[0]),
            "angle_increment": float(angles[1] - angles[0]),
            "range_min": 0.0,
            "range_max": 30.0,
            "mount": [0.3, 0.0, 0.0],
        }
    )
    gmap = GridMap(RES)
    # the base at (LASER_XY - (0, 0.3)) facing +y puts the laser at LASER_XY, turned by pi/2
    gmap.integrate_frame([LASER_XY[0], LASER_XY[1] - 0.3, np.pi / 2], np.roll(ranges, -180), laser)
    grid = gmap.occupancy()
    x, y = _cell_centres(grid)
    m = np.maximum(np.abs(x), np.abs(y))
    assert np.mean(grid.grid[np.isclose(m, HALF)] == 100) > 0.95
    assert not np.any(grid.grid[m > HALF + 0.01] == 100)


def test_the_compiled_classification_equals_the_threshold_rule():
    """Random counts: unknown where never visited, occupied where hits / visits > occ_thresh, else free,
    rows flipped to the top first when asked (the compiled pass is branch-free)."""
    rng = np.random.default_rng(4)
    visits = (rng.integers(0, 6, (57, 83)) * (rng.random((57, 83)) < 0.6)).astype(np.int32)
    hits = np.minimum(rng.integers(0, 6, visits.shape), visits).astype(np.int32)
    for occ_thresh in (0.0, 0.25, 0.5):
        want = np.where(visits <= 0, -1, np.where(hits > occ_thresh * visits, 100, 0)).astype(np.int8)
        np.testing.assert_array_equal(_classify(hits, visits, occ_thresh, False), want)
        np.testing.assert_array_equal(_classify(hits, visits, occ_thresh, True), want[::-1])
    assert set(np.unique(want).tolist()) == {-1, 0, 100}
