"""``slamtrials slam --program``: an external program over a run folder, end to end, and its one-line errors."""

from __future__ import annotations

import json
import re
import shlex
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.cli.simulate import record_relation_set
from slamtrials.geometry import wrap_angle
from slamtrials.io.runfolder import write_run
from slamtrials.io.tum import read_tum
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.slamrun import PROGRAM_OUTPUT_FILES
from slamtrials.worlds import World

runner = CliRunner()

ODOMETRY_PROGRAM = Path(__file__).resolve().parents[2] / "docs" / "examples" / "odometry_program.py"
ODOMETRY_COMMAND = f"{shlex.quote(sys.executable)} {shlex.quote(str(ODOMETRY_PROGRAM))} {{input}} {{output}}"


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    occ = np.ones((60, 120), bool)
    occ[10:50, 10:110] = False  # a 5 m x 2 m room
    occ[10:25, 60:62] = True
    world = World(occ, 0.05, name="room", start=np.array([1.0, 1.0, 0.0]))
    record = simulate_waypoints(world, [[4.5, 1.0], [4.5, 1.8], [1.0, 1.8]], SimConfig(), seed=2, max_time=60)
    folder = tmp_path_factory.mktemp("slam") / "run"
    write_run(folder, record)
    record_relation_set(folder, record, 2)  # as 'slamtrials simulate' stores it: every estimate scored on it
    return folder, record


def error_line(output: str) -> str:
    lines = [line for line in output.splitlines() if line.startswith("error: ")]
    assert len(lines) == 1, output
    return lines[0]


@pytest.mark.slow
def test_slam_program_writes_its_outputs_and_scores_like_the_odometry_algorithm(run_folder, tmp_path):
    folder, record = run_folder
    out = tmp_path / "out"
    result = runner.invoke(app, ["slam", "-i", str(folder), "-o", str(out), "--program", ODOMETRY_COMMAND, "-s", "3"])
    assert result.exit_code == 0, result.output
    assert "program:odometry_program.py ran" in result.output
    assert f"wrote {len(record)} poses ({len(record)} at a frame, 0 frames carried by odometry)" in result.output
    for name in PROGRAM_OUTPUT_FILES:
        assert (out / name).is_file(), name
    wrote = re.search(r"; wrote (.*)$", result.output.splitlines()[0]).group(1).split(", ")
    assert wrote == list(PROGRAM_OUTPUT_FILES) and wrote[-1] == "slam.json"  # slam.json last
    assert (out / "slam.json").stat().st_mtime_ns >= max((out / n).stat().st_mtime_ns for n in PROGRAM_OUTPUT_FILES)
    info = json.loads((out / "slam.json").read_text())
    assert info["algorithm"] == "program:odometry_program.py" and info["seed"] == 3 and info["frames"] == len(record)
    assert info["program"]["command"] == ODOMETRY_COMMAND and info["program"]["input"] == "carmen"
    assert info["time_origin_s"] == 0.0 and info["poses_written"] == len(record)
    assert info["input"] == str(folder) and "{" not in info["command"]
    for name in ("trajectory.tum", "program.tum"):
        tum = read_tum(out / name)
        np.testing.assert_allclose(tum.t, record.t, atol=1e-6)
        np.testing.assert_allclose(tum.poses[:, :2], record.odometry[:, :2], atol=1e-5)
        np.testing.assert_allclose(wrap_angle(tum.poses[:, 2] - record.odometry[:, 2]), 0.0, atol=1e-5)
    # the same error as the odometry algorithm on the same run's relations
    algorithm = runner.invoke(app, ["slam", "-i", str(folder), "-o", str(tmp_path / "odo"), "-a", "odometry"])
    assert algorithm.exit_code == 0, algorithm.output
    program_error = error_line(result.output)
    assert program_error == error_line(algorithm.output) and "the run's relation set" in program_error
    eps_t = float(re.search(r"eps_t ([0-9.]+) m", program_error).group(1))
    assert eps_t > 1e-4  # a drifting odometry: not a trivially zero error
    # again: refused without --overwrite, replaced with it
    again = runner.invoke(app, ["slam", "-i", str(folder), "-o", str(out), "--program", ODOMETRY_COMMAND])
    assert again.exit_code == 2 and "--overwrite" in again.output
    replaced = runner.invoke(
        app, ["slam", "-i", str(folder), "-o", str(out), "--program", ODOMETRY_COMMAND, "--overwrite"]
    )
    assert replaced.exit_code == 0, replaced.output
    assert json.loads((out / "slam.json").read_text())["seed"] == 0


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--program", "sh -c 'echo it broke >&2; exit 4' x {input} {output}"], "exited with status 4"),
        (["--program", "sh -c 'echo it broke >&2; exit 4' x {input} {output}"], "its stderr ends: it broke"),
        (["--program", "sleep 30 # {input} {output}", "--timeout", "0.5"], "ran past its timeout of 0.5 s"),
        (["--program", "true {input} {output}"], "wrote nothing to {output}"),
        (["--program", "echo garbage > {output} # {input}"], "cannot be used"),
        (["--program", "no-such-slam-program-xyz {input} {output}"], "not found on PATH"),
        (["--program", "./no_such_slam {input} {output}"], "not found (no such file"),
        (["--program", "my_slam {input}"], "--program: command: the command must hold {output}"),
        (["--program", "my_slam {input} {output} {map}"], "unknown placeholder {map}"),
        (["--program", "true {input} {output}", "--program-input", "rosbag"], "--program: input:"),
        (["--program", "true {input} {output}", "--program-output", "g2o"], "--program: output:"),
        (["--program", "true {input} {output}", "--timeout", "0"], "--program: timeout:"),
        (["--program", ODOMETRY_COMMAND, "--algorithm", "odometry"], "give either --algorithm NAME or --program"),
        ([], "give either --algorithm NAME or --program"),
        (["--program", ODOMETRY_COMMAND, "--preset", "gmapping"], "--preset and --set configure an --algorithm"),
        (["--program", ODOMETRY_COMMAND, "--set", "resolution=0.1"], "--preset and --set configure an --algorithm"),
        (["--program", ODOMETRY_COMMAND, "--runs", "3"], "--runs and --relations go together"),
    ],
)
def test_program_failures_and_bad_options_exit_2_with_one_line(run_folder, tmp_path, extra, expected):
    folder, _ = run_folder
    out = tmp_path / "o"
    result = runner.invoke(app, ["slam", "-i", str(folder), "-o", str(out), *extra])
    assert result.exit_code == 2, result.output
    assert expected in result.output and len(result.output.strip().splitlines()) == 1, result.output
    assert "Traceback" not in result.output
    assert not out.exists()


