"""CARMEN export keeps the ground truth out of the laser lines (issue 33).

The first pose triple of every laser line is the laser's pose by odometry (odometry of the base composed
with the laser mount), as CARMEN and the tools that read its logs take it; the ground truth goes into
TRUEPOS lines, only when asked for; reading takes the truth from them, matched to the laser lines by
timestamp, and refuses TRUEPOS lines that do not cover the laser lines in one line naming file and line.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.errors import FormatError
from slamtrials.geometry import compose, ominus
from slamtrials.io.carmen import (
    TRUTH_SOURCE,
    TRUTH_SOURCE_NONE,
    TRUTH_SOURCE_TRUEPOS,
    carmen_from_run,
    read_carmen,
    run_from_carmen,
    write_carmen,
)
from slamtrials.io.carmen_read import TRUEPOS_TOLERANCE, truth_at_laser
from slamtrials.io.runfolder import read_run, write_run
from slamtrials.io.transfer import read_carmen_run
from slamtrials.record import LaserGeometry, RunRecord

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared"))
MIT = SHARED / "data" / "mit-csail" / "mit-csail.clf"
MOUNT = (0.25, -0.04, 0.1)


def r6(values) -> np.ndarray:
    """Numbers as the writer prints them (%.6f) and reads them back."""
    return np.array([float(f"{v:.6f}") for v in np.ravel(values).tolist()]).reshape(np.shape(values))


def _record(n: int = 30, beams: int = 181, seed: int = 4) -> RunRecord:
    """A drive whose ground truth (world frame) is far from its odometry (odometry frame)."""
    rng = np.random.default_rng(seed)
    odometry = np.cumsum(np.column_stack([rng.uniform(0, 0.1, n), rng.normal(0, 0.01, n), rng.normal(0, 0.05, n)]), 0)
    truth = compose(np.array([12.5, -7.25, 0.6]), odometry + rng.normal(0, 0.02, (n, 3)))
    increment = math.pi / (beams - 1)
    return RunRecord(
        t=1000.0 + np.arange(n) * 0.1,
        scans=rng.uniform(0.1, 20, (n, beams)).astype(np.float32),
        odometry=odometry,
        truth=truth,
        stalled=np.zeros(n, dtype=bool),
        laser=LaserGeometry(
            angle_min=-increment * (beams - 1) / 2,
            angle_increment=increment,
            range_min=0.05,
            range_max=20.0,
            mount=MOUNT,
        ),
        metadata={},
    )


def _truth_strings(record: RunRecord) -> set[str]:
    """The ground truth's coordinates as the writer would print them (%.6f)."""
    return {f"{v:.6f}" for v in np.ravel(record.truth[:, :2]).tolist()}


# -- the laser lines: odometry (+) mount, never the truth ---------------------------------------------


@pytest.mark.parametrize("kind", ["ROBOTLASER1", "FLASER"])
@pytest.mark.parametrize("truth", [True, False])
def test_first_triple_is_the_laser_pose_by_odometry_not_the_truth(tmp_path, kind, truth):
    record = _record()
    path = write_carmen(tmp_path / "run.clf", carmen_from_run(record, kind=kind, truth=truth))
    laser = read_carmen(path).laser
    np.testing.assert_array_equal(laser.pose, r6(compose(record.odometry, MOUNT)))
    np.testing.assert_array_equal(laser.odometry, r6(record.odometry))
    assert np.abs(laser.pose[:, :2] - record.truth[:, :2]).min() > 1.0  # the old export wrote the truth here


def test_robotlaser1_triples_give_the_laser_mount(tmp_path):
    record = _record()
    laser = read_carmen(write_carmen(tmp_path / "run.clf", carmen_from_run(record))).laser
    mount = ominus(laser.odometry, laser.pose)  # laser_pose in the frame of robot_pose, as CARMEN intends
    np.testing.assert_allclose(mount, np.tile(MOUNT, (len(record), 1)), atol=2e-6)


def test_an_explicit_first_triple_is_written_as_given(tmp_path):
    record = _record()
    estimate = record.odometry + 0.5
    laser = read_carmen(write_carmen(tmp_path / "e.clf", carmen_from_run(record, first_triple=estimate))).laser
    np.testing.assert_array_equal(laser.pose, r6(estimate))
    with pytest.raises(ValueError, match="first_triple has shape"):
        carmen_from_run(record, first_triple=estimate[1:])


