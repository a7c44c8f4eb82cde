"""``slamtrials simulate`` end to end: a run folder that reads back, and nothing stored is overwritten."""

from __future__ import annotations

import numpy as np
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.io.runfolder import read_run
from slamtrials.worlds import World
from slamtrials.worlds.formats.rosmap_save import save_rosmap

runner = CliRunner()


def _corridor_world(tmp_path):
    occ = np.ones((60, 200), bool)
    occ[10:50, 10:190] = False  # a 9 m x 2 m room
    world = World(occ, 0.05, name="corridor", start=np.array([1.0, 1.5, 0.0]))
    return save_rosmap(world, tmp_path / "corridor.yaml")


def test_simulate_writes_a_run_that_follows_the_waypoints(tmp_path):
    world_file = _corridor_world(tmp_path)
    (tmp_path / "w.yaml").write_text("waypoints:\n  - [4.0, 1.5]\n  - [8.0, 1.5]\n")
    out = tmp_path / "run"
    result = runner.invoke(
        app, ["simulate", "-w", str(world_file), "-p", str(tmp_path / "w.yaml"), "-s", "4", "-o", str(out)]
    )
    assert result.exit_code == 0, result.output
    record = read_run(out)
    assert (out / "run.png").stat().st_size > 1000
    assert abs(record.truth[-1, 0] - 8.0) < 0.3 and abs(record.truth[-1, 1] - 1.5) < 0.3
    assert record.scans.shape == (len(record.t), 541)
    assert record.metadata["seed"] == 4


def test_simulate_refuses_to_overwrite_a_stored_run(tmp_path):
    world_file = _corridor_world(tmp_path)
    (tmp_path / "w.yaml").write_text("waypoints:\n  - [3.0, 1.5]\n")
    out = tmp_path / "run"
    args = ["simulate", "-w", str(world_file), "-p", str(tmp_path / "w.yaml"), "-o", str(out)]
    assert runner.invoke(app, [*args, "-s", "1"]).exit_code == 0
    before = (out / "frames.npz").read_bytes()
    result = runner.invoke(app, [*args, "-s", "2"])
    assert result.exit_code == 2 and "--overwrite" in result.output
    assert (out / "frames.npz").read_bytes() == before
    assert runner.invoke(app, [*args, "-s", "2", "--overwrite"]).exit_code == 0
    assert read_run(out).metadata["seed"] == 2


def test_bad_waypoint_file_is_one_line_with_its_name(tmp_path):
    world_file = _corridor_world(tmp_path)
    (tmp_path / "w.yaml").write_text("waypoints:\n  - [3.0]\n")
    result = runner.invoke(
        app, ["simulate", "-w", str(world_file), "-p", str(tmp_path / "w.yaml"), "-o", str(tmp_path / "r")]
    )
    assert result.exit_code == 2
    assert "w.yaml:2" in result.output and "Traceback" not in result.output


def test_config_file_sets_the_laser(tmp_path):
    world_file = _corridor_world(tmp_path)
    (tmp_path / "w.yaml").write_text("waypoints:\n  - [3.0, 1.5]\n")
    (tmp_path / "sim.yaml").write_text(
        "profile: paper\nlaser:\n  fov: 1.3962634\n  angular_resolution: 0.017453293\n  max_range: 20.0\n"
    )
    out = tmp_path / "run"
    args = [
        "simulate",
        "-w",
        str(world_file),
        "-p",
        str(tmp_path / "w.yaml"),
        "-c",
        str(tmp_path / "sim.yaml"),
        "-o",
        str(out),
    ]
    assert runner.invoke(app, args).exit_code == 0
    record = read_run(out)
    assert record.scans.shape[1] == 81  # 80 degrees at 1 degree, as the paper's industrial-hall laser
    assert record.laser.range_max == 20.0
    assert record.scans.max() <= 20.0


def test_bad_config_names_file_and_field(tmp_path):
    world_file = _corridor_world(tmp_path)
    (tmp_path / "sim.yaml").write_text("laser:\n  fov: -1\n")
    result = runner.invoke(
        app, ["simulate", "-w", str(world_file), "--tour", "-c", str(tmp_path / "sim.yaml"), "-o", str(tmp_path / "r")]
    )
    assert result.exit_code == 2
    assert "sim.yaml" in result.output and "laser.fov" in result.output
    assert not (tmp_path / "r").exists()
