"""CARMEN logs holding the front laser twice, as FLASER and as ROBOTLASER1 lines: the reader reads the
ROBOTLASER1 stream (its geometry is on every line), counts the FLASER lines in ``skipped`` and says in
one warning whether their timestamps are those of the ROBOTLASER1 lines; everything downstream reads such
a log as it reads the ROBOTLASER1 lines alone."""

from __future__ import annotations

import dataclasses
import logging
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.errors import FormatError
from slamtrials.io.carmen import CarmenLog, read_carmen, run_from_carmen, write_carmen
from slamtrials.io.runfolder import read_run
from slamtrials.io.transfer import read_carmen_run
from slamtrials.io.tum import read_tum
from slamtrials.slamrun import load_recording

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared"))
MIT = SHARED / "data" / "mit-csail"
HEADER = "Mean, Std, Min, Max, NumMeasures"
runner = CliRunner()


def _flaser(t: float, x: float) -> str:
    """A 3-beam FLASER line (no PARAMs: 180 degrees from -90, CARMEN's guess) with pose ``x 0 0``."""
    return f"FLASER 3 7.0 7.0 7.0 {x} 0 0 {x} 0 0 {t} host {t - 100}\n"


def _robot(t: float, x: float, ranges: str = "1 2 3") -> str:
    """A 3-beam ROBOTLASER1 line from -0.25 rad by 0.25 rad, 30 m, laser pose ``x 1 0``, robot pose ``x 2 0``."""
    return f"ROBOTLASER1 0 -0.25 0.5 0.25 30 0.01 0 3 {ranges} 0 {x} 1 0 {x} 2 0 0 0 0 0 0 {t} host {t - 100}\n"


def _warnings(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]


@pytest.mark.parametrize("robot_first", [False, True])
def test_both_kinds_at_the_same_timestamps_read_the_robotlaser1_lines(tmp_path, caplog, robot_first):
    t = [10.0, 10.2, 10.4]
    pairs = [(_flaser(s, 100 + k), _robot(s, k)) for k, s in enumerate(t)]
    path = tmp_path / "both.clf"
    path.write_text(
        "ODOM 0 2 0 0 0 0 9.9 host 0\n" + "".join(r + f if robot_first else f + r for f, r in pairs) + "SYNC x 1 h 1\n"
    )
    log = read_carmen(path)
    laser = log.laser
    assert laser.kind == "ROBOTLASER1" and laser.t.tolist() == t
    np.testing.assert_array_equal(laser.ranges, np.tile(np.float32([1, 2, 3]), (3, 1)))
    assert (laser.angle_min, laser.angle_increment, laser.range_max) == (-0.25, 0.25, 30.0)  # not FLASER's guess
    np.testing.assert_array_equal(laser.pose, [[k, 1, 0] for k in range(3)])  # not the FLASER poses (100 + k)
    np.testing.assert_array_equal(laser.odometry, [[k, 2, 0] for k in range(3)])
    assert log.skipped == {"FLASER": 3, "SYNC": 1} and log.tolerated == {} and len(log.odom) == 1
    first = 3 if robot_first else 2
    assert _warnings(caplog) == [
        f"{path}: 3 FLASER lines skipped (first: line {first}): the log also holds ROBOTLASER1 lines, the front "
        "laser in CARMEN's new format with its geometry on every line, read instead (3 frames); 3 of 3 FLASER "
        "timestamps match a ROBOTLASER1 line within 1 ms: the same scans"
    ]
    poses_only = read_carmen(path, ranges=False).laser
    assert poses_only.kind == "ROBOTLASER1" and poses_only.t.tolist() == t and poses_only.angle_min == -0.25
    record = run_from_carmen(log)
    assert record.metadata["carmen_kind"] == "ROBOTLASER1" and record.metadata["carmen_skipped"]["FLASER"] == 3


