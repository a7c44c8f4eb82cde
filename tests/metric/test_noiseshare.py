"""The metric's share of the between-run variance, checked against a simulated campaign of known spread."""

import math

import numpy as np
import pytest

from slamtrials.errors import MetricError
from slamtrials.metric import metric_noise_share, standard_error


def test_standard_error_is_std_over_root_n():
    errors = np.array([1.0, 2.0, 4.0, 7.0])
    assert standard_error(errors) == pytest.approx(np.std(errors, ddof=1) / 2.0)
    assert math.isnan(standard_error([3.0]))


def _campaign(rng, runs, relations, between_sd, within_sd):
    """Runs whose true means spread by ``between_sd``; each scored on ``relations`` noisy relations."""
    true_means = 1.0 + between_sd * rng.standard_normal(runs)
    samples = true_means[:, None] + within_sd * rng.standard_normal((runs, relations))
    return samples.mean(axis=1), np.array([standard_error(s) for s in samples])


def test_share_estimates_the_noise_fraction_of_the_observed_variance():
    rng = np.random.default_rng(7)
    shares = []
    for _ in range(200):
        means, se = _campaign(rng, runs=10, relations=400, between_sd=0.0, within_sd=1.0)
        shares.append(metric_noise_share(means, se))
    # no real spread between runs: all observed variance is noise, so the share is about 1
    assert np.median(shares) == pytest.approx(1.0, abs=0.15)

    means, se = _campaign(rng, runs=40, relations=400, between_sd=0.5, within_sd=1.0)
    # noise variance 1/400 against a real variance of 0.25: about 1 %
    assert metric_noise_share(means, se) < 0.03


def test_share_edge_cases():
    assert metric_noise_share([1.0, 2.0], [0.0, 0.0]) == 0.0
    assert math.isnan(metric_noise_share([1.0], [0.1]))
    assert math.isnan(metric_noise_share([1.0, 1.0], [0.1, 0.1]))
    assert math.isnan(metric_noise_share([1.0, 2.0], [0.1, math.nan]))
    with pytest.raises(MetricError):
        metric_noise_share([1.0, 2.0], [0.1])
