"""The report's exploration section: the coverage curves per world and the table of time and distance to
90 % and 99 % coverage; a campaign of runs that recorded none says so."""

from __future__ import annotations

import html
import re

import numpy as np
import pytest
from matplotlib.figure import Figure

from slamtrials.campaign import CampaignConfig, run_campaign
from slamtrials.campaign.testing import FakeTrial
from slamtrials.report.build import build_report
from slamtrials.report.exploration_figures import draw_coverage_curves
from slamtrials.trial.exploration import exploration_measures
from slamtrials.worlds import World

MEASURES = exploration_measures([0.0, 30.0, 60.0, 90.0], [0.1, 0.92, 0.97, 0.98], [0.0, 9.0, 17.0, 25.0], "fake")


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as c,
    ):
        yield c


@pytest.fixture(scope="module")
def rooms(tmp_path_factory):
    """Two 3 m x 3 m rooms as map_server files."""
    from slamtrials.worlds.formats.rosmap_save import save_rosmap

    folder = tmp_path_factory.mktemp("worlds")
    occupied = np.zeros((66, 66), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    return [
        str(save_rosmap(World(occupied, 0.05, name=name, start=np.array([1.0, 1.5, 0.0])), folder / f"{name}.yaml"))
        for name in ("room_a", "room_b")
    ]


def _campaign(folder, trial, rooms, client):
    config = CampaignConfig.from_dict(
        {
            "worlds": rooms,
            "seed": 2,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 5, "max_runs": 5},
        }
    )
    run_campaign(config, folder, scheduler=client, trial_fn=trial)
    return folder


def _rows(page: str, ident: str) -> list[list[str]]:
    body = re.search(rf'<table id="{ident}">.*?<tbody>(.*?)</tbody>', page, re.S).group(1)
    return [
        [html.unescape(re.sub(r"<[^>]+>", "", cell)) for cell in re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)]
        for row in re.findall(r"<tr[^>]*>(.*?)</tr>", body, re.S)
    ]


def test_the_section_shows_every_world_s_curves_and_measures(tmp_path, rooms, client):
    folder = _campaign(tmp_path / "c", FakeTrial(exploration=MEASURES), rooms, client)
    page = build_report(folder, pdf=False).read_text()
    assert '<section id="exploration">' in page and 'href="#exploration"' in page
    assert "report_exploration.png" in page and (folder / "report" / "figures" / "report_exploration.png").is_file()
    rows = _rows(page, "exploration-table")
    assert [row[0] for row in rows] == ["room_a", "room_b"]
    # world, runs, reached 90 %, s, m, reached 99 %, s, m, final coverage, ended by
    assert rows[0][1:] == ["5", "5 of 5", "30", "9.0", "0 of 5", "-", "-", "98.0 %", "fake 5"]


def test_runs_without_measures_leave_the_section_empty(tmp_path, rooms, client):
    folder = _campaign(tmp_path / "c", FakeTrial(), rooms, client)
    page = build_report(folder, pdf=False).read_text()
    assert "No finished run recorded exploration measures." in page
    assert "report_exploration.png" not in page


def test_the_curves_are_drawn_run_by_run_with_the_thresholds():
    other = exploration_measures([0.0, 50.0, 100.0], [0.0, 0.995, 1.0], [0.0, 20.0, 30.0], "no_frontiers")
    ax = Figure().subplots()
    draw_coverage_curves(ax, {0: MEASURES, 3: other}, title="room")
    lines = {line.get_gid(): line for line in ax.get_lines()}
    assert {"run:0", "run:3", "threshold:90", "threshold:99", "reached:90", "reached:99"} <= set(lines)
    assert list(lines["run:3"].get_ydata()) == [0.0, 99.5, 100.0]
    assert sorted(lines["reached:90"].get_xdata()) == [30.0, 50.0]
    assert list(lines["reached:99"].get_xdata()) == [50.0]
    assert ax.get_xlabel() == "simulated time (s)" and "%" in ax.get_ylabel()
    assert ax.get_legend() is not None and ax.get_xlim()[1] >= 100.0
