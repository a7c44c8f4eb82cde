"""A real tiny campaign (online GMapping, frontier exploration) on a local Dask cluster of 2 worker
processes; a replay of it with another algorithm; a worker that dies mid-run."""

from __future__ import annotations

import json

import pytest

from slamtrials.campaign import REPLAY_NOTE, CampaignConfig, campaign_status, replay_campaign, run_campaign
from slamtrials.campaign.store import CampaignStore
from slamtrials.errors import ConfigError
from slamtrials.metric import SamplingRule

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def process_client():
    """A LocalCluster of 2 single-threaded worker processes, as run_campaign starts by default."""
    from distributed import Client, LocalCluster

    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster,
        Client(cluster) as c,
    ):
        yield c


def tiny_config(rooms, **changes) -> CampaignConfig:
    return CampaignConfig.from_dict(
        {
            "worlds": rooms,
            "seed": 1,
            "termination": {"small_period": 60.0, "max_time": 300.0},
            "runs": {"initial": 5, "max_runs": 5},
            **changes,
        }
    )


@pytest.fixture(scope="module")
def campaign(rooms, process_client, tmp_path_factory):
    folder = tmp_path_factory.mktemp("real") / "campaign"
    return folder, run_campaign(tiny_config(rooms), folder, scheduler=process_client)


def test_a_real_campaign_on_two_worker_processes(campaign):
    from slamtrials.evaluation import evaluate_run
    from slamtrials.io.runfolder import read_run

    folder, result = campaign
    assert [row.world for row in result.summary] == ["room_a", "room_b"]
    for row in result.summary:
        assert row.status in ("done", "capped") and row.runs == 5
        assert 0 <= row.eps_t.mean < 0.5 and 0 <= row.eps_r.mean < 0.3
        assert set(row.terminations) <= {"map_converged", "no_frontiers", "time_cap"}
    with CampaignStore.open(folder) as store:
        runs = store.runs()
        assert len({r.worker for r in runs}) == 2  # both worker processes ran runs
        for run in runs:
            run_dir = folder / run.folder
            for name in (
                "run.json",
                "frames.npz",
                "estimate.tum",
                "map.yaml",
                "map.pgm",
                "map.png",
                "relations.npz",
            ):
                assert (run_dir / name).is_file(), name
            doc = json.loads((run_dir / "run.json").read_text())
            assert doc["seed"] == run.seed and doc["campaign"]["index"] == run.idx
            assert run.mapped_fraction > 0.8 and run.sim_duration > 0 and run.relations >= 5000
            scored = doc["campaign"]
            assert scored["relations"] == run.relations and scored["metric"]["rule"] == "precise"
            # the precise rule: the run's mean is known to about 1 % (z = 2.576 at 99 %)
            assert 0 < scored["se_t"] <= 0.011 * run.eps_t / 2.576 or scored["relation_set"]["capped"]
            assert set(scored["scores"]) == {"estimate", "online", "odometry"}
            assert scored["scores"]["estimate"]["eps_t"] == run.eps_t
            # the same numbers as 'slamtrials evaluate RUN', on the run's own relation set (up to the TUM
            # file's rounding), and from the sampling seed alone
            again = evaluate_run(run_dir, write=False)
            assert again.translational.mean == pytest.approx(run.eps_t, rel=1e-6, abs=1e-9)
            assert len(again.relations) == run.relations
            resampled = evaluate_run(run_dir, seed=run.seed, rule=SamplingRule(), write=False)
            assert resampled.translational.mean == pytest.approx(run.eps_t, rel=1e-6, abs=1e-9)
            assert read_run(run_dir).estimate is not None
    assert campaign_status(folder).finished


def test_the_same_campaign_elsewhere_gives_the_same_runs(campaign, rooms, client, tmp_path):
    # other workers, another order of runs: the same seeds give the same runs, bit for bit
    folder, result = campaign
    again = run_campaign(tiny_config(rooms), tmp_path / "again", scheduler=client)
    assert again.summary == result.summary
    with CampaignStore.open(folder) as a, CampaignStore.open(tmp_path / "again") as b:
        assert [(r.world, r.idx, r.seed, r.eps_t, r.eps_r, r.termination) for r in a.runs()] == [
            (r.world, r.idx, r.seed, r.eps_t, r.eps_r, r.termination) for r in b.runs()
        ]


def test_replay_with_another_algorithm(campaign, process_client, tmp_path):
    folder, result = campaign
    replay = replay_campaign(folder, tmp_path / "odometry", "odometry", scheduler=process_client)
    assert replay.notes[0] == REPLAY_NOTE and "first algorithm's maps" in REPLAY_NOTE
    assert [(r.world, r.runs) for r in replay.summary] == [(r.world, r.runs) for r in result.summary]
    with CampaignStore.open(tmp_path / "odometry") as store:
        assert store.kind == "replay" and store.config().replay_of == str(folder)
        assert store.config().slam.algorithm == "odometry"
        for run in store.runs():
            doc = json.loads((tmp_path / "odometry" / run.folder / "run.json").read_text())
            assert doc["replay"]["source_run"] == str(folder / run.folder) and doc["replay"]["algorithm"] == "odometry"
            # scored on the source run's own relation set: the odometry algorithm's errors are the
            # source run's odometry errors (relative errors do not depend on the frame)
            assert (tmp_path / "odometry" / run.folder / "relations.npz").read_bytes() == (
                folder / run.folder / "relations.npz"
            ).read_bytes()
            source_doc = json.loads((folder / run.folder / "run.json").read_text())
            assert run.eps_t == pytest.approx(source_doc["campaign"]["scores"]["odometry"]["eps_t"], rel=1e-9)
    with CampaignStore.open(folder) as source:
        seeds = {(r.world, r.idx): r.seed for r in source.runs()}
        with CampaignStore.open(tmp_path / "odometry") as store:
            assert {(r.world, r.idx): r.seed for r in store.runs()} == seeds
    # replaying the original algorithm and parameters reproduces the original errors exactly
    same = replay_campaign(folder, tmp_path / "same", "gmapping", "paper", scheduler=process_client)
    assert [(r.world, r.eps_t, r.eps_r) for r in same.summary] == [(r.world, r.eps_t, r.eps_r) for r in result.summary]
    # bad input: before any work
    with pytest.raises(ConfigError, match="no parameter particlez"):
        replay_campaign(folder, tmp_path / "bad", "gmapping", None, {"particlez": 3}, scheduler=process_client)
    assert not (tmp_path / "bad").exists()


def test_a_worker_that_dies_loses_only_its_run(rooms, process_client, tmp_path):
    from slamtrials.campaign.testing import FakeTrial

    marker = tmp_path / "died"

    def dies_once(world, config, seed):
        import os

        if world.name == "room_a" and not marker.exists():
            marker.write_text(str(os.getpid()))
            os._exit(1)  # the worker process dies in the middle of a run
        return FakeTrial()(world, config, seed)

    config = tiny_config(rooms, runs={"initial": 5, "max_runs": 5})
    result = run_campaign(config, tmp_path / "c", scheduler=process_client, trial_fn=dies_once)
    reference = run_campaign(config, tmp_path / "ref", scheduler=process_client, trial_fn=FakeTrial())
    assert marker.exists()
    assert result.runs_failed == 0 and result.summary == reference.summary
