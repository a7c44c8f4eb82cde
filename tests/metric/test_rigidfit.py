"""The least-squares rigid fit of a SLAM estimate onto the truth: known motions recovered, noise spread, the
fallback when the estimate does not move, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.geometry import compose, inverse
from slamtrials.metric.rigidfit import align_estimate, fit_rigid_2d


def _path(n: int = 200, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    steps = rng.normal([0.1, 0.0, 0.0], [0.02, 0.01, 0.1], size=(n, 3))
    poses = np.zeros((n, 3))
    for k in range(1, n):
        poses[k] = compose(poses[k - 1], steps[k])
    return poses


@pytest.mark.parametrize("motion", [(2.0, -1.0, 0.7), (-5.5, 3.25, -math.pi / 2), (0.0, 0.0, 3.0)])
def test_a_known_motion_is_recovered(motion):
    truth = _path()
    world_from_map = np.array(motion)
    estimate = compose(inverse(world_from_map), truth)  # the truth seen in a map frame placed at `motion`
    fit = align_estimate(estimate, truth)
    assert fit.method == "least squares" and fit.frames == len(truth)
    assert np.allclose(fit.world_from_map[:2], world_from_map[:2], atol=1e-9)
    assert math.remainder(fit.world_from_map[2] - world_from_map[2], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    assert fit.rms_m < 1e-9


def test_the_fit_is_symmetric_and_spreads_noise():
    truth = _path()
    noisy = truth.copy()
    noisy[:, :2] += np.random.default_rng(2).normal(0.0, 0.05, size=(len(truth), 2))
    forward = fit_rigid_2d(noisy[:, :2], truth[:, :2])
    backward = fit_rigid_2d(truth[:, :2], noisy[:, :2])
    assert np.allclose(compose(forward, backward), 0.0, atol=1e-9)
    fit = align_estimate(noisy, truth)
    assert 0.06 < fit.rms_m < 0.08  # 0.05 m per axis: sqrt(2) x 0.05 m apart


def test_rows_with_nan_are_left_out_and_a_still_estimate_falls_back_to_the_first_pose():
    truth = _path(50)
    estimate = compose(inverse(np.array([1.0, 2.0, 0.3])), truth)
    estimate[5] = np.nan
    fit = align_estimate(estimate, truth)
    assert fit.frames == 49 and np.allclose(fit.world_from_map, [1.0, 2.0, 0.3])
    still = np.tile([0.5, 0.5, 0.1], (4, 1))
    moving = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    fallback = align_estimate(still, moving)
    assert fallback.method == "first pose"
    assert np.allclose(compose(fallback.world_from_map, still[0]), moving[0])
    assert fit_rigid_2d(np.full((3, 2), 0.1), np.zeros((3, 2))) is None
    assert fit_rigid_2d(np.zeros((0, 2)), np.zeros((0, 2))) is None


def test_bad_shapes_and_no_usable_row_are_refused():
    with pytest.raises(ValueError, match="must both be"):
        align_estimate(np.zeros((4, 3)), np.zeros((5, 3)))
    with pytest.raises(ValueError, match="no frame"):
        align_estimate(np.full((3, 3), np.nan), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="must both be"):
        fit_rigid_2d(np.zeros((3, 3)), np.zeros((3, 3)))
