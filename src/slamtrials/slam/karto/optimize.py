"""Sparse Levenberg-Marquardt on SE(2): the pose-graph optimizer Karto calls after each loop closure.

The problem is slam_toolbox's Ceres problem (its ``PoseGraph2dErrorTerm``): for an edge from node a
to node b with relative pose ``(tx, ty, tth)`` and covariance ``C`` (in a's frame) the residual is

    r = ( R(th_a)^T (p_b - p_a) - (tx, ty),  wrap(th_b - th_a - tth) )

and the cost is ``1/2 sum r^T C^-1 r`` (slam_toolbox's CeresSolver::AddConstraint weights the residual by
the Cholesky factor of ``C^-1``). The first node is held fixed. Each iteration solves ``(H + lambda D) dx
= -g`` with ``H = J^T W J``, ``D`` its diagonal clamped to [1e-6, 1e32] and ``lambda = 1 / radius``, by
the sparse Cholesky of :mod:`.sparsechol` (no BLAS, so the same bits on every CPU). The run follows
Ceres' TrustRegionMinimizer and Levenberg-Marquardt strategy with slam_toolbox's options: initial
radius 1e4 (at most 1e8); a step whose model decrease is not positive (or whose system is not positive
definite) is invalid, and three in a row end the run; otherwise the step is tried and the run ends,
*without taking it*, when it is shorter than 1e-3 of the state's norm (parameter tolerance; the raw
coordinates of the free nodes, as Ceres takes them, so a map frame far from its origin stops runs
sooner; not before the first taken step, when Ceres does not know the norm yet) or changes the cost by at most 1e-3 of it
(function tolerance, taken or not); it is taken when its quality exceeds 1e-3, the quality being the
larger of the decrease relative to the model's and the same against a lagging reference cost
(non-monotonic steps, at most 3 in a row); the radius grows by ``1 / max(1/3, 1 - (2 q - 1)^3)`` after
a taken step and shrinks by a doubling factor after a refused one; it stops after 50 iterations, when the
largest gradient entry after a taken step is below 1e-6, or when the radius falls to 1e-16; the result is
the cheapest state a taken step reached.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse
from numba import njit
from numpy.typing import NDArray

from slamtrials.slam.karto.sparsechol import NotPositiveDefinite, cholesky, cholesky_solve, minimum_degree_order

__all__ = ["OptimizerResult", "optimize_pose_graph", "information"]

MAX_ITERATIONS = 50
FUNCTION_TOLERANCE = 1e-3
PARAMETER_TOLERANCE = 1e-3
GRADIENT_TOLERANCE = 1e-6
MIN_RELATIVE_DECREASE = 1e-3
INITIAL_RADIUS = 1e4
MIN_RADIUS = 1e-16
MAX_RADIUS = 1e8
MAX_INVALID_STEPS = 3
MAX_NONMONOTONIC_STEPS = 3
MIN_DIAGONAL, MAX_DIAGONAL = 1e-6, 1e32


@dataclass(frozen=True)
class OptimizerResult:
    """What :func:`optimize_pose_graph` did.

    Attributes
    ----------
    poses:
        float64 ``[N, 3]`` optimized poses.
    iterations:
        Iterations run (taken or refused steps).
    initial_cost, final_cost:
        ``1/2 sum r^T W r`` before and after.
    reason:
        Why it stopped.
    """

    poses: NDArray[np.float64]
    iterations: int
    initial_cost: float
    final_cost: float
    reason: str


def information(covariance: NDArray[np.float64]) -> NDArray[np.float64]:
    """Inverse of a symmetric 3 x 3 covariance by its adjugate (written out; no LAPACK)."""
    c = np.asarray(covariance, dtype=np.float64)
    a, b, d = c[0, 0], c[0, 1], c[0, 2]
    e, f, i = c[1, 1], c[1, 2], c[2, 2]
    m00 = e * i - f * f
    m01 = d * f - b * i
    m02 = b * f - d * e
    m11 = a * i - d * d
    m12 = b * d - a * f
    m22 = a * e - b * b
    det = a * m00 + b * m01 + d * m02
    return np.array([[m00, m01, m02], [m01, m11, m12], [m02, m12, m22]]) / det


@njit(cache=True, nogil=True)
def _wrap(angle):  # pragma: no cover - compiled
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True, nogil=True)
def _linearize(poses, source, target, means, weights):  # pragma: no cover - compiled
    """Cost, gradient ``[3N]`` and the Hessian's entries (COO: rows, cols, values, 36 per edge)."""
    n_edges = source.shape[0]
    g = np.zeros(poses.shape[0] * 3)
    rows = np.empty(n_edges * 36, dtype=np.int64)
    cols = np.empty(n_edges * 36, dtype=np.int64)
    vals = np.empty(n_edges * 36)
    jac = np.zeros((3, 6))
    r = np.zeros(3)
    wr = np.zeros(3)
    wj = np.zeros((3, 6))
    cost = 0.0
    for e in range(n_edges):
        a = source[e]
        b = target[e]
        c = math.cos(poses[a, 2])
        s = math.sin(poses[a, 2])
        dx = poses[b, 0] - poses[a, 0]
        dy = poses[b, 1] - poses[a, 1]
        r[0] = c * dx + s * dy - means[e, 0]
        r[1] = -s * dx + c * dy - means[e, 1]
        r[2] = _wrap(poses[b, 2] - poses[a, 2] - means[e, 2])
        for i in range(3):
            for j in range(6):
                jac[i, j] = 0.0
        jac[0, 0] = -c
        jac[0, 1] = -s
        jac[0, 2] = -s * dx + c * dy
        jac[1, 0] = s
        jac[1, 1] = -c
        jac[1, 2] = -c * dx - s * dy
        jac[2, 2] = -1.0
        jac[0, 3] = c
        jac[0, 4] = s
        jac[1, 3] = -s
        jac[1, 4] = c
        jac[2, 5] = 1.0
        w = weights[e]
        for i in range(3):
            total = 0.0
            for k in range(3):
                total += w[i, k] * r[k]
            wr[i] = total
            for j in range(6):
                total = 0.0
                for k in range(3):
                    total += w[i, k] * jac[k, j]
                wj[i, j] = total
        for i in range(3):
            cost += 0.5 * r[i] * wr[i]
        index = (a, a, a, b, b, b)
        offset = (0, 1, 2, 0, 1, 2)
        for j in range(6):
            total = 0.0
            for k in range(3):
                total += jac[k, j] * wr[k]
            g[3 * index[j] + offset[j]] += total
        q = e * 36
        for i in range(6):
            for j in range(6):
                total = 0.0
                for k in range(3):
                    total += jac[k, i] * wj[k, j]
                rows[q] = 3 * index[i] + offset[i]
                cols[q] = 3 * index[j] + offset[j]
                vals[q] = total
                q += 1
    return cost, g, rows, cols, vals


