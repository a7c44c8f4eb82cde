"""GMapping's odometry motion model (spec/gmapping.md, section 2), for all particles at once."""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials.geometry import ominus1

__all__ = ["motion_sigmas", "sample_motion"]


def motion_sigmas(
    increment: NDArray[np.float64], srr: float, srt: float, str_: float, stt: float
) -> NDArray[np.float64]:
    """Standard deviations (m, m, rad) of the noise added to an odometry increment ``(dx, dy, dth)``.

    ``increment`` is the motion in the previous odometry pose's frame, float64 ``[3]``.
    """
    dx, dy, dth = (abs(float(v)) for v in increment)
    return np.array(
        [
            srr * dx + str_ * dth + 0.3 * srr * dy,
            srr * dy + str_ * dth + 0.3 * srr * dx,
            stt * dth + srt * math.hypot(dx, dy),
        ]
    )


def sample_motion(
    poses: NDArray[np.float64],
    odometry_old: NDArray[np.float64],
    odometry_new: NDArray[np.float64],
    srr: float,
    srt: float,
    str_: float,
    stt: float,
    rng: np.random.Generator,
) -> NDArray[np.float64]:
    """Move every particle by its own noisy sample of the odometry increment.

    Parameters
    ----------
    poses:
        float64 ``[N, 3]`` particle poses (map frame).
    odometry_old, odometry_new:
        float64 ``[3]`` consecutive odometry poses (odometry frame).
    srr, srt, str_, stt:
        The noise parameters (:class:`~slamtrials.slam.gmapping.config.GMappingConfig`).
    rng:
        Source of the ``N x 3`` standard normal draws (always drawn, so the stream does not depend on
        whether the robot moved).

    Returns
    -------
    float64 ``[N, 3]``: each pose composed with ``increment + noise``, angle wrapped to [-pi, pi).
    """
    increment = ominus1(odometry_old, odometry_new)
    sigmas = motion_sigmas(increment, srr, srt, str_, stt)
    return _moved(
        np.ascontiguousarray(poses, dtype=np.float64), increment, sigmas, rng.standard_normal((poses.shape[0], 3))
    )


@njit(cache=True, nogil=True)
def _moved(poses, increment, sigmas, normals):  # pragma: no cover - compiled
    """``compose(poses[p], wrapped(increment + normals[p] * sigmas))`` for every particle ``p``: the
    arithmetic of :func:`slamtrials.geometry.compose` and ``wrap_angle``, one particle at a time
    (the array versions cost about 20 numpy calls per reading)."""
    out = np.empty_like(poses)
    for p in range(poses.shape[0]):
        bx = increment[0] + normals[p, 0] * sigmas[0]
        by = increment[1] + normals[p, 1] * sigmas[1]
        bt = (increment[2] + normals[p, 2] * sigmas[2] + math.pi) % (2.0 * math.pi) - math.pi
        c = math.cos(poses[p, 2])
        s = math.sin(poses[p, 2])
        out[p, 0] = poses[p, 0] + c * bx - s * by
        out[p, 1] = poses[p, 1] + s * bx + c * by
        out[p, 2] = (poses[p, 2] + bt + math.pi) % (2.0 * math.pi) - math.pi
    return out
