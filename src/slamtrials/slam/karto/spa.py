"""Sparse Pose Adjustment (SPA, Konolige et al. 2010): slam_karto's pose-graph optimizer.

ROS's slam_karto optimizes its pose graph with ``SpaSolver::Compute``, which calls
``SysSPA2d::doSPA(40)`` of the sparse_bundle_adjustment package with its default arguments (initial
lambda 1e-4, ``SBA_SPARSE_CHOLESKY``, initTol 1e-8, 50 CG iterations). :func:`optimize_spa` does what
``doSPA`` does, as ``src/spa2d.cpp`` (``SysSPA2d::doSPA``, ``setupSparseSys``, ``calcCost``,
``Con2dP2::calcErr`` and ``setJacobians``, ``Node2d::normArot``) and ``src/csparse.cpp``
(``CSparse2d::setupCSstructure`` and ``doChol``) of sparse_bundle_adjustment write it. Step by step:

1. State. Node k is ``(x_k, y_k, th_k)`` (metres, metres, radians); ``poses`` is float64 ``[N, 3]``.
   Node 0 is held fixed (``nFixed = 1``); the N - 1 others are free, 3 unknowns each, in node order.
2. Error of an edge from node a to node b with mean ``(mx, my, mth)`` (b seen from a) and precision
   ``P`` (3 x 3, inverse covariance): ``e = (R(th_a)^T (p_b - p_a) - (mx, my), (th_b - th_a) - mth)``,
   the rotation being *node a's* and the translation part formed as spa2d's world-to-node transform does
   it, ``R^T p_b + (-R^T p_a)``. The angle part is brought into [-pi, pi] by adding or subtracting 2 pi
   once (not a modulo). The cost is ``sum_e e^T P e`` (no factor 1/2), summed in edge order. ``P`` is
   made symmetric from its upper triangle, as ``SpaSolver::AddConstraint`` copies it.
3. Jacobians (``setJacobians``): with ``c, s = cos th_a, sin th_a`` and ``(dx, dy) = p_b - p_a``,
   ``J_a = [[-c, -s, -s dx + c dy], [s, -c, -c dx - s dy], [0, 0, -1]]`` and
   ``J_b = [[c, s, 0], [-s, c, 0], [0, 0, 1]]``, at the current state.
4. Normal equations (``setupSparseSys``): ``A = sum J^T P J`` in 3 x 3 blocks (the blocks of the fixed
   node left out), ``B = -sum J^T P e``, accumulated edge by edge; then every diagonal entry of ``A`` is
   *multiplied* by ``1 + lambda`` (``setupCSstructure``'s ``diaginc``; not ``A + lambda I``).
5. Solve ``A dx = B`` (``doChol``: CSparse's ``cs_cholsol``). If the factorisation fails (a pivot not
   positive), CSparse leaves ``B`` as it was and doSPA takes ``B`` itself as the step.
6. Stop test: if ``|dx|^2 < (1e-8)^2`` the run ends ("converged"), the step not taken. (doSPA's initTol
   and CG-iteration arguments belong to the block-PCG solver and are unused with sparse Cholesky; this
   squared-step test, ``sqMinDelta``, is the only tolerance.)
7. Update every free node: ``x += dx_x``, ``y += dx_y``, ``th += dx_th`` with ``th`` brought into
   [-pi, pi] by one add or subtract of 2 pi (``normArot``). The fixed node is never touched.
8. Accept when the new cost is strictly lower: keep it and halve lambda. Otherwise restore the nodes,
   multiply lambda by ``laminc`` and double ``laminc`` (``laminc`` starts at 2 in each call and is
   not reset by a taken step, so the k-th refusal of a call multiplies lambda by 2^k).
9. Repeat from 3 (from 4's damping alone after a refusal: the state, hence ``A`` and ``B``, are
   unchanged) until the stop test or ``max_iterations`` (40) steps, taken or refused.

Lambda starts at 1e-4 in every call (``doSPA`` resets its member ``lambda`` whenever ``sLambda > 0``).

The linear systems are solved with :mod:`.sparsechol` (plain loops, no BLAS), so the result has the same
bits on every CPU. Where the C++ may round differently (in the last bits only; the mathematics is the
same):

- Ordering. ``CSparse2d::doChol`` calls ``cs_cholsol`` with the natural order up to 100 unknowns (33 free
  nodes) and with AMD (``order = 1``) beyond. The matrix is laid out as ``setupCSstructure`` lays it out;
  beyond 100 unknowns :func:`.amd.amd_order` is CSparse's own ``cs_amd(1, A)`` (ported step for step,
  ties and all) and :func:`.amd.symmetric_permute` lays ``C = A(p, p)`` out as ``cs_symperm`` does (rows
  unsorted), so in both cases :mod:`.sparsechol`'s up-looking factorisation and solves do ``cs_chol``'s,
  ``cs_lsolve``'s and ``cs_ltsolve``'s operations in their order: given the same A and B the step has the
  bits of CXSparse's ``cs_cholsol`` (checked solve by solve over the MIT CSAIL log against Debian's
  libcxsparse 3.2.0, the library sparse_bundle_adjustment links). In a real run nearly every optimization
  takes the AMD path (loop closures come after dozens of nodes).
- Eigen's 3 x 3 products: here every sum of three products runs left to right. Compiled Eigen 3.4 does
  not quite: a 3-row product's rows 0 and 1 come from its packet path, ``(a0 b0 + a1 b1) + a2 b2``, but
  row 2 from an unrolled sum ``a0 b0 + (a1 b1 + a2 b2)``, and a build for a CPU with FMA fuses those
  multiply-adds; so A, B and the costs may differ from the C++'s in their last bits, and near
  convergence a last-bit cost difference can turn a refusal the other way. Such differences are
  amplified: one ulp changed in the initial poses of MIT CSAIL's first loop closure moves the optimum
  by 1e-10 to 1e-6 m. ``|dx|^2`` is summed in order (Eigen pairs terms with SIMD); it is only compared
  with 1e-16.
- CSparse fails only on a pivot ``<= 0`` and goes on with a NaN pivot; :mod:`.sparsechol` also fails on
  NaN (then, as in step 5, the step is ``B``).

Reported costs follow :class:`.optimize.OptimizerResult`: ``1/2 sum e^T P e``, half of doSPA's (halving
is exact, so no comparison changes).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials.slam.karto.amd import amd_order, symmetric_permute
from slamtrials.slam.karto.optimize import OptimizerResult
from slamtrials.slam.karto.sparsechol import NotPositiveDefinite, cholesky, cholesky_solve

__all__ = ["optimize_spa", "MAX_ITERATIONS", "INITIAL_LAMBDA"]

MAX_ITERATIONS = 40  # slam_karto: m_Spa.doSPA(40)
INITIAL_LAMBDA = 1e-4  # doSPA's sLambda default
LAMBDA_DECREASE = 0.5  # lamdec
INITIAL_LAMBDA_INCREASE = 2.0  # laminc, doubled after every refusal
MIN_SQUARED_STEP = 1e-8 * 1e-8  # sqMinDelta
NATURAL_ORDER_MAX_UNKNOWNS = 100  # CSparse2d::doChol: natural order up to 100 unknowns, AMD beyond


@njit(cache=True, nogil=True)
def _errors(poses, source, target, means, prec, err):  # pragma: no cover - compiled
    """Every edge's error into ``err`` ``[E, 3]`` (Con2dP2::calcErr); returns ``sum e^T P e``."""
    cost = 0.0
    two_pi = 2.0 * math.pi
    for e in range(source.shape[0]):
        a = source[e]
        b = target[e]
        c = math.cos(poses[a, 2])
        s = math.sin(poses[a, 2])
        # node a's world-to-node transform [R^T | -R^T t_a] applied to t_b
        ox = -(c * poses[a, 0] + s * poses[a, 1])
        oy = -(-s * poses[a, 0] + c * poses[a, 1])
        ex = (c * poses[b, 0] + s * poses[b, 1]) + ox - means[e, 0]
        ey = (-s * poses[b, 0] + c * poses[b, 1]) + oy - means[e, 1]
        ea = (poses[b, 2] - poses[a, 2]) - means[e, 2]
        if ea > math.pi:
            ea -= two_pi
        if ea < -math.pi:
            ea += two_pi
        err[e, 0] = ex
        err[e, 1] = ey
        err[e, 2] = ea
        p = prec[e]
        v0 = p[0, 0] * ex + p[0, 1] * ey + p[0, 2] * ea
        v1 = p[1, 0] * ex + p[1, 1] * ey + p[1, 2] * ea
        v2 = p[2, 0] * ex + p[2, 1] * ey + p[2, 2] * ea
        cost += ex * v0 + ey * v1 + ea * v2
    return cost


