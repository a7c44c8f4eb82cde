"""A run's two numbers: ``eps_t`` and ``eps_r``, its mean errors over relations sampled from its truth.

Relations are drawn from the run's ground truth by the IROS 2018 rule
(:func:`slamtrials.metric.sample_relations`: pilot, then ``N = ceil(z^2 s^2 / d^2)`` fresh pairs) with
``numpy.random.default_rng(seed)``; the estimate is matched to the truth's timestamps within
``metric.tolerance`` and the odometry carries any frame without an estimate. With the default settings
this is what ``slamtrials evaluate RUN --seed SEED`` computes on the run folder.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from slamtrials.campaign.config import MetricSettings
from slamtrials.errors import MetricError
from slamtrials.metric import SampledRelations, sample_relations
from slamtrials.record import RunRecord, Trajectory

__all__ = ["RunScore", "score_run"]


@dataclass(frozen=True, eq=False)
class RunScore:
    """The evaluation of one run.

    Attributes
    ----------
    eps_t, eps_r:
        Mean translational (m) and rotational (rad) error over the sampled relations.
    sampled:
        The sampled relations and their per-relation errors.
    """

    eps_t: float
    eps_r: float
    sampled: SampledRelations


def score_run(record: RunRecord, seed: int, metric: MetricSettings) -> RunScore:
    """Evaluate ``record.estimate`` (``[T, 3]``, map frame) against ``record.truth`` (``[T, 3]``).

    Raises
    ------
    MetricError
        The record has no estimate, or the metric cannot evaluate it.
    """
    if record.estimate is None:
        raise MetricError("the run has no SLAM estimate to evaluate", what="estimate")
    truth = Trajectory(t=record.t, poses=record.truth)
    estimate = Trajectory(t=record.t, poses=np.asarray(record.estimate, dtype=np.float64))
    odometry = Trajectory(t=record.t, poses=record.odometry)
    sampled = sample_relations(
        truth, estimate, rng=int(seed), rule=metric.rule, tolerance=metric.tolerance, odometry=odometry
    )
    errors = sampled.errors
    return RunScore(float(np.mean(errors.translational)), float(np.mean(errors.rotational)), sampled)
