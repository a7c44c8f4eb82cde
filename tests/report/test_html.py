"""The HTML report and the comparison page: built from campaigns (FakeTrial ones, and a small real one)."""

from __future__ import annotations

import math
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from slamtrials.campaign import CampaignConfig, run_campaign
from slamtrials.campaign.testing import FakeTrial
from slamtrials.errors import ConfigError, FormatError, SimulationError
from slamtrials.report import html as h
from slamtrials.report.build import build_report
from slamtrials.report.compare import A_BETTER, B_BETTER, NO_DIFFERENCE
from slamtrials.report.compare_page import compare_report
from slamtrials.report.load import load_campaign
from slamtrials.report.sampling_check import parse_run
from slamtrials.report.tables import share_percent

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
WORLDS = ["office_small_01", "lab_small_01", "house_small_01"]


class Page(HTMLParser):
    """The parts of a page the tests look at: images, links, tables (rows of cell texts) by id, all text."""

    def __init__(self, text: str):
        super().__init__()
        self.images: list[str] = []
        self.links: list[str] = []
        self.tables: dict[str, list[list[str]]] = {}
        self.text: list[str] = []
        self._table: str | None = None
        self._body = False
        self._row: list[str] | None = None
        self._cell: list[str] | None = None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.images.append(a["src"])
        elif tag == "a" and "href" in a:
            self.links.append(a["href"])
        elif tag == "table":
            self._table = a.get("id") or f"table{len(self.tables)}"
            self.tables[self._table] = []
        elif tag == "tbody":
            self._body = True
        elif tag == "tr" and self._body:
            self._row = []
        elif tag == "td" and self._row is not None:
            self._cell = []

    def handle_endtag(self, tag):
        if tag == "td" and self._cell is not None:
            self._row.append("".join(self._cell))
            self._cell = None
        elif tag == "tr" and self._row is not None:
            self.tables[self._table].append(self._row)
            self._row = None
        elif tag == "tbody":
            self._body = False

    def handle_data(self, data):
        self.text.append(data)
        if self._cell is not None:
            self._cell.append(data)


def fake_campaign(
    folder: Path, trial, worlds=WORLDS, *, initial: int = 6, max_runs: int = 8, seed: int = 5, **changes
) -> Path:
    """A campaign with a stand-in trial, on an in-process Dask cluster (fast)."""
    from distributed import Client, LocalCluster

    config = CampaignConfig.from_dict(
        {
            "worlds": list(worlds),
            "seed": seed,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": initial, "max_runs": max_runs},
            **changes,
        }
    )
    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        run_campaign(config, folder, scheduler=client, trial_fn=trial)
    return folder


class FailingIn:
    """FakeTrial with a spread, except that every run of one world fails with a message that holds markup."""

    def __init__(self, world_name: str | None):
        self.world_name = world_name

    def __call__(self, world, config, seed):
        if self.world_name in (None, world.name):
            raise SimulationError("the robot does not fit at the start pose <b>here</b>")
        return FakeTrial(std_t=0.08, std_r=0.02)(world, config, seed)


@pytest.fixture(scope="module")
def campaign(tmp_path_factory) -> Path:
    return fake_campaign(tmp_path_factory.mktemp("html") / "campaign", FailingIn("house_small_01"))


@pytest.fixture(scope="module")
def report(campaign) -> tuple[Path, Page]:
    page = build_report(campaign, repeats=30)
    return page, Page(page.read_text(encoding="utf-8"))


