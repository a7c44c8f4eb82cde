"""Write a :class:`~slamtrials.record.RunRecord` as a ROS 1 bag or a ROS 2 bag (MCAP storage).

The topics, frames and stamps are those of :mod:`slamtrials.io.ros_messages` (a Stage + ROS setup). Both
writers are atomic: the bag is written under a temporary name in the target's folder and renamed when
complete, so a crash never leaves a half-written bag under the requested name.
"""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from slamtrials.errors import ConfigError
from slamtrials.io import ros_messages as rm
from slamtrials.record import RunRecord

__all__ = ["write_rosbag1", "write_rosbag2"]

#: metadata.yaml version 8 stores QoS profiles as a YAML string, which Humble's ros2 bag reads; version 9
#: (Jazzy onwards) stores them as a YAML list, which Humble cannot parse.
_ROSBAG2_VERSION = 8
_UINT32_NS = (2**32 - 1) * 1_000_000_000  # ROS 1 time is (uint32 sec, uint32 nsec)
_INT32_NS = (2**31 - 1) * 1_000_000_000  # ROS 2 time is (int32 sec, uint32 nanosec)


def write_rosbag1(
    path: str | Path,
    record: RunRecord,
    *,
    time_origin_ns: int = rm.DEFAULT_TIME_ORIGIN_NS,
    overwrite: bool = False,
    compress: bool = False,
) -> Path:
    """Write ``record`` as a ROS 1 bag (format 2.0) at ``path`` and return the path.

    Parameters
    ----------
    path:
        The ``.bag`` file to write.
    record:
        The run. Its ``truth`` may hold NaN rows (steps without ground truth); those are not published.
    time_origin_ns:
        Stamp (ns since the epoch) of ``t = 0``; default 1 s (see :mod:`slamtrials.io.ros_messages`).
    overwrite:
        Replace an existing file; otherwise an existing ``path`` raises :class:`FileExistsError`.
    compress:
        Compress the chunks with LZ4 (``rosbag record --lz4``); default uncompressed.

    Returns
    -------
    Path
        ``path``. Topics: ``/base_scan``, ``/odom``, ``/base_pose_ground_truth``, ``/tf`` (odom ->
        base_link and base_link -> base_laser_link every step, as stageros does), ``/stall`` and the
        latched ``/slamtrials/run``. Header ``seq`` counts the messages of each topic from 0.

    Raises
    ------
    ConfigError
        A stamp would fall outside ROS 1's time range (negative, or beyond 2106), or two frames share a
        nanosecond (``t`` must be strictly increasing at that resolution).
    """
    from rosbags.rosbag1 import Writer

    path = Path(path)
    stamps = _checked_stamps(record, time_origin_ns, 0, _UINT32_NS, "ROS 1")
    store = rm.typestore(1)
    with _atomic_output(path, overwrite=overwrite) as tmp:
        writer = Writer(tmp)
        if compress:
            writer.set_compression(Writer.CompressionFormat.LZ4)
            writer.compressor = _roslz4_frame
        with writer:
            connections = {}
            for topic, msgtype, latched in _topics(record, ros=1):
                connections[topic] = (
                    writer.add_connection(
                        topic, msgtype, typestore=store, callerid="/slamtrials", latching=1 if latched else None
                    ),
                    msgtype,
                )
            for topic, stamp, msg in _messages(record, stamps, time_origin_ns, ros=1):
                connection, msgtype = connections[topic]
                writer.write(connection, stamp, store.serialize_ros1(msg, msgtype))
    return path


