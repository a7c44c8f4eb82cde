"""Evidence over several worlds: Stouffer's combined test, and intervals adjusted like the p-values.

Stouffer's test (the overall verdict of a comparison)
-----------------------------------------------------
Each world ``w`` gives a t statistic ``t_w`` of ``mean_B - mean_A`` with ``dof_w`` degrees of freedom
(paired t for a replay, Welch otherwise). Its *one-sided* tail probability, signed, becomes a standard
normal score ``z_w = sign(t_w) Phi^-1(1 - T_dof(-|t_w|))``: negative when B has the lower errors, and
exactly N(0, 1) when the two campaigns do not differ in that world. The worlds are independent (their own
runs), so ``Z = sum_w z_w / sqrt(W)`` is N(0, 1) when they differ in none, and the two-sided
``p = 2 Phi(-|Z|)``; ``Z < 0`` says B is better overall, ``Z > 0`` A.

Why one-sided scores with their sign, and why Stouffer rather than Fisher: the question is whether one
campaign is better *consistently*. Signed one-sided scores add up when the worlds agree and cancel when
B is better in one world and worse in another. Fisher's ``-2 sum log p_w`` on two-sided p-values would
call that pair "significant" (it tests "a difference somewhere, in either direction"), and Fisher on
one-sided p-values is driven by the single most extreme world. Every world counts once (equal
weights), as the paper's unit of evaluation is the environment, and the scores are free of units, so a
large building with large errors does not outweigh a small one. Unlike the sign test over worlds (which
needs 6 worlds to reach p < 0.05), three worlds with a clear effect each are enough.

Adjusted intervals
------------------
An interval shown next to a corrected verdict must be corrected the same way (:func:`interval_level`):

* ``none``: each world's own ``1 - alpha`` interval;
* ``holm``: Bonferroni's simultaneous ``1 - alpha/m`` intervals (all ``m`` cover their true differences
  together with probability at least ``1 - alpha``). An interval that excludes 0 has ``p <= alpha/m``,
  so Holm rejects it; Holm's later steps test at ``alpha/(m-1), ..., alpha`` and can call a world
  significant whose interval still reaches 0 (never the reverse). There are no simple step-down
  intervals, so this is the usual choice (R's emmeans makes it too);
* ``bh``: Benjamini and Yekutieli's false-coverage-rate intervals, ``1 - R alpha/m`` with ``R`` the
  number of worlds Benjamini-Hochberg selects (at least 1): BH rejects exactly the ``p <= R alpha/m``,
  so an interval excludes 0 exactly where the verdict is significant, and the selected intervals fail to
  cover on average at most a fraction ``alpha`` of the time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats

__all__ = ["StoufferResult", "stouffer", "one_sided_scores", "IntervalLevel", "interval_level"]


def one_sided_scores(t: ArrayLike, dof: ArrayLike) -> np.ndarray:
    """Standard normal scores ``[W]`` with the one-sided tail probabilities of ``t [W]`` under Student t ``dof [W]``.

    ``z = sign(t) Phi^-1(1 - T_dof(-|t|))``, computed from the tail so that large ``|t|`` keep their
    precision; ``t = +-inf`` gives ``+-inf``, NaN stays NaN.
    """
    t = np.asarray(t, dtype=np.float64).reshape(-1)
    dof = np.asarray(dof, dtype=np.float64).reshape(-1)
    if t.shape != dof.shape:
        raise ValueError(f"t and dof must have the same length, got {len(t)} and {len(dof)}")
    tail = stats.t.sf(np.abs(t), dof)
    return np.sign(t) * stats.norm.isf(tail)


@dataclass(frozen=True)
class StoufferResult:
    """Stouffer's combination of per-world one-sided tests (see the module docstring).

    Attributes
    ----------
    z:
        ``sum_w z_w / sqrt(W)``: negative when B is better; NaN when no world has a test, or when one
        world is infinitely in favour of each side.
    p:
        Two-sided p-value ``2 Phi(-|z|)``; NaN with ``z``.
    worlds:
        ``W``, the worlds with a finite-or-infinite score (worlds without a test are left out).
    """

    z: float
    p: float
    worlds: int


def stouffer(t: ArrayLike, dof: ArrayLike) -> StoufferResult:
    """Stouffer's equal-weight combination of the worlds' t statistics ``t [W]`` with ``dof [W]``."""
    z = one_sided_scores(t, dof)
    z = z[~np.isnan(z)]
    if len(z) == 0:
        return StoufferResult(math.nan, math.nan, 0)
    if np.isposinf(z).any() and np.isneginf(z).any():  # each side infinitely better in some world
        return StoufferResult(math.nan, math.nan, len(z))
    total = float(np.sum(np.sort(z, kind="stable")))  # sorted: the same sum whatever the order of the worlds
    combined = total / math.sqrt(len(z))
    return StoufferResult(combined, float(2.0 * stats.norm.sf(abs(combined))), len(z))


@dataclass(frozen=True)
class IntervalLevel:
    """The confidence level of the intervals shown beside corrected verdicts.

    Attributes
    ----------
    confidence:
        Level of each interval.
    label:
        What it is, for captions and column heads (e.g. ``"simultaneous 95% (Bonferroni, 3 worlds)"``).
    """

    confidence: float
    label: str


def interval_level(alpha: float, correction: str, p_adjusted: ArrayLike, *, unit: str = "world") -> IntervalLevel:
    """The level of intervals consistent with ``correction`` (see the module docstring).

    Parameters
    ----------
    alpha:
        Significance level of the verdicts.
    correction:
        ``"holm"``, ``"bh"`` or ``"none"``.
    p_adjusted:
        The adjusted p-values ``[m']`` of the family; NaN entries (worlds without a test, members left
        out of the family) do not count.
    unit:
        What one member of the family is, for the label: ``"world"`` (a comparison of two campaigns),
        ``"comparison"`` (a study's family of every axis step and world).
    """
    p = np.asarray(p_adjusted, dtype=np.float64).reshape(-1)
    m = int(np.isfinite(p).sum())
    if correction == "none" or m <= 1:
        level = 1.0 - alpha
        return IntervalLevel(level, f"{level:.0%} per {unit}" + (", unadjusted" if correction == "none" else ""))
    if correction == "holm":
        level = 1.0 - alpha / m
        return IntervalLevel(level, f"simultaneous {1 - alpha:.0%} (Bonferroni, {m} {unit}s: each at {_pct(level)})")
    if correction == "bh":
        selected = int((p[np.isfinite(p)] <= alpha).sum())
        level = 1.0 - max(selected, 1) * alpha / m
        return IntervalLevel(
            level, f"FCR-adjusted {1 - alpha:.0%} (Benjamini-Yekutieli, {selected} of {m} selected: {_pct(level)})"
        )
    raise ValueError(f"unknown correction {correction!r}; use 'holm', 'bh' or 'none'")


def _pct(level: float) -> str:
    text = f"{100 * level:.2f}".rstrip("0").rstrip(".")
    return f"{text}%"
