"""The campaign report's Fig. 4 (maps with both trajectories in the map frame), its world order, the metric's
share of the between-run variance and the outlier explanation, on a FakeTrial campaign whose map frame is
turned and moved against the world frame and whose catalog records standard errors."""

from __future__ import annotations

import html
import json
import re
import sqlite3
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from slamtrials.campaign import CampaignConfig, run_campaign
from slamtrials.campaign.store import DB_FILE
from slamtrials.campaign.testing import FakeTrial
from slamtrials.io.runfolder import read_run
from slamtrials.report import campaign_figures as cf
from slamtrials.report import html as h
from slamtrials.report.build import build_report
from slamtrials.report.load import load_campaign

WORLDS = ["office_small_01", "lab_small_01", "house_small_01"]  # not in alphabetical order
MAP_FROM_WORLD = (2.0, -1.0, 0.9)
#: Standard errors written into the catalog per world (se_t m, se_r rad); None: not recorded for one run.
STANDARD_ERRORS = {"office_small_01": (0.01, 0.002), "lab_small_01": (0.05, 0.015), "house_small_01": None}

# a campaign over three bundled worlds and its whole report: about 6 s (tests/report/test_html.py builds a
# report in the fast lane)
pytestmark = pytest.mark.slow


def with_standard_errors(folder: Path) -> None:
    """Add se_t, se_r to the details of every done run, as this version's campaigns record them; in
    house_small_01 one run keeps none (a run of an earlier version)."""
    db = sqlite3.connect(folder / DB_FILE)
    try:
        rows = db.execute("SELECT world, idx, details FROM runs WHERE status = 'done' ORDER BY world, idx").fetchall()
        for world, idx, details in rows:
            value = json.loads(details)
            se = STANDARD_ERRORS[world]
            if se is None:
                se = (None, None) if idx == 0 else (0.01, 0.002)
            value["se_t"], value["se_r"] = se
            db.execute("UPDATE runs SET details = ? WHERE world = ? AND idx = ?", (json.dumps(value), world, idx))
        db.commit()
    finally:
        db.close()


@pytest.fixture(scope="module")
def campaign(tmp_path_factory) -> Path:
    from distributed import Client, LocalCluster

    folder = tmp_path_factory.mktemp("maps") / "campaign"
    config = CampaignConfig.from_dict(
        {
            "worlds": WORLDS,
            "seed": 9,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 6, "max_runs": 6},
        }
    )
    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        run_campaign(
            config, folder, scheduler=client, trial_fn=FakeTrial(std_t=0.08, std_r=0.02, map_offset=MAP_FROM_WORLD)
        )
    with_standard_errors(folder)
    return folder


@pytest.fixture(scope="module")
def drawn(campaign, tmp_path_factory) -> tuple[str, dict[str, list]]:
    """The report page, and what the figure functions drew: per function, the world order of each call."""
    original = {name: getattr(cf, name) for name in ("draw_all_runs", "draw_termination", "draw_explored")}
    seen: dict[str, list] = {name: [] for name in (*original, "draw_sorted_errors", "draw_world_errors")}

    def ticks(name):
        def wrapper(ax, *args, **kwargs):
            result = original[name](ax, *args, **kwargs)
            seen[name].append([label.get_text() for label in ax.get_xticklabels()])
            return result

        return wrapper

    sorted_errors, world_errors = cf.draw_sorted_errors, cf.draw_world_errors

    def curves(ax, *args, **kwargs):
        sorted_errors(ax, *args, **kwargs)
        seen["draw_sorted_errors"].append([line.get_gid().removeprefix("world:") for line in ax.lines])

    def bars(ax, runs, world, *args, **kwargs):
        world_errors(ax, runs, world, *args, **kwargs)
        seen["draw_world_errors"].append(world)

    with pytest.MonkeyPatch.context() as patch:
        for name in original:
            patch.setattr(cf, name, ticks(name))
        patch.setattr(cf, "draw_sorted_errors", curves)
        patch.setattr(cf, "draw_world_errors", bars)
        page = build_report(campaign, tmp_path_factory.mktemp("page"), repeats=10, pdf=False)
    return page.read_text(encoding="utf-8"), seen


def table_rows(page: str, ident: str) -> list[list[str]]:
    body = re.search(rf'<table id="{ident}">.*?<tbody>(.*?)</tbody>', page, re.S).group(1)
    return [
        [html.unescape(re.sub(r"<[^>]+>", "", cell)) for cell in re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)]
        for row in re.findall(r"<tr[^>]*>(.*?)</tr>", body, re.S)
    ]


def caption_of(page: str, ident: str) -> str:
    found = re.search(rf'<figure id="{re.escape(ident)}">.*?<figcaption>(.*?)</figcaption>', page, re.S)
    return html.unescape(re.sub(r"<[^>]+>", "", found.group(1)))


