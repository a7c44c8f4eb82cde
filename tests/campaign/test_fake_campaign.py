"""run_campaign with an injected cheap trial of known error spread: run counts, resume, failures, bad input."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.campaign import CampaignConfig, campaign_status, load_summary, run_campaign, run_seed
from slamtrials.campaign.testing import FakeTrial
from slamtrials.cli.main import app
from slamtrials.errors import ConfigError, SimulationError
from slamtrials.metric import replay_run_count
from slamtrials.report.load import load_campaign

FAKE = FakeTrial(mean_t=0.3, std_t=0.05, mean_r=0.05, std_r=0.012)


def config_for(rooms, **changes) -> CampaignConfig:
    data = {
        "worlds": rooms,
        "seed": 7,
        "slam": {"algorithm": "odometry", "preset": None},
        "runs": {"initial": 10, "max_runs": 80},
        **changes,
    }
    return CampaignConfig.from_dict(data)


def expected_runs(config: CampaignConfig, world: str, trial: FakeTrial = FAKE):
    """The rule replayed independently over the fake's errors, taken in run order."""
    errors = np.array([trial.errors(run_seed(config.seed, world, i)) for i in range(config.runs.max_runs)])
    return replay_run_count(
        errors[:, 0],
        errors[:, 1],
        margin_t=config.runs.margin_t,
        margin_r=config.runs.margin_r,
        confidence=config.runs.confidence,
        min_runs=config.runs.initial,
        max_runs=config.runs.max_runs,
    )


