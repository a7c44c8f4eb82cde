"""Particle weights and resampling as GMapping's code does them (spec/gmapping.md, section 4)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from slamtrials import stablemath

__all__ = ["normalized_weights", "effective_sample_size", "systematic_resample"]


def normalized_weights(log_weights: NDArray[np.float64], ogain: float) -> NDArray[np.float64]:
    """``w_i = exp((l_i - max l) / (ogain * N))`` normalised to sum 1; float64 ``[N]``."""
    n = log_weights.shape[0]
    w = stablemath.exp((log_weights - log_weights.max()) / (ogain * n))
    return w / w.sum()


def effective_sample_size(weights: NDArray[np.float64]) -> float:
    """``Neff = 1 / sum w_i^2`` of normalised weights."""
    return float(1.0 / np.sum(weights * weights))


def systematic_resample(weights: NDArray[np.float64], u: float) -> NDArray[np.intp]:
    """Low-variance resampling: indexes of the particles drawn, intp ``[N]``, in increasing order.

    ``N`` equally spaced pointers ``(u + k) / N`` (``u`` uniform in [0, 1), drawn by the caller) pick
    the particle whose cumulative weight interval holds them.
    """
    n = weights.shape[0]
    cumulative = np.cumsum(weights)
    cumulative /= cumulative[-1]
    pointers = (u + np.arange(n)) / n
    return np.minimum(np.searchsorted(cumulative, pointers, side="right"), n - 1)
