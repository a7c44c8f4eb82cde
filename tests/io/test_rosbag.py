"""ROS bags: exact round trips (ROS 1 and ROS 2), the topic layout as ROS 1's own reader sees it, recordings
of real robots (other topics, rates, no ground truth), and clear errors."""

from __future__ import annotations

import json
import shutil
import subprocess
from functools import cache
from pathlib import Path

import numpy as np
import pytest
import yaml

from slamtrials.errors import ConfigError, FormatError
from slamtrials.io.rosbag import bag_topics, run_from_bag, write_bag, write_rosbag1, write_rosbag2
from slamtrials.io.runfolder import read_run, write_run
from slamtrials.record import LaserGeometry, RunRecord
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.worlds import World

MOUNT = [0.12, -0.03, 0.05]


@cache
def _simulated() -> RunRecord:
    occ = np.ones((60, 200), bool)
    occ[10:50, 10:190] = False  # a 9 m x 2 m room
    world = World(occ, 0.05, name="corridor", start=np.array([1.0, 1.5, 0.0]))
    config = SimConfig.from_dict({"laser": {"mount": MOUNT}})
    return simulate_waypoints(world, [[2.5, 1.5], [2.5, 2.2], [1.2, 1.2]], config, seed=3, max_time=20.0)


def small_run() -> RunRecord:
    """A fresh copy of a short simulated run that turns (yaw crosses quadrants) with an off-centre laser."""
    run = _simulated()
    return RunRecord(
        t=run.t.copy(),
        scans=run.scans.copy(),
        odometry=run.odometry.copy(),
        truth=run.truth.copy(),
        stalled=run.stalled.copy(),
        laser=run.laser,
        metadata=dict(run.metadata),
    )


def wrapped(angle):
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def assert_same_run(back: RunRecord, record: RunRecord) -> None:
    np.testing.assert_array_equal(back.scans, record.scans)
    assert back.scans.dtype == np.float32
    assert np.max(np.abs(back.t - record.t)) <= 1e-9
    for name in ("odometry", "truth"):
        a, b = getattr(back, name), getattr(record, name)
        np.testing.assert_allclose(a[:, :2], b[:, :2], rtol=0, atol=1e-9)
        assert np.max(np.abs(wrapped(a[:, 2] - b[:, 2]))) <= 1e-9
    np.testing.assert_array_equal(back.stalled, record.stalled)
    assert back.laser == record.laser


def _write(kind: str, path: Path, record: RunRecord, **options) -> Path:
    return write_bag(path / ("run.bag" if kind == "ros1" else "run"), record, ros=1 if kind == "ros1" else 2, **options)


@pytest.mark.parametrize("kind", ["ros1", "ros2"])
def test_round_trip_is_exact(tmp_path, kind):
    record = small_run()
    record.stalled[5:8] = True
    bag = _write(kind, tmp_path, record)
    back = run_from_bag(bag)
    assert_same_run(back, record)
    assert back.metadata["seed"] == 3 and back.metadata["world"] == "corridor"
    assert back.metadata["truth_available"] is True
    assert back.metadata["ros_bag"]["ros"] == (1 if kind == "ros1" else 2)
    assert back.metadata["ros_bag"]["dropped_scans"] == 0
    assert back.laser.mount == tuple(MOUNT)


@pytest.mark.parametrize("kind", ["ros1", "ros2"])
def test_stamps_keep_nanoseconds_with_a_unix_time_origin(tmp_path, kind):
    record = small_run()
    origin = 1_700_000_000_123_456_789
    back = run_from_bag(_write(kind, tmp_path, record, time_origin_ns=origin))
    assert np.max(np.abs(back.t - record.t)) <= 1e-9
    assert back.metadata["ros_bag"]["ros_time_origin_ns"] == origin


def test_bare_mcap_file_reads_like_its_folder(tmp_path):
    record = small_run()
    write_rosbag2(tmp_path / "run", record)
    shutil.copy(tmp_path / "run" / "run.mcap", tmp_path / "alone.mcap")
    assert_same_run(run_from_bag(tmp_path / "alone.mcap"), record)
    assert_same_run(run_from_bag(tmp_path / "run" / "run.mcap"), record)


