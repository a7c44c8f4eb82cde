"""Critical values (quantiles) for confidence levels: the ``z`` of ``N = ceil(z^2 s^2 / d^2)``.

slamtrials uses the two-sided standard-normal quantile by default (2.576 at 99 %), as the paper's method
states; a Student-t quantile is available on request (the seed system used a one-sided t quantile,
2.334 at 99 % with 499 degrees of freedom, which ``critical_value(0.99, distribution="t", dof=499,
sides=1)`` reproduces).
"""

from __future__ import annotations

import math
from typing import Literal

from scipy import stats

from slamtrials.errors import MetricError

__all__ = ["Distribution", "DISTRIBUTIONS", "critical_value"]

#: The reference distributions a critical value can come from.
Distribution = Literal["normal", "t"]
DISTRIBUTIONS: tuple[str, ...] = ("normal", "t")


def critical_value(
    confidence: float, *, distribution: Distribution = "normal", dof: float | None = None, sides: int = 2
) -> float:
    """The quantile ``q`` such that a (two- or one-sided) interval of ``q`` standard errors has ``confidence``.

    Parameters
    ----------
    confidence:
        Confidence level ``1 - alpha``, strictly between 0 and 1 (e.g. 0.99).
    distribution:
        ``"normal"`` (standard normal, the default) or ``"t"`` (Student t with ``dof`` degrees of freedom).
    dof:
        Degrees of freedom of the t distribution (usually sample size - 1); required for ``"t"``,
        ignored for ``"normal"``.
    sides:
        2 (default) for the two-sided quantile ``q_{1 - alpha/2}``, 1 for the one-sided ``q_{1 - alpha}``.

    Returns
    -------
    float
        The critical value, e.g. 2.5758 for 99 % two-sided normal.

    Raises
    ------
    MetricError
        A confidence outside (0, 1), an unknown distribution, ``sides`` not 1 or 2, or a missing or
        non-positive ``dof`` for the t distribution.
    """
    if not (0.0 < confidence < 1.0):
        raise MetricError(f"confidence must be strictly between 0 and 1, got {confidence}")
    if sides not in (1, 2):
        raise MetricError(f"sides must be 1 or 2, got {sides}")
    alpha = 1.0 - confidence
    p = 1.0 - alpha / sides
    if distribution == "normal":
        return float(stats.norm.ppf(p))
    if distribution == "t":
        if dof is None or not (dof > 0) or not math.isfinite(dof):
            raise MetricError(f"the t distribution needs positive degrees of freedom, got {dof}")
        return float(stats.t.ppf(p, dof))
    raise MetricError(f"unknown distribution {distribution!r}; expected one of {', '.join(DISTRIBUTIONS)}")
