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
        # random walks per metre and per radian: the values before issue 32 (0.03 m/m and 0.05 rad/rad per
        # 0.1 s step) carried over to this tour's steps of about 0.05 m and 0.03 rad
        odometry=OdometryConfig(
            bias_linear=0.02, bias_angular=-0.05, noise_linear_per_m=0.007, noise_angular_per_rad=0.009
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


@pytest.mark.slow
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
    # without relations the printout says the odometry was fitted against the SLAM path
    assert "odometry against the SLAM path" in result.output and "give --relations" in result.output
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
    _one_line_error(
        runner.invoke(app, ["calibrate", str(log), "--out", str(out)]), "short.clf", "too short", "at least 200"
    )
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


def _relations_file(record, path, shift: float = 0.0):
    """Relations of the simulated tour as the Freiburg benchmark gives them: chained ones every two frames
    and a few long ones, from the true path (stamps moved by ``shift`` seconds)."""
    from slamtrials.io.relations import write_relations
    from slamtrials.metric.sampling import relations_between
    from slamtrials.record import Relations, Trajectory

    n = len(record)
    first = np.concatenate([np.arange(0, n - 2, 2), np.arange(10, n - 400, 300)])
    second = np.concatenate(
        [np.arange(2, n, 2)[: first.size - len(np.arange(10, n - 400, 300))], np.arange(10, n - 400, 300) + 350]
    )
    rel = relations_between(Trajectory(record.t, record.truth), first, second)
    return write_relations(path, Relations(t1=rel.t1 + shift, t2=rel.t2 + shift, delta=rel.delta))


@pytest.mark.slow
def test_calibrate_fits_the_odometry_against_the_logs_relations_and_says_so(record, tmp_path):
    log = write_carmen(tmp_path / "office.clf", carmen_from_run(record))
    relations = _relations_file(record, tmp_path / "office.relations")
    out = tmp_path / "office.yaml"
    args = ["calibrate", str(log), "--out", str(out), "--set", "particles=5", "--bootstrap", "10"]
    result = runner.invoke(app, [*args, "--relations", str(relations)])
    assert result.exit_code == 0, result.output
    assert "odometry against benchmark relations:" in result.output
    assert "used in 1 chains" in result.output and "long ones not used" in result.output
    assert "excluded: no relations where the odometry moves against the reference" in result.output
    assert "benchmark relations of office.relations" in read_profile(out).description
    # the same without relations: test_calibrate_writes_a_valid_profile_and_a_page_of_figures


def test_relations_of_another_log_are_one_line_exit_2_and_nothing_written(record, tmp_path):
    log = write_carmen(tmp_path / "office.clf", carmen_from_run(record))
    relations = _relations_file(record, tmp_path / "other.relations", shift=1e5)
    out = tmp_path / "office.yaml"
    result = runner.invoke(app, ["calibrate", str(log), "--out", str(out), "--relations", str(relations)])
    _one_line_error(result, "other.relations", "outside the log's span", "not this log's")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["office.clf", "other.relations"]


def test_a_too_irregular_log_is_one_line_exit_2_saying_which(record, tmp_path):
    t = record.t.copy()
    t[1::3] = t[0::3][: t[1::3].size] + 0.004  # two of three frames 4 and 8 ms after the one before
    t[2::3] = t[0::3][: t[2::3].size] + 0.008
    log = write_carmen(tmp_path / "dup.clf", carmen_from_run(replace(record, t=t)))
    out = tmp_path / "dup.yaml"
    _one_line_error(runner.invoke(app, ["calibrate", str(log), "--out", str(out)]), "dup.clf", "too irregular")
    assert not out.exists()
