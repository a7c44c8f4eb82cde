"""positive_mean_interval: Student t where it stays positive, a seeded bootstrap where it does not."""

import dataclasses

import numpy as np
import pytest

from slamtrials.metric import environment_stats
from slamtrials.metric.meaninterval import positive_mean_interval


def test_a_t_interval_above_zero_is_kept():
    values = [0.21, 0.23, 0.22, 0.24, 0.20]
    stats = environment_stats(values, confidence=0.95)
    interval = positive_mean_interval(values, stats)
    assert (interval.low, interval.high, interval.method) == (stats.ci_low, stats.ci_high, "Student t")


def test_skewed_runs_get_a_positive_bootstrap_interval():
    """Five runs that kept track and one that did not: the t interval reaches below zero."""
    values = [0.031, 0.029, 0.033, 0.030, 0.032, 0.40]
    stats = environment_stats(values, confidence=0.95)
    assert stats.ci_low < 0
    interval = positive_mean_interval(values, stats)
    assert 0 < interval.low < stats.mean < interval.high <= max(values)
    assert interval.low >= min(values)
    assert interval.method == "bootstrap percentile, 9999 resamples, seed 0"
    again = positive_mean_interval(values, stats)
    assert (again.low, again.high) == (interval.low, interval.high)
    other = positive_mean_interval(values, stats, seed=1)
    assert other.method.endswith("seed 1") and other.high == pytest.approx(interval.high, rel=0.2)


def test_the_bootstrap_covers_the_mean_at_the_stated_level():
    """Lognormal runs (skewed): the bootstrap interval of 30 runs covers the true mean about as often
    as it says (percentile intervals run a little short with few runs)."""
    rng = np.random.default_rng(7)
    truth = np.exp(0.5 * 1.2**2) * 0.05
    covered = 0
    trials = 200
    for _ in range(trials):
        values = 0.05 * rng.lognormal(0.0, 1.2, 30)
        stats = environment_stats(values, confidence=0.9)
        forced = dataclasses.replace(stats, ci_low=-1.0)  # take the bootstrap whatever the t interval says
        interval = positive_mean_interval(values, forced, resamples=999)
        covered += interval.low <= truth <= interval.high
    assert 0.75 <= covered / trials <= 0.97
