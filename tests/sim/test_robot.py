"""Robot kinematics: exact arcs, speed and acceleration limits, and disc-footprint collisions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from slamtrials.geometry import compose, compose1, ominus, ominus1
from slamtrials.sim import RobotConfig, SimConfig, Simulator
from slamtrials.sim.robot import CollisionChecker, arc_increment, arc_sagitta, limit_velocity
from slamtrials.worlds.world import World, world_to_map

finite = st.floats(-50.0, 50.0)
angle = st.floats(-10.0, 10.0)


def room_world(size_m: float = 10.0, resolution: float = 0.05, origin=(0.0, 0.0, 0.0)) -> World:
    n = int(round(size_m / resolution))
    occ = np.zeros((n, n), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return World(occ, resolution, origin=np.array(origin, dtype=float), name="room")


def footprint_clearance(world: World, xy) -> float:
    """Brute force: distance (m) from ``xy`` to the nearest occupied cell (closed squares; outside occupied)."""
    occ = np.pad(world.occupied[::-1], 1, constant_values=True)  # [v + 1, u + 1]
    jj, ii = np.nonzero(occ)
    u, v = world_to_map(world, np.asarray(xy, dtype=float))
    du = np.maximum(np.maximum((ii - 1.0) - u, 0.0), u - ii)
    dv = np.maximum(np.maximum((jj - 1.0) - v, 0.0), v - jj)
    return float(np.sqrt(du**2 + dv**2).min()) * world.resolution


# --- kinematics ------------------------------------------------------------------------------------------


def test_arc_increment_known_answers():
    np.testing.assert_allclose(arc_increment(0.5, 0.0, 0.1), [0.05, 0.0, 0.0])
    np.testing.assert_allclose(arc_increment(0.0, 1.0, 0.1), [0.0, 0.0, 0.1])
    # A quarter circle of radius 2 / pi.
    np.testing.assert_allclose(
        arc_increment(1.0, math.pi / 2, 1.0), [2 / math.pi, 2 / math.pi, math.pi / 2], atol=1e-15
    )
    # Backwards on the same circle.
    np.testing.assert_allclose(
        arc_increment(-1.0, -math.pi / 2, 1.0), [-2 / math.pi, 2 / math.pi, -math.pi / 2], atol=1e-15
    )


@settings(max_examples=60, deadline=None)
@given(v=st.floats(-2.0, 2.0), w=st.floats(-3.0, 3.0), dt=st.floats(0.01, 0.5))
def test_arc_increment_matches_fine_integration(v, w, dt):
    n = 2000
    h = dt / n
    theta = w * h * (np.arange(n) + 0.5)  # midpoint rule
    expected = [np.sum(v * h * np.cos(theta)), np.sum(v * h * np.sin(theta)), w * dt]
    np.testing.assert_allclose(arc_increment(v, w, dt), expected, atol=1e-7)


def test_arc_sagitta():
    assert arc_sagitta(1.0, 0.0) == 0.0
    r = 2.0 / math.pi
    assert arc_sagitta(1.0, math.pi / 2) == pytest.approx(r * (1 - math.cos(math.pi / 4)))
    assert arc_sagitta(-1.0, -math.pi / 2) == pytest.approx(r * (1 - math.cos(math.pi / 4)))


@given(a=st.tuples(finite, finite, angle), b=st.tuples(finite, finite, angle))
@settings(deadline=None)  # the first example may load the numba kernels from cache
def test_scalar_pose_helpers_equal_geometry(a, b):
    np.testing.assert_allclose(compose1(a, b), compose(np.array(a), np.array(b)), atol=1e-9)
    rel = ominus1(a, b)
    ref = ominus(np.array(a), np.array(b))
    np.testing.assert_allclose(rel[:2], ref[:2], atol=1e-9)
    assert abs(math.remainder(rel[2] - ref[2], 2 * math.pi)) < 1e-9
    assert -math.pi <= compose1(a, b)[2] < math.pi


def test_limit_velocity():
    cfg = RobotConfig()
    dt = 0.1
    # Acceleration from rest.
    assert limit_velocity((0.0, 0.0), (10.0, 10.0), cfg, dt) == pytest.approx((0.05, cfg.max_angular_accel * dt))
    # Speed limits once up to speed.
    v, w = limit_velocity((0.69, 1.2), (10.0, 10.0), cfg, dt)
    assert v == pytest.approx(0.7) and w == pytest.approx(cfg.max_angular_speed)
    # Braking is limited too.
    assert limit_velocity((0.7, 0.0), (0.0, 0.0), cfg, dt)[0] == pytest.approx(0.65)
    # Reverse.
    assert limit_velocity((-0.68, 0.0), (-5.0, 0.0), cfg, dt)[0] == pytest.approx(-0.7)
    no_rev = RobotConfig(allow_reverse=False)
    assert no_rev.reverse_speed_limit == 0.0
    assert limit_velocity((0.0, 0.0), (-5.0, 0.0), no_rev, dt)[0] == 0.0
    slow_rev = RobotConfig(max_reverse_speed=0.2)
    assert limit_velocity((-0.19, 0.0), (-5.0, 0.0), slow_rev, dt)[0] == pytest.approx(-0.2)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(commands=st.lists(st.tuples(st.floats(-3.0, 3.0), st.floats(-5.0, 5.0)), min_size=1, max_size=60))
def test_simulator_respects_speed_and_acceleration_limits(commands):
    world = room_world(size_m=30.0)
    sim = Simulator(world, SimConfig(), np.random.default_rng(0), start=[15.0, 15.0, 0.0])
    cfg = sim.config.robot
    dt = sim.config.dt
    prev = sim.velocity
    for cmd in commands:
        before = sim.truth
        sim.step(cmd)
        v, w = sim.velocity
        assert -cfg.reverse_speed_limit - 1e-12 <= v <= cfg.max_linear_speed + 1e-12
        assert abs(w) <= cfg.max_angular_speed + 1e-12
        assert abs(v - prev[0]) <= cfg.max_linear_accel * dt + 1e-12
        assert abs(w - prev[1]) <= cfg.max_angular_accel * dt + 1e-12
        moved = math.hypot(*(sim.truth[:2] - before[:2]))
        assert moved <= cfg.max_linear_speed * dt + 1e-12
        prev = (v, w)


# --- collisions ------------------------------------------------------------------------------------------


def test_driving_into_a_wall_stops_before_it_and_stalls():
    world = room_world()
    sim = Simulator(world, SimConfig(), np.random.default_rng(0), start=[5.0, 5.0, 0.0])
    frames = [sim.step((0.7, 0.0)) for _ in range(200)]
    radius = sim.config.robot.radius
    for f in frames:
        assert footprint_clearance(world, f.truth[:2]) >= radius
    stalled = np.array([f.stalled for f in frames])
    assert stalled.any() and stalled[-20:].all()
    # After a bump it starts again from rest (0.05 m/s after one step, 5 mm), so it creeps up to the
    # wall: it ends closer than one step at standstill speed, never past the contact point.
    x = frames[-1].truth[0]
    assert 9.95 - radius - 0.005 <= x <= 9.95 - radius
    # Stalled: no translation any more, speed zero.
    assert np.all(np.array([f.truth[:2] for f in frames[-20:]]) == frames[-1].truth[:2])
    assert sim.velocity[0] == 0.0


def test_stalled_robot_can_still_turn_in_place_and_back_out():
    world = room_world()
    sim = Simulator(world, SimConfig(), np.random.default_rng(0), start=[9.7, 5.0, 0.0])
    frames = [sim.step((0.3, 0.5)) for _ in range(30)]
    stalled = [f for f in frames if f.stalled]
    assert len(stalled) >= 2
    # It kept turning while blocked, without translating.
    assert stalled[-1].truth[2] > stalled[0].truth[2] + 0.05
    assert footprint_clearance(world, stalled[-1].truth[:2]) >= sim.config.robot.radius
    before = sim.truth
    for _ in range(30):
        f = sim.step((-0.3, 0.0))
    assert not f.stalled and math.hypot(*(sim.truth[:2] - before[:2])) > 0.5


def test_start_pose_in_collision_is_refused():
    from slamtrials.errors import SimulationError

    world = room_world()
    with pytest.raises(SimulationError, match="overlaps a wall"):
        Simulator(world, SimConfig(), np.random.default_rng(0), start=[0.15, 5.0, 0.0])


@settings(max_examples=200, deadline=None)
@given(x=st.floats(0.0, 3.0), y=st.floats(0.0, 3.0), radius=st.floats(0.01, 0.6))
def test_disc_check_is_exact(x, y, radius):
    occ = np.zeros((60, 60), dtype=bool)
    occ[20:25, 30:33] = True
    occ[40, 10] = True
    world = World(occ, 0.05, start=[0.5, 0.5, 0.0])
    checker = CollisionChecker(world, radius)
    true_clearance = footprint_clearance(world, (x, y))
    if true_clearance > radius + 1e-9:
        assert checker.disc_free((x, y))
    elif true_clearance < radius - 1e-9:
        assert not checker.disc_free((x, y))


@settings(max_examples=200, deadline=None)
@given(x0=st.floats(0.3, 2.7), y0=st.floats(0.3, 2.7), dx=st.floats(-0.4, 0.4), dy=st.floats(-0.4, 0.4))
def test_swept_check_never_misses_a_cell(x0, y0, dx, dy):
    occ = np.zeros((60, 60), dtype=bool)
    occ[20:25, 30:33] = True
    occ[40, 10] = True
    occ[10, 10:50] = True
    world = World(occ, 0.05, start=[0.5, 0.5, 0.0])
    radius = 0.15
    checker = CollisionChecker(world, radius)
    if checker.path_free((x0, y0), (x0 + dx, y0 + dy)):
        for s in np.linspace(0.0, 1.0, 41):
            assert footprint_clearance(world, (x0 + s * dx, y0 + s * dy)) >= radius - 1e-12


def cluttered_world() -> World:
    rng = np.random.default_rng(5)
    occ = np.zeros((120, 120), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    for _ in range(25):
        r, c = rng.integers(5, 115, 2)
        h, w = rng.integers(1, 12, 2)
        occ[r : r + h, c : c + w] = True
    occ[55:66, 55:66] = False
    return World(occ, 0.05, start=[3.0, 3.0, 0.0])


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    commands=st.lists(st.tuples(st.floats(-0.7, 0.7), st.floats(-1.2, 1.2)), min_size=10, max_size=80),
    repeat=st.integers(1, 8),
)
def test_random_driving_never_overlaps_a_wall(commands, repeat):
    world = cluttered_world()
    sim = Simulator(world, SimConfig(), np.random.default_rng(1), start=[3.0, 3.0, 0.3])
    radius = sim.config.robot.radius
    for cmd in commands:
        for _ in range(repeat):
            f = sim.step(cmd)
            assert footprint_clearance(world, f.truth[:2]) >= radius - 1e-12
