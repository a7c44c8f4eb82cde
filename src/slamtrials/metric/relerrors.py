"""Per-relation localization errors in the Kuemmerle et al. form, as the Freiburg program computes them.

For a relation with true relative pose ``delta*`` and estimated relative pose ``delta`` (both SE(2),
the pose at ``t2`` seen from the pose at ``t1``)::

    translational error = || t(delta) - t(delta*) ||                 (m)
    rotational error    = | wrap(theta(delta) - theta(delta*)) |      (rad)

absolute values by default, their squares on request (the program's ``-q``).

Relation to evo's RPE: evo takes ``E = delta*^-1 * delta`` and reports ``||t(E)||`` =
``||R(delta*)^T (t(delta) - t(delta*))||``, which is the same number (a rotation keeps lengths), and the
angle of ``rot(E)``, which is the rotational error above; so for one pair of poses the two agree even when
the rotations differ (``tests/metric/test_relerrors.py`` checks it against evo 1.38). They differ in
which pairs are evaluated (evo: poses a fixed number of frames or metres apart; here: the given
relations) and in how timestamps are matched. The right-handed form ``||t(delta * delta*^-1)||`` would
differ when the rotations differ; neither program uses it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials import stablemath
from slamtrials.geometry import as_poses, wrap_angle
from slamtrials.metric.matching import DEFAULT_TOLERANCE, match_relations
from slamtrials.record import Relations, Trajectory

__all__ = ["relative_pose_errors", "RelationErrors", "evaluate_relations"]


def relative_pose_errors(
    delta: ArrayLike, delta_true: ArrayLike, *, squared: bool = False
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Translational and rotational error of estimated relative poses against true ones.

    Parameters
    ----------
    delta:
        ``[..., 3]`` estimated relative poses (m, m, rad).
    delta_true:
        ``[..., 3]`` true relative poses, broadcast against ``delta``.
    squared:
        Return squared errors (m^2, rad^2) instead of absolute ones (m, rad).

    Returns
    -------
    translational, rotational:
        ``[...]`` arrays: ``||t(delta) - t(delta_true)||`` and ``|wrap(theta(delta) - theta(delta_true))|``,
        or their squares.
    """
    delta = as_poses(delta)
    delta_true = as_poses(delta_true)
    dx = delta[..., 0] - delta_true[..., 0]
    dy = delta[..., 1] - delta_true[..., 1]
    dtheta = wrap_angle(delta[..., 2] - delta_true[..., 2])
    if squared:
        return dx * dx + dy * dy, dtheta * dtheta
    return stablemath.hypot(dx, dy), np.abs(dtheta)


@dataclass(frozen=True, eq=False)
class RelationErrors:
    """Errors of the matched relations of one evaluation.

    Attributes
    ----------
    translational:
        float64 ``[M]`` translational error per matched relation: m, or m^2 when ``squared``.
    rotational:
        float64 ``[M]`` rotational error per matched relation: rad, or rad^2 when ``squared``.
    index:
        int64 ``[M]`` index of each matched relation in the evaluated relations.
    unmatched:
        int64 ``[U]`` indices of the relations without an estimated counterpart (no pose within the
        tolerance, even through the odometry).
    corrected:
        int64 ``[C]`` indices of matched relations that needed the odometry correction.
    n_relations:
        Number of relations evaluated (``M + U``).
    squared:
        Whether the errors are squared.
    """

    translational: NDArray[np.float64]
    rotational: NDArray[np.float64]
    index: NDArray[np.int64]
    unmatched: NDArray[np.int64]
    corrected: NDArray[np.int64]
    n_relations: int
    squared: bool = False

    def __len__(self) -> int:
        return len(self.translational)

    @property
    def units(self) -> tuple[str, str]:
        """Units of (translational, rotational): ``("m", "rad")`` or ``("m^2", "rad^2")``."""
        return ("m^2", "rad^2") if self.squared else ("m", "rad")


def evaluate_relations(
    estimate: Trajectory,
    relations: Relations,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
    interpolate: bool = False,
    odometry: Trajectory | None = None,
    squared: bool = False,
    allow_outside: bool = False,
) -> RelationErrors:
    """Match ``estimate`` to ``relations`` and compute each matched relation's errors.

    Parameters
    ----------
    estimate:
        Estimated trajectory (any frame: the errors do not depend on it), timestamps strictly increasing.
    relations:
        True relations, ``K`` of them.
    tolerance, interpolate, odometry, allow_outside:
        Matching options, see :func:`slamtrials.metric.matching.match_relations`.
    squared:
        Squared errors instead of absolute ones.

    Returns
    -------
    RelationErrors

    Raises
    ------
    MetricError
        Bad trajectories or relations (see :func:`~slamtrials.metric.matching.match_relations`).
    """
    match = match_relations(
        estimate,
        relations,
        tolerance=tolerance,
        interpolate=interpolate,
        odometry=odometry,
        allow_outside=allow_outside,
    )
    index = np.flatnonzero(match.matched)
    if len(index) == len(relations):  # all matched: no gathered copies
        translational, rotational = relative_pose_errors(match.delta, relations.delta, squared=squared)
    else:
        translational, rotational = relative_pose_errors(match.delta[index], relations.delta[index], squared=squared)
    return RelationErrors(
        translational=translational,
        rotational=rotational,
        index=index,
        unmatched=match.unmatched,
        corrected=np.flatnonzero(match.corrected),
        n_relations=len(relations),
        squared=squared,
    )
