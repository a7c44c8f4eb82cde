"""The correlative matcher: known offsets, Karto's smearing kernel and valid-point rule."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.slam.karto.correlation import find_valid_points, smear_kernel
from slamtrials.slam.karto.scanmatch import MatcherSettings, ScanMatcher, points_in_map

SETTINGS = MatcherSettings(
    coarse_search_angle_offset=0.349,
    coarse_angle_resolution=0.0349,
    fine_search_angle_offset=0.00349,
    distance_variance=0.25,
    angle_variance=1.0,
    minimum_distance_penalty=0.5,
    minimum_angle_penalty=0.9,
    use_response_expansion=True,
)


def _local(ranges, angles, range_max):
    r = np.where(np.asarray(ranges) < range_max, ranges, np.nan).astype(np.float64)
    return r * np.cos(angles), r * np.sin(angles)


@pytest.mark.parametrize("offset", [(0.06, -0.04, 0.0698), (-0.10, 0.12, -0.1396), (0.0, 0.0, 0.0)])
def test_a_scan_matched_against_itself_recovers_a_known_offset(offset, synthetic):
    laser = synthetic.laser
    angles = laser.beam_angles(361)
    true_pose = np.array([-6.0, -1.0, math.pi / 2])
    lx, ly = _local(synthetic.raycast(true_pose, angles, synthetic.segments, laser.range_max), angles, laser.range_max)
    matcher = ScanMatcher(0.5, 0.01, 0.1, laser.range_max, SETTINGS)
    guess = true_pose + np.array(offset)
    result = matcher.match(guess, lx, ly, [points_in_map(true_pose, lx, ly)])
    error = result.pose - true_pose
    assert math.hypot(error[0], error[1]) <= 0.011  # one fine cell
    assert abs(error[2]) <= 0.0036  # one fine angular step
    assert result.response > 0.9
    assert result.covariance[0, 0] > 0 and result.covariance[1, 1] > 0 and result.covariance[2, 2] > 0


def test_a_scan_with_no_beams_gives_no_response_and_the_largest_variance():
    matcher = ScanMatcher(0.5, 0.01, 0.1, 10.0, SETTINGS)
    result = matcher.match(np.zeros(3), np.zeros(0), np.zeros(0), [])
    assert result.response == 0.0 and result.covariance[0, 0] == 500.0


def test_smear_kernel_is_karto_s():
    kernel = smear_kernel(0.01, 0.1)
    assert kernel.shape == (41, 41)  # half size round(2 * 0.1 / 0.01) = 20
    assert kernel[20, 20] == 100 and kernel[20, 30] == 61 and kernel[30, 20] == 61  # exp(-1/2) = 0.607
    np.testing.assert_array_equal(kernel, kernel.T)
    assert smear_kernel(0.05, 0.03).shape == (3, 3)


def test_valid_points_keep_what_faces_the_viewpoint():
    # a wall seen from (0, 0): points ordered counter-clockwise face the viewpoint and are kept ...
    x = np.linspace(2.0, -2.0, 9)
    y = np.full(9, 3.0)
    kept = find_valid_points(x, y, 0.0, 0.0)
    assert kept[:-1].all() and not kept[-1]  # Karto never keeps the last point of a run
    # ... the same wall seen from behind (0, 6) turns clockwise and is dropped
    assert not find_valid_points(x, y, 0.0, 6.0).any()


def test_valid_points_check_only_steps_longer_than_karto_square_of_a_tenth():
    # Karto compares the squared step with math::Square(0.1) = 0.1 * 0.1, one ulp above 0.01: a step of
    # exactly 0.1 m is not a check, so the first point stays the reference for the next step
    assert 0.1 * 0.1 > 0.01
    x = np.array([0.0, 0.1, -1.0])
    y = np.array([1.0, 1.0, 1.0])
    # seen from (0, 0), the step to (0.1, 1) turns the wrong way; were it checked (a bound of 0.01), point
    # 0 would be dropped. Unchecked, the step to (-1, 1) turns the right way from point 0 and keeps 0 and 1.
    np.testing.assert_array_equal(find_valid_points(x, y, 0.0, 0.0), [True, True, False])
