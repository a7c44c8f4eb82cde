"""The evidence layer: the SLAM map corrected by the explorer's own returns (gaps closed, halo unknown)."""

from __future__ import annotations

import math

import numpy as np

from slamtrials.explore import ExploreConfig, RobotLimits, build_costmap, find_frontiers
from slamtrials.explore.costmap import PASSABLE
from slamtrials.explore.evidence import EvidenceLayer, MapView, _correct
from slamtrials.record import LaserGeometry, OccupancyGrid

RES = 0.05
LASER = LaserGeometry(-0.75 * math.pi, math.radians(0.5), 0.02, 30.0)
F, OCC, U = 0, 100, -1


def cast(truth: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Noise-free ranges from ``pose`` in a true occupancy grid (bool ``[H, W]``, row 0 at the top,
    origin (0, 0)): the first occupied cell along each beam, sampled every 5 mm; no return past 10 m."""
    height = truth.shape[0]
    angles = LASER.beam_angles(541) + pose[2]
    steps = np.arange(1, 2001) * 0.005
    xs = pose[0] + steps[None, :] * np.cos(angles)[:, None]
    ys = pose[1] + steps[None, :] * np.sin(angles)[:, None]
    cols = np.floor(xs / RES).astype(int)
    rows = height - 1 - np.floor(ys / RES).astype(int)
    inside = (rows >= 0) & (rows < height) & (cols >= 0) & (cols < truth.shape[1])
    hit = np.zeros(xs.shape, dtype=bool)
    hit[inside] = truth[rows[inside], cols[inside]]
    first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
    return np.where(first >= 0, steps[np.maximum(first, 0)], LASER.range_max)


def room() -> tuple[np.ndarray, np.ndarray]:
    """A 4 m x 4 m room in a 10 m x 6 m grid (walls 2 cells thick, a 1 m door in the west wall onto an
    unexplored corridor 2 m wide), as the truth and as a SLAM map that wore a 0.6 m gap into the east wall and
    drew 3 m of free space beyond it (beams without a return)."""
    height, width = int(6.0 / RES), int(10.0 / RES)
    truth = np.zeros((height, width), dtype=bool)
    top, bottom, left, right = 20, 100, 40, 120  # rows and columns of the room's walls
    truth[top : top + 2, left : right + 2] = truth[bottom : bottom + 2, left : right + 2] = True
    truth[top : bottom + 2, left : left + 2] = truth[top : bottom + 2, right : right + 2] = True
    truth[50:70, left : left + 2] = False  # the door (1 m)
    truth[:, :2] = True  # the corridor's far wall, 2 m west of the door
    grid = np.full((height, width), U, dtype=np.int8)
    grid[top + 2 : bottom, left + 2 : right] = F
    grid[truth] = OCC
    grid[50:70, left : left + 2] = F  # the door, seen through
    grid[50:70, left - 10 : left] = F  # a little of the corridor behind it
    grid[60:72, right : right + 2] = F  # the gap in the east wall
    grid[30:90, right + 2 : right + 62] = F  # the halo behind it
    return truth, grid


def layer_after_looking(truth: np.ndarray, dropouts: float = 0.0) -> EvidenceLayer:
    """The layer after six scans from three places in the room, ``dropouts`` of the returns lost."""
    layer = EvidenceLayer(min_hits=2, occupied_ratio=0.25, free_distance=0.15)
    rng = np.random.default_rng(0)
    for x, y in ((3.0, 2.5), (4.0, 3.5), (5.0, 2.0)):
        for heading in (0.0, math.pi):
            pose = np.array([x, y, heading])
            ranges = cast(truth, pose)
            ranges[rng.random(ranges.shape[0]) < dropouts] = LASER.range_max
            layer.add_scan(pose, ranges, LASER, RES)
    return layer


def goal_cells(view) -> np.ndarray:
    """bool ``[H, W]``: the frontier cells the explorer may take as goals on ``view`` (passable ones),
    as :class:`~slamtrials.explore.goalsearch.GoalSearch` finds them."""
    grid = np.asarray(view.grid)
    costmap = build_costmap(grid, RES, ExploreConfig(), RobotLimits())
    return find_frontiers(grid, min_cells=10).mask & (costmap.kind == PASSABLE)


def test_the_halo_is_unknown_the_gap_closed_and_the_door_stays_a_frontier():
    truth, grid = room()
    slam_map = OccupancyGrid(grid, RES, np.zeros(3))
    view = layer_after_looking(truth, dropouts=0.1).view(slam_map)  # beams without a return wore the gap
    assert isinstance(view, MapView)
    assert view.grid.shape == grid.shape and np.array_equal(view.origin, slam_map.origin)
    # the gap's inner column, where the returns ended, is a wall again
    assert (view.grid[60:72, 120] == OCC).sum() >= 10
    assert np.all(view.grid[30:90, 125:182] == U)  # the halo
    room_cells = (slice(25, 95), slice(45, 115))
    assert np.array_equal(view.grid[room_cells], grid[room_cells])  # what the robot saw is untouched
    # frontiers the robot can go to: only at the door, none beyond the east wall
    rows, cols = np.nonzero(goal_cells(view))
    assert rows.size > 0 and np.all(cols <= 45)
    # the uncorrected map offers goals in the halo, reachable through the gap
    assert np.any(np.nonzero(goal_cells(slam_map))[1] > 125)


def test_a_map_the_returns_agree_with_is_handed_back_as_it_is():
    truth, _ = room()
    grid = np.full(truth.shape, U, dtype=np.int8)
    grid[22:100, 42:120] = F
    grid[truth] = OCC
    grid[50:70, 40:42] = U  # the door: not seen through
    slam_map = OccupancyGrid(grid, RES, np.zeros(3))
    assert layer_after_looking(truth, dropouts=0.1).view(slam_map) is slam_map


def test_a_gap_no_beam_without_a_return_crossed_is_left_open():
    # the returns end in the gap, but nothing explains why the map has it: the map's walls and the
    # returns may just be a few centimetres apart (the explorer's pose is not the map's best particle's)
    truth, grid = room()
    view = layer_after_looking(truth).view(OccupancyGrid(grid, RES, np.zeros(3)))
    assert (view.grid[60:72, 120:122] == F).all()


def test_no_scan_no_change_and_a_stray_return_marks_no_wall():
    truth, grid = room()
    slam_map = OccupancyGrid(grid, RES, np.zeros(3))
    layer = EvidenceLayer(min_hits=2, occupied_ratio=0.25, free_distance=0.15)
    assert layer.view(slam_map) is slam_map
    pose = np.array([3.0, 2.5, 0.0])
    ranges = cast(truth, pose)
    ranges[270] = 1.0  # one short reading, straight ahead: a single hit mid-room
    layer.add_scan(pose, ranges, LASER, RES)
    view = layer.view(slam_map)
    row, col = grid.shape[0] - 1 - math.floor(2.5 / RES), math.floor(4.0 / RES)
    assert view.grid[row, col] == F


def _plain_correct(grid, hits, passes, near, crossed, r_off, c_off, row0, row1, col0, col1, min_hits, ratio):
    """The layer's correction cell by cell, as its docstring says (the compiled pass must equal it)."""
    out = grid.copy()
    changed = outside = 0
    lh, lw = hits.shape
    for row in range(grid.shape[0]):
        for col in range(grid.shape[1]):
            if not 0 <= grid[row, col] < 50:
                continue
            if not (row0 <= row < row1 and col0 <= col < col1):
                out[row, col] = U
                outside += 1
                continue
            lr, lc = r_off - (row - row0), c_off + (col - col0)
            if not (0 <= lr < lh and 0 <= lc < lw and near[lr, lc]):
                out[row, col] = U
                changed += 1
            elif (
                hits[lr, lc] >= min_hits and hits[lr, lc] > ratio * (hits[lr, lc] + passes[lr, lc]) and crossed[lr, lc]
            ):
                out[row, col] = OCC
                changed += 1
    return out, changed, outside


def test_the_compiled_correction_equals_the_cell_by_cell_one():
    """Random maps (unknown, free, occupied and in-between values) and layers, with windows inside the
    map, reaching past its edges, empty and reversed: the compiled pass (branch-free outside the window)
    gives the same map and the same counts as the plain loop."""
    rng = np.random.default_rng(21)
    values = np.array([U, F, 10, 49, 50, OCC], dtype=np.int8)
    outside_seen = 0
    for _ in range(400):
        height, width = (int(v) for v in rng.integers(1, 40, 2))
        lh, lw = (int(v) for v in rng.integers(1, 30, 2))
        grid = rng.choice(values, size=(height, width))
        hits = rng.integers(0, 5, (lh, lw)).astype(np.int32)
        passes = rng.integers(0, 5, (lh, lw)).astype(np.int32)
        near, crossed = rng.random((lh, lw)) < 0.7, rng.random((lh, lw)) < 0.7
        row0, row1 = int(rng.integers(0, height + 2)), int(rng.integers(0, height + 3))
        col0, col1 = int(rng.integers(0, width + 2)), int(min(rng.integers(0, width + 5), width))
        r_off, c_off = int(rng.integers(-5, lh + 5)), int(rng.integers(-5, lw + 5))
        args = (grid, hits, passes, near, crossed, r_off, c_off, row0, row1, col0, col1, 2, 0.3)
        got, want = _correct(*args), _plain_correct(*args)
        np.testing.assert_array_equal(got[0], want[0])
        assert got[1:] == want[1:]
        outside_seen += want[2] > 0
    assert outside_seen > 100  # free cells outside the window were made unknown in many cases
