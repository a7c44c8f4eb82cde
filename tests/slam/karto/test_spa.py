"""Sparse Pose Adjustment (slam_karto's doSPA) on graphs with known answers, against a dense reference
written from spa2d.cpp, and against the Ceres-style optimizer that minimises the same cost."""

from __future__ import annotations

import math

import numpy as np

from slamtrials.geometry import ominus
from slamtrials.slam.karto.optimize import information, optimize_pose_graph
from slamtrials.slam.karto.spa import optimize_spa


def _square(n_side: int) -> np.ndarray:
    poses = []
    for side in range(4):
        heading = side * math.pi / 2
        for k in range(n_side):
            x, y = [(k, 0.0), (n_side, k), (n_side - k, n_side), (0.0, n_side - k)][side]
            poses.append((x, y, (heading + math.pi) % (2 * math.pi) - math.pi))
    return np.array(poses, dtype=np.float64)


def _loop_graph(n_side: int, seed: int, noise: tuple[float, float, float]):
    """A square loop of ``4 n_side`` poses: odometry edges, the closing edge and a chord every 7 nodes (every
    other one backwards, from the later node to the earlier), with measurements off the truth by ``noise``
    (so the optimum does not meet them all)."""
    truth = _square(n_side)
    n = truth.shape[0]
    chords = [(k, k + 5) if k % 2 else (k + 5, k) for k in range(0, n - 8, 7)]
    source = list(range(n - 1)) + [n - 1] + [a for a, _ in chords]
    target = list(range(1, n)) + [0] + [b for _, b in chords]
    rng = np.random.default_rng(seed)
    src, tgt = np.array(source), np.array(target)
    means = ominus(truth[src], truth[tgt]) + rng.normal(0.0, noise, (src.shape[0], 3))
    weights = np.repeat(information(np.diag([0.01, 0.01, 0.001]))[None], src.shape[0], axis=0)
    start = truth.copy()
    start[1:] += rng.normal(0.0, [0.3, 0.3, 0.05], size=(n - 1, 3))
    return truth, start, src, tgt, means, weights


def _wrap_once(angle: float) -> float:
    if angle > math.pi:
        angle -= 2 * math.pi
    if angle < -math.pi:
        angle += 2 * math.pi
    return angle


def _dense_spa(poses, source, target, means, prec, max_iterations=40):
    """doSPA read straight from spa2d.cpp with dense numpy: returns poses, steps tried, reason and which
    steps were taken."""
    x = poses.astype(np.float64).copy()
    n = x.shape[0]

    def errors(x):
        out = []
        for a, b, m in zip(source, target, means):
            c, s = math.cos(x[a, 2]), math.sin(x[a, 2])
            dx, dy = x[b, :2] - x[a, :2]
            out.append([c * dx + s * dy - m[0], -s * dx + c * dy - m[1], _wrap_once(x[b, 2] - x[a, 2] - m[2])])
        return np.array(out)

    def cost(x):
        return float(sum(e @ p @ e for e, p in zip(errors(x), prec)))

    lam, laminc, taken = 1e-4, 2.0, []
    for iteration in range(max_iterations):
        e = errors(x)
        hessian, rhs = np.zeros((3 * n, 3 * n)), np.zeros(3 * n)
        for k, (a, b) in enumerate(zip(source, target)):
            c, s = math.cos(x[a, 2]), math.sin(x[a, 2])
            dx, dy = x[b, :2] - x[a, :2]
            jac = np.zeros((3, 3 * n))
            jac[:, 3 * a : 3 * a + 3] = [[-c, -s, -s * dx + c * dy], [s, -c, -c * dx - s * dy], [0, 0, -1]]
            jac[:, 3 * b : 3 * b + 3] = [[c, s, 0], [-s, c, 0], [0, 0, 1]]
            hessian += jac.T @ prec[k] @ jac
            rhs -= jac.T @ prec[k] @ e[k]
        hessian, rhs = hessian[3:, 3:], rhs[3:]
        hessian[np.diag_indices_from(hessian)] *= 1.0 + lam
        step = np.linalg.solve(hessian, rhs)
        if step @ step < 1e-16:
            return x, iteration, "converged", taken
        candidate = x.copy()
        candidate[1:] += step.reshape(-1, 3)
        candidate[1:, 2] = [_wrap_once(t) for t in candidate[1:, 2]]
        if cost(candidate) < cost(x):
            x, lam = candidate, lam * 0.5
            taken.append(True)
        else:
            lam, laminc = lam * laminc, laminc * 2.0
            taken.append(False)
    return x, max_iterations, "maximum iterations", taken