@njit(cache=True, nogil=True)
def _product(left, right, out, transpose_left):  # pragma: no cover - compiled
    """``out = left^T right`` (or ``left right``) for 3 x 3 arrays, each entry summed left to right."""
    for i in range(3):
        for j in range(3):
            total = 0.0
            for k in range(3):
                if transpose_left:
                    total += left[k, i] * right[k, j]
                else:
                    total += left[i, k] * right[k, j]
            out[i, j] = total


@njit(cache=True, nogil=True)
def _assemble(poses, source, target, prec, err, edge_slot, n_free, n_slots):  # pragma: no cover - compiled
    """SysSPA2d::setupSparseSys without the damping: diagonal blocks ``[n_free, 3, 3]``, upper off-diagonal
    blocks ``[n_slots, 3, 3]`` (rows of the lower-numbered node) and ``B`` ``[3 n_free]``."""
    diag = np.zeros((n_free, 3, 3))
    off = np.zeros((n_slots, 3, 3))
    rhs = np.zeros(3 * n_free)
    j0 = np.zeros((3, 3))
    j1 = np.zeros((3, 3))
    j0p = np.zeros((3, 3))
    j1p = np.zeros((3, 3))
    tp = np.zeros((3, 3))
    block = np.zeros((3, 3))
    for e in range(source.shape[0]):
        a = source[e]
        b = target[e]
        c = math.cos(poses[a, 2])
        s = math.sin(poses[a, 2])
        dx = poses[b, 0] - poses[a, 0]
        dy = poses[b, 1] - poses[a, 1]
        j0[0, 0] = -c
        j0[0, 1] = -s
        j0[0, 2] = -s * dx + c * dy
        j0[1, 0] = s
        j0[1, 1] = -c
        j0[1, 2] = -c * dx + -s * dy
        j0[2, 0] = 0.0
        j0[2, 1] = 0.0
        j0[2, 2] = -1.0
        j1[0, 0] = c
        j1[0, 1] = s
        j1[0, 2] = 0.0
        j1[1, 0] = -s
        j1[1, 1] = c
        j1[1, 2] = 0.0
        j1[2, 0] = 0.0
        j1[2, 1] = 0.0
        j1[2, 2] = 1.0
        p = prec[e]
        i0 = a - 1  # negative for the fixed node
        i1 = b - 1
        if i0 >= 0:
            _product(j0, p, j0p, True)  # (J0^T P) J0
            _product(j0p, j0, block, False)
            for r in range(3):
                for k in range(3):
                    diag[i0, r, k] += block[r, k]
        if i1 >= 0:
            _product(p, j1, tp, False)  # J1^T (P J1)
            _product(j1, tp, block, True)
            for r in range(3):
                for k in range(3):
                    diag[i1, r, k] += block[r, k]
            if i0 >= 0:
                _product(j0, tp, block, True)  # J0^T (P J1): rows of a, columns of b
                slot = edge_slot[e]
                for r in range(3):
                    for k in range(3):
                        if i1 < i0:
                            off[slot, r, k] += block[k, r]
                        else:
                            off[slot, r, k] += block[r, k]
        if i0 >= 0:
            for r in range(3):
                rhs[3 * i0 + r] -= j0p[r, 0] * err[e, 0] + j0p[r, 1] * err[e, 1] + j0p[r, 2] * err[e, 2]
        if i1 >= 0:
            _product(j1, p, j1p, True)  # (J1^T P) e
            for r in range(3):
                rhs[3 * i1 + r] -= j1p[r, 0] * err[e, 0] + j1p[r, 1] * err[e, 1] + j1p[r, 2] * err[e, 2]
    return diag, off, rhs


