"""ROS bags in and out: a run as the topics of a Stage + ROS setup, in ROS 1 (``.bag``) or ROS 2 (MCAP).

The paper stored every run as a ROS bag; these functions let a slamtrials run be replayed through ROS
tools (rosbag play, rviz, GMapping, slam_toolbox) and let a recording of a real robot be evaluated:

* :func:`write_rosbag1`, :func:`write_rosbag2` (and :func:`write_bag` choosing by ``ros``): export;
* :func:`run_from_bag`: import (ROS 1 file, ROS 2 folder or MCAP file, found from the path);
* :func:`bag_topics`: a bag's topics and types.

Topic layout, frame ids and stamps: :mod:`slamtrials.io.ros_messages`. Writing: :mod:`slamtrials.io.rosbag_write`.
Reading and pairing of scans with poses: :mod:`slamtrials.io.rosbag_read`.
"""

from __future__ import annotations

from pathlib import Path

from slamtrials.io.ros_messages import (
    BASE_FRAME,
    DEFAULT_TIME_ORIGIN_NS,
    LASER_FRAME,
    ODOM_FRAME,
    ODOM_TOPIC,
    SCAN_TOPIC,
    TRUTH_TOPIC,
    WORLD_FRAME,
)
from slamtrials.io.rosbag_read import bag_topics, run_from_bag
from slamtrials.io.rosbag_write import write_rosbag1, write_rosbag2
from slamtrials.record import RunRecord

__all__ = [
    "write_bag",
    "write_rosbag1",
    "write_rosbag2",
    "run_from_bag",
    "bag_topics",
    "SCAN_TOPIC",
    "ODOM_TOPIC",
    "TRUTH_TOPIC",
    "ODOM_FRAME",
    "BASE_FRAME",
    "LASER_FRAME",
    "WORLD_FRAME",
    "DEFAULT_TIME_ORIGIN_NS",
]


def write_bag(
    path: str | Path,
    record: RunRecord,
    *,
    ros: int = 1,
    time_origin_ns: int = DEFAULT_TIME_ORIGIN_NS,
    overwrite: bool = False,
    compress: bool = False,
) -> Path:
    """Write ``record`` as a ROS 1 bag file (``ros=1``) or a ROS 2 MCAP bag folder (``ros=2``).

    See :func:`write_rosbag1` and :func:`write_rosbag2`; returns ``path``.
    """
    if ros == 1:
        return write_rosbag1(path, record, time_origin_ns=time_origin_ns, overwrite=overwrite, compress=compress)
    if ros == 2:
        return write_rosbag2(path, record, time_origin_ns=time_origin_ns, overwrite=overwrite, compress=compress)
    raise ValueError(f"ros must be 1 or 2, got {ros!r}")
