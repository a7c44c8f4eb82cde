"""CARMEN logs: the real MIT CSAIL log, exact round trips at the printed precision, run conversion,
and a FormatError naming file and line for every kind of malformed log."""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path

import numpy as np
import pytest

from slamtrials.errors import FormatError
from slamtrials.geometry import compose
from slamtrials.io.carmen import (
    TRUTH_SOURCE_TRUEPOS,
    CarmenLaser,
    CarmenLog,
    CarmenOdometry,
    carmen_from_run,
    read_carmen,
    run_from_carmen,
    write_carmen,
)
from slamtrials.io.relations import read_relations
from slamtrials.record import LaserGeometry, RunRecord

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared"))
MIT = SHARED / "data" / "mit-csail"


def r3(values) -> np.ndarray:
    """Ranges as the writer prints them (%.3f) and the reader stores them (float32)."""
    return np.array([float(f"{v:.3f}") for v in np.ravel(values).tolist()], dtype=np.float32).reshape(np.shape(values))


def r6(values) -> np.ndarray:
    """Numbers as the writer prints them (%.6f) and reads them back."""
    return np.array([float(f"{v:.6f}") for v in np.ravel(values).tolist()]).reshape(np.shape(values))


def _log(kind: str = "ROBOTLASER1", n: int = 30, beams: int = 9, seed: int = 0, hostname="b21") -> CarmenLog:
    rng = np.random.default_rng(seed)
    t = r6(1134864629.0 + np.cumsum(rng.uniform(0.05, 0.2, n)))
    increment = math.radians(1.0)
    laser = CarmenLaser(
        kind=kind,
        t=t,
        logger_t=r6(t - t[0] + 0.25),
        hostname=hostname,
        ranges=r3(rng.uniform(0, 80, (n, beams))),
        pose=r6(rng.normal(0, 50, (n, 3))),
        odometry=r6(rng.normal(0, 50, (n, 3))),
        angle_min=-increment * (beams - 1) / 2 if kind == "FLASER" else -2.1,
        angle_increment=increment,
        range_max=80.0,
        laser_type=4 if kind == "ROBOTLASER1" else 0,
        accuracy=0.01 if kind == "ROBOTLASER1" else 0.0,
        remission_mode=0,
        extra=r6(rng.normal(size=(n, 5))) if kind == "ROBOTLASER1" else None,
    )
    m = 2 * n
    odom_t = r6(np.sort(rng.uniform(t[0] - 1, t[-1] + 1, m)))
    odom_host = hostname if isinstance(hostname, str) else (hostname * 2)[:m]
    odom = CarmenOdometry(
        t=odom_t,
        logger_t=r6(odom_t - t[0]),
        hostname=odom_host,
        pose=r6(rng.normal(0, 50, (m, 3))),
        tv=r6(rng.normal(size=m)),
        rv=r6(rng.normal(size=m)),
        accel=r6(rng.normal(size=m)),
    )
    return CarmenLog(
        laser=laser, odom=odom, params={"robot_use_laser": "on", "robot_frontlaser_offset": "0.12", "note": "two words"}
    )