def test_ros2_layout_static_laser_transform_is_latched(tmp_path):
    bag = write_rosbag2(tmp_path / "run", small_run())
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    topics = {t["topic_metadata"]["name"]: t for t in info["topics_with_message_count"]}
    assert info["storage_identifier"] == "mcap" and info["relative_file_paths"] == ["run.mcap"]
    assert topics["/tf_static"]["message_count"] == 1
    assert info["version"] == 8  # QoS as a YAML string, as Humble reads it
    qos = yaml.safe_load(topics["/tf_static"]["topic_metadata"]["offered_qos_profiles"])
    assert qos[0]["durability"] == 1 and qos[0]["reliability"] == 1  # rmw's TRANSIENT_LOCAL and RELIABLE
    assert topics["/tf"]["topic_metadata"]["type"] == "tf2_msgs/msg/TFMessage"
    assert topics["/base_scan"]["message_count"] == len(small_run())
    assert not list(tmp_path.glob(".*"))  # no temporary left behind


def test_odometry_from_tf_equals_the_odometry_topic(tmp_path):
    record = small_run()
    bag = write_rosbag1(tmp_path / "run.bag", record)
    back = run_from_bag(bag, use_tf=True, odom_topic="/nonexistent")
    assert_same_run(back, record)
    assert back.metadata["ros_bag"]["odometry"] == "/tf odom -> base_link"


def test_existing_output_is_kept_unless_overwrite(tmp_path):
    first, second = small_run(), small_run()
    second.scans[:] = 1.0
    for kind in ("ros1", "ros2"):
        bag = _write(kind, tmp_path, first)
        with pytest.raises(FileExistsError):
            _write(kind, tmp_path, second)
        np.testing.assert_array_equal(run_from_bag(bag).scans, first.scans)
        _write(kind, tmp_path, second, overwrite=True)
        np.testing.assert_array_equal(run_from_bag(bag).scans, second.scans)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run", "run.bag"]


def test_time_before_ros1_epoch_is_refused(tmp_path):
    with pytest.raises(ConfigError, match="time range"):
        write_rosbag1(tmp_path / "run.bag", small_run(), time_origin_ns=-5)
    record = small_run()
    record.t[3] = record.t[2] + 1e-10  # the same nanosecond
    with pytest.raises(ConfigError, match="strictly increasing"):
        write_rosbag2(tmp_path / "run", record)
    assert not list(tmp_path.iterdir())


def test_runs_without_truth_export_no_truth_topic(tmp_path):
    record = small_run()
    record.truth[:] = np.nan
    bag = write_rosbag1(tmp_path / "run.bag", record)
    assert "/base_pose_ground_truth" not in bag_topics(bag)
    back = run_from_bag(bag, truth_topic=None)
    assert np.isnan(back.truth).all() and back.metadata["truth_available"] is False


# --- ROS 1's own reader ---------------------------------------------------------------------------------

DUMP_SCRIPT = r"""
import json, sys
import rosbag

def plain(value):
    if hasattr(value, "__slots__"):
        return {name: plain(getattr(value, name)) for name in value.__slots__}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value

with rosbag.Bag(sys.argv[1]) as bag:
    info = bag.get_type_and_topic_info()
    topics = {name: [t.msg_type, t.message_count] for name, t in info.topics.items()}
    latching = {c.topic: c.header.get("latching", b"").decode() for c in bag._connections.values()}
    messages = [{"topic": topic, "type": msg._type, "time": t.to_nsec(), "msg": plain(msg)}
                for topic, msg, t in bag.read_messages()]
json.dump({"topics": topics, "latching": latching, "messages": messages}, sys.stdout)
"""


@cache
def _ros1_python() -> bool:
    try:
        return (
            subprocess.run(["/usr/bin/python3", "-c", "import rosbag"], capture_output=True, timeout=60).returncode == 0
        )
    except (OSError, subprocess.TimeoutExpired):
        return False


def _stamp(header: dict) -> int:
    return header["stamp"]["secs"] * 1_000_000_000 + header["stamp"]["nsecs"]


