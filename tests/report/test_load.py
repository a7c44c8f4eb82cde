"""load_campaign and export_table: DataFrames equal to the catalog, read-only, CSV and Parquet round trips."""

from __future__ import annotations

import sqlite3

import numpy as np
import pandas as pd
import pytest

from slamtrials.campaign import CampaignConfig, load_summary, run_campaign
from slamtrials.campaign.store import CampaignStore
from slamtrials.campaign.testing import FakeTrial
from slamtrials.errors import ConfigError, FormatError, SimulationError
from slamtrials.report.load import RUN_COLUMNS, WORLD_COLUMNS, export_table, load_campaign
from slamtrials.report.tables import world_outliers

WORLDS = ["office_small_01", "lab_small_01", "house_small_01"]


class FailingIn:
    """FakeTrial, except that every run of one world fails (a property of the run: not retried)."""

    def __init__(self, world_name: str):
        self.world_name = world_name

    def __call__(self, world, config, seed):
        if world.name == self.world_name:
            raise SimulationError("the robot does not fit at the start pose <here>")
        return FakeTrial(std_t=0.08)(world, config, seed)


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """A FakeTrial campaign of three worlds, one of them failed (in-process Dask cluster)."""
    from distributed import Client, LocalCluster

    folder = tmp_path_factory.mktemp("load") / "campaign"
    config = CampaignConfig.from_dict(
        {
            "worlds": WORLDS,
            "seed": 5,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 6, "max_runs": 8},
        }
    )
    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        run_campaign(config, folder, scheduler=client, trial_fn=FailingIn("house_small_01"))
    return folder


def test_runs_frame_equals_the_catalog(campaign):
    data = load_campaign(campaign)
    runs = data.runs
    assert list(runs.columns[: len(RUN_COLUMNS)]) == list(RUN_COLUMNS)
    assert {"frames", "distance_m", "relations_capped"} <= set(runs.columns)  # the catalog's details
    with CampaignStore.open(campaign) as store:
        rows = store.runs()
        assert len(runs) == len(rows)
        for (_, got), row in zip(runs.iterrows(), rows, strict=True):
            assert (got["world"], got["run"], got["seed"], got["status"], got["attempts"]) == (
                row.world,
                row.idx,
                row.seed,
                row.status,
                row.attempts,
            )
            for column, value in (
                ("eps_t", row.eps_t),
                ("eps_r", row.eps_r),
                ("mapped", row.mapped_fraction),
                ("duration_s", row.sim_duration),
                ("wall_s", row.wall_time),
            ):
                assert got[column] == value or (value is None and np.isnan(got[column])), column
            assert (got["termination"], got["folder"], got["worker"]) == (
                row.termination,
                row.folder,
                row.worker,
            ) or row.status != "done"
            if row.status == "failed":
                assert "SimulationError" in got["error"]
        assert data.meta["config_hash"] == store.meta("config_hash") and data.kind == "campaign"
        assert CampaignConfig.model_validate(data.config) == store.config()
    assert runs["seed"].dtype == np.int64 and runs["run"].dtype == np.int64
    assert set(runs.loc[runs["world"] == "house_small_01", "status"]) == {"failed"}
    # outlier marks: the tables' rule within each world's done runs
    done = data.done
    assert done["outlier_t"].tolist() == world_outliers(done, "eps_t").tolist()
    assert done["outlier_r"].tolist() == world_outliers(done, "eps_r").tolist()
    assert not runs.loc[runs["status"] != "done", ["outlier_t", "outlier_r"]].to_numpy().any()


def test_worlds_frame_is_the_catalog_and_table_one(campaign):
    data = load_campaign(campaign)
    worlds = data.worlds
    assert list(worlds.columns) == list(WORLD_COLUMNS)
    assert worlds["world"].tolist() == WORLDS
    summary = {row.world: row for row in load_summary(campaign)}
    with CampaignStore.open(campaign) as store:
        for (_, got), row in zip(worlds.iterrows(), store.worlds(), strict=True):
            assert (got["world"], got["status"], got["ref"], bool(got["capped"])) == (
                row.name,
                row.status,
                row.ref,
                bool(row.capped),
            )
            assert (pd.isna(got["runs_needed"]) and row.runs_needed is None) or got["runs_needed"] == row.runs_needed
            expected = summary[row.name]
            assert got["runs_done"] == expected.runs and got["runs_failed"] == expected.failed_runs
            if expected.eps_t is None:
                assert np.isnan(got["eps_t_mean"]) and got["eps_t_outliers"] == 0
                continue
            for metric, stats in (("eps_t", expected.eps_t), ("eps_r", expected.eps_r)):
                assert got[f"{metric}_mean"] == pytest.approx(stats.mean, rel=1e-12)
                assert got[f"{metric}_std"] == pytest.approx(stats.std_sample, rel=1e-12)
                assert got[f"{metric}_std_population"] == pytest.approx(stats.std_population, rel=1e-12)
                assert (got[f"{metric}_ci_low"], got[f"{metric}_ci_high"]) == pytest.approx(
                    (stats.ci_low, stats.ci_high), rel=1e-12
                )
            mine = data.done[data.done["world"] == row.name]
            assert got["eps_t_max"] == mine["eps_t"].max() and got["eps_t_outliers"] == int(mine["outlier_t"].sum())
    assert worlds.set_index("world").loc["house_small_01", "status"] == "failed"
    assert (worlds["confidence"] == 0.99).all()