def _assert_same_log(back: CarmenLog, log: CarmenLog, exact_angles: bool = True) -> None:
    a, b = back.laser, log.laser
    assert a.kind == b.kind
    for name in ("t", "logger_t", "ranges", "pose", "odometry"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
        assert getattr(a, name).dtype == getattr(b, name).dtype
    assert a.hostnames() == b.hostnames()
    if exact_angles:
        assert (a.angle_min, a.angle_increment, a.range_max) == (b.angle_min, b.angle_increment, b.range_max)
    else:
        np.testing.assert_allclose(
            [a.angle_min, a.angle_increment, a.range_max], [b.angle_min, b.angle_increment, b.range_max], rtol=1e-15
        )
    for name in ("t", "logger_t", "pose", "tv", "rv", "accel"):
        np.testing.assert_array_equal(getattr(back.odom, name), getattr(log.odom, name), err_msg=name)
    assert back.odom.hostnames() == log.odom.hostnames()
    assert {k: back.params[k] for k in log.params} == log.params


# -- the real log ------------------------------------------------------------------------------------


@pytest.mark.skipif(not (MIT / "mit-csail.clf").is_file(), reason="shared data not present")
def test_mit_csail_log_has_1988_scans_of_361_beams_over_180_degrees():
    log = read_carmen(MIT / "mit-csail.clf")
    laser = log.laser
    assert laser.kind == "FLASER"
    assert laser.ranges.shape == (1988, 361) and laser.ranges.dtype == np.float32
    assert laser.angle_min == pytest.approx(-math.pi / 2, abs=1e-15)
    assert laser.angle_increment * 360 == pytest.approx(math.pi, abs=1e-14)
    assert laser.range_max == 81.91  # the SICK's no-return reading, no PARAM lines in this log
    assert laser.hostname == "b21"
    assert laser.t[0] == 1134864629.895182 and laser.t[-1] == 1134865053.892206
    assert laser.logger_t[0] == 0.086295 and laser.logger_t[-1] == 424.077432
    assert np.all(np.diff(laser.t) > 0)
    np.testing.assert_array_equal(laser.pose[0], [576.536523, 0.106594, -2.255213])
    assert laser.ranges[0, 0] == np.float32(1.40) and laser.ranges[0, 24] == np.float32(81.91)
    assert len(log.odom) == 0 and log.params == {} and log.skipped == {}


@pytest.mark.skipif(not (MIT / "mit-csail.relations").is_file(), reason="shared data not present")
def test_mit_csail_relations_refer_to_laser_timestamps():
    laser = read_carmen(MIT / "mit-csail.clf").laser
    relations = read_relations(MIT / "mit-csail.relations")
    stamps = np.concatenate([relations.t1, relations.t2])
    nearest = np.abs(laser.t[None, :] - stamps[:, None]).min(axis=1)
    assert nearest.max() < 1e-5  # relations print 5 decimals, the log 6


@pytest.mark.slow  # real data: the whole MIT CSAIL log, written and read back
@pytest.mark.skipif(not (MIT / "mit-csail.clf").is_file(), reason="shared data not present")
def test_mit_csail_rewrites_to_the_same_log(tmp_path):
    log = read_carmen(MIT / "mit-csail.clf")
    write_carmen(tmp_path / "again.clf", log)
    back = read_carmen(tmp_path / "again.clf")
    _assert_same_log(back, log, exact_angles=False)
    assert back.params["laser_front_laser_fov"] == "180.0" and back.params["laser_front_laser_resolution"] == "0.5"


# -- round trips -------------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["ROBOTLASER1", "FLASER"])
def test_round_trip_is_exact_at_the_printed_precision(tmp_path, kind):
    log = _log(kind)
    write_carmen(tmp_path / "log.clf", log)
    back = read_carmen(tmp_path / "log.clf")
    _assert_same_log(back, log, exact_angles=kind == "ROBOTLASER1")  # FLASER angles pass through degrees
    if kind == "ROBOTLASER1":
        np.testing.assert_array_equal(back.laser.extra, log.laser.extra)
        assert (back.laser.laser_type, back.laser.accuracy, back.laser.remission_mode) == (4, 0.01, 0)
    else:
        assert back.laser.extra is None
    assert back.params["note"] == "two words" and back.skipped == {}


def test_round_trip_keeps_one_hostname_per_line(tmp_path):
    hosts = [f"host{i % 3}" for i in range(30)]
    log = _log(hostname=hosts)
    write_carmen(tmp_path / "log.clf", log)
    back = read_carmen(tmp_path / "log.clf")
    assert back.laser.hostname == hosts


def test_written_lines_are_in_timestamp_order(tmp_path):
    write_carmen(tmp_path / "log.clf", _log())
    lines = [line.split() for line in (tmp_path / "log.clf").read_text().splitlines() if line[:1] != "#"]
    stamps = [float(tokens[-3]) for tokens in lines if tokens[0] != "PARAM"]
    assert stamps == sorted(stamps)
    assert lines[0][0] == "PARAM" and {tokens[0] for tokens in lines} == {"PARAM", "ODOM", "ROBOTLASER1"}


def _record(n: int = 40, beams: int = 541, seed: int = 1) -> RunRecord:
    rng = np.random.default_rng(seed)
    increment = 1.5 * math.pi / (beams - 1)
    return RunRecord(
        t=np.arange(n) * 0.1,
        scans=rng.uniform(0.05, 30, (n, beams)).astype(np.float32),
        odometry=np.cumsum(rng.normal(0, 0.05, (n, 3)), axis=0),
        truth=np.cumsum(rng.normal(0, 0.05, (n, 3)), axis=0),
        stalled=np.zeros(n, dtype=bool),
        laser=LaserGeometry.from_dict(
            {
                "angle_min": -0.75 * math.pi,
                "angle_increment": increment,
                "range_min": 0.02,
                "range_max": 30.0,
                "mount": [0.1, -0.02, 0.01],
            }
        ),
        metadata={"world": "lab"},
    )


@pytest.mark.parametrize("kind", ["ROBOTLASER1", "FLASER"])
def test_run_export_and_import(tmp_path, kind):
    record = _record()
    write_carmen(tmp_path / "run.clf", carmen_from_run(record, kind=kind, truth=True))
    log = read_carmen(tmp_path / "run.clf")
    back = run_from_carmen(log)
    # the first triple is the laser's pose by odometry; the ground truth comes from the TRUEPOS lines
    np.testing.assert_array_equal(log.laser.pose, r6(compose(record.odometry, record.laser.mount)))
    np.testing.assert_array_equal(back.t, r6(record.t))
    np.testing.assert_array_equal(back.scans, r3(record.scans))
    np.testing.assert_array_equal(back.truth, r6(record.truth))
    np.testing.assert_array_equal(back.odometry, r6(record.odometry))
    assert not back.stalled.any()
    assert back.laser.mount == (0.1, -0.02, 0.01) and back.laser.range_min == 0.02 and back.laser.range_max == 30.0
    if kind == "ROBOTLASER1":
        assert (back.laser.angle_min, back.laser.angle_increment) == (
            record.laser.angle_min,
            record.laser.angle_increment,
        )
    else:
        assert back.laser.angle_min == pytest.approx(record.laser.angle_min, rel=1e-15)
        assert back.laser.angle_increment == pytest.approx(record.laser.angle_increment, rel=1e-15)
    assert back.metadata["truth_source"] == TRUTH_SOURCE_TRUEPOS and back.metadata["carmen_kind"] == kind


def test_export_writes_odometry_velocities(tmp_path):
    record = _record(n=5, beams=3)
    record.odometry[:] = [[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0.05], [0.2, 0, 0.05], [0.2, 0, 0.15]]
    log = carmen_from_run(record)
    np.testing.assert_allclose(log.odom.tv, [0, 1, 1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(log.odom.rv, [0, 0, 0.5, 0, 1.0], atol=1e-12)
    np.testing.assert_array_equal(log.laser.extra[:, :2], np.column_stack([log.odom.tv, log.odom.rv]))


def test_flaser_export_refuses_an_off_centre_scan(tmp_path):
    record = _record(n=3, beams=5)
    record.laser = dataclasses.replace(record.laser, angle_min=-0.1)
    with pytest.raises(ValueError, match="centred"):
        write_carmen(tmp_path / "run.clf", carmen_from_run(record, kind="FLASER"))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda log: log.laser.ranges.__setitem__((0, 0), np.inf), "non-finite"),
        (lambda log: log.laser.ranges.__setitem__((0, 0), -1.0), "negative"),
        (lambda log: log.odom.pose.__setitem__((0, 0), np.nan), "non-finite"),
        (lambda log: setattr(log.laser, "hostname", "two words"), "hostname"),
        (lambda log: log.params.__setitem__("bad", " x"), "PARAM"),
        (lambda log: log.laser.t.__setitem__(1, log.laser.t[0] + 1e-7), "1 us"),
    ],
)
def test_writer_refuses_what_would_not_read_back(tmp_path, change, message):
    log = _log()
    change(log)
    with pytest.raises(ValueError, match=message):
        write_carmen(tmp_path / "log.clf", log)


