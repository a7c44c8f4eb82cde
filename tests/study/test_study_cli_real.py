"""A real tiny study from the command line: 2 cells (laser range 4 m and 1.5 m) on one tiny room, 5 runs
each with the odometry baseline, then its status and its report."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app

pytestmark = pytest.mark.slow

runner = CliRunner()


def test_study_run_status_report_and_resume(tmp_path, rooms, write_study):
    import yaml

    base = {
        "worlds": rooms[1:],
        "seed": 2,
        "slam": {"algorithm": "odometry", "preset": None},
        "termination": {"small_period": 30.0, "max_time": 120.0},
        "runs": {"initial": 5, "max_runs": 5},
    }
    text = yaml.safe_dump({"campaign": base, "axes": {"sim.laser.max_range": [4.0, 1.5]}})
    config = write_study(tmp_path / "study.yaml", rooms, text)
    out = tmp_path / "study"
    result = runner.invoke(app, ["study", "run", config, "--out", str(out), "--workers", "2"])
    assert result.exit_code == 0, result.output
    assert "2 cells (max_range=4.0, max_range=1.5) x 1 worlds" in result.output
    assert "max_range=1.5: room_b: " in result.output and "10 runs done (0 failed)" in result.output
    status = runner.invoke(app, ["study", "status", str(out)])
    assert status.exit_code == 0 and "10 runs done; finished" in status.output
    again = runner.invoke(app, ["study", "run", "--out", str(out), "--workers", "1"])
    assert again.exit_code == 0 and "complete, every cell is finished" in again.output
    report = runner.invoke(app, ["study", "report", str(out), "--no-pdf"])
    assert report.exit_code == 0, report.output
    assert "paired comparisons significant after correction" in report.output
    assert (out / "report" / "index.html").is_file() and (out / "report" / "figures" / "error-room_b.png").is_file()
    # each cell is a normal campaign: the campaign report works on it
    cell = runner.invoke(app, ["report", str(out / "cells" / "max_range=1.5"), "--no-pdf"])
    assert cell.exit_code == 0, cell.output
