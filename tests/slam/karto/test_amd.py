"""CSparse's AMD ordering (amd.py) and SPA's solves beyond 100 unknowns, against CSparse itself.

The fixed expectations were produced by CXSparse 3.2.0 (SuiteSparse 5.12, Debian bookworm's
libcxsparse3, the library sparse_bundle_adjustment links): ``cs_di_amd(1, A)``. Where the system has
that library the tests also call it through ctypes and require the same permutations and the same
solution bits; elsewhere those comparisons are skipped.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import math

import numpy as np
import pytest
import scipy.sparse

from slamtrials.geometry import ominus
from slamtrials.slam.karto import spa
from slamtrials.slam.karto.amd import amd_order, symmetric_permute
from slamtrials.slam.karto.optimize import information


class _Cs(ctypes.Structure):
    """CXSparse's ``cs_di``: a compressed-column matrix with int indices."""

    _fields_ = [
        ("nzmax", ctypes.c_int),
        ("m", ctypes.c_int),
        ("n", ctypes.c_int),
        ("p", ctypes.POINTER(ctypes.c_int)),
        ("i", ctypes.POINTER(ctypes.c_int)),
        ("x", ctypes.POINTER(ctypes.c_double)),
        ("nz", ctypes.c_int),
    ]


def _load_cxsparse():
    for name in (ctypes.util.find_library("cxsparse"), "libcxsparse.so.4", "libcxsparse.so.3"):
        if not name:
            continue
        try:
            lib = ctypes.CDLL(name)
        except OSError:
            continue
        lib.cs_di_amd.restype = ctypes.POINTER(ctypes.c_int)
        lib.cs_di_amd.argtypes = [ctypes.c_int, ctypes.POINTER(_Cs)]
        lib.cs_di_cholsol.restype = ctypes.c_int
        lib.cs_di_cholsol.argtypes = [ctypes.c_int, ctypes.POINTER(_Cs), ctypes.POINTER(ctypes.c_double)]
        lib.cs_di_free.restype = ctypes.c_void_p
        lib.cs_di_free.argtypes = [ctypes.c_void_p]
        return lib
    return None


CXSPARSE = _load_cxsparse()
needs_cxsparse = pytest.mark.skipif(CXSPARSE is None, reason="CXSparse (libcxsparse) is not installed")


def _cs(indptr, indices, data=None):
    p = np.ascontiguousarray(indptr, dtype=np.int32)
    i = np.ascontiguousarray(indices, dtype=np.int32)
    x = None if data is None else np.ascontiguousarray(data, dtype=np.float64)
    matrix = _Cs(
        i.shape[0],
        p.shape[0] - 1,
        p.shape[0] - 1,
        p.ctypes.data_as(ctypes.POINTER(ctypes.c_int)),
        i.ctypes.data_as(ctypes.POINTER(ctypes.c_int)),
        None if x is None else x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
        -1,
    )
    return matrix, (p, i, x)  # the arrays must outlive the call


def _csparse_amd(indptr, indices) -> list[int]:
    matrix, _keep = _cs(indptr, indices)
    result = CXSPARSE.cs_di_amd(1, ctypes.byref(matrix))
    order = [result[k] for k in range(len(indptr) - 1)]
    CXSPARSE.cs_di_free(ctypes.cast(result, ctypes.c_void_p))
    return order


def _csparse_cholsol(order, indptr, indices, data, b):
    matrix, _keep = _cs(indptr, indices, data)
    x = np.array(b, dtype=np.float64)
    ok = CXSPARSE.cs_di_cholsol(order, ctypes.byref(matrix), x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)))
    return x, bool(ok)


def _upper_pattern(n: int, pairs: list[tuple[int, int]]) -> scipy.sparse.csc_matrix:
    rows = list(range(n)) + [min(a, b) for a, b in pairs]
    cols = list(range(n)) + [max(a, b) for a, b in pairs]
    matrix = scipy.sparse.csc_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    matrix.sort_indices()
    return matrix


SMALL = {
    # a path: both ends have degree 1 and the list's head is the last one entered (9); each pivot leaves
    # its neighbour at degree 1 at the head again; 0 is mass-eliminated with 1 and postordered before it
    "path": (10, [(i, i + 1) for i in range(9)], [9, 8, 7, 6, 5, 4, 3, 2, 0, 1]),
    # a star of 5: the centre's degree 4 exceeds the dense threshold min(n - 2, 16) = 3, so it is set
    # aside and comes last; each leaf is then a root of its own, postordered by index
    "star5": (5, [(0, i) for i in range(1, 5)], [1, 2, 3, 4, 0]),
    # a star of 20 (threshold 16: the centre of degree 19 is dense too)
    "star20": (20, [(0, i) for i in range(1, 20)], list(range(1, 20)) + [0]),
    "grid3x3": (
        9,
        [(r * 3 + c, r * 3 + c + 1) for r in range(3) for c in range(2)]
        + [(r * 3 + c, (r + 1) * 3 + c) for r in range(2) for c in range(3)],
        [2, 0, 6, 3, 8, 1, 5, 7, 4],
    ),
    "cycle8": (8, [(i, (i + 1) % 8) for i in range(8)], [7, 6, 5, 4, 3, 0, 1, 2]),
}