def _yaw(q: dict) -> float:
    return float(np.arctan2(2 * (q["w"] * q["z"] + q["x"] * q["y"]), 1 - 2 * (q["y"] ** 2 + q["z"] ** 2)))


@pytest.mark.slow  # ROS 1's own reader in another Python
@pytest.mark.skipif(
    not _ros1_python(), reason="ROS 1's rosbag is not importable by /usr/bin/python3 (apt-get install python3-rosbag)"
)
def test_ros1_reader_sees_the_stage_layout(tmp_path):
    record = small_run()
    record.stalled[3] = True
    origin = 1_000_000_000
    bag = write_rosbag1(tmp_path / "run.bag", record)
    result = subprocess.run(
        ["/usr/bin/python3", "-c", DUMP_SCRIPT, str(bag)], capture_output=True, text=True, timeout=300
    )
    assert result.returncode == 0, result.stderr
    dump = json.loads(result.stdout)
    n = len(record)
    assert dump["topics"] == {
        "/base_scan": ["sensor_msgs/LaserScan", n],
        "/odom": ["nav_msgs/Odometry", n],
        "/base_pose_ground_truth": ["nav_msgs/Odometry", n],
        "/tf": ["tf2_msgs/TFMessage", n],
        "/stall": ["std_msgs/Int8", n],
        "/slamtrials/run": ["std_msgs/String", 1],
    }
    assert dump["latching"]["/slamtrials/run"] == "1"
    by_topic: dict[str, list[dict]] = {}
    for m in dump["messages"]:
        by_topic.setdefault(m["topic"], []).append(m)
    stamps = origin + np.rint(record.t * 1e9).astype(np.int64)

    info = json.loads(by_topic["/slamtrials/run"][0]["msg"]["data"])
    assert info["time_origin_ns"] == origin and info["laser"] == record.laser.to_dict()

    laser = record.laser
    beams = record.scans.shape[1]
    for k, m in enumerate(by_topic["/base_scan"]):
        msg = m["msg"]
        assert m["type"] == "sensor_msgs/LaserScan" and m["time"] == stamps[k]
        assert msg["header"]["seq"] == k and _stamp(msg["header"]) == stamps[k]
        assert msg["header"]["frame_id"] == "base_laser_link"
        np.testing.assert_array_equal(np.array(msg["ranges"], dtype=np.float32), record.scans[k])
        assert msg["intensities"] == []
        assert msg["angle_min"] == np.float32(laser.angle_min)
        assert msg["angle_increment"] == np.float32(laser.angle_increment)
        assert msg["angle_max"] == np.float32(laser.angle_min + (beams - 1) * laser.angle_increment)
        assert msg["range_min"] == np.float32(laser.range_min) and msg["range_max"] == np.float32(laser.range_max)
        assert msg["time_increment"] == 0.0 and msg["scan_time"] == np.float32(0.1)

    for topic, poses, frame in (("/odom", record.odometry, "odom"), ("/base_pose_ground_truth", record.truth, "map")):
        for k, m in enumerate(by_topic[topic]):
            msg = m["msg"]
            assert msg["header"]["seq"] == k and _stamp(msg["header"]) == stamps[k] == m["time"]
            assert msg["header"]["frame_id"] == frame and msg["child_frame_id"] == "base_link"
            pose = msg["pose"]["pose"]
            assert (pose["position"]["x"], pose["position"]["y"], pose["position"]["z"]) == (
                poses[k, 0],
                poses[k, 1],
                0.0,
            )
            q = pose["orientation"]
            assert q["x"] == 0.0 and q["y"] == 0.0 and abs(q["z"] ** 2 + q["w"] ** 2 - 1) < 1e-15
            assert abs(wrapped(_yaw(q) - poses[k, 2])) < 1e-12
            twist = msg["twist"]["twist"]
            if k > 0:
                dt = record.t[k] - record.t[k - 1]
                c, s = np.cos(poses[k - 1, 2]), np.sin(poses[k - 1, 2])
                dx, dy = poses[k, 0] - poses[k - 1, 0], poses[k, 1] - poses[k - 1, 1]
                assert abs(twist["linear"]["x"] - (c * dx + s * dy) / dt) < 1e-9
                assert abs(twist["linear"]["y"] - (-s * dx + c * dy) / dt) < 1e-9
                assert abs(twist["angular"]["z"] - wrapped(poses[k, 2] - poses[k - 1, 2]) / dt) < 1e-9
            assert msg["pose"]["covariance"] == [0.0] * 36

    for k, m in enumerate(by_topic["/tf"]):
        odom_tf, laser_tf = m["msg"]["transforms"]
        assert (odom_tf["header"]["frame_id"], odom_tf["child_frame_id"]) == ("odom", "base_link")
        assert (laser_tf["header"]["frame_id"], laser_tf["child_frame_id"]) == ("base_link", "base_laser_link")
        assert _stamp(odom_tf["header"]) == _stamp(laser_tf["header"]) == stamps[k]
        translation = odom_tf["transform"]["translation"]
        assert (translation["x"], translation["y"]) == (record.odometry[k, 0], record.odometry[k, 1])
        assert abs(wrapped(_yaw(odom_tf["transform"]["rotation"]) - record.odometry[k, 2])) < 1e-12
        mount = laser_tf["transform"]
        assert (mount["translation"]["x"], mount["translation"]["y"], mount["translation"]["z"]) == (
            MOUNT[0],
            MOUNT[1],
            0.0,
        )
        assert abs(_yaw(mount["rotation"]) - MOUNT[2]) < 1e-15

    assert [m["msg"]["data"] for m in by_topic["/stall"]] == record.stalled.astype(int).tolist()


