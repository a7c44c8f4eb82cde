"""Run folders: exact round trip, atomic completion marker, clear errors on damaged folders."""

from __future__ import annotations

import json

import numpy as np
import pytest

from slamtrials.errors import FormatError
from slamtrials.io.runfolder import RUN_FORMAT, RunFolder, read_run, write_run
from slamtrials.record import LaserGeometry, RunRecord

FRAMES_FILE, RUN_FILE = RunFolder.FRAMES, RunFolder.RUN

LASER = LaserGeometry.from_dict(
    {"angle_min": -2.356, "angle_increment": 0.0087, "range_min": 0.0, "range_max": 30.0, "mount": [0.1, 0.0, 0.0]}
)


def _record(n: int = 20, beams: int = 11, seed: int = 0) -> RunRecord:
    rng = np.random.default_rng(seed)
    return RunRecord(
        t=np.arange(n) * 0.1,
        scans=rng.uniform(0, 30, (n, beams)).astype(np.float32),
        odometry=rng.normal(size=(n, 3)),
        truth=rng.normal(size=(n, 3)),
        stalled=rng.random(n) < 0.2,
        laser=LASER,
        metadata={"seed": seed, "odometry_bias": {"linear": 0.004, "angular": -0.01}, "outcome": "completed"},
    )


def test_round_trip_is_exact(tmp_path):
    record = _record()
    write_run(tmp_path / "run", record)
    back = read_run(tmp_path / "run")
    for name in ("t", "scans", "odometry", "truth", "stalled"):
        np.testing.assert_array_equal(getattr(back, name), getattr(record, name))
        assert getattr(back, name).dtype == getattr(record, name).dtype
    assert back.laser == LASER
    assert back.metadata["odometry_bias"] == record.metadata["odometry_bias"]
    assert back.metadata["versions"]["slamtrials"]


def test_folder_without_run_json_is_not_a_run(tmp_path):
    write_run(tmp_path, _record())
    (tmp_path / RUN_FILE).unlink()
    with pytest.raises(FormatError, match="run.json"):
        read_run(tmp_path)


def test_truncated_frames_names_the_file(tmp_path):
    write_run(tmp_path, _record())
    data = (tmp_path / FRAMES_FILE).read_bytes()
    (tmp_path / FRAMES_FILE).write_bytes(data[: len(data) // 2])
    with pytest.raises(FormatError, match="frames.npz"):
        read_run(tmp_path)


def test_missing_array_is_named(tmp_path):
    write_run(tmp_path, _record())
    with np.load(tmp_path / FRAMES_FILE) as npz:
        arrays = {k: npz[k] for k in npz.files if k != "truth"}
    np.savez(tmp_path / FRAMES_FILE, **arrays)
    with pytest.raises(FormatError, match="'truth' is missing"):
        read_run(tmp_path)


def test_disagreeing_lengths_and_time_order_are_rejected(tmp_path):
    write_run(tmp_path, _record())
    with np.load(tmp_path / FRAMES_FILE) as npz:
        arrays = {k: npz[k] for k in npz.files}
    arrays["t"] = arrays["t"][::-1].copy()
    np.savez(tmp_path / FRAMES_FILE, **arrays)
    with pytest.raises(FormatError, match="strictly increasing"):
        read_run(tmp_path)
    arrays["t"] = arrays["t"][:-1][::-1].copy()
    np.savez(tmp_path / FRAMES_FILE, **arrays)
    with pytest.raises(FormatError, match="disagree"):
        read_run(tmp_path)


def test_garbled_run_json_names_the_line(tmp_path):
    write_run(tmp_path, _record())
    (tmp_path / RUN_FILE).write_text('{\n  "format": "slamtrials-run/1",\n  oops\n}\n')
    with pytest.raises(FormatError, match=r"run.json:3"):
        read_run(tmp_path)


def test_wrong_format_tag_is_rejected(tmp_path):
    write_run(tmp_path, _record())
    doc = json.loads((tmp_path / RUN_FILE).read_text())
    doc["format"] = "something-else"
    (tmp_path / RUN_FILE).write_text(json.dumps(doc))
    with pytest.raises(FormatError, match="format"):
        read_run(tmp_path)


def test_rewrite_leaves_no_temporary_files(tmp_path):
    write_run(tmp_path, _record(seed=1))
    write_run(tmp_path, _record(seed=2))
    assert sorted(p.name for p in tmp_path.iterdir()) == [FRAMES_FILE, RUN_FILE]
    assert read_run(tmp_path).metadata["seed"] == 2


def test_flipped_bytes_inside_frames_are_a_format_error(tmp_path):
    write_run(tmp_path, _record(n=200, beams=50))
    data = bytearray((tmp_path / FRAMES_FILE).read_bytes())
    for offset in range(200, len(data) - 200, 997):  # corrupt compressed payloads, keep the zip directory
        data[offset] ^= 0xFF
    (tmp_path / FRAMES_FILE).write_bytes(bytes(data))
    with pytest.raises(FormatError, match="frames.npz"):
        read_run(tmp_path)


def test_a_run_folder_of_format_version_1_still_reads(tmp_path):
    record = _record()
    write_run(tmp_path, record)
    doc = json.loads((tmp_path / RUN_FILE).read_text())
    assert doc["format"] == RUN_FORMAT == "slamtrials-run/2"
    doc["format"] = "slamtrials-run/1"
    (tmp_path / RUN_FILE).write_text(json.dumps(doc))
    back = read_run(tmp_path)
    assert back.laser == record.laser and np.array_equal(back.scans, record.scans)
    assert RunFolder(tmp_path).is_complete() and RunFolder(tmp_path).frames == tmp_path / "frames.npz"
