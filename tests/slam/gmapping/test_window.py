"""The vector 3 x 3 window minimum (``slam/gmapping/window.py``) equals the scalar loop bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from slamtrials.slam.gmapping.kernels import EMPTY
from slamtrials.slam.gmapping.window import NOTHING_D2, window_min_3x3

ROW_STRIDE = 32  # a tile row: 16 cells of (x, y)


@njit(cache=False)
def scalar_window_min(mean, first, row_stride, ox, oy, res):
    """The scalar code of score_pose's default window."""
    d2 = NOTHING_D2
    for dr in range(3):
        uy0 = oy - (dr - 1) * res
        k = first + dr * row_stride
        for dc in range(3):
            ux = ox - (dc - 1) * res - mean[k + 2 * dc]
            uy = uy0 - mean[k + 2 * dc + 1]
            d2 = min(d2, ux * ux + uy * uy)
    return d2


@njit(cache=False)
def vector_window_min(mean, first, row_stride, ox, oy, res):
    return window_min_3x3(mean, first, row_stride, ox, oy, res)


def _means(rng: np.random.Generator, size: int, empty_share: float) -> np.ndarray:
    mean = rng.uniform(0.0, 0.05, size).astype(np.float32)
    mean[rng.random(size) < empty_share] = EMPTY
    return mean


def test_random_windows_equal_the_scalar_loop_exactly():
    """20,000 windows over mean arrays with 0 %, 70 % and 100 % empty cells: identical results, and both
    the found and the nothing-found cases occur."""
    rng = np.random.default_rng(5)
    found = nothing = 0
    for empty_share in (0.0, 0.7, 1.0):
        mean = _means(rng, 4096, empty_share)
        for _ in range(7000):
            first = np.int64(rng.integers(0, mean.size - 2 * ROW_STRIDE - 6))
            ox, oy = rng.uniform(-0.01, 0.06, 2)
            want = scalar_window_min(mean, first, np.int64(ROW_STRIDE), ox, oy, 0.05)
            got = vector_window_min(mean, first, np.int64(ROW_STRIDE), ox, oy, 0.05)
            assert got == want
            found += want < 1e30
            nothing += want == NOTHING_D2
    assert found > 1000 and nothing > 1000


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.floats(0.0, float(np.float32(0.05)), width=32) | st.just(float(EMPTY)), min_size=70, max_size=70),
    st.floats(-0.2, 0.2),
    st.floats(-0.2, 0.2),
    st.sampled_from([0.01, 0.05, 0.1]),
)
@pytest.mark.slow
def test_any_window_equals_the_scalar_loop(values, ox, oy, res):
    """Any cell contents (including ties and empty cells) and endpoint offsets: identical results."""
    mean = np.array(values, dtype=np.float32)
    want = scalar_window_min(mean, np.int64(0), np.int64(26), ox, oy, res)
    got = vector_window_min(mean, np.int64(0), np.int64(26), ox, oy, res)
    assert got == want