@pytest.mark.slow  # ROS 1's own reader in another Python
@pytest.mark.skipif(
    not _ros1_python(), reason="ROS 1's rosbag is not importable by /usr/bin/python3 (apt-get install python3-rosbag)"
)
def test_ros1_reader_reads_lz4_bags(tmp_path):
    record = small_run()
    bag = write_rosbag1(tmp_path / "run.bag", record, compress=True)
    result = subprocess.run(
        ["/usr/bin/python3", "-c", DUMP_SCRIPT, str(bag)], capture_output=True, text=True, timeout=300
    )
    assert result.returncode == 0, result.stderr
    scans = [m["msg"]["ranges"] for m in json.loads(result.stdout)["messages"] if m["topic"] == "/base_scan"]
    np.testing.assert_array_equal(np.array(scans, dtype=np.float32), record.scans)
    assert_same_run(run_from_bag(bag), record)


WRITE_SCRIPT = r"""
import json, math, sys
import rosbag, rospy
from genpy.dynamic import generate_dynamic

classes = {}
for name, text in json.loads(sys.stdin.read()).items():
    classes.update(generate_dynamic(name, text))
LaserScan, Odometry = classes["sensor_msgs/LaserScan"], classes["nav_msgs/Odometry"]
TFMessage, TransformStamped = classes["tf2_msgs/TFMessage"], classes["geometry_msgs/TransformStamped"]
with rosbag.Bag(sys.argv[1], "w") as bag:
    for k in range(30):  # odometry and tf at 50 Hz, a scan 10 ms after every fifth
        stamp = rospy.Time(1600000000, 0) + rospy.Duration.from_sec(0.02 * k)
        yaw = 0.1 * k
        odom = Odometry()
        odom.header.seq, odom.header.stamp, odom.header.frame_id, odom.child_frame_id = k, stamp, "odom", "base_link"
        odom.pose.pose.position.x, odom.pose.pose.position.y = 0.05 * k, -0.01 * k
        odom.pose.pose.orientation.z, odom.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        bag.write("/odom", odom, stamp)
        base, laser = TransformStamped(), TransformStamped()
        base.header.stamp, base.header.frame_id, base.child_frame_id = stamp, "odom", "base_link"
        base.transform.translation.x, base.transform.translation.y = 0.05 * k, -0.01 * k
        base.transform.rotation.z, base.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        laser.header.stamp, laser.header.frame_id, laser.child_frame_id = stamp, "base_link", "laser"
        laser.transform.translation.x, laser.transform.rotation.w = 0.25, 1.0
        bag.write("/tf", TFMessage(transforms=[base, laser]), stamp)
        if k % 5 == 2:
            scan = LaserScan()
            scan.header.seq, scan.header.frame_id = k // 5, "laser"
            scan.header.stamp = stamp + rospy.Duration.from_sec(0.01)
            scan.angle_min, scan.angle_max, scan.angle_increment = -1.0, 1.0, 0.5
            scan.range_min, scan.range_max = 0.05, 20.0
            scan.ranges = [1.0 + 0.25 * k + 0.125 * i for i in range(5)]
            bag.write("/scan", scan, scan.header.stamp)
"""