def test_both_kinds_at_other_timestamps_still_read_the_robotlaser1_lines_and_say_so(tmp_path, caplog):
    path = tmp_path / "two.clf"
    path.write_text(
        _robot(1.0, 0)
        + _flaser(1.5, 9)
        + _robot(2.0, 1)
        + _flaser(2.5, 9)
        + _robot(3.0, 2)
        + _flaser(3.0009, 9)  # 0.9 ms from the ROBOTLASER1 line: the same scan
        + _flaser(3.5, 9)
    )
    log = read_carmen(path)
    assert log.laser.kind == "ROBOTLASER1" and log.laser.t.tolist() == [1.0, 2.0, 3.0]
    np.testing.assert_array_equal(log.laser.pose[:, 0], [0, 1, 2])
    assert log.skipped == {"FLASER": 4} and log.tolerated == {}
    (message,) = _warnings(caplog)
    assert message.startswith(f"{path}: 4 FLASER lines skipped (first: line 2): ")
    assert message.endswith(
        "read instead (3 frames); 1 of 4 FLASER timestamps match a ROBOTLASER1 line within 1 ms: the two "
        "streams differ (two lasers, or lines missing from one): only the ROBOTLASER1 lines are read"
    )


def test_the_robotlaser1_stream_keeps_its_own_tolerances(tmp_path, caplog):
    """Oddities of the stream read are counted as in a ROBOTLASER1-only log; the FLASER lines count nowhere else."""
    path = tmp_path / "odd.clf"
    path.write_text(
        _flaser(1.0, 9)
        + _robot(1.0, 0)
        + _flaser(2.0, 9)
        + _robot(2.0, 1, ranges="1 nan 3").replace(" 1 0 1 2 0 ", " nan 0 1 2 0 ")  # a nan pose: skipped
        + _flaser(3.0, 9)
        + _robot(3.0, 2)
        + _robot(3.0, 3)  # a repeat of 3.0: the first kept
    )
    log = read_carmen(path)
    assert log.laser.t.tolist() == [1.0, 3.0] and log.laser.pose[:, 0].tolist() == [0, 2]
    assert log.tolerated == {"laser_nonfinite": 1, "laser_duplicate": 1} and log.skipped == {"FLASER": 3}
    messages = _warnings(caplog)
    assert len(messages) == 3 and "1 ROBOTLASER1 lines with a non-finite pose" in messages[0]
    assert "3 of 3 FLASER timestamps match" in messages[2]


def test_a_broken_line_of_the_skipped_kind_is_still_an_error_but_a_cut_last_one_is_not(tmp_path, caplog):
    path = tmp_path / "broken.clf"
    path.write_text(_robot(1.0, 0) + _flaser(1.0, 9) + _robot(2.0, 1) + _flaser(2.0, 9)[:25] + "\n" + _robot(3.0, 2))
    with pytest.raises(FormatError, match="FLASER with num_readings 3 needs 14 fields") as info:
        read_carmen(path)
    assert info.value.line == 4 and str(info.value).startswith(f"{path}:4: ")
    path.write_text(_robot(1.0, 0) + _flaser(1.0, 9) + _robot(2.0, 1) + _flaser(2.0, 9)[:25])  # cut short, no newline
    log = read_carmen(path)
    assert log.laser.t.tolist() == [1.0, 2.0] and log.skipped == {"FLASER": 1}
    assert log.tolerated == {"truncated_last_line": 1}
    assert "1 of 1 FLASER timestamps match" in _warnings(caplog)[-1]


# ----------------------------------------------------------------------------- the MIT CSAIL log, doubled


def _doubled(source_lines: list[str], folder: Path, name: str) -> tuple[Path, Path]:
    """The log of ``source_lines`` (FLASER lines only), and the same log with each FLASER line followed by
    a ROBOTLASER1 line of the same scan, written by slamtrials' own CARMEN writer."""
    plain = folder / f"{name}.clf"
    plain.write_text("".join(source_lines))
    laser = read_carmen(plain).laser
    copy = dataclasses.replace(laser, kind="ROBOTLASER1", line_readings=None)
    robot = write_carmen(folder / f"{name}.robot", CarmenLog(laser=copy), header=False).read_text()
    robot_lines = robot.splitlines(keepends=True)
    assert len(robot_lines) == len(source_lines) and all(line.startswith("ROBOTLASER1 ") for line in robot_lines)
    mixed = folder / f"{name}-mixed.clf"
    mixed.write_text("".join(f + r for f, r in zip(source_lines, robot_lines)))
    return plain, mixed