def test_report_page_has_table_one_and_every_figure(campaign, report):
    path, page = report
    assert path == campaign.absolute() / "report" / "index.html"
    data = load_campaign(campaign)
    rows = page.tables["summary-table"]
    assert [r[0] for r in rows] == WORLDS  # one row per world, in campaign order, failed one included
    text = path.read_text(encoding="utf-8")
    assert "error profile realistic" in text and "precise rule: pilot 500" in text and "final SLAM estimate" in text
    for row, (_, world) in zip(rows, data.worlds.iterrows(), strict=True):
        assert row[1] == world["status"]
        if world["runs_done"]:
            assert row[3] == f"{world['eps_t_mean']:.3f}" and row[4] == f"{world['eps_t_std']:.3f}"
            assert row[5] == f"{world['eps_t_half_width']:.3f}" and row[7] == f"{world['eps_r_mean']:.4f}"
            # the metric's share of the between-run variance, from the runs' recorded standard errors
            share = world["eps_t_metric_share"]
            assert row[6] == share_percent(share)
        else:
            assert row[3] == "-" and row[6] == "-"
    # every image is a PNG file beside the page, every PDF link too
    assert len(page.images) >= 1 + 2 + 1 + 1 + 1 + 2 + 1  # Fig. 1 (all + 2 worlds), 5, 6, 3, 4 (2 worlds), termination
    for src in page.images:
        file = path.parent / src
        assert not Path(src).is_absolute() and file.is_file() and file.read_bytes()[:8] == PNG_MAGIC, src
    pdfs = [link for link in page.links if link.endswith(".pdf")]
    assert len(pdfs) == len(page.images) and all((path.parent / link).read_bytes()[:5] == b"%PDF-" for link in pdfs)
    names = {Path(src).name for src in page.images}
    for i, world in enumerate(WORLDS[:2]):
        assert f"report_fig1_{i:03d}_{world}.png" in names and f"report_fig4_{i:03d}_{world}.png" in names
    assert {
        "report_fig5_all_runs.png",
        "report_fig3_sampling.png",
        "report_termination.png",
        "report_fig6_trap.png",
    } <= names
    # the runs table: every run with its seed
    runs = page.tables["runs-table"]
    assert [(r[0], int(r[1]), int(r[2])) for r in runs] == list(
        zip(data.runs["world"], data.runs["run"], data.runs["seed"])
    )


def test_the_table_of_contents_lists_every_section_in_page_order(report):
    path, _ = report
    text = path.read_text(encoding="utf-8")
    anchors = re.findall(r'href="#([^"]+)"', re.search(r"<nav>(.*?)</nav>", text).group(1))
    assert anchors == re.findall(r'<section id="([^"]+)">', text) and len(anchors) == 13


def test_report_notes_provenance_and_escaping(campaign, report):
    path, page = report
    text = path.read_text(encoding="utf-8")
    joined = " ".join(page.text)
    assert "house_small_01: failed" in joined and "resume the campaign to retry" in joined
    assert "<b>here</b>" not in text and "&lt;b&gt;here&lt;/b&gt;" in text  # the failure message is escaped
    assert "Provenance" in joined and "slamtrials_version" in joined and "config_hash" in joined
    data = load_campaign(campaign)
    assert f"seed: {data.config['seed']}" in joined  # the config as YAML
    versions = page.tables["versions-table"]
    assert sum(int(r[1]) for r in versions) == len(data.done)
    assert (
        "Fig. 3" in joined and "run #0 of office_small_01" in joined
    )  # default: first finished run of the first world
    assert "<script" not in text


@pytest.fixture(scope="module")
def rebuilt(campaign, tmp_path_factory) -> tuple[Path, Path, Path]:
    """A second page of the campaign, for Fig. 3 on a chosen run and without PDFs, built in a folder that
    held a figure of an earlier page (``stale``) and a file of the user's (``mine``): (page, stale, mine)."""
    out = tmp_path_factory.mktemp("rebuilt") / "r"
    (out / "figures").mkdir(parents=True)
    stale, mine = out / "figures" / "report_fig1_099_gone.png", out / "figures" / "notes.png"
    stale.write_bytes(b"old")
    mine.write_bytes(b"user's")
    return build_report(campaign, out, sampling_run="lab_small_01/3", repeats=10, pdf=False), stale, mine


@pytest.mark.slow  # a second whole report
def test_report_of_a_chosen_run(rebuilt):
    page, _, _ = rebuilt
    text = page.read_text(encoding="utf-8")
    assert "run #3 of lab_small_01" in text and "over 10 independent samplings" in text
    assert not list((page.parent / "figures").glob("*.pdf"))


def test_bad_choices_are_refused_before_anything_is_written(campaign, tmp_path):
    for bad, message in (
        ("lab_small_01/99", "has no run lab_small_01/99"),
        ("house_small_01/0", "is not finished"),
        ("nonsense", "WORLD/INDEX"),
    ):
        with pytest.raises(ConfigError, match=message):
            build_report(campaign, tmp_path / "bad", sampling_run=bad)
    assert not (tmp_path / "bad").exists()
    with pytest.raises(ConfigError, match="repeats"):
        build_report(campaign, tmp_path / "bad", repeats=1)
    with pytest.raises(FormatError, match="not a campaign folder"):
        build_report(tmp_path / "r")
    assert parse_run("a-b.c/7") == ("a-b.c", 7) and parse_run(("w", 2)) == ("w", 2)