def _line_problem():
    # three poses on a line; the direct edge 0 -> 2 says 2.2 m, the chain says 2.0 m; unit precisions
    source, target = np.array([0, 1, 0]), np.array([1, 2, 2])
    means = np.array([[1.0, 0, 0], [1.0, 0, 0], [2.2, 0, 0]])
    weights = np.repeat(np.eye(3)[None], 3, axis=0)
    start = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]])
    return start, source, target, means, weights


def _hard_problem():
    """Four poses along 12 m, edges with long lever arms, headings off by up to ~2 rad: doSPA's first three
    steps raise the cost and are refused."""
    rng = np.random.default_rng(9)
    truth = np.zeros((4, 3))
    truth[:, 0] = [0.0, 1.0, 11.0, 12.0]
    source, target = np.array([0, 1, 2, 0, 1]), np.array([1, 2, 3, 2, 3])
    means = ominus(truth[source], truth[target]) + rng.normal(0.0, 0.3, (5, 3))
    prec = np.repeat(np.diag([1.0, 1.0, 0.1])[None], 5, axis=0)
    start = truth.copy()
    start[1:] += rng.normal(0.0, [1.0, 1.0, 1.5], (3, 3))
    start[:, 2] = (start[:, 2] + math.pi) % (2 * math.pi) - math.pi
    return start, source, target, means, prec


def test_a_consistent_loop_started_at_its_optimum_stops_before_any_step():
    # the measurements are the truth's own relative poses: the first step is rounding noise, far below the
    # 1e-8 stop test, so doSPA ends without moving a node
    truth, _, source, target, means, weights = _loop_graph(5, seed=1, noise=(0.0, 0.0, 0.0))
    result = optimize_spa(truth, source, target, means, weights)
    assert result.reason == "converged" and result.iterations == 0
    np.testing.assert_array_equal(result.poses, truth)
    assert result.final_cost == result.initial_cost < 1e-20


def test_a_perturbed_consistent_loop_is_recovered_with_node_0_fixed():
    truth, start, source, target, means, weights = _loop_graph(5, seed=3, noise=(0.0, 0.0, 0.0))
    start[0] = [0.0, 0.0, 0.0]
    result = optimize_spa(start, source, target, means, weights)
    np.testing.assert_array_equal(result.poses[0], start[0])
    assert result.reason == "converged"
    np.testing.assert_allclose(result.poses[:, :2], truth[:, :2], rtol=0, atol=1e-9)
    heading_error = (result.poses[:, 2] - truth[:, 2] + math.pi) % (2 * math.pi) - math.pi
    assert np.abs(heading_error).max() < 1e-9
    assert result.final_cost < 1e-15 * result.initial_cost
    assert np.all(np.abs(result.poses[:, 2]) <= math.pi)


