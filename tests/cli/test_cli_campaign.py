"""``slamtrials campaign`` and ``slamtrials config``: dump, one-line errors, status, a small real run."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from slamtrials.campaign import CampaignConfig
from slamtrials.cli import campaign as campaign_cli
from slamtrials.cli import config as config_cli
from slamtrials.cli.main import make_app

runner = CliRunner()


def cli_app():
    """The root app with the campaign commands (as cli/main.py registers them)."""
    from slamtrials.cli.main import app

    names = {group.name for group in app.registered_groups}
    if "campaign" in names and "config" in names:
        return app
    test_app = make_app()
    campaign_cli.register(test_app)
    config_cli.register(test_app)
    return test_app


def write_room(folder, name="room"):
    """A 4 m x 3 m room as a map_server map."""
    from slamtrials.worlds import World
    from slamtrials.worlds.formats.rosmap_save import save_rosmap

    occupied = np.zeros((66, 86), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    folder.mkdir(parents=True, exist_ok=True)
    return str(save_rosmap(World(occupied, 0.05, name=name, start=np.array([1.0, 1.5, 0.0])), folder / f"{name}.yaml"))


def write_config(path, worlds, **changes):
    data = {
        "worlds": worlds,
        "slam": {"algorithm": "odometry", "preset": None},
        "termination": {"small_period": 60.0, "max_time": 300.0},
        "runs": {"initial": 5, "max_runs": 5},
        **changes,
    }
    path.write_text(yaml.safe_dump(data))
    return path


def test_config_dump_prints_a_loadable_default(tmp_path):
    result = runner.invoke(cli_app(), ["config", "dump"])
    assert result.exit_code == 0, result.output
    assert CampaignConfig.from_dict(yaml.safe_load(result.output)).runs.initial == 10
    assert "# cap on the runs of one world" in result.output
    out = tmp_path / "c.yaml"
    assert runner.invoke(cli_app(), ["config", "dump", "--out", str(out)]).exit_code == 0
    assert out.read_text() == result.output


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("worlds: [office_small_01]\nrunz: {initial: 3}\n", "c.yaml: runz: Extra inputs are not permitted"),
        (
            "worlds: [office_small_01]\nruns: {initial: 0}\n",
            "c.yaml: runs.initial: Input should be greater than or equal to 2 (got 0)",
        ),
        ("worlds: [no_such_world]\n", "worlds: world 'no_such_world' does not load"),
    ],
)
def test_bad_config_is_one_line_and_exit_2(tmp_path, content, expected):
    config = tmp_path / "c.yaml"
    config.write_text(content)
    result = runner.invoke(cli_app(), ["campaign", "run", str(config), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2 and expected in result.output
    assert result.output.count("\n") == 1 and result.output.startswith("error: ")
    assert not (tmp_path / "out").exists()


def test_missing_arguments_and_folders(tmp_path):
    app = cli_app()
    result = runner.invoke(app, ["campaign", "run"])
    assert result.exit_code == 2 and "give a campaign config" in result.output
    result = runner.invoke(app, ["campaign", "run", "--out", str(tmp_path)])
    assert result.exit_code == 2 and "not a campaign folder" in result.output
    result = runner.invoke(app, ["campaign", "status", str(tmp_path)])
    assert result.exit_code == 2 and "not a campaign folder" in result.output
    result = runner.invoke(
        app, ["campaign", "replay", str(tmp_path), "--algorithm", "odometry", "--out", str(tmp_path / "new")]
    )
    assert result.exit_code == 2 and "not a campaign folder" in result.output


@pytest.mark.slow
def test_a_small_real_campaign_status_resume_and_replay(tmp_path):
    app = cli_app()
    room = write_room(tmp_path / "worlds")
    config = write_config(tmp_path / "c.yaml", [room])
    out = tmp_path / "campaign"
    result = runner.invoke(app, ["campaign", "run", str(config), "--out", str(out), "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert (
        "room: done with 5 runs" in result.output or "room: capped with 5 runs" in result.output
    ) and "eps_t" in result.output
    assert f"summary: {out / 'summary.csv'}" in result.output.replace("\n", "")
    assert (out / "summary.csv").is_file() and (out / "runs" / "room" / "001" / "run.json").is_file()
    status = runner.invoke(app, ["campaign", "status", str(out)])
    assert status.exit_code == 0 and "finished" in status.output and "room" in status.output
    # resume without the config: nothing left to do, said in one line
    again = runner.invoke(app, ["campaign", "run", "--out", str(out), "--workers", "1"])
    assert again.exit_code == 0 and again.output.count("\n") == 1 and "complete" in again.output
    # another config on the same folder: refused, one line
    other = write_config(tmp_path / "other.yaml", [room], seed=5)
    refused = runner.invoke(app, ["campaign", "run", str(other), "--out", str(out)])
    assert refused.exit_code == 2 and "different config (seed: stored 0, given 5)" in refused.output
    # replay with another parameter of the same algorithm
    replay = runner.invoke(
        app,
        [
            "campaign",
            "replay",
            str(out),
            "--algorithm",
            "odometry",
            "--set",
            "resolution=0.1",
            "--out",
            str(tmp_path / "replay"),
            "--workers",
            "1",
        ],
    )
    assert replay.exit_code == 0, replay.output
    assert "first algorithm's maps" in replay.output and (tmp_path / "replay" / "summary.csv").is_file()
    bad = runner.invoke(
        app,
        ["campaign", "replay", str(out), "--algorithm", "odometry", "--set", "nope=1", "--out", str(tmp_path / "r2")],
    )
    assert bad.exit_code == 2 and "no parameter nope" in bad.output


@pytest.fixture(scope="module")
def inproc():
    """An in-process Dask cluster whose address the CLI's --scheduler takes."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster:
        yield cluster.scheduler_address


