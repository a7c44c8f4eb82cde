"""A sparse Cholesky factorisation in numba, for the optimizer's normal equations.

Why not scipy's ``spsolve`` / ``splu``: scipy builds SuperLU with ``USE_VENDOR_BLAS``, so its
supernodal updates call the BLAS (``dgemv``, ``dtrsv``), whose kernels OpenBLAS picks by CPU; the
poses that come out could then differ in the last bits between machines, and a trial is chaotic (a
pose that moves a last bit changes the map, the explorer's path and everything after). The
factorisation here is the textbook up-looking sparse Cholesky (elimination tree, row patterns by
``ereach``, one scalar update at a time, as in Davis' CSparse ``cs_chol``), in plain loops: the same
operations in the same order on every machine; with its triangular solves (``cs_lsolve``,
``cs_ltsolve``) it does CSparse's operations in CSparse's order for a matrix laid out the same way.
The fill-reducing ordering is the caller's: :func:`minimum_degree_order` (a minimum-degree ordering
of the pose graph's nodes, ties to the lowest index, each node's three unknowns kept together) for
:mod:`.optimize`; CSparse's own AMD (:func:`.amd.amd_order`) with ``cs_symperm``'s layout for
slam_karto's SPA (:mod:`.spa`), as ``cs_cholsol`` orders beyond 100 unknowns.

Matrices are in compressed-column form holding the UPPER triangle (row <= column) of the symmetric
matrix, as ``(indptr, indices, data)``.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence

import numpy as np
from numba import njit
from numpy.typing import NDArray

__all__ = ["minimum_degree_order", "cholesky", "cholesky_solve", "NotPositiveDefinite"]


class NotPositiveDefinite(ArithmeticError):
    """The matrix has a non-positive pivot (it is singular or indefinite)."""


def minimum_degree_order(n: int, pairs: Sequence[tuple[int, int]]) -> NDArray[np.intp]:
    """A minimum-degree elimination order of the graph of ``n`` vertices and edges ``pairs``.

    The vertex of least degree in the current elimination graph goes next (the lowest index among equal
    degrees); eliminating it joins its neighbours into a clique. Returns int ``[n]``: the order.
    """
    adjacency: list[set[int]] = [set() for _ in range(n)]
    for a, b in pairs:
        if a != b:
            adjacency[a].add(b)
            adjacency[b].add(a)
    heap = [(len(adjacency[v]), v) for v in range(n)]
    heapq.heapify(heap)
    done = [False] * n
    order: list[int] = []
    while heap:
        degree, v = heapq.heappop(heap)
        if done[v] or degree != len(adjacency[v]):
            continue
        done[v] = True
        order.append(v)
        neighbours = sorted(adjacency[v])
        for u in neighbours:
            adjacency[u].discard(v)
        for u in neighbours:
            adjacency[u].update(w for w in neighbours if w != u)
            heapq.heappush(heap, (len(adjacency[u]), u))
        adjacency[v] = set()
    return np.array(order, dtype=np.intp)


@njit(cache=True, nogil=True)
def _etree(n, indptr, indices):  # pragma: no cover - compiled
    parent = np.full(n, -1, dtype=np.int64)
    ancestor = np.full(n, -1, dtype=np.int64)
    for k in range(n):
        for p in range(indptr[k], indptr[k + 1]):
            i = indices[p]
            while i != -1 and i < k:
                following = ancestor[i]
                ancestor[i] = k
                if following == -1:
                    parent[i] = k
                i = following
    return parent


@njit(cache=True, nogil=True)
def _ereach(indptr, indices, k, parent, stack, mark):  # pragma: no cover - compiled
    """Row ``k``'s pattern of L (columns < k), topologically ordered, in ``stack[top:]``; returns top."""
    n = parent.shape[0]
    top = n
    mark[k] = k
    for p in range(indptr[k], indptr[k + 1]):
        i = indices[p]
        if i > k:
            continue
        length = 0
        while mark[i] != k:
            stack[length] = i
            length += 1
            mark[i] = k
            i = parent[i]
        while length > 0:
            top -= 1
            length -= 1
            stack[top] = stack[length]
    return top


@njit(cache=True, nogil=True)
def _cholesky(n, indptr, indices, data):  # pragma: no cover - compiled
    parent = _etree(n, indptr, indices)
    stack = np.empty(n, dtype=np.int64)
    mark = np.full(n, -1, dtype=np.int64)
    counts = np.ones(n, dtype=np.int64)
    for k in range(n):
        top = _ereach(indptr, indices, k, parent, stack, mark)
        for t in range(top, n):
            counts[stack[t]] += 1
    lp = np.zeros(n + 1, dtype=np.int64)
    for k in range(n):
        lp[k + 1] = lp[k] + counts[k]
    li = np.empty(lp[n], dtype=np.int64)
    lx = np.empty(lp[n], dtype=np.float64)
    fill = lp[:n].copy()
    x = np.zeros(n)
    mark[:] = -1
    for k in range(n):
        top = _ereach(indptr, indices, k, parent, stack, mark)
        x[k] = 0.0
        for p in range(indptr[k], indptr[k + 1]):
            if indices[p] <= k:
                x[indices[p]] += data[p]
        d = x[k]
        x[k] = 0.0
        for t in range(top, n):
            i = stack[t]
            lki = x[i] / lx[lp[i]]
            x[i] = 0.0
            for p in range(lp[i] + 1, fill[i]):
                x[li[p]] -= lx[p] * lki
            d -= lki * lki
            p = fill[i]
            fill[i] += 1
            li[p] = k
            lx[p] = lki
        if not d > 0.0:
            return lp, li, lx, False
        p = fill[k]
        fill[k] += 1
        li[p] = k
        lx[p] = math.sqrt(d)
    return lp, li, lx, True


@njit(cache=True, nogil=True)
def _solve(lp, li, lx, b):  # pragma: no cover - compiled
    n = lp.shape[0] - 1
    x = b.copy()
    for j in range(n):  # L y = b; column j of L holds L(j, j) first, then rows below
        x[j] /= lx[lp[j]]
        for p in range(lp[j] + 1, lp[j + 1]):
            x[li[p]] -= lx[p] * x[j]
    for j in range(n - 1, -1, -1):  # L^T x = y
        for p in range(lp[j] + 1, lp[j + 1]):
            x[j] -= lx[p] * x[li[p]]
        x[j] /= lx[lp[j]]
    return x


def cholesky(
    indptr: NDArray[np.int64], indices: NDArray[np.int64], data: NDArray[np.float64]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """Factor ``A = L L^T`` from A's upper triangle in compressed columns; return L's compressed columns
    (diagonal first in each column).

    Raises
    ------
    NotPositiveDefinite
        A pivot is not positive.
    """
    n = indptr.shape[0] - 1
    lp, li, lx, ok = _cholesky(
        n, np.asarray(indptr, dtype=np.int64), np.asarray(indices, dtype=np.int64), np.asarray(data, dtype=np.float64)
    )
    if not ok:
        raise NotPositiveDefinite("the matrix is not positive definite")
    return lp, li, lx


def cholesky_solve(
    factor: tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]], b: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Solve ``L L^T x = b`` with a factor of :func:`cholesky`."""
    lp, li, lx = factor
    return _solve(lp, li, lx, np.asarray(b, dtype=np.float64))
