"""SE(2) poses as float64 arrays of shape ``[..., 3]`` holding (x, y, theta).

x and y are in metres, theta in radians, counter-clockwise from the x axis. All functions broadcast
over leading dimensions and never loop in Python.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials import stablemath

__all__ = [
    "Pose1Like",
    "wrap_angle",
    "compose",
    "inverse",
    "ominus",
    "transform_points",
    "as_poses",
    "wrap_angle1",
    "compose1",
    "ominus1",
    "interpolate",
]

#: One pose ``(x, y, theta)`` (or one point) given as numbers: a sequence of floats or a 1-D array.
#: The single-pose functions read its elements one by one as Python floats.
Pose1Like: TypeAlias = "Sequence[float] | NDArray[Any]"


def as_poses(poses: ArrayLike) -> NDArray[np.float64]:
    """Return ``poses`` as a float64 array whose last axis has length 3."""
    array = np.asarray(poses, dtype=np.float64)
    if array.shape[-1:] != (3,):
        raise ValueError(f"poses must have shape [..., 3], got {array.shape}")
    return array


def wrap_angle(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles (rad) into [-pi, pi)."""
    a = np.asarray(angle, dtype=np.float64)
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def compose(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Pose composition ``a (+) b``: ``b`` expressed in the frame of ``a``, returned in a's parent frame.

    Shapes ``[..., 3]`` broadcast against each other.
    """
    a = as_poses(a)
    b = as_poses(b)
    c, s = stablemath.cos(a[..., 2]), stablemath.sin(a[..., 2])
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 0] + c * b[..., 0] - s * b[..., 1]
    out[..., 1] = a[..., 1] + s * b[..., 0] + c * b[..., 1]
    out[..., 2] = wrap_angle(a[..., 2] + b[..., 2])
    return out


def inverse(a: ArrayLike) -> NDArray[np.float64]:
    """Inverse pose ``(-) a`` such that ``compose(a, inverse(a))`` is the identity."""
    a = as_poses(a)
    c, s = stablemath.cos(a[..., 2]), stablemath.sin(a[..., 2])
    out = np.empty(a.shape)
    out[..., 0] = -c * a[..., 0] - s * a[..., 1]
    out[..., 1] = s * a[..., 0] - c * a[..., 1]
    out[..., 2] = wrap_angle(-a[..., 2])
    return out


def ominus(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Relative pose ``(-) a (+) b``: pose ``b`` seen from the frame of pose ``a``."""
    return compose(inverse(a), b)


def transform_points(pose: ArrayLike, points: ArrayLike) -> NDArray[np.float64]:
    """Map points ``[..., 2]`` given in the frame of ``pose`` (shape ``[3]``) into the parent frame."""
    pose = as_poses(pose)
    pts = np.asarray(points, dtype=np.float64)
    c, s = stablemath.cos(pose[2]), stablemath.sin(pose[2])
    out = np.empty(pts.shape)
    out[..., 0] = pose[0] + c * pts[..., 0] - s * pts[..., 1]
    out[..., 1] = pose[1] + s * pts[..., 0] + c * pts[..., 1]
    return out


def interpolate(a: ArrayLike, b: ArrayLike, fraction: ArrayLike) -> NDArray[np.float64]:
    """Poses a fraction of the way from ``a`` to ``b``: linear in (x, y), along the shorter arc in theta.

    Parameters
    ----------
    a, b:
        Poses ``[..., 3]`` (m, m, rad), broadcast against each other.
    fraction:
        ``[...]`` position between them: 0 gives ``a``, 1 gives ``b`` (up to angle wrapping).

    Returns
    -------
    NDArray[np.float64]
        ``[..., 3]`` interpolated poses, theta wrapped into [-pi, pi).
    """
    a = as_poses(a)
    b = as_poses(b)
    f = np.asarray(fraction, dtype=np.float64)
    out = np.empty(np.broadcast_shapes(a.shape, b.shape, f.shape + (3,)))
    out[..., 0] = a[..., 0] + f * (b[..., 0] - a[..., 0])
    out[..., 1] = a[..., 1] + f * (b[..., 1] - a[..., 1])
    out[..., 2] = wrap_angle(a[..., 2] + f * wrap_angle(b[..., 2] - a[..., 2]))
    return out


# Single-pose versions in scalar arithmetic: the simulator composes a few single poses every step, and
# the array functions above cost tens of microseconds on one pose; these cost about one.


def wrap_angle1(angle: float) -> float:
    """Wrap one angle (rad) into [-pi, pi), the same formula as :func:`wrap_angle`."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def compose1(a: Pose1Like, b: Pose1Like) -> NDArray[np.float64]:
    """:func:`compose` for two single poses ``[3]``, in scalar arithmetic.

    The simulator composes a few single poses every step; ``geometry.compose`` is written for arrays of
    poses and costs tens of microseconds on one pose, this costs about one. Same formulas and results.
    """
    ax, ay, at = (float(v) for v in a)
    bx, by, bt = (float(v) for v in b)
    c, s = math.cos(at), math.sin(at)
    return np.array([ax + c * bx - s * by, ay + s * bx + c * by, wrap_angle1(at + bt)])


def ominus1(a: Pose1Like, b: Pose1Like) -> NDArray[np.float64]:
    """:func:`ominus` for two single poses ``[3]``: pose ``b`` in the frame of ``a``.

    Computed directly as the rotation by ``-theta_a`` of ``b - a`` (equal to ``compose(inverse(a), b)``
    up to rounding).
    """
    ax, ay, at = (float(v) for v in a)
    bx, by, bt = (float(v) for v in b)
    c, s = math.cos(at), math.sin(at)
    dx, dy = bx - ax, by - ay
    return np.array([c * dx + s * dy, -s * dx + c * dy, wrap_angle1(bt - at)])