@pytest.mark.slow  # a second whole report
def test_rebuilding_removes_only_stale_figures(rebuilt):
    _, stale, mine = rebuilt
    assert not stale.exists() and mine.exists()


def test_a_campaign_without_finished_runs_still_renders(tmp_path):
    folder = fake_campaign(tmp_path / "c", FailingIn(None), WORLDS[:2], initial=5, max_runs=5)
    page = build_report(folder, pdf=False)
    parsed = Page(page.read_text(encoding="utf-8"))
    assert [r[0] for r in parsed.tables["summary-table"]] == WORLDS[:2]
    joined = " ".join(parsed.text)
    assert "No run has finished yet" in joined and parsed.images == []


def test_html_helpers_escape_everything():
    assert h.esc('<a href="x">&</a>') == "&lt;a href=&quot;x&quot;&gt;&amp;&lt;/a&gt;"
    table = h.table(["<th>"], [["<td>", 1.23456, None, math.nan]], id='x"y')
    assert "&lt;th&gt;" in table and "&lt;td&gt;" in table and 'id="x&quot;y"' in table
    assert ">1.235<" in table and table.count(">-<") == 1 and "<td></td>" in table  # NaN as '-', None as nothing
    figure = h.figure("figures/a b.png", "caption <i>", pdf="figures/a.pdf")
    assert 'src="figures/a b.png"' in figure and "caption &lt;i&gt;" in figure and 'href="figures/a.pdf"' in figure
    assert h.notes([]) == "" and "&lt;" in h.notes(["<"])


def test_times_are_rounded():
    assert [h.fmt_seconds(v) for v in (0.04, 8.64, 9.96, 166.2, 1234.5, None, math.nan)] == [
        "0.0",
        "8.6",
        "10",
        "166",
        "1234",
        "-",
        "-",
    ]
    assert [h.fmt_duration(v) for v in (0.01, 0.0, 8.64, 43.4, 59.7, 166.2, 3599.4, 3600.0, 11130.0, "x")] == [
        "< 0.1 s",
        "0.0 s",
        "8.6 s",
        "43 s",
        "1 min 00 s",
        "2 min 46 s",
        "59 min 59 s",
        "1 h 00 min",
        "3 h 06 min",
        "-",
    ]


# ------------------------------------------------------------------------------------------ comparison


@pytest.fixture(scope="module")
def two_levels(tmp_path_factory) -> tuple[Path, Path]:
    """The same worlds and seeds, B's translational error 0.15 m lower than A's in every run; rotational equal."""
    root = tmp_path_factory.mktemp("compare")
    worlds = WORLDS[:2]
    a = fake_campaign(
        root / "algo_a", FakeTrial(mean_t=0.40, std_t=0.08, mean_r=0.05, std_r=0.01), worlds, initial=10, max_runs=10
    )
    b = fake_campaign(
        root / "algo_b", FakeTrial(mean_t=0.25, std_t=0.08, mean_r=0.05, std_r=0.01), worlds, initial=10, max_runs=10
    )
    return a, b


