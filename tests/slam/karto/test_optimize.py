"""The sparse Levenberg-Marquardt pose-graph optimizer on graphs with known solutions."""

from __future__ import annotations

import math

import numpy as np

from slamtrials.geometry import compose, ominus
from slamtrials.slam.karto.optimize import information, optimize_pose_graph


def _square(n_side: int = 5) -> np.ndarray:
    poses = []
    for side in range(4):
        heading = side * math.pi / 2
        for k in range(n_side):
            if side == 0:
                x, y = k, 0.0
            elif side == 1:
                x, y = n_side, k
            elif side == 2:
                x, y = n_side - k, n_side
            else:
                x, y = 0.0, n_side - k
            poses.append((x, y, (heading + math.pi) % (2 * math.pi) - math.pi))
    return np.array(poses, dtype=np.float64)


def test_square_loop_with_exact_measurements_is_recovered_from_a_distorted_start():
    truth = _square()
    n = truth.shape[0]
    source = np.array(list(range(n - 1)) + [n - 1])
    target = np.array(list(range(1, n)) + [0])
    means = ominus(truth[source], truth[target])  # consecutive edges and the loop-closing edge
    weights = np.repeat(information(np.diag([0.01, 0.01, 0.001]))[None], source.shape[0], axis=0)
    start = truth.copy()
    rng = np.random.default_rng(3)
    start[1:] += rng.normal(0.0, [0.3, 0.3, 0.1], size=(n - 1, 3))
    result = optimize_pose_graph(start, source, target, means, weights)
    np.testing.assert_array_equal(result.poses[0], truth[0])  # the first node is held fixed
    # Ceres stops before a step shorter than 1e-3 of the state (22 m here): within a millimetre
    np.testing.assert_allclose(result.poses[:, :2], truth[:, :2], atol=1e-3)
    heading_error = (result.poses[:, 2] - truth[:, 2] + math.pi) % (2 * math.pi) - math.pi
    assert np.abs(heading_error).max() < 1e-4
    assert result.final_cost < 1e-6 * result.initial_cost


def test_inconsistent_loop_spreads_the_error_by_the_weights():
    # three poses on a line; the direct edge 0 -> 2 says 2.2 m, the chain says 2.0 m; equal weights
    source, target = np.array([0, 1, 0]), np.array([1, 2, 2])
    means = np.array([[1.0, 0, 0], [1.0, 0, 0], [2.2, 0, 0]])
    weights = np.repeat(np.eye(3)[None], 3, axis=0)
    result = optimize_pose_graph(np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]]), source, target, means, weights)
    # least squares: x2 = 2 x1 and 2 x2 - x1 = 3.2, so x1 = 3.2 / 3 and x2 = 6.4 / 3 (to Ceres' parameter
    # tolerance: 1e-3 of the state, 2.4 m here)
    np.testing.assert_allclose(result.poses[:, 0], [0.0, 3.2 / 3, 6.4 / 3], atol=1e-4)


def test_it_stops_as_ceres_does_without_taking_the_last_step():
    # slam_toolbox's Ceres options: parameter tolerance 1e-3, checked before a step is judged
    # (TrustRegionMinimizer::ParameterToleranceReached), so the step that would end the run is not taken,
    # and not in the first iteration, whose state norm Ceres does not know yet; here one Levenberg-Marquardt
    # step (trust radius 1e4) from the start is the result
    source, target = np.array([0, 1, 0]), np.array([1, 2, 2])
    means = np.array([[1.0, 0, 0], [1.0, 0, 0], [2.2, 0, 0]])
    weights = np.repeat(np.eye(3)[None], 3, axis=0)
    start = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]])
    result = optimize_pose_graph(start, source, target, means, weights)
    # the first step by hand: x-residuals r = (x1 - 1, x2 - x1 - 1, x2 - 2.2), cost 1/2 |r|^2
    jacobian = np.array([[1.0, 0.0], [-1.0, 1.0], [0.0, 1.0]])
    residual = np.array([0.0, 0.0, -0.2])
    hessian = jacobian.T @ jacobian
    damped = hessian + np.diag(np.diag(hessian)) / 1e4
    step = np.linalg.solve(damped, -jacobian.T @ residual)
    assert result.reason == "parameter tolerance" and result.iterations == 2
    np.testing.assert_allclose(result.poses[1:, 0], start[1:, 0] + step, rtol=0, atol=1e-12)
    assert abs(result.poses[2, 0] - 6.4 / 3) > 1e-6  # the second, untaken step would have gone on


def test_information_inverts_a_covariance():
    cov = np.array([[0.04, 0.01, 0.0], [0.01, 0.09, 0.0], [0.0, 0.0, 0.002]])
    product = information(cov) @ cov
    np.testing.assert_allclose(product, np.eye(3), atol=1e-12)


def test_the_parameter_tolerance_is_measured_on_the_raw_coordinates_as_ceres_does():
    # Ceres compares a step with 1e-3 of the norm of the free parameters as they are, so the same graph far
    # from the map frame's origin (the Freiburg logs start 576 m from it) stops sooner: on MIT CSAIL every
    # solve of slam_toolbox ends after 2 iterations. A 120-node ring, bent by heading drift as a loop
    # closure leaves it:
    n = 120
    angle = np.arange(n) * 2 * math.pi / n
    heading = (angle + 1.5 * math.pi) % (2 * math.pi) - math.pi
    truth = np.column_stack([10 * np.cos(angle), 10 * np.sin(angle), heading])
    source = np.array(list(range(n - 1)) + [n - 1])
    target = np.array(list(range(1, n)) + [0])
    means = ominus(truth[source], truth[target])
    weights = np.repeat(information(np.diag([1e-3, 1e-3, 1e-4]))[None], n, axis=0)
    start = truth.copy()
    for k in range(1, n):
        start[k] = compose(start[k - 1], means[k - 1] + np.array([0.0, 0.0, 0.002]))
    near = optimize_pose_graph(start, source, target, means, weights)
    far_start = start.copy()
    far_start[:, :2] += 1000.0
    far = optimize_pose_graph(far_start, source, target, means, weights)
    assert far.reason == near.reason == "parameter tolerance"
    assert far.iterations == 2 < near.iterations
    assert far.final_cost > 100 * near.final_cost