def test_each_step_multiplies_the_diagonal_by_one_plus_lambda_and_halves_lambda_when_taken():
    # only the x coordinates are wrong here, and the x residuals are linear in them, so the steps can be
    # worked by hand: (H with its diagonal times 1 + lambda) dx = -J^T r, lambda = 1e-4, then 5e-5, ...
    start, source, target, means, weights = _line_problem()
    jacobian = np.array([[1.0, 0.0], [-1.0, 1.0], [0.0, 1.0]])  # rows: x-residuals of edges 0-1, 1-2, 0-2
    hessian = jacobian.T @ jacobian
    x = start[1:, 0].copy()
    expected = []
    for lam in (1e-4, 5e-5):
        residual = np.array([x[0] - 1.0, x[1] - x[0] - 1.0, x[1] - 2.2])
        damped = hessian + np.diag(lam * np.diag(hessian))
        x = x + np.linalg.solve(damped, -jacobian.T @ residual)
        expected.append(x.copy())
    one = optimize_spa(start, source, target, means, weights, max_iterations=1)
    np.testing.assert_allclose(one.poses[1:, 0], expected[0], rtol=0, atol=1e-15)
    # an additive lambda I would have stopped elsewhere by far more than that
    additive = start[1:, 0] + np.linalg.solve(hessian + 1e-4 * np.eye(2), -jacobian.T @ np.array([0, 0, -0.2]))
    assert np.abs(additive - expected[0]).max() > 1e-6
    np.testing.assert_array_equal(one.poses[1:, 1:], 0.0)
    # the third solve is below 1e-8 (the error after two steps is ~1e-9): doSPA stops after two steps
    full = optimize_spa(start, source, target, means, weights)
    assert full.reason == "converged" and full.iterations == 2
    np.testing.assert_allclose(full.poses[1:, 0], expected[1], rtol=0, atol=1e-15)
    np.testing.assert_allclose(full.poses[1:, 0], [3.2 / 3, 6.4 / 3], rtol=0, atol=1e-8)
    # residuals (0.2, 0.2, -0.2) / 3 at the optimum; the reported cost is half of doSPA's sum
    assert math.isclose(full.final_cost, 0.5 * 3 * (0.2 / 3) ** 2, rel_tol=1e-9)


def test_the_stop_test_is_a_squared_step_below_1e_minus_16():
    # two poses, one edge from the fixed node with a unit precision: the first step is -r / (1 + 1e-4)
    means = np.array([[1.0, 0.0, 0.0]])
    weights = np.eye(3)[None]
    for offset, steps in ((0.99e-8, 0), (1.02e-8, 1)):
        start = np.array([[0.0, 0.0, 0.0], [1.0 + offset, 0.0, 0.0]])
        result = optimize_spa(start, np.array([0]), np.array([1]), means, weights)
        assert result.reason == "converged" and result.iterations == steps
        assert (result.poses[1, 0] == start[1, 0]) == (steps == 0)


def test_refused_steps_grow_lambda_by_a_doubling_factor_and_leave_the_nodes():
    start, source, target, means, prec = _hard_problem()
    _, _, _, taken = _dense_spa(start, source, target, means, prec)
    assert taken[:4] == [False, False, False, True]
    # three refusals: nothing moved, the cost is the initial one
    three = optimize_spa(start, source, target, means, prec, max_iterations=3)
    np.testing.assert_array_equal(three.poses, start)
    assert three.final_cost == three.initial_cost and three.reason == "maximum iterations"
    # the fourth step is taken with lambda = 1e-4 * 2 * 4 * 8 = 6.4e-3, the same state's system
    four = optimize_spa(start, source, target, means, prec, max_iterations=4)
    by_hand, _, _, _ = _dense_spa(start, source, target, means, prec, max_iterations=4)
    np.testing.assert_allclose(four.poses, by_hand, rtol=0, atol=1e-12)
    assert four.final_cost < four.initial_cost


