"""The tutorials of docs/tutorials run as written: every shell block of each page, in order, in one
folder, by /bin/sh with the project's venv first on PATH (so a heredoc or a pipe runs as a user's
shell runs it)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
TUTORIALS = REPO / "docs" / "tutorials"


def _blocks(page: Path) -> list[str]:
    return re.findall(r"```sh\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S)


def _run(page: Path, folder: Path) -> None:
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
    for block in _blocks(page):
        done = subprocess.run(["/bin/sh", "-e", "-c", block], cwd=folder, env=env, capture_output=True, text=True)
        assert done.returncode == 0, f"{page.name}:\n{block}\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"


@pytest.mark.slow
def test_your_buildings_then_compare(tmp_path):
    _run(TUTORIALS / "your-buildings.md", tmp_path)
    assert (tmp_path / "office-plan.png").is_file()
    assert (tmp_path / "campaigns" / "mine" / "report" / "index.html").is_file()
    summary = (tmp_path / "campaigns" / "mine" / "summary.csv").read_text()
    assert "office" in summary
    _run(TUTORIALS / "compare.md", tmp_path)
    assert (tmp_path / "campaigns" / "mine-karto" / "report" / "compare-mine" / "compare.html").is_file()


@pytest.mark.slow
def test_cluster(tmp_path):
    _run(TUTORIALS / "cluster.md", tmp_path)
    summary = (tmp_path / "campaigns" / "cluster" / "summary.csv").read_text()
    assert "office_small_01" in summary and ",5," in summary.replace(" ", "")


def _catalog(study: Path) -> dict:
    """Per cell of a study: every run's seed, status and errors, and every world's status and run counts."""
    from slamtrials.campaign.store import CampaignStore

    found = {}
    for cell in sorted((study / "cells").iterdir()):
        with CampaignStore.open(cell) as store:
            runs = {(r.world, r.idx): (r.seed, r.status, r.eps_t, r.eps_r) for r in store.runs()}
            worlds = {w.name: (w.status, w.runs_target, w.runs_needed) for w in store.worlds()}
        found[cell.name] = (runs, worlds)
    return found


@pytest.mark.slow
def test_cluster_study(tmp_path):
    """The page's tiny study on a dask scheduler and two dask workers (the driver and one worker killed on
    the way, then resumed) equals the same study on a local cluster, bit for bit in the errors."""
    _run(TUTORIALS / "cluster-study.md", tmp_path)
    study = tmp_path / "studies" / "tiny"
    assert (study / "report" / "index.html").is_file() and (study / "report" / "comparisons.csv").is_file()
    assert (tmp_path / "host-a.log").is_file() and (tmp_path / "host-b.log").is_file()
    local = [str(Path(sys.executable).parent / "slamtrials"), "study", "run", "tiny-study.yaml", "--workers", "2"]
    done = subprocess.run([*local, "--out", "studies/local"], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    ours, theirs = _catalog(study), _catalog(tmp_path / "studies" / "local")
    assert ours == theirs
    assert sum(len(runs) for runs, _ in ours.values()) == 2 * 2 * 5  # 2 cells x 2 worlds x 5 runs, all done


SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared"))


@pytest.mark.slow
@pytest.mark.skipif(not (SHARED / "data" / "mit-csail" / "mit-csail.clf").is_file(), reason="no MIT CSAIL log")
def test_calibrate(tmp_path):
    (tmp_path / "work").mkdir()
    (tmp_path / "shared").symlink_to(SHARED, target_is_directory=True)  # ../shared from the work folder
    _run(TUTORIALS / "calibrate.md", tmp_path / "work")
    assert "odometry" in (tmp_path / "work" / "mit-profile.yaml").read_text()
    assert (tmp_path / "work" / "validation.json").is_file()


def test_every_tutorial_is_run_here():
    """A new page needs its test: each page of docs/tutorials is named in this file."""
    source = Path(__file__).read_text(encoding="utf-8")
    for page in TUTORIALS.glob("*.md"):
        assert page.name in source, f"{page.name} is not run by {Path(__file__).name}"
