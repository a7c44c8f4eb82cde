"""``slamtrials trial``: a whole trial through the CLI on a small floor plan, and its one-line errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.io.runfolder import read_run

runner = CliRunner()


def _plan(path):
    """A 6 m x 4 m room as a PNG at 5 cm per pixel (black walls, white floor)."""
    pixels = np.full((84, 124), 255, dtype=np.uint8)
    pixels[:2, :] = pixels[-2:, :] = pixels[:, :2] = pixels[:, -2:] = 0
    pixels[30:54, 60:64] = 0  # a pillar
    Image.fromarray(pixels).save(path)
    return path


@pytest.mark.slow  # a whole trial through the CLI; tests/cli/test_cli_profile.py keeps a short one in the fast lane
def test_trial_writes_a_complete_run_folder(tmp_path):
    plan = _plan(tmp_path / "room.png")
    config = tmp_path / "trial.yaml"
    config.write_text("termination:\n  small_period: 60\n  max_time: 600\n")
    out = tmp_path / "run"
    result = runner.invoke(
        app,
        [
            "trial",
            "--world",
            str(plan),
            "--resolution",
            "0.05",
            "--seed",
            "3",
            "--config",
            str(config),
            "--out",
            str(out),
        ],
    )
    assert result.exit_code == 0, result.output
    for name in ("frames.npz", "run.json", "estimate.tum", "map.yaml", "map.pgm", "map.png", "run.png"):
        assert (out / name).is_file(), name
    doc = json.loads((out / "run.json").read_text())
    assert doc["seed"] == 3 and doc["config"]["termination"]["max_time"] == 600
    assert doc["trial"]["termination_reason"] in ("map_converged", "no_frontiers")
    assert doc["trial"]["mapped_fraction"] > 0.9
    assert f"{doc['trial']['termination_reason']} after" in result.output
    assert f"exploration: 90 % after {doc['exploration']['time_to_90_s']:.0f} s" in result.output
    record = read_run(out)
    assert record.estimate is not None and record.estimate.shape == record.truth.shape
    # a stored run is not replaced without --overwrite, and nothing in it changes
    before = (out / "frames.npz").read_bytes()
    again = runner.invoke(app, ["trial", "--world", str(plan), "--resolution", "0.05", "--out", str(out)])
    assert again.exit_code == 2 and "already holds a run" in again.output
    assert (out / "frames.npz").read_bytes() == before


def test_bad_config_is_one_line_and_exit_2(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("slam:\n  params:\n    particles: 0\n")
    result = runner.invoke(
        app, ["trial", "--world", "office_small_01", "--config", str(bad), "--out", str(tmp_path / "o")]
    )
    assert result.exit_code == 2
    assert "bad.yaml" in result.output and "particles" in result.output
    assert len(result.output.strip().splitlines()) == 1
    unknown = tmp_path / "unknown.yaml"
    unknown.write_text("explore:\n  warp_speed: 9\n")
    result = runner.invoke(
        app, ["trial", "--world", "office_small_01", "--config", str(unknown), "--out", str(tmp_path / "o")]
    )
    assert result.exit_code == 2 and "warp_speed" in result.output
    result = runner.invoke(app, ["trial", "--world", "no_such_world", "--out", str(tmp_path / "o")])
    assert result.exit_code == 2 and "no_such_world" in result.output
    assert not (tmp_path / "o").exists()
