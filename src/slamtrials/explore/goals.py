"""Goal bookkeeping: failed and reached goals, and the progress timer of the current goal.

Goals are kept as map-frame points (m), not cells, so they survive a map that grows (its origin moves).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.explore.gridframe import GridFrame

__all__ = ["GoalRecord", "exclude_discs"]


@dataclass
class GoalRecord:
    """The current goal and how the robot is doing on the way to it.

    Attributes
    ----------
    xy:
        float64 ``[2]`` goal point (map frame, m).
    target:
        float64 ``[2]`` the frontier cell the goal is for (map frame, m): the goal itself, or for a
        frontier the robot cannot reach, the frontier cell it is to look at from the goal.
    since:
        Time (s) the goal was first chosen.
    best:
        Shortest remaining path length (m) seen so far.
    last_progress:
        Time (s) of the last improvement of ``best`` by at least the progress distance.
    recoveries:
        Recoveries done on the way to this goal.
    """

    xy: NDArray[np.float64]
    target: NDArray[np.float64]
    since: float
    best: float = math.inf
    last_progress: float = 0.0
    recoveries: int = 0

    def update(self, t: float, remaining: float, progress_distance: float) -> None:
        """Record the remaining path length ``remaining`` (m) at time ``t``."""
        if remaining < self.best - progress_distance:
            self.best = remaining
            self.last_progress = t

    def rerouted(self, t: float, remaining: float, slack: float) -> None:
        """A new path to the same goal: a much longer one (the map changed) restarts the progress count."""
        if remaining > self.best + slack:
            self.best = remaining
            self.last_progress = t


def exclude_discs(mask: NDArray[np.bool_], frame: GridFrame, points: list[NDArray[np.float64]], radius: float) -> None:
    """Clear ``mask`` (bool ``[H, W]`` on ``frame``) within ``radius`` (m) of each map-frame point, in place."""
    if not points or radius <= 0.0:
        return
    res = frame.resolution
    n = math.ceil(radius / res)
    height, width = mask.shape
    offsets = np.arange(-n, n + 1)
    disc = (offsets[:, None] ** 2 + offsets[None, :] ** 2) * res * res <= radius * radius
    rows, cols = frame.to_cell(np.asarray(points, dtype=np.float64).reshape(-1, 2))
    for r, c in zip(rows.tolist(), cols.tolist()):
        r0, r1, c0, c1 = r - n, r + n + 1, c - n, c + n + 1
        if r1 <= 0 or c1 <= 0 or r0 >= height or c0 >= width:
            continue
        cr0, cr1, cc0, cc1 = max(r0, 0), min(r1, height), max(c0, 0), min(c1, width)
        mask[cr0:cr1, cc0:cc1] &= ~disc[cr0 - r0 : cr1 - r0, cc0 - c0 : cc1 - c0]
