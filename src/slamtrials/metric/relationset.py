"""One relation set per run: pairs of its frames drawn once from its ground truth, and every estimate of
the run (the SLAM estimate, the online one, the odometry, a replay's) scored on that same set.

Scoring two estimates of one run on the same relations makes their difference a paired one: the metric's
sampling noise is common to both and cancels from the difference, instead of adding to it.

The set is drawn by :func:`~slamtrials.metric.sampling.sample_relations` (pilot, then ``N`` fresh
pairs by the run's :class:`~slamtrials.metric.rule.SamplingRule`), sized on one estimate (the run's SLAM
estimate); it holds frame indices, so it is tied to the run's frames and refuses a run of another length.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import MetricError
from slamtrials.geometry import ominus
from slamtrials.metric.matching import DEFAULT_TOLERANCE, check_trajectory, lookup_poses
from slamtrials.metric.noiseshare import standard_error
from slamtrials.metric.relerrors import RelationErrors, relative_pose_errors
from slamtrials.metric.rule import SamplingRule
from slamtrials.metric.sampling import SampledRelations, relations_between, sample_relations
from slamtrials.record import Relations, Trajectory

__all__ = ["RelationSet", "SetScore", "draw_relation_set", "score_on_set"]


@dataclass(frozen=True, eq=False)
class RelationSet:
    """The relations a run is scored on, as pairs of its frames.

    Attributes
    ----------
    first, second:
        int64 ``[N]`` frame indices of each relation's two poses, ``first < second``.
    frames:
        Frame count ``T`` of the run the set was drawn from.
    seed:
        Seed of the draw (``numpy.random.default_rng(seed)``).
    rule:
        The sampling rule.
    sized_on:
        Which estimate's pilot errors sized the set (``"estimate"``: the run's SLAM estimate).
    mean_t, mean_r, std_t, std_r:
        Mean and sample std of the pilot's translational (m) and rotational (rad) errors.
    needed_t, needed_r:
        Relation counts the rule asked for translation and rotation.
    capped:
        Whether the rule's cap cut the count.
    """

    first: NDArray[np.int64]
    second: NDArray[np.int64]
    frames: int
    seed: int
    rule: SamplingRule
    sized_on: str
    mean_t: float
    mean_r: float
    std_t: float
    std_r: float
    needed_t: int
    needed_r: int
    capped: bool

    def __post_init__(self) -> None:
        first, second = np.asarray(self.first), np.asarray(self.second)
        if first.shape != second.shape or first.ndim != 1:
            raise MetricError(f"relation set: index arrays of shapes {first.shape} and {second.shape}")
        if len(first) and (first.min() < 0 or second.max() >= self.frames or (first >= second).any()):
            raise MetricError(
                f"relation set: indices must satisfy 0 <= first < second < {self.frames} (the run's frames)"
            )

    def __len__(self) -> int:
        return len(self.first)

    @classmethod
    def from_sampling(cls, sampled: SampledRelations, frames: int, seed: int, sized_on: str) -> RelationSet:
        """The set of a :func:`sample_relations` result drawn from a truth of ``frames`` poses."""
        return cls(
            first=sampled.first,
            second=sampled.second,
            frames=int(frames),
            seed=int(seed),
            rule=sampled.rule,
            sized_on=sized_on,
            mean_t=sampled.mean_t,
            mean_r=sampled.mean_r,
            std_t=sampled.std_t,
            std_r=sampled.std_r,
            needed_t=sampled.needed_t,
            needed_r=sampled.needed_r,
            capped=sampled.capped,
        )

    def relations(self, truth: Trajectory) -> Relations:
        """The relations in time form (``t1``, ``t2``, ``delta*``) on ``truth`` (``[T, 3]``, the run's)."""
        self._check_run(len(truth))
        return relations_between(truth, self.first, self.second)

    def _check_run(self, frames: int) -> None:
        if frames != self.frames:
            raise MetricError(
                f"the relation set was drawn from a run of {self.frames} frames, but this run has {frames}: "
                "it is another run's",
                what="relations",
            )


@dataclass(frozen=True, eq=False)
class SetScore:
    """One estimate scored on a run's relation set.

    Attributes
    ----------
    eps_t, eps_r:
        Mean translational (m) and rotational (rad) error over the set (squared units when the rule is).
    se_t, se_r:
        Their standard errors (std of the per-relation errors over ``sqrt(N)``).
    errors:
        The per-relation errors (all relations matched).
    """

    eps_t: float
    eps_r: float
    se_t: float
    se_r: float
    errors: RelationErrors


def draw_relation_set(
    truth: Trajectory,
    estimate: Trajectory,
    *,
    seed: int,
    rule: SamplingRule = SamplingRule(),
    tolerance: float = DEFAULT_TOLERANCE,
    odometry: Trajectory | None = None,
    sized_on: str = "estimate",
) -> tuple[RelationSet, SampledRelations]:
    """Draw a run's relation set from ``truth`` (``[T, 3]``), sized on ``estimate``'s pilot errors.

    Returns the set and the full sampling (whose errors are ``estimate``'s on the set).
    """
    sampled = sample_relations(truth, estimate, rng=int(seed), rule=rule, tolerance=tolerance, odometry=odometry)
    return RelationSet.from_sampling(sampled, len(truth), seed, sized_on), sampled


def score_on_set(
    relation_set: RelationSet,
    truth: Trajectory,
    estimate: Trajectory,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
    odometry: Trajectory | None = None,
    what: str = "estimate",
) -> SetScore:
    """Score ``estimate`` on ``relation_set`` (frames of ``truth``, ``[T, 3]``, world frame).

    The estimate is matched to the truth's timestamps within ``tolerance``; ``odometry`` carries frames
    without an estimated pose (as in sampling), so an estimate of the set's own run gives the same errors
    as the sampling that drew the set.

    Raises
    ------
    MetricError
        A set of another run (another frame count), bad trajectories, or an estimate that has no pose for a
        frame of the set.
    """
    check_trajectory(truth, "truth")
    relation_set._check_run(len(truth))
    found = lookup_poses(estimate, truth.t, tolerance=tolerance, odometry=odometry)
    used = np.concatenate([relation_set.first, relation_set.second])
    missing = used[~found.found[used]]
    if len(missing):
        k = int(missing.min())
        raise MetricError(
            f"{what}: no pose within {tolerance:g} s of frame {k} (t = {float(truth.t[k])!r} s) of the relation set",
            what=what,
        )
    relations = relations_between(truth, relation_set.first, relation_set.second)
    squared = relation_set.rule.squared
    estimated = found.poses
    translational, rotational = relative_pose_errors(
        ominus(estimated[relation_set.first], estimated[relation_set.second]), relations.delta, squared=squared
    )
    corrected = found.corrected
    errors = RelationErrors(
        translational=translational,
        rotational=rotational,
        index=np.arange(len(relation_set), dtype=np.int64),
        unmatched=np.empty(0, dtype=np.int64),
        corrected=np.flatnonzero(corrected[relation_set.first] | corrected[relation_set.second]),
        n_relations=len(relation_set),
        squared=squared,
    )
    return SetScore(
        eps_t=float(np.mean(translational)),
        eps_r=float(np.mean(rotational)),
        se_t=standard_error(translational),
        se_r=standard_error(rotational),
        errors=errors,
    )