def test_compare_report_verdicts_statistics_and_trap(two_levels, tmp_path):
    a, b = two_levels
    result = compare_report(a, b, tmp_path / "cmp", alpha=0.05, correction="holm", pdf=False)
    comparison = result.comparison
    assert comparison.labels == ("algo_a", "algo_b")
    runs_a, runs_b = load_campaign(a).done, load_campaign(b).done
    table_t = comparison.for_metric("eps_t")
    assert table_t["verdict"].tolist() == [B_BETTER, B_BETTER]
    assert comparison.for_metric("eps_r")["verdict"].tolist() == [NO_DIFFERENCE, NO_DIFFERENCE]  # identical errors
    for _, row in table_t.iterrows():
        x = runs_a.loc[runs_a["world"] == row["world"], "eps_t"].to_numpy()
        y = runs_b.loc[runs_b["world"] == row["world"], "eps_t"].to_numpy()
        test = stats.ttest_ind(y, x, equal_var=False)
        assert row["difference"] == pytest.approx(y.mean() - x.mean(), abs=1e-12)
        assert row["difference"] == pytest.approx(-0.15, abs=1e-9)
        assert row["p"] == pytest.approx(test.pvalue, rel=1e-9) and row["t"] == pytest.approx(test.statistic, rel=1e-9)
        low, high = test.confidence_interval(0.95)
        assert (row["ci_low"], row["ci_high"]) == pytest.approx((low, high), rel=1e-9)
        # the trap: the share of (run of A, run of B) pairs where B's run is the worse one, by brute force
        assert row["trap_fraction"] == pytest.approx(np.mean(y[None, :] > x[:, None]))
    p = table_t["p"].to_numpy()
    assert table_t["p_adjusted"].to_numpy() == pytest.approx(
        np.minimum(1, np.maximum.accumulate(np.sort(p) * [2, 1]))[np.argsort(np.argsort(p))]
    )
    # the page and the table file
    page = Page(result.page.read_text(encoding="utf-8"))
    assert [r[0] for r in page.tables["comparison-table-eps_t"]] == WORLDS[:2]  # campaign A's order
    assert all((result.page.parent / src).is_file() for src in page.images) and len(page.images) == 3
    text = " ".join(page.text)
    assert "Overall verdict" in text
    # independent campaigns (the same seeds, but neither is a replay): Welch, and the page says so
    assert comparison.pairing == "unpaired (Welch)" and "unpaired (Welch): Welch's t-test per world" in text
    assert "overall: Stouffer's Z over the worlds' one-sided Welch t-tests" in text
    # both intervals, each labelled: the one corrected like the p-values, and the one of a world alone
    assert "CI: simultaneous 95% (Bonferroni, 2 worlds: each at 97.5%)" in text
    assert "CI: 95% this world alone (unadjusted)" in text
    back = pd.read_csv(result.table_csv)
    assert len(back) == 4 and back["verdict"].tolist()[:2] == [B_BETTER, B_BETTER]
    # swapped: A better
    swapped = compare_report(b, a, tmp_path / "swapped", pdf=False).comparison
    assert swapped.for_metric("eps_t")["verdict"].tolist() == [A_BETTER, A_BETTER]


