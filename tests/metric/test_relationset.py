"""One relation set per run: drawn once, every estimate of the run scored on the same pairs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.errors import MetricError
from slamtrials.metric import (
    RelationSet,
    SamplingRule,
    draw_relation_set,
    sample_relations,
    score_on_set,
)
from slamtrials.record import Trajectory

from .test_sampling import _all_pairs_errors, _drive


def test_scoring_the_sizing_estimate_reproduces_the_sampling():
    truth, estimate = _drive(800, seed=3)
    relation_set, sampled = draw_relation_set(truth, estimate, seed=11)
    assert len(relation_set) == sampled.count and relation_set.frames == 800 and relation_set.seed == 11
    score = score_on_set(relation_set, truth, estimate)
    np.testing.assert_array_equal(score.errors.translational, sampled.errors.translational)
    np.testing.assert_array_equal(score.errors.rotational, sampled.errors.rotational)
    assert score.eps_t == float(np.mean(sampled.errors.translational))
    assert score.se_t == pytest.approx(np.std(sampled.errors.translational, ddof=1) / math.sqrt(sampled.count))
    # the same seed draws the same set; the set does not depend on a later estimate
    again, _ = draw_relation_set(truth, estimate, seed=11)
    np.testing.assert_array_equal(again.first, relation_set.first)


@pytest.mark.slow  # by simulation: 40 pairs of sets
def test_two_estimates_on_one_set_differ_more_precisely_than_on_two_sets():
    """Paired scoring: the metric's sampling noise cancels from the difference of two estimates."""
    truth, _ = _drive(1000, seed=4)
    rng = np.random.default_rng(0)
    estimate = Trajectory(t=truth.t, poses=truth.poses + rng.normal(0.0, 0.05, truth.poses.shape))
    other = Trajectory(t=truth.t, poses=estimate.poses + rng.normal(0.0, 0.01, truth.poses.shape))
    rule = SamplingRule(rule="paper", margin_t=0.01, margin_r=0.01)  # a few hundred relations: the noise is large
    paired, unpaired = [], []
    for seed in range(40):
        relation_set, _ = draw_relation_set(truth, estimate, seed=seed, rule=rule)
        a = score_on_set(relation_set, truth, estimate)
        b = score_on_set(relation_set, truth, other)
        paired.append(b.eps_t - a.eps_t)
        separate, _ = draw_relation_set(truth, other, seed=1000 + seed, rule=rule)
        unpaired.append(score_on_set(separate, truth, other).eps_t - a.eps_t)
    assert np.std(paired) < 0.5 * np.std(unpaired)


def test_set_of_another_run_and_uncovered_frames_are_refused():
    truth, estimate = _drive(300, seed=5)
    relation_set, _ = draw_relation_set(truth, estimate, seed=1)
    shorter_truth, shorter_estimate = _drive(250, seed=5)
    with pytest.raises(MetricError, match="drawn from a run of 300 frames, but this run has 250"):
        score_on_set(relation_set, shorter_truth, shorter_estimate)
    partial = Trajectory(t=estimate.t[:100], poses=estimate.poses[:100])
    with pytest.raises(MetricError, match="no pose within"):
        score_on_set(relation_set, truth, partial, tolerance=0.001)
    with pytest.raises(MetricError, match="0 <= first < second < 300"):
        RelationSet(
            first=np.array([5]),
            second=np.array([5]),
            frames=300,
            seed=0,
            rule=SamplingRule(),
            sized_on="estimate",
            mean_t=0.0,
            mean_r=0.0,
            std_t=0.0,
            std_r=0.0,
            needed_t=0,
            needed_r=0,
            capped=False,
        )


@pytest.mark.slow  # by simulation: 200 samplings
@pytest.mark.parametrize("binding", ["t", "r"])
def test_precise_rule_mean_falls_within_one_percent_at_its_confidence(binding):
    """The precise rule's promise, by simulation: the sampled mean is within 1 % of the all-pairs mean
    (the quantity the sampling estimates) in about 99 % of repeats."""
    truth, estimate = _drive(900, seed=6)
    all_t, all_r = _all_pairs_errors(truth, estimate)
    population = all_t if binding == "t" else all_r
    rule = SamplingRule(confidence=0.95, relative_margin=0.02, min_relations=2)
    hits, repeats = 0, 200
    for seed in range(repeats):
        sampled = sample_relations(truth, estimate, rng=seed, rule=rule)
        errors = sampled.errors.translational if binding == "t" else sampled.errors.rotational
        margin = 0.02 * population.mean()
        hits += abs(errors.mean() - population.mean()) <= margin
    coverage = hits / repeats
    # both components are sized; the larger N binds, so coverage of either is at least the confidence
    # (up to the pilot's own uncertainty and the binomial spread of 200 repeats: about 1.5 %)
    assert coverage >= 0.95 - 0.035, f"coverage {coverage:.3f}"
