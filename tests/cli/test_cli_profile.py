"""One profile rule for every command: the default profile, the ``profile:`` line every simulating command
prints, the one warning line of a config that overrides its profile, ``config dump``, and bad profiles
(unknown keys, negative rates) as one line, exit 2 and nothing written, for a campaign config, the
``--config`` of ``trial`` and ``simulate``, and profile YAML files."""

from __future__ import annotations

import functools
import json
import logging

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from slamtrials.campaign import CampaignConfig
from slamtrials.cli.main import app
from slamtrials.sim.profiles import BUNDLED_PROFILES, DEFAULT_PROFILE
from slamtrials.worlds import World
from slamtrials.worlds.formats.rosmap_save import save_rosmap

runner = CliRunner()

#: Bad profiles as they appear in a config's sim section, and what the one error line names.
BAD_SIM = [
    ("profile: {name: x, laser: {dropout_chance: 0.1}}\n", "unknown laser error field 'dropout_chance'"),
    ("profile: {name: x, laser: {dropout_rate: -0.1}}\n", "dropout_rate"),
    ("profile: {name: x, odometry: {noise_linear_per_m: -0.2}}\n", "noise_linear_per_m"),
    ("profile: {name: x, odometry: {slip_rate: 0.1}}\n", "unknown odometry error field 'slip_rate'"),
    ("profile: realstic\n", "unknown error profile 'realstic'"),
    ("laser: {short_rate: -0.5}\n", "short_rate"),
]
#: Bad profile YAML files, and what the one error line names.
BAD_FILES = [
    ("name: x\nlaser:\n  dropout_chance: 0.1\n", "unknown laser error field 'dropout_chance'"),
    ("name: x\nlaser:\n  range_noise_std: -0.01\n", "range_noise_std"),
    ("name: x\nodometry:\n  noise_angular_per_rad: -1\n", "noise_angular_per_rad"),
    ("name: x\nlazer:\n  dropout_rate: 0.1\n", "lazer"),
]


def _indent(text: str, pad: str = "  ") -> str:
    return "".join(pad + line + "\n" for line in text.splitlines())


@pytest.fixture(scope="module")
def corridor(tmp_path_factory):
    occ = np.ones((60, 200), bool)
    occ[10:50, 10:190] = False  # a 9 m x 2 m room
    folder = tmp_path_factory.mktemp("corridor")
    world = World(occ, 0.05, name="corridor", start=np.array([1.0, 1.5, 0.0]))
    path = save_rosmap(world, folder / "corridor.yaml")
    (folder / "w.yaml").write_text("waypoints:\n  - [2.5, 1.5]\n")
    return path, folder / "w.yaml"


def _one_line_and_nothing_written(result, expected, out):
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and expected in lines[0], result.output
    assert not out.exists()


# --------------------------------------------------------------------------- the default and the line


