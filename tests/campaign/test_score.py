"""A run's score: its relation set, the final, online and odometry estimates on it, which one is the run's."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.campaign.config import MetricSettings
from slamtrials.campaign.score import score_run
from slamtrials.errors import MetricError
from slamtrials.geometry import compose
from slamtrials.record import LaserGeometry, RunRecord


def _record(n: int = 500, online: bool = True) -> RunRecord:
    rng = np.random.default_rng(3)
    steps = np.column_stack([np.full(n - 1, 0.05), np.zeros(n - 1), rng.normal(0, 0.05, n - 1)])
    truth, odometry = np.zeros((n, 3)), np.zeros((n, 3))
    for k in range(n - 1):
        truth[k + 1] = compose(truth[k], steps[k])
        odometry[k + 1] = compose(odometry[k], steps[k] * [1.02, 1.0, 1.03])
    final = truth + rng.normal(0.0, 0.01, truth.shape)
    return RunRecord(
        t=np.arange(n) * 0.1,
        scans=np.zeros((n, 3), np.float32),
        odometry=odometry,
        truth=truth,
        stalled=np.zeros(n, bool),
        laser=LaserGeometry(angle_min=-1.0, angle_increment=1.0, range_min=0.1, range_max=10.0),
        estimate=final,
        online=final + rng.normal(0.0, 0.03, truth.shape) if online else None,
    )


def test_every_estimate_is_scored_on_the_one_set_and_the_chosen_one_is_the_runs():
    record = _record()
    final = score_run(record, 4, MetricSettings())
    assert final.scored == "final" and final.eps_t == final.estimate.eps_t
    # the noisier online poses and the drifting odometry score worse than the final estimate
    assert final.estimate.eps_t < final.online.eps_t and final.estimate.eps_t < final.odometry.eps_t
    assert (
        len(final.estimate.errors.translational) == len(final.odometry.errors.translational) == len(final.relation_set)
    )
    online = score_run(record, 4, MetricSettings(estimate="online"))
    np.testing.assert_array_equal(online.relation_set.first, final.relation_set.first)
    assert online.eps_t == final.online.eps_t and online.to_dict()["se_t"] == final.online.se_t
    assert online.to_dict()["scored_estimate"] == "online"
    with pytest.raises(MetricError, match="no online estimate"):
        score_run(_record(online=False), 4, MetricSettings(estimate="online"))


def test_a_given_set_is_reused_as_it_is():
    record = _record()
    first = score_run(record, 4, MetricSettings())
    again = score_run(record, 99, MetricSettings(), first.relation_set)
    assert again.relation_set is first.relation_set and again.eps_t == first.eps_t
