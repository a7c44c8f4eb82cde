"""The data that flows between layers: one simulator step (:class:`Frame`) and one run (:class:`RunRecord`).

Plain containers with no behaviour beyond shape checks. Poses are ``(x, y, theta)`` in metres and
radians; ground truth is in the world frame, odometry in the odometry frame (which starts at
``(0, 0, 0)`` at the first frame, as in Stage and ROS).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Frame",
    "Reading",
    "LaserGeometry",
    "RunRecord",
    "Trajectory",
    "Relations",
    "OccupancyGrid",
    "OCCUPIED",
    "FREE",
    "UNKNOWN",
]


@dataclass(frozen=True, eq=False)
class Frame:
    """What the robot senses at one simulator step.

    Attributes
    ----------
    t:
        Time in seconds since the start of the run.
    ranges:
        float32 ``[B]`` laser ranges in metres, beam 0 at the laser's ``angle_min``, counter-clockwise;
        a beam with no return reads ``+inf`` from the simulator (ROS REP 117); readings from real logs
        may say no return with a value at or above ``range_max``. Every consumer treats both alike.
    odometry:
        float64 ``[3]`` pose of the robot base in the odometry frame.
    truth:
        float64 ``[3]`` true pose of the robot base in the world frame.
    stalled:
        True when the robot bumped into a wall during the step that led to this frame (it did not move).
    """

    t: float
    ranges: NDArray[np.float32]
    odometry: NDArray[np.float64]
    truth: NDArray[np.float64]
    stalled: bool = False

    def reading(self) -> Reading:
        """What a SLAM algorithm is given of this frame: its time, ranges and odometry, no ground truth."""
        return Reading(t=self.t, ranges=self.ranges, odometry=self.odometry)


@dataclass(frozen=True, eq=False)
class Reading:
    """What a SLAM algorithm is given at one step: the robot's sensor data and nothing else.

    The ground truth of a run (:attr:`Frame.truth`) never reaches an algorithm, built-in, plug-in or
    external program: an algorithm that could read it would score whatever it liked. Built from a frame
    with :meth:`Frame.reading`, or from a recording's arrays.

    Attributes
    ----------
    t:
        Time in seconds (the recording's time base).
    ranges:
        float32 ``[B]`` laser ranges in metres, as :attr:`Frame.ranges` (a no-return is ``+inf`` or at
        least the laser's ``range_max``).
    odometry:
        float64 ``[3]`` pose of the robot base in the odometry frame.
    """

    t: float
    ranges: NDArray[np.float32]
    odometry: NDArray[np.float64]


@dataclass(frozen=True)
class LaserGeometry:
    """Where a planar laser looks and how far: everything needed to turn a scan into points.

    Attributes
    ----------
    angle_min:
        Bearing (rad) of beam 0 in the laser frame; beam ``i`` points at ``angle_min + i * angle_increment``
        (counter-clockwise).
    angle_increment:
        Angle (rad) between neighbouring beams, > 0.
    range_min, range_max:
        Shortest and longest valid reading (m); a reading of ``range_max`` or more, or ``+inf``, is "no
        return" and marks nothing (it says nothing about where the nearest surface is).
    mount:
        Pose (x, y, theta) of the laser in the robot base frame, metres and radians.
    """

    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    mount: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        for name in ("angle_min", "angle_increment", "range_min", "range_max"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
                raise ValueError(f"LaserGeometry.{name} must be a finite number, got {value!r}")
            object.__setattr__(self, name, float(value))
        mount = tuple(float(v) for v in self.mount)
        if len(mount) != 3 or not all(math.isfinite(v) for v in mount):
            raise ValueError(f"LaserGeometry.mount must be three finite numbers (x, y, theta), got {self.mount!r}")
        object.__setattr__(self, "mount", mount)
        if self.angle_increment <= 0:
            raise ValueError(f"LaserGeometry.angle_increment must be > 0 rad, got {self.angle_increment!r}")
        if not 0 <= self.range_min < self.range_max:
            raise ValueError(
                f"LaserGeometry needs 0 <= range_min < range_max, got {self.range_min!r} and {self.range_max!r}"
            )

    def beam_angles(self, beams: int) -> NDArray[np.float64]:
        """float64 ``[beams]`` bearings (rad) of the beams in the laser frame."""
        return self.angle_min + self.angle_increment * np.arange(beams, dtype=np.float64)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form stored in run.json: the four numbers and ``mount`` as a list."""
        return {
            "angle_min": self.angle_min,
            "angle_increment": self.angle_increment,
            "range_min": self.range_min,
            "range_max": self.range_max,
            "mount": list(self.mount),
        }

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> LaserGeometry:
        """Read the JSON form (``mount`` optional, default at the base origin). Raises ValueError naming the field."""
        fields = ("angle_min", "angle_increment", "range_min", "range_max")
        missing = [k for k in fields if k not in doc]
        if missing:
            raise ValueError(f"laser geometry lacks {', '.join(missing)}")
        return cls(**{k: doc[k] for k in fields}, mount=tuple(doc.get("mount", (0.0, 0.0, 0.0))))


@dataclass(eq=False)
class RunRecord:
    """All frames of one run as stacked arrays, plus the metadata needed to interpret them.

    Attributes
    ----------
    t:
        float64 ``[T]`` timestamps in seconds, strictly increasing.
    scans:
        float32 ``[T, B]`` laser ranges in metres.
    odometry:
        float64 ``[T, 3]`` odometry poses.
    truth:
        float64 ``[T, 3]`` ground-truth poses in the world frame.
    stalled:
        bool ``[T]`` collision flag per frame.
    laser:
        The laser's geometry (:class:`LaserGeometry`).
    metadata:
        Free-form JSON-serialisable facts about the run (world name, seed, drawn odometry bias, ...).
    estimate:
        Optional float64 ``[T, 3]`` SLAM pose estimates (map frame), filled in by later stages: the
        algorithm's final trajectory (:meth:`SlamAlgorithm.trajectory` after the last frame).
    online:
        Optional float64 ``[T, 3]``: what the algorithm returned at each frame while running (map frame).
    map:
        Optional final SLAM map (:class:`OccupancyGrid`, map frame), filled in by a trial.
    """

    t: NDArray[np.float64]
    scans: NDArray[np.float32]
    odometry: NDArray[np.float64]
    truth: NDArray[np.float64]
    stalled: NDArray[np.bool_]
    laser: LaserGeometry
    metadata: dict[str, Any] = field(default_factory=dict)
    estimate: NDArray[np.float64] | None = None
    map: OccupancyGrid | None = None
    online: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.laser, LaserGeometry):
            raise TypeError(f"RunRecord.laser must be a LaserGeometry, got {type(self.laser).__name__}")
        n = len(self.t)
        expected = {"scans": (n,), "odometry": (n, 3), "truth": (n, 3), "stalled": (n,)}
        for name, shape in expected.items():
            got = getattr(self, name).shape[: len(shape)]
            if got != shape:
                raise ValueError(f"RunRecord.{name} has shape {getattr(self, name).shape}, expected {shape}[...]")

    def __len__(self) -> int:
        return len(self.t)

    @classmethod
    def from_frames(
        cls, frames: list[Frame], laser: LaserGeometry, metadata: dict[str, Any] | None = None
    ) -> RunRecord:
        """Stack a list of frames into a record."""
        return cls(
            t=np.array([f.t for f in frames], dtype=np.float64),
            scans=np.stack([f.ranges for f in frames]).astype(np.float32, copy=False),
            odometry=np.stack([f.odometry for f in frames]).astype(np.float64, copy=False),
            truth=np.stack([f.truth for f in frames]).astype(np.float64, copy=False),
            stalled=np.array([f.stalled for f in frames], dtype=bool),
            laser=laser,
            metadata=dict(metadata or {}),
        )


#: Cell values of :attr:`OccupancyGrid.grid` (those of a ``nav_msgs/OccupancyGrid``).
OCCUPIED, FREE, UNKNOWN = 100, 0, -1


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """An occupancy-grid map (a SLAM algorithm's), as ROS publishes it.

    Attributes
    ----------
    grid:
        int8 ``[H, W]``: 100 occupied, 0 free, -1 unknown; row 0 is the TOP row (largest y), column 0
        the left one (smallest x).
    resolution:
        Cell size (m).
    origin:
        float64 ``[3]``: map-frame pose (x, y, theta) of the lower-left corner of the lower-left cell
        (row ``H - 1``, column 0), as in ROS.
    """

    grid: NDArray[np.int8]
    resolution: float
    origin: NDArray[np.float64]

    def __post_init__(self) -> None:
        if self.grid.ndim != 2 or self.grid.dtype != np.int8:
            raise ValueError(f"OccupancyGrid.grid must be int8 [H, W], got {self.grid.dtype} {self.grid.shape}")
        if not (math.isfinite(self.resolution) and self.resolution > 0):
            raise ValueError(f"OccupancyGrid.resolution must be positive metres, got {self.resolution!r}")
        if np.shape(self.origin) != (3,):
            raise ValueError(f"OccupancyGrid.origin must be (x, y, theta), got {self.origin!r}")


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Timestamped 2-D poses, e.g. a SLAM estimate or a ground truth read from a file.

    Attributes
    ----------
    t:
        float64 ``[N]`` timestamps in seconds.
    poses:
        float64 ``[N, 3]`` poses (x, y, theta) in metres and radians, in the trajectory's own frame.
    """

    t: NDArray[np.float64]
    poses: NDArray[np.float64]

    def __post_init__(self) -> None:
        if self.t.ndim != 1 or self.poses.shape != (len(self.t), 3):
            raise ValueError(f"Trajectory needs t [N] and poses [N, 3], got {self.t.shape} and {self.poses.shape}")

    def __len__(self) -> int:
        return len(self.t)


@dataclass(frozen=True, eq=False)
class Relations:
    """Relative-pose relations of the Kuemmerle et al. metric: the true motion between two times.

    Attributes
    ----------
    t1, t2:
        float64 ``[K]`` timestamps (s) of the two poses of each relation.
    delta:
        float64 ``[K, 3]`` true relative pose (dx, dy, dtheta): the pose at ``t2`` seen from the pose at
        ``t1`` (``ominus(x(t1), x(t2))``), in metres and radians.
    """

    t1: NDArray[np.float64]
    t2: NDArray[np.float64]
    delta: NDArray[np.float64]

    def __post_init__(self) -> None:
        k = len(self.t1)
        if self.t1.ndim != 1 or self.t2.shape != (k,) or self.delta.shape != (k, 3):
            raise ValueError(
                f"Relations needs t1 [K], t2 [K], delta [K, 3], got {self.t1.shape}, {self.t2.shape}, {self.delta.shape}"
            )

    def __len__(self) -> int:
        return len(self.t1)