@pytest.fixture(scope="module")
def fake_campaign(tmp_path_factory, inproc):
    """A finished campaign of the odometry baseline with its ``gmapping`` preset, runs from FakeTrial."""
    from slamtrials.campaign import run_campaign
    from slamtrials.campaign.testing import FakeTrial

    root = tmp_path_factory.mktemp("fake")
    room = write_room(root / "worlds")
    config = CampaignConfig.from_dict(
        {
            "worlds": [room],
            "slam": {"algorithm": "odometry", "preset": "gmapping"},
            "runs": {"initial": 5, "max_runs": 5},
        }
    )
    run_campaign(config, root / "c", scheduler=inproc, trial_fn=FakeTrial())
    return root / "c"


def settings_lines(output: str) -> list[str]:
    lines = output.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("settings that differ"))
    found = []
    for line in lines[start + 1 :]:
        if not line.startswith("  "):
            break
        found.append(line.strip())
    return found


def test_replay_prints_the_changed_settings_and_keeps_the_preset(fake_campaign, inproc, tmp_path):
    app = cli_app()
    out = tmp_path / "r"
    args = ["campaign", "replay", str(fake_campaign), "--set", "resolution=0.1", "--out", str(out)]
    result = runner.invoke(app, [*args, "--scheduler", inproc])
    assert result.exit_code == 0, result.output
    assert result.output.startswith(f"settings that differ ({fake_campaign} -> {out}):")
    assert settings_lines(result.output) == ["slam.params.resolution: 0.05 -> 0.1"]
    assert "first algorithm's maps" in result.output and "eps_t" in result.output
    # the same command again: complete, one line, no cluster needed
    again = runner.invoke(app, [*args, "--scheduler", "tcp://127.0.0.1:1"])
    assert again.exit_code == 0, again.output
    assert again.output.splitlines()[-1] == f"{out}: complete, every world is finished; nothing to run " + (
        f"(see 'slamtrials campaign status {out}')"
    )
    # compare prints the same difference before its results
    compared = runner.invoke(
        make_compare_app(), ["compare", str(fake_campaign), str(out), "--out", str(tmp_path / "cmp"), "--no-pdf"]
    )
    assert compared.exit_code == 0, compared.output
    assert compared.output.startswith("settings that differ")
    assert settings_lines(compared.output)[0] == "slam.params.resolution: 0.05 -> 0.1"


def make_compare_app():
    from slamtrials.cli import report as report_cli

    test_app = make_app()
    report_cli.register(test_app)
    return test_app


def test_replay_no_preset_and_bad_choices(fake_campaign, inproc, tmp_path):
    app = cli_app()
    out = tmp_path / "r"
    result = runner.invoke(
        app, ["campaign", "replay", str(fake_campaign), "--no-preset", "--out", str(out), "--scheduler", inproc]
    )
    assert result.exit_code == 0, result.output
    lines = settings_lines(result.output)
    assert [line.split(":")[0] for line in lines] == [
        "slam.params.angular_update",
        "slam.params.linear_update",
        "slam.preset",
    ]
    assert lines[2] == "slam.preset: gmapping -> null"
    both = runner.invoke(
        app, ["campaign", "replay", str(fake_campaign), "--no-preset", "-p", "gmapping", "--out", str(tmp_path / "x")]
    )
    assert both.exit_code == 2 and "give --preset NAME or --no-preset, not both" in both.output
    assert not (tmp_path / "x").exists()


def test_status_of_an_interrupted_campaign_and_resuming_a_complete_one(fake_campaign, tmp_path):
    import shutil
    import sqlite3

    app = cli_app()
    folder = tmp_path / "c"
    shutil.copytree(fake_campaign, folder)
    done = runner.invoke(app, ["campaign", "run", "--out", str(folder), "--scheduler", "tcp://127.0.0.1:1"])
    assert done.exit_code == 0, done.output
    assert done.output.count("\n") == 1 and "complete, every world is finished; nothing to run" in done.output
    with sqlite3.connect(folder / "campaign.sqlite") as conn:  # as a driver killed mid-run leaves it
        conn.execute("UPDATE runs SET status = 'running' WHERE idx = 0")
        conn.execute("UPDATE worlds SET status = 'running'")
    status = runner.invoke(app, ["campaign", "status", str(folder)])
    assert status.exit_code == 0, status.output
    assert "profile realistic, seed" in status.output  # the campaign names no profile: the default
    assert "interrupted" in status.output and "running" not in status.output.replace("campaign run", "")
    assert f"not finished, no driver alive (interrupted; resume with 'slamtrials campaign run --out {folder}')" in (
        status.output.replace("\n", "")
    )
