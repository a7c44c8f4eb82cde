"""Per-environment statistics over runs: the paper's Definition III.3 plus a confidence interval.

Each run ``r`` in an environment gives one value (e.g. its mean translational error ``eps_t(r)``). The
paper reports the mean and the standard deviation with divisor ``|R_E|`` (population form, as printed
and as its code computes it); slamtrials reports that, the sample form (divisor ``|R_E| - 1``), and a
confidence interval of the mean, ``mean +- q * s_sample / sqrt(n)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from slamtrials.errors import MetricError
from slamtrials.metric.quantiles import Distribution, critical_value

__all__ = ["EnvironmentStats", "environment_stats"]


@dataclass(frozen=True)
class EnvironmentStats:
    """Mean, spread and confidence interval of one per-run quantity over the runs of an environment.

    Attributes
    ----------
    n:
        Number of runs.
    mean:
        Mean over runs (units of the values, e.g. m).
    std_population:
        Standard deviation with divisor ``n`` (the paper's ``s``); 0 for one run.
    std_sample:
        Standard deviation with divisor ``n - 1``; NaN for one run.
    ci_low, ci_high:
        Confidence interval of the mean, ``mean -+ half_width``; NaN for one run.
    half_width:
        ``q * std_sample / sqrt(n)``.
    confidence:
        Confidence level of the interval.
    """

    n: int
    mean: float
    std_population: float
    std_sample: float
    ci_low: float
    ci_high: float
    half_width: float
    confidence: float


def environment_stats(
    values: ArrayLike, *, confidence: float = 0.99, distribution: Distribution = "t", sides: int = 2
) -> EnvironmentStats:
    """Statistics of per-run values ``[R]`` of one environment.

    Parameters
    ----------
    values:
        ``[R]`` one value per run (e.g. mean translational error of each run, m).
    confidence:
        Confidence level of the interval (default 0.99, the paper's).
    distribution, sides:
        Quantile of the interval: ``"t"`` with ``R - 1`` degrees of freedom (default: exact for normally
        distributed per-run errors, which matters with 5 to 10 runs) or ``"normal"`` (the IROS 2018
        paper's, too narrow with few runs: 93.8 % true coverage for a "99 %" interval at R = 5); two-sided
        by default. Use the run-count rule's quantile, so that a campaign stopped by it has ``half_width <= d``.

    Returns
    -------
    EnvironmentStats

    Raises
    ------
    MetricError
        No values, or a non-finite one.
    """
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    n = len(v)
    if n == 0:
        raise MetricError("no runs: cannot compute statistics over an empty set of runs")
    if not np.isfinite(v).all():
        i = int(np.argmax(~np.isfinite(v)))
        raise MetricError(f"run {i} has a non-finite value {v[i]}", what="runs", index=i)
    mean = float(np.mean(v))
    std_population = float(np.std(v, ddof=0))
    if n < 2:
        nan = math.nan
        return EnvironmentStats(n, mean, std_population, nan, nan, nan, nan, confidence)
    std_sample = float(np.std(v, ddof=1))
    q = critical_value(confidence, distribution=distribution, dof=n - 1, sides=sides)
    half = q * std_sample / math.sqrt(n)
    return EnvironmentStats(n, mean, std_population, std_sample, mean - half, mean + half, half, confidence)
