"""``slamtrials export`` / ``slamtrials import``: run folder <-> ROS bags, CARMEN logs, TUM files, end to end."""

from __future__ import annotations

import bz2
import gzip
import shutil
from functools import cache

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.geometry import compose
from slamtrials.io.carmen import read_carmen
from slamtrials.io.rosbag import write_rosbag1
from slamtrials.io.runfolder import read_run, write_run
from slamtrials.io.tum import read_tum
from slamtrials.record import RunRecord
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.worlds import World

runner = CliRunner()


@cache
def _simulated() -> RunRecord:
    occ = np.ones((60, 200), bool)
    occ[10:50, 10:190] = False  # a 9 m x 2 m room
    world = World(occ, 0.05, name="corridor", start=np.array([1.0, 1.5, 0.0]))
    config = SimConfig.from_dict({"profile": "paper", "laser": {"mount": [0.1, 0.0, 0.0]}})
    return simulate_waypoints(world, [[2.5, 1.5], [2.5, 2.2]], config, seed=5, max_time=15.0)


@pytest.fixture
def run_folder(tmp_path):
    return write_run(tmp_path / "run", _simulated())


def _wrapped(angle):
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def _invoke(*args):
    result = runner.invoke(app, [str(a) for a in args])
    result.text = " ".join(result.output.split())  # rich wraps long lines
    return result


@pytest.mark.parametrize("to, name", [("bag", "run.bag"), ("bag2", "run_bag")])
def test_bag_export_and_import_give_the_same_run(tmp_path, run_folder, to, name):
    bag = tmp_path / name
    result = _invoke("export", run_folder, "--to", to, "--truth", "--out", bag)
    assert result.exit_code == 0, result.output
    assert "/base_scan" in result.output
    result = _invoke("import", bag, "--out", tmp_path / "back")
    assert result.exit_code == 0, result.output
    original, back = read_run(run_folder), read_run(tmp_path / "back")
    np.testing.assert_array_equal(back.scans, original.scans)
    assert np.max(np.abs(back.t - original.t)) <= 1e-9
    for name_ in ("odometry", "truth"):
        a, b = getattr(back, name_), getattr(original, name_)
        np.testing.assert_allclose(a[:, :2], b[:, :2], rtol=0, atol=1e-9)
        assert np.max(np.abs(_wrapped(a[:, 2] - b[:, 2]))) <= 1e-9
    assert back.laser == original.laser
    assert back.metadata["seed"] == 5 and back.metadata["truth_available"] is True
    assert back.metadata["imported_from"] == str(bag)


def test_tum_exports_truth_by_default_and_odometry_on_request(tmp_path, run_folder):
    original = read_run(run_folder)
    assert _invoke("export", run_folder, "--to", "tum", "--out", tmp_path / "truth.tum").exit_code == 0
    result = _invoke("export", run_folder, "--to", "tum", "--what", "odometry", "--out", tmp_path / "odo.tum")
    assert result.exit_code == 0, result.output
    for file, poses in (("truth.tum", original.truth), ("odo.tum", original.odometry)):
        trajectory = read_tum(tmp_path / file)
        np.testing.assert_array_equal(trajectory.t, original.t)
        np.testing.assert_array_equal(trajectory.poses[:, :2], poses[:, :2])
        assert np.max(np.abs(_wrapped(trajectory.poses[:, 2] - poses[:, 2]))) < 1e-12


@pytest.mark.parametrize("compressed", [None, "gz", "bz2"])
def test_carmen_export_and_import(tmp_path, run_folder, compressed):
    log = tmp_path / "run.clf"
    result = _invoke("export", run_folder, "--to", "carmen", "--truth", "--out", log)
    assert result.exit_code == 0, result.output
    if compressed:
        opener = gzip.open if compressed == "gz" else bz2.open
        with open(log, "rb") as source, opener(tmp_path / f"run.clf.{compressed}", "wb") as target:
            shutil.copyfileobj(source, target)
        log = tmp_path / f"run.clf.{compressed}"
    result = _invoke("import", log, "--out", tmp_path / "back")
    assert result.exit_code == 0, result.output
    original, back = read_run(run_folder), read_run(tmp_path / "back")
    np.testing.assert_allclose(back.scans, original.scans, atol=5e-4 + 1e-6)  # CARMEN keeps millimetres
    np.testing.assert_allclose(back.truth[:, :2], original.truth[:, :2], atol=1e-6)  # from the TRUEPOS lines
    np.testing.assert_allclose(back.odometry[:, :2], original.odometry[:, :2], atol=1e-6)
    assert back.laser.mount == original.laser.mount and back.metadata["truth_source"] == "carmen TRUEPOS lines"
    laser = read_carmen(log).laser  # the first triple: the laser's pose by odometry (mount 0.1 m ahead)
    np.testing.assert_allclose(laser.pose[:, :2], compose(original.odometry, original.laser.mount)[:, :2], atol=1e-6)


def test_outputs_are_not_overwritten_without_overwrite(tmp_path, run_folder):
    bag = tmp_path / "run.bag"
    assert _invoke("export", run_folder, "--to", "bag", "--out", bag).exit_code == 0
    before = bag.read_bytes()
    result = _invoke("export", run_folder, "--to", "bag", "--out", bag, "--compress")
    assert result.exit_code == 2 and "--overwrite" in result.output
    assert bag.read_bytes() == before
    assert _invoke("export", run_folder, "--to", "bag", "--out", bag, "--compress", "--overwrite").exit_code == 0
    assert bag.read_bytes() != before
    result = _invoke("import", bag, "--out", run_folder)
    assert result.exit_code == 2 and "--overwrite" in result.output
    assert _invoke("import", bag, "--out", run_folder, "--overwrite").exit_code == 0
    # a ROS 2 bag folder may replace a ROS 1 bag file of the same name, and back
    assert _invoke("export", run_folder, "--to", "bag2", "--out", bag, "--overwrite").exit_code == 0
    assert bag.is_dir()
    assert _invoke("export", run_folder, "--to", "bag", "--out", bag, "--overwrite").exit_code == 0
    assert bag.is_file()


