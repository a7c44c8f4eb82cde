"""Automatic relation sampling from a ground-truth trajectory (Amigoni, Castelli, Luperto, IROS 2018).

1. Pilot: draw ``n0`` pairs (default 500) of ground-truth poses uniformly at random, ``t1 < t2``, and take
   the means and sample standard deviations ``s_t``, ``s_r`` of their translational and rotational errors.
2. Sample size ``N = ceil(z^2 s^2 / d^2)`` for translation (margin ``d_t``) and rotation (``d_r``); the
   relation count is ``max(N_t, N_r)`` within the rule's floor and cap. The margins are 1 % of the pilot's
   mean errors under the default ``precise`` rule, 0.02 m and 0.02 rad under the paper's
   (:class:`~slamtrials.metric.rule.SamplingRule`). ``z`` is the two-sided normal quantile of the
   confidence (default 99 %: 2.576) unless another is asked for.
3. Draw that many fresh pairs (a new sample, not the pilot extended) and compute their errors.

Pairs are drawn among the ground-truth poses that the estimate covers (an estimated pose within the
matching tolerance, directly or through the odometry), so every sampled relation has an estimated
counterpart. A pair of one pose with itself is never drawn: the second index is drawn among the other
``n - 1`` poses, which gives the same distribution as drawing and discarding ``t1 == t2``. Pairs are
drawn with replacement, independently, as the method's normal approximation assumes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import MetricError
from slamtrials.geometry import ominus
from slamtrials.metric.matching import DEFAULT_TOLERANCE, check_trajectory, lookup_poses
from slamtrials.metric.quantiles import critical_value
from slamtrials.metric.relerrors import RelationErrors, relative_pose_errors
from slamtrials.metric.rule import SamplingRule
from slamtrials.record import Relations, Trajectory

__all__ = [
    "sample_size",
    "draw_pairs",
    "relations_between",
    "SampledRelations",
    "sample_relations",
]


def sample_size(std: float, margin: float, critical: float) -> int:
    """Sample size ``ceil(critical^2 * std^2 / margin^2)`` that estimates a mean to +-``margin``.

    Parameters
    ----------
    std:
        (Estimated) standard deviation of the quantity, in its units.
    margin:
        Margin of error ``d``, same units, positive.
    critical:
        The quantile ``z`` of the confidence level (:func:`~slamtrials.metric.quantiles.critical_value`).

    Returns
    -------
    int
        The count; 0 when ``std`` is 0. A relative slack of 1e-9 keeps an exact integer from rounding up.

    Raises
    ------
    MetricError
        Non-finite or negative ``std``, non-positive ``margin``.
    """
    if not (margin > 0) or not math.isfinite(margin):
        raise MetricError(f"the margin of error must be a positive number, got {margin}")
    if not (std >= 0) or not math.isfinite(std):
        raise MetricError(f"cannot size a sample from a standard deviation of {std}")
    exact = (critical * std / margin) ** 2
    return int(math.ceil(exact * (1.0 - 1e-9)))


def _needed(std: float, margin: float, critical: float) -> int:
    """:func:`sample_size`, and 0 for a zero margin of a zero spread (a relative margin of a perfect estimate)."""
    if margin == 0.0 and std == 0.0:
        return 0
    return sample_size(std, margin, critical)


def draw_pairs(n: int, count: int, rng: np.random.Generator) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Draw ``count`` pairs of distinct indices in ``[0, n)`` uniformly, each ordered ``i < j``.

    Parameters
    ----------
    n:
        Number of poses to draw from (at least 2).
    count:
        Number of pairs.
    rng:
        Source of randomness.

    Returns
    -------
    i, j:
        int64 ``[count]`` arrays with ``i < j``.
    """
    if n < 2:
        raise MetricError(f"need at least 2 poses to draw pairs from, got {n}")
    a = rng.integers(0, n, size=count)
    b = rng.integers(0, n - 1, size=count)
    b = b + (b >= a)
    return np.minimum(a, b).astype(np.int64), np.maximum(a, b).astype(np.int64)


def relations_between(truth: Trajectory, i: NDArray[np.int64], j: NDArray[np.int64]) -> Relations:
    """Relations between ground-truth poses ``i`` and ``j``: times and ``delta* = x*(t_i)^-1 x*(t_j)``."""
    return Relations(t1=truth.t[i].copy(), t2=truth.t[j].copy(), delta=ominus(truth.poses[i], truth.poses[j]))