@njit(cache=True, nogil=True)
def _cost(poses, source, target, means, weights):  # pragma: no cover - compiled
    cost = 0.0
    r = np.zeros(3)
    for e in range(source.shape[0]):
        a = source[e]
        b = target[e]
        c = math.cos(poses[a, 2])
        s = math.sin(poses[a, 2])
        dx = poses[b, 0] - poses[a, 0]
        dy = poses[b, 1] - poses[a, 1]
        r[0] = c * dx + s * dy - means[e, 0]
        r[1] = -s * dx + c * dy - means[e, 1]
        r[2] = _wrap(poses[b, 2] - poses[a, 2] - means[e, 2])
        for i in range(3):
            for k in range(3):
                cost += 0.5 * r[i] * weights[e, i, k] * r[k]
    return cost


@njit(cache=True, nogil=True)
def _dot(a, b):  # pragma: no cover - compiled
    total = 0.0
    for i in range(a.shape[0]):
        total += a[i] * b[i]
    return total


@njit(cache=True, nogil=True)
def _max_abs(a):  # pragma: no cover - compiled
    best = 0.0
    for i in range(a.shape[0]):
        best = max(best, abs(a[i]))
    return best


class _StepEvaluator:
    """Ceres' TrustRegionStepEvaluator with non-monotonic steps (slam_toolbox: ``use_nonmonotonic_steps``,
    at most 3 in a row): a step's quality is the larger of its decrease relative to the current cost and
    to a reference cost that may lag behind (Conn, Gould and Toint, algorithm 10.1.2)."""

    def __init__(self, cost: float):
        self.minimum = self.current = self.reference = self.candidate = cost
        self.reference_change = self.candidate_change = 0.0
        self.nonmonotonic = 0

    def quality(self, cost: float, predicted: float) -> float:
        relative = (self.current - cost) / predicted
        historical = (self.reference - cost) / (self.reference_change + predicted)
        return max(relative, historical)

    def accepted(self, cost: float, predicted: float) -> None:
        self.current = cost
        self.candidate_change += predicted
        self.reference_change += predicted
        if cost < self.minimum:
            self.minimum = cost
            self.nonmonotonic = 0
            self.candidate = cost
            self.candidate_change = 0.0
        else:
            self.nonmonotonic += 1
            if cost > self.candidate:
                self.candidate = cost
                self.candidate_change = 0.0
        if self.nonmonotonic == MAX_NONMONOTONIC_STEPS:
            self.reference = self.candidate
            self.reference_change = self.candidate_change


def _scalar_order(n_free: int, source: NDArray[np.int64], target: NDArray[np.int64]) -> NDArray[np.intp]:
    """Unknown order: minimum degree over the free nodes (node k >= 1 is free node k - 1), 3 unknowns each."""
    pairs = [(int(a) - 1, int(b) - 1) for a, b in zip(source, target) if a > 0 and b > 0]
    nodes = minimum_degree_order(n_free, pairs)
    return (3 * nodes[:, None] + np.arange(3)[None, :]).reshape(-1)


