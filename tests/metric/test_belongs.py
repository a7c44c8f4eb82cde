"""turn_agreement: an estimate of the run turns with its odometry; another run's does not."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.metric.belongs import turn_agreement
from slamtrials.record import Trajectory


def test_the_run_s_own_estimate_agrees_even_with_a_drifting_odometry(drive, odometry_of):
    t, truth = drive(1)
    odometry = Trajectory(t=t, poses=odometry_of(truth, 2))
    agreement = turn_agreement(Trajectory(t=t, poses=truth), odometry)
    assert agreement.decided and agreement.belongs
    assert agreement.contradicting_windows == 0 and agreement.turning_windows > 40


def test_a_sparse_estimate_with_a_few_jumps_still_belongs(drive, odometry_of):
    t, truth = drive(3)
    estimate = truth[::5].copy()
    estimate[::40, 2] += 0.8  # a relocalisation jump now and then
    agreement = turn_agreement(Trajectory(t=t[::5], poses=estimate), Trajectory(t=t, poses=odometry_of(truth, 4)))
    assert agreement.belongs and agreement.contradicting_share < 0.3


@pytest.mark.parametrize("other_seed", [5, 6, 7])
def test_another_run_of_the_same_length_is_refused(other_seed, drive, odometry_of):
    t, truth = drive(1)
    _, other = drive(other_seed)
    agreement = turn_agreement(Trajectory(t=t, poses=other), Trajectory(t=t, poses=odometry_of(truth, 2)))
    assert agreement.decided and not agreement.belongs
    assert agreement.contradicting_share > 0.6


def test_too_little_turning_decides_nothing():
    t = np.arange(600) * 0.1
    straight = np.column_stack([0.4 * t, np.zeros_like(t), np.zeros_like(t)])
    bent = straight.copy()
    bent[300:, 2] = 1.0
    agreement = turn_agreement(Trajectory(t=t, poses=bent), Trajectory(t=t, poses=straight))
    assert agreement.turning_windows == 1 and not agreement.decided and agreement.belongs


def test_headings_are_compared_across_the_wrap(drive):
    t, truth = drive(8)
    wrapped = truth.copy()
    wrapped[:, 2] = np.arctan2(np.sin(truth[:, 2] + 3.0), np.cos(truth[:, 2] + 3.0))
    agreement = turn_agreement(Trajectory(t=t, poses=wrapped), Trajectory(t=t, poses=truth))
    assert agreement.decided and agreement.contradicting_windows == 0