def test_a_step_must_lower_the_cost_strictly():
    # node 1 sits at the optimum of two contradicting edges (+-1 km: cost 2e6 exactly, gradient exactly 0);
    # node 2 is 1e-6 m off its edge. Its step is ~1e-6 m, above the stop test, but lowers the cost by 1e-12,
    # lost in rounding against 2e6: doSPA refuses it (newcost < cost fails) and grows lambda by 2, 4, 8,
    # 16, 32, 64, to 209.7, where the step, 1e-6 / 210.7, is below 1e-8: six refusals, no node moved
    start = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0 + 1e-6, 0.0, 0.0]])
    source, target = np.array([0, 0, 0]), np.array([1, 1, 2])
    means = np.array([[1000.0, 0.0, 0.0], [-1000.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    result = optimize_spa(start, source, target, means, np.repeat(np.eye(3)[None], 3, axis=0))
    assert (result.iterations, result.reason) == (6, "converged")
    np.testing.assert_array_equal(result.poses, start)
    assert result.final_cost == result.initial_cost == 1e6


def test_a_whole_run_with_refusals_follows_the_dense_reading_of_spa2d():
    start, source, target, means, prec = _hard_problem()
    expected, steps, reason, taken = _dense_spa(start, source, target, means, prec)
    assert False in taken and reason == "converged"
    result = optimize_spa(start, source, target, means, prec)
    assert (result.iterations, result.reason) == (steps, reason)
    np.testing.assert_allclose(result.poses, expected, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(result.poses[0], start[0])


def test_node_angles_and_angle_errors_are_brought_into_minus_pi_pi():
    # node 1 at 3.1 rad must turn to 3.2 rad: the update crosses pi and is wrapped to 3.2 - 2 pi, and the
    # next error, -3.08 - 3.2 = -6.28, is wrapped back to about 0
    start = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 3.1]])
    means = np.array([[1.0, 0.0, 3.2]])
    result = optimize_spa(start, np.array([0]), np.array([1]), means, np.eye(3)[None])
    assert result.reason == "converged"
    assert math.isclose(result.poses[1, 2], 3.2 - 2 * math.pi, abs_tol=1e-9)
    assert result.final_cost < 1e-16 * result.initial_cost


def test_a_failed_factorisation_steps_by_the_right_hand_side_as_csparse_leaves_it():
    # node 2 has no edge, so A is singular; cs_cholsol fails and leaves B = -J^T P e, which doSPA then
    # takes as the step: node 1 moves by -P e = -0.5 * 0.2 (a solve would have moved it by about -0.2)
    start = np.array([[0.0, 0.0, 0.0], [1.2, 0.0, 0.0], [5.0, 5.0, 0.0]])
    means = np.array([[1.0, 0.0, 0.0]])
    weights = (0.5 * np.eye(3))[None]
    result = optimize_spa(start, np.array([0]), np.array([1]), means, weights, max_iterations=1)
    np.testing.assert_allclose(result.poses[1], [1.2 - 0.1, 0.0, 0.0], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(result.poses[2], start[2])


def test_only_the_upper_triangle_of_the_precision_is_read():
    # SpaSolver::AddConstraint copies the upper triangle of Karto's inverse covariance into both halves
    _, start, source, target, means, weights = _loop_graph(5, seed=4, noise=(0.02, 0.02, 0.005))
    weights = weights.copy()
    weights[:, 0, 1] = weights[:, 1, 0] = 3.0
    lopsided = weights.copy()
    lopsided[:, 1, 0] = lopsided[:, 2, 0] = lopsided[:, 2, 1] = -7.0
    a = optimize_spa(start, source, target, means, weights)
    b = optimize_spa(start, source, target, means, lopsided)
    np.testing.assert_array_equal(a.poses, b.poses)


def test_it_reaches_the_same_optimum_as_the_ceres_style_optimizer():
    # both minimise sum r^T W r; Ceres (slam_toolbox's options) stops at a parameter tolerance of 1e-3 of
    # the state, SPA at steps of 1e-8, so SPA is at least as low and the poses agree to Ceres' tolerance.
    # 20 nodes take CSparse's natural order, 60 nodes the fill-reducing one
    for n_side in (5, 15):
        _, start, source, target, means, weights = _loop_graph(n_side, seed=7, noise=(0.05, 0.05, 0.01))
        spa = optimize_spa(start, source, target, means, weights)
        ceres = optimize_pose_graph(start, source, target, means, weights)
        assert spa.reason == "converged"
        assert spa.final_cost <= ceres.final_cost and spa.final_cost < 0.01 * spa.initial_cost
        assert math.isclose(spa.final_cost, ceres.final_cost, rel_tol=1e-3)
        np.testing.assert_allclose(spa.poses, ceres.poses, rtol=0, atol=1e-2)
        assert math.isclose(spa.initial_cost, ceres.initial_cost, rel_tol=1e-12)


def test_repeated_runs_give_the_same_bits():
    for n_side in (5, 15):
        _, start, source, target, means, weights = _loop_graph(n_side, seed=11, noise=(0.05, 0.05, 0.01))
        first = optimize_spa(start, source, target, means, weights)
        second = optimize_spa(start.copy(), source.copy(), target.copy(), means.copy(), weights.copy())
        assert first.poses.tobytes() == second.poses.tobytes()
        assert (first.iterations, first.final_cost) == (second.iterations, second.final_cost)