@pytest.fixture(scope="module")
def mit_doubled(tmp_path_factory):
    if not (MIT / "mit-csail.clf").is_file():
        pytest.skip("shared data not present")
    lines = (MIT / "mit-csail.clf").read_text().splitlines(keepends=True)
    assert all(line.startswith("FLASER ") for line in lines)
    return _doubled(lines, tmp_path_factory.mktemp("mixed"), "mit")


@pytest.mark.slow  # real data: the whole MIT CSAIL log, doubled
def test_mit_csail_with_a_robotlaser1_copy_reads_the_same_frames(mit_doubled, caplog):
    original, mixed = mit_doubled
    a, b = read_carmen(MIT / "mit-csail.clf"), read_carmen(mixed)
    assert b.laser.kind == "ROBOTLASER1" and b.laser.ranges.shape == (1988, 361)
    for name in ("t", "logger_t", "ranges", "pose", "odometry"):
        np.testing.assert_array_equal(getattr(b.laser, name), getattr(a.laser, name), err_msg=name)
    assert b.laser.angle_min == a.laser.angle_min == -math.pi / 2
    assert b.laser.angle_increment == a.laser.angle_increment and b.laser.range_max == a.laser.range_max == 81.91
    assert b.skipped == {"FLASER": 1988} and b.tolerated == {}
    assert _warnings(caplog)[-1].endswith(
        "1988 of 1988 FLASER timestamps match a ROBOTLASER1 line within 1 ms: the same scans"
    )
    ra, rb = read_carmen_run(MIT / "mit-csail.clf"), load_recording(mixed)  # what slam, calibrate, validate read
    for name in ("t", "scans", "odometry", "truth", "stalled"):
        np.testing.assert_array_equal(getattr(rb, name), getattr(ra, name), err_msg=name)
    assert rb.laser == ra.laser


def _rows(output: str) -> list[str]:
    lines = output.splitlines()
    return [lines[i + 1] for i, line in enumerate(lines) if line == HEADER]


@pytest.mark.slow  # real data: evaluate and map the whole log twice
def test_mit_csail_doubled_evaluates_and_maps_as_the_original(mit_doubled, tmp_path, caplog):
    if not (MIT / "mit-csail.relations").is_file():
        pytest.skip("shared data not present")
    _, mixed = mit_doubled
    relations = str(MIT / "mit-csail.relations")
    scores = []
    for log in (MIT / "mit-csail.clf", mixed):
        result = runner.invoke(app, ["evaluate", "-e", str(log), "-r", relations, "--odometry", str(log)])
        assert result.exit_code == 0 and "Traceback" not in result.output, result.output
        scores.append(_rows(result.output))
    assert scores[0] == scores[1] and len(scores[0]) == 2 and scores[0][0].endswith(", 1172")
    assert any("1988 of 1988 FLASER timestamps match" in message for message in _warnings(caplog))
    out = tmp_path / "odometry"
    result = runner.invoke(app, ["slam", "-a", "odometry", "-i", str(mixed), "-o", str(out)])
    assert result.exit_code == 0 and "Traceback" not in result.output, result.output
    assert len(read_tum(out / "trajectory.tum")) == 1988
    scored = runner.invoke(app, ["evaluate", "-e", str(out / "trajectory.log"), "-r", relations])
    assert scored.exit_code == 0 and _rows(scored.output)[0].endswith(", 1172"), scored.output