@njit(cache=True, nogil=True)
def _pattern(n_free, block_ptr, block_rows):  # pragma: no cover - compiled
    """The compressed columns of A's upper triangle as CSparse2d::setupCSstructure lays them out: in column
    ``3 i + k`` the off-diagonal blocks' three rows each (lower block rows first), then rows ``3 i .. 3 i + k``."""
    n = 3 * n_free
    indptr = np.zeros(n + 1, dtype=np.int64)
    nnz = 6 * n_free + 9 * block_rows.shape[0]
    indices = np.empty(nnz, dtype=np.int64)
    q = 0
    for i in range(n_free):
        for k in range(3):
            indptr[3 * i + k] = q
            for t in range(block_ptr[i], block_ptr[i + 1]):
                for j in range(3):
                    indices[q] = 3 * block_rows[t] + j
                    q += 1
            for kk in range(k + 1):
                indices[q] = 3 * i + kk
                q += 1
    indptr[n] = q
    return indptr, indices


@njit(cache=True, nogil=True)
def _values(n_free, block_ptr, block_slots, diag, off, diaginc, data):  # pragma: no cover - compiled
    """Fill ``data`` in :func:`_pattern`'s layout, every diagonal entry multiplied by ``diaginc``."""
    q = 0
    for i in range(n_free):
        for k in range(3):
            for t in range(block_ptr[i], block_ptr[i + 1]):
                slot = block_slots[t]
                for j in range(3):
                    data[q] = off[slot, j, k]
                    q += 1
            for kk in range(k + 1):
                data[q] = diag[i, kk, k]
                q += 1
            data[q - 1] *= diaginc