def write_rosbag2(
    path: str | Path,
    record: RunRecord,
    *,
    time_origin_ns: int = rm.DEFAULT_TIME_ORIGIN_NS,
    overwrite: bool = False,
    compress: bool = False,
) -> Path:
    """Write ``record`` as a ROS 2 bag (a folder with ``metadata.yaml``, version 8, and ``<name>.mcap``).

    Parameters
    ----------
    path:
        The bag folder to create (as ``ros2 bag record -o path -s mcap`` would).
    record:
        The run. Its ``truth`` may hold NaN rows (steps without ground truth); those are not published.
    time_origin_ns:
        Stamp (ns since the epoch) of ``t = 0``; default 1 s (see :mod:`slamtrials.io.ros_messages`).
    overwrite:
        Replace an existing folder; otherwise an existing ``path`` raises :class:`FileExistsError`.
    compress:
        Compress the MCAP chunks with zstd (``ros2 bag record --storage-preset-profile zstd_fast``
        style storage compression); default uncompressed.

    Returns
    -------
    Path
        ``path``. Topics as :func:`write_rosbag1`, except that ``base_link -> base_laser_link`` is
        published once on ``/tf_static`` and ``/tf`` carries only ``odom -> base_link``. ``/tf_static``
        and ``/slamtrials/run`` are offered with transient-local durability (latched). Messages are CDR
        in the definitions of ROS 2 Humble.

    Raises
    ------
    ConfigError
        A stamp would fall outside ROS 2's time range (negative, or beyond 2038), or two frames share a
        nanosecond (``t`` must be strictly increasing at that resolution).
    """
    from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer

    path = Path(path)
    stamps = _checked_stamps(record, time_origin_ns, 0, _INT32_NS, "ROS 2")
    store = rm.typestore(2)
    with _atomic_output(path, overwrite=overwrite) as tmp:
        writer = Writer(tmp, version=_ROSBAG2_VERSION, storage_plugin=StoragePlugin.MCAP)
        if compress:
            writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        with writer:
            connections = {}
            for topic, msgtype, latched in _topics(record, ros=2):
                qos = [_latched_qos()] if latched else []
                connections[topic] = (
                    writer.add_connection(topic, msgtype, typestore=store, offered_qos_profiles=qos),
                    msgtype,
                )
            for topic, stamp, msg in _messages(record, stamps, time_origin_ns, ros=2):
                connection, msgtype = connections[topic]
                writer.write(connection, stamp, store.serialize_cdr(msg, msgtype))
    return path


# --- helpers ---------------------------------------------------------------------------------------------


def _checked_stamps(record: RunRecord, origin: int, low: int, high: int, which: str) -> np.ndarray:
    if isinstance(origin, bool) or not isinstance(origin, (int, np.integer)):
        raise ConfigError(f"time_origin_ns must be an integer number of nanoseconds, got {origin!r}")
    if len(record.t) == 0:
        raise ConfigError("cannot write a bag of a run without frames")
    if not np.all(np.isfinite(record.t)):
        raise ConfigError("run timestamps t must be finite to become ROS stamps")
    stamps = rm.stamps_ns(record.t, int(origin))
    if len(stamps) > 1 and not np.all(np.diff(stamps) > 0):
        raise ConfigError("run timestamps t must be strictly increasing at nanosecond resolution to become ROS stamps")
    if stamps.min() < low or stamps.max() > high:
        raise ConfigError(
            f"time_origin_ns={origin} puts stamps at {stamps.min()}..{stamps.max()} ns, outside {which}'s time range "
            f"{low}..{high} ns"
        )
    return stamps


def _topics(record: RunRecord, *, ros: int) -> list[tuple[str, str, bool]]:
    """(topic, message type, latched) of every connection, in the order they are added."""
    topics = [
        (rm.RUN_INFO_TOPIC, rm.STRING, True),
        (rm.SCAN_TOPIC, rm.LASER_SCAN, False),
        (rm.ODOM_TOPIC, rm.ODOMETRY, False),
    ]
    if np.isfinite(record.truth).all(axis=1).any():
        topics.append((rm.TRUTH_TOPIC, rm.ODOMETRY, False))
    topics.append((rm.TF_TOPIC, rm.TF_MESSAGE, False))
    if ros == 2:
        topics.append((rm.TF_STATIC_TOPIC, rm.TF_MESSAGE, True))
    topics.append((rm.STALL_TOPIC, rm.INT8, False))
    return topics


