"""GMapping's scan matcher (spec/gmapping.md, section 3) on synthetic maps.

* hill climbing from a pose offset by (8 cm, -5 cm, 0.03 rad) recovers the true laser pose of a scan of
  a known room to within 1 cm / 0.005 rad, and the score at the true pose beats the score at the offset;
* the matcher's shortcuts leave its result that of the plain climb (every move scored), bit for bit;
* ``score_pose`` (score and log-likelihood) equals a naive re-implementation of the spec's formulas
  (nearest cell mean in the (2k+1)^2 window, ``exp(-|mu|^2 / sigma)``, ``-|mu|^2 / lsigma`` or
  ``-0.5 / lsigma``) computed from the endpoints themselves, for several window sizes, with and
  without the free-cell test, at poses whose windows straddle tile borders;
* ``score_3x3`` and ``likelihood_3x3``, the staged kernels used for the default window, give the very
  score and log-likelihood of ``score_pose``, bit for bit, also for beams beyond the map and windows
  across tile borders;
* ``score_3x3`` given a floor returns either its score, the same number, or (only when that score is at
  most the floor) ``STOPPED``; it does stop early for poses that score far below the floor;
* the free-cell test (``free_cell_test=True``) skips a window cell whose counterpart next to the free
  point holds endpoints, lowering the score in the predicted way.

Ranges of the synthetic scans come from an exact ray-polygon intersection written here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.slam.gmapping.kernels import (
    STOPPED,
    TILE,
    likelihood_3x3,
    match_particles,
    score_3x3,
    score_pose,
    score_scratch,
)
from slamtrials.slam.gmapping.tilemap import TileMaps

RES = 0.05
#: An L-shaped room (m): no symmetry, so a scan fixes x, y and theta.
ROOM = np.array([(-3.0, -2.0), (4.0, -2.0), (4.0, 1.0), (2.0, 1.0), (2.0, 3.0), (-3.0, 3.0)])
#: A square pillar inside the room.
PILLAR = np.array([(-1.6, 0.8), (-1.1, 0.8), (-1.1, 1.3), (-1.6, 1.3)])
TRUE_POSE = np.array([0.37, 0.21, 0.4])


def ray_ranges(pose: np.ndarray, angles: np.ndarray, polygons=(ROOM, PILLAR)) -> np.ndarray:
    """Distance from the laser at ``pose`` along each beam (laser-frame angle) to the nearest polygon edge."""
    x, y, theta = pose
    heading = theta + angles
    dx, dy = np.cos(heading), np.sin(heading)
    best = np.full(angles.shape, np.inf)
    for poly in polygons:
        p = poly
        e = np.roll(poly, -1, axis=0) - poly
        for k in range(len(p)):
            den = dx * e[k, 1] - dy * e[k, 0]
            wx, wy = p[k, 0] - x, p[k, 1] - y
            with np.errstate(divide="ignore", invalid="ignore"):
                s = (wx * e[k, 1] - wy * e[k, 0]) / den  # distance along the beam
                u = (wx * dy - wy * dx) / den  # fraction along the edge
            hit = (den != 0) & (s > 0) & (u >= 0) & (u <= 1)
            best = np.where(hit, np.minimum(best, s), best)
    assert np.all(np.isfinite(best))
    return best


def scan_endpoints(pose: np.ndarray, beams: int, offset: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Laser-frame endpoints (lx, ly) of a full-circle scan from ``pose``."""
    angles = np.linspace(-np.pi, np.pi, beams, endpoint=False) + offset
    r = ray_ranges(pose, angles)
    return r * np.cos(angles), r * np.sin(angles)


