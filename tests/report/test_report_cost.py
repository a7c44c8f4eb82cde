"""The report's cost: Table I's SLAM cost columns, the cost section (figure and table), the runs table, the
worlds table's means; a campaign of runs that recorded no cost shows them as missing."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from slamtrials.campaign.costsummary import COST_CSV_COLUMNS
from slamtrials.campaign.testing import FakeTrial
from slamtrials.cost import RunCost
from slamtrials.report import cost_figures as costf
from slamtrials.report.build import build_report
from slamtrials.report.load import load_campaign

COST = RunCost(2.0, 40.0, 3.0, 250.0, 20.0, 30.0, updates_timed=5)


@pytest.fixture(scope="module")
def costed(tmp_path_factory, fake_campaign):
    return fake_campaign(tmp_path_factory.mktemp("report_cost") / "c", FakeTrial(cost=COST))


@pytest.mark.slow
def test_table_one_the_cost_section_and_the_runs_table_show_the_cost(costed, table_rows):
    data = load_campaign(costed)
    assert [data.worlds[c].tolist() for c in COST_CSV_COLUMNS] == [[v, v] for v in (2.0, 40.0, 3.0, 250.0, 20.0, 30.0)]
    page = build_report(costed, repeats=10, pdf=False).read_text(encoding="utf-8")
    for row in table_rows(page, "summary-table"):
        assert row[-3:] == ["2.0", "20 / 30", "40"]  # SLAM CPU s, ms per update (median / p90), MiB: the last columns
    for row in table_rows(page, "cost-table"):
        assert row[1:] == ["5", "2.0", "3.0", "20", "30", "67 %", "40", "250"]
    for row in table_rows(page, "runs-table"):
        assert row[-4:-1] == ["2.0", "20", "40"]
    assert 'src="figures/report_cost.png"' in page and 'href="#cost"' in page
    assert (costed / "report" / "figures" / "report_cost.png").is_file()


@pytest.mark.slow
def test_a_campaign_of_runs_without_cost_reports_none(tmp_path, fake_campaign, table_rows):
    folder = fake_campaign(tmp_path / "c", FakeTrial())
    assert load_campaign(folder).worlds[list(COST_CSV_COLUMNS)].isna().all().all()
    page = build_report(folder, repeats=10, pdf=False).read_text(encoding="utf-8")
    assert all(row[-3:] == ["-", "-", "-"] for row in table_rows(page, "summary-table"))
    assert "No finished run recorded its cost." in page and "report_cost.png" not in page


def test_the_cost_figures_draw_every_run_and_the_world_means():
    runs = pd.DataFrame(
        {
            "world": ["a", "a", "b", "b"],
            "slam_cpu_s": [1.0, 3.0, 5.0, np.nan],  # the last run recorded no cost
            "update_ms_median": [10.0, 20.0, 30.0, np.nan],
            "update_ms_p90": [15.0, 25.0, 45.0, np.nan],
        }
    )
    ax = Figure().add_subplot()
    means = costf.draw_cost_per_world(ax, runs, "slam_cpu_s", ["b", "a"], "CPU s", legend=True)
    assert means.to_dict() == {"b": 5.0, "a": 2.0}
    (points,) = [line for line in ax.lines if line.get_gid() == "runs"]
    assert len(points.get_ydata()) == 3 and ax.get_ylim()[0] == 0.0 and ax.get_ylim()[1] > 5.0
    ax = Figure().add_subplot()
    costf.draw_update_times(ax, runs, ["a", "b"])
    (p90,) = [line for line in ax.lines if line.get_gid() == "p90"]
    assert list(p90.get_ydata()) == [15.0, 25.0, 45.0] and ax.get_ylim()[1] > 45.0
    assert (
        costf.draw_cost_per_world(Figure().add_subplot(), runs[["world"]], "slam_cpu_s", ["a", "b"], "s").isna().all()
    )
