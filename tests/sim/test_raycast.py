"""The laser: known answers in a square room, border and max range, mount offset, noise, and the
accelerated kernel against the plain traversal (bit for bit) and a brute-force reference."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from slamtrials.sim.config import LaserConfig
from slamtrials.sim.raycast import LaserModel, RaycastMap, cast_scan, cast_scan_dda
from slamtrials.worlds.world import World, world_to_map


def room_world(size_m: float = 10.0, resolution: float = 0.05, origin=(0.0, 0.0, 0.0), walls: bool = True) -> World:
    """A square grid of ``size_m`` metres whose border cells are walls (1 cell thick)."""
    n = int(round(size_m / resolution))
    occ = np.zeros((n, n), dtype=bool)
    if walls:
        occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return World(occ, resolution, origin=np.array(origin, dtype=float), name="room")


def box_distance(px: float, py: float, angle: float, x0: float, y0: float, x1: float, y1: float) -> float:
    """Distance from (px, py) inside the box [x0, x1] x [y0, y1] to its boundary along ``angle``."""
    c, s = math.cos(angle), math.sin(angle)
    ts = []
    if c > 0:
        ts.append((x1 - px) / c)
    if c < 0:
        ts.append((x0 - px) / c)
    if s > 0:
        ts.append((y1 - py) / s)
    if s < 0:
        ts.append((y0 - py) / s)
    return min(ts)


# --- known answers --------------------------------------------------------------------------------------


def test_laser_geometry_of_the_paper():
    cfg = LaserConfig()
    assert cfg.num_beams == 541
    angles = cfg.angles
    assert angles.shape == (541,)
    assert angles[0] == pytest.approx(-math.radians(135.0), abs=1e-12)
    assert angles[-1] == pytest.approx(math.radians(135.0), abs=1e-12)
    assert np.allclose(np.diff(angles), math.radians(0.5), atol=1e-12)
    info = cfg.geometry()
    assert (info.angle_min, info.angle_increment) == (cfg.angle_min, cfg.angle_increment)
    assert info.range_max == 80.0 and info.mount == (0.0, 0.0, 0.0)  # the seed's Stage laser


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (-3.0, 2.0, 0.0)])
@pytest.mark.parametrize("pose", [(3.0, 4.0, 0.3), (5.0, 5.0, 0.0), (8.7, 1.3, -2.5)])
def test_square_room_known_distances(origin, pose):
    world = room_world(origin=origin)
    laser = LaserModel(world, LaserConfig())
    pose = np.array([pose[0] + origin[0], pose[1] + origin[1], pose[2]])
    ranges = laser.true_ranges(pose)
    assert ranges.dtype == np.float32 and ranges.shape == (541,)
    # Free interior: from one cell in from each edge to one cell in from the opposite edge.
    x0, y0 = origin[0] + 0.05, origin[1] + 0.05
    x1, y1 = origin[0] + 9.95, origin[1] + 9.95
    expected = np.array([box_distance(pose[0], pose[1], pose[2] + a, x0, y0, x1, y1) for a in laser.angles])
    # Exact up to float32 rounding (the brief asks for one cell; the ray caster is exact).
    np.testing.assert_allclose(ranges, expected, atol=1e-4, rtol=0)


def test_rotated_world_origin():
    # The same room placed in the world with a rotated origin: ranges depend only on the pose in the map.
    theta0 = 0.4
    world = room_world(origin=(1.0, -2.0, theta0))
    laser = LaserModel(world, LaserConfig())
    uv = np.array([60.0, 80.0]) * 0.05  # map point in metres, in the map frame
    c, s = math.cos(theta0), math.sin(theta0)
    xy = np.array([1.0 + c * uv[0] - s * uv[1], -2.0 + s * uv[0] + c * uv[1]])
    heading_map = 0.7
    ranges = laser.true_ranges([xy[0], xy[1], heading_map + theta0])
    expected = [box_distance(uv[0], uv[1], heading_map + a, 0.05, 0.05, 9.95, 9.95) for a in laser.angles]
    np.testing.assert_allclose(ranges, expected, atol=1e-4, rtol=0)


def test_open_grid_rays_stop_at_the_image_border():
    # No walls at all: everything outside the grid counts as occupied.
    occ = np.zeros((100, 100), dtype=bool)
    world = World(occ, 0.1, start=[2.0, 3.0, 0.0])
    laser = LaserModel(world, LaserConfig(max_range=30.0))
    ranges = laser.true_ranges([2.0, 3.0, 0.0])
    expected = [box_distance(2.0, 3.0, a, 0.0, 0.0, 10.0, 10.0) for a in laser.angles]
    np.testing.assert_allclose(ranges, expected, atol=1e-4, rtol=0)


@pytest.mark.slow
def test_beams_into_open_space_read_exactly_max_range_inside_and_inf_as_a_reading():
    # A 200 m x 200 m empty room; from its centre, nothing is within 80 m.
    world = room_world(size_m=200.0)
    laser = LaserModel(world, LaserConfig())
    ranges = laser.true_ranges([100.0, 100.0, 0.123])
    assert np.all(ranges == np.float32(80.0))  # the raycast's own value
    assert np.all(np.isposinf(laser.scan([100.0, 100.0, 0.123], np.random.default_rng(0))))  # REP 117
    # Near a wall: beams towards the wall hit it, the others have no return.
    pose = [100.0, 4.0, 0.0]
    ranges = laser.true_ranges(pose)
    assert ranges.max() == np.float32(80.0)
    assert np.all((ranges == np.float32(80.0)) | (ranges < 80.0))
    right = np.argmin(np.abs(laser.angles + math.pi / 2))  # pointing down, at the wall y = 0.05
    assert ranges[right] == pytest.approx(3.95, abs=1e-5)
    reading = laser.scan(pose, np.random.default_rng(0))
    np.testing.assert_array_equal(np.isposinf(reading), ranges == np.float32(80.0))
    np.testing.assert_array_equal(reading[ranges < 80.0], ranges[ranges < 80.0])


def test_a_shorter_laser_reports_walls_beyond_its_range_as_no_returns():
    world = room_world(size_m=100.0)
    laser = LaserModel(world, LaserConfig(max_range=30.0))
    reading = laser.scan([50.0, 50.0, 0.123], np.random.default_rng(0))
    assert np.all(np.isposinf(reading))


def test_origin_inside_a_wall_reads_zero_then_min_range():
    world = room_world()
    laser = LaserModel(world, LaserConfig())
    assert np.all(laser.true_ranges([0.02, 5.0, 0.0]) == 0.0)
    laser = LaserModel(world, LaserConfig(min_range=0.05))
    assert np.all(laser.scan([0.02, 5.0, 0.0], np.random.default_rng(0)) == np.float32(0.05))


def test_range_noise():
    world = room_world(size_m=40.0)
    cfg = LaserConfig(range_noise_std=0.02, max_range=30.0)
    laser = LaserModel(world, cfg)
    pose = np.array([5.0, 5.0, 0.0])
    true = laser.true_ranges(pose)
    a = laser.scan(pose, np.random.default_rng(7))
    b = laser.scan(pose, np.random.default_rng(7))
    np.testing.assert_array_equal(a, b)
    hit = true < 30.0
    assert (~hit).any() and hit.any()
    assert np.all(np.isposinf(a[~hit]))  # no-return readings stay no-returns
    err = a[hit].astype(float) - true[hit]
    assert 0.01 < err.std() < 0.03 and abs(err.mean()) < 0.01
    assert np.all(a[hit] >= cfg.min_range) and np.all(a[hit] <= cfg.max_range)


def test_no_noise_leaves_the_random_stream_alone():
    world = room_world()
    laser = LaserModel(world, LaserConfig())
    rng = np.random.default_rng(3)
    state = rng.bit_generator.state
    laser.scan([5.0, 5.0, 0.0], rng)
    assert rng.bit_generator.state == state


def test_raycast_map_is_shared_per_world():
    world = room_world()
    assert RaycastMap.for_world(world) is RaycastMap.for_world(world)
    rmap = RaycastMap.for_world(world)
    assert rmap.dist.dtype == np.float32 and rmap.dist.flags.c_contiguous
    # Flipped: dist[iy] is map row iy counted from the bottom; occupied exactly where dist is 0.
    np.testing.assert_array_equal(rmap.dist[::-1] == 0, world.occupied)


# --- the accelerated kernel against the plain traversal and a brute-force reference --------------------


def random_world(seed: int, size: int, rooms: int, clutter: float) -> World:
    """A random floor plan: random wall rectangles (outlines and blocks) plus scattered clutter cells."""
    rng = np.random.default_rng(seed)
    occ = rng.random((size, size)) < clutter
    for _ in range(rooms):
        r0, c0 = rng.integers(0, size, 2)
        h, w = rng.integers(1, max(2, size // 2), 2)
        if rng.random() < 0.5:
            occ[r0 : r0 + h, c0 : c0 + w] = True
        else:
            occ[r0, c0 : c0 + w] = True
            occ[min(r0 + h, size - 1), c0 : c0 + w] = True
            occ[r0 : r0 + h, c0] = True
            occ[r0 : r0 + h, min(c0 + w, size - 1)] = True
    occ[size // 2, size // 2] = False
    return World(occ, 1.0, name=f"random{seed}", start=[size // 2 + 0.5, size - size // 2 - 0.5, 0.0])


def brute_force_bounds(occ_up: np.ndarray, ox: float, oy: float, angle: float, max_t: float, tol: float = 1e-9):
    """Bounds (lo, hi) for the range (cells) of one ray, from every occupied square separately.

    ``lo``: first entry over the closed squares the ray touches (corners included); ``hi``: first entry
    over the squares whose interior it crosses. A correct caster returns a value between them (they
    differ only where a ray grazes a corner exactly). Cells outside the grid are a ring of occupied cells.
    """
    padded = np.pad(occ_up, 1, constant_values=True)
    jj, ii = np.nonzero(padded)
    x0 = ii - 1.0
    y0 = jj - 1.0
    dx, dy = math.cos(angle), math.sin(angle)

    def slab(lo, origin, d, closed):
        if d != 0.0:
            with np.errstate(over="ignore"):
                t0 = (lo - origin) / d
                t1 = (lo + 1.0 - origin) / d
            return np.minimum(t0, t1), np.maximum(t0, t1)
        # A ray parallel to the slab: inside it for all t, or never (on its edge: closed yes, open no).
        inside = (lo <= origin) & (origin <= lo + 1.0) if closed else (lo < origin) & (origin < lo + 1.0)
        return np.where(inside, -np.inf, np.inf), np.where(inside, np.inf, -np.inf)

    bounds = []
    for closed in (True, False):
        tx0, tx1 = slab(x0, ox, dx, closed)
        ty0, ty1 = slab(y0, oy, dy, closed)
        enter = np.maximum(tx0, ty0)
        leave = np.minimum(tx1, ty1)
        if closed:
            hit = (enter <= leave + tol) & (leave >= 0.0)
        else:
            hit = (leave - enter > tol) & (leave > 0.0)
        bounds.append(min(np.maximum(enter, 0.0)[hit].min(initial=np.inf), max_t))
    return bounds[0], bounds[1]


# Fractions and angles with the awkward special values (cell boundaries, axis-aligned and diagonal rays).
fractions = st.one_of(st.floats(0.0, 1.0, exclude_max=True), st.sampled_from([0.0, 0.5, 0.9999999999999998, 1e-300]))
headings = st.one_of(
    st.floats(-7.0, 7.0), st.sampled_from([0.0, 1e-300, -1e-300, math.pi / 2, math.pi / 4, math.pi, -3 * math.pi / 4])
)

world_params = st.tuples(
    st.integers(0, 2**32 - 1),  # seed
    st.integers(8, 120),  # size (cells)
    st.integers(0, 12),  # rectangles
    st.sampled_from([0.0, 0.002, 0.02, 0.1]),  # clutter density
)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    params=world_params,
    fx=fractions,
    fy=fractions,
    cell=st.integers(0, 10**9),
    theta=headings,
    max_t=st.floats(0.5, 200.0),
)
# found by hypothesis: a subnormal heading (1 / sin overflows) from a point on a cell boundary gave NaN
@example(
    params=(1080, 58, 0, 0.1), fx=0.0, fy=0.9999999999999998, cell=513566, theta=-2.225073858507203e-309, max_t=1.0
)
def test_accelerated_equals_plain_traversal_bitwise(params, fx, fy, cell, theta, max_t):
    world = random_world(*params)
    dist = RaycastMap(world).dist
    free = np.argwhere(dist > 0)
    iy, ix = free[cell % len(free)]
    origin = (ix + fx, iy + fy)
    angles = np.linspace(-math.pi, math.pi, 361)
    fast = cast_scan(dist, origin, theta, angles, max_t)
    plain = cast_scan_dda(dist, origin, theta, angles, max_t)
    np.testing.assert_array_equal(fast, plain)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    params=world_params,
    fx=fractions,
    fy=fractions,
    cell=st.integers(0, 10**9),
    theta=headings,
    max_t=st.floats(0.5, 200.0),
)
def test_raycaster_matches_brute_force(params, fx, fy, cell, theta, max_t):
    world = random_world(*params)
    occ_up = np.ascontiguousarray(world.occupied[::-1])
    dist = RaycastMap(world).dist
    free = np.argwhere(~occ_up)
    iy, ix = free[cell % len(free)]
    ox, oy = ix + fx, iy + fy
    angles = np.linspace(-math.pi, math.pi, 37)
    ranges = cast_scan(dist, (ox, oy), theta, angles, max_t)
    for a, r in zip(angles, ranges):
        lo, hi = brute_force_bounds(occ_up, ox, oy, theta + a, max_t)
        tol = 1e-5 * max(1.0, hi)  # float32 output
        assert lo - tol <= r <= hi + tol, (a, r, lo, hi)
        if lo >= max_t:  # nothing within range: exactly max range
            assert r == np.float32(max_t)


def test_ray_along_a_cell_boundary_regression():
    # A ray starting exactly on a horizontal cell boundary and running along it (dy = -1.2e-16): the
    # point after a jump rounds back onto the boundary; the traversal must not step back (it looped).
    world = random_world(1079865, 21, 1, 0.02)
    dist = RaycastMap(world).dist
    angles = np.linspace(-math.pi, math.pi, 361)
    origin = (16.07339193789365, 19.0)
    fast = cast_scan(dist, origin, 4.1570075119565214e-253, angles, 39.55746820746612)
    np.testing.assert_array_equal(fast, cast_scan_dda(dist, origin, 4.1570075119565214e-253, angles, 39.55746820746612))


@pytest.mark.parametrize("seed", range(6))
def test_accelerated_equals_plain_on_large_worlds(seed):
    # Bigger worlds with large empty rooms, so that long jumps happen; many poses and dense beams.
    world = random_world(seed, 400, 25, 0.0005)
    dist = RaycastMap(world).dist
    rng = np.random.default_rng(seed)
    free = np.argwhere(dist > 0)
    angles = np.linspace(-math.pi, math.pi, 2001)
    for _ in range(20):
        iy, ix = free[rng.integers(len(free))]
        origin = (ix + rng.random(), iy + rng.random())
        theta = rng.uniform(-math.pi, math.pi)
        fast = cast_scan(dist, origin, theta, angles, 600.0, 0.05)
        plain = cast_scan_dda(dist, origin, theta, angles, 600.0, 0.05)
        np.testing.assert_array_equal(fast, plain)


def test_exact_axis_aligned_and_diagonal_rays():
    # Rays along the axes (a zero direction component) and through cell corners.
    occ = np.zeros((20, 20), dtype=bool)
    occ[:, 15] = True  # wall at u in [15, 16)
    world = World(occ, 1.0, start=[5.5, 5.5, 0.0])
    dist = RaycastMap(world).dist
    r = cast_scan(dist, (5.0, 5.0), 0.0, np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]), 100.0)
    np.testing.assert_allclose(r, [10.0, 15.0, 5.0, 5.0], atol=1e-6)
    d = cast_scan_dda(dist, (5.0, 5.0), 0.0, np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]), 100.0)
    np.testing.assert_array_equal(r, d)
    r = cast_scan(dist, (5.0, 5.0), math.pi / 4, np.array([0.0]), 100.0)
    assert r[0] == pytest.approx(10.0 * math.sqrt(2.0), abs=1e-4)


def test_world_to_map_is_the_frame_used():
    world = room_world(origin=(2.0, 1.0, 0.0))
    laser = LaserModel(world, LaserConfig())
    pose = np.array([5.0, 3.0, 0.0])
    uv = world_to_map(world, pose[:2])
    direct = cast_scan(laser.map.dist, uv, 0.0, laser.angles, 30.0, 0.05)
    np.testing.assert_array_equal(direct, laser.true_ranges(pose))
