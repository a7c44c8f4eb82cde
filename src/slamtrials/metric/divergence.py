"""Which runs of a repeated experiment diverged: an error far above the typical one.

A run diverged when its error exceeds ``factor`` times the median error of all runs (default 5): a
particle filter that lost track gives errors of metres where the others give centimetres, and the
median is not moved by a few such runs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials.errors import MetricError

__all__ = ["Divergence", "divergence", "DEFAULT_DIVERGENCE_FACTOR"]

#: A run diverged when its error is above this many times the median.
DEFAULT_DIVERGENCE_FACTOR = 5.0


@dataclass(frozen=True, eq=False)
class Divergence:
    """The diverged runs of a set.

    Attributes
    ----------
    threshold:
        ``factor * median`` (units of the values).
    factor:
        The factor.
    diverged:
        bool ``[R]``: the runs above the threshold.
    share:
        Fraction of the runs that diverged.
    """

    threshold: float
    factor: float
    diverged: NDArray[np.bool_]
    share: float


def divergence(values: ArrayLike, factor: float = DEFAULT_DIVERGENCE_FACTOR) -> Divergence:
    """The runs whose value is above ``factor`` times the median of ``values`` ``[R]``.

    Raises
    ------
    MetricError
        No values, a non-finite one, or a factor that is not above 1.
    """
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if v.size == 0:
        raise MetricError("no runs: cannot tell which diverged")
    if not np.isfinite(v).all():
        i = int(np.argmax(~np.isfinite(v)))
        raise MetricError(f"run {i} has a non-finite value {v[i]}", what="runs", index=i)
    if not factor > 1.0:
        raise MetricError(f"the divergence factor must be above 1, got {factor}")
    threshold = float(factor * np.median(v))
    diverged = v > threshold
    return Divergence(threshold, float(factor), diverged, float(np.count_nonzero(diverged)) / v.size)