# -- reading details ---------------------------------------------------------------------------------


def _flaser(beams: int, t: float, ranges: str | None = None) -> str:
    readings = ranges if ranges is not None else " ".join(["1.5"] * beams)
    return f"FLASER {beams} {readings} 1 2 0.5 1.1 2.1 0.6 {t} host {t - 100}\n"


def test_other_line_types_are_skipped_and_counted(tmp_path):
    path = tmp_path / "log.clf"
    path.write_text(
        "# CARMEN Logfile\n\n"
        "RLASER 2 1 1 0 0 0 0 0 0 5.0 host 1.0\n"
        + _flaser(3, 101.0)
        + "TRUEPOS 1 2 3 4 5 6 101.0 host 1.0\nSYNC tag 101.5 host 1.5\nRLASER 2 1 1 0 0 0 0 0 0 5.0 host 1.0\n"
        + _flaser(3, 102.0)
    )
    log = read_carmen(path)
    assert len(log.laser) == 2 and log.skipped == {"RLASER": 2, "SYNC": 1}
    assert len(log.truepos) == 1  # TRUEPOS lines are read (tests/io/test_carmen_truepos.py)
    np.testing.assert_array_equal(log.laser.pose[0], [1, 2, 0.5])
    np.testing.assert_array_equal(log.laser.odometry[0], [1.1, 2.1, 0.6])
    assert log.laser.logger_t.tolist() == [1.0, 2.0]


