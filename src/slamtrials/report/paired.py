"""The paired comparison of one world's runs in two campaigns that share their recorded data (a replay).

Run ``i`` of a replay was computed from the same recorded laser and odometry as run ``i`` of its
source, so the two errors of one run are correlated (the same path, the same hard corners): their
difference ``d_i = b_i - a_i`` varies far less than either error. The paired t-test works on the
differences alone: mean ``d`` with standard error ``s_d / sqrt(n)`` and ``n - 1`` degrees of freedom.
Welch's test on the same numbers would use ``sqrt(s_a^2/n + s_b^2/n)``, which ignores the correlation and
is much wider when the correlation is positive (and still valid, only weak).

The Wilcoxon signed-rank test of the same differences is the check: it assumes only that the
differences are symmetric about their median, not normal, so a verdict that rests on one wild run shows
up as a disagreement. It cannot go below ``2 / 2^n`` (0.0625 for 5 pairs), so with very few pairs it
cannot agree with a significant t-test at all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats

__all__ = ["PairedResult", "paired_test", "signed_rank_p"]


@dataclass(frozen=True)
class PairedResult:
    """The paired comparison of ``b [n]`` with ``a [n]``, run ``k`` of each from the same recorded data.

    Attributes
    ----------
    n:
        Number of pairs.
    mean_a, mean_b:
        Means of the two samples (units of the values); ``difference = mean_b - mean_a`` is the mean of
        the run-by-run differences.
    std_a, std_b:
        Sample standard deviations (divisor ``n - 1``) of the two samples.
    std_difference:
        Sample standard deviation of the differences ``b_k - a_k``.
    correlation:
        Pearson correlation of ``a`` and ``b`` over the pairs, ``(s_a^2 + s_b^2 - s_d^2) / (2 s_a s_b)``: the
        pairing narrows the interval (against Welch's) only where it is positive; NaN when a side is constant.
    difference, se, dof, t, p:
        Mean difference, its standard error ``std_difference / sqrt(n)``, ``n - 1``, ``difference / se``
        (``+-inf`` when ``se == 0`` and the mean differs from 0, 0 when both are 0) and the two-sided
        p-value (equal to ``scipy.stats.ttest_rel(b, a)``).
    ci_low, ci_high:
        ``difference -+ q se``, ``q`` the Student t quantile of ``confidence`` with ``dof``.
    confidence:
        Level of the interval.
    wilcoxon_p:
        Two-sided p-value of the Wilcoxon signed-rank test of the differences (zero differences dropped,
        as Wilcoxon did; exact for up to 50 pairs without ties; 1 when every difference is 0).

    Every statistic but ``n`` and the means is NaN when there are fewer than 2 pairs.
    """

    n: int
    mean_a: float
    mean_b: float
    std_a: float
    std_b: float
    std_difference: float
    correlation: float
    difference: float
    se: float
    dof: float
    t: float
    p: float
    ci_low: float
    ci_high: float
    confidence: float
    wilcoxon_p: float


def signed_rank_p(differences: ArrayLike) -> float:
    """Two-sided Wilcoxon signed-rank p-value of ``differences [n]`` (zeros dropped; 1 if all are 0)."""
    d = np.asarray(differences, dtype=np.float64).reshape(-1)
    if len(d) == 0 or not np.any(d != 0.0):
        return 1.0
    return float(stats.wilcoxon(d, zero_method="wilcox", alternative="two-sided").pvalue)


def paired_test(a: ArrayLike, b: ArrayLike, *, confidence: float = 0.95) -> PairedResult:
    """Paired t-test and interval of ``mean(b - a)`` for pairs ``(a[k], b[k])``, with the Wilcoxon check.

    Parameters
    ----------
    a, b:
        ``[n]`` values of the same runs in the two campaigns, in the same order.
    confidence:
        Level of the interval, strictly between 0 and 1.
    """
    a = np.asarray(a, dtype=np.float64).reshape(-1)
    b = np.asarray(b, dtype=np.float64).reshape(-1)
    if len(a) != len(b):
        raise ValueError(f"paired samples must have the same length, got {len(a)} and {len(b)}")
    if len(a) == 0:
        raise ValueError("need at least one pair")
    if not (0.0 < confidence < 1.0):
        raise ValueError(f"confidence must be strictly between 0 and 1, got {confidence}")
    n = len(a)
    d = b - a
    ma, mb = float(a.mean()), float(b.mean())
    diff = float(d.mean())
    nan = math.nan
    if n < 2:
        return PairedResult(n, ma, mb, nan, nan, nan, nan, diff, nan, nan, nan, nan, nan, nan, confidence, nan)
    sd = float(d.std(ddof=1))
    sa, sb = float(a.std(ddof=1)), float(b.std(ddof=1))
    correlation = (sa * sa + sb * sb - sd * sd) / (2.0 * sa * sb) if sa > 0.0 and sb > 0.0 else nan
    se = sd / math.sqrt(n)
    dof = float(n - 1)
    if se == 0.0:
        t = 0.0 if diff == 0.0 else math.copysign(math.inf, diff)
        p = 1.0 if diff == 0.0 else 0.0
    else:
        t = diff / se
        p = float(2.0 * stats.t.sf(abs(t), dof))
    half = float(stats.t.ppf(0.5 + confidence / 2.0, dof)) * se
    return PairedResult(
        n,
        ma,
        mb,
        sa,
        sb,
        sd,
        min(1.0, max(-1.0, correlation)) if math.isfinite(correlation) else nan,
        diff,
        se,
        dof,
        t,
        p,
        diff - half,
        diff + half,
        confidence,
        signed_rank_p(d),
    )