def snapshot(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_run_counts_follow_the_rule_and_resume_does_nothing_more(tmp_path, rooms, client):
    config = config_for(rooms)
    events = []
    result = run_campaign(config, tmp_path / "c", scheduler=client, trial_fn=FAKE, on_event=events.append)
    by_world = {row.world: row for row in result.summary}
    assert list(by_world) == ["room_a", "room_b"]
    for world, row in by_world.items():
        expected = expected_runs(config, world)
        assert row.status == "done" and row.runs == expected.done and row.runs_needed == expected.needed
        assert row.eps_t.n == row.runs and row.terminations == {"fake": row.runs}
        # eps_t has the fake's spread: z^2 sigma^2 / d^2 = 41.5 with the normal quantile; Student t's first
        # estimate (9 degrees of freedom) asks for about 1.6 times as many, the later ones for fewer
        assert 25 <= row.runs <= config.runs.max_runs
    assert result.runs_done == sum(r.runs for r in result.summary) and result.runs_failed == 0
    # every done run has its folder, seed and errors
    status = campaign_status(tmp_path / "c")
    assert status.finished and status.runs_done == result.runs_done
    kinds = [e.kind for e in events]
    assert kinds.count("start") == 2 and kinds.count("world_done") == 2 and kinds.count("run_done") == result.runs_done
    assert kinds.count("batch") >= 4  # initial batch and at least one more per world
    from slamtrials.campaign.store import CampaignStore

    with CampaignStore.open(tmp_path / "c") as store:
        for run in store.runs():
            e_t, e_r = FAKE.errors(run.seed)
            assert run.seed == run_seed(7, run.world, run.idx)
            assert run.eps_t == pytest.approx(e_t, abs=1e-12) and run.eps_r == pytest.approx(e_r, abs=1e-12)
            assert (tmp_path / "c" / run.folder / "run.json").is_file()
    # the summary CSV
    rows = list(csv.DictReader((tmp_path / "c" / "summary.csv").open()))
    assert [r["world"] for r in rows] == ["room_a", "room_b"]
    assert int(rows[0]["runs"]) == by_world["room_a"].runs
    assert float(rows[0]["eps_t_mean"]) == pytest.approx(by_world["room_a"].eps_t.mean)
    assert load_summary(tmp_path / "c") == list(result.summary)
    # running it again (or resuming without the config) changes nothing
    before = snapshot(tmp_path / "c" / "runs")
    again = run_campaign(config, tmp_path / "c", scheduler=client, trial_fn=FAKE)
    assert again.runs_done == 0 and again.summary == result.summary
    assert run_campaign(None, tmp_path / "c", scheduler=client, trial_fn=FAKE).summary == result.summary
    assert snapshot(tmp_path / "c" / "runs") == before


def test_the_cap_is_reported(tmp_path, rooms, client):
    config = config_for(rooms[:1], runs={"initial": 5, "max_runs": 6})
    result = run_campaign(config, tmp_path / "c", scheduler=client, trial_fn=FAKE)
    (row,) = result.summary
    assert row.status == "capped" and row.capped and row.runs == 6 and row.cap == 6
    # the rule's own figure, not the cap, everywhere: the summary, summary.csv, the note, status, the report
    asked = row.runs_needed
    assert asked > 6
    (csv_row,) = csv.DictReader((tmp_path / "c" / "summary.csv").open())
    assert (csv_row["runs_needed"], csv_row["capped"], csv_row["capped_at"]) == (str(asked), "1", "6")
    assert any(f"cap of 6 runs; the rule asked for {asked}," in note for note in result.notes)
    status = CliRunner().invoke(app, ["campaign", "status", str(tmp_path / "c")], env={"COLUMNS": "200"})
    assert f"{asked} (capped at 6)" in status.output, status.output
    assert f"6/{asked} (capped at 6)" in status.output
    worlds = load_campaign(tmp_path / "c").worlds
    assert int(worlds["runs_needed"].iloc[0]) == asked


class FailingIn:
    """A fake trial that fails (as a run can, e.g. a start pose in a wall) in one world."""

    def __init__(self, world_name: str):
        self.world_name = world_name

    def __call__(self, world, config, seed):
        if world.name == self.world_name:
            raise SimulationError("the robot does not fit at the start pose")
        return FAKE(world, config, seed)


def test_a_failing_world_is_reported_and_the_others_go_on(tmp_path, rooms, client):
    config = config_for(rooms, runs={"initial": 5, "max_runs": 5})
    result = run_campaign(config, tmp_path / "c", scheduler=client, trial_fn=FailingIn("room_b"))
    rows = {row.world: row for row in result.summary}
    assert rows["room_a"].status in ("done", "capped") and rows["room_a"].runs >= 5
    assert rows["room_b"].status == "failed" and rows["room_b"].runs == 0 and rows["room_b"].failed_runs == 5
    assert "SimulationError" in rows["room_b"].note and result.runs_failed == 5
    assert any("room_b: failed" in note for note in result.notes)
    # a resume retries the failed world
    resumed = run_campaign(config, tmp_path / "c", scheduler=client, trial_fn=FAKE)
    assert {row.world: row.status for row in resumed.summary}["room_b"] in ("done", "capped")
    fresh = run_campaign(config, tmp_path / "d", scheduler=client, trial_fn=FAKE)
    assert [(r.world, r.runs, r.eps_t) for r in resumed.summary] == [(r.world, r.runs, r.eps_t) for r in fresh.summary]


def test_bad_input_fails_before_any_work(tmp_path, rooms, client):
    with pytest.raises(ConfigError, match=r"worlds: world 'no_such_world' does not load: no bundled world named"):
        run_campaign(config_for([rooms[0], "no_such_world"]), tmp_path / "c", scheduler=client, trial_fn=FAKE)
    assert not (tmp_path / "c").exists()
    broken = tmp_path / "broken.yaml"
    broken.write_text("image: missing.png\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(ConfigError, match="broken.yaml"):
        run_campaign(config_for([str(broken)]), tmp_path / "c", scheduler=client, trial_fn=FAKE)
    with pytest.raises(ConfigError, match="workers must be a positive integer"):
        run_campaign(config_for(rooms), tmp_path / "c", workers=0)
    with pytest.raises(ConfigError, match="no campaign folder"):
        run_campaign(config_for(rooms), None, scheduler=client)
    assert not (tmp_path / "c").exists()
    # an existing campaign with another config is refused and left as it was
    config = config_for(rooms[:1], runs={"initial": 5, "max_runs": 5})
    run_campaign(config, tmp_path / "c", scheduler=client, trial_fn=FAKE)
    before = snapshot(tmp_path / "c")
    with pytest.raises(ConfigError, match=r"different config \(seed: stored 7, given 8\)"):
        run_campaign(
            config_for(rooms[:1], seed=8, runs={"initial": 5, "max_runs": 5}),
            tmp_path / "c",
            scheduler=client,
            trial_fn=FAKE,
        )
    assert snapshot(tmp_path / "c") == before


def test_a_folder_entry_expands_to_its_floor_plans(tmp_path, rooms, client):
    from pathlib import Path

    from slamtrials.campaign.worldset import expand_worlds

    folder = Path(rooms[0]).parent
    (folder / "notes.yaml").write_text("not: a map\n")  # not a map_server map: skipped
    names = [name for name, _, _ in expand_worlds([str(folder)])]
    assert names == ["room_a", "room_b"]
    with pytest.raises(ConfigError, match="two worlds are named 'room_a'"):
        expand_worlds([str(folder), rooms[0]])
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ConfigError, match="holds no floor plan"):
        expand_worlds([str(empty)])


def test_folder_problems_fail_before_a_cluster_starts(tmp_path, rooms, monkeypatch):
    import slamtrials.campaign.execute as execute

    def no_cluster(*args, **kwargs):
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(execute, "dask_client", no_cluster)
    folder = tmp_path / "c"
    folder.mkdir()
    (folder / "mine.txt").write_text("keep")
    with pytest.raises(ConfigError, match="not empty and holds no campaign"):
        run_campaign(config_for(rooms), folder, workers=1)
    assert [p.name for p in folder.iterdir()] == ["mine.txt"]


def test_an_unreachable_scheduler_is_a_clear_error(tmp_path, rooms, monkeypatch):
    import slamtrials.campaign.cluster as cluster

    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", 0.5)
    with pytest.raises(ConfigError, match=r"cannot connect to the Dask scheduler 'tcp://127.0.0.1:9'"):
        run_campaign(config_for(rooms), tmp_path / "c", scheduler="tcp://127.0.0.1:9", trial_fn=FAKE)
    assert not (tmp_path / "c").exists()
