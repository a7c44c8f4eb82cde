"""Small robust and least-squares estimators the calibration fits are made of (no BLAS, no linalg).

The systems solved here have two to four unknowns, so they are solved by Gaussian elimination in plain
Python on the normal equations; sums are numpy reductions over float64 arrays, whose results do not
depend on the CPU's vector width beyond the usual pairwise-summation order.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "MAD_TO_SIGMA",
    "robust_sigma",
    "shortest_interval",
    "central_sigma",
    "solve_small",
    "least_squares",
    "nonnegative_least_squares",
]

#: Factor from the median absolute deviation to the standard deviation of a normal distribution.
MAD_TO_SIGMA = 1.482602218505602


def robust_sigma(values: NDArray[np.float64]) -> tuple[float, float]:
    """``(median, 1.4826 * MAD)`` of ``values`` ``[N]`` (NaN, NaN when empty)."""
    if values.size == 0:
        return math.nan, math.nan
    centre = float(np.median(values))
    return centre, MAD_TO_SIGMA * float(np.median(np.abs(values - centre)))


def shortest_interval(values: NDArray[np.float64], share: float = 0.2) -> tuple[float, float]:
    """``(centre, sigma)`` of the shortest interval holding ``share`` of ``values`` ``[N]``: its midpoint,
    and its half-width over that of a normal's central ``share`` (in sigmas).

    Unlike the median and the MAD it sits on the densest part of the values, so one-sided outliers (short
    readings, more than half of the beams at long range in a real log) do not pull it off the Gaussian
    core, as long as the core holds more than ``share`` of the values.
    """
    n = values.size
    h = int(math.ceil(share * n))
    if n < 4 or h < 2:
        return math.nan, math.nan
    v = np.sort(values, kind="stable")
    widths = v[h:] - v[: n - h]
    i = int(np.argmin(widths))
    half_normal = math.sqrt(2.0) * _erfinv(share)
    return 0.5 * float(v[i] + v[i + h]), 0.5 * float(widths[i]) / half_normal


def _erfinv(y: float) -> float:
    """Inverse error function by bisection (``0 < y < 1``; 60 halvings reach float precision)."""
    low, high = 0.0, 6.0
    for _ in range(60):
        mid = 0.5 * (low + high)
        if math.erf(mid) < y:
            low = mid
        else:
            high = mid
    return 0.5 * (low + high)


def _truncated_variance_factor(c: float) -> float:
    """Variance of a standard normal restricted to ``|z| < c``: ``1 - 2 c phi(c) / (2 Phi(c) - 1)``."""
    phi = math.exp(-0.5 * c * c) / math.sqrt(2.0 * math.pi)
    inside = math.erf(c / math.sqrt(2.0))
    return 1.0 - 2.0 * c * phi / inside


def central_sigma(values: NDArray[np.float64], cut: float = 2.5, iterations: int = 30) -> tuple[float, float, float]:
    """The standard deviation of the Gaussian core of ``values`` ``[N]`` that holds outliers.

    Starts from the shortest half (:func:`shortest_interval`), then repeatedly takes the values within ``cut`` sigmas of the
    median and their standard deviation, corrected for the truncation of a normal at ``cut`` sigmas. For
    a normal core with outliers spread far from it (short readings, unmapped objects) this converges to
    the core's sigma, where the MAD alone is pulled up by the outliers' share.

    Returns
    -------
    (centre, sigma, inside):
        The median (same unit as the values), the sigma, and the share of values within ``cut`` sigmas.
    """
    centre, sigma = shortest_interval(values)
    if not math.isfinite(sigma) or sigma <= 0.0:
        return centre, sigma, math.nan
    factor = math.sqrt(_truncated_variance_factor(cut))
    inside = np.abs(values - centre) < cut * sigma
    for _ in range(iterations):
        inside = np.abs(values - centre) < cut * sigma
        core = values[inside]
        if core.size < 10:
            break
        previous = sigma
        centre = float(np.median(core))
        sigma = float(np.sqrt(np.mean((core - centre) ** 2))) / factor
        if abs(sigma - previous) <= 1e-6 * sigma:
            break
    return centre, sigma, float(np.mean(inside))


def solve_small(matrix: list[list[float]], rhs: list[float]) -> list[float] | None:
    """Solve the ``n x n`` system by Gaussian elimination with partial pivoting; None when singular."""
    n = len(rhs)
    a = [list(map(float, row)) + [float(b)] for row, b in zip(matrix, rhs)]
    scale = max((abs(v) for row in a for v in row[:n]), default=0.0)
    if scale == 0.0:
        return None
    for col in range(n):
        pivot = max(range(col, n), key=lambda r: (abs(a[r][col]), -r))
        if abs(a[pivot][col]) <= 1e-12 * scale:
            return None
        a[col], a[pivot] = a[pivot], a[col]
        for r in range(col + 1, n):
            f = a[r][col] / a[col][col]
            for c in range(col, n + 1):
                a[r][c] -= f * a[col][c]
    x = [0.0] * n
    for r in range(n - 1, -1, -1):
        x[r] = (a[r][n] - sum(a[r][c] * x[c] for c in range(r + 1, n))) / a[r][r]
    return x


def least_squares(
    columns: list[NDArray[np.float64]], target: NDArray[np.float64], weights: NDArray[np.float64] | None = None
) -> list[float] | None:
    """Weighted least squares ``target ~ sum_j x_j columns[j]`` (each ``[N]``), from the normal equations."""
    w = np.ones_like(target) if weights is None else weights
    n = len(columns)
    normal = [[float(np.sum(w * columns[i] * columns[j])) for j in range(n)] for i in range(n)]
    rhs = [float(np.sum(w * columns[i] * target)) for i in range(n)]
    return solve_small(normal, rhs)


def nonnegative_least_squares(
    columns: list[NDArray[np.float64]], target: NDArray[np.float64], weights: NDArray[np.float64] | None = None
) -> list[float]:
    """:func:`least_squares` with every coefficient ``>= 0``: an active set by exhaustion (few unknowns).

    Every subset of the columns is fitted; among the fits whose coefficients are all non-negative, the one
    with the smallest weighted residual wins (ties: the earlier subset, fewer columns first). Columns left
    out get 0. With four or fewer columns that is at most 16 small solves.
    """
    n = len(columns)
    w = np.ones_like(target) if weights is None else weights
    best: tuple[float, list[float]] = (float(np.sum(w * target * target)), [0.0] * n)
    subsets = sorted(range(1, 1 << n), key=lambda m: (bin(m).count("1"), m))
    for mask in subsets:
        chosen = [j for j in range(n) if mask >> j & 1]
        x = least_squares([columns[j] for j in chosen], target, w)
        if x is None or min(x) < 0.0:
            continue
        fitted = np.zeros_like(target)
        for j, value in zip(chosen, x):
            fitted = fitted + value * columns[j]
        cost = float(np.sum(w * (target - fitted) ** 2))
        if cost < best[0] * (1.0 - 1e-12):
            full = [0.0] * n
            for j, value in zip(chosen, x):
                full[j] = value
            best = (cost, full)
    return best[1]
