"""The numba kernels agree with brute force, and geometry.interpolate has the expected endpoints and arcs."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from slamtrials.geometry import interpolate, ominus, wrap_angle
from slamtrials.metric.kernels import nearest_indices, relative_poses


@settings(deadline=None)  # the first example may load the numba kernels from cache
@given(
    hnp.arrays(np.float64, st.integers(1, 60), elements=st.floats(0.0, 100.0), unique=True),
    hnp.arrays(np.float64, st.integers(0, 60), elements=st.floats(-10.0, 110.0)),
    st.floats(0.0, 5.0),
)
def test_nearest_matches_brute_force(times, queries, tolerance):
    times = np.sort(times)
    index, gap, within = nearest_indices(times, queries, tolerance)
    for k, q in enumerate(queries):
        distances = np.abs(times - q)
        assert gap[k] == distances.min()
        assert (
            distances[index[k]] == distances.min()
        )  # (ties between the two neighbours go to the earlier, test_matching)
        assert within[k] == (distances.min() <= tolerance + abs(q) * np.finfo(float).eps)


def test_nearest_with_clustered_times_and_large_offsets():
    rng = np.random.default_rng(3)
    times = 1.1e9 + np.sort(np.concatenate([rng.uniform(0, 1, 500), rng.uniform(1000, 1001, 500), [5000.0]]))
    queries = 1.1e9 + rng.uniform(-10, 5010, 5000)
    index, gap, _ = nearest_indices(times, queries, 0.1)
    brute = np.abs(queries[:, None] - times[None, :])
    np.testing.assert_array_equal(gap, brute.min(axis=1))
    np.testing.assert_array_equal(index, brute.argmin(axis=1))


@settings(deadline=None)  # the first example may load the numba kernels from cache
@given(
    hnp.arrays(np.float64, (20, 3), elements=st.floats(-50, 50)),
    hnp.arrays(np.float64, (20, 3), elements=st.floats(-50, 50)),
)
def test_relative_poses_match_ominus(a, b):
    rows = np.arange(20)
    got = relative_poses(a, rows, b, rows[::-1])
    want = ominus(a, b[::-1])
    np.testing.assert_allclose(got[:, :2], want[:, :2], atol=1e-9)
    np.testing.assert_allclose(wrap_angle(got[:, 2] - want[:, 2]), 0.0, atol=1e-9)


def test_interpolate_endpoints_and_short_arc():
    a = np.array([0.0, 0.0, 3.0])
    b = np.array([2.0, -4.0, -3.0])
    np.testing.assert_allclose(interpolate(a, b, 0.0), a)
    np.testing.assert_allclose(interpolate(a, b, 1.0), b, atol=1e-12)
    half = interpolate(a, b, 0.5)
    np.testing.assert_allclose(half[:2], [1.0, -2.0])
    assert abs(abs(half[2]) - np.pi) < 1e-12  # through pi, not through 0
    assert interpolate(np.zeros((4, 3)), np.ones(3), np.linspace(0, 1, 4)).shape == (4, 3)