def test_a_program_reading_a_carmen_log_input(run_folder, tmp_path):
    """``-i`` a CARMEN log without ground truth: outputs written, no error printed (nothing to score on)."""
    from slamtrials.io.transfer import export_record

    _, record = run_folder
    log = tmp_path / "run.clf"
    export_record(record, log, "carmen", truth=False)
    out = tmp_path / "out"
    result = runner.invoke(app, ["slam", "-i", str(log), "-o", str(out), "--program", ODOMETRY_COMMAND])
    assert result.exit_code == 0, result.output
    assert "error:" not in result.output and (out / "slam.json").is_file()
    assert len(read_tum(out / "trajectory.tum")) == len(record)


@pytest.mark.slow
def test_slam_program_repeated_on_a_dataset_scores_every_run_on_its_relations(run_folder, tmp_path):
    from slamtrials.io.relations import write_relations
    from slamtrials.metric import evaluate_relations, relations_between
    from slamtrials.record import Trajectory

    folder, record = run_folder
    i = np.arange(0, len(record) - 10, 5)
    relations = relations_between(Trajectory(t=record.t, poses=record.truth), i, i + 10)
    rel = tmp_path / "relations.txt"
    write_relations(rel, relations)
    seeds = tmp_path / "seeds.txt"
    command = f"echo {{seed}} >> {shlex.quote(str(seeds))} && {ODOMETRY_COMMAND}"
    out = tmp_path / "out"
    args = ["slam", "-i", str(folder), "-o", str(out), "--program", command, "--runs", "3", "-r", str(rel)]
    result = runner.invoke(app, [*args, "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert sorted(seeds.read_text().split()) == ["0", "1", "2"]  # each run given its seed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["runs"] == 3 and summary["program"]["command"] == command
    expected = evaluate_relations(Trajectory(t=record.t, poses=record.odometry), relations, tolerance=0.1)
    assert summary["translational_m"]["mean"] == pytest.approx(float(np.mean(expected.translational)), abs=1e-6)
    fails = "sh -c 'exit 6' x {seed} # {input} {output}"
    failed = tmp_path / "failed"
    failing = runner.invoke(
        app,
        [
            "slam",
            "-i",
            str(folder),
            "-o",
            str(failed),
            "--program",
            fails,
            "--runs",
            "2",
            "-r",
            str(rel),
            "--workers",
            "1",
        ],
    )
    assert failing.exit_code == 2 and "exited with status 6" in failing.output, failing.output
    assert len(failing.output.strip().splitlines()) == 1 and not (failed / "summary.json").exists()


@pytest.mark.slow
def test_a_seed_the_program_fails_on_is_a_failed_run_and_the_others_count(run_folder, tmp_path):
    from slamtrials.io.relations import write_relations
    from slamtrials.metric import relations_between
    from slamtrials.record import Trajectory

    folder, record = run_folder
    i = np.arange(0, len(record) - 10, 5)
    rel = tmp_path / "relations.txt"
    write_relations(rel, relations_between(Trajectory(t=record.t, poses=record.truth), i, i + 10))
    command = f"if [ {{seed}} = 1 ]; then echo lost >&2; exit 7; fi; {ODOMETRY_COMMAND}"
    out = tmp_path / "out"
    args = ["slam", "-i", str(folder), "-o", str(out), "--program", command, "--runs", "3", "-r", str(rel)]
    result = runner.invoke(app, [*args, "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert "failed: seed 1: the program exited with status 7" in result.output and "lost" in result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["seeds"] == [0, 2] and summary["failed"][0]["seed"] == 1
