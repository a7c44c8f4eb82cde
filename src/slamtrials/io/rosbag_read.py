"""Read a ROS 1 or ROS 2 bag back into a :class:`~slamtrials.record.RunRecord`.

Works on the bags :mod:`slamtrials.io.rosbag_write` writes, exactly: float32 scans identical, x and y
bit for bit, yaw to about 1e-15 rad (it passes through a quaternion and comes back wrapped into
(-pi, pi]), ``t`` to the nanosecond, and the laser geometry, stall flags and metadata restored. And on
recordings of real robots: any bag with a ``sensor_msgs/LaserScan`` topic, odometry as
``nav_msgs/Odometry`` (or as ``odom -> base_link`` transforms on ``/tf``) and, optionally, ground truth
as ``nav_msgs/Odometry``.

Pairing: each scan (by its header stamp) gets the odometry and ground truth at its stamp. With
``pairing="interpolate"`` (default) a pose between two messages is interpolated (linear in x, y, shorter
arc in yaw) and a message with exactly the scan's stamp is used as it is; with ``pairing="previous"`` the
latest message at or before the scan is used. Scans before the first odometry message (or, when
interpolating, after the last) are dropped and counted in the metadata. Ground truth outside its
messages' span is NaN.

Time: ``t = (stamp - origin) / 1e9``. The origin is the one stored in ``/slamtrials/run`` when the bag
has it, else the stamp of the first scan kept (so ``t[0] = 0``); it is kept in the metadata as
``ros_bag.ros_time_origin_ns``.

Without a ground-truth topic (``truth_topic=None``) ``truth`` is all NaN and ``metadata["truth_available"]``
is False: odometry is never passed off as ground truth.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from slamtrials.errors import FormatError
from slamtrials.geometry import interpolate
from slamtrials.io import ros_messages as rm
from slamtrials.io.rosbag_source import DECODE_ERRORS, BagSource, open_bag
from slamtrials.record import LaserGeometry, RunRecord

__all__ = ["run_from_bag", "bag_topics"]

log = logging.getLogger(__name__)

_LASER_KEYS = ("angle_min", "angle_increment", "range_min", "range_max")


def bag_topics(path: str | Path) -> dict[str, str]:
    """Topic -> message type of the bag at ``path`` (ROS 1 file, ROS 2 folder or MCAP file).

    Raises
    ------
    FormatError
        Not a bag, or a damaged one.
    """
    with open_bag(path) as bag:
        return dict(bag.topics)


def run_from_bag(
    path: str | Path,
    *,
    scan_topic: str = rm.SCAN_TOPIC,
    odom_topic: str = rm.ODOM_TOPIC,
    truth_topic: str | None = rm.TRUTH_TOPIC,
    use_tf: bool = False,
    odom_frame: str = rm.ODOM_FRAME,
    base_frame: str = rm.BASE_FRAME,
    pairing: Literal["interpolate", "previous"] = "interpolate",
) -> RunRecord:
    """Read a run from a ROS 1 bag, a ROS 2 bag folder or an MCAP file.

    Parameters
    ----------
    path:
        The bag (see :func:`slamtrials.io.rosbag_source.bag_kind` for how its kind is found).
    scan_topic:
        ``sensor_msgs/LaserScan`` topic; every message becomes a frame (if odometry covers it).
    odom_topic:
        ``nav_msgs/Odometry`` topic of the odometry (pose in the odometry frame). Ignored with ``use_tf``.
    truth_topic:
        ``nav_msgs/Odometry`` topic of the ground truth (world frame), or ``None`` for a recording
        without ground truth (then ``truth`` is NaN and ``metadata["truth_available"]`` is False).
    use_tf:
        Take odometry from the ``odom_frame -> base_frame`` transforms on ``/tf`` instead of ``odom_topic``.
    odom_frame, base_frame:
        Frame ids of the odometry transform (for ``use_tf``) and of the robot base (to find the laser
        mount ``base_frame -> <scan frame>`` on ``/tf_static`` or ``/tf``). A leading ``/`` is ignored.
    pairing:
        ``"interpolate"`` or ``"previous"`` (see the module docstring).

    Returns
    -------
    RunRecord
        ``t`` [T] s, ``scans`` float32 [T, B] m, ``odometry`` [T, 3] (odometry frame), ``truth`` [T, 3]
        (world frame, NaN where unknown), ``stalled`` [T] (from ``/stall`` if present, else False).
        ``laser`` comes from ``/slamtrials/run`` when present, else from the first scan (float32 values)
        and the mount transform (zero, with a note in the metadata, if the bag has none). ``metadata``
        holds the stored run's metadata (if any) plus ``truth_available`` and ``ros_bag`` (path, ROS
        version, topics used, pairing, time origin, dropped scans).

    Raises
    ------
    FormatError
        Not a bag or a damaged one; a topic is missing (the message lists the bag's topics) or has
        another message type; the scans change their number of beams; no scan is covered by odometry.
    """
    if pairing not in ("interpolate", "previous"):
        raise ValueError(f"pairing must be 'interpolate' or 'previous', got {pairing!r}")
    path = Path(path)
    with open_bag(path) as bag:
        _require(bag, scan_topic, (rm.LASER_SCAN,), "laser scans")
        if use_tf:
            _require(bag, rm.TF_TOPIC, rm.TF_MESSAGE_ALIASES, f"odometry transforms {odom_frame} -> {base_frame}")
        else:
            _require(bag, odom_topic, (rm.ODOMETRY,), "odometry")
        if truth_topic is not None:
            _require(
                bag,
                truth_topic,
                (rm.ODOMETRY,),
                "ground truth; for a recording without it use truth_topic=None, in the CLI --no-truth",
            )
        wanted = _Wanted(
            scan_topic,
            None if use_tf else odom_topic,
            truth_topic,
            use_tf,
            odom_frame.lstrip("/"),
            base_frame.lstrip("/"),
        )
        try:
            data = _collect(bag, wanted)
        except DECODE_ERRORS as exc:
            raise FormatError(
                path, f"damaged {bag.kind} bag while reading messages: {exc or type(exc).__name__}"
            ) from None
        return _assemble(bag, data, wanted, pairing)


# --- reading ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Wanted:
    scan: str
    odom: str | None
    truth: str | None
    use_tf: bool
    odom_frame: str
    base_frame: str


@dataclass
class _Collected:
    scan_stamps: list[int] = field(default_factory=list)
    ranges: list[np.ndarray] = field(default_factory=list)
    first_scan: Any = None
    odom_stamps: list[int] = field(default_factory=list)
    odom_poses: list[tuple[float, float, float, float, float, float]] = field(default_factory=list)
    truth_stamps: list[int] = field(default_factory=list)
    truth_poses: list[tuple[float, float, float, float, float, float]] = field(default_factory=list)
    stall_times: list[int] = field(default_factory=list)
    stall_values: list[int] = field(default_factory=list)
    run_info: str | None = None
    base_children: dict[str, tuple[float, float, float, float, float, float]] = field(default_factory=dict)
    tf_frames: set[tuple[str, str]] = field(default_factory=set)


def _require(bag: BagSource, topic: str, types: tuple[str, ...], role: str) -> None:
    if topic not in bag.topics:
        raise FormatError(bag.path, f"no topic {topic} ({role}); {bag.topic_list()}")
    if bag.topics[topic] not in types:
        raise FormatError(
            bag.path, f"topic {topic} ({role}) has type {bag.topics[topic]}, expected {' or '.join(types)}"
        )
    bag.check_digest(topic)


def _stamp(header: Any) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def _pose6(pose: Any) -> tuple[float, float, float, float, float, float]:
    """(x, y, qx, qy, qz, qw) of a ``geometry_msgs/Pose``."""
    p, q = pose.position, pose.orientation
    return (float(p.x), float(p.y), float(q.x), float(q.y), float(q.z), float(q.w))


def _transform6(transform: Any) -> tuple[float, float, float, float, float, float]:
    """(x, y, qx, qy, qz, qw) of a ``geometry_msgs/Transform``."""
    p, q = transform.translation, transform.rotation
    return (float(p.x), float(p.y), float(q.x), float(q.y), float(q.z), float(q.w))


#: Topics read when present (with these types): the run description, stall flags, static transforms.
_OPTIONAL = {rm.RUN_INFO_TOPIC: (rm.STRING,), rm.STALL_TOPIC: (rm.INT8,), rm.TF_STATIC_TOPIC: rm.TF_MESSAGE_ALIASES}


def _collect(bag: BagSource, want: _Wanted) -> _Collected:
    out = _Collected()
    optional = [topic for topic, types in _OPTIONAL.items() if bag.topics.get(topic) in types]
    topics = [want.scan] + [t for t in (want.odom, want.truth) if t is not None] + optional
    if want.use_tf:
        topics.append(rm.TF_TOPIC)
    types = bag.topics
    for topic, timestamp, raw in bag.messages(list(dict.fromkeys(topics))):
        msg = bag.decode(raw, types[topic])
        if topic == want.scan:
            if out.first_scan is None:
                out.first_scan = msg
            out.scan_stamps.append(_stamp(msg.header))
            out.ranges.append(msg.ranges)
        if topic == want.odom:
            out.odom_stamps.append(_stamp(msg.header))
            out.odom_poses.append(_pose6(msg.pose.pose))
        if topic == want.truth:  # may be the odometry topic, if the caller says so
            out.truth_stamps.append(_stamp(msg.header))
            out.truth_poses.append(_pose6(msg.pose.pose))
        if topic == rm.STALL_TOPIC:
            out.stall_times.append(timestamp)
            out.stall_values.append(int(msg.data))
        if topic == rm.RUN_INFO_TOPIC:
            if out.run_info is None:
                out.run_info = msg.data
        if topic in (rm.TF_TOPIC, rm.TF_STATIC_TOPIC):
            _collect_transforms(msg, want, out)
    return out


def _collect_transforms(msg: Any, want: _Wanted, out: _Collected) -> None:
    for transform in msg.transforms:
        parent, child = transform.header.frame_id.lstrip("/"), transform.child_frame_id.lstrip("/")
        out.tf_frames.add((parent, child))
        if parent == want.base_frame:
            out.base_children.setdefault(child, _transform6(transform.transform))
        if want.use_tf and parent == want.odom_frame and child == want.base_frame:
            out.odom_stamps.append(_stamp(transform.header))
            out.odom_poses.append(_transform6(transform.transform))


def _find_mount(
    bag: BagSource, want: _Wanted, laser_frame: str, out: _Collected
) -> tuple[float, float, float, float, float, float] | None:
    """The ``base_frame -> laser_frame`` transform: from what was read, else the first one on ``/tf``."""
    if laser_frame in out.base_children:
        return out.base_children[laser_frame]
    if want.use_tf or bag.topics.get(rm.TF_TOPIC) not in rm.TF_MESSAGE_ALIASES:
        return None
    try:
        for _, _, raw in bag.messages([rm.TF_TOPIC]):
            for transform in bag.decode(raw, bag.topics[rm.TF_TOPIC]).transforms:
                if (
                    transform.header.frame_id.lstrip("/") == want.base_frame
                    and transform.child_frame_id.lstrip("/") == laser_frame
                ):
                    return _transform6(transform.transform)
    except DECODE_ERRORS as exc:
        raise FormatError(bag.path, f"damaged {bag.kind} bag while reading /tf: {exc or type(exc).__name__}") from None
    return None


# --- assembling the record ----------------------------------------------------------------------------------


def _poses(stamps: list[int], poses6: list[tuple[float, ...]]) -> tuple[np.ndarray, np.ndarray]:
    """Sorted int64 stamps [N] and float64 poses [N, 3] (yaw from the quaternion)."""
    s = np.asarray(stamps, dtype=np.int64)
    p6 = np.asarray(poses6, dtype=np.float64).reshape(-1, 6)
    order = np.argsort(s, kind="stable")
    poses = np.column_stack([p6[:, 0], p6[:, 1], rm.quaternion_yaw(p6[:, 2:6])])
    return s[order], poses[order]


def _pair(query: np.ndarray, stamps: np.ndarray, poses: np.ndarray, pairing: str) -> np.ndarray:
    """Poses [Q, 3] at the ``query`` stamps (int64 ns): NaN where the messages do not cover a stamp."""
    out = np.full((len(query), 3), np.nan)
    if len(stamps) == 0:
        return out
    before = np.searchsorted(stamps, query, side="right") - 1  # latest message at or before
    covered = before >= 0
    if pairing == "previous":
        out[covered] = poses[before[covered]]
        return out
    exact = covered & (stamps[np.maximum(before, 0)] == query)
    out[exact] = poses[before[exact]]
    inner = covered & ~exact & (before + 1 < len(stamps))
    if inner.any():
        i0 = before[inner]
        t0, t1 = stamps[i0], stamps[i0 + 1]
        fraction = (query[inner] - t0).astype(np.float64) / (t1 - t0).astype(np.float64)
        out[inner] = interpolate(poses[i0], poses[i0 + 1], fraction)
    return out


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _parse_run_info(bag: BagSource, text: str | None) -> dict[str, Any] | None:
    if text is None:
        return None
    where = f"topic {rm.RUN_INFO_TOPIC}"
    try:
        doc = json.loads(text)
    except ValueError as exc:
        raise FormatError(bag.path, f"{where}: not valid JSON ({exc})") from None
    if not isinstance(doc, dict) or doc.get("format") != rm.RUN_INFO_FORMAT:
        raise FormatError(bag.path, f'{where}: expected a JSON object with "format": "{rm.RUN_INFO_FORMAT}"')
    origin, laser, metadata = doc.get("time_origin_ns"), doc.get("laser"), doc.get("metadata")
    if isinstance(origin, bool) or not isinstance(origin, int):
        raise FormatError(bag.path, f"{where}: time_origin_ns must be an integer, got {origin!r}")
    if not isinstance(laser, dict) or not all(_is_number(laser.get(k)) for k in _LASER_KEYS):
        raise FormatError(bag.path, f"{where}: laser must be an object with numbers {', '.join(_LASER_KEYS)}")
    mount = laser.get("mount", [0.0, 0.0, 0.0])
    if not isinstance(mount, list) or len(mount) != 3 or not all(_is_number(v) for v in mount):
        raise FormatError(bag.path, f"{where}: laser.mount must be [x, y, theta], got {mount!r}")
    if not isinstance(metadata, dict):
        raise FormatError(bag.path, f"{where}: metadata must be a JSON object")
    return doc


def _info_laser(bag: BagSource, info: dict[str, Any]) -> LaserGeometry:
    """The laser geometry of a checked ``/slamtrials/run`` document."""
    try:
        return LaserGeometry.from_dict(info["laser"])
    except ValueError as exc:
        raise FormatError(bag.path, f"{rm.RUN_INFO_TOPIC}: laser: {exc}") from None


def _scans(bag: BagSource, topic: str, ranges: list[np.ndarray]) -> np.ndarray:
    if not ranges:
        raise FormatError(bag.path, f"topic {topic} has no messages")
    beams = {len(r) for r in ranges}
    if len(beams) != 1:
        raise FormatError(bag.path, f"topic {topic}: the scans have different numbers of beams {sorted(beams)[:5]}")
    return np.stack(ranges).astype(np.float32, copy=False)


def _laser_from_scans(bag: BagSource, want: _Wanted, data: _Collected, notes: dict[str, Any]) -> LaserGeometry:
    scan = data.first_scan
    frame = scan.header.frame_id.lstrip("/")
    found = _find_mount(bag, want, frame, data)
    if found is None:
        mount = (0.0, 0.0, 0.0)
        notes["laser_mount"] = f"no transform {want.base_frame} -> {frame} in the bag; assumed zero"
        log.warning(
            "%s: no transform %s -> %s; assuming the laser sits at the base origin", bag.path, want.base_frame, frame
        )
    else:
        mount = (float(found[0]), float(found[1]), float(rm.quaternion_yaw(np.asarray(found[2:6]))))
        notes["laser_mount"] = f"transform {want.base_frame} -> {frame}"
    try:
        return LaserGeometry(
            angle_min=float(scan.angle_min),
            angle_increment=float(scan.angle_increment),
            range_min=float(scan.range_min),
            range_max=float(scan.range_max),
            mount=mount,
        )
    except ValueError as exc:
        raise FormatError(bag.path, f"topic {want.scan}: first scan's geometry: {exc}") from None


def _assemble(bag: BagSource, data: _Collected, want: _Wanted, pairing: str) -> RunRecord:
    scans = _scans(bag, want.scan, data.ranges)
    scan_stamps = np.asarray(data.scan_stamps, dtype=np.int64)
    order = np.argsort(scan_stamps, kind="stable")
    scan_stamps, scans = scan_stamps[order], scans[order]
    if len(scan_stamps) > 1 and not np.all(np.diff(scan_stamps) > 0):
        raise FormatError(bag.path, f"topic {want.scan}: two scans have the same header stamp")
    odom_source = f"{rm.TF_TOPIC} {want.odom_frame} -> {want.base_frame}" if want.use_tf else want.odom
    if not data.odom_stamps:
        raise FormatError(
            bag.path,
            f"no odometry in {odom_source}" + (f"; /tf has {sorted(data.tf_frames)[:10]}" if want.use_tf else ""),
        )
    odometry = _pair(scan_stamps, *_poses(data.odom_stamps, data.odom_poses), pairing)
    keep = np.isfinite(odometry).all(axis=1)
    if not keep.any():
        raise FormatError(
            bag.path, f"no scan of {want.scan} falls within the time span of the odometry ({odom_source})"
        )
    scan_stamps, scans, odometry = scan_stamps[keep], scans[keep], odometry[keep]
    if want.truth is not None:
        truth = _pair(scan_stamps, *_poses(data.truth_stamps, data.truth_poses), pairing)
    else:
        truth = np.full(odometry.shape, np.nan)
    stalled = np.zeros(len(scan_stamps), dtype=bool)
    if data.stall_times:
        times = np.asarray(data.stall_times, dtype=np.int64)
        order = np.argsort(times, kind="stable")
        index = np.searchsorted(times[order], scan_stamps, side="right") - 1
        values = np.asarray(data.stall_values)[order]
        stalled = np.where(index >= 0, values[np.maximum(index, 0)] != 0, False)

    info = _parse_run_info(bag, data.run_info)
    notes: dict[str, Any] = {}
    if info is not None:
        laser, metadata, origin = _info_laser(bag, info), dict(info["metadata"]), int(info["time_origin_ns"])
    else:
        laser, metadata, origin = _laser_from_scans(bag, want, data, notes), {}, int(scan_stamps[0])
    t = (scan_stamps - origin).astype(np.float64) / 1e9
    metadata["truth_available"] = bool(np.isfinite(truth).all(axis=1).any())
    metadata["ros_bag"] = {
        "path": str(bag.path),
        "ros": bag.ros,
        "scan_topic": want.scan,
        "odometry": odom_source,
        "truth_topic": want.truth,
        "pairing": pairing,
        "ros_time_origin_ns": origin,
        "dropped_scans": int(np.count_nonzero(~keep)),
        "run_info": info is not None,
        **notes,
    }
    return RunRecord(t=t, scans=scans, odometry=odometry, truth=truth, stalled=stalled, laser=laser, metadata=metadata)