@pytest.mark.slow  # real data: GMapping twice, then import, export and import again
def test_gmapping_and_transfer_on_a_doubled_slice_give_the_original_results(tmp_path):
    if not (MIT / "mit-csail.clf").is_file():
        pytest.skip("shared data not present")
    with open(MIT / "mit-csail.clf") as handle:
        lines = [next(handle) for _ in range(120)]  # 3 m, 16 scan matches
    plain, mixed = _doubled(lines, tmp_path, "slice")
    estimates = []
    for log in (plain, mixed):
        out = tmp_path / log.stem
        args = ["slam", "-a", "gmapping", "-i", str(log), "-o", str(out), "--set", "particles=5"]
        result = runner.invoke(app, args)
        assert result.exit_code == 0 and "Traceback" not in result.output, result.output
        estimates.append(read_tum(out / "trajectory.tum"))
    np.testing.assert_array_equal(estimates[1].t, estimates[0].t)
    np.testing.assert_array_equal(estimates[1].poses, estimates[0].poses)
    odometry = read_carmen(plain).laser.odometry
    assert len(estimates[0]) == 120 and np.abs(estimates[0].poses - odometry).max() > 0.1  # scan matching did act
    runs = []
    for log in (plain, mixed):  # CARMEN -> run folder -> ROS bag -> run folder
        folder, bag = tmp_path / f"{log.stem}-run", tmp_path / f"{log.stem}.bag"
        for args in (["import", log, "--out", folder], ["export", folder, "--to", "bag", "--out", bag]):
            result = runner.invoke(app, [str(a) for a in args])
            assert result.exit_code == 0 and "Traceback" not in result.output, result.output
        assert (
            runner.invoke(app, ["import", str(bag), "--out", str(folder.with_name(folder.name + "-back"))]).exit_code
            == 0
        )
        runs.append((read_run(folder), read_run(folder.with_name(folder.name + "-back"))))
    assert runs[1][0].metadata["carmen_kind"] == "ROBOTLASER1" and runs[1][0].metadata["carmen_skipped"] == {
        "FLASER": 120
    }
    for a, b in zip(runs[0], runs[1]):
        for name in ("t", "scans", "odometry", "truth"):
            np.testing.assert_array_equal(getattr(b, name), getattr(a, name), err_msg=name)
        assert b.laser == a.laser


def test_a_broken_mixed_log_is_one_line_from_the_cli(tmp_path):
    path = tmp_path / "broken.clf"
    path.write_text(_robot(1.0, 0) + "FLASER 3 1 2\n" + _robot(2.0, 1))
    for args in (["evaluate", "-e", str(path), "-r", str(path)], ["slam", "-a", "odometry", "-i", str(path)]):
        result = runner.invoke(app, [*args, "-o", str(tmp_path / "o")] if args[0] == "slam" else args)
        assert result.exit_code == 2 and "Traceback" not in result.output, result.output
        assert f"{path}:2: " in result.output and "needs 14 fields" in result.output
        assert len(result.output.strip().splitlines()) == 1, result.output


@pytest.mark.slow  # a new Python process (about 2.5 s of imports); the reader's warning is checked in-process above
def test_the_cli_shows_the_skipped_stream_in_one_warning_line(tmp_path):
    log = tmp_path / "both.clf"
    log.write_text("".join(_flaser(t, 9) + _robot(t, k) for k, t in enumerate([10.0, 10.2, 10.4])))
    relations = tmp_path / "both.relations"
    relations.write_text("10.0 10.4 2 0 0 0 0 0\n")
    code = "import sys; from slamtrials.cli.main import main; sys.argv[0] = 'slamtrials'; main()"
    done = subprocess.run(
        [sys.executable, "-c", code, "evaluate", "-e", str(log), "-r", str(relations)],
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "PYTHONPATH": str(REPO / "src")},
    )
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr
    warnings = [line for line in done.stderr.splitlines() if line.startswith("WARNING")]
    assert len(warnings) == 1 and "3 FLASER lines skipped" in warnings[0], done.stderr
    assert "3 of 3 FLASER timestamps match a ROBOTLASER1 line within 1 ms: the same scans" in warnings[0]
    assert "3 ROBOTLASER1 lines" in done.stdout and done.stdout.count(", 1\n") == 2, done.stdout
