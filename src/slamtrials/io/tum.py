"""TUM trajectory files: one pose per line, ``t x y z qx qy qz qw``.

The format of the TUM RGB-D benchmark, read by evo and most SLAM evaluation tools. Units are seconds and
metres; ``(qx, qy, qz, qw)`` is the Hamilton quaternion of the body's orientation in the trajectory's
frame. Lines whose first token starts with ``#`` are comments; blank lines are ignored.

slamtrials trajectories are 2-D, ``(x, y, theta)``:

* :func:`write_tum` writes ``z = 0`` and the rotation about z by ``theta``
  (``qx = qy = 0, qz = sin(theta / 2), qw = cos(theta / 2)``), every number as the shortest text that
  reads back to the same float64 (Python's ``repr``), so ``t``, ``x`` and ``y`` round-trip exactly and
  ``theta`` to within a few ulps (it passes through the quaternion).
* :func:`read_tum` accepts any 3-D pose and projects it onto the plane: ``x``, ``y`` as written (``z`` is
  dropped) and ``theta`` the heading of the body's x axis, ``atan2(R[1, 0], R[0, 0])`` of the rotation
  matrix; with no roll or pitch this is the yaw. Quaternions need not be unit length (they are
  normalised), but must not be zero, and must not point the x axis straight up or down (no heading).
  Timestamps must be strictly increasing: a trajectory has one pose per time, and matching relation
  timestamps to poses depends on it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from slamtrials import stablemath
from slamtrials.atomicfile import atomic_write_text
from slamtrials.errors import FormatError
from slamtrials.io.textfile import read_number_table
from slamtrials.record import Trajectory

__all__ = ["read_tum", "write_tum", "TUM_FIELDS"]

TUM_FIELDS = ("t", "x", "y", "z", "qx", "qy", "qz", "qw")


def read_tum(path: str | Path) -> Trajectory:
    """Read a TUM trajectory file as a 2-D :class:`~slamtrials.record.Trajectory`.

    Parameters
    ----------
    path:
        The file: one pose per line, ``t x y z qx qy qz qw`` (s, m, unit-less quaternion).

    Returns
    -------
    Trajectory
        ``t`` float64 [N] (s) and ``poses`` float64 [N, 3] = (x, y, theta) in metres and radians, theta
        in [-pi, pi], projected onto the plane as the module docstring describes.

    Raises
    ------
    FormatError
        Naming the file and line: a line without 8 fields, a field that is not a finite number, a zero
        quaternion or one with no heading, timestamps not strictly increasing, or no poses at all.
    """
    path = Path(path)
    values, numbers = read_number_table(path, TUM_FIELDS, "poses")
    t = values[:, 0]
    step = np.flatnonzero(np.diff(t) <= 0)
    if step.size:
        i = int(step[0])
        raise FormatError(
            path,
            f"timestamps must be strictly increasing: {t[i + 1]!r} after {t[i]!r} (line {numbers[i]})",
            line=numbers[i + 1],
        )
    quat = values[:, 4:8]
    scale = np.abs(quat).max(axis=1)
    zero = np.flatnonzero(scale == 0)
    if zero.size:
        raise FormatError(path, "quaternion is zero", line=numbers[int(zero[0])])
    qx, qy, qz, qw = (quat / scale[:, None]).T  # largest component +-1: no overflow below
    norm2 = qx * qx + qy * qy + qz * qz + qw * qw
    # First column of the rotation matrix, times |q|^2: R[0, 0] and R[1, 0] up to a positive factor.
    r00 = qw * qw + qx * qx - qy * qy - qz * qz
    r10 = 2.0 * (qx * qy + qw * qz)
    vertical = np.flatnonzero(stablemath.hypot(r00, r10) <= 1e-9 * norm2)
    if vertical.size:
        i = int(vertical[0])
        raise FormatError(
            path,
            f"rotation points the x axis vertically, it has no heading (qx qy qz qw = {values[i, 4:].tolist()})",
            line=numbers[i],
        )
    poses = np.column_stack([values[:, 1], values[:, 2], stablemath.arctan2(r10, r00)])
    return Trajectory(t=t.copy(), poses=poses)


def write_tum(path: str | Path, trajectory: Trajectory, *, header: bool = True) -> Path:
    """Write a 2-D trajectory as a TUM file (atomically) and return its path.

    Parameters
    ----------
    path:
        The file to write.
    trajectory:
        ``t`` float64 [N] (s), strictly increasing, and ``poses`` [N, 3] = (x, y, theta) (m, rad).
    header:
        Start with a ``# t x y z qx qy qz qw`` comment line (evo and :func:`read_tum` skip it).

    Raises
    ------
    ValueError
        A value is not finite or the timestamps are not strictly increasing (the file would not read
        back).
    """
    t = np.asarray(trajectory.t, dtype=np.float64)
    poses = np.asarray(trajectory.poses, dtype=np.float64)
    if not (np.isfinite(t).all() and np.isfinite(poses).all()):
        raise ValueError("write_tum: trajectory has non-finite timestamps or poses")
    if np.any(np.diff(t) <= 0):
        raise ValueError("write_tum: timestamps must be strictly increasing")
    half = poses[:, 2] / 2.0
    columns = [t, poses[:, 0], poses[:, 1], stablemath.sin(half), stablemath.cos(half)]
    lines = ["# " + " ".join(TUM_FIELDS) + "\n"] if header else []
    lines += [
        f"{ti!r} {x!r} {y!r} 0.0 0.0 0.0 {qz!r} {qw!r}\n" for ti, x, y, qz, qw in zip(*(c.tolist() for c in columns))
    ]
    return atomic_write_text(path, "".join(lines))
