"""The ROS topic layout of a slamtrials run, and the conversions between run arrays and ROS messages.

Shared by :mod:`slamtrials.io.rosbag_write` and :mod:`slamtrials.io.rosbag_read`. A run is published the
way a Stage + ROS setup (``stageros``) publishes a robot, one message per topic per simulator step:

==============================  ===========================  ==========================================
topic                           type                         content
==============================  ===========================  ==========================================
``/base_scan``                  ``sensor_msgs/LaserScan``    ``record.scans``, frame ``base_laser_link``
``/odom``                       ``nav_msgs/Odometry``        ``record.odometry``, frame ``odom``, child
                                                             ``base_link``
``/base_pose_ground_truth``     ``nav_msgs/Odometry``        ``record.truth``, frame ``map``, child
                                                             ``base_link`` (steps with NaN truth omitted)
``/tf``                         ``tf2_msgs/TFMessage``       ``odom -> base_link`` every step (ROS 1:
                                                             also ``base_link -> base_laser_link``)
``/tf_static`` (ROS 2 only)     ``tf2_msgs/TFMessage``       ``base_link -> base_laser_link`` once,
                                                             transient-local QoS
``/stall``                      ``std_msgs/Int8``            ``record.stalled`` (1 when stalled)
``/slamtrials/run``             ``std_msgs/String``          JSON: time origin, laser geometry, metadata
==============================  ===========================  ==========================================

Frames (REP 105): the ground truth is in ``map``, the fixed frame whose coordinates are those of the
world's map_server YAML (``stageros`` labels its ground truth ``odom``, ``stage_ros2`` ``world``; both
mean Stage's world frame, which is our ``map``).

Stamps: ``stamp = time_origin + t``, in integer nanoseconds, with ``time_origin`` 1 s by default. A run
starts at ``t = 0``, and ROS treats time zero as "unset" (``stageros`` skips publishing it; tf2 reads a
zero stamp as "latest"), so the whole run is shifted by one second. The origin is stored in the
``/slamtrials/run`` message, so reading the bag back recovers ``t`` to the nanosecond. Every message of
a step has the same header stamp, and the bag's record time equals it.

Poses are planar: z = 0 everywhere (also for the laser mount; stageros adds the robot's height) and
quaternions are rotations about z. Twists are finite differences of consecutive poses, expressed in
the robot's base frame at the earlier pose: ``ominus(p[k-1], p[k]) / (t[k] - t[k-1])`` (linear x, y and
angular z); zero at the first step. Covariances are zero, as stageros publishes them.
"""

from __future__ import annotations

import json
import math
from functools import cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials import stablemath
from slamtrials.geometry import ominus
from slamtrials.io.runfolder import json_default

__all__ = [
    "SCAN_TOPIC",
    "ODOM_TOPIC",
    "TRUTH_TOPIC",
    "TF_TOPIC",
    "TF_STATIC_TOPIC",
    "STALL_TOPIC",
    "RUN_INFO_TOPIC",
    "ODOM_FRAME",
    "BASE_FRAME",
    "LASER_FRAME",
    "WORLD_FRAME",
    "DEFAULT_TIME_ORIGIN_NS",
    "RUN_INFO_FORMAT",
    "LASER_SCAN",
    "ODOMETRY",
    "TF_MESSAGE",
    "TF_MESSAGE_ALIASES",
    "INT8",
    "STRING",
    "typestore",
    "stamps_ns",
    "yaw_quaternions",
    "quaternion_yaw",
    "body_twists",
    "scan_period",
    "run_info_json",
]

SCAN_TOPIC = "/base_scan"
ODOM_TOPIC = "/odom"
TRUTH_TOPIC = "/base_pose_ground_truth"
TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"
STALL_TOPIC = "/stall"
RUN_INFO_TOPIC = "/slamtrials/run"

ODOM_FRAME = "odom"
BASE_FRAME = "base_link"
LASER_FRAME = "base_laser_link"
WORLD_FRAME = "map"

#: Stamp (ns) of ``t = 0``: one second, because ROS reads a zero time as "unset".
DEFAULT_TIME_ORIGIN_NS = 1_000_000_000
#: ``format`` value of the JSON document on ``/slamtrials/run``.
RUN_INFO_FORMAT = "slamtrials-bag/1"