def optimize_pose_graph(
    poses: NDArray[np.float64],
    source: NDArray[np.int64],
    target: NDArray[np.int64],
    means: NDArray[np.float64],
    weights: NDArray[np.float64],
) -> OptimizerResult:
    """Minimise the pose-graph cost (module docstring) over every node but node 0.

    Parameters
    ----------
    poses:
        float64 ``[N, 3]`` initial poses (x, y, theta).
    source, target:
        int ``[E]`` edge end nodes.
    means:
        float64 ``[E, 3]`` relative poses (target seen from source).
    weights:
        float64 ``[E, 3, 3]`` information matrices (inverse covariances).
    """
    x = np.array(poses, dtype=np.float64).reshape(-1, 3)
    n = x.shape[0]
    source = np.asarray(source, dtype=np.int64)
    target = np.asarray(target, dtype=np.int64)
    means = np.asarray(means, dtype=np.float64).reshape(-1, 3)
    weights = np.asarray(weights, dtype=np.float64).reshape(-1, 3, 3)
    cost = _cost(x, source, target, means, weights)
    initial = cost
    if n < 2 or source.shape[0] == 0:
        return OptimizerResult(x, 0, initial, cost, "nothing to optimize")
    m = 3 * (n - 1)
    order = _scalar_order(n - 1, source, target)
    radius = INITIAL_RADIUS
    decrease_factor = 2.0
    reason = "maximum iterations"
    iteration = 0
    invalid_steps = 0
    linearized = True
    # Ceres knows the state's norm only after its first successful step (TrustRegionMinimizer::Init sets
    # x_norm_ to -1), so the parameter tolerance cannot end the first iteration
    state_norm = -1.0
    best, minimum_cost = x, cost  # the solution returned: the cheapest state a successful step reached
    steps = _StepEvaluator(cost)
    while iteration < MAX_ITERATIONS:
        if linearized:
            cost, g_all, rows, cols, vals = _linearize(x, source, target, means, weights)
            keep = (rows >= 3) & (cols >= 3)
            hessian = scipy.sparse.coo_matrix((vals[keep], (rows[keep] - 3, cols[keep] - 3)), shape=(m, m)).tocsc()
            g = g_all[3:]
            diagonal = np.clip(hessian.diagonal(), MIN_DIAGONAL, MAX_DIAGONAL)
            permuted = hessian[order][:, order]
            linearized = False
            if _max_abs(g) <= GRADIENT_TOLERANCE:
                reason = "gradient tolerance"
                break
        iteration += 1
        lam = 1.0 / radius
        damped = permuted + scipy.sparse.diags(lam * diagonal[order], format="csc")
        upper = scipy.sparse.triu(damped, format="csc")
        upper.sort_indices()
        predicted = 0.0
        try:
            factor = cholesky(upper.indptr, upper.indices, upper.data)
            step = np.empty(m)
            step[order] = cholesky_solve(factor, -g[order])
            scaled = lam * diagonal * step
            predicted = -0.5 * _dot(g, step) + 0.5 * _dot(step, scaled)
        except NotPositiveDefinite:
            pass
        if not predicted > 0.0:  # an invalid step (HandleInvalidStep): counted, then as a refused step
            invalid_steps += 1
            if invalid_steps >= MAX_INVALID_STEPS:
                reason = "invalid steps"
                break
            radius /= decrease_factor
            decrease_factor *= 2.0
            if radius <= MIN_RADIUS:
                reason = "trust region too small"
                break
            continue
        invalid_steps = 0
        candidate = x.copy()
        candidate[1:] += step.reshape(-1, 3)
        candidate[1:, 2] = (candidate[1:, 2] + math.pi) % (2.0 * math.pi) - math.pi
        new_cost = _cost(candidate, source, target, means, weights)
        # both tolerances end the run before the step is judged, and the step is not taken
        moved = (candidate - x).reshape(-1)
        if math.sqrt(_dot(moved, moved)) <= PARAMETER_TOLERANCE * (state_norm + PARAMETER_TOLERANCE):
            reason = "parameter tolerance"
            break
        if abs(cost - new_cost) <= FUNCTION_TOLERANCE * cost:
            reason = "function tolerance"
            break
        quality = steps.quality(new_cost, predicted)
        if quality > MIN_RELATIVE_DECREASE:
            x = candidate
            # Ceres' norm of the free parameters as they are, so where the map frame's origin lies
            # matters: far from it (as on logs in world coordinates) the tolerance ends runs sooner
            free = x[1:].reshape(-1)
            state_norm = math.sqrt(_dot(free, free))
            linearized = True
            radius = min(MAX_RADIUS, radius / max(1.0 / 3.0, 1.0 - (2.0 * quality - 1.0) ** 3))
            decrease_factor = 2.0
            steps.accepted(new_cost, predicted)
            cost = new_cost
            if cost < minimum_cost:
                best, minimum_cost = x, cost
        else:
            radius /= decrease_factor
            decrease_factor *= 2.0
        if radius <= MIN_RADIUS:
            reason = "trust region too small"
            break
    x = best
    return OptimizerResult(x, iteration, float(initial), float(_cost(x, source, target, means, weights)), reason)
