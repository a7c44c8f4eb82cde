"""``slamtrials calibrate`` end to end on a simulated CARMEN log, and its one-line refusals."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.campaign.profilefile import read_profile
from slamtrials.cli.calibrate import profile_name
from slamtrials.cli.main import app
from slamtrials.io.carmen import carmen_from_run, write_carmen
from slamtrials.sim.config import LaserConfig, OdometryConfig, SimConfig
from slamtrials.sim.tour import tour_waypoints
from slamtrials.sim.waypoints import simulate_waypoints
from slamtrials.worlds import load_world

runner = CliRunner()


@pytest.fixture(scope="module")
def record():
    world = load_world("office_small_01")
    config = SimConfig(
        profile="paper",  # the errors below, nothing else
        laser=LaserConfig(range_noise_std=0.02, short_rate=0.05, dropout_rate=0.02),
        odometry=OdometryConfig(
            bias_linear=0.02, bias_angular=-0.05, noise_linear_per_m=0.03, noise_angular_per_rad=0.05
        ),
    )
    rec = simulate_waypoints(world, tour_waypoints(world, num_goals=4), config, seed=11, max_time=400)
    assert rec.metadata["outcome"] == "completed"
    return rec


def _one_line_error(result, *words):
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.strip().splitlines() if line]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    for word in words:
        assert word in lines[0], lines[0]


def test_calibrate_writes_a_valid_profile_and_a_page_of_figures(record, tmp_path):
    log = write_carmen(tmp_path / "office.clf", carmen_from_run(record))
    out = tmp_path / "profiles" / "office.yaml"
    out.parent.mkdir()
    args = ["calibrate", str(log), "--out", str(out), "--set", "particles=5", "--bootstrap", "10"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    profile = read_profile(out)
    assert profile.name == "office"
    assert "office.clf" in profile.description and "gmapping" in profile.description
    assert set(profile.laser) == {
        "range_noise_std",
        "range_noise_per_m",
        "short_rate",
        "short_run_beams",
        "short_position_power",
        "short_range_scale",
        "short_range_shape",
        "short_lifetime",
        "short_fleeting_share",
        "dropout_rate",
        "dropout_per_m",
        "dropout_grazing",
        "edge_chance",
        "edge_reach",
    }
    assert (
        "short_lifetime" in result.output and "edge_chance" in result.output and "short_position_power" in result.output
    )
    low, high = profile.odometry["bias_angular_range"]
    assert low == -high and high > 0.0
    # against GMapping's map the noise is the simulated noise or more, never nothing
    assert profile.laser["range_noise_std"] + profile.laser["range_noise_per_m"] > 0.01
    assert (tmp_path / "profiles" / "office.png").stat().st_size > 10_000
    assert "range_noise_std" in result.output and "+-" in result.output
    # and a simulation config takes the written file's profile
    SimConfig(profile=profile)
    again = runner.invoke(app, args)  # an existing profile is not replaced without --overwrite
    _one_line_error(again, "already exists")


def test_a_too_short_log_is_one_line_exit_2_and_nothing_written(record, tmp_path):
    n = 120
    short = replace(
        record,
        t=record.t[:n],
        scans=record.scans[:n],
        odometry=record.odometry[:n],
        truth=record.truth[:n],
        stalled=record.stalled[:n],
    )
    log = write_carmen(tmp_path / "short.clf", carmen_from_run(short))
    out = tmp_path / "short.yaml"
    _one_line_error(runner.invoke(app, ["calibrate", str(log), "--out", str(out)]), "short.clf", "at least 200")
    assert not out.exists() and not (tmp_path / "short.png").exists()


def test_a_log_without_odometry_is_one_line_exit_2_and_nothing_written(record, tmp_path):
    still = replace(record, odometry=np.zeros_like(record.odometry))
    log = write_carmen(tmp_path / "still.clf", carmen_from_run(still))
    out = tmp_path / "still.yaml"
    _one_line_error(runner.invoke(app, ["calibrate", str(log), "--out", str(out)]), "no odometry")
    assert list(tmp_path.iterdir()) == [log]


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--out", "x.txt"], ["YAML"]),
        (["--out", "x.yaml", "--figures", "x.pdf"], ["PNG"]),
        (["--out", "x.yaml", "--set", "particles=-3"], ["particles"]),
        (["--out", "x.yaml", "--bootstrap", "1"], ["--bootstrap"]),
        (["--out", "x.yaml", "--algorithm", "nope"], ["nope"]),
    ],
)
def test_bad_options_are_one_line_exit_2(tmp_path, extra, words):
    log = tmp_path / "missing.clf"
    log.write_text("")
    _one_line_error(runner.invoke(app, ["calibrate", str(log), *extra]), *words)
    assert not (tmp_path / "x.yaml").exists()


def test_a_missing_log_is_one_line_exit_2(tmp_path):
    _one_line_error(
        runner.invoke(app, ["calibrate", str(tmp_path / "none.clf"), "--out", str(tmp_path / "p.yaml")]), "none.clf"
    )


@pytest.mark.parametrize(
    ("name", "expected"),
    [("mit-csail.clf", "mit-csail"), ("fr079.clf.bz2", "fr079"), ("intel lab.log.gz", "intel_lab"), ("run", "run")],
)
def test_the_profile_is_named_after_the_log(name, expected, tmp_path):
    assert profile_name(tmp_path / name) == expected
