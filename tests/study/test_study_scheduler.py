"""A study on a Dask scheduler and workers started as separate processes (``dask scheduler``, ``dask worker``,
as on the hosts of a cluster): one worker killed in the middle of a run, the driver interrupted and the
study resumed; its catalog equals, bit for bit in the errors, that of the same study on a local cluster."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from slamtrials.campaign.cluster import dask_client, is_scheduler_file
from slamtrials.campaign.store import CampaignStore
from slamtrials.campaign.testing import FakeTrial
from slamtrials.errors import ConfigError
from slamtrials.study import run_study, study_status

DASK = Path(sys.executable).parent / "dask"
FAKE = FakeTrial(sleep=0.3)  # long enough for a run to be in flight when its worker is killed


class Interrupted(Exception):
    """The driver dies (a crash, Ctrl-C, the head node rebooting)."""


def _start(args: list[str], log: Path, cwd: Path) -> subprocess.Popen:
    """A ``dask`` command in its own process group (a worker's nanny and its worker process die together)."""
    with log.open("w") as out:
        return subprocess.Popen(
            [str(DASK), *args], stdout=out, stderr=subprocess.STDOUT, cwd=cwd, start_new_session=True
        )


def _kill(process: subprocess.Popen) -> None:
    """SIGKILL to the process group this test started: a host that loses its power."""
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=30)


def _catalog(folder: Path) -> dict:
    """Per cell: every run (seed, status, errors) and every world (status, target, capped)."""
    found = {}
    for cell in sorted((folder / "cells").iterdir()):
        with CampaignStore.open(cell) as store:
            runs = {(r.world, r.idx): (r.seed, r.status, r.eps_t, r.eps_r) for r in store.runs()}
            worlds = {w.name: (w.status, w.runs_target, w.runs_needed, w.capped) for w in store.worlds()}
        found[cell.name] = (runs, worlds)
    return found


def _workers_of(folder: Path) -> set[str]:
    names = set()
    for cell in (folder / "cells").iterdir():
        with CampaignStore.open(cell) as store:
            names |= {r.worker for r in store.runs() if r.status == "done"}
    return names


@pytest.mark.slow
def test_a_study_on_separate_scheduler_and_worker_processes_survives_a_dead_worker_and_a_resume(
    tmp_path, rooms, client
):
    config = {
        "campaign": {
            "worlds": list(rooms),
            "seed": 21,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 5, "max_runs": 6},
        },
        "axes": {"sim.laser.max_range": [30, 15]},
    }
    reference = run_study(config, tmp_path / "local", scheduler=client, trial_fn=FAKE)  # a local cluster
    assert reference.runs_done == 2 * 2 * 6  # capped: the fake's spread asks for more than 6

    scheduler_file = tmp_path / "scheduler.json"
    assert is_scheduler_file(str(scheduler_file)) and not is_scheduler_file("tcp://127.0.0.1:8786")
    started = [
        _start(
            [
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--scheduler-file",
                str(scheduler_file),
                "--no-dashboard",
            ],
            tmp_path / "scheduler.log",
            tmp_path,
        )
    ]
    try:
        for name in ("victim", "survivor"):
            args = ["worker", "--scheduler-file", str(scheduler_file), "--nworkers", "1", "--nthreads", "1"]
            started.append(_start([*args, "--name", name, "--no-dashboard"], tmp_path / f"{name}.log", tmp_path))
        victim = started[1]
        with dask_client(str(scheduler_file)) as probe:
            probe.wait_for_workers(2, timeout=120)
            address = {info["name"]: a for a, info in probe.scheduler_info()["workers"].items()}["victim"]
            lost: list = []
            done = [0]

            def chaos(cell, event) -> None:
                if event.kind != "run_done":
                    return
                done[0] += 1
                if done[0] == 4:  # kill the victim while it runs one
                    for _ in range(200):
                        lost.extend(probe.processing(workers=[address]).get(address, ()))
                        if lost:
                            break
                        time.sleep(0.01)
                    _kill(victim)
                if done[0] == 12:
                    raise Interrupted

            folder = tmp_path / "cluster"
            with pytest.raises(Interrupted):
                run_study(config, folder, scheduler=str(scheduler_file), trial_fn=FAKE, on_event=chaos)
        assert lost, "the victim was running nothing when it was killed"
        assert victim.poll() is not None
        assert "Remove worker addr" in (tmp_path / "scheduler.log").read_text()  # its run went to the survivor
        status = study_status(folder)
        assert not status.finished and 12 <= status.runs_done < 24
        # resumed from the stored config on the one worker left, as `slamtrials study run --out` does
        resumed = run_study(None, folder, scheduler=str(scheduler_file), trial_fn=FAKE)
        assert resumed.runs_failed == 0 and study_status(folder).finished
    finally:
        for process in reversed(started):
            _kill(process)
    assert _catalog(folder) == _catalog(tmp_path / "local")  # seeds, statuses, targets and errors, bit for bit
    assert len(_workers_of(folder)) == 2  # both workers ran runs before the victim died


def test_a_missing_scheduler_file_is_a_clear_error(tmp_path, monkeypatch):
    import slamtrials.campaign.cluster as cluster

    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", 0.3)
    with pytest.raises(ConfigError, match=r"cannot connect to the Dask scheduler '.*none\.json': no scheduler file"):
        with dask_client(str(tmp_path / "none.json")):
            pass