@njit(cache=True, nogil=True)
def _squared_norm(v):  # pragma: no cover - compiled
    total = 0.0
    for i in range(v.shape[0]):
        total += v[i] * v[i]
    return total


@njit(cache=True, nogil=True)
def _update(poses, step):  # pragma: no cover - compiled
    """The free nodes moved by ``step`` ``[3 (N - 1)]``, angles into [-pi, pi] as Node2d::normArot does."""
    moved = poses.copy()
    two_pi = 2.0 * math.pi
    for k in range(1, poses.shape[0]):
        moved[k, 0] += step[3 * (k - 1)]
        moved[k, 1] += step[3 * (k - 1) + 1]
        angle = moved[k, 2] + step[3 * (k - 1) + 2]
        if angle > math.pi:
            angle -= two_pi
        if angle < -math.pi:
            angle += two_pi
        moved[k, 2] = angle
    return moved


class _System:
    """The block layout of A for one graph: which upper off-diagonal block each edge adds to, the
    compressed-column pattern and, beyond 100 unknowns, CSparse's AMD permutation and the permuted layout."""

    def __init__(self, n_free: int, source: NDArray[np.int64], target: NDArray[np.int64]):
        slots: dict[tuple[int, int], int] = {}
        edge_slot = np.full(source.shape[0], -1, dtype=np.int64)
        for e, (a, b) in enumerate(zip(source.tolist(), target.tolist())):
            if a > 0 and b > 0:
                edge_slot[e] = slots.setdefault((min(a, b) - 1, max(a, b) - 1), len(slots))
        columns: list[list[tuple[int, int]]] = [[] for _ in range(n_free)]
        for (row, column), slot in slots.items():
            columns[column].append((row, slot))
        block_ptr = np.zeros(n_free + 1, dtype=np.int64)
        rows: list[int] = []
        block_slots: list[int] = []
        for i, column_blocks in enumerate(columns):
            for row, slot in sorted(column_blocks):  # CSparse2d keeps a column's blocks in a std::map by row
                rows.append(row)
                block_slots.append(slot)
            block_ptr[i + 1] = len(rows)
        self.n_free = n_free
        self.n_slots = len(slots)
        self.edge_slot = edge_slot
        self.block_ptr = block_ptr
        self.block_slots = np.array(block_slots, dtype=np.int64)
        self.indptr, self.indices = _pattern(n_free, block_ptr, np.array(rows, dtype=np.int64))
        self.data = np.empty(self.indices.shape[0])
        self.order: NDArray[np.int64] | None = None
        if 3 * n_free > NATURAL_ORDER_MAX_UNKNOWNS:  # cs_schol(1, A): CSparse's AMD, then cs_symperm's layout
            self.order = amd_order(self.indptr, self.indices)
            pinv = np.empty_like(self.order)
            pinv[self.order] = np.arange(self.order.shape[0])
            self.perm_indptr, self.perm_indices, self.perm_source = symmetric_permute(self.indptr, self.indices, pinv)

    def solve(
        self, diag: NDArray[np.float64], off: NDArray[np.float64], rhs: NDArray[np.float64], lam: float
    ) -> NDArray[np.float64]:
        """``dx`` of ``A (1 + lam on the diagonal) dx = B``; ``B`` itself when the factorisation fails."""
        _values(self.n_free, self.block_ptr, self.block_slots, diag, off, 1.0 + lam, self.data)
        try:
            if self.order is None:
                factor = cholesky(self.indptr, self.indices, self.data)
                return cholesky_solve(factor, rhs)
            factor = cholesky(self.perm_indptr, self.perm_indices, self.data[self.perm_source])
            step = np.empty_like(rhs)
            step[self.order] = cholesky_solve(factor, rhs[self.order])
            return step
        except NotPositiveDefinite:  # cs_cholsol leaves B as it was, and doSPA steps by it
            return rhs.copy()


