"""The particles' family tree: each particle's pose at every processed reading and who its parent was.

GMapping keeps a tree of trajectory nodes so the best particle's whole path can be read back; here the
tree is a list of per-update arrays: ``poses[u]`` float64 ``[N, 3]`` (the particles' poses after matching
at update ``u``) and ``parents[u]`` intp ``[N]`` (row of ``poses[u - 1]`` each row of ``poses[u]``
descends from). Resampling between updates is folded into the next update's ``parents``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["Lineage"]


class Lineage:
    """Poses and ancestry of the particles at every processed reading."""

    def __init__(self) -> None:
        self.poses: list[NDArray[np.float64]] = []
        self.parents: list[NDArray[np.intp]] = []
        #: row of the latest ``poses`` entry that current particle ``j`` is (changed by resampling)
        self.current: NDArray[np.intp] = np.zeros(0, dtype=np.intp)

    def __len__(self) -> int:
        return len(self.poses)

    def add(self, poses: NDArray[np.float64]) -> None:
        """Record the current particles' poses ``[N, 3]`` as a new update."""
        n = poses.shape[0]
        self.parents.append(self.current if self.poses else np.arange(n))
        self.poses.append(np.array(poses, dtype=np.float64))
        self.current = np.arange(n)

    def resampled(self, indexes: NDArray[np.intp]) -> None:
        """Current particle ``j`` became a copy of current particle ``indexes[j]``."""
        self.current = self.current[np.asarray(indexes)]

    def path(self, particle: int) -> NDArray[np.float64]:
        """float64 ``[U, 3]``: current particle ``particle``'s pose at every update, oldest first."""
        count = len(self.poses)
        path = np.empty((count, 3))
        row = int(self.current[particle])
        for u in range(count - 1, -1, -1):
            path[u] = self.poses[u][row]
            row = int(self.parents[u][row])
        return path
