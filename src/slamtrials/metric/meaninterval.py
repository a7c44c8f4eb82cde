"""An interval of the mean of a positive quantity that stays positive.

Per-run errors are positive and, over a handful of runs, often skewed: one run that lost track among
five that did not gives a Student t interval whose lower end is below zero, which no error can be.
Where the t interval stays above zero it is kept (it is exact for normal per-run errors and matches the
run-count rule). Where it does not, the interval is the bootstrap percentile interval of the mean: the
``(1 - c) / 2`` and ``(1 + c) / 2`` quantiles of the means of ``resamples`` resamples of the runs with
replacement, drawn from ``seed``. Every resampled mean is a mean of positive values, so the interval
stays positive. Its sums are taken one run at a time over all resamples (element-wise additions), so
the result does not depend on the CPU's vector units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from slamtrials.metric.stats import EnvironmentStats

__all__ = ["MeanInterval", "positive_mean_interval", "BOOTSTRAP_RESAMPLES"]

#: Resamples of the bootstrap interval.
BOOTSTRAP_RESAMPLES = 9999


@dataclass(frozen=True)
class MeanInterval:
    """An interval of the mean (units of the values) and how it was made.

    Attributes
    ----------
    low, high:
        Its ends.
    method:
        ``"Student t"`` or ``"bootstrap percentile, 9999 resamples, seed 0"``: said next to the figures.
    """

    low: float
    high: float
    method: str


def positive_mean_interval(
    values: ArrayLike, stats: EnvironmentStats, *, resamples: int = BOOTSTRAP_RESAMPLES, seed: int = 0
) -> MeanInterval:
    """The interval of the mean of the non-negative ``values`` ``[R]`` at ``stats.confidence``.

    Parameters
    ----------
    values:
        ``[R]`` per-run values (e.g. errors in m), all >= 0.
    stats:
        Their :func:`~slamtrials.metric.environment_stats` (Student t interval).
    resamples, seed:
        Bootstrap resamples and the seed of their draws, used only where the t interval reaches below 0.
    """
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if not (stats.ci_low <= 0.0 and len(v) >= 2 and np.all(v >= 0.0)):
        return MeanInterval(stats.ci_low, stats.ci_high, "Student t")
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    picks = rng.integers(0, len(v), size=(resamples, len(v)))
    sums = np.zeros(resamples)
    for column in range(len(v)):
        sums += v[picks[:, column]]
    means = sums / len(v)
    tail = (1.0 - stats.confidence) / 2.0
    low, high = np.quantile(means, [tail, 1.0 - tail])
    return MeanInterval(float(low), float(high), f"bootstrap percentile, {resamples} resamples, seed {seed}")
