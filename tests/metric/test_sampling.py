"""Automatic relation sampling: the sample-size formula, the pairs, seeding, and the paper's Fig. 3 check."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from slamtrials.errors import MetricError
from slamtrials.geometry import compose
from slamtrials.metric import (
    SamplingRule,
    critical_value,
    draw_pairs,
    evaluate_relations,
    sample_relations,
    sample_size,
)
from slamtrials.metric.kernels import relative_poses
from slamtrials.metric.relerrors import relative_pose_errors
from slamtrials.record import Trajectory


def _drive(n: int, seed: int) -> tuple[Trajectory, Trajectory]:
    """A 10 Hz drive (0.05 m steps, wandering heading) and an odometry-like estimate that drifts from it."""
    rng = np.random.default_rng(seed)
    steps = np.column_stack([np.full(n - 1, 0.05), np.zeros(n - 1), rng.normal(0.0, 0.05, n - 1)])
    noisy = steps * np.array([1.02, 1.0, 1.0]) + np.column_stack(
        [rng.normal(0, 0.004, n - 1), rng.normal(0, 0.004, n - 1), rng.normal(0.002, 0.004, n - 1)]
    )
    truth = np.zeros((n, 3))
    estimate = np.zeros((n, 3))
    for k in range(n - 1):
        truth[k + 1] = compose(truth[k], steps[k])
        estimate[k + 1] = compose(estimate[k], noisy[k])
    t = 100.0 + 0.1 * np.arange(n)
    return Trajectory(t=t, poses=truth), Trajectory(t=t, poses=estimate)


def _all_pairs_errors(truth: Trajectory, estimate: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    i, j = np.triu_indices(len(truth), k=1)
    return relative_pose_errors(
        relative_poses(estimate.poses, i, estimate.poses, j), relative_poses(truth.poses, i, truth.poses, j)
    )


def test_sample_size_formula():
    assert sample_size(0.1, 0.02, 2.0) == 100  # exactly 100: not rounded up to 101 by float error
    assert sample_size(0.1, 0.02, 2.5758293035489) == math.ceil(2.5758293035489**2 * 0.01 / 0.0004)  # 165.86 -> 166
    assert sample_size(0.0, 0.02, 2.5) == 0
    with pytest.raises(MetricError, match="margin"):
        sample_size(0.1, 0.0, 2.0)
    with pytest.raises(MetricError, match="standard deviation"):
        sample_size(math.nan, 0.1, 2.0)


def test_pairs_are_distinct_ordered_and_uniform():
    rng = np.random.default_rng(0)
    i, j = draw_pairs(5, 200_000, rng)
    assert (i < j).all() and i.min() >= 0 and j.max() <= 4
    counts = np.bincount(i * 5 + j, minlength=25).reshape(5, 5)
    upper = counts[np.triu_indices(5, k=1)]
    assert upper.sum() == 200_000
    np.testing.assert_allclose(upper / 200_000, 0.1, atol=0.005)  # 10 unordered pairs, equally likely
    with pytest.raises(MetricError, match="at least 2 poses"):
        draw_pairs(1, 3, rng)


def test_sampling_follows_the_rule_and_is_seeded():
    truth, estimate = _drive(600, seed=1)
    paper = SamplingRule(rule="paper")
    a = sample_relations(truth, estimate, rng=7, rule=paper)
    b = sample_relations(truth, estimate, rng=7, rule=paper)
    np.testing.assert_array_equal(a.relations.t1, b.relations.t1)
    np.testing.assert_array_equal(a.errors.translational, b.errors.translational)
    assert len(a.pilot_relations) == 500
    z = critical_value(0.99)
    assert a.critical == z
    assert a.std_t == pytest.approx(np.std(a.pilot_errors.translational, ddof=1))
    assert a.needed_t == math.ceil(z**2 * a.std_t**2 / 0.02**2 * (1 - 1e-9))
    assert a.needed_r == math.ceil(z**2 * a.std_r**2 / 0.02**2 * (1 - 1e-9))
    assert a.count == len(a.relations) == len(a.errors) == max(a.needed_t, a.needed_r)
    assert (a.relations.t1 < a.relations.t2).all()
    # a fresh sample, not the pilot extended
    assert not np.array_equal(a.relations.t1[:500], a.pilot_relations.t1)
    # the sampled relations evaluate to the same errors through the general path
    again = evaluate_relations(estimate, a.relations)
    np.testing.assert_allclose(again.translational, a.errors.translational, atol=1e-12)
    c = sample_relations(truth, estimate, rng=8, rule=paper)
    assert not np.array_equal(a.relations.t1, c.relations.t1)


def test_precise_rule_sizes_on_a_margin_relative_to_the_pilot_mean():
    truth, estimate = _drive(600, seed=1)
    a = sample_relations(truth, estimate, rng=7)
    assert a.rule.rule == "precise" and a.rule.relative_margin == 0.01
    z = critical_value(0.99)
    assert a.mean_t == pytest.approx(np.mean(a.pilot_errors.translational))
    assert a.margin_t == pytest.approx(0.01 * a.mean_t) and a.margin_r == pytest.approx(0.01 * a.mean_r)
    assert a.needed_t == math.ceil(z**2 * a.std_t**2 / a.margin_t**2 * (1 - 1e-9))
    assert a.needed_r == math.ceil(z**2 * a.std_r**2 / a.margin_r**2 * (1 - 1e-9))
    wanted = max(a.needed_t, a.needed_r, 5000)
    assert a.count == min(wanted, 200_000) and a.capped == (wanted > 200_000)
    # frame indices of every relation: the relations are those poses' truth
    np.testing.assert_array_equal(truth.t[a.first], a.relations.t1)
    np.testing.assert_array_equal(truth.t[a.second], a.relations.t2)
    # a larger relative margin needs fewer relations, down to the floor
    loose = sample_relations(truth, estimate, rng=7, rule=SamplingRule(relative_margin=0.2, min_relations=50))
    assert loose.count == max(loose.needed_t, loose.needed_r, 50) < a.count


def test_rules_fill_their_fields_and_refuse_the_other_kind_of_margin():
    precise, paper = SamplingRule(), SamplingRule(rule="paper")
    assert (precise.min_relations, precise.max_relations, precise.margin_t) == (5000, 200_000, None)
    assert (paper.relative_margin, paper.margin_t, paper.margin_r, paper.min_relations) == (None, 0.02, 0.02, 2)
    assert SamplingRule(rule="paper", margin_t=0.05).margin_r == 0.02
    with pytest.raises(ValidationError, match="margin_t is an absolute margin of the paper rule"):
        SamplingRule(margin_t=0.05)
    with pytest.raises(ValidationError, match="relative_margin belongs to rule: precise"):
        SamplingRule(rule="paper", relative_margin=0.01)
    with pytest.raises(ValidationError, match="rule"):
        SamplingRule(rule="loose")
    # a stored rule reads back as itself
    assert SamplingRule.model_validate(paper.model_dump(mode="json")) == paper


def test_sampling_options_cap_and_bad_input():
    truth, estimate = _drive(300, seed=2)
    capped = sample_relations(
        truth, estimate, rng=0, rule=SamplingRule(rule="paper", margin_t=1e-4, max_relations=1000)
    )
    assert capped.capped and capped.count == 1000
    perfect = sample_relations(truth, truth, rng=0)
    assert perfect.count == 5000 and perfect.needed_t == 0 and perfect.needed_r == 0
    perfect_paper = sample_relations(truth, truth, rng=0, rule=SamplingRule(rule="paper"))
    assert perfect_paper.count == 2 and np.allclose(perfect.errors.translational, 0.0, atol=1e-12)
    t_based = sample_relations(truth, estimate, rng=0, rule=SamplingRule(distribution="t", sides=1, confidence=0.99))
    assert t_based.critical == pytest.approx(2.334, abs=1e-3)
    squared = sample_relations(
        truth, estimate, rng=0, rule=SamplingRule(rule="paper", squared=True, margin_t=1e-3, margin_r=1e-3)
    )
    assert squared.errors.squared
    far = Trajectory(t=truth.t + 1000.0, poses=truth.poses)
    with pytest.raises(MetricError, match="covers 0 of the 300"):
        sample_relations(truth, far, rng=0)
    with pytest.raises(ValidationError, match="pilot"):
        SamplingRule(pilot=1)
    with pytest.raises(ValidationError, match="min_relations"):
        SamplingRule(min_relations=10, max_relations=5)


@pytest.mark.slow  # by simulation: 400 samplings
@pytest.mark.parametrize(("confidence", "binding"), [(0.99, "t"), (0.95, "t"), (0.99, "r")])
def test_sampled_mean_falls_within_the_margin_at_the_stated_confidence(confidence, binding):
    """The paper's Fig. 3 check, by simulation.

    One trajectory (1,200 poses: 719,400 pairs). Its all-pairs mean error is the quantity the sampling
    estimates. The whole procedure (pilot of 500, N from the rule, N fresh pairs) is repeated 400 times
    with different seeds; the sampled mean must fall within +-d of the all-pairs mean in about the
    stated fraction of repeats (binomial spread at 400 repeats: about 1 % at 95 %, 0.5 % at 99 %), and
    the spread of the sampled means must match s / sqrt(N).
    """
    truth, estimate = _drive(1200, seed=5)
    all_t, all_r = _all_pairs_errors(truth, estimate)
    population = all_t if binding == "t" else all_r
    z = critical_value(confidence)
    margin = z * population.std() / math.sqrt(400)  # about 400 relations per sample
    margins = {"margin_t": margin, "margin_r": 10.0} if binding == "t" else {"margin_t": 100.0, "margin_r": margin}
    means, counts = [], []
    for seed in range(400):
        sampled = sample_relations(
            truth, estimate, rng=seed, rule=SamplingRule(rule="paper", confidence=confidence, **margins)
        )
        errors = sampled.errors.translational if binding == "t" else sampled.errors.rotational
        means.append(errors.mean())
        counts.append(sampled.count)
    means = np.array(means)
    coverage = np.mean(np.abs(means - population.mean()) <= margin)
    assert abs(coverage - confidence) <= 0.035, f"coverage {coverage:.3f} at confidence {confidence}"
    expected_spread = population.std() / math.sqrt(np.mean(counts))
    assert means.std() == pytest.approx(expected_spread, rel=0.15)
    assert 300 < np.mean(counts) < 500
