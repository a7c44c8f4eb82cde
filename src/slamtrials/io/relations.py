"""Relations files of the Kuemmerle et al. metric: one relation per line, ``t1 t2 x y z roll pitch yaw``.

A relation is the true motion between the robot's poses at times ``t1`` and ``t2`` (s): the pose at
``t2`` seen from the pose at ``t1``, as the homogeneous transform
``translate(x, y, z) * Rz(yaw) * Ry(pitch) * Rx(roll)`` (m, rad). This is the format of the Freiburg SLAM
benchmark files (e.g. ``mit-csail.relations``) and of the metricEvaluator program.

* :func:`read_relations` projects each relation onto the plane: ``(dx, dy) = (x, y)`` (``z`` is dropped)
  and ``dtheta`` the heading of the rotated x axis, ``atan2(R[1, 0], R[0, 0]) =
  atan2(sin(yaw) cos(pitch), cos(yaw) cos(pitch))``. When roll and pitch are both exactly 0 (every 2-D
  file) that is ``yaw`` itself, taken exactly as written (not wrapped); otherwise it is yaw wrapped into
  [-pi, pi], plus pi when ``|pitch| > pi/2``. A pitch of +-pi/2 leaves no heading and is an error.
  Relations may come in any order, and ``t1`` need not be smaller than ``t2``.
* :func:`write_relations` writes ``z = roll = pitch = 0`` and every other number as the shortest text
  that reads back to the same float64, so a written file reads back exactly.

Lines whose first token starts with ``#`` are comments; blank lines are ignored.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from slamtrials import stablemath
from slamtrials.atomicfile import atomic_write_text
from slamtrials.errors import FormatError
from slamtrials.io.textfile import read_number_table
from slamtrials.record import Relations

__all__ = ["read_relations", "write_relations", "RELATION_FIELDS"]

RELATION_FIELDS = ("t1", "t2", "x", "y", "z", "roll", "pitch", "yaw")


def read_relations(path: str | Path) -> Relations:
    """Read a relations file as 2-D :class:`~slamtrials.record.Relations`.

    Parameters
    ----------
    path:
        The file: one relation per line, ``t1 t2 x y z roll pitch yaw`` (s, s, m, m, m, rad, rad, rad).

    Returns
    -------
    Relations
        ``t1``, ``t2`` float64 [K] (s) and ``delta`` float64 [K, 3] = (dx, dy, dtheta) (m, rad), in file
        order, projected onto the plane as the module docstring describes.

    Raises
    ------
    FormatError
        Naming the file and line: a line without 8 fields, a field that is not a finite number, a pitch
        of +-pi/2 (no heading), or no relations at all.
    """
    path = Path(path)
    values, numbers = read_number_table(path, RELATION_FIELDS, "relations")
    roll, pitch, yaw = values[:, 5], values[:, 6], values[:, 7]
    cos_pitch = stablemath.cos(pitch)
    vertical = np.flatnonzero(np.abs(cos_pitch) < 1e-9)
    if vertical.size:
        i = int(vertical[0])
        raise FormatError(
            path, f"pitch {pitch[i]!r} points the x axis vertically: the relation has no 2-D heading", line=numbers[i]
        )
    planar = (roll == 0.0) & (pitch == 0.0)
    tilted = stablemath.arctan2(stablemath.sin(yaw) * cos_pitch, stablemath.cos(yaw) * cos_pitch)
    heading = np.where(planar, yaw, tilted)
    delta = np.column_stack([values[:, 2], values[:, 3], heading])
    return Relations(t1=values[:, 0].copy(), t2=values[:, 1].copy(), delta=delta)


def write_relations(path: str | Path, relations: Relations) -> Path:
    """Write 2-D relations as a relations file (atomically) and return its path.

    Parameters
    ----------
    path:
        The file to write.
    relations:
        ``t1``, ``t2`` float64 [K] (s) and ``delta`` [K, 3] = (dx, dy, dtheta) (m, rad); written as
        ``t1 t2 dx dy 0.0 0.0 0.0 dtheta``.

    Raises
    ------
    ValueError
        A value is not finite (the file would not read back).
    """
    t1 = np.asarray(relations.t1, dtype=np.float64)
    t2 = np.asarray(relations.t2, dtype=np.float64)
    delta = np.asarray(relations.delta, dtype=np.float64)
    if not (np.isfinite(t1).all() and np.isfinite(t2).all() and np.isfinite(delta).all()):
        raise ValueError("write_relations: relations have non-finite timestamps or values")
    columns = (t1, t2, delta[:, 0], delta[:, 1], delta[:, 2])
    lines = [f"{a!r} {b!r} {x!r} {y!r} 0.0 0.0 0.0 {th!r}\n" for a, b, x, y, th in zip(*(c.tolist() for c in columns))]
    return atomic_write_text(path, "".join(lines))