@pytest.mark.parametrize("name", sorted(SMALL))
def test_small_orderings_are_csparses(name):
    n, pairs, expected = SMALL[name]
    pattern = _upper_pattern(n, pairs)
    assert amd_order(pattern.indptr, pattern.indices).tolist() == expected


def test_ordering_depends_on_the_stored_order_of_entries_as_csparses_does():
    # the same pattern with column 3's rows stored in reverse order changes which node enters the degree
    # lists' heads through A + A^T's layout; amd_order reads entries in stored order, as cs_amd does
    n, pairs, _ = SMALL["grid3x3"]
    pattern = _upper_pattern(n, pairs)
    indices = pattern.indices.copy()
    for j in range(n):
        indices[pattern.indptr[j] : pattern.indptr[j + 1]] = indices[pattern.indptr[j] : pattern.indptr[j + 1]][::-1]
    order = amd_order(pattern.indptr, indices)
    assert sorted(order.tolist()) == list(range(n))
    if CXSPARSE is not None:
        assert order.tolist() == _csparse_amd(pattern.indptr, indices)


@needs_cxsparse
def test_orderings_equal_cxsparses_on_random_patterns():
    rng = np.random.default_rng(0)
    for trial in range(150):
        n = int(rng.integers(1, 300))
        density = float(rng.choice([0.003, 0.02, 0.1, 0.5]))
        a = scipy.sparse.random(n, n, density=density, random_state=rng, format="csc")
        a = [scipy.sparse.triu(a + scipy.sparse.identity(n)), a + a.T + scipy.sparse.identity(n), a][trial % 3].tocsc()
        indices = a.indices.copy()
        for j in range(n):  # stored order within columns shuffled
            segment = indices[a.indptr[j] : a.indptr[j + 1]]
            rng.shuffle(segment)
            indices[a.indptr[j] : a.indptr[j + 1]] = segment
        assert amd_order(a.indptr, indices).tolist() == _csparse_amd(a.indptr, indices), trial


def test_symmetric_permute_lays_columns_out_in_reading_order():
    # upper triangle of a 3 x 3 full matrix, columns (0), (0 1), (0 1 2); p = [2, 0, 1], pinv = [1, 2, 0]
    indptr = np.array([0, 1, 3, 6])
    indices = np.array([0, 0, 1, 0, 1, 2])
    pinv = np.array([1, 2, 0])
    new_ptr, rows, source = symmetric_permute(indptr, indices, pinv)
    # entries read column by column: (0,0)->(1,1), (0,1)->(1,2), (1,1)->(2,2), (0,2)->(0,1), (1,2)->(0,2),
    # (2,2)->(0,0); each lands at the end of its new column so far, rows unsorted (column 1: rows 1, 0)
    assert new_ptr.tolist() == [0, 1, 3, 6]
    assert rows.tolist() == [0, 1, 0, 1, 2, 0]
    assert source.tolist() == [5, 0, 3, 1, 2, 4]


def _pose_graph(n: int, seed: int):
    """A square-ish loop of ``n`` poses with odometry edges, chords and the closing edge (some backwards)."""
    rng = np.random.default_rng(seed)
    angles = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    truth = np.stack(
        [10 * np.cos(angles), 10 * np.sin(angles), (angles + math.pi / 2 + math.pi) % (2 * math.pi) - math.pi], 1
    )
    pairs = [(k, k + 1) for k in range(n - 1)] + [(n - 1, 0)]
    pairs += [(k + 9, k) if k % 2 else (k, k + 9) for k in range(0, n - 10, 6)]
    source = np.array([a for a, _ in pairs])
    target = np.array([b for _, b in pairs])
    means = ominus(truth[source], truth[target]) + rng.normal(0.0, [0.02, 0.02, 0.005], (len(pairs), 3))
    weights = np.repeat(information(np.diag([0.01, 0.02, 0.003]))[None], len(pairs), axis=0)
    start = truth + np.vstack([np.zeros((1, 3)), rng.normal(0.0, [0.2, 0.2, 0.03], (n - 1, 3))])
    return start, source, target, means, weights


@needs_cxsparse
@pytest.mark.parametrize("n", [20, 120])  # 57 unknowns: natural order; 357: AMD
def test_spa_steps_are_cs_cholsols_to_the_bit(n):
    poses, source, target, means, weights = _pose_graph(n, seed=n)
    upper = np.triu(weights)
    prec = np.ascontiguousarray(upper + np.triu(upper, 1).transpose(0, 2, 1))
    err = np.empty((source.shape[0], 3))
    spa._errors(poses, source, target, means, prec, err)
    system = spa._System(n - 1, source, target)
    diag, off, rhs = spa._assemble(poses, source, target, prec, err, system.edge_slot, system.n_free, system.n_slots)
    for lam in (1e-4, 3e-7):
        step = system.solve(diag, off, rhs, lam)
        expected, ok = _csparse_cholsol(1 if rhs.shape[0] > 100 else 0, system.indptr, system.indices, system.data, rhs)
        assert ok
        assert np.array_equal(step, expected)
