"""The ``odometry`` baseline: no correction at all, the estimate is the odometry.

The estimate at frame ``k`` is ``initial_pose (+) (odometry_0 (-) odometry_k)``: the odometry motion
since the first processed frame, started at the configured initial pose (default the origin). A
simulated run's odometry starts at (0, 0, 0), so there the estimate equals the recorded odometry. The
map is built with :class:`~slamtrials.slam.gridmap.GridMap` from the scans at the estimated poses, on
every frame or on GMapping's update rule (a frame is mapped when it is the first, or the odometry moved
``linear_update`` metres or turned ``angular_update`` radians since the last mapped frame, or more
than ``temporal_update`` seconds passed when that is >= 0). Its error is the baseline any SLAM algorithm
should beat.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, field_validator

from slamtrials.geometry import compose1, ominus1
from slamtrials.record import LaserGeometry, Reading, Trajectory
from slamtrials.slam.base import OccupancyGrid, register_algorithm
from slamtrials.slam.gridmap import GridMap

__all__ = ["OdometrySlam", "OdometryConfig"]


class OdometryConfig(BaseModel):
    """Parameters of the odometry baseline (SI units).

    Attributes
    ----------
    resolution:
        Map cell size (m).
    max_urange:
        Usable range (m): longer beams are cut there and mark only free cells. ``None``: the laser's
        ``range_max``.
    occ_thresh:
        A cell is occupied when hits / visits exceeds this.
    linear_update, angular_update:
        Map a frame once the odometry moved this far (m) or turned this much (rad) since the last mapped
        frame; 0 and 0 map every frame.
    temporal_update:
        Also map a frame when more than this many seconds passed since the last mapped one; negative: off.
    initial_pose:
        Map-frame pose (x, y, theta) of the first frame.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    resolution: float = Field(0.05, gt=0.0, le=10.0, description="map cell size (m)")
    max_urange: float | None = Field(
        None, gt=0.0, le=1000.0, description="usable range (m); None: the laser's range_max"
    )
    occ_thresh: float = Field(0.25, ge=0.0, lt=1.0, description="occupied when hits/visits exceeds this")
    linear_update: float = Field(0.0, ge=0.0, le=1000.0, description="map after this much travel (m)")
    angular_update: float = Field(0.0, ge=0.0, le=2.0 * math.pi, description="map after this much turning (rad)")
    temporal_update: float = Field(-1.0, le=1.0e6, description="map after this much time (s); negative: off")
    initial_pose: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="pose of the first frame (m, m, rad)")

    @field_validator("initial_pose")
    @classmethod
    def _finite(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        if not all(math.isfinite(v) for v in value):
            raise ValueError(f"initial_pose must be finite numbers, got {value}")
        return value


@register_algorithm
class OdometrySlam:
    """The odometry baseline (registry name ``odometry``); see the module docstring.

    Parameters
    ----------
    config:
        Validated :class:`OdometryConfig`.
    laser:
        The laser's geometry (:class:`~slamtrials.record.LaserGeometry`).
    """

    name = "odometry"
    Config = OdometryConfig
    PRESETS: dict[str, dict[str, Any]] = {
        "every-frame": {},
        "gmapping": {"linear_update": 1.0, "angular_update": 0.5},  # slam_gmapping's update rule
    }

    def __init__(self, config: OdometryConfig, laser: LaserGeometry):
        self.config = config
        self.laser = laser
        self.reset(np.random.default_rng(0))

    def reset(self, rng: np.random.Generator) -> None:
        """Forget everything processed (the baseline draws no random numbers)."""
        self.updates = 0
        self._map = GridMap(self.config.resolution)
        self._t: list[float] = []
        self._poses: list[NDArray[np.float64]] = []
        self._first_odometry: NDArray[np.float64] | None = None
        self._last_odometry: NDArray[np.float64] | None = None
        self._moved = 0.0
        self._turned = 0.0
        self._last_update_t = -math.inf

    def _due(self, frame: Reading) -> bool:
        """GMapping's update rule, accumulating the odometry motion since the last mapped frame."""
        c = self.config
        if self._last_odometry is None:
            return True
        step = ominus1(self._last_odometry, frame.odometry)
        self._moved += math.hypot(step[0], step[1])
        self._turned += abs(step[2])
        if self._moved >= c.linear_update or self._turned >= c.angular_update:
            return True
        return c.temporal_update >= 0 and frame.t - self._last_update_t > c.temporal_update

    def process(self, frame: Reading) -> NDArray[np.float64]:
        """The odometry pose composed onto the initial pose; maps the scan when an update is due."""
        odometry = np.asarray(frame.odometry, dtype=np.float64)
        if self._first_odometry is None:
            self._first_odometry = odometry
        pose = compose1(np.asarray(self.config.initial_pose), ominus1(self._first_odometry, odometry))
        if self._due(frame):
            self._map.integrate_frame(pose, frame.ranges, self.laser, max_urange=self.config.max_urange)
            self.updates += 1
            self._moved = self._turned = 0.0
            self._last_update_t = frame.t
        self._last_odometry = odometry
        self._t.append(float(frame.t))
        self._poses.append(pose)
        return pose

    def occupancy(self) -> OccupancyGrid:
        """The map built so far."""
        return self._map.occupancy(self.config.occ_thresh)

    def trajectory(self) -> Trajectory:
        """Timestamps and estimates of every processed frame."""
        poses = np.array(self._poses, dtype=np.float64).reshape(-1, 3)
        return Trajectory(t=np.array(self._t, dtype=np.float64), poses=poses)
