"""Replay keeps the source campaign's SLAM settings; the differences between two campaigns' settings;
``campaign status`` of an interrupted campaign; resuming a complete one."""

from __future__ import annotations

import json
import sqlite3

import pytest

from slamtrials.campaign import CampaignConfig, campaign_status, replay_campaign, run_campaign
from slamtrials.campaign.differences import campaign_differences, setting_differences
from slamtrials.campaign.folder import campaign_lock, driver_alive
from slamtrials.campaign.replay import replay_slam_settings
from slamtrials.campaign.store import DB_FILE, CampaignStore
from slamtrials.campaign.testing import FakeTrial
from slamtrials.trial import SlamSettings

#: An unreachable scheduler: a call that tried to start work would fail on it.
NO_SCHEDULER = "tcp://127.0.0.1:1"


def source_config(rooms, **slam) -> CampaignConfig:
    """The odometry baseline with its ``gmapping`` preset (linear_update 1.0, angular_update 0.5)."""
    return CampaignConfig.from_dict(
        {
            "worlds": rooms,
            "seed": 3,
            "slam": {"algorithm": "odometry", "preset": "gmapping", **slam},
            "runs": {"initial": 5, "max_runs": 5},
        }
    )


@pytest.fixture(scope="module")
def source(tmp_path_factory, rooms, client):
    folder = tmp_path_factory.mktemp("source") / "c"
    run_campaign(source_config(rooms[:1]), folder, scheduler=client, trial_fn=FakeTrial())
    return folder


def replayed_slam_configs(folder):
    with CampaignStore.open(folder) as store:
        runs = [r for r in store.runs() if r.status == "done"]
    assert runs
    return [json.loads((folder / r.folder / "run.json").read_text())["slam_config"] for r in runs]


def test_the_replay_settings_rule():
    base = SlamSettings(algorithm="gmapping", preset="paper", params={"particles": 30, "srr": 0.1})
    same = replay_slam_settings(base, None, params={"particles": 80})
    assert same == SlamSettings(algorithm="gmapping", preset="paper", params={"particles": 80, "srr": 0.1})
    assert replay_slam_settings(base, "gmapping").preset == "paper"
    assert replay_slam_settings(base, "gmapping", None).preset is None  # --no-preset
    assert replay_slam_settings(base, "gmapping", "other").params == {"particles": 30, "srr": 0.1}
    other = replay_slam_settings(base, "karto", params={"resolution": 0.1})
    assert other == SlamSettings(algorithm="karto", preset=None, params={"resolution": 0.1})
    assert replay_slam_settings(base, "karto", "x").preset == "x"


def test_replay_with_a_parameter_keeps_the_source_preset(source, tmp_path, client):
    replay_campaign(source, tmp_path / "r", params={"resolution": 0.1}, scheduler=client)
    with CampaignStore.open(tmp_path / "r") as store:
        slam = store.config().slam
    assert slam == SlamSettings(algorithm="odometry", preset="gmapping", params={"resolution": 0.1})
    for run_config in replayed_slam_configs(tmp_path / "r"):
        assert run_config["resolution"] == 0.1
        assert run_config["linear_update"] == 1.0 and run_config["angular_update"] == 0.5  # the preset's
    differences = [str(d) for d in campaign_differences(source, tmp_path / "r")]
    assert differences == ["slam.params.resolution: 0.05 -> 0.1"]


def test_replay_without_a_preset_runs_the_defaults(source, tmp_path, client):
    replay_campaign(source, tmp_path / "r", "odometry", None, scheduler=client)
    with CampaignStore.open(tmp_path / "r") as store:
        assert store.config().slam == SlamSettings(algorithm="odometry", preset=None, params={})
    defaults = SlamSettings(algorithm="odometry", preset=None).resolved().model_dump(mode="json")
    assert defaults["linear_update"] != 1.0
    for run_config in replayed_slam_configs(tmp_path / "r"):
        assert run_config == defaults
    differences = [str(d) for d in campaign_differences(source, tmp_path / "r")]
    assert differences == [
        f"slam.params.angular_update: 0.5 -> {json.dumps(defaults['angular_update'])}",
        f"slam.params.linear_update: 1.0 -> {json.dumps(defaults['linear_update'])}",
        "slam.preset: gmapping -> null",
    ]


