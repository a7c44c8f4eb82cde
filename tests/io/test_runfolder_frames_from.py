"""A replayed run refers to its source run's frames: it reads back whole, stays readable when both
campaigns move together, and a source that is gone or changed is one clear line."""

from __future__ import annotations

import dataclasses
import shutil

import numpy as np
import pytest

from slamtrials.errors import FormatError
from slamtrials.io.runfolder import FRAMES_FROM, RunFolder, read_run, write_run
from slamtrials.record import LaserGeometry, RunRecord

LASER = LaserGeometry.from_dict({"angle_min": -1.5, "angle_increment": 0.01, "range_min": 0.0, "range_max": 30.0})


def _record(n: int = 40) -> RunRecord:
    rng = np.random.default_rng(4)
    return RunRecord(
        t=np.arange(n) * 0.1,
        scans=rng.uniform(0, 30, (n, 301)).astype(np.float32),
        odometry=rng.normal(size=(n, 3)),
        truth=rng.normal(size=(n, 3)),
        stalled=np.zeros(n, bool),
        laser=LASER,
        metadata={"seed": 4},
    )


def _replayed(tmp_path):
    source = write_run(tmp_path / "a" / "runs" / "w" / "000", _record())
    record = dataclasses.replace(read_run(source), estimate=np.ones((40, 3)), online=np.full((40, 3), 2.0))
    replay = write_run(tmp_path / "b" / "runs" / "w" / "000", record, frames_from=source)
    return source, replay, record


def test_a_replayed_run_reads_back_whole_and_holds_no_copy_of_the_frames(tmp_path):
    source, replay, record = _replayed(tmp_path)
    back = read_run(replay)
    for name in ("t", "scans", "odometry", "truth", "stalled", "estimate", "online"):
        np.testing.assert_array_equal(getattr(back, name), getattr(record, name))
    assert FRAMES_FROM not in back.metadata
    assert RunFolder(replay).frames.stat().st_size < RunFolder(source).frames.stat().st_size / 5
    # written again elsewhere (an export, a copy), it holds its frames itself
    copy = write_run(tmp_path / "copy", back)
    np.testing.assert_array_equal(read_run(copy).scans, record.scans)


def test_both_campaigns_moved_together_stay_readable(tmp_path):
    _replayed(tmp_path)
    shutil.move(tmp_path / "a", tmp_path / "moved" / "a")
    shutil.move(tmp_path / "b", tmp_path / "moved" / "b")
    back = read_run(tmp_path / "moved" / "b" / "runs" / "w" / "000")
    assert back.scans.shape == (40, 301)


def test_a_source_that_is_gone_is_one_line(tmp_path):
    source, replay, _ = _replayed(tmp_path)
    shutil.rmtree(tmp_path / "a")
    with pytest.raises(FormatError, match="not there any more") as info:
        read_run(replay)
    assert "\n" not in str(info.value) and str(source) in str(info.value)


def test_a_source_that_changed_is_refused(tmp_path):
    source, replay, _ = _replayed(tmp_path)
    other = dataclasses.replace(_record(), t=np.arange(40) * 0.2)
    write_run(source, other)
    with pytest.raises(FormatError, match="the source changed"):
        read_run(replay)
