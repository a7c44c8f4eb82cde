"""Per-relation errors: hand-computed answers, properties, and agreement with evo's RPE."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from slamtrials.geometry import compose, ominus
from slamtrials.metric import evaluate_relations, relative_pose_errors
from slamtrials.record import Relations, Trajectory


def test_known_answer_absolute_and_squared():
    """Truth moves 1 m straight ahead; the estimate, facing +y, moves 1.1 m ahead and turns 0.1 rad."""
    truth = Trajectory(t=np.array([0.0, 1.0]), poses=np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))
    estimate = Trajectory(t=np.array([0.0, 1.0]), poses=np.array([[2.0, 3.0, np.pi / 2], [2.0, 4.1, np.pi / 2 + 0.1]]))
    relations = Relations(t1=np.array([0.0]), t2=np.array([1.0]), delta=ominus(truth.poses[0], truth.poses[1])[None])
    errors = evaluate_relations(estimate, relations)
    np.testing.assert_allclose(errors.translational, [0.1], atol=1e-12)
    np.testing.assert_allclose(errors.rotational, [0.1], atol=1e-12)
    assert errors.units == ("m", "rad") and not errors.squared
    squared = evaluate_relations(estimate, relations, squared=True)
    np.testing.assert_allclose(squared.translational, [0.01], atol=1e-12)
    np.testing.assert_allclose(squared.rotational, [0.01], atol=1e-12)
    assert squared.units == ("m^2", "rad^2")


def test_known_answers_of_the_error_formula():
    delta_true = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 3.1], [3.0, 4.0, 0.0]])
    delta = np.array([[1.0, 0.2, -0.3], [0.0, 0.0, -3.1], [0.0, 0.0, 0.0]])
    trans, rot = relative_pose_errors(delta, delta_true)
    np.testing.assert_allclose(trans, [0.2, 0.0, 5.0], atol=1e-12)
    np.testing.assert_allclose(rot, [0.3, 2 * np.pi - 6.2, 0.0], atol=1e-12)  # 3.1 vs -3.1 is 0.083 rad apart


# ---------------------------------------------------------------- properties

coordinate = st.floats(-50, 50, allow_nan=False)
angle = st.floats(-np.pi, np.pi, allow_nan=False)


@st.composite
def trajectories_and_pairs(draw):
    n = draw(st.integers(2, 30))
    steps = draw(hnp.arrays(np.float64, n, elements=st.floats(0.2, 5.0)))
    t = 1e9 + np.cumsum(steps)
    truth = np.column_stack(
        [draw(hnp.arrays(np.float64, n, elements=coordinate)) for _ in range(2)]
        + [draw(hnp.arrays(np.float64, n, elements=angle))]
    )
    noise = draw(hnp.arrays(np.float64, (n, 3), elements=st.floats(-1.0, 1.0)))
    k = draw(st.integers(1, 20))
    i = np.array(draw(st.lists(st.integers(0, n - 1), min_size=k, max_size=k)))
    j = np.array(draw(st.lists(st.integers(0, n - 1), min_size=k, max_size=k)))
    keep = i != j
    if not keep.any():
        i, j = np.array([0]), np.array([n - 1])
    else:
        i, j = i[keep], j[keep]
    return t, truth, truth + noise, i, j


def _relations(t, poses, i, j):
    return Relations(t1=t[i], t2=t[j], delta=ominus(poses[i], poses[j]))


@settings(deadline=None)  # the first example may load the numba kernels from cache
@given(trajectories_and_pairs())
def test_perfect_estimate_has_zero_error(case):
    t, truth, _, i, j = case
    errors = evaluate_relations(Trajectory(t=t, poses=truth), _relations(t, truth, i, j))
    np.testing.assert_allclose(errors.translational, 0.0, atol=1e-9)
    np.testing.assert_allclose(errors.rotational, 0.0, atol=1e-9)
    assert len(errors.unmatched) == 0


@settings(deadline=None)  # the first example may load the numba kernels from cache
@given(trajectories_and_pairs(), st.tuples(coordinate, coordinate, angle).map(np.array))
def test_one_rigid_transform_of_the_whole_estimate_changes_nothing(case, g):
    t, truth, estimate, i, j = case
    relations = _relations(t, truth, i, j)
    before = evaluate_relations(Trajectory(t=t, poses=estimate), relations)
    after = evaluate_relations(Trajectory(t=t, poses=compose(g, estimate)), relations)
    np.testing.assert_allclose(after.translational, before.translational, atol=1e-8)
    np.testing.assert_allclose(after.rotational, before.rotational, atol=1e-9)


@settings(deadline=None)  # the first example may load the numba kernels from cache
@given(trajectories_and_pairs())
def test_swapping_estimate_and_truth_gives_the_same_errors(case):
    t, truth, estimate, i, j = case
    forward = evaluate_relations(Trajectory(t=t, poses=estimate), _relations(t, truth, i, j))
    backward = evaluate_relations(Trajectory(t=t, poses=truth), _relations(t, estimate, i, j))
    np.testing.assert_allclose(backward.translational, forward.translational, atol=1e-9)
    np.testing.assert_allclose(backward.rotational, forward.rotational, atol=1e-9)


# ---------------------------------------------------------------- evo

evo_metrics = pytest.importorskip("evo.core.metrics")
evo_trajectory = pytest.importorskip("evo.core.trajectory")


def _se3(poses):
    """SE(2) poses [N, 3] -> SE(3) matrices [N, 4, 4] (rotation about z)."""
    out = np.tile(np.eye(4), (len(poses), 1, 1))
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
    out[:, 0, 3], out[:, 1, 3] = poses[:, 0], poses[:, 1]
    return out


@settings(max_examples=30, deadline=None)
@given(trajectories_and_pairs(), st.integers(1, 5))
def test_agrees_with_evo_rpe(case, delta):
    """evo's RPE (delta in frames, all pairs (i, i + delta)) against our errors on the same pairs.

    The definitions coincide in these cases: evo takes E = delta*^-1 delta and reports ||t(E)|| =
    ||R*^T (t(delta) - t(delta*))|| = ||t(delta) - t(delta*)|| (a rotation keeps the norm), and the angle
    of rot(E) = |wrap(theta(delta) - theta(delta*))|; so for SE(2) relations they agree even when the
    rotations differ. They differ in which pairs they evaluate (evo: every pose with the one ``delta``
    frames later; Kuemmerle: the given relations) and in matching timestamps, so the test gives both the
    same pairs on one shared set of timestamps.
    """
    t, truth, estimate, _, _ = case
    if len(t) <= delta:
        return
    ref = evo_trajectory.PoseTrajectory3D(poses_se3=list(_se3(truth)), timestamps=t)
    est = evo_trajectory.PoseTrajectory3D(poses_se3=list(_se3(estimate)), timestamps=t)
    i = np.arange(len(t) - delta)
    ours = evaluate_relations(Trajectory(t=t, poses=estimate), _relations(t, truth, i, i + delta))
    for relation, expected in (
        (evo_metrics.PoseRelation.translation_part, ours.translational),
        (evo_metrics.PoseRelation.rotation_angle_rad, ours.rotational),
    ):
        rpe = evo_metrics.RPE(relation, delta=delta, delta_unit=evo_metrics.Unit.frames, all_pairs=True)
        rpe.process_data((ref, est))
        assert rpe.delta_ids == (i + delta).tolist()  # evo keeps the second index of each pair
        np.testing.assert_allclose(rpe.error, expected, atol=1e-6)
