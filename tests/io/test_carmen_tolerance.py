"""What the CARMEN reader tolerates in logs of the wild (and in the Freiburg evaluator's input files): each
oddity read, counted in ``CarmenLog.tolerated`` and warned about once; what stays an error."""

from __future__ import annotations

import bz2
import gzip
import logging
import math
import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from slamtrials.errors import FormatError
from slamtrials.io.carmen import read_carmen, run_from_carmen
from slamtrials.io.carmen_read import TOLERATED
from slamtrials.io.transfer import read_carmen_run

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared"))
FR079 = SHARED / "data" / "fr079" / "fr079.clf.bz2"
MIT = SHARED / "data" / "mit-csail" / "mit-csail.clf"


def _flaser(t: float, beams: int = 3, pose=(1.0, 2.0, 0.5), odom=(1.1, 2.1, 0.6), ranges: str | None = None) -> str:
    readings = ranges if ranges is not None else " ".join(["1.5"] * beams)
    body = f"{beams} {readings} " if beams else "0 "
    return f"FLASER {body}{' '.join(map(str, pose))} {' '.join(map(str, odom))} {t} host {t - 100}\n"


def _robot(t: float, ranges: list[float], start: float = -0.5, res: float = 0.25, max_range: float = 30.0) -> str:
    fov = res * (len(ranges) - 1)
    values = " ".join(map(str, ranges))
    return (
        f"ROBOTLASER1 0 {start} {fov} {res} {max_range} 0.01 0 {len(ranges)} {values} 0 "
        f"1 2 0.5 1.1 2.1 0.6 0 0 0 0 0 {t} host 1.0\n"
    )


def _warnings(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]


def test_param_lines_with_any_trailing_fields(tmp_path):
    path = tmp_path / "aces.clf"
    path.write_text(
        "PARAM robot_frontlaser_offset 0.0 nohost 0\n"  # as in aces.clf: no ipc timestamp
        "PARAM robot_front_laser_max 80.0 1071078718.46 merci 1071078718.46\n"
        "PARAM robot_frontlaser_side_offset 0.05 trailing words\n" + _flaser(1.0)  # a numeric PARAM is its first token
    )
    log = read_carmen(path)
    assert log.params["robot_frontlaser_offset"] == "0.0" and log.params["robot_front_laser_max"] == "80.0"
    assert log.laser.range_max == 80.0
    assert run_from_carmen(log).laser.mount == (0.0, 0.05, 0.0)
    assert log.tolerated == {}


def test_pose_only_flaser_lines_are_a_trajectory(tmp_path, caplog):
    """``FLASER 0 x y th x y th ts host ts``: what SLAM programs write for the Freiburg evaluator."""
    path = tmp_path / "test.log"
    path.write_text("".join(_flaser(10.0 + k, beams=0, pose=(k, 2 * k, 0.1), odom=(k, 2 * k, 0.1)) for k in range(4)))
    log = read_carmen(path)
    assert log.laser.ranges.shape == (4, 0) and log.laser.ranges.dtype == np.float32
    np.testing.assert_array_equal(log.laser.pose[:, 0], [0, 1, 2, 3])
    np.testing.assert_array_equal(log.laser.t, [10, 11, 12, 13])
    assert log.tolerated == {} and not _warnings(caplog)
    with pytest.raises(FormatError, match="no readings .*pose-only.*evaluate") as info:
        read_carmen_run(path)
    assert "\n" not in str(info.value)


def test_beam_count_change_on_one_grid_is_padded_with_no_returns(tmp_path, caplog):
    path = tmp_path / "robot.clf"
    path.write_text(
        _robot(1.0, [1, 2, 3, 4, 5])  # beams at -0.5 .. 0.5 every 0.25
        + _robot(2.0, [7, 8, 9], start=-0.25)  # the middle three beams of the same grid
        + _robot(3.0, [6, 6, 6, 6, 6, 6], start=-0.5, max_range=40.0)  # one more beam, and a longer maximum range
        + _robot(4.0, [30, 1, 2, 3, 4], start=-0.5)  # 30 = no return of a 30 m laser
    )
    log = read_carmen(path)
    laser = log.laser
    assert laser.beams == 6 and laser.angle_min == -0.5 and laser.angle_increment == 0.25 and laser.range_max == 40.0
    np.testing.assert_array_equal(laser.ranges[0], [1, 2, 3, 4, 5, 40])
    np.testing.assert_array_equal(laser.ranges[1], [40, 7, 8, 9, 40, 40])
    np.testing.assert_array_equal(laser.ranges[3], [40, 1, 2, 3, 4, 40])
    assert log.tolerated == {"laser_padded": 3, "laser_range_raised": 3}
    messages = _warnings(caplog)
    assert len(messages) == 2
    assert (
        "3 ROBOTLASER1 lines with fewer readings than the common grid padded" in messages[0]
        and "(first: line 1)" in messages[0]
    )