def test_every_figure_keeps_the_worlds_in_the_tables_order(drawn):
    page, seen = drawn
    order = [row[0] for row in table_rows(page, "summary-table")]
    assert order == WORLDS
    assert seen["draw_sorted_errors"] == [order, order]  # Fig. 1, both metrics
    assert seen["draw_world_errors"] == [w for w in order for _ in range(2)]  # Fig. 1 per world
    assert seen["draw_all_runs"] == [order, order]  # Fig. 5
    assert seen["draw_termination"] == [order] and seen["draw_explored"] == [order]
    fig4 = re.findall(r'<figure id="fig-4-([^"]+)">', page)
    assert fig4 == order
    fig1 = re.findall(r'src="figures/report_fig1_\d{3}_([^"]+)\.png"', page)
    assert fig1 == order
    assert [row[0] for row in table_rows(page, "termination-table")] == order
    assert [row[0] for row in table_rows(page, "runs-table")] == [w for w in order for _ in range(6)]


def test_fig4_fits_the_truth_onto_the_estimate_of_the_best_and_worst_runs(campaign, drawn):
    page, _ = drawn
    data = load_campaign(campaign)
    for world in WORLDS:
        mine = data.done[data.done["world"] == world]
        best, worst = mine.loc[mine["eps_t"].idxmin()], mine.loc[mine["eps_t"].idxmax()]
        caption = caption_of(page, f"fig-4-{world}")
        assert f"the best run #{best['run']} (\u03b5t {best['eps_t']:.3f} m" in caption
        assert f"the worst run #{worst['run']} (\u03b5t {worst['eps_t']:.3f} m" in caption
        assert "least-squares SE(2) fit" in caption and "map frame" in caption
        for row in (best, worst):
            record = read_run(data.run_folder(world, int(row["run"])))
            fig = Figure()
            FigureCanvasAgg(fig)
            fit = cf.draw_run_on_map(fig.subplots(), record.map, record.truth, record.estimate)
            # the map frame is turned by the known angle, and the fitted truth lies on the estimate within the
            # run's error (the fake estimate overshoots the 1 m path by eps_t; the fit splits it at both ends)
            assert fit.map_from_world[2] == pytest.approx(MAP_FROM_WORLD[2], abs=1e-9)
            assert fit.max_distance <= row["eps_t"] and fit.max_distance == pytest.approx(row["eps_t"] / 2, rel=1e-6)
            assert f"{fit.rms:.3f} m" in caption
            # the estimate was recorded in the map frame: without the fit the truth is metres away from it
            assert np.hypot(*(record.truth[-1, :2] - record.estimate[-1, :2])) > 1.0


def test_metric_share_per_world_and_what_it_means(campaign, drawn):
    page, _ = drawn
    data = load_campaign(campaign)
    rows = {row[0]: row for row in table_rows(page, "summary-table")}
    for world, se in STANDARD_ERRORS.items():
        errors = data.done[data.done["world"] == world]
        for column, metric, se_value in ((6, "eps_t", 0), (10, "eps_r", 1)):
            cell = rows[world][column]
            if se is None:
                assert cell == "n/a"  # a run without a standard error: the share is not known
                continue
            expected = se[se_value] ** 2 / np.var(errors[metric].to_numpy(), ddof=1)
            assert cell.endswith(" %")
            assert float(cell[:-2]) == pytest.approx(100 * expected, abs=0.051 if expected < 0.1 else 0.51)
            assert data.worlds.set_index("world").loc[world, f"{metric}_metric_share"] == pytest.approx(expected)
    office_t = STANDARD_ERRORS["office_small_01"][0] ** 2 / np.var(
        data.done.loc[data.done["world"] == "office_small_01", "eps_t"], ddof=1
    )
    lab_t = STANDARD_ERRORS["lab_small_01"][0] ** 2 / np.var(
        data.done.loc[data.done["world"] == "lab_small_01", "eps_t"], ddof=1
    )
    assert office_t < 0.1 <= lab_t  # the fixture has one world on each side of 10 %
    note = html.unescape(re.search(r'<p class="explain" id="metric-share-note">(.*?)</p>', page, re.S).group(1))
    assert "mean(se\u00b2) over the variance of the run errors" in note
    assert "Below 10 %, the differences between the runs are real" in note and "n/a" in note
    assert f"lab_small_01 (\u03b5t {100 * lab_t:.0f} %" in note and "office_small_01 (\u03b5t" not in note
    assert note.count("lab_small_01") == 1  # one entry per world, both errors in it


def test_the_outlier_column_is_explained_on_the_page(drawn):
    page, _ = drawn
    note = html.unescape(re.search(r'<p class="explain" id="outlier-note">(.*?)</p>', page, re.S).group(1))
    assert "Tukey's fences" in note and "1.5 interquartile ranges" in note and "first quartile Q1" in note
    assert "outlier in: the errors in which the run lies beyond its world's Tukey fences" in html.unescape(page)


def test_times_on_the_page_are_rounded(campaign, drawn):
    page, _ = drawn
    data = load_campaign(campaign)
    for row, (_, run) in zip(table_rows(page, "runs-table"), data.runs.iterrows(), strict=True):
        assert row[9] == "1.0" and re.fullmatch(r"\d+\.\d|\d+", row[10]), row  # sim s, wall s
        assert row[10] == (f"{run['wall_s']:.1f}" if run["wall_s"] < 9.95 else f"{run['wall_s']:.0f}")
    overview = html.unescape(re.search(r"<dt>run times</dt><dd>(.*?)</dd>", page).group(1))
    assert overview.startswith("18 s simulated (mean 1.0 s per run); ")
    wall = data.done["wall_s"]
    assert overview.endswith(f"of worker time (mean {h.fmt_duration(wall.mean())} per run)")