def free_points(lx: np.ndarray, ly: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points sqrt(2) cells back along each beam (as the filter computes them)."""
    r = np.hypot(lx, ly)
    back = (r - math.sqrt(2.0) * RES) / r
    return lx * back, ly * back


def to_map(pose: np.ndarray, lx: np.ndarray, ly: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return pose[0] + c * lx - s * ly, pose[1] + s * lx + c * ly


@pytest.fixture(scope="module")
def room_map():
    """One particle's map of the room from three dense scans (2880 beams) taken at known poses."""
    maps = TileMaps(1, RES)
    for pose in (TRUE_POSE, np.array([-1.0, 1.9, -0.3]), np.array([2.5, -1.0, 2.0])):
        ex, ey = to_map(pose, *scan_endpoints(pose, 2880))
        maps.register(ex[None, :], ey[None, :])
    return maps


def _score(maps: TileMaps, pose, lx, ly, lfx, lfy, *, kernel=1, sigma=0.05, lsigma=0.075, free=False):
    return score_pose(
        maps.directories[0],
        maps.mean.reshape(-1),
        maps.tile_col0,
        maps.tile_row0,
        maps.resolution,
        float(pose[0]),
        float(pose[1]),
        float(pose[2]),
        lx,
        ly,
        lfx,
        lfy,
        kernel,
        sigma,
        lsigma,
        free,
        True,
    )


def test_hill_climbing_recovers_a_known_offset(room_map):
    """A sparser scan (360 beams, angles not those of the map's scans) from the true pose, matched from
    a start 8 cm / -5 cm / 0.03 rad off, lands within 1 cm and 0.005 rad of the true pose; the matcher's
    score at the result is the best seen and the returned likelihood is the one at the returned pose."""
    lx, ly = scan_endpoints(TRUE_POSE, 360, offset=np.pi / 720)
    lfx, lfy = free_points(lx, ly)
    start = TRUE_POSE + np.array([0.08, -0.05, 0.03])
    m = room_map
    matched, scores, likelihoods = match_particles(
        m.directories,
        m.mean.reshape(-1),
        m.tile_col0,
        m.tile_row0,
        RES,
        start[None, :].copy(),
        lx,
        ly,
        lfx,
        lfy,
        1,
        0.05,
        0.075,
        False,
        0.05,
        0.05,
        5,
        0.0,
    )
    error = matched[0] - TRUE_POSE
    assert math.hypot(error[0], error[1]) < 0.01
    assert abs(error[2]) < 0.005
    at_true, _ = _score(m, TRUE_POSE, lx, ly, lfx, lfy)
    at_start, _ = _score(m, start, lx, ly, lfx, lfy)
    at_match, lik_match = _score(m, matched[0], lx, ly, lfx, lfy)
    assert at_true > at_start * 1.2  # the offset pose is clearly worse
    assert scores[0] == pytest.approx(at_match, rel=1e-12)
    assert scores[0] >= at_true * 0.999  # hill climbing found (about) the optimum
    assert likelihoods[0] == pytest.approx(lik_match, rel=1e-12)
    # at the true pose nearly every beam has a cell mean close by (a beam scores at most 1)
    assert at_true > 0.95 * len(lx)


def test_minimum_score_keeps_the_motion_sample(room_map):
    """When the best score does not exceed minimumScore the particle keeps its input pose, and the
    likelihood is evaluated there."""
    lx, ly = scan_endpoints(TRUE_POSE, 360, offset=np.pi / 720)
    lfx, lfy = free_points(lx, ly)
    start = TRUE_POSE + np.array([0.08, -0.05, 0.03])
    m = room_map
    matched, scores, likelihoods = match_particles(
        m.directories,
        m.mean.reshape(-1),
        m.tile_col0,
        m.tile_row0,
        RES,
        start[None, :].copy(),
        lx,
        ly,
        lfx,
        lfy,
        1,
        0.05,
        0.075,
        False,
        0.05,
        0.05,
        5,
        1.0e6,
    )
    np.testing.assert_array_equal(matched[0], start)
    assert scores[0] > 300  # a good match was found, but below the (huge) minimum score
    assert likelihoods[0] == pytest.approx(_score(m, start, lx, ly, lfx, lfy)[1], rel=1e-12)


def _reference_climb(maps: TileMaps, start, lx, ly, lfx, lfy, lstep=0.05, astep=0.05, iterations=5):
    """GMapping's ScanMatcher::optimize as the spec gives it, with no shortcut: every iteration scores
    all six moves."""

    def score(p):
        return _score(maps, p, lx, ly, lfx, lfy)[0]

    current_pose = np.array(start, dtype=np.float64)
    current = score(current_pose)
    ld, ad, refinement, best = lstep, astep, 0, -1.0
    while True:
        if best >= current:
            refinement += 1
            ld, ad = ld * 0.5, ad * 0.5
        best = current
        best_pose = current_pose
        for move in ((ld, 0, 0), (-ld, 0, 0), (0, -ld, 0), (0, ld, 0), (0, 0, ad), (0, 0, -ad)):
            candidate = np.array([current_pose[0] + move[0], current_pose[1] + move[1], current_pose[2] + move[2]])
            local = score(candidate)
            if local > current:
                current, best_pose = local, candidate
        current_pose = best_pose
        if not (current > best or refinement < iterations):
            return current_pose, best


def test_hill_climbing_equals_the_plain_climb_bit_for_bit(room_map):
    """The matcher's shortcuts (no step straight back, no pose scored twice, the likelihood from the
    climb's last window minima) never change its result: from 16 seeded starts up to 15 cm / 0.1 rad
    off, pose, score and likelihood equal those of the plain climb that scores every move."""
    lx, ly = scan_endpoints(TRUE_POSE, 360, offset=np.pi / 720)
    lfx, lfy = free_points(lx, ly)
    rng = np.random.default_rng(5)
    starts = TRUE_POSE + rng.uniform([-0.15, -0.15, -0.1], [0.15, 0.15, 0.1], size=(16, 3))
    m = room_map
    directories = np.repeat(m.directories, len(starts), axis=0)
    matched, scores, likelihoods = match_particles(
        directories,
        m.mean.reshape(-1),
        m.tile_col0,
        m.tile_row0,
        RES,
        starts.copy(),
        lx,
        ly,
        lfx,
        lfy,
        1,
        0.05,
        0.075,
        False,
        0.05,
        0.05,
        5,
        0.0,
    )
    for k, start in enumerate(starts):
        pose, score = _reference_climb(m, start, lx, ly, lfx, lfy)
        assert scores[k] == score
        np.testing.assert_array_equal(matched[k, :2], pose[:2])
        assert matched[k, 2] == math.atan2(math.sin(pose[2]), math.cos(pose[2]))
        # the likelihood (taken from the climb's own window minima where it can) is that at the result
        assert likelihoods[k] == _score(m, matched[k], lx, ly, lfx, lfy)[1]


# ----------------------------------------------------------------------------- naive reference


def naive_score(cells: dict, pose, lx, ly, lfx, lfy, *, kernel, sigma, lsigma, free):
    """The spec's score and log-likelihood, one beam and one window cell at a time.

    ``cells`` maps global cell (column, row) to the mean (x, y) of the endpoints in it.
    """
    ex, ey = to_map(pose, lx, ly)
    fx, fy = to_map(pose, lfx, lfy)
    score = likelihood = 0.0
    for b in range(len(lx)):
        gc, gr = math.floor(ex[b] / RES), math.floor(ey[b] / RES)
        fc, fr = math.floor(fx[b] / RES), math.floor(fy[b] / RES)
        best = None
        for dc in range(-kernel, kernel + 1):
            for dr in range(-kernel, kernel + 1):
                mean = cells.get((gc + dc, gr + dr))
                if mean is None:
                    continue
                if free and (fc + dc, fr + dr) in cells:
                    continue
                d2 = (ex[b] - mean[0]) ** 2 + (ey[b] - mean[1]) ** 2
                best = d2 if best is None else min(best, d2)
        if best is not None:
            score += math.exp(-best / sigma)
            likelihood -= best / lsigma
        else:
            likelihood -= 0.5 / lsigma
    return score, likelihood


def _cells_from_endpoints(ex: np.ndarray, ey: np.ndarray) -> dict:
    sums: dict = {}
    for x, y in zip(ex.tolist(), ey.tolist()):
        key = (math.floor(x / RES), math.floor(y / RES))
        sx, sy, n = sums.get(key, (0.0, 0.0, 0))
        sums[key] = (sx + x, sy + y, n + 1)
    return {k: (sx / n, sy / n) for k, (sx, sy, n) in sums.items()}


@pytest.mark.parametrize("kernel", [0, 1, 2])
@pytest.mark.parametrize("free", [False, True])
def test_score_and_likelihood_equal_a_naive_reference(kernel, free):
    """Random sparse endpoints (several per cell in places, over many tiles around the origin, so
    windows cross tile borders and negative cells) and random poses: ``score_pose`` equals the naive
    formulas to 1e-6 relative (the map stores means as float32)."""
    rng = np.random.default_rng(100 + kernel + 10 * free)
    points = rng.uniform(-1.2, 1.2, size=(1500, 2))
    points = np.vstack([points, points[:300] + rng.normal(0.0, 0.01, size=(300, 2))])  # some cells with several
    maps = TileMaps(1, RES)
    maps.register(points[None, :, 0], points[None, :, 1])
    cells = _cells_from_endpoints(points[:, 0], points[:, 1])
    angles = rng.uniform(-np.pi, np.pi, 200)
    r = rng.uniform(0.2, 1.0, 200)
    lx, ly = r * np.cos(angles), r * np.sin(angles)
    lfx, lfy = free_points(lx, ly)
    for _ in range(15):
        pose = np.array([rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(-np.pi, np.pi)])
        got = _score(maps, pose, lx, ly, lfx, lfy, kernel=kernel, sigma=0.05, lsigma=0.075, free=free)
        want = naive_score(cells, pose, lx, ly, lfx, lfy, kernel=kernel, sigma=0.05, lsigma=0.075, free=free)
        assert got[0] == pytest.approx(want[0], rel=1e-6, abs=1e-9)
        assert got[1] == pytest.approx(want[1], rel=1e-6)
    # the test is not vacuous: some beams found cells and some did not
    assert 0 < want[0] and want[1] > -0.5 / 0.075 * len(lx)


@pytest.mark.parametrize("kernel", [0, 1, 2])
def test_windows_beyond_the_directory_and_on_its_edge_equal_the_naive_reference(kernel):
    """Beams that end outside the directory, in directory cells without a tile, and in windows that
    straddle the directory's edge: cells there hold nothing (the kernel reads the pool's empty tile or
    skips them), so the score equals the naive formulas, and beams that reach nothing count as misses."""
    rng = np.random.default_rng(7 + kernel)
    points = rng.uniform(-0.8, 0.8, size=(800, 2))
    maps = TileMaps(1, RES)
    maps.register(points[None, :, 0], points[None, :, 1])
    cells = _cells_from_endpoints(points[:, 0], points[:, 1])
    col0, row0 = maps.tile_col0 * TILE * RES, maps.tile_row0 * TILE * RES  # directory corner (m)
    _, rows, cols = maps.directories.shape
    col1, row1 = col0 + cols * TILE * RES, row0 + rows * TILE * RES
    # beams from the origin to just inside and just outside every edge of the directory, and far beyond
    targets = []
    for t in np.linspace(0.05, 0.95, 25):
        for dx in (-0.02, -0.001, 0.001, 0.02, 3.0):
            targets += [
                (col1 + dx, row0 + t * (row1 - row0)),
                (col0 - dx, row0 + t * (row1 - row0)),
                (col0 + t * (col1 - col0), row1 + dx),
                (col0 + t * (col1 - col0), row0 - dx),
            ]
    targets = np.array(targets + [tuple(p) for p in points[:100] + 0.01])
    lx, ly = targets[:, 0].copy(), targets[:, 1].copy()
    lfx, lfy = free_points(lx, ly)
    got = _score(maps, np.zeros(3), lx, ly, lfx, lfy, kernel=kernel)
    want = naive_score(cells, np.zeros(3), lx, ly, lfx, lfy, kernel=kernel, sigma=0.05, lsigma=0.075, free=False)
    assert got[0] == pytest.approx(want[0], rel=1e-6)
    assert got[1] == pytest.approx(want[1], rel=1e-6)
    assert 0 < want[0] < len(targets) / 2  # the hits near the points count, the edge beams miss


def test_the_staged_default_window_score_is_score_pose_bit_for_bit():
    """Random endpoints over several tiles (some cells with several), beams ending on them, near them, in
    cells without a tile, across tile borders and far outside the directory, at random poses: the score
    of ``score_3x3`` and the log-likelihood of ``likelihood_3x3`` are exactly ``score_pose``'s (the
    filter must not depend on which one runs)."""
    rng = np.random.default_rng(33)
    points = rng.uniform(-1.5, 1.5, size=(2000, 2))
    points = np.vstack([points, points[:400] + rng.normal(0.0, 0.01, size=(400, 2))])
    maps = TileMaps(1, RES)
    maps.register(points[None, :, 0], points[None, :, 1])
    targets = np.vstack(
        [
            points[rng.choice(len(points), 300)] + rng.normal(0.0, 0.03, size=(300, 2)),
            rng.uniform(-6.0, 6.0, size=(200, 2)),
        ]
    )  # many beyond the directory
    lx, ly = targets[:, 0].copy(), targets[:, 1].copy()
    floats, ints = score_scratch(len(lx))
    directory, mean = maps.directories[0], maps.mean.reshape(-1)
    found = 0
    for _ in range(40):
        x, y, theta = rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), rng.uniform(-0.5, 0.5)
        want, want_likelihood = score_pose(
            directory,
            mean,
            maps.tile_col0,
            maps.tile_row0,
            RES,
            x,
            y,
            theta,
            lx,
            ly,
            lx,
            ly,
            1,
            0.05,
            0.075,
            False,
            True,
        )
        got = score_3x3(directory, mean, maps.tile_col0, maps.tile_row0, RES, x, y, theta, lx, ly, 0.05, floats, ints)
        assert got == want
        got_likelihood = likelihood_3x3(
            directory, mean, maps.tile_col0, maps.tile_row0, RES, x, y, theta, lx, ly, 0.075, floats, ints
        )
        assert got_likelihood == want_likelihood and got_likelihood < 0.0
        found += want > 1.0
    assert found == 40  # beams found cells at every pose: the comparison is not between two zeros