def test_beam_count_change_off_the_grid_is_refused_for_scans_but_read_for_poses(tmp_path):
    path = tmp_path / "robot.clf"
    path.write_text(_robot(1.0, [1, 2, 3, 4, 5]) + _robot(2.0, [1, 2, 3], res=0.5) + _robot(3.0, [1, 2, 3, 4, 5]))
    with pytest.raises(FormatError, match="not on the angular grid of line 1") as info:
        read_carmen(path)
    assert info.value.line == 2 and "\n" not in str(info.value)
    poses = read_carmen(path, ranges=False)
    assert poses.laser.ranges.shape == (3, 0) and poses.laser.t.tolist() == [1.0, 2.0, 3.0] and poses.tolerated == {}


def test_flaser_beam_count_change_without_a_resolution_param_is_another_grid(tmp_path):
    path = tmp_path / "f.clf"
    path.write_text(_flaser(1.0, beams=5) + _flaser(2.0, beams=3))  # 180 degrees over 5, then over 3 beams
    with pytest.raises(FormatError, match="not on the angular grid") as info:
        read_carmen(path)
    assert info.value.line == 2
    path.write_text("PARAM laser_front_laser_resolution 45\n" + _flaser(1.0, beams=5) + _flaser(2.0, beams=3))
    laser = read_carmen(path).laser  # centred on the heading, 45 degrees apart: the 3 are the middle of the 5
    np.testing.assert_array_equal(laser.ranges[1], [1.5, 1.5, 1.5, 1.5, 1.5])
    path.write_text(
        "PARAM laser_front_laser_resolution 45\n" + _flaser(1.0, beams=5, ranges="1 1 1 1 1") + _flaser(2.0, beams=0)
    )
    laser = read_carmen(path).laser  # a line without readings: all no-return
    np.testing.assert_array_equal(laser.ranges[1], [1, 1, 1, 1, 1])


def test_odom_lines_interleaved_with_laser_lines(tmp_path):
    """A frame's odometry is its own laser line's second triple; ODOM lines are kept apart, in time order."""
    path = tmp_path / "log.clf"
    path.write_text(
        "ODOM 0 0 0 0 0 0 0.95 h 0\n"
        + _flaser(1.0, odom=(1, 0, 0))
        + "ODOM 1.2 0 0 0 0 0 1.05 h 0\n"
        + "ODOM 1.4 0 0 0 0 0 1.02 h 0\n"  # earlier than the ODOM line before it
        + _flaser(1.1, odom=(2, 0, 0))
        + "ODOM 2 0 0 nan 0 0 1.15 h 0\n"
    )
    log = read_carmen(path)
    np.testing.assert_array_equal(log.laser.odometry[:, 0], [1, 2])
    np.testing.assert_array_equal(log.odom.t, [0.95, 1.02, 1.05])
    np.testing.assert_array_equal(log.odom.pose[:, 0], [0, 1.4, 1.2])
    assert log.tolerated == {"odom_reordered": 1, "odom_nonfinite": 1}


def test_odom_moving_forward_while_reversing_is_counted_and_warned(tmp_path, caplog):
    path = tmp_path / "log.clf"
    path.write_text(
        _flaser(0.5, odom=(0, 0, 0))
        + "ODOM 0 0 0 0 0 0 1.0 h 0\n"
        + "ODOM 0.05 0 0 -0.3 0 0 1.1 h 0\n"  # forward 5 cm while tv says backing up at 0.3 m/s
        + "ODOM 0.02 0 0 -0.3 0 0 1.2 h 0\n"  # backwards, as tv says
        + "ODOM 0.06 0.03 0.6 -0.02 0 0 1.3 h 0\n"  # forward at a crawl: not a reversal
        + "ODOM 0.09 0.05 0.6 -0.3 0 0 1.4 h 0\n"  # forward along the heading 0.6 while reversing
    )
    log = read_carmen(path)
    assert log.tolerated == {"odom_against_velocity": 2}
    messages = _warnings(caplog)
    assert len(messages) == 1 and "2 ODOM lines move the pose forward while their velocity tv is below" in messages[0]
    assert messages[0].endswith("(first: line 3)")


