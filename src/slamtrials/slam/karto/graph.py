"""The pose graph: one node per processed scan, edges with a relative pose and its covariance.

A node holds the robot BASE pose (map frame) of its scan, as slam_toolbox's Karto does (its links join
corrected base poses; open_karto joined laser poses), and the scan itself as laser-frame points. An
edge from node ``a`` to node ``b`` holds ``mean``: b's base pose seen from a's (a (-) b), and
``covariance``: the match covariance rotated into a's frame (Karto's LinkInfo). Karto links a pair once:
a second link from ``a`` to ``b`` is dropped.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from slamtrials.geometry import compose1, ominus1
from slamtrials.slam.karto.correlation import KT_TOLERANCE

__all__ = ["ScanNode", "Edge", "PoseGraph", "rotate_covariance", "laser_pose"]


@dataclass(eq=False)
class ScanNode:
    """One processed scan.

    Attributes
    ----------
    frame:
        Index of the frame it came from.
    t:
        Its time (s).
    odometry:
        float64 ``[3]`` base pose in the odometry frame.
    pose:
        float64 ``[3]`` corrected base pose, map frame (changed by matching and optimisation: always by
        assigning a new array, never in place, so caches may key on the array itself).
    ranges:
        float32 ``[B]`` the readings (for the map).
    readings:
        float64 ``[B]`` the readings that give a point (m), NaN elsewhere (Karto's unfiltered points).
    within:
        bool ``[B]`` the readings within the range threshold (Karto's filtered points: the barycentre's).
    """

    frame: int
    t: float
    odometry: NDArray[np.float64]
    pose: NDArray[np.float64]
    ranges: NDArray[np.float32]
    readings: NDArray[np.float64]
    within: NDArray[np.bool_]


@dataclass(frozen=True)
class Edge:
    """A link from node ``source`` to node ``target`` (see the module docstring)."""

    source: int
    target: int
    mean: NDArray[np.float64]
    covariance: NDArray[np.float64]


def rotate_covariance(covariance: NDArray[np.float64], angle: float) -> NDArray[np.float64]:
    """``R C R^T`` for the rotation ``R`` by ``angle`` (rad) about z, written out (3 x 3)."""
    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    out = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            total = 0.0
            for k in range(3):
                for m in range(3):
                    total += rot[i, k] * covariance[k, m] * rot[j, m]
            out[i, j] = total
    return out


@dataclass(eq=False)
class PoseGraph:
    """Nodes and edges, with each node's neighbours in the order its edges were added."""

    nodes: list[ScanNode] = field(default_factory=list)
    edges: list[Edge] = field(default_factory=list)
    neighbours: list[list[int]] = field(default_factory=list)
    _pairs: set[tuple[int, int]] = field(default_factory=set)

    def add_node(self, node: ScanNode) -> int:
        """Append ``node``; return its index."""
        self.nodes.append(node)
        self.neighbours.append([])
        return len(self.nodes) - 1

    def link(
        self,
        source: int,
        target: int,
        target_pose: NDArray[np.float64],
        covariance: NDArray[np.float64],
        *,
        origin: NDArray[np.float64] | None = None,
    ) -> bool:
        """Add an edge from ``source`` to ``target`` placing target at ``target_pose`` (map frame) with
        ``covariance`` (map frame), seen from ``origin`` (default: source's base pose); False (and
        nothing added) if that pair is linked already. The edge holds ``target_pose`` in the frame of
        ``origin`` and the covariance rotated into it (Karto's LinkInfo)."""
        if (source, target) in self._pairs or source == target:
            return False
        if origin is None:
            origin = self.nodes[source].pose
        self.edges.append(
            Edge(
                source,
                target,
                ominus1(origin, target_pose),
                rotate_covariance(np.asarray(covariance, dtype=np.float64), -float(origin[2])),
            )
        )
        self._pairs.add((source, target))
        self.neighbours[source].append(target)
        self.neighbours[target].append(source)
        return True

    def near_linked(self, start: int, reference: NDArray[np.float64], max_distance: float) -> list[int]:
        """Karto's FindNearLinkedScans: breadth-first from ``start`` through edges, over the nodes whose
        reference position ``reference[i]`` (``[N, 2]``) lies within ``max_distance`` of start's."""
        limit = max_distance * max_distance - KT_TOLERANCE
        cx, cy = reference[start]
        seen = {start}
        queue = deque([start])
        found = []
        while queue:
            node = queue.popleft()
            dx, dy = reference[node, 0] - cx, reference[node, 1] - cy
            if dx * dx + dy * dy <= limit:
                found.append(node)
                for other in self.neighbours[node]:
                    if other not in seen:
                        seen.add(other)
                        queue.append(other)
        return found

    def poses(self) -> NDArray[np.float64]:
        """float64 ``[N, 3]`` the nodes' base poses."""
        return np.array([n.pose for n in self.nodes], dtype=np.float64).reshape(-1, 3)

    def set_poses(self, poses: NDArray[np.float64]) -> None:
        """Set every node's base pose from ``[N, 3]``."""
        for node, pose in zip(self.nodes, poses):
            node.pose = np.array(pose, dtype=np.float64)


def laser_pose(node: ScanNode, mount: NDArray[np.float64]) -> NDArray[np.float64]:
    """The node's laser pose (map frame)."""
    return compose1(node.pose, mount)
