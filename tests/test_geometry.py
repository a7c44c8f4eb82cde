"""SE(2) basics: identities of compose/inverse/ominus, and the single-pose versions agree with the array ones."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from slamtrials.geometry import compose, compose1, inverse, ominus, ominus1, transform_points, wrap_angle, wrap_angle1

coordinate = st.floats(-100, 100, allow_nan=False)
angle = st.floats(-20, 20, allow_nan=False)
pose = st.tuples(coordinate, coordinate, angle).map(np.array)


def test_known_composition():
    a = np.array([1.0, 2.0, np.pi / 2])
    b = np.array([3.0, 0.0, np.pi / 2])
    np.testing.assert_allclose(compose(a, b), [1.0, 5.0, -np.pi], atol=1e-12)  # wrapped into [-pi, pi)
    np.testing.assert_allclose(transform_points(a, [[3.0, 0.0]]), [[1.0, 5.0]], atol=1e-12)


@given(pose, pose)
def test_ominus_undoes_compose(a, b):
    np.testing.assert_allclose(ominus(a, compose(a, b))[:2], b[:2], atol=1e-8)
    assert abs(wrap_angle(ominus(a, compose(a, b))[2] - b[2])) < 1e-9
    np.testing.assert_allclose(compose(a, inverse(a)), [0, 0, 0], atol=1e-9)


@given(pose, pose)
def test_single_pose_versions_match(a, b):
    np.testing.assert_allclose(compose1(a, b), compose(a, b), atol=1e-9)
    np.testing.assert_allclose(ominus1(a, b), ominus(a, b), atol=1e-8)
    assert wrap_angle1(float(a[2])) == float(wrap_angle(a[2]))


def test_broadcasting_over_arrays():
    a = np.zeros((4, 5, 3))
    b = np.ones(3)
    assert compose(a, b).shape == (4, 5, 3)
    assert (
        -np.pi <= wrap_angle(np.linspace(-50, 50, 1001)).min() and wrap_angle(np.linspace(-50, 50, 1001)).max() < np.pi
    )