def test_non_finite_poses_are_skipped_and_counted_once(tmp_path, caplog):
    path = tmp_path / "log.clf"
    path.write_text(
        _flaser(1.0)
        + _flaser(2.0, pose=("nan", 2, 0))
        + _flaser(3.0, odom=(1, "inf", 0))
        + _flaser(4.0)
        + "FLASER 0 1 2 0 1 2 0 nan host 1\n"
    )
    log = read_carmen(path)
    assert log.laser.t.tolist() == [1.0, 4.0] and log.tolerated == {"laser_nonfinite": 3}
    messages = _warnings(caplog)
    assert messages == [f"{path}: 3 FLASER lines with a non-finite pose, velocity or timestamp skipped (first: line 2)"]


def test_backwards_timestamps_are_ordered_stably_and_repeats_dropped(tmp_path, caplog):
    path = tmp_path / "log.clf"
    path.write_text(
        _flaser(1.0, pose=(1, 0, 0))
        + _flaser(3.0, pose=(3, 0, 0))
        + _flaser(2.0, pose=(2, 0, 0))
        + _flaser(3.0, pose=(33, 0, 0))
        + _flaser(4.0, pose=(4, 0, 0))
    )
    log = read_carmen(path)
    assert log.laser.t.tolist() == [1.0, 2.0, 3.0, 4.0]
    assert log.laser.pose[:, 0].tolist() == [1, 2, 3, 4]  # of the two lines at t = 3, the first in the file
    assert log.tolerated == {"laser_reordered": 1, "laser_duplicate": 1}  # the 2.0 after the 3.0; the second 3.0
    assert len(_warnings(caplog)) == 2


@pytest.mark.parametrize("cut", [12, 30, -8])
def test_a_truncated_last_line_is_skipped_with_a_warning(tmp_path, caplog, cut):
    path = tmp_path / "log.clf"
    whole = _flaser(1.0) + _flaser(2.0) + _flaser(3.0)
    path.write_text(whole[: len(whole) - 1 + cut] if cut < 0 else whole + _flaser(4.0)[:cut])
    log = read_carmen(path)
    assert len(log.laser) == (2 if cut < 0 else 3) and log.tolerated == {"truncated_last_line": 1}
    assert len(_warnings(caplog)) == 1 and "cut short" in _warnings(caplog)[0]


def test_a_broken_line_elsewhere_is_still_an_error(tmp_path):
    broken = _flaser(2.0)[:30]
    path = tmp_path / "log.clf"
    path.write_text(_flaser(1.0) + broken + "\n" + _flaser(3.0))  # in the middle
    with pytest.raises(FormatError, match="needs 14 fields") as info:
        read_carmen(path)
    assert info.value.line == 2 and str(info.value).startswith(f"{path}:2: ")
    path.write_text(_flaser(1.0) + broken + "\n")  # last, but the file ends with a newline: written whole, not cut
    with pytest.raises(FormatError) as info:
        read_carmen(path)
    assert info.value.line == 2


@pytest.mark.parametrize("compress", [gzip.compress, bz2.compress])
def test_compressed_logs_read_directly(tmp_path, compress):
    text = "PARAM robot_front_laser_max 50\n" + "".join(_flaser(1.0 + k, ranges="1 2 3") for k in range(5))
    plain, packed = tmp_path / "log.clf", tmp_path / "log.clf.z"  # recognised by content, not by name
    plain.write_text(text)
    packed.write_bytes(compress(text.encode()))
    a, b = read_carmen(plain), read_carmen(packed)
    np.testing.assert_array_equal(a.laser.ranges, b.laser.ranges)
    np.testing.assert_array_equal(a.laser.pose, b.laser.pose)
    assert a.params == b.params