# -- TRUEPOS lines ------------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["ROBOTLASER1", "FLASER"])
def test_round_trip_keeps_truth_odometry_ranges_and_mount(tmp_path, kind):
    record = _record()
    path = write_carmen(tmp_path / "run.clf", carmen_from_run(record, kind=kind, truth=True))
    lines = path.read_text().splitlines()
    truepos = [line.split() for line in lines if line.startswith("TRUEPOS ")]
    assert len(truepos) == len(record) and all(len(tokens) == 10 for tokens in truepos)
    # CARMEN's field order: true pose, odometry pose, ipc_timestamp, ipc_hostname, logger_timestamp
    first = truepos[0]
    assert first[1:7] == [f"{v:.6f}" for v in [*record.truth[0], *record.odometry[0]]]
    assert first[7:] == [f"{record.t[0]:.6f}", "slamtrials", "0.000000"]
    back = run_from_carmen(read_carmen(path))
    np.testing.assert_array_equal(back.truth, r6(record.truth))
    np.testing.assert_array_equal(back.odometry, r6(record.odometry))
    np.testing.assert_allclose(back.scans, record.scans, atol=5e-4 + 1e-6)
    assert back.laser.mount == MOUNT
    assert back.metadata["truth_source"] == TRUTH_SOURCE_TRUEPOS and back.metadata["truth_available"] is True
    assert back.metadata["carmen_truepos_lines"] == len(record) and "TRUEPOS" not in back.metadata["carmen_skipped"]


def test_truepos_lines_come_before_the_laser_line_of_their_timestamp(tmp_path):
    path = write_carmen(tmp_path / "run.clf", carmen_from_run(_record(n=3), truth=True))
    names = [line.split()[0] for line in path.read_text().splitlines() if line[:1] != "#"]
    assert names[-9:] == ["ODOM", "TRUEPOS", "ROBOTLASER1"] * 3


def test_without_truth_the_file_holds_no_ground_truth(tmp_path):
    record = _record()
    path = write_carmen(tmp_path / "run.clf", carmen_from_run(record))  # truth=False is the default
    text = path.read_text()
    assert "TRUEPOS" not in text and "this log holds no ground truth" in text
    tokens = set(text.split())
    assert not (tokens & _truth_strings(record)), "a ground-truth coordinate is in the log"
    back = run_from_carmen(read_carmen(path))  # read as a log of a real robot: the first triple, said so
    assert back.metadata["truth_source"] == TRUTH_SOURCE and "truth_available" not in back.metadata
    np.testing.assert_array_equal(back.truth, r6(compose(record.odometry, MOUNT)))


def test_truth_at_every_frame_is_needed_for_truepos_lines():
    record = _record()
    record.truth[3] = np.nan
    with pytest.raises(ValueError, match="ground truth for 29 of 30 frames"):
        carmen_from_run(record, truth=True)
    assert len(carmen_from_run(record).truepos) == 0


def test_reading_without_truth_gives_nan(tmp_path):
    path = write_carmen(tmp_path / "run.clf", carmen_from_run(_record(), truth=True))
    back = read_carmen_run(path, truth=False)
    assert np.isnan(back.truth).all()
    assert back.metadata["truth_available"] is False and back.metadata["truth_source"] == TRUTH_SOURCE_NONE


# -- matching TRUEPOS lines to laser lines ------------------------------------------------------------

FLASER = "FLASER 3 1 2 3 0.5 0.5 0 0 0 0 {t} host {t}\n"
TRUEPOS = "TRUEPOS {x} 7 0.25 0 0 0 {t} host {t}\n"


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "log.clf"
    path.write_text(text)
    return path


def test_nearest_truepos_within_the_tolerance_and_the_first_of_equal_timestamps(tmp_path):
    near = TRUEPOS_TOLERANCE / 2
    text = (
        TRUEPOS.format(x=1, t=100.0)
        + TRUEPOS.format(x=2, t=100.0)  # the same timestamp again: the first is taken
        + FLASER.format(t=100.0)
        + FLASER.format(t=101.0)
        + TRUEPOS.format(x=3, t=101.0 + near)
        + TRUEPOS.format(x=4, t=102.0 - near)  # written late: ordered by timestamp
        + FLASER.format(t=102.0)
        + TRUEPOS.format(x=5, t=101.5)
    )
    log = read_carmen(_write(tmp_path, text))
    assert log.tolerated == {"truepos_reordered": 1}
    np.testing.assert_array_equal(truth_at_laser(log)[:, 0], [1, 3, 4])
    assert run_from_carmen(log).truth[:, 1].tolist() == [7, 7, 7]