LASER_SCAN = "sensor_msgs/msg/LaserScan"
ODOMETRY = "nav_msgs/msg/Odometry"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
#: Transform message types read as TFMessage (old ROS 1 bags use tf's, which has the same layout).
TF_MESSAGE_ALIASES = (TF_MESSAGE, "tf/msg/tfMessage")
INT8 = "std_msgs/msg/Int8"
STRING = "std_msgs/msg/String"

# ROS 1 Noetic's store in rosbags lacks tf2_msgs; this is its definition (md5 94810edda583a504dfda3829e70d7eec).
_TF_MESSAGE_MSG = "geometry_msgs/TransformStamped[] transforms"


@cache
def typestore(ros: int) -> Any:
    """The rosbags typestore of ROS 1 Noetic (``ros=1``) or ROS 2 Humble (``ros=2``), built once.

    The ROS 1 store gets ``tf2_msgs/msg/TFMessage`` registered, with the definition and md5 of Noetic's.
    """
    from rosbags.typesys import Stores, get_types_from_msg
    from rosbags.typesys import get_typestore as _get

    if ros == 1:
        store = _get(Stores.ROS1_NOETIC)
        store.register(get_types_from_msg(_TF_MESSAGE_MSG, TF_MESSAGE))
        return store
    if ros == 2:
        return _get(Stores.ROS2_HUMBLE)
    raise ValueError(f"ros must be 1 or 2, got {ros!r}")


def stamps_ns(t: ArrayLike, time_origin_ns: int) -> NDArray[np.int64]:
    """int64 ``[T]`` stamps in nanoseconds: ``time_origin_ns + round(t * 1e9)``.

    Integer arithmetic after rounding, so a large origin (e.g. a Unix time) loses no precision.
    """
    t = np.asarray(t, dtype=np.float64)
    return np.rint(t * 1e9).astype(np.int64) + np.int64(time_origin_ns)


def yaw_quaternions(theta: ArrayLike) -> NDArray[np.float64]:
    """float64 ``[N, 4]`` unit quaternions ``(x, y, z, w)`` of rotations by ``theta`` (rad) about z."""
    half = 0.5 * np.asarray(theta, dtype=np.float64)
    out = np.zeros(half.shape + (4,))
    out[..., 2] = stablemath.sin(half)
    out[..., 3] = stablemath.cos(half)
    return out


def quaternion_yaw(q: ArrayLike) -> NDArray[np.float64]:
    """Yaw (rad, in (-pi, pi]) of quaternions ``[..., 4]`` ``(x, y, z, w)``; roll and pitch are ignored.

    For a pure yaw quaternion this inverts :func:`yaw_quaternions` to within 1e-15 rad.
    """
    q = np.asarray(q, dtype=np.float64)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    with np.errstate(over="ignore", invalid="ignore"):  # damaged input gives inf/NaN, not warnings
        return stablemath.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def body_twists(t: ArrayLike, poses: ArrayLike) -> NDArray[np.float64]:
    """float64 ``[T, 3]`` velocities ``(vx, vy, wz)`` (m/s, rad/s) in the base frame, by finite differences.

    Row ``k`` is ``ominus(poses[k-1], poses[k]) / (t[k] - t[k-1])``; row 0 is zero. Rows whose pose or
    previous pose is not finite are zero.
    """
    t = np.asarray(t, dtype=np.float64)
    poses = np.asarray(poses, dtype=np.float64)
    out = np.zeros((len(t), 3))
    if len(t) > 1:
        with np.errstate(invalid="ignore"):
            delta = ominus(poses[:-1], poses[1:]) / np.diff(t)[:, None]
        out[1:] = np.where(np.isfinite(delta), delta, 0.0)
    return out


def scan_period(record: Any) -> float:
    """The time between scans (s): the simulation step ``sim_config.dt`` if recorded, else the median gap."""
    sim_config = record.metadata.get("sim_config")
    dt = sim_config.get("dt") if isinstance(sim_config, dict) else None
    if isinstance(dt, (int, float)) and not isinstance(dt, bool) and math.isfinite(dt) and dt > 0:
        return float(dt)
    if len(record.t) > 1:
        return float(np.median(np.diff(record.t)))
    return 0.0


def run_info_json(record: Any, time_origin_ns: int) -> str:
    """The JSON document of ``/slamtrials/run``: format, time origin (ns), frames, laser geometry, metadata."""
    doc = {
        "format": RUN_INFO_FORMAT,
        "time_origin_ns": int(time_origin_ns),
        "frames": len(record.t),
        "laser": record.laser.to_dict(),
        "metadata": record.metadata,
    }
    return json.dumps(doc, default=json_default)
