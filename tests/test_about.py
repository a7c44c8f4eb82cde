"""The source revision recorded for provenance."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import slamtrials
from slamtrials.__about__ import source_revision
from slamtrials.io.runfolder import write_run
from slamtrials.record import LaserGeometry, RunRecord


def test_source_revision_names_the_checkout_the_package_came_from():
    package = Path(slamtrials.__file__).resolve().parent
    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    head = subprocess.run(
        ["git", "-C", str(package), "rev-parse", "--short=12", "HEAD"], capture_output=True, text=True
    )
    revision = source_revision()
    if head.returncode != 0:  # installed outside a checkout
        assert revision is None
        return
    assert revision is not None and re.fullmatch(r"[0-9a-f]{12}(\+dirty)?", revision)
    assert revision.split("+")[0] == head.stdout.strip()


def test_run_folders_carry_it(tmp_path):

    t = np.arange(3) * 0.1
    poses = np.zeros((3, 3))
    record = RunRecord(
        t=t,
        scans=np.ones((3, 4), dtype=np.float32),
        odometry=poses,
        truth=poses,
        stalled=np.zeros(3, dtype=bool),
        laser=LaserGeometry.from_dict({"angle_min": -1.0, "angle_increment": 0.5, "range_min": 0.0, "range_max": 10.0}),
    )
    folder = write_run(tmp_path / "run", record)
    versions = json.loads((folder / "run.json").read_text())["versions"]
    assert versions["slamtrials"] == slamtrials.__version__
    assert versions.get("source") == source_revision()
