"""The scan matcher's exp(-a): a Taylor series for the small arguments every score has, libm beyond."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from slamtrials.slam.gmapping.kernels import _EXP_SERIES_MAX, _exp_minus


@njit(cache=False)
def _many(a):
    out = np.empty_like(a)
    for i in range(a.shape[0]):
        out[i] = _exp_minus(a[i])
    return out


def test_within_a_few_ulp_of_libm_over_the_series_range_and_equal_beyond():
    a = np.concatenate(
        [np.linspace(0.0, _EXP_SERIES_MAX, 200_001), np.random.default_rng(0).uniform(0.0, _EXP_SERIES_MAX, 100_000)]
    )
    got = _many(a)
    want = np.exp(-a)
    assert np.max(np.abs(got - want) / want) < 8 * np.finfo(float).eps
    assert got[0] == 1.0
    beyond = np.array([_EXP_SERIES_MAX + 1e-12, 0.7, 3.0, 40.0, 800.0])
    np.testing.assert_array_equal(_many(beyond), [math.exp(-v) for v in beyond])