def test_truepos_lines_that_do_not_cover_the_laser_lines_are_one_line_errors(tmp_path):
    text = (
        TRUEPOS.format(x=1, t=100.0)
        + FLASER.format(t=100.0)
        + FLASER.format(t=100.1)  # line 3: no TRUEPOS line within 1 ms
        + TRUEPOS.format(x=2, t=100.2)
        + FLASER.format(t=100.2)
    )
    path = _write(tmp_path, text)
    log = read_carmen(path)  # reading the log is fine: the laser lines and the TRUEPOS lines are there
    with pytest.raises(FormatError) as info:
        run_from_carmen(log)
    message = str(info.value)
    assert info.value.path == path and info.value.line == 3 and "\n" not in message
    assert message.startswith(f"{path}:3: the TRUEPOS lines do not cover the FLASER lines") and "--no-truth" in message
    assert np.isnan(read_carmen_run(path, truth=False).truth).all()  # and they can be ignored


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("TRUEPOS 1 2 3 4 5 6 100.0 host\n", "expected 10 fields 'TRUEPOS true_x"),
        ("TRUEPOS 1 2 3 4 5 6 100.0 host 1 2\n", "got 11"),
        ("TRUEPOS 1 two 3 4 5 6 100.0 host 1\n", "field 3 (true_y) is not a number: 'two'"),
        ("TRUEPOS 1 2 nan 4 5 6 100.0 host 1\n", "TRUEPOS field 4 (true_theta) is not finite"),
        ("TRUEPOS 1 2 3 4 5 6 inf host 1\n", "field 8 (ipc_timestamp) is not finite"),
        ("TRUEPOS 1 2 3 4 5 6 100.0 host 1e999\n", "field 10 (logger_timestamp) is not finite"),
    ],
)
def test_bad_truepos_lines_are_one_line_errors_naming_the_line(tmp_path, line, message):
    path = _write(tmp_path, FLASER.format(t=100.0) + line + FLASER.format(t=101.0))
    with pytest.raises(FormatError) as info:
        read_carmen(path)
    assert info.value.line == 2 and message in str(info.value) and str(path) in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.skipif(not MIT.is_file(), reason="shared data not present")
def test_a_real_log_without_truepos_reads_as_before():
    log = read_carmen(MIT)
    record = run_from_carmen(log)
    assert len(log.truepos) == 0 and record.metadata["truth_source"] == TRUTH_SOURCE
    assert "truth_available" not in record.metadata and "carmen_truepos_lines" not in record.metadata
    np.testing.assert_array_equal(record.truth, log.laser.pose)


# -- the CLI ------------------------------------------------------------------------------------------


def _invoke(*args):
    result = CliRunner().invoke(app, [str(a) for a in args])
    result.text = " ".join(result.output.split())  # rich wraps long lines
    return result


def test_export_writes_the_truth_only_when_asked(tmp_path):
    record = _record()
    run = write_run(tmp_path / "run", record)
    done = _invoke("export", run, "--to", "carmen", "--truth", "--out", tmp_path / "with.clf")
    assert done.exit_code == 0 and "TRUEPOS lines with the ground truth" in done.text, done.output
    assert _invoke("import", tmp_path / "with.clf", "--out", tmp_path / "back").exit_code == 0
    back = read_run(tmp_path / "back")
    np.testing.assert_array_equal(back.truth, r6(record.truth))
    np.testing.assert_array_equal(back.odometry, r6(record.odometry))

    done = _invoke("export", run, "--to", "carmen", "--carmen-kind", "FLASER", "--out", tmp_path / "n.clf")
    assert done.exit_code == 0 and "no ground truth" in done.text, done.output
    text = (tmp_path / "n.clf").read_text()
    assert not re.search(r"^TRUEPOS", text, re.MULTILINE)
    assert not (set(text.split()) & _truth_strings(record))
    imported = _invoke("import", tmp_path / "n.clf", "--out", tmp_path / "n", "--no-truth")
    assert imported.exit_code == 0 and "WITHOUT ground truth" in imported.text, imported.output
    assert np.isnan(read_run(tmp_path / "n").truth).all()


def test_no_truth_is_refused_for_tum(tmp_path):
    run = write_run(tmp_path / "run", _record(n=5))
    result = _invoke("export", run, "--to", "tum", "--truth", "--out", tmp_path / "t.tum")
    assert result.exit_code == 2 and "--truth applies to --to carmen, bag and bag2" in result.text


def test_import_of_uncovered_truepos_lines_is_one_line(tmp_path):
    path = _write(tmp_path, TRUEPOS.format(x=1, t=100.0) + FLASER.format(t=100.0) + FLASER.format(t=100.5))
    result = _invoke("import", path, "--out", tmp_path / "r")
    assert result.exit_code == 2 and f"{path}:3:" in result.text and "Traceback" not in result.output
    assert not (tmp_path / "r").exists()
