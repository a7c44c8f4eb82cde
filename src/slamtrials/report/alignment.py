"""The true trajectory of a run moved into its SLAM map's frame, for drawing both on the map (Fig. 4).

A run's ground truth is in the world frame; its SLAM estimate and final map are in the map frame, which
SLAM anchors at its first pose. :func:`align_truth` finds the rigid motion (rotation and translation, no
scale) ``map_from_world`` that puts the true positions closest to the estimated ones in the least-squares
sense, ``argmin sum_k |R p_k + t - q_k|^2`` over the poses ``k`` where both are known, in closed form
(the 2-D case of Kabsch / Umeyama without scale: :func:`slamtrials.metric.rigidfit.fit_rigid_2d`).

When the truth does not move (no direction to fit), it falls back to the first pose:
``map_from_world = estimate[0] (+) (-)truth[0]``. No random draws: the same run gives the same fit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials.geometry import as_poses, compose, inverse
from slamtrials.metric.rigidfit import fit_rigid_2d

__all__ = ["TruthAlignment", "fit_rigid_2d", "align_truth", "LEAST_SQUARES", "FIRST_POSE"]

LEAST_SQUARES = "least-squares SE(2) fit of the true positions onto the estimated ones"
FIRST_POSE = "first pose"

Method = Literal["least squares", "first pose"]


@dataclass(frozen=True)
class TruthAlignment:
    """The ground truth of one run placed in its map frame.

    Attributes
    ----------
    map_from_world:
        ``[3]`` (x m, y m, theta rad): the pose of the world frame in the map frame; a true pose ``p``
        (world frame) is at ``compose(map_from_world, p)`` in the map frame.
    truth:
        ``[T, 3]`` the true poses in the map frame (every row, also those without an estimate).
    used:
        ``[T]`` bool: the poses the fit used (truth and estimate finite).
    rms:
        Root mean square distance (m) between the aligned true and the estimated positions over ``used``.
    max_distance:
        Largest such distance (m).
    method:
        ``"least squares"``, or ``"first pose"`` when the truth does not move.
    """

    map_from_world: NDArray[np.float64]
    truth: NDArray[np.float64]
    used: NDArray[np.bool_]
    rms: float
    max_distance: float
    method: Method


def align_truth(truth: ArrayLike, estimate: ArrayLike) -> TruthAlignment:
    """Place the true trajectory in the estimate's (map) frame by a least-squares rigid fit (module docstring).

    Parameters
    ----------
    truth:
        ``[T, 3]`` true poses (world frame; m, m, rad).
    estimate:
        ``[T, 3]`` the SLAM estimate at the same timestamps (map frame); rows with a non-finite value are
        left out of the fit.

    Raises
    ------
    ValueError
        Shapes differ, or no row has both a finite true and a finite estimated pose.
    """
    true_poses, estimated = as_poses(truth), as_poses(estimate)
    if true_poses.shape != estimated.shape or true_poses.ndim != 2:
        raise ValueError(f"truth {true_poses.shape} and estimate {estimated.shape} must both be [T, 3]")
    used: NDArray[np.bool_] = np.asarray(np.isfinite(true_poses).all(axis=1) & np.isfinite(estimated).all(axis=1))
    if not used.any():
        raise ValueError("no pose has both a finite true and a finite estimated value")
    transform = fit_rigid_2d(true_poses[used, :2], estimated[used, :2])
    method: Method = "least squares"
    if transform is None:
        first = int(np.argmax(used))
        transform = compose(estimated[first], inverse(true_poses[first]))
        method = "first pose"
    aligned = compose(transform, true_poses)
    gaps = np.hypot(*(aligned[used, :2] - estimated[used, :2]).T)
    return TruthAlignment(
        map_from_world=transform,
        truth=aligned,
        used=used,
        rms=float(np.sqrt(np.mean(gaps**2))),
        max_distance=float(gaps.max()),
        method=method,
    )