def test_loading_is_read_only_and_works_while_the_driver_writes(campaign):
    db = campaign / "campaign.sqlite"
    before = db.read_bytes()
    first = load_campaign(campaign)
    # a driver in the middle of a write transaction: the reader sees the last committed state
    with CampaignStore.open(campaign) as store:
        store._conn.execute("BEGIN IMMEDIATE")
        store._conn.execute("UPDATE runs SET eps_t = 99.0 WHERE idx = 0")
        during = load_campaign(campaign)
        store._conn.execute("ROLLBACK")
    pd.testing.assert_frame_equal(during.runs, first.runs)
    assert db.read_bytes() == before


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_export_round_trip(campaign, tmp_path, fmt):
    data = load_campaign(campaign)
    path = export_table(campaign, fmt, tmp_path / f"runs.{fmt}")
    back = pd.read_csv(path) if fmt == "csv" else pd.read_parquet(path)
    assert list(back.columns) == list(data.runs.columns) and len(back) == len(data.runs)
    assert back["seed"].tolist() == data.runs["seed"].tolist()  # 64-bit seeds survive exactly
    assert (
        back["world"].tolist() == data.runs["world"].tolist()
        and back["status"].tolist() == data.runs["status"].tolist()
    )
    np.testing.assert_array_equal(back["eps_t"].to_numpy(dtype=float), data.runs["eps_t"].to_numpy(dtype=float))
    if fmt == "parquet":
        pd.testing.assert_frame_equal(back, data.runs)
    worlds = export_table(campaign, fmt, tmp_path / f"worlds.{fmt}", table="worlds")
    back = pd.read_csv(worlds) if fmt == "csv" else pd.read_parquet(worlds)
    assert back["world"].tolist() == WORLDS
    np.testing.assert_allclose(
        back["eps_t_mean"].to_numpy(dtype=float), data.worlds["eps_t_mean"].to_numpy(dtype=float), rtol=1e-15
    )
    # default file: inside the campaign folder
    default = export_table(campaign, fmt)
    assert default == campaign.absolute() / f"runs.{fmt}" and default.is_file()
    default.unlink()


def test_not_a_campaign_is_a_format_error(tmp_path):
    with pytest.raises(FormatError, match="not a campaign folder"):
        load_campaign(tmp_path / "missing")
    with pytest.raises(FormatError, match="campaign.sqlite missing"):
        load_campaign(tmp_path)
    (tmp_path / "campaign.sqlite").write_bytes(b"this is not a database" * 100)
    with pytest.raises(FormatError, match="not a readable campaign catalog"):
        load_campaign(tmp_path)
    other = tmp_path / "other"
    other.mkdir()
    with sqlite3.connect(other / "campaign.sqlite") as conn:
        conn.execute("CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL)")
        conn.execute("INSERT INTO meta VALUES ('format', 'something-else/9')")
    with pytest.raises(FormatError, match="expected a campaign catalog of format"):
        load_campaign(other)


def test_bad_export_arguments(campaign, tmp_path):
    with pytest.raises(ConfigError, match="format must be one of csv, parquet"):
        export_table(campaign, "xlsx", tmp_path / "x.xlsx")
    with pytest.raises(ConfigError, match="table must be one of"):
        export_table(campaign, "csv", tmp_path / "x.csv", table="seeds")
    with pytest.raises(ConfigError, match="is a folder"):
        export_table(campaign, "csv", tmp_path)


def test_public_names():
    import slamtrials.report as report

    assert report.load_campaign is load_campaign and report.export_table is export_table
    assert callable(report.build_report) and callable(report.compare_report)
