"""The report's exploration section: the coverage curves per world and the table of time and distance to
90 % and 99 % coverage; a campaign of runs that recorded none says so."""

from __future__ import annotations

from matplotlib.figure import Figure

from slamtrials.campaign.testing import FakeTrial
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.exploration import exploration_section
from slamtrials.report.exploration_figures import draw_coverage_curves
from slamtrials.report.figure_writer import FigureWriter
from slamtrials.report.load import load_campaign
from slamtrials.trial.exploration import exploration_measures

MEASURES = exploration_measures([0.0, 30.0, 60.0, 90.0], [0.1, 0.92, 0.97, 0.98], [0.0, 9.0, 17.0, 25.0], "fake")


def section(folder):
    """The exploration section of ``folder``'s report, drawn as build_report draws it (its figure in
    ``folder/report/figures``); the page around it is tests/report/test_html.py's."""
    return exploration_section(
        CampaignView.of(load_campaign(folder)), FigureWriter(folder / "report", "report_", False)
    )


def test_the_section_shows_every_world_s_curves_and_measures(tmp_path, fake_campaign, table_rows):
    folder = fake_campaign(tmp_path / "c", FakeTrial(exploration=MEASURES))
    page = section(folder)
    assert '<section id="exploration">' in page
    assert "report_exploration.png" in page and (folder / "report" / "figures" / "report_exploration.png").is_file()
    rows = table_rows(page, "exploration-table")
    assert [row[0] for row in rows] == ["room_a", "room_b"]
    # world, runs, reached 90 %, s, m, reached 99 %, s, m, final coverage, ended by
    assert rows[0][1:] == ["5", "5 of 5", "30", "9.0", "0 of 5", "-", "-", "98.0 %", "fake 5"]


def test_runs_without_measures_leave_the_section_empty(tmp_path, fake_campaign):
    folder = fake_campaign(tmp_path / "c", FakeTrial())
    page = section(folder)
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