def test_the_early_stop_never_changes_a_score_that_could_exceed_the_floor(room_map):
    """The hill climbing passes its current score as ``floor``: a pose may be given up (``STOPPED``) only
    when its score is at most the floor, and a score that is returned is the full score, bit for bit.
    The floors tried sit just below, at and just above each pose's score, and at the true pose's score
    (which poses 10 to 20 cm off miss by far, so those stop early)."""
    lx, ly = scan_endpoints(TRUE_POSE, 360, offset=np.pi / 720)
    m = room_map
    directory, mean = m.directories[0], m.mean.reshape(-1)
    floats, ints = score_scratch(len(lx))

    def score(pose, floor=STOPPED):
        return score_3x3(
            directory,
            mean,
            m.tile_col0,
            m.tile_row0,
            RES,
            pose[0],
            pose[1],
            pose[2],
            lx,
            ly,
            0.05,
            floats,
            ints,
            2,
            floor,
        )

    at_truth = score(TRUE_POSE)
    rng = np.random.default_rng(8)
    stopped = 0
    for _ in range(30):
        pose = TRUE_POSE + rng.uniform([-0.2, -0.2, -0.1], [0.2, 0.2, 0.1])
        full = score(pose)
        assert full >= 0.0
        for floor in (np.nextafter(full, -1.0), full, np.nextafter(full, 1e9), full + 5.0, at_truth):
            got = score(pose, floor)
            assert got == full or (got == STOPPED and full <= floor)
        far = np.hypot(pose[0] - TRUE_POSE[0], pose[1] - TRUE_POSE[1]) > 0.1
        stopped += far and score(pose, at_truth) == STOPPED
    assert score(TRUE_POSE, np.nextafter(at_truth, -1.0)) == at_truth
    assert stopped >= 10  # the early stop happens, so the equalities above were tested on it


