"""Resume after kill -9 at any moment: the finished campaign equals an uninterrupted one with the same seed."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import time

import pytest

from slamtrials.campaign import CampaignConfig, run_campaign
from slamtrials.campaign.store import DB_FILE, CampaignStore
from slamtrials.campaign.testing import FakeTrial

#: Columns that describe when and where a run happened, not what it produced.
CIRCUMSTANCES = {"attempts", "wall_time", "worker", "submitted", "finished", "updated"}

DRIVER = """
import json, sys
from distributed import Client, LocalCluster
from slamtrials.campaign import CampaignConfig, run_campaign
from slamtrials.campaign.testing import FakeTrial

if __name__ == "__main__":
    config = CampaignConfig.from_dict(json.loads(sys.argv[1]))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, Client(cluster) as client:
        run_campaign(config, sys.argv[2], scheduler=client, trial_fn=FakeTrial(sleep=0.03))
"""


def outcome(folder):
    """The catalog's rows without their circumstances, plus the run folders and what their run.json say."""
    with CampaignStore.open(folder) as store:
        runs = [{k: v for k, v in vars(r).items() if k not in CIRCUMSTANCES} for r in store.runs()]
        worlds = [{k: v for k, v in vars(w).items() if k not in CIRCUMSTANCES} for w in store.worlds()]
    folders = sorted(p.relative_to(folder).as_posix() for p in (folder / "runs").glob("*/*"))
    recorded = {}
    for path in (folder / "runs").glob("*/*/run.json"):
        doc = json.loads(path.read_text())
        recorded[path.parent.relative_to(folder).as_posix()] = (
            doc["seed"],
            doc["campaign"]["eps_t"],
            doc["campaign"]["eps_r"],
        )
    return runs, worlds, folders, recorded


def done_count(folder) -> int:
    if not (folder / DB_FILE).is_file():
        return 0
    try:
        conn = sqlite3.connect(f"file:{folder / DB_FILE}?mode=ro", uri=True, timeout=1.0)
        try:
            return conn.execute("SELECT COUNT(*) FROM runs WHERE status = 'done'").fetchone()[0]
        finally:
            conn.close()
    except sqlite3.Error:
        return 0


@pytest.mark.slow
def test_kill_9_then_resume_equals_an_uninterrupted_campaign(tmp_path, rooms, client):
    config = CampaignConfig.from_dict(
        {
            "worlds": rooms,
            "seed": 11,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 10, "max_runs": 60},
        }
    )
    reference = run_campaign(config, tmp_path / "reference", scheduler=client, trial_fn=FakeTrial())
    total = reference.runs_done
    assert total > 40

    script = tmp_path / "driver.py"
    script.write_text(DRIVER)
    folder = tmp_path / "killed"
    killed = 0
    for kill_at in (3, total // 3, (2 * total) // 3):
        proc = subprocess.Popen(
            [sys.executable, str(script), json.dumps(config.model_dump(mode="json")), str(folder)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        deadline = time.monotonic() + 60
        while proc.poll() is None and done_count(folder) < kill_at and time.monotonic() < deadline:
            time.sleep(0.005)
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
            killed += 1
        proc.wait()
        assert done_count(folder) < total, "the campaign finished before it could be killed"
    assert killed == 3

    resumed = run_campaign(config, folder, scheduler=client, trial_fn=FakeTrial())
    assert resumed.runs_done < total  # the runs finished before the kills were kept
    assert resumed.summary == reference.summary
    assert outcome(folder) == outcome(tmp_path / "reference")
    assert not list(folder.glob("runs/*/.*"))  # no partial folders left


def test_a_crash_between_rename_and_commit_is_redone(tmp_path, rooms, client):
    config = CampaignConfig.from_dict(
        {
            "worlds": rooms[:1],
            "seed": 2,
            "runs": {"initial": 5, "max_runs": 5},
            "slam": {"algorithm": "odometry", "preset": None},
        }
    )
    reference = run_campaign(config, tmp_path / "reference", scheduler=client, trial_fn=FakeTrial())
    folder = tmp_path / "c"
    run_campaign(config, folder, scheduler=client, trial_fn=FakeTrial())
    # undo the commit of run 2 (its folder stays, as after a crash right after the rename) and
    # leave a half-written partial folder of run 3 behind
    with CampaignStore.open(folder) as store:
        store._conn.execute("UPDATE runs SET status = 'running', eps_t = NULL, eps_r = NULL WHERE idx = 2")
    (folder / "runs" / "room_a" / "002" / "frames.npz").write_bytes(b"stale")
    partial = folder / "runs" / "room_a" / ".003.partial-abc"
    partial.mkdir()
    (partial / "frames.npz").write_bytes(b"half")
    resumed = run_campaign(config, folder, scheduler=client, trial_fn=FakeTrial())
    assert resumed.runs_done == 1 and resumed.summary == reference.summary
    assert outcome(folder) == outcome(tmp_path / "reference")
    assert (folder / "runs" / "room_a" / "002" / "frames.npz").read_bytes() != b"stale"
    assert not partial.exists()
