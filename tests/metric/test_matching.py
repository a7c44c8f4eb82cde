"""Matching relation timestamps to an estimate: nearest within 0.1 s inclusive, interpolation, odometry, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.errors import MetricError
from slamtrials.metric import lookup_poses, match_relations
from slamtrials.record import Relations, Trajectory


def _trajectory(t, poses=None):
    t = np.asarray(t, dtype=float)
    if poses is None:
        poses = np.column_stack([t - t[0], np.zeros_like(t), np.zeros_like(t)])  # 1 m/s along x
    return Trajectory(t=t, poses=np.asarray(poses, dtype=float))


def _relations(t1, t2, delta=None):
    t1 = np.atleast_1d(np.asarray(t1, dtype=float))
    t2 = np.atleast_1d(np.asarray(t2, dtype=float))
    if delta is None:
        delta = np.zeros((len(t1), 3))
    return Relations(t1=t1, t2=t2, delta=np.asarray(delta, dtype=float).reshape(-1, 3))


def test_nearest_pose_within_tolerance_is_taken_and_ties_take_the_earlier():
    est = _trajectory([0.0, 1.0, 2.0])
    found = lookup_poses(est, [0.04, 0.96, 1.5, 2.1])
    np.testing.assert_array_equal(found.nearest, [0, 1, 1, 2])  # 1.5 is a tie between poses 1 and 2
    np.testing.assert_array_equal(found.found, [True, True, False, True])
    np.testing.assert_allclose(found.gap, [0.04, 0.04, 0.5, 0.1], atol=1e-12)
    np.testing.assert_allclose(found.poses[[0, 1, 3], 0], [0.0, 1.0, 2.0])
    assert np.isnan(found.poses[2]).all()


@pytest.mark.parametrize("base", [0.0, 1134864645.90321])
def test_tolerance_is_inclusive_even_for_large_timestamps(base):
    """A gap of exactly 0.1 s in decimal is accepted whichever way float64 rounded it (1e9 s: ulp 2.4e-7 s)."""
    est = _trajectory([base, base + 1.0])
    found = lookup_poses(est, [base + 0.1, base + 0.9, base + 0.1 + 1e-6, base + 0.5], tolerance=0.1)
    np.testing.assert_array_equal(found.found, [True, True, False, False])


def test_interpolation_uses_the_surrounding_poses_and_the_same_acceptance():
    est = _trajectory([0.0, 1.0, 2.0], [[0, 0, 3.0], [1, 2, -3.0], [2, 2, 0.0]])
    found = lookup_poses(est, [0.05, 0.5, 1.0, 2.05], interpolate=True)
    np.testing.assert_array_equal(found.found, [True, False, True, True])
    # 5 % of the way from (0, 0, 3) to (1, 2, -3): theta along the short arc through pi
    short_arc = 3.0 + 0.05 * (2 * np.pi - 6.0)
    np.testing.assert_allclose(found.poses[0], [0.05, 0.1, short_arc], atol=1e-12)
    np.testing.assert_allclose(found.poses[2], [1, 2, -3.0], atol=1e-12)
    np.testing.assert_allclose(found.poses[3], [2, 2, 0.0], atol=1e-12)  # past the end: the last pose


def test_unmatched_relations_are_reported_not_dropped():
    est = _trajectory([0.0, 1.0, 2.0, 3.0])
    rel = _relations([0.0, 0.5, 1.0], [1.0, 2.0, 2.55])
    match = match_relations(est, rel)
    np.testing.assert_array_equal(match.matched, [True, False, False])
    np.testing.assert_array_equal(match.unmatched, [1, 2])
    assert np.isnan(match.delta[1:]).all()
    np.testing.assert_allclose(match.delta[0], [1.0, 0.0, 0.0])


def test_odometry_carries_the_nearest_pose_to_the_timestamp():
    """Known answer: estimate at t=0 only (pose (5, 5, pi/2)); odometry moves 1 m/s along its own x axis."""
    est = _trajectory([0.0, 10.0], [[5.0, 5.0, np.pi / 2], [0.0, 0.0, 0.0]])
    odo_t = np.arange(0.0, 10.01, 0.5)
    heading = 0.3  # the odometry frame is rotated and shifted against the estimate's
    odo_poses = np.column_stack(
        [100.0 + odo_t * np.cos(heading), -7.0 + odo_t * np.sin(heading), np.full_like(odo_t, heading)]
    )
    odo = Trajectory(t=odo_t, poses=odo_poses)
    found = lookup_poses(est, [2.0, 0.05], odometry=odo)
    assert found.corrected.tolist() == [True, False]
    # from the nearest pose (t=0) the odometry moved 2 m forward in its own frame -> 2 m along the
    # estimate's heading (pi/2), whatever the odometry frame's origin and rotation
    np.testing.assert_allclose(found.poses[0], [5.0, 7.0, np.pi / 2], atol=1e-12)
    rel = _relations([0.0], [2.0], [[2.0, 0.0, 0.0]])
    match = match_relations(est, rel, odometry=odo)
    assert match.matched.all() and match.corrected.all()
    np.testing.assert_allclose(match.delta[0], [2.0, 0.0, 0.0], atol=1e-12)
    # without odometry the same relation is unmatched
    assert not match_relations(est, rel).matched.any()


def test_timestamps_outside_the_trajectory_are_refused_with_the_relation_index():
    est = _trajectory([10.0, 11.0, 12.0])
    rel = _relations([10.0, 11.0, 10.0], [11.0, 12.0, 12.2])
    with pytest.raises(MetricError, match="relation 2: timestamp 12.2 lies outside") as info:
        match_relations(est, rel)
    assert (info.value.what, info.value.index) == ("relations", 2)
    match = match_relations(est, rel, allow_outside=True)
    np.testing.assert_array_equal(match.matched, [True, True, False])
    np.testing.assert_array_equal(match.outside, [False, False, True])
    # within the tolerance of the ends is inside
    assert match_relations(est, _relations([9.9], [12.1])).matched.all()


@pytest.mark.parametrize(
    ("t", "problem", "index"),
    [
        ([], "empty", None),
        ([0.0, 1.0, 1.0, 2.0], "strictly increase, but pose 2", 2),
        ([0.0, 2.0, 1.0], "strictly increase, but pose 2", 2),
        ([0.0, np.nan, 1.0], "pose 1 has a non-finite", 1),
    ],
)
def test_bad_trajectories_name_the_pose(t, problem, index):
    est = Trajectory(t=np.asarray(t, dtype=float), poses=np.zeros((len(t), 3)))
    with pytest.raises(MetricError, match=problem) as info:
        match_relations(est, _relations([0.0], [1.0]))
    assert info.value.what == "estimate" and info.value.index == index


def test_bad_relations_name_the_relation():
    est = _trajectory([0.0, 1.0, 2.0])
    with pytest.raises(MetricError, match="relation 1 has a non-finite") as info:
        match_relations(est, _relations([0.0, 0.0], [1.0, 2.0], [[0, 0, 0], [np.inf, 0, 0]]))
    assert info.value.index == 1
    with pytest.raises(MetricError, match="relation 0 relates a timestamp to itself"):
        match_relations(est, _relations([1.0], [1.0]))
    with pytest.raises(MetricError, match="tolerance"):
        lookup_poses(est, [0.0], tolerance=-1.0)
