"""The per-trajectory summary that the Freiburg program prints: ``Mean, Std, Min, Max, NumMeasures``."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["ErrorSummary", "summarize", "SUMMARY_HEADER"]

#: The header line of the summary, as the Freiburg program prints it.
SUMMARY_HEADER = "Mean, Std, Min, Max, NumMeasures"


@dataclass(frozen=True)
class ErrorSummary:
    """Statistics of one kind of per-relation error (translational or rotational, never both mixed).

    Attributes
    ----------
    mean:
        Mean error (units of the errors: m, rad, or their squares).
    std:
        Sample standard deviation (divisor ``n - 1``); NaN for fewer than 2 errors.
    min, max:
        Smallest and largest error.
    n:
        Number of errors (``NumMeasures``).

    All statistics are NaN when ``n == 0``.
    """

    mean: float
    std: float
    min: float
    max: float
    n: int

    def as_tuple(self) -> tuple[float, float, float, float, int]:
        """``(mean, std, min, max, n)``, the order of :data:`SUMMARY_HEADER`."""
        return (self.mean, self.std, self.min, self.max, self.n)


def summarize(errors: ArrayLike) -> ErrorSummary:
    """Summarize per-relation errors ``[M]`` as mean, sample standard deviation, min, max and count.

    Parameters
    ----------
    errors:
        ``[M]`` errors of one kind (e.g. translational, m).

    Returns
    -------
    ErrorSummary
    """
    e = np.asarray(errors, dtype=np.float64).reshape(-1)
    n = len(e)
    if n == 0:
        return ErrorSummary(math.nan, math.nan, math.nan, math.nan, 0)
    std = float(np.std(e, ddof=1)) if n > 1 else math.nan
    return ErrorSummary(float(np.mean(e)), std, float(np.min(e)), float(np.max(e)), n)
