"""``slamtrials report``, ``compare`` and ``export-table`` through typer's runner."""

from __future__ import annotations

import pandas as pd
import pytest
from typer.testing import CliRunner

from slamtrials.campaign import CampaignConfig, run_campaign
from slamtrials.campaign.testing import FakeTrial
from slamtrials.cli import report as report_cli
from slamtrials.cli.common import make_app

runner = CliRunner()
WORLDS = ["office_small_01", "lab_small_01"]


def cli_app():
    """The root app with the report commands (as cli/main.py registers them)."""
    from slamtrials.cli.main import app

    names = {command.name for command in app.registered_commands}
    if {"report", "compare", "export-table"} <= names:
        return app
    test_app = make_app()
    report_cli.register(test_app)
    return test_app


def fake_campaign(folder, trial):
    from distributed import Client, LocalCluster

    config = CampaignConfig.from_dict(
        {
            "worlds": WORLDS,
            "seed": 11,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 8, "max_runs": 8},
        }
    )
    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        run_campaign(config, folder, scheduler=client, trial_fn=trial)
    return folder


def replay(source, folder):
    from distributed import Client, LocalCluster

    from slamtrials.campaign import replay_campaign

    with (
        LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        replay_campaign(source, folder, params={"resolution": 0.1}, scheduler=client)
    return folder


@pytest.fixture(scope="module")
def campaigns(tmp_path_factory):
    root = tmp_path_factory.mktemp("cli_report")
    a = fake_campaign(root / "slow_algo", FakeTrial(mean_t=0.5, std_t=0.05))
    b = fake_campaign(root / "fast_algo", FakeTrial(mean_t=0.3, std_t=0.05))
    return a, b


@pytest.fixture(scope="module")
def replayed(campaigns):
    """The odometry replay of ``slow_algo`` (FakeTrial's odometry is the truth: every replayed error is 0)."""
    a, _ = campaigns
    return replay(a, a.parent / "slow_replay")


def one_line_error(result, *fragments):
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


@pytest.mark.slow  # a whole report through the CLI; the report's own tests build it in the fast lane
def test_report_command(campaigns):
    a, _ = campaigns
    result = runner.invoke(cli_app(), ["report", str(a), "--repeats", "10", "--no-pdf", "--run", "lab_small_01/2"])
    assert result.exit_code == 0, result.output
    page = a.absolute() / "report" / "index.html"
    assert f"Report: {page}" in result.output and page.is_file()
    assert "office_small_01" in result.output and "lab_small_01" in result.output  # Table I printed
    assert "run #2 of lab_small_01" in page.read_text(encoding="utf-8")


@pytest.mark.slow  # two comparison pages; test_compare_with_itself_warns_in_one_line keeps the command in the fast lane
def test_compare_command(campaigns, tmp_path):
    a, b = campaigns
    result = runner.invoke(cli_app(), ["compare", str(a), str(b), "--alpha", "0.01", "--correction", "bh", "--no-pdf"])
    assert result.exit_code == 0, result.output
    out = b / "report" / "compare-slow_algo"
    assert (out / "compare.html").is_file() and (out / "comparison.csv").is_file()
    assert "fast_algo better" in result.output and "by bh" in result.output
    assert "test: unpaired (Welch): Welch's t-test per world; p and intervals corrected by bh" in result.output
    assert "CI: FCR-adjusted 99% (Benjamini-Yekutieli, 2 of 2 selected: 99%)" in result.output
    # two worlds, each 0.2 m better by 4 standard deviations: Stouffer's test decides, the sign test could not
    assert "overall: fast_algo is better overall in eps_t: Stouffer's Z over the worlds' one-sided Welch t-tests" in (
        result.output.replace("\n", " ")
    )
    assert "sign test over worlds p = 0.5" in result.output
    table = pd.read_csv(out / "comparison.csv")
    assert table.loc[table["metric"] == "eps_t", "verdict"].tolist() == ["B better", "B better"]
    assert table.loc[table["metric"] == "eps_t", "difference"].to_numpy() == pytest.approx([-0.2, -0.2], abs=1e-9)
    explicit = runner.invoke(cli_app(), ["compare", str(a), str(b), "--out", str(tmp_path / "cmp"), "--no-pdf"])
    assert explicit.exit_code == 0 and (tmp_path / "cmp" / "compare.html").is_file()


@pytest.mark.slow  # three comparison pages and a replay; tests/report/test_html.py compares in the fast lane
def test_compare_a_replay_is_paired(campaigns, replayed, tmp_path):
    a, b = campaigns
    result = runner.invoke(cli_app(), ["compare", str(a), str(replayed), "--out", str(tmp_path / "p"), "--no-pdf"])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "test: paired (slow_replay is a replay of slow_algo): paired t on the run-by-run differences" in text
    assert "overall: slow_replay is better overall in eps_t: Stouffer's Z over the worlds' one-sided paired" in text
    assert "CI: simultaneous 95% (Bonferroni, 2 worlds: each at 97.5%)" in text and "W adj" in text
    table = pd.read_csv(tmp_path / "p" / "comparison.csv")
    assert set(table["test"]) == {"paired t"} and (table["n_a"] == 8).all() and (table["left_out_a"] == 0).all()
    swapped = runner.invoke(cli_app(), ["compare", str(replayed), str(a), "--out", str(tmp_path / "s"), "--no-pdf"])
    assert "test: paired (slow_replay is a replay of slow_algo)" in " ".join(swapped.output.split())
    unpaired = runner.invoke(cli_app(), ["compare", str(b), str(replayed), "--out", str(tmp_path / "u"), "--no-pdf"])
    text = " ".join(unpaired.output.split())
    assert "test: unpaired (Welch)" in text and "slow_replay is a replay of" in text and "not paired" in text


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_export_table_command(campaigns, tmp_path, fmt):
    a, _ = campaigns
    out = tmp_path / f"runs.{fmt}"
    result = runner.invoke(cli_app(), ["export-table", str(a), "--format", fmt, "--out", str(out)])
    assert result.exit_code == 0, result.output
    table = pd.read_csv(out) if fmt == "csv" else pd.read_parquet(out)
    assert len(table) == 16 and {"world", "run", "seed", "eps_t", "eps_r", "termination"} <= set(table.columns)
    worlds = runner.invoke(
        cli_app(), ["export-table", str(a), "--format", fmt, "--table", "worlds", "--out", str(tmp_path / f"w.{fmt}")]
    )
    assert worlds.exit_code == 0 and "worlds table" in worlds.output


def test_one_line_errors(campaigns, tmp_path):
    a, b = campaigns
    app = cli_app()
    (tmp_path / "stuff.txt").write_text("x")
    one_line_error(runner.invoke(app, ["report", str(tmp_path)]), str(tmp_path), "not a campaign folder")
    one_line_error(runner.invoke(app, ["report", str(tmp_path / "nowhere")]), "not a campaign folder")
    one_line_error(runner.invoke(app, ["export-table", str(tmp_path), "--format", "csv"]), "not a campaign folder")
    one_line_error(runner.invoke(app, ["compare", str(a), str(tmp_path)]), "not a campaign folder")
    one_line_error(runner.invoke(app, ["report", str(a), "--run", "lab_small_01/42"]), "has no run lab_small_01/42")
    one_line_error(runner.invoke(app, ["report", str(a), "--run", "lab_small_01"]), "WORLD/INDEX")
    one_line_error(runner.invoke(app, ["report", str(a), "--repeats", "1"]), "repeats")
    one_line_error(runner.invoke(app, ["compare", str(a), str(b), "--alpha", "1.5"]), "--alpha")
    one_line_error(runner.invoke(app, ["export-table", str(a), "--out", str(tmp_path)]), "is a folder")
    bad_format = runner.invoke(app, ["export-table", str(a), "--format", "xlsx"])
    assert bad_format.exit_code == 2 and "xlsx" in bad_format.output


def test_compare_with_itself_warns_in_one_line(campaigns, tmp_path):
    a, _ = campaigns
    result = runner.invoke(cli_app(), ["compare", str(a), str(a), "--out", str(tmp_path / "self"), "--no-pdf"])
    assert result.exit_code == 0, result.output
    warnings = [line for line in result.output.splitlines() if line.startswith("warning:")]
    assert warnings == [f"warning: {a} is compared with itself: every difference is 0"]


@pytest.mark.slow  # two comparison pages
def test_compare_shows_world_names_whole_on_a_narrow_terminal(campaigns, replayed, tmp_path):
    a, _ = campaigns
    for columns in ("80", "100"):
        result = runner.invoke(
            cli_app(),
            ["compare", str(a), str(replayed), "--out", str(tmp_path / columns), "--no-pdf"],
            env={"COLUMNS": columns},
        )
        assert result.exit_code == 0, result.output
        rows = [line for line in result.output.splitlines() if line.startswith("\u2502")]
        names = [line.split("\u2502")[1].strip() for line in rows]
        assert [name for name in names if name] == WORLDS * 2, names  # eps_t's table, eps_r's
