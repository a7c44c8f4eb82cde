"""The deterministic sparse Cholesky behind the optimizer."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse
import scipy.sparse.linalg

from slamtrials.slam.karto.sparsechol import NotPositiveDefinite, cholesky, cholesky_solve, minimum_degree_order


def _random_spd(n: int, seed: int) -> scipy.sparse.csc_matrix:
    rng = np.random.default_rng(seed)
    a = scipy.sparse.random(n, n, density=0.05, random_state=rng, format="csc")
    return (a @ a.T + n * scipy.sparse.identity(n)).tocsc()


@pytest.mark.parametrize("seed", [0, 1])
def test_solution_matches_scipy(seed):
    a = _random_spd(60, seed)
    b = np.arange(60, dtype=np.float64)
    upper = scipy.sparse.triu(a, format="csc")
    upper.sort_indices()
    x = cholesky_solve(cholesky(upper.indptr, upper.indices, upper.data), b)
    np.testing.assert_allclose(x, scipy.sparse.linalg.spsolve(a, b), rtol=1e-10, atol=1e-12)


def test_indefinite_matrix_is_reported():
    a = scipy.sparse.csc_matrix(np.array([[1.0, 2.0], [2.0, 1.0]]))
    upper = scipy.sparse.triu(a, format="csc")
    with pytest.raises(NotPositiveDefinite):
        cholesky(upper.indptr, upper.indices, upper.data)


def test_minimum_degree_order_is_a_permutation_that_takes_leaves_first():
    # a star: the centre has the largest degree and goes last
    order = minimum_degree_order(5, [(0, 1), (0, 2), (0, 3), (0, 4)])
    assert sorted(order.tolist()) == [0, 1, 2, 3, 4]
    assert order[-1] == 0 or order.tolist().index(0) >= 3