@pytest.mark.parametrize(
    ("params", "angle_min", "increment", "range_max"),
    [
        ("", -math.pi / 2, math.pi / 4, 7.5),  # CARMEN's default: 180 degrees over the beams; largest range
        ("PARAM laser_front_laser_fov 100 1.0 h 1.0\n", -math.radians(50), math.radians(25), 7.5),
        (  # CARMEN's reader starts every old-format laser at -90 degrees
            "PARAM laser_front_laser_resolution 1.0\nPARAM robot_front_laser_max 50.0 1.0 h 1.0\n",
            -math.pi / 2,
            math.radians(1),
            50.0,
        ),
    ],
)
def test_flaser_geometry_comes_from_params(tmp_path, params, angle_min, increment, range_max):
    path = tmp_path / "log.clf"
    path.write_text(params + _flaser(5, 101.0, "1 2 3 7.5 0"))
    laser = read_carmen(path).laser
    assert laser.angle_min == pytest.approx(angle_min, rel=1e-14)
    assert laser.angle_increment == pytest.approx(increment, rel=1e-14)
    assert laser.range_max == range_max


def test_a_360_beam_flaser_laser_starts_at_minus_90_degrees_as_carmen_reads_it(tmp_path):
    # fr079: 360 readings and laser_front_laser_resolution 0.5; CARMEN's reader (start_angle -pi/2,
    # "179.5 degrees, last beam ignored") and GMapping's put beam 0 at -90, not at -89.75 degrees
    path = tmp_path / "log.clf"
    path.write_text("PARAM laser_front_laser_resolution 0.5\n" + _flaser(360, 101.0))
    laser = read_carmen(path).laser
    assert laser.angle_min == -math.pi / 2
    assert laser.angle_increment == pytest.approx(math.radians(0.5), rel=1e-15)
    assert laser.angle_min + 359 * laser.angle_increment == pytest.approx(math.radians(89.5), rel=1e-14)


def test_param_values_with_and_without_stamps(tmp_path):
    path = tmp_path / "log.clf"
    path.write_text("PARAM a 1\nPARAM b x y 3.0 host 4.0\nPARAM c some words\nPARAM a 2 1.0 h 1.0\n" + _flaser(2, 1.0))
    assert read_carmen(path).params == {"a": "2", "b": "x y", "c": "some words"}


def test_odometry_lines(tmp_path):
    path = tmp_path / "log.clf"
    path.write_text("ODOM 1 2 3 0.5 0.1 0 100.0 h 0.5\nODOM 1.5 2 3 0.5 0.1 0 100.0 h 0.6\n" + _flaser(2, 101.0))
    odom = read_carmen(path).odom
    np.testing.assert_array_equal(odom.pose, [[1, 2, 3], [1.5, 2, 3]])
    assert odom.t.tolist() == [100.0, 100.0] and odom.logger_t.tolist() == [0.5, 0.6]
    assert odom.tv.tolist() == [0.5, 0.5] and odom.hostname == "h"


