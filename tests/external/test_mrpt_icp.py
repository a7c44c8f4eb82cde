"""A real external SLAM program through ``slam --program``: MRPT's icp-slam (Debian's mrpt-apps) with the
adapter in docs/examples/mrpt, on a simulated run and on the MIT CSAIL log of the Freiburg benchmark."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "docs" / "examples" / "mrpt" / "icp_slam.sh"
DATA = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared")) / "data" / "mit-csail"
COMMAND = f"sh {SCRIPT} {{input}} {{output}} {{workdir}}"

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(shutil.which("icp-slam") is None, reason="MRPT's icp-slam is not installed (mrpt-apps)"),
]


def _invoke(args: list[str]):
    result = CliRunner().invoke(app, args, env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    return result.output


def _eps(output: str) -> tuple[float, float]:
    line = next(line for line in output.splitlines() if line.startswith("error: eps_t"))
    words = line.split()
    return float(words[2]), float(words[5])


def test_icp_slam_on_a_simulated_run_beats_the_odometry(tmp_path):
    run = tmp_path / "run"
    _invoke(["simulate", "--world", "office_small_01", "--tour", "--seed", "1", "--out", str(run)])
    icp = _eps(_invoke(["slam", "--program", COMMAND, "-i", str(run), "-o", str(tmp_path / "icp")]))
    odometry = _eps(_invoke(["slam", "-a", "odometry", "-i", str(run), "-o", str(tmp_path / "odo")]))
    # a scan matcher corrects most of the drift of the realistic odometry (the same relation set)
    assert icp[0] < 0.5 * odometry[0] and icp[1] < 0.5 * odometry[1]
    summary = json.loads((tmp_path / "icp" / "slam.json").read_text())
    assert summary["algorithm"] == "program:icp_slam.sh" and summary["frames_at_a_pose"] == summary["frames"]


@pytest.mark.skipif(not (DATA / "mit-csail.clf").is_file(), reason=f"no MIT CSAIL data in {DATA}")
def test_icp_slam_on_the_mit_csail_log_is_near_gmapping(tmp_path):
    out = tmp_path / "icp"
    _invoke(["slam", "--program", COMMAND, "-i", str(DATA / "mit-csail.clf"), "-o", str(out)])
    report = _invoke(
        ["evaluate", "--estimate", str(out / "trajectory.tum"), "--relations", str(DATA / "mit-csail.relations")]
    )
    rows = report.splitlines()
    eps_t = float(rows[rows.index(next(r for r in rows if r.startswith("Translational"))) + 2].split(",")[0])
    # the raw odometry is 1.68 m on these relations and GMapping about 0.05 m
    assert eps_t < 0.15
