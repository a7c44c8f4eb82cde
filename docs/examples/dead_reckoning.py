"""A SLAM algorithm as a Python class: it trusts the odometry and maps every frame (a template).

Use it without packaging, by reference: ``slamtrials slam --algorithm docs/examples/dead_reckoning.py:DeadReckoning``
or ``slam: {algorithm: "docs/examples/dead_reckoning.py:DeadReckoning"}`` in a config; imported, the
decorator also registers it as ``dead-reckoning``.
"""

import numpy as np
from pydantic import BaseModel, Field

from slamtrials.record import Trajectory
from slamtrials.slam import GridMap, register_algorithm


@register_algorithm
class DeadReckoning:
    name = "dead-reckoning"
    PRESETS = {"coarse": {"resolution": 0.2}}

    class Config(BaseModel):
        resolution: float = Field(0.05, gt=0.0, le=1.0)  # map cell size (m)
        occ_thresh: float = Field(0.25, ge=0.0, lt=1.0)

    def __init__(self, config, laser):
        self.config, self.laser = config, laser  # laser: a LaserGeometry (angles, ranges, mount)

    def reset(self, rng):
        self.updates, self.times, self.poses = 0, [], []
        self.map = GridMap(self.config.resolution)

    def process(self, frame):
        pose = np.asarray(frame.odometry, dtype=float)  # the odometry frame is the map frame
        self.map.integrate_frame(pose, frame.ranges, self.laser)
        self.updates += 1
        self.times.append(frame.t)
        self.poses.append(pose)
        return pose

    def occupancy(self):
        return self.map.occupancy(self.config.occ_thresh)

    def trajectory(self):
        return Trajectory(np.array(self.times), np.array(self.poses).reshape(-1, 3))
