"""The localization error metric: relation matching, per-relation errors, sampling, statistics, run counts.

Pure functions over arrays and the dataclasses of :mod:`slamtrials.record`; no file I/O, no printing.

- :mod:`~slamtrials.metric.matching`: relation timestamps -> estimated poses (nearest within 0.1 s,
  optional interpolation, odometry correction), unmatched relations reported.
- :mod:`~slamtrials.metric.relerrors`: per-relation translational / rotational errors (Kuemmerle form).
- :mod:`~slamtrials.metric.summary`: ``Mean, Std, Min, Max, NumMeasures`` as the Freiburg program prints.
- :mod:`~slamtrials.metric.quantiles`: critical values of a confidence level.
- :mod:`~slamtrials.metric.rule`: the relation-sampling rule (:class:`SamplingRule`).
- :mod:`~slamtrials.metric.sampling`: automatic relation sampling (pilot, ``N = ceil(z^2 s^2 / d^2)``).
- :mod:`~slamtrials.metric.relationset`: a run's one relation set, and any estimate scored on it.
- :mod:`~slamtrials.metric.noiseshare`: standard errors, and the metric's share of the between-run variance.
- :mod:`~slamtrials.metric.runcount`: the run-count rule of the paper's Section III-C.
- :mod:`~slamtrials.metric.stats`: per-environment mean, population and sample std, confidence interval.
"""

from __future__ import annotations

from slamtrials.metric.matching import (
    DEFAULT_TOLERANCE,
    PoseLookup,
    RelationMatch,
    check_relations,
    check_trajectory,
    lookup_poses,
    match_relations,
)
from slamtrials.metric.noiseshare import metric_noise_share, standard_error
from slamtrials.metric.quantiles import critical_value
from slamtrials.metric.relationset import RelationSet, SetScore, draw_relation_set, score_on_set
from slamtrials.metric.relerrors import RelationErrors, evaluate_relations, relative_pose_errors
from slamtrials.metric.rule import SamplingRule
from slamtrials.metric.runcount import RunCount, replay_run_count, runs_needed
from slamtrials.metric.sampling import SampledRelations, draw_pairs, relations_between, sample_relations, sample_size
from slamtrials.metric.stats import EnvironmentStats, environment_stats
from slamtrials.metric.summary import SUMMARY_HEADER, ErrorSummary, summarize

__all__ = [
    "DEFAULT_TOLERANCE",
    "PoseLookup",
    "RelationMatch",
    "check_relations",
    "check_trajectory",
    "lookup_poses",
    "match_relations",
    "critical_value",
    "RelationErrors",
    "evaluate_relations",
    "relative_pose_errors",
    "RunCount",
    "replay_run_count",
    "runs_needed",
    "SampledRelations",
    "SamplingRule",
    "draw_pairs",
    "relations_between",
    "sample_relations",
    "sample_size",
    "EnvironmentStats",
    "environment_stats",
    "metric_noise_share",
    "RelationSet",
    "SetScore",
    "draw_relation_set",
    "score_on_set",
    "standard_error",
    "SUMMARY_HEADER",
    "ErrorSummary",
    "summarize",
]