@pytest.mark.slow  # a replay and a comparison page; the pairing's statistics are tests/report/test_compare_paired.py's
def test_compare_report_of_a_replay_is_paired(two_levels, tmp_path):
    from distributed import Client, LocalCluster

    from slamtrials.campaign import replay_campaign

    a, _ = two_levels
    with (
        LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        replay_campaign(a, tmp_path / "algo_a_r01", params={"resolution": 0.1}, scheduler=client)
    result = compare_report(a, tmp_path / "algo_a_r01", tmp_path / "cmp", pdf=False)
    comparison = result.comparison
    assert comparison.paired and comparison.pairing == "paired (algo_a_r01 is a replay of algo_a)"
    runs_a, runs_b = load_campaign(a).done, load_campaign(tmp_path / "algo_a_r01").done
    for _, row in comparison.table.iterrows():
        x = runs_a[runs_a["world"] == row["world"]].sort_values("run")[row["metric"]].to_numpy()
        y = runs_b[runs_b["world"] == row["world"]].sort_values("run")[row["metric"]].to_numpy()
        assert row["test"] == "paired t" and row["n_a"] == len(x) == len(y) == 10
        assert row["p"] == pytest.approx(stats.ttest_rel(y, x).pvalue, rel=1e-9)
        assert row["wilcoxon_p"] == pytest.approx(stats.wilcoxon(y - x).pvalue, rel=1e-9)
    text = " ".join(Page(result.page.read_text(encoding="utf-8")).text)
    assert (
        "paired (algo_a_r01 is a replay of algo_a): paired t-test per world (Wilcoxon signed-rank as a check)" in text
    )
    assert "overall: Stouffer's Z over the worlds' one-sided paired t-tests" in text
    assert "p (Wilcoxon check, holm)" in text and "pairs" in text
    assert any(note.startswith("Paired (algo_a_r01 is a replay of algo_a): run i of a world") for note in result.notes)


def test_compare_problems_are_config_errors(two_levels, tmp_path):
    a, _ = two_levels
    other = fake_campaign(tmp_path / "elsewhere", FakeTrial(), [WORLDS[2]], initial=5, max_runs=5)
    with pytest.raises(ConfigError, match="no world in common"):
        compare_report(a, other, tmp_path / "x")
    empty = fake_campaign(tmp_path / "empty", FailingIn(None), WORLDS[:1], initial=5, max_runs=5)
    with pytest.raises(ConfigError, match="has no finished run"):
        compare_report(a, empty, tmp_path / "x")
    with pytest.raises(ConfigError, match="alpha"):
        compare_report(a, a, tmp_path / "x", alpha=1.5)


# ------------------------------------------------------------------------------------------ a real campaign


def two_rooms(folder: Path, name: str, width_m: float) -> str:
    """Two rooms joined by a door (the robot must move to see the second), as a map_server map."""
    from slamtrials.worlds import World
    from slamtrials.worlds.formats.rosmap_save import save_rosmap

    res, height_m = 0.05, 3.0
    h_, w_ = int(round(height_m / res)) + 6, int(round(width_m / res)) + 6
    occupied = np.zeros((h_, w_), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    occupied[: int(h_ * 0.6), w_ // 2 - 1 : w_ // 2 + 2] = True
    folder.mkdir(parents=True, exist_ok=True)
    world = World(occupied, res, name=name, start=np.array([1.0, 0.7 * height_m, 0.0]))
    return str(save_rosmap(world, folder / f"{name}.yaml"))


@pytest.fixture(scope="module")
def real_campaign(tmp_path_factory):
    """A small real campaign (online GMapping, frontier exploration), 2 worker processes, and its odometry replay."""
    from distributed import Client, LocalCluster

    from slamtrials.campaign import replay_campaign

    root = tmp_path_factory.mktemp("real")
    worlds = [two_rooms(root / "worlds", "rooms_6m", 6.0), two_rooms(root / "worlds", "rooms_5m", 5.0)]
    config = CampaignConfig.from_dict(
        {
            "worlds": worlds,
            "seed": 2,
            "termination": {"small_period": 60.0, "max_time": 300.0},
            "runs": {"initial": 5, "max_runs": 5},
        }
    )
    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        run_campaign(config, root / "gmapping", scheduler=client)
        replay_campaign(root / "gmapping", root / "odometry", "odometry", scheduler=client)
    return root / "gmapping", root / "odometry"


@pytest.mark.slow
def test_report_of_a_real_campaign(real_campaign, tmp_path):
    folder, _ = real_campaign
    page_path = build_report(folder, tmp_path / "report", repeats=40)
    page = Page(page_path.read_text(encoding="utf-8"))
    data = load_campaign(folder)
    assert len(data.done) == 10 and set(data.done["termination"]) <= {"map_converged", "no_frontiers", "time_cap"}
    assert [r[0] for r in page.tables["summary-table"]] == ["rooms_6m", "rooms_5m"]
    for src in page.images:
        assert (page_path.parent / src).read_bytes()[:8] == PNG_MAGIC
    assert any("fig4_000_rooms_6m" in src for src in page.images) and any("fig3_sampling" in src for src in page.images)
    # the robot explored: it moved, and its estimate is not the truth
    assert (data.done["distance_m"] > 1.0).all() and (data.done["eps_t"] > 0).all()


@pytest.mark.slow
def test_compare_a_real_campaign_with_its_replay(real_campaign, tmp_path):
    gmapping, odometry = real_campaign
    result = compare_report(gmapping, odometry, tmp_path / "cmp", pdf=False)
    table = result.comparison.table
    assert sorted(set(table["world"])) == ["rooms_5m", "rooms_6m"] and len(table) == 4
    a, b = load_campaign(gmapping).done, load_campaign(odometry).done
    for _, row in table.iterrows():
        x = a[a["world"] == row["world"]].sort_values("run")[row["metric"]].to_numpy()
        y = b[b["world"] == row["world"]].sort_values("run")[row["metric"]].to_numpy()
        # the replay is paired run by run with its source
        assert row["p"] == pytest.approx(stats.ttest_rel(y, x).pvalue, rel=1e-9)
        expected = NO_DIFFERENCE if row["p_adjusted"] > 0.05 else (B_BETTER if row["difference"] < 0 else A_BETTER)
        assert row["verdict"] == expected
    assert result.comparison.pairing == "paired (odometry is a replay of gmapping)"
    assert any(note.startswith("Paired (odometry is a replay of gmapping)") for note in result.notes)
    page = (tmp_path / "cmp" / "compare.html").read_text(encoding="utf-8")
    assert "settings that differ (A -&gt; B)" in page and "slam.algorithm: gmapping -&gt; odometry" in page