def test_beams_given_in_another_order_give_the_same_score_bit_for_bit(room_map):
    """``match_particles`` hands the climbs after the first the beams in another order (those that fit
    worst first, for the early stop); ``score_3x3`` then sums in the scan's own order: the same number as
    with the beams in order, and the same early stops only where the score cannot exceed the floor."""
    lx, ly = scan_endpoints(TRUE_POSE, 360, offset=np.pi / 720)
    m = room_map
    directory, mean = m.directories[0], m.mean.reshape(-1)
    floats, ints = score_scratch(len(lx))
    order = np.random.default_rng(3).permutation(len(lx))
    canonical = np.empty_like(order)
    canonical[order] = np.arange(len(lx))
    rng = np.random.default_rng(9)
    for _ in range(20):
        pose = TRUE_POSE + rng.uniform([-0.1, -0.1, -0.05], [0.1, 0.1, 0.05])
        args = (directory, mean, m.tile_col0, m.tile_row0, RES, pose[0], pose[1], pose[2])
        in_order = score_3x3(*args, lx, ly, 0.05, floats, ints)
        reordered = score_3x3(*args, lx[order], ly[order], 0.05, floats, ints, 2, STOPPED, canonical)
        assert reordered == in_order and in_order > 1.0
        for floor in (np.nextafter(in_order, -1.0), in_order):
            got = score_3x3(*args, lx[order], ly[order], 0.05, floats, ints, 2, floor, canonical)
            assert got == in_order or (got == STOPPED and in_order <= floor)


