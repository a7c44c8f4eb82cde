"""How much of the spread between runs is the metric's own sampling noise.

A run's error ``eps`` is a mean over ``N`` sampled relations, so it carries a standard error
``se = s / sqrt(N)`` (``s``: the sample std of its per-relation errors). Over the runs of a world, the
observed variance of the run means is the true between-run variance plus, on average, ``mean(se^2)``.
The **metric's share** ``mean(se^2) / var(eps)`` (sample variance, divisor ``n - 1``) says how much of
what looks like run-to-run variability is the metric's noise: near 0, the runs' differences are real;
near 1 or above, the per-run errors are too imprecise to tell runs apart.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from slamtrials.errors import MetricError

__all__ = ["standard_error", "metric_noise_share"]


def standard_error(errors: ArrayLike) -> float:
    """Standard error of the mean of per-relation ``errors`` ``[N]``: ``std(errors, ddof=1) / sqrt(N)``.

    NaN for fewer than 2 errors.
    """
    values = np.asarray(errors, dtype=np.float64)
    if len(values) < 2:
        return math.nan
    return float(np.std(values, ddof=1) / math.sqrt(len(values)))


def metric_noise_share(run_means: ArrayLike, standard_errors: ArrayLike) -> float:
    """``mean(se^2) / var(run_means)``: the metric's share of the between-run variance of one world.

    Parameters
    ----------
    run_means:
        ``[R]`` per-run mean errors (m or rad).
    standard_errors:
        ``[R]`` their standard errors, same units.

    Returns
    -------
    float
        The share (0 when every standard error is 0); NaN for fewer than 2 runs, for a non-finite
        standard error, or when the run means do not vary (but their standard errors do).

    Raises
    ------
    MetricError
        Arrays of different lengths.
    """
    means = np.asarray(run_means, dtype=np.float64)
    se = np.asarray(standard_errors, dtype=np.float64)
    if means.shape != se.shape or means.ndim != 1:
        raise MetricError(f"run means {means.shape} and standard errors {se.shape} must be 1-D of one length")
    if len(means) < 2 or not np.all(np.isfinite(se)):
        return math.nan
    noise = float(np.mean(se**2))
    if noise == 0.0:
        return 0.0
    spread = float(np.var(means, ddof=1))
    return noise / spread if spread > 0.0 else math.nan
