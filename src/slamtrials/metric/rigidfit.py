"""The rigid motion (rotation and translation, no scale) that best puts one set of 2-D points onto another.

:func:`fit_rigid_2d` is the least-squares fit ``argmin sum_k |R(theta) p_k + t - q_k|^2``, in closed form
(the 2-D case of Kabsch / Umeyama without scale):

    a_k = p_k - mean(p),  b_k = q_k - mean(q)
    theta = atan2(sum(a_x b_y - a_y b_x), sum(a_x b_x + a_y b_y)),  t = mean(q) - R(theta) mean(p)

:func:`align_estimate` applies it to a run: the SLAM estimate (map frame) fitted onto the ground truth
(world frame), which gives ``world_from_map``, the pose of the map frame in the world frame. The fit is
symmetric: the inverse motion is the least-squares fit of the truth onto the estimate.

Same bits on every machine: the sums are ``math.fsum`` (exactly rounded) and the angle's functions the C
library's, so the fit depends on no SIMD or BLAS code path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials import stablemath
from slamtrials.geometry import as_poses, compose, inverse

__all__ = ["EstimateAlignment", "fit_rigid_2d", "align_estimate"]

Method = Literal["least squares", "first pose"]


def fit_rigid_2d(source: ArrayLike, target: ArrayLike) -> NDArray[np.float64] | None:
    """The rigid motion ``(x, y, theta)`` minimizing ``sum |R source_k + t - target_k|^2``.

    Parameters
    ----------
    source, target:
        ``[N, 2]`` corresponding points (m), finite.

    Returns
    -------
    ``[3]`` the motion as a pose (m, m, rad): ``target_k ~ compose(motion, source_k)``; None when ``source``
    has no spread (all points equal, or N = 0).
    """
    p = np.asarray(source, dtype=np.float64)
    q = np.asarray(target, dtype=np.float64)
    if p.shape != q.shape or p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"source {p.shape} and target {q.shape} must both be [N, 2]")
    n = len(p)
    if n == 0 or not (np.ptp(p[:, 0]) > 0.0 or np.ptp(p[:, 1]) > 0.0):
        return None
    p_mean = (math.fsum(p[:, 0]) / n, math.fsum(p[:, 1]) / n)
    q_mean = (math.fsum(q[:, 0]) / n, math.fsum(q[:, 1]) / n)
    ax, ay = p[:, 0] - p_mean[0], p[:, 1] - p_mean[1]
    bx, by = q[:, 0] - q_mean[0], q[:, 1] - q_mean[1]
    s_cos = math.fsum(ax * bx) + math.fsum(ay * by)
    s_sin = math.fsum(ax * by) - math.fsum(ay * bx)
    theta = float(stablemath.arctan2(s_sin, s_cos))
    c, s = float(stablemath.cos(theta)), float(stablemath.sin(theta))
    tx = q_mean[0] - (c * p_mean[0] - s * p_mean[1])
    ty = q_mean[1] - (s * p_mean[0] + c * p_mean[1])
    return np.array([tx, ty, theta])


@dataclass(frozen=True)
class EstimateAlignment:
    """A run's SLAM estimate placed on its ground truth by a rigid motion.

    Attributes
    ----------
    world_from_map:
        ``[3]`` (x m, y m, theta rad): the pose of the map frame in the world frame; a map-frame point
        ``m`` is at ``transform_points(world_from_map, m)`` in the world frame.
    rms_m:
        Root mean square distance (m) between the aligned estimated positions and the true ones, over the
        frames used.
    frames:
        Frames the fit used (estimate and truth both finite).
    method:
        ``"least squares"``, or ``"first pose"`` when the estimate does not move (no direction to fit):
        ``world_from_map = truth[0] (+) (-)estimate[0]``.
    """

    world_from_map: NDArray[np.float64]
    rms_m: float
    frames: int
    method: Method


def align_estimate(estimate: ArrayLike, truth: ArrayLike) -> EstimateAlignment:
    """The least-squares rigid fit of the estimated positions onto the true ones (module docstring).

    Parameters
    ----------
    estimate:
        ``[T, 3]`` the SLAM estimate (map frame; m, m, rad); rows with a non-finite value are left out.
    truth:
        ``[T, 3]`` the true poses at the same frames (world frame).

    Raises
    ------
    ValueError
        Shapes differ, or no row has both a finite estimated and a finite true pose.
    """
    estimated, true_poses = as_poses(estimate), as_poses(truth)
    if estimated.shape != true_poses.shape or estimated.ndim != 2:
        raise ValueError(f"estimate {estimated.shape} and truth {true_poses.shape} must both be [T, 3]")
    used = np.isfinite(estimated).all(axis=1) & np.isfinite(true_poses).all(axis=1)
    if not used.any():
        raise ValueError("no frame has both a finite estimated and a finite true pose")
    method: Method = "least squares"
    motion = fit_rigid_2d(estimated[used, :2], true_poses[used, :2])
    if motion is None:
        first = int(np.argmax(used))
        motion = compose(true_poses[first], inverse(estimated[first]))
        method = "first pose"
    placed = compose(motion, estimated[used])
    gaps2 = (placed[:, 0] - true_poses[used, 0]) ** 2 + (placed[:, 1] - true_poses[used, 1]) ** 2
    rms = math.sqrt(math.fsum(gaps2) / len(gaps2))
    return EstimateAlignment(world_from_map=motion, rms_m=rms, frames=int(used.sum()), method=method)