def test_differences_list_exactly_the_changed_settings(rooms):
    a = source_config(rooms)
    data = a.model_dump(mode="json")
    data["metric"]["relative_margin"] = 0.02
    data["sim"]["odometry"]["noise_linear_per_m"] = 0.02
    data["output"] = "elsewhere"  # where the results are, not how they were made: not listed
    data["replay_of"] = "somewhere"
    b = CampaignConfig.from_dict(data)
    assert [str(d) for d in setting_differences(a, b)] == [
        "metric.relative_margin: 0.01 -> 0.02",
        f"sim.odometry.noise_linear_per_m: {a.sim.odometry.noise_linear_per_m} -> 0.02",
    ]
    assert setting_differences(a, a) == []
    # another algorithm: the parameters are not resolved (they are not comparable), only the overrides
    c = CampaignConfig.from_dict({**a.model_dump(mode="json"), "slam": {"algorithm": "gmapping", "preset": "paper"}})
    assert [str(d) for d in setting_differences(a, c)] == [
        "slam.algorithm: odometry -> gmapping",
        "slam.preset: gmapping -> paper",
    ]


def set_run_running(folder) -> None:
    """Leave one done run as a killed driver leaves it: 'running' in the catalog."""
    with sqlite3.connect(folder / DB_FILE) as conn:
        conn.execute("UPDATE runs SET status = 'running' WHERE idx = (SELECT MIN(idx) FROM runs)")
        conn.execute("UPDATE worlds SET status = 'running'")


def test_status_shows_runs_of_a_dead_driver_as_interrupted(tmp_path, rooms, client):
    folder = tmp_path / "c"
    run_campaign(source_config(rooms[:1]), folder, scheduler=client, trial_fn=FakeTrial())
    set_run_running(folder)
    state = campaign_status(folder)
    assert state.driver is False and state.interrupted and not state.finished
    assert state.runs["room_a"] == {"done": 4, "interrupted": 1}
    assert [w.status for w in state.worlds] == ["interrupted"]
    with campaign_lock(folder):  # a live driver
        assert driver_alive(folder) is True
        live = campaign_status(folder)
        assert live.driver is True and not live.interrupted
        assert live.runs["room_a"] == {"done": 4, "running": 1} and live.worlds[0].status == "running"
    assert driver_alive(folder) is False  # the probe left the lock free
    # resuming runs the interrupted run again and ends complete
    result = run_campaign(None, folder, scheduler=client, trial_fn=FakeTrial())
    assert not result.complete and result.runs_done == 1
    assert campaign_status(folder).runs["room_a"] == {"done": 5}


def test_a_folder_never_run_has_no_driver(tmp_path):
    assert driver_alive(tmp_path) is False and not (tmp_path / ".campaign.lock").exists()


def test_resuming_a_complete_campaign_runs_nothing_and_starts_no_cluster(source, tmp_path, client):
    before = (source / DB_FILE).stat().st_mtime_ns
    result = run_campaign(None, source, scheduler=NO_SCHEDULER)
    assert result.complete and result.runs_done == 0 and [r.world for r in result.summary] == ["room_a"]
    assert result.summary_csv == source / "summary.csv"
    with CampaignStore.open(source) as store:
        refs = [w.ref for w in store.world_infos()]
    assert run_campaign(source_config(refs), source, scheduler=NO_SCHEDULER).complete  # with the config, too
    assert (source / DB_FILE).stat().st_mtime_ns == before
    replay_campaign(source, tmp_path / "r", scheduler=client)
    assert replay_campaign(source, tmp_path / "r", scheduler=NO_SCHEDULER).complete


def test_a_driver_starting_while_the_lock_is_probed_gets_it(tmp_path):
    import fcntl
    import os
    import threading

    (tmp_path / ".campaign.lock").touch()
    fd = os.open(tmp_path / ".campaign.lock", os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)  # a probe holding it (far longer than a real one)
    threading.Timer(0.08, os.close, (fd,)).start()
    with campaign_lock(tmp_path):
        assert driver_alive(tmp_path) is True