def test_missing_topic_is_one_line_listing_the_topics(tmp_path, run_folder):
    bag = tmp_path / "run.bag"
    assert _invoke("export", run_folder, "--to", "bag", "--out", bag).exit_code == 0
    result = _invoke("import", bag, "--out", tmp_path / "back", "--scan-topic", "/scan")
    assert result.exit_code == 2
    assert (
        "run.bag" in result.output
        and "/scan" in result.output
        and "/base_scan (sensor_msgs/msg/LaserScan)" in result.output
    )
    assert "Traceback" not in result.output
    assert not (tmp_path / "back").exists()


def test_recording_without_ground_truth(tmp_path, run_folder):
    record = read_run(run_folder)
    record.truth[:] = np.nan  # a real robot: no ground truth topic in the bag
    bag = write_rosbag1(tmp_path / "robot.bag", record)
    named = _invoke("import", bag, "--out", tmp_path / "robot", "--truth-topic", "/base_pose_ground_truth")
    assert named.exit_code == 2 and "--no-truth" in named.text  # a topic asked for by name must be there
    result = _invoke("import", bag, "--out", tmp_path / "robot")  # by default: read without ground truth
    assert result.exit_code == 0, result.output
    assert "WITHOUT ground truth" in result.text
    imported = read_run(tmp_path / "robot")
    assert np.isnan(imported.truth).all() and imported.metadata["truth_available"] is False
    result = _invoke("export", tmp_path / "robot", "--to", "tum", "--out", tmp_path / "t.tum")
    assert result.exit_code == 2 and "--what odometry" in result.text
    assert (
        _invoke(
            "export", tmp_path / "robot", "--to", "tum", "--what", "odometry", "--out", tmp_path / "t.tum"
        ).exit_code
        == 0
    )
    result = _invoke("export", tmp_path / "robot", "--to", "carmen", "--truth", "--out", tmp_path / "r.clf")
    assert result.exit_code == 0 and "no ground truth" in result.text, result.output  # as a bag is written
    assert "TRUEPOS" not in (tmp_path / "r.clf").read_text()


def test_option_mistakes_exit_2(tmp_path, run_folder):
    result = _invoke("export", run_folder, "--to", "bag", "--what", "odometry", "--out", tmp_path / "x.bag")
    assert result.exit_code == 2 and "--what" in result.output
    result = _invoke("export", run_folder, "--to", "tum", "--truth", "--out", tmp_path / "x.tum")
    assert result.exit_code == 2 and "--truth applies to --to carmen, bag and bag2" in result.text
    assert not (tmp_path / "x.tum").exists()
    assert _invoke("export", tmp_path / "nothing", "--to", "tum", "--out", tmp_path / "x.tum").exit_code == 2
    (tmp_path / "log.clf").write_text("ODOM 0 0 0 0 0 0 1.0 host 0.0\n")
    result = _invoke("import", tmp_path / "log.clf", "--out", tmp_path / "r", "--scan-topic", "/scan")
    assert result.exit_code == 2 and "applies to ROS bags" in result.text
    result = _invoke("import", tmp_path / "x.bag", "--out", tmp_path / "r", "--truth-topic", "/gt", "--no-truth")
    assert result.exit_code == 2 and "not both" in result.output
    (tmp_path / "broken.clf.gz").write_bytes(b"not gzip at all")
    result = _invoke("import", tmp_path / "broken.clf.gz", "--out", tmp_path / "r")
    assert result.exit_code == 2 and "broken.clf.gz" in result.output and "Traceback" not in result.output


@pytest.mark.parametrize("to, name", [("bag", "robot.bag"), ("bag2", "robot_bag")])
def test_a_bag_without_truth_holds_nothing_a_robot_could_not_have_recorded(tmp_path, run_folder, to, name):
    """What a SLAM program is given: scans and odometry; no ground-truth topic, and no start pose, drawn
    bias, seed or scores in /slamtrials/run."""
    bag = tmp_path / name
    result = _invoke("export", run_folder, "--to", to, "--out", bag)  # the default: no ground truth
    assert result.exit_code == 0, result.output
    assert "without /base_pose_ground_truth" in result.text
    result = _invoke("import", bag, "--out", tmp_path / "back")  # no truth topic: read without ground truth
    assert result.exit_code == 0, result.output
    original, back = read_run(run_folder), read_run(tmp_path / "back")
    np.testing.assert_array_equal(back.scans, original.scans)
    np.testing.assert_allclose(back.odometry[:, :2], original.odometry[:, :2], rtol=0, atol=1e-9)
    assert np.isnan(back.truth).all() and back.metadata["truth_available"] is False
    kept = {key for key in original.metadata if key in back.metadata}
    assert kept <= {"format", "versions", "frames", "beams", "laser", "truth_available"}
    for leak in ("start", "bias", "seed", "world"):
        assert leak in original.metadata and leak not in back.metadata, leak
    raw = b"".join(p.read_bytes() for p in ([bag] if bag.is_file() else sorted(bag.iterdir())))
    assert b'"start"' not in raw and b'"bias"' not in raw and b"base_pose_ground_truth" not in raw
