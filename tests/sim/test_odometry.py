"""The odometry error model: per-run bias draw, exact scaling of distance and rotation, optional noise."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from slamtrials.sim import OdometryConfig, SimConfig, Simulator
from slamtrials.sim.odometry import Odometry, draw_bias, measured_increment
from slamtrials.sim.robot import arc_increment
from slamtrials.worlds.world import World


def corridor_world() -> World:
    """A 60 m x 4 m corridor (0.05 m cells) for straight drives."""
    occ = np.zeros((80, 1200), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return World(occ, 0.05, name="corridor", start=[2.0, 2.0, 0.0])


def config_with_bias(linear: float, angular: float, **odo) -> SimConfig:
    return SimConfig(profile="paper", odometry=OdometryConfig(bias_linear=linear, bias_angular=angular, **odo))


def test_bias_draw_ranges_and_paper_values():
    cfg = OdometryConfig()
    assert cfg.bias_linear_range == (-0.005, 0.005)
    assert cfg.bias_angular_range[1] == pytest.approx(0.0174533, abs=1e-7)
    rng = np.random.default_rng(0)
    draws = [draw_bias(cfg, rng) for _ in range(2000)]
    lin = np.array([d["linear"] for d in draws])
    ang = np.array([d["angular"] for d in draws])
    assert lin.min() >= -0.005 and lin.max() <= 0.005 and lin.min() < -0.0045 and lin.max() > 0.0045
    assert np.abs(ang).max() <= math.radians(1.0) and np.abs(ang).max() > 0.9 * math.radians(1.0)


def test_fixed_bias_overrides_the_draw_but_not_the_stream():
    a = np.random.default_rng(4)
    b = np.random.default_rng(4)
    drawn = draw_bias(OdometryConfig(), a)
    fixed = draw_bias(OdometryConfig(bias_linear=0.01, bias_angular=-0.02), b)
    assert fixed == {"linear": 0.01, "angular": -0.02}
    assert drawn != fixed
    assert a.random() == b.random()  # same position in the stream afterwards


def test_zero_bias_is_exact():
    delta = np.array([0.07, 0.003, 0.12])
    np.testing.assert_allclose(measured_increment(delta, 0.0, 0.0), delta, atol=1e-16)
    np.testing.assert_array_equal(measured_increment([0.0, 0.0, 0.3], 0.01, 0.0), [0.0, 0.0, 0.3])


@settings(max_examples=200, deadline=None)
@given(v=st.floats(-1.0, 1.0), w=st.floats(-1.5, 1.5), e_lin=st.floats(-0.05, 0.05), e_ang=st.floats(-0.05, 0.05))
def test_an_arc_is_measured_as_the_scaled_arc(v, w, e_lin, e_ang):
    # Measuring arc (v, w) with biases gives exactly the arc ((1 + e_lin) v, (1 + e_ang) w), forwards or backwards.
    dt = 0.1
    measured = measured_increment(arc_increment(v, w, dt), e_lin, e_ang)
    np.testing.assert_allclose(measured, arc_increment((1 + e_lin) * v, (1 + e_ang) * w, dt), atol=1e-13)


def test_plus_one_percent_linear_bias_on_a_straight_drive():
    world = corridor_world()
    sim = Simulator(world, config_with_bias(0.01, 0.0), np.random.default_rng(0))
    start = sim.truth
    for _ in range(400):
        sim.step((0.7, 0.0))
    true_distance = math.hypot(*(sim.truth[:2] - start[:2]))
    odo_distance = math.hypot(*sim.odometry[:2])
    assert true_distance > 20.0
    assert odo_distance == pytest.approx(1.01 * true_distance, rel=1e-9)
    assert sim.odometry[1] == pytest.approx(0.0, abs=1e-9) and sim.odometry[2] == 0.0


def rotate_in_place(sim: Simulator, total: float) -> tuple[float, float]:
    """Turn in place by ``total`` radians of true rotation; return (true, odometry) unwrapped rotation."""
    cfg = sim.config.robot
    dt = sim.config.dt
    true_turned = 0.0
    odo_turned = 0.0
    for _ in range(10_000):
        remaining = total - true_turned
        if abs(remaining) < 1e-12 and sim.velocity[1] == 0.0:
            break
        w = min(cfg.max_angular_speed, remaining / dt, math.sqrt(2 * cfg.max_angular_accel * max(remaining, 0.0)))
        t0, o0 = sim.truth[2], sim.odometry[2]
        sim.step((0.0, w))
        true_turned += math.remainder(sim.truth[2] - t0, 2 * math.pi)
        odo_turned += math.remainder(sim.odometry[2] - o0, 2 * math.pi)
    return true_turned, odo_turned


def test_minus_one_degree_per_radian_turns_360_into_353_7():
    world = corridor_world()
    e = -math.radians(1.0)
    sim = Simulator(world, config_with_bias(0.0, e), np.random.default_rng(0))
    true_turned, odo_turned = rotate_in_place(sim, 2 * math.pi)
    assert math.degrees(true_turned) == pytest.approx(360.0, abs=0.1)
    assert math.degrees(odo_turned) == pytest.approx(353.7, abs=0.1)
    assert odo_turned == pytest.approx((1 + e) * true_turned, rel=1e-12)
    # A pure rotation moves neither the robot nor its odometry.
    np.testing.assert_allclose(sim.odometry[:2], 0.0, atol=1e-12)
    np.testing.assert_allclose(sim.truth[:2], world.start[:2], atol=1e-12)


def test_odometry_starts_at_zero_and_integrates_a_biased_square():
    world = corridor_world()
    sim = Simulator(world, config_with_bias(0.004, 0.01), np.random.default_rng(0))
    assert np.all(sim.observe().odometry == 0.0)
    for _ in range(50):
        sim.step((0.5, 0.3))
    # With bias, odometry is the same kind of path but drifts away from the truth expressed from the start.
    assert np.abs(sim.odometry - (sim.truth - world.start)).max() > 1e-3


def test_noise_is_zero_mean_a_random_walk_in_motion_and_seeded():
    cfg = OdometryConfig(bias_linear=0.0, bias_angular=0.0, noise_linear_per_m=0.05, noise_angular_per_rad=0.1)
    delta = arc_increment(0.5, 0.2, 0.1)
    results = []
    for seed in range(400):
        odo = Odometry(cfg, draw_bias(cfg, np.random.default_rng(seed)), np.random.default_rng(seed))
        results.append(odo.update(delta).copy())
    results = np.array(results)
    length = 0.05  # arc length of the step; its heading change is 0.02 rad
    # a random walk per metre and per radian: std 0.05 m/sqrt(m) * sqrt(0.05 m), 0.1 rad/sqrt(rad) * sqrt(0.02 rad)
    std_length, std_heading = 0.05 * math.sqrt(length), 0.1 * math.sqrt(0.02)
    lengths = np.hypot(results[:, 0], results[:, 1])
    assert abs(lengths.mean() - length) < 3 * std_length / math.sqrt(400) + 1e-9
    assert lengths.std() == pytest.approx(std_length, rel=0.2)
    assert results[:, 2].std() == pytest.approx(std_heading, rel=0.2)
    # Same seed, same result; no motion, no noise.
    a = Odometry(cfg, {"linear": 0.0, "angular": 0.0}, np.random.default_rng(1)).update(delta)
    b = Odometry(cfg, {"linear": 0.0, "angular": 0.0}, np.random.default_rng(1)).update(delta)
    np.testing.assert_array_equal(a, b)
    still = Odometry(cfg, {"linear": 0.0, "angular": 0.0}, np.random.default_rng(1)).update([0.0, 0.0, 0.0])
    np.testing.assert_array_equal(still, [0.0, 0.0, 0.0])


def test_no_noise_draws_nothing():
    cfg = OdometryConfig()
    rng = np.random.default_rng(0)
    state = rng.bit_generator.state
    Odometry(cfg, {"linear": 0.003, "angular": 0.01}, rng).update([0.05, 0.0, 0.01])
    assert rng.bit_generator.state == state


@pytest.mark.slow  # by simulation: 3,300 noisy odometries
def test_noise_of_a_step_cut_in_pieces_adds_up_to_the_noise_of_the_whole_step():
    """Cut invariance for a single step: one step of 0.2 m and 0.1 rad, or the same arc in 1, 7 or 400
    pieces (a zero-motion step among them), gives the same spread of the summed arc-length and heading errors."""
    cfg = OdometryConfig(
        bias_linear=0.0, bias_angular=0.0, noise_linear_per_m=0.04, noise_angular_per_rad=0.05,
        noise_linear_per_rad=0.02, noise_angular_per_m=0.03,
    )  # fmt: skip
    expected_length = math.sqrt(0.04**2 * 0.2 + 0.02**2 * 0.1)
    expected_heading = math.sqrt(0.05**2 * 0.1 + 0.03**2 * 0.2)
    for pieces in (1, 7, 400):
        piece = arc_increment(0.2 / pieces, 0.1 / pieces, 1.0)
        heading_errors, length_errors = [], []
        for seed in range(300 if pieces == 400 else 1500):
            odo = Odometry(cfg, {"linear": 0.0, "angular": 0.0}, np.random.default_rng(seed))
            total_length = total_heading = 0.0
            for k in range(pieces):
                before = odo.pose.copy()
                after = odo.update(piece).copy()
                if k == 0:
                    odo.update([0.0, 0.0, 0.0])  # a duplicated stamp: no motion, no noise
                    np.testing.assert_array_equal(odo.pose, after)
                phi = after[2] - before[2]
                half = 0.5 * phi
                total_heading += phi
                mean_heading = before[2] + half  # the chord's direction; the arc length is signed
                chord = math.cos(mean_heading) * (after[0] - before[0]) + math.sin(mean_heading) * (
                    after[1] - before[1]
                )
                total_length += chord / (math.sin(half) / half)
            heading_errors.append(total_heading - 0.1)
            length_errors.append(total_length - 0.2)
        n = len(heading_errors)
        allowed = 4.5 * math.sqrt(2.0 / n)
        assert np.mean(np.square(length_errors)) / expected_length**2 == pytest.approx(1.0, abs=allowed), pieces
        assert np.mean(np.square(heading_errors)) / expected_heading**2 == pytest.approx(1.0, abs=allowed), pieces