def optimize_spa(
    poses: NDArray[np.float64],
    source: NDArray[np.int64],
    target: NDArray[np.int64],
    means: NDArray[np.float64],
    weights: NDArray[np.float64],
    max_iterations: int = MAX_ITERATIONS,
) -> OptimizerResult:
    """Optimize the pose graph as sparse_bundle_adjustment's ``SysSPA2d::doSPA`` does (module docstring),
    node 0 held fixed.

    Parameters
    ----------
    poses:
        float64 ``[N, 3]`` initial poses (x, y in metres, theta in radians), in the order the nodes were
        added to the solver (node 0 is the fixed one).
    source, target:
        int ``[E]`` edge end nodes, in the order the constraints were added.
    means:
        float64 ``[E, 3]`` relative poses (target seen from source).
    weights:
        float64 ``[E, 3, 3]`` precision matrices (inverse covariances); only the upper triangle is read.
    max_iterations:
        Most steps tried (taken or refused); slam_karto's is 40.

    Returns
    -------
    OptimizerResult
        ``iterations`` counts the steps tried (doSPA's ``iter`` on leaving; the solve that meets the stop
        test is not a step); ``reason`` is ``"converged"`` (squared step below 1e-16), ``"maximum
        iterations"`` or ``"nothing to optimize"`` (fewer than two nodes or no edges).
    """
    x = np.array(poses, dtype=np.float64).reshape(-1, 3)
    n = x.shape[0]
    source = np.asarray(source, dtype=np.int64).reshape(-1)
    target = np.asarray(target, dtype=np.int64).reshape(-1)
    means = np.ascontiguousarray(means, dtype=np.float64).reshape(-1, 3)
    upper = np.triu(np.asarray(weights, dtype=np.float64).reshape(-1, 3, 3))
    prec = np.ascontiguousarray(upper + np.triu(upper, 1).transpose(0, 2, 1))
    n_edges = source.shape[0]
    if not (target.shape[0] == means.shape[0] == prec.shape[0] == n_edges):
        raise ValueError(
            f"edges disagree in number: {n_edges} sources, {target.shape[0]} targets, "
            f"{means.shape[0]} means, {prec.shape[0]} weights"
        )
    if n_edges and (min(source.min(), target.min()) < 0 or max(source.max(), target.max()) >= n):
        raise ValueError(f"an edge names a node outside 0..{n - 1}")
    if np.any(source == target):
        raise ValueError(f"edge {int(np.argmax(source == target))} joins a node to itself")
    err = np.empty((n_edges, 3))
    cost = _errors(x, source, target, means, prec, err)
    initial = cost
    if n < 2 or n_edges == 0:
        return OptimizerResult(x, 0, 0.5 * initial, 0.5 * cost, "nothing to optimize")
    system = _System(n - 1, source, target)
    lam = INITIAL_LAMBDA
    laminc = INITIAL_LAMBDA_INCREASE
    reason = "maximum iterations"
    iteration = 0
    linearized = False
    diag = off = rhs = np.empty(0)
    while iteration < max_iterations:
        if not linearized:
            diag, off, rhs = _assemble(x, source, target, prec, err, system.edge_slot, system.n_free, system.n_slots)
            linearized = True
        step = system.solve(diag, off, rhs, lam)
        if _squared_norm(step) < MIN_SQUARED_STEP:
            reason = "converged"
            break
        candidate = _update(x, step)
        candidate_err = np.empty_like(err)
        new_cost = _errors(candidate, source, target, means, prec, candidate_err)
        if new_cost < cost:
            x, err, cost = candidate, candidate_err, new_cost
            lam *= LAMBDA_DECREASE
            linearized = False
        else:  # the nodes stay where they were; only the damping changes
            lam *= laminc
            laminc *= 2.0
        iteration += 1
    return OptimizerResult(x, iteration, 0.5 * initial, 0.5 * cost, reason)