@dataclass(frozen=True, eq=False)
class SampledRelations:
    """The outcome of :func:`sample_relations`.

    Attributes
    ----------
    relations:
        The ``count`` sampled relations (ground-truth timestamps and relative poses).
    errors:
        Their errors against the estimate (all matched).
    first, second:
        int64 ``[count]`` indices into ``truth`` of each relation's two poses (``first < second``).
    pilot_relations, pilot_errors:
        The pilot sample and its errors.
    mean_t, mean_r:
        Means of the pilot's translational and rotational errors.
    margin_t, margin_r:
        The margins of error used (absolute, or the relative margin times the pilot's means).
    std_t, std_r:
        Sample standard deviations (divisor ``n0 - 1``) of the pilot's translational (m) and rotational
        (rad) errors (squared units when the errors are squared).
    critical:
        The quantile ``z`` used.
    needed_t, needed_r:
        ``ceil(z^2 s^2 / d^2)`` for translation and rotation.
    count:
        Number of relations drawn: ``max(needed_t, needed_r, min_relations)``, capped at ``max_relations``.
    capped:
        True when the cap cut the count.
    covered:
        Number of ground-truth poses the estimate covers (the poses pairs were drawn from).
    rule:
        The sampling rule used.
    """

    relations: Relations
    errors: RelationErrors
    first: NDArray[np.int64]
    second: NDArray[np.int64]
    pilot_relations: Relations
    pilot_errors: RelationErrors
    mean_t: float
    mean_r: float
    margin_t: float
    margin_r: float
    std_t: float
    std_r: float
    critical: float
    needed_t: int
    needed_r: int
    count: int
    capped: bool
    covered: int
    rule: SamplingRule


def _errors_for(
    truth: Trajectory, estimated: NDArray[np.float64], corrected: NDArray[np.bool_], i, j, squared: bool
) -> tuple[Relations, RelationErrors]:
    relations = relations_between(truth, i, j)
    translational, rotational = relative_pose_errors(
        ominus(estimated[i], estimated[j]), relations.delta, squared=squared
    )
    errors = RelationErrors(
        translational=translational,
        rotational=rotational,
        index=np.arange(len(i), dtype=np.int64),
        unmatched=np.empty(0, dtype=np.int64),
        corrected=np.flatnonzero(corrected[i] | corrected[j]),
        n_relations=len(i),
        squared=squared,
    )
    return relations, errors


def sample_relations(
    truth: Trajectory,
    estimate: Trajectory,
    *,
    rng: np.random.Generator | int,
    rule: SamplingRule = SamplingRule(),
    tolerance: float = DEFAULT_TOLERANCE,
    interpolate: bool = False,
    odometry: Trajectory | None = None,
) -> SampledRelations:
    """Sample relations from ``truth`` by ``rule`` (pilot, then N fresh pairs) and evaluate ``estimate`` on them.

    Parameters
    ----------
    truth:
        Ground-truth trajectory (world frame), timestamps strictly increasing.
    estimate:
        Estimated trajectory (any frame), matched to the ground-truth timestamps.
    rng:
        Generator, or an integer seed turned into one.
    rule:
        Pilot size, confidence, margins, quantile, floor and cap of the relation count (:class:`SamplingRule`).
    tolerance, interpolate, odometry:
        Matching of the estimate to the ground-truth timestamps (:func:`~slamtrials.metric.matching.lookup_poses`).

    Returns
    -------
    SampledRelations

    Raises
    ------
    MetricError
        Bad trajectories, bad settings, or an estimate that covers fewer than 2 ground-truth poses.
    """
    rng = np.random.default_rng(rng)
    check_trajectory(truth, "truth")
    squared = rule.squared
    critical = critical_value(rule.confidence, distribution=rule.distribution, dof=rule.pilot - 1, sides=rule.sides)
    found = lookup_poses(estimate, truth.t, tolerance=tolerance, interpolate=interpolate, odometry=odometry)
    covered = np.flatnonzero(found.found)
    if len(covered) < 2:
        raise MetricError(
            f"the estimate covers {len(covered)} of the {len(truth)} ground-truth poses (within {tolerance} s); need at least 2",
            what="estimate",
        )
    sub_truth = Trajectory(t=truth.t[covered], poses=truth.poses[covered])
    estimated = found.poses[covered]
    corrected = found.corrected[covered]

    i, j = draw_pairs(len(covered), rule.pilot, rng)
    pilot_relations, pilot_errors = _errors_for(sub_truth, estimated, corrected, i, j, squared)
    std_t = float(np.std(pilot_errors.translational, ddof=1))
    std_r = float(np.std(pilot_errors.rotational, ddof=1))
    mean_t = float(np.mean(pilot_errors.translational))
    mean_r = float(np.mean(pilot_errors.rotational))
    margin_t, margin_r = rule.margins(mean_t, mean_r)
    needed_t = _needed(std_t, margin_t, critical)
    needed_r = _needed(std_r, margin_r, critical)
    wanted = max(needed_t, needed_r, rule.min_relations)
    count = min(wanted, rule.max_relations)

    i, j = draw_pairs(len(covered), count, rng)
    relations, errors = _errors_for(sub_truth, estimated, corrected, i, j, squared)
    return SampledRelations(
        relations=relations,
        errors=errors,
        first=covered[i].astype(np.int64),
        second=covered[j].astype(np.int64),
        pilot_relations=pilot_relations,
        pilot_errors=pilot_errors,
        mean_t=mean_t,
        mean_r=mean_r,
        margin_t=margin_t,
        margin_r=margin_r,
        std_t=std_t,
        std_r=std_r,
        critical=critical,
        needed_t=needed_t,
        needed_r=needed_r,
        count=count,
        capped=wanted > rule.max_relations,
        covered=len(covered),
        rule=rule,
    )