def _roslz4_frame(data: bytes) -> bytes:
    """An LZ4 frame that ROS 1's own reader (roslz4) decompresses.

    roslz4 rejects frames that store the content size, lack the content checksum or link their blocks,
    which rosbags' LZ4 writer does (lz4.frame's defaults), so the chunks are compressed here instead,
    in 4 MB independent blocks as roslz4 writes them.
    """
    import lz4.frame

    return lz4.frame.compress(
        data, block_size=lz4.frame.BLOCKSIZE_MAX4MB, block_linked=False, store_size=False, content_checksum=True
    )


def _latched_qos() -> Any:
    """The QoS ``ros2 bag`` records for a latched publisher (tf_static): reliable, transient local, depth 1."""
    from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime

    infinite = QosTime(9223372036, 854775807)  # rmw's "infinite" duration, as Humble stores it
    return Qos(
        QosHistory.KEEP_LAST,
        1,
        QosReliability.RELIABLE,
        QosDurability.TRANSIENT_LOCAL,
        infinite,
        infinite,
        QosLiveliness.AUTOMATIC,
        infinite,
        False,
    )


class _Factory:
    """Builds the typestore's message objects; ROS 1 headers carry ``seq``, ROS 2 headers do not."""

    def __init__(self, ros: int):
        types = rm.typestore(ros).types
        self.ros = ros
        self.Time = types["builtin_interfaces/msg/Time"]
        self.Header = types["std_msgs/msg/Header"]
        self.LaserScan = types[rm.LASER_SCAN]
        self.Odometry = types[rm.ODOMETRY]
        self.PoseWithCovariance = types["geometry_msgs/msg/PoseWithCovariance"]
        self.TwistWithCovariance = types["geometry_msgs/msg/TwistWithCovariance"]
        self.Pose = types["geometry_msgs/msg/Pose"]
        self.Twist = types["geometry_msgs/msg/Twist"]
        self.Point = types["geometry_msgs/msg/Point"]
        self.Vector3 = types["geometry_msgs/msg/Vector3"]
        self.Quaternion = types["geometry_msgs/msg/Quaternion"]
        self.Transform = types["geometry_msgs/msg/Transform"]
        self.TransformStamped = types["geometry_msgs/msg/TransformStamped"]
        self.TFMessage = types[rm.TF_MESSAGE]
        self.Int8 = types[rm.INT8]
        self.String = types[rm.STRING]
        self.zero_covariance = np.zeros(36)

    def header(self, stamp: int, frame_id: str, seq: int) -> Any:
        time = self.Time(sec=stamp // 1_000_000_000, nanosec=stamp % 1_000_000_000)
        if self.ros == 1:
            return self.Header(seq=seq, stamp=time, frame_id=frame_id)
        return self.Header(stamp=time, frame_id=frame_id)

    def odometry(self, header: Any, child: str, pose: np.ndarray, quat: np.ndarray, twist: np.ndarray) -> Any:
        return self.Odometry(
            header=header,
            child_frame_id=child,
            pose=self.PoseWithCovariance(
                pose=self.Pose(
                    position=self.Point(x=pose[0], y=pose[1], z=0.0),
                    orientation=self.Quaternion(x=quat[0], y=quat[1], z=quat[2], w=quat[3]),
                ),
                covariance=self.zero_covariance,
            ),
            twist=self.TwistWithCovariance(
                twist=self.Twist(
                    linear=self.Vector3(x=twist[0], y=twist[1], z=0.0), angular=self.Vector3(x=0.0, y=0.0, z=twist[2])
                ),
                covariance=self.zero_covariance,
            ),
        )

    def transform(self, header: Any, child: str, pose: np.ndarray, quat: np.ndarray) -> Any:
        return self.TransformStamped(
            header=header,
            child_frame_id=child,
            transform=self.Transform(
                translation=self.Vector3(x=pose[0], y=pose[1], z=0.0),
                rotation=self.Quaternion(x=quat[0], y=quat[1], z=quat[2], w=quat[3]),
            ),
        )


def _messages(record: RunRecord, stamps: np.ndarray, origin: int, *, ros: int) -> Iterator[tuple[str, int, Any]]:
    """Every message of the bag as (topic, stamp ns, message object), in time order."""
    f = _Factory(ros)
    t = np.asarray(record.t, dtype=np.float64)
    odometry = np.asarray(record.odometry, dtype=np.float64)
    truth = np.asarray(record.truth, dtype=np.float64)
    scans = np.ascontiguousarray(record.scans, dtype=np.float32)
    odo_q, truth_q = rm.yaw_quaternions(odometry[:, 2]), rm.yaw_quaternions(truth[:, 2])
    odo_twist, truth_twist = rm.body_twists(t, odometry), rm.body_twists(t, truth)
    has_truth = np.isfinite(truth).all(axis=1)
    laser = record.laser
    beams = scans.shape[1]
    angle_min = laser.angle_min
    increment = laser.angle_increment
    angle_max = angle_min + (beams - 1) * increment
    period = rm.scan_period(record)
    mount = np.asarray(laser.mount, dtype=np.float64)
    mount_q = rm.yaw_quaternions(mount[2])
    no_intensities = np.zeros(0, dtype=np.float32)
    stamp_list = [int(s) for s in stamps]

    first = stamp_list[0]
    yield rm.RUN_INFO_TOPIC, first, f.String(data=rm.run_info_json(record, origin))
    if ros == 2:
        laser_tf = f.transform(f.header(first, rm.BASE_FRAME, 0), rm.LASER_FRAME, mount, mount_q)
        yield rm.TF_STATIC_TOPIC, first, f.TFMessage(transforms=[laser_tf])
    truth_seq = 0
    for k, stamp in enumerate(stamp_list):
        yield (
            rm.SCAN_TOPIC,
            stamp,
            f.LaserScan(
                header=f.header(stamp, rm.LASER_FRAME, k),
                angle_min=angle_min,
                angle_max=angle_max,
                angle_increment=increment,
                time_increment=0.0,
                scan_time=period,
                range_min=laser.range_min,
                range_max=laser.range_max,
                ranges=scans[k],
                intensities=no_intensities,
            ),
        )
        odom_header = f.header(stamp, rm.ODOM_FRAME, k)
        yield rm.ODOM_TOPIC, stamp, f.odometry(odom_header, rm.BASE_FRAME, odometry[k], odo_q[k], odo_twist[k])
        if has_truth[k]:
            truth_header = f.header(stamp, rm.WORLD_FRAME, truth_seq)
            yield rm.TRUTH_TOPIC, stamp, f.odometry(truth_header, rm.BASE_FRAME, truth[k], truth_q[k], truth_twist[k])
            truth_seq += 1
        transforms = [f.transform(f.header(stamp, rm.ODOM_FRAME, k), rm.BASE_FRAME, odometry[k], odo_q[k])]
        if ros == 1:
            transforms.append(f.transform(f.header(stamp, rm.BASE_FRAME, k), rm.LASER_FRAME, mount, mount_q))
        yield rm.TF_TOPIC, stamp, f.TFMessage(transforms=transforms)
        yield rm.STALL_TOPIC, stamp, f.Int8(data=int(bool(record.stalled[k])))


@contextmanager
def _atomic_output(path: Path, *, overwrite: bool) -> Iterator[Path]:
    """Yield a fresh temporary path beside ``path``; on success move it to ``path`` (file or folder).

    The temporary path lives in a hidden folder beside ``path`` and has ``path``'s own name, so a ROS 2
    bag's storage file is already named after the final folder.
    """
    if path.exists() and not overwrite:
        raise FileExistsError(errno.EEXIST, "already exists; pass overwrite=True to replace it", str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    workdir = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp"))
    try:
        tmp = workdir / path.name
        yield tmp
        if tmp.is_file():
            with open(tmp, "rb+") as handle:
                os.fsync(handle.fileno())
            os.replace(tmp, path)
        else:
            if path.exists():
                old = workdir / ".old"
                os.replace(path, old)  # a folder cannot be renamed over another
            os.replace(tmp, path)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
