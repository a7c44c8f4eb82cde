"""CSparse's approximate minimum degree ordering, for slam_karto's SPA solves beyond 100 unknowns.

sparse_bundle_adjustment's ``CSparse2d::doChol`` solves its normal equations with CSparse's
``cs_cholsol(1, A, b)`` once A has more than 100 rows (the library it links is SuiteSparse's CXSparse,
``cs_di_*``, whose ordering is CSparse's). ``cs_cholsol`` orders A by ``cs_schol``: ``cs_amd(1, A)``,
the approximate minimum degree ordering of the pattern of ``A + A^T`` (Amestoy, Davis and Duff's AMD as
Davis writes it in CSparse, ``CSparse/Source/cs_amd.c``; T. A. Davis, *Direct Methods for Sparse Linear
Systems*, SIAM 2006, section 7.1), then factors ``C = A(p, p)`` laid out by ``cs_symperm``. Every
floating-point operation of the factorisation and of the solves follows from that permutation and
layout, so to do the C++'s arithmetic in its order both have to be CSparse's exactly, ties and all.

:func:`amd_order` is that ordering: the same steps on the same data structures, so the same permutation
for every input (not merely *an* AMD ordering):

1. ``C = A + A^T`` as ``cs_transpose`` then ``cs_add`` build it (each column: A's entries in A's order,
   then A^T's new ones by ascending row), its diagonal dropped (``cs_fkeep``), with ``cnz / 5 + 2 n``
   slots of elbow room.
2. The quotient graph: degree lists (a node enters at the head of its list), rows denser than
   ``min(n - 2, max(16, 10 sqrt n))`` (truncated) set aside into a placeholder element ``n``, empty
   rows eliminated at once.
3. Pivot loop: the head of the lowest non-empty degree list; garbage collection when the workspace
   runs short; the new element Lk built from the pivot's elements (absorbed) and nodes; the set
   differences |Le \\ Lk| by the ``w`` marks; the approximate degree update with aggressive absorption
   of elements covered by Lk and mass elimination; supervariable detection by the hash (the sum of a
   node's elements and nodes, modulo n) and a list comparison within each bucket; each node of Lk put
   back at the head of its degree list, degree capped by the nodes left.
4. The assembly tree postordered by ``cs_tdfs`` (children listed by ascending index, roots in index
   order, placeholder ``n`` last), giving the permutation.

The workspace marks are 64-bit here where CXSparse's ``cs_di`` has ``int``; they only overflow (and are
reset, ``cs_wclear``) for matrices far larger than a pose graph, so the orderings agree.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

__all__ = ["amd_order", "symmetric_permute"]


@njit(cache=True, nogil=True)
def _flip(i):  # pragma: no cover - compiled
    """CS_FLIP: -2 - i, a reversible mark of an index (flip(flip(i)) == i, flip(-1) == -1)."""
    return -i - 2


@njit(cache=True, nogil=True)
def _clear_marks(mark, lemax, w, n):  # pragma: no cover - compiled
    """cs_wclear: reset the live marks of ``w`` to 1 when ``mark`` is about to overflow; returns the mark."""
    if mark < 2 or mark + lemax < 0:
        for k in range(n):
            if w[k] != 0:
                w[k] = 1
        mark = 2
    return mark


@njit(cache=True, nogil=True)
def _scatter_new_rows(rows, start, stop, mark, seen, out, nz):  # pragma: no cover - compiled
    """cs_scatter's pattern part: append ``rows[start:stop]`` not yet marked with ``mark`` in ``seen`` to
    ``out[nz:]``, marking them; returns the new ``nz``."""
    for p in range(start, stop):
        i = rows[p]
        if seen[i] < mark:
            seen[i] = mark
            out[nz] = i
            nz += 1
    return nz


@njit(cache=True, nogil=True)
def _symmetric_pattern(n, ap, ai):  # pragma: no cover - compiled
    """Pattern of ``A + A^T`` without its diagonal, built as cs_transpose, cs_add and cs_fkeep order it."""
    nnz = ap[n]
    # A^T by a counting sort over A's columns: each column of A^T lists its rows ascending
    counts = np.zeros(n, dtype=np.int64)
    for p in range(nnz):
        counts[ai[p]] += 1
    tp = np.zeros(n + 1, dtype=np.int64)
    for i in range(n):
        tp[i + 1] = tp[i] + counts[i]
    slot = tp[:n].copy()
    ti = np.empty(nnz, dtype=np.int64)
    for j in range(n):
        for p in range(ap[j], ap[j + 1]):
            q = slot[ai[p]]
            slot[ai[p]] += 1
            ti[q] = j
    # column j of the sum: A's rows in A's order, then A^T's rows not seen yet (cs_scatter twice)
    cp = np.zeros(n + 1, dtype=np.int64)
    ci = np.empty(2 * nnz, dtype=np.int64)
    seen = np.zeros(n, dtype=np.int64)
    nz = 0
    for j in range(n):
        cp[j] = nz
        nz = _scatter_new_rows(ai, ap[j], ap[j + 1], j + 1, seen, ci, nz)
        nz = _scatter_new_rows(ti, tp[j], tp[j + 1], j + 1, seen, ci, nz)
    cp[n] = nz
    # drop the diagonal, keeping the order
    nz = 0
    for j in range(n):
        p = cp[j]
        cp[j] = nz
        for q in range(p, cp[j + 1]):
            if ci[q] != j:
                ci[nz] = ci[q]
                nz += 1
    cp[n] = nz
    return cp, ci


@njit(cache=True, nogil=True)
def _tree_dfs(j, k, head, next_, post, stack):  # pragma: no cover - compiled
    """cs_tdfs: postorder the subtree rooted at ``j`` (children taken from ``head``/``next_`` lists) into
    ``post[k:]``; returns the next free position."""
    top = 0
    stack[0] = j
    while top >= 0:
        p = stack[top]
        i = head[p]
        if i == -1:
            top -= 1
            post[k] = p
            k += 1
        else:
            head[p] = next_[i]
            top += 1
            stack[top] = i
    return k


@njit(cache=True, nogil=True)
def _amd(n, ap, ai):  # pragma: no cover - compiled
    """cs_amd(1, A) on A's pattern (compressed columns ``ap`` [n + 1], ``ai``); returns int64 ``[n]``."""
    cp_sym, ci_sym = _symmetric_pattern(n, ap, ai)
    cnz = cp_sym[n]
    nzmax = cnz + cnz // 5 + 2 * n  # elbow room
    cp = cp_sym.copy()  # Cp: object pointers, later parents in the assembly tree (flipped)
    ci = np.zeros(max(nzmax, 1), dtype=np.int64)
    ci[:cnz] = ci_sym[:cnz]
    dense = int(max(16.0, 10.0 * math.sqrt(float(n))))
    dense = min(n - 2, dense)
    length = np.empty(n + 1, dtype=np.int64)  # len: size of each object's list in ci
    nv = np.empty(n + 1, dtype=np.int64)  # nodes a supervariable stands for (negated while in Lk)
    next_ = np.empty(n + 1, dtype=np.int64)
    last = np.empty(n + 1, dtype=np.int64)  # previous in a degree list, or a node's hash
    head = np.empty(n + 1, dtype=np.int64)  # degree lists
    elen = np.empty(n + 1, dtype=np.int64)  # elements in a node's list (-2: an element, -1: dead)
    degree = np.empty(n + 1, dtype=np.int64)
    w = np.empty(n + 1, dtype=np.int64)
    hhead = np.empty(n + 1, dtype=np.int64)  # hash buckets
    perm = np.empty(n + 1, dtype=np.int64)
    for k in range(n):
        length[k] = cp[k + 1] - cp[k]
    length[n] = 0
    for i in range(n + 1):
        head[i] = -1
        last[i] = -1
        next_[i] = -1
        hhead[i] = -1
        nv[i] = 1
        w[i] = 1
        elen[i] = 0
        degree[i] = length[i]
    mark = _clear_marks(0, 0, w, n)
    elen[n] = -2  # the placeholder n is a dead element, the root for dense rows
    cp[n] = -1
    w[n] = 0
    nel = 0
    for i in range(n):
        d = degree[i]
        if d == 0:  # an empty row is eliminated at once
            elen[i] = -2
            nel += 1
            cp[i] = -1
            w[i] = 0
        elif d > dense:  # a dense row goes to the placeholder
            nv[i] = 0
            elen[i] = -1
            nel += 1
            cp[i] = _flip(n)
            nv[n] += 1
        else:
            if head[d] != -1:
                last[head[d]] = i
            next_[i] = head[d]
            head[d] = i
    mindeg = 0
    lemax = 0
    while nel < n:
        # pivot: the head of the lowest non-empty degree list
        k = -1
        while mindeg < n:
            k = head[mindeg]
            if k != -1:
                break
            mindeg += 1
        if next_[k] != -1:
            last[next_[k]] = -1
        head[mindeg] = next_[k]
        elenk = elen[k]
        nvk = nv[k]
        nel += nvk
        # garbage collection: compact the live objects' lists to the front of ci
        if elenk > 0 and cnz + mindeg >= nzmax:
            for j in range(n):
                p = cp[j]
                if p >= 0:
                    cp[j] = ci[p]
                    ci[p] = _flip(j)
            q = 0
            p = 0
            while p < cnz:
                j = _flip(ci[p])
                p += 1
                if j >= 0:
                    ci[q] = cp[j]
                    cp[j] = q
                    q += 1
                    for _ in range(length[j] - 1):
                        ci[q] = ci[p]
                        q += 1
                        p += 1
            cnz = q
        # the new element Lk: the live nodes of k's elements and of k's own list
        dk = 0
        nv[k] = -nvk
        p = cp[k]
        pk1 = p if elenk == 0 else cnz  # built in place when k has no elements
        pk2 = pk1
        for k1 in range(1, elenk + 2):
            if k1 > elenk:
                e = k
                pj = p
                ln = length[k] - elenk
            else:
                e = ci[p]
                p += 1
                pj = cp[e]
                ln = length[e]
            for _ in range(ln):
                i = ci[pj]
                pj += 1
                nvi = nv[i]
                if nvi <= 0:  # dead, or already in Lk
                    continue
                dk += nvi
                nv[i] = -nvi
                ci[pk2] = i
                pk2 += 1
                if next_[i] != -1:  # out of its degree list
                    last[next_[i]] = last[i]
                if last[i] != -1:
                    next_[last[i]] = next_[i]
                else:
                    head[degree[i]] = next_[i]
            if e != k:  # element e is absorbed into k
                cp[e] = _flip(k)
                w[e] = 0
        if elenk != 0:
            cnz = pk2
        degree[k] = dk
        cp[k] = pk1
        length[k] = pk2 - pk1
        elen[k] = -2
        # set differences |Le \ Lk| for the elements next to Lk's nodes, kept as w[e] - mark
        mark = _clear_marks(mark, lemax, w, n)
        for pk in range(pk1, pk2):
            i = ci[pk]
            eln = elen[i]
            if eln <= 0:
                continue
            nvi = -nv[i]
            wnvi = mark - nvi
            for p in range(cp[i], cp[i] + eln):
                e = ci[p]
                if w[e] >= mark:
                    w[e] -= nvi
                elif w[e] != 0:  # a live element, first seen
                    w[e] = degree[e] + wnvi
        # approximate degrees of Lk's nodes; their lists pruned; hashes
        for pk in range(pk1, pk2):
            i = ci[pk]
            p1 = cp[i]
            p2 = p1 + elen[i] - 1
            pn = p1
            h = 0
            d = 0
            for p in range(p1, p2 + 1):
                e = ci[p]
                if w[e] != 0:
                    dext = w[e] - mark
                    if dext > 0:
                        d += dext
                        ci[pn] = e
                        pn += 1
                        h += e
                    else:  # aggressive absorption: Le is inside Lk
                        cp[e] = _flip(k)
                        w[e] = 0
            elen[i] = pn - p1 + 1
            p3 = pn
            p4 = p1 + length[i]
            for p in range(p2 + 1, p4):
                j = ci[p]
                nvj = nv[j]
                if nvj <= 0:
                    continue
                d += nvj
                ci[pn] = j
                pn += 1
                h += j
            if d == 0:  # mass elimination: i is eliminated with k
                cp[i] = _flip(k)
                nvi = -nv[i]
                dk -= nvi
                nvk += nvi
                nel += nvi
                nv[i] = 0
                elen[i] = -1
            else:
                degree[i] = min(degree[i], d)
                ci[pn] = ci[p3]  # k becomes i's first element
                ci[p3] = ci[p1]
                ci[p1] = k
                length[i] = pn - p1 + 1
                h = (-h if h < 0 else h) % n
                next_[i] = hhead[h]
                hhead[h] = i
                last[i] = h
        degree[k] = dk
        lemax = max(lemax, dk)
        mark = _clear_marks(mark + lemax, lemax, w, n)
        # supervariables: nodes of one hash bucket with identical lists merge into the first
        for pk in range(pk1, pk2):
            i = ci[pk]
            if nv[i] >= 0:
                continue
            h = last[i]
            i = hhead[h]
            hhead[h] = -1
            while i != -1 and next_[i] != -1:
                ln = length[i]
                eln = elen[i]
                for p in range(cp[i] + 1, cp[i] + ln):
                    w[ci[p]] = mark
                jlast = i
                j = next_[i]
                while j != -1:
                    ok = length[j] == ln and elen[j] == eln
                    p = cp[j] + 1
                    while ok and p <= cp[j] + ln - 1:
                        if w[ci[p]] != mark:
                            ok = False
                        p += 1
                    if ok:  # j is absorbed into i
                        cp[j] = _flip(i)
                        nv[i] += nv[j]
                        nv[j] = 0
                        elen[j] = -1
                        j = next_[j]
                        next_[jlast] = j
                    else:
                        jlast = j
                        j = next_[j]
                i = next_[i]
                mark += 1
        # Lk's surviving nodes back into the degree lists, with their external degrees
        p = pk1
        for pk in range(pk1, pk2):
            i = ci[pk]
            nvi = -nv[i]
            if nvi <= 0:
                continue
            nv[i] = nvi
            d = degree[i] + dk - nvi
            d = min(d, n - nel - nvi)
            if head[d] != -1:
                last[head[d]] = i
            next_[i] = head[d]
            last[i] = -1
            head[d] = i
            mindeg = min(mindeg, d)
            degree[i] = d
            ci[p] = i
            p += 1
        nv[k] = nvk
        length[k] = p - pk1
        if length[k] == 0:  # k is a root of the assembly tree
            cp[k] = -1
            w[k] = 0
        if elenk != 0:
            cnz = p
    # postorder the assembly tree
    for i in range(n):
        cp[i] = _flip(cp[i])
    for j in range(n + 1):
        head[j] = -1
    for j in range(n, -1, -1):  # absorbed nodes under their parents
        if nv[j] > 0:
            continue
        next_[j] = head[cp[j]]
        head[cp[j]] = j
    for e in range(n, -1, -1):  # elements under their parents
        if nv[e] <= 0:
            continue
        if cp[e] != -1:
            next_[e] = head[cp[e]]
            head[cp[e]] = e
    k = 0
    for i in range(n + 1):
        if cp[i] == -1:
            k = _tree_dfs(i, k, head, next_, perm, w)
    return perm[:n].copy()