@pytest.mark.parametrize("compress", [gzip.compress, bz2.compress])
def test_a_compressed_log_cut_short_reads_its_complete_lines(tmp_path, caplog, compress):
    text = "".join(_flaser(1.0 + k, ranges="1 2 3") for k in range(8000)).encode()  # bzip2: 3 blocks of 100 kB
    data = compress(text, compresslevel=1)
    path = tmp_path / "cut.clf"
    path.write_bytes(data[: len(data) * 2 // 3])
    log = read_carmen(path)
    assert 0 < len(log.laser) < 8000
    assert any("ends early" in m for m in _warnings(caplog))


def test_a_corrupt_compressed_log_is_one_format_error(tmp_path):
    path = tmp_path / "bad.clf.gz"
    path.write_bytes(gzip.compress(b"FLASER 0 1 2 3 1 2 3 1.0 h 1\n")[:10] + b"\xff" * 40)
    with pytest.raises(FormatError, match="not a readable gzip file") as info:
        read_carmen(path)
    assert "\n" not in str(info.value)


@pytest.mark.slow  # real data: the whole fr079 log, read twice
@pytest.mark.skipif(not FR079.is_file(), reason="shared data not present")
def test_fr079_bzip2_log_reads_directly():
    log = read_carmen(FR079)
    laser = log.laser
    assert laser.kind == "FLASER" and laser.ranges.shape == (4934, 360) and len(log.odom) == 8951
    assert laser.range_max == 80.99 and laser.angle_increment == pytest.approx(math.radians(0.5), rel=1e-12)
    assert laser.angle_min == -math.pi / 2  # CARMEN's start angle for FLASER lines, not centred
    assert log.params["robot_frontlaser_offset"] == "-0.04" and log.skipped == {}
    # the log's known defect: reversing logged as driving forward (docs/real-datasets.md)
    assert log.tolerated == {"odom_against_velocity": 308}
    assert laser.t[0] == pytest.approx(1211.520329) and laser.t[-1] == pytest.approx(2272.97, abs=0.01)
    # each frame's odometry is its FLASER line's own second triple, in the frame of the ODOM lines
    assert np.abs(laser.odometry[0, :2] - log.odom.pose[0, :2]).max() < 0.01
    record = read_carmen_run(FR079)
    assert record.scans.shape == (4934, 360) and record.laser.mount == (-0.04, 0.0, 0.0)


@pytest.mark.slow  # real data: the whole MIT CSAIL log, read twice
@pytest.mark.skipif(not MIT.is_file(), reason="shared data not present")
def test_mit_csail_reads_the_same_compressed(tmp_path):
    packed = tmp_path / "mit-csail.clf.gz"
    packed.write_bytes(gzip.compress(MIT.read_bytes()))
    a, b = read_carmen(MIT), read_carmen(packed)
    assert b.laser.ranges.shape == (1988, 361) and b.tolerated == {}
    np.testing.assert_array_equal(a.laser.ranges, b.laser.ranges)
    np.testing.assert_array_equal(a.laser.t, b.laser.t)


def test_a_geometry_a_run_cannot_hold_is_one_format_error(tmp_path):
    path = tmp_path / "one.clf"
    path.write_text(_flaser(1.0, beams=1) + _flaser(2.0, beams=1))  # one beam: no angular increment
    assert read_carmen(path).laser.ranges.shape == (2, 1)
    with pytest.raises(FormatError, match="laser geometry cannot be used: .*angle_increment") as info:
        read_carmen_run(path)
    assert "\n" not in str(info.value)


def test_a_trajectory_written_as_a_freiburg_test_log_reads_back(tmp_path):
    from slamtrials.io.carmen import carmen_from_trajectory, write_carmen
    from slamtrials.record import Trajectory

    t = 1134864600.0 + 0.25 * np.arange(6)
    poses = np.column_stack([np.arange(6) * 0.5, np.sin(np.arange(6)), 0.1 * np.arange(6)])
    path = write_carmen(tmp_path / "test.log", carmen_from_trajectory(Trajectory(t=t, poses=poses)))
    lines = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    assert len(lines) == 6 and lines[1].startswith(
        "FLASER 0 0.500000 0.841471 0.100000 0.500000 0.841471 0.100000 1134864600.250000 "
    )
    log = read_carmen(path)
    assert log.laser.pose_only and log.params == {} and log.tolerated == {}
    np.testing.assert_allclose(log.laser.odometry, poses, atol=5e-7)
    np.testing.assert_array_equal(log.laser.t, t)


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_any_mix_of_oddities_reads_as_the_clean_log(tmp_path_factory, data):
    """Lines shuffled, repeated, given nan poses and a cut last line: what is read is the clean log's lines
    with finite poses, in time order, the first of each repeated timestamp; each oddity counted as it was made."""
    n = data.draw(st.integers(min_value=2, max_value=25))
    t = 100.0 + np.cumsum(data.draw(st.lists(st.integers(1, 5), min_size=n, max_size=n))) * 0.1
    lines = [_flaser(float(t[k]), pose=(k, 0, 0), ranges="1 2 3") for k in range(n)]
    order = data.draw(st.permutations(range(n)))
    bad = set(data.draw(st.lists(st.sampled_from(range(n)), max_size=n - 1, unique=True)))
    repeats = data.draw(st.lists(st.sampled_from(range(n)), max_size=3, unique=True))
    text = [lines[k].replace(f" {k} 0 0 ", " nan 0 0 ", 1) if k in bad else lines[k] for k in order]
    for k in repeats:  # a later line with an earlier line's timestamp and another pose
        text.append(_flaser(float(t[k]), pose=(1000 + k, 0, 0), ranges="1 2 3"))
    cut = data.draw(st.booleans())
    body = "".join(text) + ("FLASER 3 1 2" if cut else "")
    path = tmp_path_factory.mktemp("mix") / "log.clf"
    path.write_text(body)
    log = read_carmen(path)
    good = sorted(k for k in range(n) if k not in bad)
    first_repeat = [k for k in repeats if k in bad]  # a repeat of a skipped line is the only line at its time
    expected_t = sorted([float(t[k]) for k in good] + [float(t[k]) for k in first_repeat])
    np.testing.assert_array_equal(log.laser.t, expected_t)
    expected_x = {float(t[k]): k for k in good} | {float(t[k]): 1000 + k for k in first_repeat}
    assert log.laser.pose[:, 0].tolist() == [expected_x[v] for v in expected_t]
    assert log.tolerated.get("laser_nonfinite", 0) == len(bad)
    assert log.tolerated.get("laser_duplicate", 0) == len([k for k in repeats if k not in bad])
    assert log.tolerated.get("truncated_last_line", 0) == int(cut)
    assert set(log.tolerated) <= set(TOLERATED)


@settings(max_examples=80, deadline=None)
@given(data=st.data())
def test_common_grid_puts_every_reading_at_its_angle(data):
    """Lines on one grid (same increment, starts whole increments apart): each reading lands in the column of
    its angle, every other cell is a no-return reading, and nothing is lost."""
    from slamtrials.io.carmen_grid import common_grid

    increment = data.draw(st.sampled_from([0.25, math.radians(0.5), -0.1]))
    base = data.draw(st.floats(-2.0, 0.0))
    n = data.draw(st.integers(1, 6))
    offsets = data.draw(st.lists(st.integers(0, 4), min_size=n, max_size=n))
    counts = data.draw(st.lists(st.integers(0, 6), min_size=n, max_size=n))
    maxima = data.draw(st.lists(st.sampled_from([30.0, 40.0]), min_size=n, max_size=n))
    ranges = [np.arange(1, c + 1, dtype=np.float64) + 0.1 * k for k, c in enumerate(counts)]  # below every maximum
    geometry = np.array([[base + o * increment, increment, m] for o, m in zip(offsets, maxima)])
    filled = [k for k in range(n) if counts[k]]
    widest = max(counts)
    if filled:  # shifts beyond the widest line, or a grid over twice as wide, are refused as not one laser
        span = max(offsets[k] + counts[k] for k in filled) - min(offsets[k] for k in filled)
        if any(abs(offsets[k] - offsets[filled[0]]) > widest for k in filled) or span > 2 * widest:
            with pytest.raises(FormatError, match="grid"):
                common_grid(Path("x.clf"), "ROBOTLASER1", list(range(1, n + 1)), ranges, geometry)
            return
    grid = common_grid(Path("x.clf"), "ROBOTLASER1", list(range(1, n + 1)), ranges, geometry)
    assert grid.range_max == max(maxima) and grid.ranges.shape[0] == n
    if not any(counts):
        assert grid.ranges.shape[1] == 0
        return
    assert grid.angle_increment == increment
    for k in range(n):
        row = grid.ranges[k]
        for j, value in enumerate(ranges[k]):
            column = round((base + (offsets[k] + j) * increment - grid.angle_min) / increment)
            assert row[column] == np.float32(value)
        assert np.count_nonzero(row != grid.range_max) == counts[k]
