"""The SQLite store and the run folders: creation, config checks, state changes, crash leftovers."""

from __future__ import annotations

import sqlite3

import pytest

from slamtrials.campaign import CampaignConfig
from slamtrials.campaign.folder import campaign_lock, open_campaign, prepare_resume
from slamtrials.campaign.results import RunDetails, RunDone
from slamtrials.campaign.runfiles import (
    clean_partials,
    publish_run,
    remove_unrecorded,
    run_folder,
)
from slamtrials.campaign.store import DB_FILE, CampaignStore, WorldInfo
from slamtrials.errors import ConfigError

WORLDS = [WorldInfo("a", "a", 0, 10.0), WorldInfo("b", "/x/b.yaml", 1, 20.0)]
RESULT = RunDone(
    world="a",
    index=0,
    eps_t=0.25,
    eps_r=0.03,
    relations=12,
    termination="map_converged",
    mapped_fraction=0.97,
    sim_duration=100.0,
    wall_time=2.0,
    worker="w:1",
    folder="runs/a/000",
    details=RunDetails(
        frames=5,
        distance_m=3.0,
        observed_fraction=0.99,
        slam_updates=7,
        relation_std_t=0.1,
        relation_std_r=0.01,
        relations_capped=False,
    ),
)


def snapshot(folder):
    """Every file of a folder with its bytes (to show that nothing changed)."""
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_create_open_and_record(tmp_path):
    config = CampaignConfig(worlds=["a", "b"], seed=5)
    folder = tmp_path / "c"
    with CampaignStore.create(folder, config, WORLDS) as store:
        assert store.kind == "campaign" and store.config() == config
        assert [w.name for w in store.worlds()] == ["a", "b"] and store.worlds()[0].status == "pending"
        store.mark_submitted("a", [(0, 111), (1, 222)])
        assert {r.status for r in store.runs("a")} == {"running"} and store.worlds()[0].status == "running"
        store.record_done("a", 0, RESULT)
        store.record_failed("a", 1, "MetricError: boom")
        assert store.done_results("a") == {0: (0.25, 0.03)}
        assert store.worlds()[0].status == "failed" and "boom" in store.worlds()[0].note
    assert (folder / "config.yaml").is_file()
    text = (folder / "config.yaml").read_text()
    assert CampaignConfig.from_dict(__import__("yaml").safe_load(text)) == config
    with CampaignStore.open(folder) as store:
        assert store.prepare_resume() == 1  # the failed run goes back to the queue
        rows = {r.idx: r for r in store.runs("a")}
        assert rows[0].status == "done" and rows[0].seed == 111 and rows[0].termination == "map_converged"
        assert rows[1].status == "pending" and rows[1].attempts == 1
        assert store.worlds()[0].status == "pending"
        store.mark_submitted("a", [(1, 222)])
        assert {r.idx: r.attempts for r in store.runs("a")}[1] == 2
    # WAL journal, one catalog file
    assert sqlite3.connect(folder / DB_FILE).execute("PRAGMA journal_mode").fetchone()[0] == "wal"


def test_a_different_config_is_refused_before_anything_changes(tmp_path):
    folder = tmp_path / "c"
    CampaignStore.create(folder, CampaignConfig(worlds=["a", "b"], seed=5), WORLDS).close()
    before = snapshot(folder)
    with pytest.raises(ConfigError, match=r"different config \(seed: stored 5, given 6\)"):
        open_campaign(folder, CampaignConfig(worlds=["a", "b"], seed=6), WORLDS, kind="campaign")
    with pytest.raises(ConfigError, match="worlds"):
        open_campaign(folder, CampaignConfig(worlds=["a", "b"], seed=5), WORLDS[:1], kind="campaign")
    with pytest.raises(ConfigError, match="holds a campaign, not a replay"):
        open_campaign(folder, CampaignConfig(worlds=["a", "b"], seed=5), WORLDS, kind="replay")
    assert snapshot(folder) == before
    # the same config with another output folder is the same campaign
    open_campaign(
        folder, CampaignConfig(worlds=["a", "b"], seed=5, output="elsewhere"), WORLDS, kind="campaign"
    ).close()


def test_a_folder_that_is_not_a_campaign_is_not_touched(tmp_path):
    folder = tmp_path / "c"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    with pytest.raises(ConfigError, match="not empty and holds no campaign"):
        CampaignStore.create(folder, CampaignConfig(worlds=["a"]), WORLDS[:1])
    assert [p.name for p in folder.iterdir()] == ["notes.txt"]
    with pytest.raises(ConfigError, match="not a campaign folder"):
        CampaignStore.open(folder)