@pytest.mark.skipif(
    not _ros1_python(), reason="ROS 1's rosbag is not importable by /usr/bin/python3 (apt-get install python3-rosbag)"
)
@pytest.mark.parametrize("use_tf", [False, True])
def test_bag_written_by_ros1_itself_is_imported(tmp_path, use_tf):
    from slamtrials.io.ros_messages import typestore

    store = typestore(1)
    definitions = {
        name.replace("/msg/", "/"): store.generate_msgdef(name)[0]
        for name in ("sensor_msgs/msg/LaserScan", "nav_msgs/msg/Odometry", "tf2_msgs/msg/TFMessage")
    }
    bag = tmp_path / "robot.bag"
    result = subprocess.run(
        ["/usr/bin/python3", "-c", WRITE_SCRIPT, str(bag)],
        input=json.dumps(definitions),
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    run = run_from_bag(bag, scan_topic="/scan", truth_topic=None, use_tf=use_tf)
    k = 2 + 5 * np.arange(6)
    np.testing.assert_allclose(run.t, 0.1 * np.arange(6), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(run.scans, [[1.0 + 0.25 * kk + 0.125 * i for i in range(5)] for kk in k])
    # each scan lies halfway between two odometry messages
    np.testing.assert_allclose(
        run.odometry, np.column_stack([0.05 * (k + 0.5), -0.01 * (k + 0.5), 0.1 * (k + 0.5)]), atol=1e-12
    )
    assert run.laser == LaserGeometry(
        angle_min=-1.0, angle_increment=0.5, range_min=float(np.float32(0.05)), range_max=20.0, mount=(0.25, 0.0, 0.0)
    )
    assert np.isnan(run.truth).all() and run.metadata["ros_bag"]["ros_time_origin_ns"] == 1_600_000_000_050_000_000


# --- recordings of real robots ------------------------------------------------------------------------------


def _robot_bag(path: Path, *, ros: int, with_mount: bool = True, odom_delay_ns: int = 0) -> dict:
    """A bag as a real robot records it: /scan at 10 Hz, /odom at 50 Hz (other stamps), no ground truth."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import StoragePlugin
    from rosbags.rosbag2 import Writer as Writer2

    from slamtrials.io.ros_messages import typestore, yaw_quaternions

    store = typestore(ros)
    T = store.types
    start = 1_650_000_000_000_000_000
    scan_stamps = start + 7_000_000 + np.arange(20) * 100_000_000
    odom_stamps = start + odom_delay_ns + np.arange(120) * 20_000_000
    odom = np.column_stack([np.arange(120) * 0.01, np.arange(120) * 0.002, wrapped(3.0 + np.arange(120) * 0.01)])
    ranges = np.random.default_rng(1).uniform(0.5, 8.0, (20, 181)).astype(np.float32)

    def header(stamp, frame):
        time = T["builtin_interfaces/msg/Time"](sec=int(stamp) // 10**9, nanosec=int(stamp) % 10**9)
        return (
            T["std_msgs/msg/Header"](seq=0, stamp=time, frame_id=frame)
            if ros == 1
            else T["std_msgs/msg/Header"](stamp=time, frame_id=frame)
        )

    def quat(yaw):
        x, y, z, w = yaw_quaternions(yaw)
        return T["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w)

    messages = []
    for k, stamp in enumerate(scan_stamps):
        messages.append(
            (
                "/scan",
                "sensor_msgs/msg/LaserScan",
                int(stamp),
                T["sensor_msgs/msg/LaserScan"](
                    header=header(stamp, "laser"),
                    angle_min=-1.5,
                    angle_max=1.5,
                    angle_increment=3.0 / 180,
                    time_increment=0.0,
                    scan_time=0.1,
                    range_min=0.1,
                    range_max=10.0,
                    ranges=ranges[k],
                    intensities=np.zeros(0, np.float32),
                ),
            )
        )
    zero36 = np.zeros(36)
    for k, stamp in enumerate(odom_stamps):
        Vector3 = T["geometry_msgs/msg/Vector3"]
        messages.append(
            (
                "/odom",
                "nav_msgs/msg/Odometry",
                int(stamp),
                T["nav_msgs/msg/Odometry"](
                    header=header(stamp, "odom"),
                    child_frame_id="base_footprint",
                    pose=T["geometry_msgs/msg/PoseWithCovariance"](
                        pose=T["geometry_msgs/msg/Pose"](
                            position=T["geometry_msgs/msg/Point"](x=odom[k, 0], y=odom[k, 1], z=0.0),
                            orientation=quat(odom[k, 2]),
                        ),
                        covariance=zero36,
                    ),
                    twist=T["geometry_msgs/msg/TwistWithCovariance"](
                        twist=T["geometry_msgs/msg/Twist"](
                            linear=Vector3(x=0.0, y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=0.0)
                        ),
                        covariance=zero36,
                    ),
                ),
            )
        )
    if with_mount:
        transform = T["geometry_msgs/msg/TransformStamped"](
            header=header(start, "base_link"),
            child_frame_id="laser",
            transform=T["geometry_msgs/msg/Transform"](
                translation=T["geometry_msgs/msg/Vector3"](x=0.2, y=0.0, z=0.3), rotation=quat(np.pi)
            ),
        )
        messages.append(
            ("/tf_static", "tf2_msgs/msg/TFMessage", start, T["tf2_msgs/msg/TFMessage"](transforms=[transform]))
        )
    messages.sort(key=lambda m: m[2])
    serialize = store.serialize_ros1 if ros == 1 else store.serialize_cdr
    writer = Writer1(path) if ros == 1 else Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP)
    with writer:
        connections = {}
        for topic, msgtype, stamp, msg in messages:
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(connections[topic], stamp, serialize(msg, msgtype))
    return {"scan_stamps": scan_stamps, "odom_stamps": odom_stamps, "odom": odom, "ranges": ranges}


@pytest.mark.parametrize("ros", [1, 2])
def test_real_robot_bag_interpolates_odometry_and_has_no_truth(tmp_path, ros):
    bag = tmp_path / ("robot.bag" if ros == 1 else "robot")
    made = _robot_bag(bag, ros=ros)
    run = run_from_bag(bag, scan_topic="/scan", truth_topic=None)
    np.testing.assert_array_equal(run.scans, made["ranges"])
    np.testing.assert_array_equal(run.t, (made["scan_stamps"] - made["scan_stamps"][0]) / 1e9)
    # scan k is 7 ms after odometry message 5k: 35 % of the way to the next one
    i = 5 * np.arange(20)
    expected = made["odom"][i] + 0.35 * (made["odom"][i + 1] - made["odom"][i])
    expected[:, 2] = made["odom"][i, 2] + 0.35 * wrapped(made["odom"][i + 1, 2] - made["odom"][i, 2])
    np.testing.assert_allclose(run.odometry[:, :2], expected[:, :2], rtol=0, atol=1e-12)
    np.testing.assert_allclose(wrapped(run.odometry[:, 2] - expected[:, 2]), 0, atol=1e-12)  # yaw crosses +-pi
    assert np.isnan(run.truth).all() and run.metadata["truth_available"] is False
    assert not run.stalled.any()
    assert run.laser.angle_min == np.float32(-1.5) and run.laser.range_max == 10.0
    assert run.laser.mount[:2] == (0.2, 0.0) and abs(abs(run.laser.mount[2]) - np.pi) < 1e-12
    assert run.metadata["ros_bag"]["ros_time_origin_ns"] == made["scan_stamps"][0]
    # the run folder keeps the NaN ground truth as it is
    back = read_run(write_run(tmp_path / "folder", run))
    assert np.isnan(back.truth).all() and back.metadata["truth_available"] is False
    np.testing.assert_array_equal(back.odometry, run.odometry)


def test_previous_pairing_takes_the_latest_odometry_at_or_before(tmp_path):
    made = _robot_bag(tmp_path / "robot.bag", ros=1, with_mount=False)
    run = run_from_bag(tmp_path / "robot.bag", scan_topic="/scan", truth_topic=None, pairing="previous")
    np.testing.assert_array_equal(run.odometry, made["odom"][::5][:20])
    assert run.laser.mount == (0.0, 0.0, 0.0) and "assumed zero" in run.metadata["ros_bag"]["laser_mount"]


def test_scans_outside_the_odometry_are_dropped(tmp_path):
    made = _robot_bag(tmp_path / "robot.bag", ros=1, odom_delay_ns=150_000_000)  # scans 0 and 1 come first
    run = run_from_bag(tmp_path / "robot.bag", scan_topic="/scan", truth_topic=None)
    assert run.metadata["ros_bag"]["dropped_scans"] == 2
    np.testing.assert_array_equal(run.scans, made["ranges"][2:])
    assert run.t[0] == 0.0 and run.metadata["ros_bag"]["ros_time_origin_ns"] == made["scan_stamps"][2]


# --- errors ----------------------------------------------------------------------------------------------


def test_missing_topic_lists_the_topics(tmp_path):
    bag = write_rosbag1(tmp_path / "run.bag", small_run())
    with pytest.raises(FormatError, match=r"no topic /scan .*/base_scan \(sensor_msgs/msg/LaserScan\).*/odom") as info:
        run_from_bag(bag, scan_topic="/scan")
    assert info.value.path == bag


def test_missing_truth_says_how_to_read_without_it(tmp_path):
    made = tmp_path / "robot.bag"
    _robot_bag(made, ros=1)
    with pytest.raises(FormatError, match="truth_topic=None"):
        run_from_bag(made, scan_topic="/scan")


@pytest.mark.parametrize("kind", ["ros1", "ros2"])
def test_wrong_message_type_names_topic_and_types(tmp_path, kind):
    bag = _write(kind, tmp_path, small_run())
    with pytest.raises(
        FormatError,
        match=r"topic /odom \(laser scans\) has type nav_msgs/msg/Odometry, expected sensor_msgs/msg/LaserScan",
    ):
        run_from_bag(bag, scan_topic="/odom")
    with pytest.raises(FormatError, match="topic /base_scan .*expected nav_msgs/msg/Odometry"):
        run_from_bag(bag, truth_topic="/base_scan")


def test_not_a_bag(tmp_path):
    (tmp_path / "notes.bag").write_text("hello\n")
    with pytest.raises(FormatError, match="notes.bag"):
        run_from_bag(tmp_path / "notes.bag")
    (tmp_path / "notes.txt").write_text("hello\n")
    with pytest.raises(FormatError, match="not a ROS bag"):
        run_from_bag(tmp_path / "notes.txt")
    with pytest.raises(FormatError, match="no such"):
        run_from_bag(tmp_path / "missing.bag")
    (tmp_path / "empty").mkdir()
    with pytest.raises(FormatError, match="metadata.yaml"):
        run_from_bag(tmp_path / "empty")


def test_truncated_ros1_bag_suggests_reindex(tmp_path):
    bag = write_rosbag1(tmp_path / "run.bag", small_run())
    data = bag.read_bytes()
    bag.write_bytes(data[: len(data) * 2 // 3])
    with pytest.raises(FormatError, match="run.bag.*reindex"):
        run_from_bag(bag)


def test_ros1_type_with_another_definition_is_refused(tmp_path):
    from rosbags.rosbag1 import Writer

    definition = "std_msgs/Header header\nfloat32[] ranges\n"
    bag = tmp_path / "odd.bag"
    with Writer(bag) as writer:
        writer.add_connection(
            "/base_scan", "sensor_msgs/msg/LaserScan", msgdef=definition, md5sum="0123456789abcdef0123456789abcdef"
        )
    with pytest.raises(FormatError, match="/base_scan.*md5 0123456789abcdef"):
        run_from_bag(bag)
