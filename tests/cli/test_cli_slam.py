"""``slamtrials slam`` end to end on a small simulated run, and its one-line errors."""

from __future__ import annotations

import bz2
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.cli.slam import parse_settings
from slamtrials.errors import ConfigError
from slamtrials.geometry import wrap_angle
from slamtrials.io.carmen import read_carmen
from slamtrials.io.mapfile import read_map
from slamtrials.io.runfolder import write_run
from slamtrials.io.transfer import export_record
from slamtrials.io.tum import read_tum
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.worlds import World

runner = CliRunner()


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    occ = np.ones((60, 120), bool)
    occ[10:50, 10:110] = False  # a 5 m x 2 m room
    occ[10:25, 60:62] = True
    world = World(occ, 0.05, name="room", start=np.array([1.0, 1.0, 0.0]))
    record = simulate_waypoints(world, [[4.5, 1.0], [4.5, 1.8], [1.0, 1.8]], SimConfig.paper(), seed=2, max_time=60)
    folder = tmp_path_factory.mktemp("slam") / "run"
    write_run(folder, record)
    return folder, record


def test_slam_writes_every_output_and_evaluate_reads_them(run_folder, tmp_path):
    folder, record = run_folder
    out = tmp_path / "out"
    result = runner.invoke(
        app, ["slam", "--algorithm", "odometry", "--input", str(folder), "--out", str(out), "--set", "resolution=0.1"]
    )
    assert result.exit_code == 0, result.output
    assert f"{len(record)} frames, {len(record)} updates" in result.output and "ms per frame" in result.output
    for name in (
        "trajectory.tum",
        "trajectory.clf",
        "trajectory.log",
        "map.yaml",
        "map.pgm",
        "map.png",
        "timing.csv",
        "slam.json",
    ):
        assert (out / name).is_file(), name
    tum = read_tum(out / "trajectory.tum")
    np.testing.assert_allclose(tum.t, record.t, atol=1e-6)
    np.testing.assert_allclose(tum.poses[:, :2], record.odometry[:, :2], atol=1e-6)
    np.testing.assert_allclose(wrap_angle(tum.poses[:, 2] - record.odometry[:, 2]), 0.0, atol=1e-6)
    log = read_carmen(out / "trajectory.clf")
    np.testing.assert_allclose(log.laser.pose, record.odometry, atol=1e-5)  # first triple: the estimate
    np.testing.assert_allclose(log.laser.odometry, record.odometry, atol=1e-5)
    grid = read_map(out / "map.yaml")
    assert grid.resolution == 0.1 and (grid.grid == 100).sum() > 20 and (grid.grid == 0).sum() > 100
    info = json.loads((out / "slam.json").read_text())
    assert info["algorithm"] == "odometry" and info["config"]["resolution"] == 0.1 and info["frames"] == len(record)
    assert len((out / "timing.csv").read_text().splitlines()) == len(record) + 1
    evaluated = runner.invoke(app, ["evaluate", str(folder), "--estimate", str(out / "trajectory.tum")])
    assert evaluated.exit_code == 0, evaluated.output
    assert "Translational error" in evaluated.output
    from_clf = runner.invoke(app, ["evaluate", str(folder), "--estimate", str(out / "trajectory.clf")])
    assert from_clf.exit_code == 0, from_clf.output
    test_log = read_carmen(out / "trajectory.log")  # the Freiburg program's input: the estimate in both triples
    assert test_log.laser.beams == 0 and np.array_equal(test_log.laser.pose, test_log.laser.odometry)
    np.testing.assert_allclose(test_log.laser.odometry, record.odometry, atol=1e-5)


def test_slam_reads_a_carmen_log_and_refuses_to_overwrite(run_folder, tmp_path):
    _, record = run_folder
    log = tmp_path / "run.clf"
    export_record(record, log, "carmen")
    out = tmp_path / "out"
    args = ["slam", "-a", "odometry", "-i", str(log), "-o", str(out), "--preset", "gmapping"]
    assert runner.invoke(app, args).exit_code == 0
    again = runner.invoke(app, args)
    assert again.exit_code == 2 and "--overwrite" in again.output
    assert runner.invoke(app, [*args, "--overwrite", "--seed", "1"]).exit_code == 0
    assert json.loads((out / "slam.json").read_text())["seed"] == 1


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--algorithm", "nope"], "unknown SLAM algorithm 'nope'"),
        (["--algorithm", "odometry", "--set", "resolution=-1"], "resolution = -1"),
        (["--algorithm", "odometry", "--set", "typo=1"], "no parameter typo"),
        (["--algorithm", "odometry", "--set", "novalue"], "key=value"),
        (["--algorithm", "odometry", "--preset", "best"], "no preset 'best'"),
        (["--algorithm", "odometry", "--seed", "-1"], "--seed"),
    ],
)
def test_bad_options_exit_2_with_one_line(run_folder, tmp_path, extra, expected):
    folder, _ = run_folder
    result = runner.invoke(app, ["slam", "--input", str(folder), "--out", str(tmp_path / "o"), *extra])
    assert result.exit_code == 2
    assert expected in result.output and len(result.output.strip().splitlines()) == 1, result.output
    assert not (tmp_path / "o").exists()


def test_slam_reads_a_bzip2_log_and_refuses_a_pose_only_one(run_folder, tmp_path):
    _, record = run_folder
    log = tmp_path / "run.clf"
    export_record(record, log, "carmen")
    packed = tmp_path / "run.clf.bz2"
    packed.write_bytes(bz2.compress(log.read_bytes()))
    out = tmp_path / "out"
    result = runner.invoke(app, ["slam", "-a", "odometry", "-i", str(packed), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert len(read_tum(out / "trajectory.tum")) == len(record)
    poses = tmp_path / "poses.log"  # a trajectory as SLAM programs write it for the Freiburg evaluator
    poses.write_text("".join(f"FLASER 0 {k} 0 0 {k} 0 0 {100.0 + k} h {k}\n" for k in range(5)))
    refused = runner.invoke(app, ["slam", "-a", "odometry", "-i", str(poses), "-o", str(tmp_path / "o")])
    assert refused.exit_code == 2 and "pose-only" in refused.output and len(refused.output.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_bad_input_exits_2(tmp_path):
    missing = runner.invoke(
        app, ["slam", "-a", "odometry", "-i", str(tmp_path / "none.clf"), "-o", str(tmp_path / "o")]
    )
    assert missing.exit_code == 2 and "none.clf" in missing.output and "Traceback" not in missing.output
    (tmp_path / "bad.clf").write_text("FLASER 3 1.0 2.0\n")
    bad = runner.invoke(app, ["slam", "-a", "odometry", "-i", str(tmp_path / "bad.clf"), "-o", str(tmp_path / "o")])
    assert bad.exit_code == 2 and "bad.clf" in bad.output and len(bad.output.strip().splitlines()) == 1


def test_set_values_are_yaml():
    assert parse_settings(["a=1", "b=0.5", "c=[1, 2, 0]", "d=true", "e=text"]) == {
        "a": 1,
        "b": 0.5,
        "c": [1, 2, 0],
        "d": True,
        "e": "text",
    }
    with pytest.raises(ConfigError, match="not a YAML value"):
        parse_settings(["a=[1"])
