"""The fit of how the chance of a short reading grows with the wall's range (``short_rate``,
``short_range_scale``, ``short_range_shape``; :mod:`slamtrials.sim.shortrate`).

A returned beam whose wall is at ``r`` reads short, as the laser fit counts it, with probability

    q(r) = f + (1 - f) seen(r) p(r),   p(r) = rate (1 - exp(-(r / scale)^shape)),

``seen`` the chance that a short reading lies beyond the short-reading cut (given per beam by the
caller) and ``f`` the normal tail's false alarms. The beams are pooled in range bins of
:data:`BIN_WIDTH` (their mean ``seen`` and range stand for them), and ``(rate, scale, shape)`` maximise
the binomial likelihood of the bins' short counts (Nelder-Mead from a fixed start, so the same data give
the same values). The constant model (``scale`` 0: ``q = f + (1 - f) seen p``) is kept unless the rise
raises the log-likelihood by more than :data:`MIN_GAIN` (a likelihood-ratio test of the two added
values at about the 5 % level).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize

from slamtrials import stablemath

__all__ = ["ShortChance", "fit_short_chance", "BIN_WIDTH", "MIN_GAIN"]

#: Width (m) of the range bins the beams are pooled in.
BIN_WIDTH = 0.05
#: Least gain in log-likelihood for the rise to replace the constant rate (chi-square, 2 degrees of
#: freedom, 95 %: 5.99 / 2).
MIN_GAIN = 3.0
#: Bounds of the fitted scale (m) and shape.
SCALE_BOUNDS = (0.05, 1000.0)
SHAPE_BOUNDS = (0.2, 10.0)


@dataclass(frozen=True)
class ShortChance:
    """The fitted chance of a short reading: ``rate`` alone when ``scale`` is 0, else the rise."""

    rate: float
    scale: float
    shape: float

    def at(self, r: NDArray[np.float64]) -> NDArray[np.float64]:
        """float64 ``[N]``: the chance for walls at ``r`` ``[N]`` (m)."""
        if self.scale <= 0.0:
            return np.full(r.shape, self.rate)
        return self.rate * (1.0 - stablemath.exp(-stablemath.power(np.maximum(r, 0.0) / self.scale, self.shape)))


def _bins(r, short, seen):
    index = np.floor(np.maximum(r, 0.0) / BIN_WIDTH).astype(np.int64)
    size = int(index.max()) + 1 if index.size else 1
    n = np.bincount(index, minlength=size).astype(np.float64)
    keep = n > 0
    k = np.bincount(index, weights=short.astype(np.float64), minlength=size)[keep]
    mean_seen = np.bincount(index, weights=seen, minlength=size)[keep] / n[keep]
    mean_r = np.bincount(index, weights=r, minlength=size)[keep] / n[keep]
    return n[keep], k, mean_seen, mean_r


def _log_likelihood(q, n, k):
    q = np.clip(q, 1e-12, 1.0 - 1e-12)
    return float(np.sum(k * stablemath.log(q) + (n - k) * stablemath.log(1.0 - q)))


def fit_short_chance(
    r: NDArray[np.float64], short: NDArray[np.bool_], seen: NDArray[np.float64], false_alarm: float
) -> ShortChance:
    """The chance of a short reading by range, fitted to the returned beams: walls at ``r`` ``[N]`` (m),
    whether each read short ``[N]``, the chance ``seen`` ``[N]`` that a short reading of it would be seen as
    one, and the false-alarm chance of a beam that did not read short (see the module docstring)."""
    n, k, seen_bin, r_bin = _bins(np.asarray(r, dtype=np.float64), short, np.asarray(seen, dtype=np.float64))
    f = float(false_alarm)
    exposure = float(np.sum(n * seen_bin))
    constant = min(max((float(np.sum(k)) - f * float(np.sum(n))) / max((1.0 - f) * exposure, 1e-12), 0.0), 0.999)
    base = _log_likelihood(f + (1.0 - f) * seen_bin * constant, n, k)
    if float(np.sum(k)) < 10.0 or r_bin.size < 3:
        return ShortChance(constant, 0.0, 1.0)

    def cost(x):
        rate = 1.0 / (1.0 + math.exp(-x[0]))
        scale = min(max(math.exp(x[1]), SCALE_BOUNDS[0]), SCALE_BOUNDS[1])
        shape = min(max(math.exp(x[2]), SHAPE_BOUNDS[0]), SHAPE_BOUNDS[1])
        p = rate * (1.0 - stablemath.exp(-stablemath.power(r_bin / scale, shape)))
        return -_log_likelihood(f + (1.0 - f) * seen_bin * p, n, k)

    start = np.array([math.log(max(constant, 1e-3) / (1.0 - max(constant, 1e-3))), math.log(3.0), 0.0])
    best = minimize(cost, start, method="Nelder-Mead", options={"xatol": 1e-6, "fatol": 1e-6, "maxiter": 4000})
    if -float(best.fun) - base <= MIN_GAIN:
        return ShortChance(constant, 0.0, 1.0)
    rate = 1.0 / (1.0 + math.exp(-float(best.x[0])))
    scale = min(max(math.exp(float(best.x[1])), SCALE_BOUNDS[0]), SCALE_BOUNDS[1])
    shape = min(max(math.exp(float(best.x[2])), SHAPE_BOUNDS[0]), SHAPE_BOUNDS[1])
    return ShortChance(min(rate, 0.999), scale, shape)