def test_free_cell_test_skips_a_cell_whose_free_counterpart_holds_endpoints():
    """One beam along +x from (0, 0.0125) ending at x = 1.0125 (cell column 20, row 0); its free point
    lies sqrt(2) cells back, in column 18. The map has endpoints in cell A = (20, 0) (the nearest),
    cell C = (21, 0) (farther, free counterpart (19, 0) empty) and cell B = (18, 0), the free counterpart
    of A. By default A is used; with the free-cell test A is skipped and the beam scores with C: a lower
    score equal to exp(-|e - mean_C|^2 / sigma). Without B both modes agree."""
    pose = np.array([0.0, 0.0125, 0.0])
    lx, ly = np.array([1.0125]), np.array([0.0])
    lfx, lfy = free_points(lx, ly)
    assert math.floor(lfx[0] / RES) == 18
    a, c, b = (1.02, 0.02), (1.09, 0.03), (0.92, 0.02)
    endpoint = np.array([1.0125, 0.0125])
    expected_a = math.exp(-float(np.sum((endpoint - a) ** 2)) / 0.05)
    expected_c = math.exp(-float(np.sum((endpoint - c) ** 2)) / 0.05)

    def scores(points):
        maps = TileMaps(1, RES)
        pts = np.array(points)
        maps.register(pts[None, :, 0], pts[None, :, 1])
        return [_score(maps, pose, lx, ly, lfx, lfy, free=free) for free in (False, True)]

    (plain, _), (tested, _) = scores([a, c])
    assert plain == pytest.approx(expected_a, rel=1e-6) and tested == pytest.approx(expected_a, rel=1e-6)
    (plain, _), (tested, tested_lik) = scores([a, c, b])
    assert plain == pytest.approx(expected_a, rel=1e-6)  # the original never rejects
    assert tested == pytest.approx(expected_c, rel=1e-6)  # A skipped, C used
    assert tested < plain
    # with only A and B, the free-cell test leaves the beam without a cell: no score, the no-hit likelihood
    (plain, _), (tested, tested_lik) = scores([a, b])
    assert plain == pytest.approx(expected_a, rel=1e-6)
    assert tested == 0.0 and tested_lik == pytest.approx(-0.5 / 0.075)