def amd_order(indptr: NDArray[np.int64], indices: NDArray[np.int64], n: int | None = None) -> NDArray[np.int64]:
    """CSparse's ``cs_amd(1, A)``: the approximate minimum degree ordering of ``A + A^T`` (module docstring).

    Parameters
    ----------
    indptr, indices:
        int ``[n + 1]`` and ``[nnz]``: the pattern of the square matrix A in compressed columns, entries in
        the order they are stored (the order matters for ties, as in CSparse); A may hold one triangle or
        both, the diagonal or not.
    n:
        A's size; ``len(indptr) - 1`` by default.

    Returns
    -------
    NDArray[np.int64]
        ``[n]``: the permutation ``p`` (row/column ``k`` of ``A(p, p)`` is ``p[k]`` of A), as ``cs_amd``
        returns it.
    """
    ap = np.ascontiguousarray(indptr, dtype=np.int64)
    ai = np.ascontiguousarray(indices, dtype=np.int64)
    size = ap.shape[0] - 1 if n is None else int(n)
    if size <= 0:
        return np.empty(0, dtype=np.int64)
    return _amd(size, ap, ai)


@njit(cache=True, nogil=True)
def _symperm(indptr, indices, pinv):  # pragma: no cover - compiled
    n = indptr.shape[0] - 1
    counts = np.zeros(n, dtype=np.int64)
    for j in range(n):
        for p in range(indptr[j], indptr[j + 1]):
            i = indices[p]
            if i > j:
                continue
            counts[max(pinv[i], pinv[j])] += 1
    new_ptr = np.zeros(n + 1, dtype=np.int64)
    for j in range(n):
        new_ptr[j + 1] = new_ptr[j] + counts[j]
    fill = new_ptr[:n].copy()
    rows = np.empty(new_ptr[n], dtype=np.int64)
    source = np.empty(new_ptr[n], dtype=np.int64)
    for j in range(n):
        for p in range(indptr[j], indptr[j + 1]):
            i = indices[p]
            if i > j:
                continue
            a = pinv[i]
            b = pinv[j]
            q = fill[max(a, b)]
            fill[max(a, b)] += 1
            rows[q] = min(a, b)
            source[q] = p
    return new_ptr, rows, source


def symmetric_permute(
    indptr: NDArray[np.int64], indices: NDArray[np.int64], pinv: NDArray[np.int64]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """The upper triangle of ``P A P^T`` laid out as CSparse's ``cs_symperm`` lays it out.

    Entries of A below the diagonal are skipped; entry ``(i, j)`` goes to column ``max(pinv[i], pinv[j])``
    at row ``min(...)``, columns filled in the order A's columns and entries are read (rows NOT sorted:
    ``cs_chol`` finds each row's pattern in this order, which sets the order of its updates).

    Parameters
    ----------
    indptr, indices:
        int ``[n + 1]``, ``[nnz]``: A in compressed columns.
    pinv:
        int ``[n]``: the inverse permutation (``pinv[old] = new``).

    Returns
    -------
    tuple
        ``indptr`` ``[n + 1]``, ``indices`` ``[nnz']`` of the permuted matrix, and for each of its entries
        the position ``[nnz']`` of its value in A's data.
    """
    return _symperm(
        np.ascontiguousarray(indptr, dtype=np.int64),
        np.ascontiguousarray(indices, dtype=np.int64),
        np.ascontiguousarray(pinv, dtype=np.int64),
    )
