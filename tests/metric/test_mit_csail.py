"""The metric on real data: the MIT CSAIL log and its Freiburg benchmark relations.

Observed when this test was written (2026-11, nearest pose within 0.1 s, no interpolation):

- every FLASER line of ``mit-csail.clf`` has IDENTICAL first and second pose triples: the "corrected"
  triple of this log is the raw odometry, not a SLAM-corrected pose;
- raw odometry (either triple) against ``mit-csail.relations``: all 1,172 relations matched (largest
  timestamp gap 5e-6 s), translational error 1.681 +- 5.294 m (mean +- sample std, min 3e-7, max
  22.97), rotational error 0.0885 +- 0.1439 rad. Relations between scans less than 1 s apart (1,040 of
  them) have a mean translational error of 0.032 m; the 97 relations more than 100 s apart, 18.6 m:
  odometry drifts, as a relative metric should show;
- for comparison, GMapping on this log gives 0.048-0.049 m (metric.md, section 5; gmapping.md, section 7).

So the log cannot show "corrected poses small, raw odometry large" by itself; the test checks what it
can: the two triples are equal, raw odometry's error is far (> 5x) above GMapping's published figure,
and the errors of short relations are small.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from slamtrials.metric import evaluate_relations, summarize
from slamtrials.record import Trajectory

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared")) / "data" / "mit-csail"
LOG = DATA / "mit-csail.clf"
RELATIONS = DATA / "mit-csail.relations"

pytestmark = pytest.mark.skipif(not (LOG.is_file() and RELATIONS.is_file()), reason=f"no MIT CSAIL data in {DATA}")

#: Published GMapping translational error on this log (m), metric.md section 5.
GMAPPING_PUBLISHED = 0.049


@pytest.fixture(scope="module")
def data():
    from slamtrials.io.carmen import read_carmen
    from slamtrials.io.relations import read_relations

    return read_carmen(LOG), read_relations(RELATIONS)


def test_both_pose_triples_of_the_log_are_raw_odometry(data):
    log, relations = data
    assert len(log.laser) == 1988 and len(relations) == 1172
    np.testing.assert_array_equal(log.laser.pose, log.laser.odometry)


def test_raw_odometry_error_is_large_and_short_relations_small(data):
    log, relations = data
    results = {}
    for name, poses in (("first triple", log.laser.pose), ("odometry", log.laser.odometry)):
        errors = evaluate_relations(Trajectory(t=log.laser.t, poses=poses), relations)
        assert len(errors.unmatched) == 0 and len(errors) == 1172
        results[name] = (summarize(errors.translational), summarize(errors.rotational), errors)
    trans, rot, errors = results["odometry"]
    assert trans.mean > 5 * GMAPPING_PUBLISHED  # observed 1.68 m
    assert trans.max > 10.0  # loop closures: odometry drifted by metres (observed 22.97 m)
    assert 0.01 < rot.mean < 1.0  # observed 0.0885 rad
    assert results["first triple"][0].mean == trans.mean
    short = np.abs(relations.t2 - relations.t1)[errors.index] < 1.0
    assert short.sum() > 1000 and errors.translational[short].mean() < 0.1  # observed 0.032 m


def test_odometry_correction_on_a_sparse_estimate(data):
    """Keep every 5th pose (like a SLAM program that processes some scans): with the log's odometry
    carrying each relation timestamp to the nearest kept pose, raw odometry evaluates exactly as before."""
    log, relations = data
    t, poses = log.laser.t, log.laser.odometry
    full = evaluate_relations(Trajectory(t=t, poses=poses), relations)
    sparse = Trajectory(t=t[::5], poses=poses[::5])
    without = evaluate_relations(sparse, relations)
    assert len(without.unmatched) > 500
    with_odometry = evaluate_relations(sparse, relations, odometry=Trajectory(t=t, poses=poses))
    assert len(with_odometry.unmatched) == 0 and len(with_odometry.corrected) > 500
    np.testing.assert_allclose(with_odometry.translational, full.translational, atol=1e-6)
