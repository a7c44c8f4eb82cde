"""The true trajectory fitted onto a run's estimate (map frame), checked against known motions and an SVD fit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.geometry import compose, inverse
from slamtrials.report.alignment import align_truth, fit_rigid_2d


def curvy_path(n: int = 300) -> np.ndarray:
    """A path ``[n, 3]`` (world frame) that turns both ways, as a robot exploring a building might."""
    s = np.linspace(0.0, 12.0, n)
    x, y = 4.0 * np.cos(0.4 * s) + 0.3 * s, 3.0 * np.sin(0.7 * s)
    heading = np.arctan2(np.gradient(y), np.gradient(x))
    return np.column_stack([x, y, heading])


def svd_fit(p: np.ndarray, q: np.ndarray) -> tuple[float, np.ndarray]:
    """Kabsch by SVD (an independent way to the same optimum): rotation angle and translation of p onto q."""
    pm, qm = p.mean(axis=0), q.mean(axis=0)
    u, _s, vt = np.linalg.svd((p - pm).T @ (q - qm))
    d = np.sign(np.linalg.det(vt.T @ u.T))
    rotation = vt.T @ np.diag([1.0, d]) @ u.T
    return math.atan2(rotation[1, 0], rotation[0, 0]), qm - rotation @ pm


def test_a_known_rigid_offset_is_recovered_exactly():
    truth = curvy_path()
    map_from_world = np.array([3.0, -2.0, 0.7])
    estimate = compose(map_from_world, truth)  # a perfect estimate, in another frame
    fit = align_truth(truth, estimate)
    assert fit.method == "least squares" and fit.used.all()
    assert fit.map_from_world == pytest.approx(map_from_world, abs=1e-12)
    assert fit.truth == pytest.approx(estimate, abs=1e-12)  # headings turned too
    assert fit.rms == pytest.approx(0.0, abs=1e-12) and fit.max_distance == pytest.approx(0.0, abs=1e-12)


def test_a_drifting_estimate_gets_the_least_squares_fit():
    truth = curvy_path()
    rng = np.random.default_rng(11)
    drift = np.cumsum(rng.normal(0.0, 0.01, (len(truth), 3)), axis=0)  # a random walk: the SLAM error
    offset = np.array([-5.0, 1.5, -2.4])
    estimate = compose(offset, truth + drift)
    fit = align_truth(truth, estimate)
    theta, translation = svd_fit(truth[:, :2], estimate[:, :2])
    assert fit.map_from_world[2] == pytest.approx(theta, abs=1e-10)
    assert fit.map_from_world[:2] == pytest.approx(translation, abs=1e-9)
    gaps = np.hypot(*(fit.truth[:, :2] - estimate[:, :2]).T)
    assert fit.rms == pytest.approx(np.sqrt(np.mean(gaps**2))) and fit.max_distance == pytest.approx(gaps.max())
    # the least-squares fit is no worse than anchoring at the first pose, and no small change improves it
    anchored = compose(compose(estimate[0], inverse(truth[0])), truth)
    assert fit.rms < np.sqrt(np.mean(np.sum((anchored[:, :2] - estimate[:, :2]) ** 2, axis=1)))
    for change in ([1e-3, 0, 0], [0, 1e-3, 0], [0, 0, 1e-4], [0, 0, -1e-4]):
        moved = compose(fit.map_from_world + np.array(change), truth)
        assert np.sqrt(np.mean(np.sum((moved[:, :2] - estimate[:, :2]) ** 2, axis=1))) > fit.rms
    # the same answer every time (no random draws)
    again = align_truth(truth, estimate)
    assert np.array_equal(again.map_from_world, fit.map_from_world) and np.array_equal(again.truth, fit.truth)


def test_rows_without_an_estimate_are_left_out_and_a_still_robot_is_anchored_at_its_first_pose():
    truth = curvy_path(50)
    offset = np.array([1.0, 2.0, 0.3])
    estimate = compose(offset, truth)
    estimate[:5] = np.nan  # SLAM had not published yet
    fit = align_truth(truth, estimate)
    assert fit.used.tolist() == [False] * 5 + [True] * 45
    assert fit.map_from_world == pytest.approx(offset, abs=1e-12)
    assert np.isfinite(fit.truth).all()  # every true pose is placed, also those without an estimate
    still = np.tile([2.0, 3.0, 0.5], (10, 1))
    seen = compose(offset, still)
    fit = align_truth(still, seen)
    assert fit.method == "first pose" and fit.map_from_world == pytest.approx(offset, abs=1e-12)
    assert fit_rigid_2d(still[:, :2], seen[:, :2]) is None and fit_rigid_2d(np.zeros((0, 2)), np.zeros((0, 2))) is None


def test_bad_inputs_are_refused():
    with pytest.raises(ValueError, match="must both be"):
        align_truth(np.zeros((4, 3)), np.zeros((5, 3)))
    with pytest.raises(ValueError, match="no pose has both"):
        align_truth(np.zeros((3, 3)), np.full((3, 3), np.nan))
    with pytest.raises(ValueError, match=r"\[N, 2\]"):
        fit_rigid_2d(np.zeros((3, 3)), np.zeros((3, 3)))