ROBOT = "ROBOTLASER1 0 -1.5 3.0 1.5 30 0.01 0 3 1 2 3 {m} 0 0 0 1 1 1 0 0 0 0 0 {t} host 1.0\n"


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("", 1, "no FLASER or ROBOTLASER1"),
        ("# only a comment\n\nODOM 1 2 3 0 0 0 1.0 h 1.0\n", 3, "no FLASER or ROBOTLASER1"),
        (_flaser(3, 1.0) + "FLASER 3 1 2 1 2 0.5 1.1 2.1 0.6 2.0 host 3.0\n", 2, "needs 14 fields"),
        (_flaser(3, 1.0) + "FLASER\n", 2, "before num_readings"),
        ("FLASER x 1 2\n", 1, "num_readings"),
        ("FLASER -3 1 2\n", 1, ">= 0"),
        (_flaser(3, 1.0, "1 abc 3"), 1, "field 4 (range) is not a number: 'abc'"),
        (_flaser(3, 1.0, "1 nan 3"), 1, "range 2 is not finite"),
        (_flaser(3, 1.0, "1 1e400 3"), 1, "range 2 is not finite"),
        (_flaser(3, 1.0, "1 1e300 3"), 1, "too large for float32"),
        (_flaser(3, 1.0, "1 -2 3"), 1, "range 2 is negative"),
        ("FLASER 1 1 1 2 inf 1.1 2.1 0.6 2.0 host 3.0\n", 1, "every FLASER line has a non-finite pose"),
        ("FLASER 1 1 1 2 0 1 2 0 2.0 host x\n", 1, "logger_timestamp) is not a number"),
        (_flaser(3, 1.0) + _flaser(4, 2.0), 2, "not on the angular grid of line 1"),
        (ROBOT.format(m=0, t=1.0) + "FLASER 3 1 2\n", 2, "FLASER with num_readings 3 needs 14 fields"),
        (ROBOT.format(m=2, t=1.0), 1, "needs 29 fields, got 27"),
        (ROBOT.format(m="x", t=1.0), 1, "num_remissions"),
        (ROBOT.format(m=0, t=1.0).replace(" 30 ", " 0 "), 1, "maximum_range must be positive"),
        (ROBOT.format(m=0, t=1.0).replace("ROBOTLASER1 0 ", "ROBOTLASER1 0.5 "), 1, "laser_type"),
        ("ROBOTLASER1 0 -1.5 3.0 1.5\n", 1, "before its readings"),
        ("ROBOTLASER1 0 -1.5 3.0 1.5 30 0.01 0 30 1 2 3\n", 1, "before num_remissions"),
        (_flaser(2, 1.0) + "ODOM 1 2 3 0 0 0 1.0 h\n", 2, "expected 10 fields"),
        (_flaser(2, 1.0) + "ODOM 1 2 0 fast 0 0 1.0 h 1\n", 2, "field 5 (tv) is not a number: 'fast'"),
        ("PARAM lonely\n" + _flaser(2, 1.0), 1, "PARAM name value"),
        ("PARAM laser_front_laser_fov wide\n" + _flaser(2, 1.0), 1, "positive number"),
        ("PARAM robot_front_laser_max -3\n" + _flaser(2, 1.0), 1, "positive number"),
        ("PARAM robot_frontlaser_offset nan\n" + _flaser(2, 1.0), 1, "finite number"),
    ],
)
def test_malformed_logs_name_file_and_line(tmp_path, text, line, message):
    path = tmp_path / "bad.clf"
    path.write_text(text)
    with pytest.raises(FormatError, match=None) as info:
        read_carmen(path)
    assert info.value.path == path and info.value.line == line, str(info.value)
    assert message in str(info.value) and str(path) in str(info.value)


def test_non_utf8_bytes_name_the_line_and_byte(tmp_path):
    path = tmp_path / "bad.clf"
    path.write_bytes(_flaser(2, 1.0).encode() + b"FLASER 2 1 \xff 2\n")
    with pytest.raises(FormatError, match="byte") as info:
        read_carmen(path)
    assert info.value.line == 2


def test_missing_file_is_a_format_error(tmp_path):
    with pytest.raises(FormatError, match="no such file"):
        read_carmen(tmp_path / "nothing.clf")
    with pytest.raises(FormatError, match="directory"):
        read_carmen(tmp_path)