def test_simulate_follows_the_default_profile_and_says_so(corridor, tmp_path):
    world, waypoints = corridor
    out = tmp_path / "run"
    result = runner.invoke(app, ["simulate", "-w", str(world), "-p", str(waypoints), "-s", "1", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines() == [f"profile: {DEFAULT_PROFILE}"]
    doc = json.loads((out / "run.json").read_text())
    assert doc["profile"] == {"name": DEFAULT_PROFILE, "label": DEFAULT_PROFILE, "overrides": {}}
    assert doc["sim_config"]["profile"] == DEFAULT_PROFILE == "realistic"
    assert doc["sim_config"]["laser"]["dropout_rate"] == BUNDLED_PROFILES["realistic"].laser["dropout_rate"]


def test_simulate_config_that_overrides_its_profile_warns_once_and_the_line_names_the_keys(corridor, tmp_path, caplog):
    world, waypoints = corridor
    config = tmp_path / "sim.yaml"
    config.write_text("profile: paper\nlaser:\n  short_rate: 0.1\n  dropout_rate: 0.0\n")  # dropout 0: paper's own
    out = tmp_path / "run"
    with caplog.at_level(logging.WARNING):
        result = runner.invoke(
            app, ["simulate", "-w", str(world), "-p", str(waypoints), "-c", str(config), "-o", str(out)]
        )
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines() == ["profile: paper + 1 override (laser.short_rate)"]
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert warnings == [f"{config}: keys that override profile paper: laser.short_rate"]
    doc = json.loads((out / "run.json").read_text())
    assert doc["profile"] == {"name": "paper", "label": "paper + 1 override", "overrides": {"laser.short_rate": 0.1}}


def test_trial_follows_the_default_profile_and_says_so(tmp_path):
    config = tmp_path / "t.yaml"
    config.write_text("termination:\n  max_time: 1.0\n")
    out = tmp_path / "run"
    result = runner.invoke(app, ["trial", "-w", "office_small_01", "-c", str(config), "-o", str(out), "-s", "2"])
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines()[0] == f"profile: {DEFAULT_PROFILE}"
    doc = json.loads((out / "run.json").read_text())
    assert doc["profile"]["label"] == DEFAULT_PROFILE and doc["config"]["sim"]["profile"] == DEFAULT_PROFILE


def test_trial_with_profile_paper_and_an_override_says_so(tmp_path, caplog):
    config = tmp_path / "t.yaml"
    config.write_text(
        "sim:\n  profile: paper\n  odometry:\n    bias_linear_range: [-0.01, 0.01]\ntermination:\n  max_time: 1.0\n"
    )
    out = tmp_path / "run"
    with caplog.at_level(logging.WARNING):
        result = runner.invoke(app, ["trial", "-w", "office_small_01", "-c", str(config), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines()[0] == "profile: paper + 1 override (odometry.bias_linear_range)"
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert warnings == [f"{config}: keys that override profile paper: sim.odometry.bias_linear_range"]


def test_campaign_run_prints_its_profile_when_the_runs_start(tmp_path, monkeypatch):
    import slamtrials.campaign
    from slamtrials.campaign import run_campaign
    from slamtrials.campaign.testing import FakeTrial

    monkeypatch.setattr(
        slamtrials.campaign, "run_campaign", functools.partial(run_campaign, trial_fn=FakeTrial(std_t=0.01))
    )
    config = tmp_path / "c.yaml"
    config.write_text(
        "worlds: [office_small_01]\nruns: {initial: 5, max_runs: 5}\nsim:\n  laser:\n    dropout_rate: 0.0\n"
    )
    from distributed import LocalCluster

    # an in-process cluster: a worker process would take seconds to start
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster:
        result = runner.invoke(
            app,
            ["campaign", "run", str(config), "--out", str(tmp_path / "c"), "--scheduler", cluster.scheduler_address],
        )
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines()[0] == f"profile: {DEFAULT_PROFILE} + 1 override (laser.dropout_rate)"


def test_config_dump_names_the_profile_and_no_value_it_sets():
    result = runner.invoke(app, ["config", "dump"])
    assert result.exit_code == 0, result.output
    sim = yaml.safe_load(result.stdout)["sim"]
    assert sim["profile"] == DEFAULT_PROFILE
    assert not set(sim["laser"]) & set(BUNDLED_PROFILES[DEFAULT_PROFILE].laser_values())
    assert not set(sim["odometry"]) & set(BUNDLED_PROFILES[DEFAULT_PROFILE].odometry_values())
    paper = yaml.safe_load(result.stdout.replace(f"profile: {DEFAULT_PROFILE}", "profile: paper"))
    assert not CampaignConfig.from_dict(paper).sim.laser.has_errors  # the name sets every value


# --------------------------------------------------------------------------- bad profiles


@pytest.mark.parametrize(("sim", "expected"), BAD_SIM)
def test_campaign_config_with_a_bad_profile(tmp_path, sim, expected):
    config = tmp_path / "c.yaml"
    config.write_text("worlds: [office_small_01]\nsim:\n" + _indent(sim))
    out = tmp_path / "out"
    result = runner.invoke(app, ["campaign", "run", str(config), "--out", str(out)])
    _one_line_and_nothing_written(result, expected, out)
    assert "c.yaml" in result.output


@pytest.mark.parametrize(("sim", "expected"), BAD_SIM)
def test_trial_config_with_a_bad_profile(tmp_path, sim, expected):
    config = tmp_path / "t.yaml"
    config.write_text("sim:\n" + _indent(sim))
    out = tmp_path / "out"
    result = runner.invoke(app, ["trial", "-w", "office_small_01", "-c", str(config), "-o", str(out)])
    _one_line_and_nothing_written(result, expected, out)
    assert "t.yaml" in result.output


@pytest.mark.parametrize(("sim", "expected"), BAD_SIM)
def test_simulate_config_with_a_bad_profile(corridor, tmp_path, sim, expected):
    world, waypoints = corridor
    config = tmp_path / "s.yaml"
    config.write_text(sim)
    out = tmp_path / "out"
    result = runner.invoke(app, ["simulate", "-w", str(world), "-p", str(waypoints), "-c", str(config), "-o", str(out)])
    _one_line_and_nothing_written(result, expected, out)
    assert "s.yaml" in result.output


@pytest.mark.parametrize(("content", "expected"), BAD_FILES)
@pytest.mark.parametrize("command", ["campaign", "trial", "simulate"])
def test_a_bad_profile_file_named_by_a_config(corridor, tmp_path, command, content, expected):
    (tmp_path / "bad.yaml").write_text(content)
    out = tmp_path / "out"
    if command == "simulate":
        world, waypoints = corridor
        (tmp_path / "s.yaml").write_text("profile: bad.yaml\n")
        args = ["simulate", "-w", str(world), "-p", str(waypoints), "-c", str(tmp_path / "s.yaml"), "-o", str(out)]
    elif command == "trial":
        (tmp_path / "t.yaml").write_text("sim:\n  profile: bad.yaml\n")
        args = ["trial", "-w", "office_small_01", "-c", str(tmp_path / "t.yaml"), "-o", str(out)]
    else:
        (tmp_path / "c.yaml").write_text("worlds: [office_small_01]\nsim:\n  profile: bad.yaml\n")
        args = ["campaign", "run", str(tmp_path / "c.yaml"), "--out", str(out)]
    result = runner.invoke(app, args)
    _one_line_and_nothing_written(result, expected, out)
    assert "bad.yaml" in result.output