def test_publish_run_is_atomic_and_replaces_a_stale_folder(tmp_path):
    def write(content):
        def go(folder):
            (folder / "run.json").write_text(content)

        return go

    final = publish_run(tmp_path, "a", 3, write("first"))
    assert final == run_folder(tmp_path, "a", 3) == tmp_path / "runs" / "a" / "003"
    assert publish_run(tmp_path, "a", 3, write("second")) == final and (final / "run.json").read_text() == "second"
    assert sorted(p.name for p in final.parent.iterdir()) == ["003"]

    def crash(folder):
        (folder / "frames.npz").write_bytes(b"half")
        raise RuntimeError("killed while writing")

    with pytest.raises(RuntimeError):
        publish_run(tmp_path, "a", 4, crash)
    assert sorted(p.name for p in final.parent.iterdir()) == ["003"]  # no partial left, no 004


def test_resume_removes_partial_and_unrecorded_run_folders(tmp_path):
    folder = tmp_path / "c"
    store = CampaignStore.create(folder, CampaignConfig(worlds=["a", "b"]), WORLDS)
    store.mark_submitted("a", [(0, 1), (1, 2)])
    publish_run(folder, "a", 0, lambda f: (f / "run.json").write_text("{}"))
    store.record_done("a", 0, RESULT)
    publish_run(folder, "a", 1, lambda f: (f / "run.json").write_text("{}"))  # crash before the commit
    partial = folder / "runs" / "b" / ".000.partial-xyz"  # crash in the middle of writing
    partial.mkdir(parents=True)
    (partial / "frames.npz").write_bytes(b"half")
    with campaign_lock(folder):
        prepare_resume(store)
        with pytest.raises(ConfigError, match="another slamtrials process"):
            with campaign_lock(folder):
                pass
    assert (folder / "runs" / "a" / "000").is_dir()
    assert not (folder / "runs" / "a" / "001").exists() and not partial.exists()
    assert {r.idx: r.status for r in store.runs("a")} == {0: "done", 1: "pending"}
    store.close()
    assert clean_partials(folder) == [] and remove_unrecorded(folder, {("a", 0)}) == []


def test_a_campaign_stored_by_an_earlier_version_loads_and_resumes(tmp_path):
    """Earlier versions stored explore's robot fields (then overridden by sim.robot) and fewer metric fields."""
    import hashlib
    import json

    config = CampaignConfig(worlds=["a", "b"], seed=5)
    folder = tmp_path / "c"
    CampaignStore.create(folder, config, WORLDS).close()
    old = config.model_dump(mode="json")
    old["explore"].update({"robot_radius": 0.15, "max_linear_speed": 0.7, "control_period": 0.1})
    for name in ("sides", "min_relations", "max_relations", "squared"):
        del old["metric"][name]
    identity = {k: v for k, v in old.items() if k != "output"}
    old_hash = hashlib.sha256(json.dumps(identity, sort_keys=True, separators=(",", ":")).encode()).hexdigest()
    with sqlite3.connect(folder / DB_FILE) as conn:
        conn.execute("UPDATE meta SET value = ? WHERE key = 'config'", (json.dumps(old),))
        conn.execute("UPDATE meta SET value = ? WHERE key = 'config_hash'", (old_hash,))
    with CampaignStore.open(folder) as store:
        assert store.config() == config
    open_campaign(folder, config, WORLDS, kind="campaign").close()
    with pytest.raises(ConfigError, match="different config"):
        open_campaign(folder, CampaignConfig(worlds=["a", "b"], seed=6), WORLDS, kind="campaign")


def test_a_capped_world_keeps_the_rule_s_own_run_count(tmp_path):
    """runs_needed is what the rule asked for before the cap; a catalog of an earlier version, which
    stored the capped figure, reads the same from needed_t and needed_r."""
    from slamtrials.metric import runs_needed

    eps_t = [0.1, 0.5, 0.2, 0.9, 0.3]
    decision = runs_needed(eps_t, eps_t, margin_t=0.02, margin_r=0.02, min_runs=5, max_runs=5)
    assert decision.capped and decision.needed == 5 and decision.asked == max(decision.needed_t, decision.needed_r) > 5
    with CampaignStore.create(tmp_path / "c", CampaignConfig(worlds=["a", "b"]), WORLDS) as store:
        store.record_world("a", status="capped", target=5, decision=decision)
        assert store.worlds()[0].runs_needed == decision.asked and store.worlds()[0].capped
    with sqlite3.connect(tmp_path / "c" / DB_FILE) as conn:  # as an earlier version wrote it
        conn.execute("UPDATE worlds SET runs_needed = 5 WHERE name = 'a'")
    with CampaignStore.open(tmp_path / "c") as store:
        assert store.worlds()[0].runs_needed == decision.asked
