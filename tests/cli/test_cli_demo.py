"""The main job: ``slamtrials demo`` runs a small campaign on bundled worlds, resumes it, and writes its report.

The real job (online GMapping on three buildings, several minutes) is what ``make demo`` runs; these
tests inject the campaign's FakeTrial through :func:`slamtrials.demo.run_demo`'s ``trial_fn`` and an
in-process Dask client, so the wiring is checked in seconds.
"""

from __future__ import annotations

import functools

import pytest
from typer.testing import CliRunner

from slamtrials.campaign import DEMO_WORLDS, CampaignConfig
from slamtrials.campaign.demo import DEMO_INITIAL_RUNS, DEMO_MAX_RUNS
from slamtrials.campaign.testing import FakeTrial
from slamtrials.cli.main import app
from slamtrials.demo import demo_config, run_demo
from slamtrials.sim.profiles import DEFAULT_PROFILE

runner = CliRunner()


def test_the_demo_is_the_small_campaign_with_the_papers_settings(tmp_path):
    config = demo_config(tmp_path / "d")
    assert isinstance(config, CampaignConfig) and config.worlds == list(DEMO_WORLDS) and len(DEMO_WORLDS) == 3
    assert config.slam.algorithm == "gmapping" and config.output == str(tmp_path / "d")
    # bounded: at most 10 runs per world (30 in all), about 8 minutes on 2 cores
    assert (config.runs.initial, config.runs.max_runs) == (DEMO_INITIAL_RUNS, DEMO_MAX_RUNS) == (5, 10)
    assert (config.runs.confidence, config.runs.margin_t, config.runs.margin_r) == (0.99, 0.02, 0.02)


@pytest.mark.slow  # two campaigns and two reports; test_demo_command_... below keeps the wiring in the fast lane
def test_run_demo_runs_the_campaign_writes_the_report_and_resumes(tmp_path, client):
    out = tmp_path / "demo"
    fake = FakeTrial(std_t=0.01, std_r=0.005)
    result = run_demo(out, scheduler=client, trial_fn=fake, repeats=5, pdf=False)
    summary = result.campaign.summary
    assert [row.world for row in summary] == list(DEMO_WORLDS)
    assert all(row.status in ("done", "capped") and DEMO_INITIAL_RUNS <= row.runs <= DEMO_MAX_RUNS for row in summary)
    assert result.report == out.absolute() / "report" / "index.html" and result.report.is_file()
    assert 'id="summary-table"' in result.report.read_text(encoding="utf-8")
    assert (out / "summary.csv").is_file() and (out / "campaign.sqlite").is_file()
    # again on the same folder: nothing more to run, the same summary, the report rebuilt
    again = run_demo(out, scheduler=client, trial_fn=fake, repeats=5, pdf=False)
    assert again.campaign.runs_done == 0 and again.campaign.summary == result.campaign.summary
    assert again.report.is_file()


@pytest.mark.slow  # a campaign and its report through the CLI; the options' checks below stay in the fast lane
def test_demo_command_prints_the_summary_and_the_report(tmp_path, client, monkeypatch):
    import slamtrials.demo

    monkeypatch.setattr(
        slamtrials.demo,
        "run_demo",
        functools.partial(run_demo, scheduler=client, trial_fn=FakeTrial(std_t=0.01), repeats=5, pdf=False),
    )
    out = tmp_path / "results" / "demo"
    result = runner.invoke(
        app, ["demo", "--out", str(out), "--world", "office_small_01", "--world", "lab_small_01", "--seed", "4"]
    )
    assert result.exit_code == 0, result.output
    assert (
        "office_small_01" in result.output and "lab_small_01" in result.output and "house_small_01" not in result.output
    )
    assert f"Report: {out.absolute() / 'report' / 'index.html'}" in result.output
    assert "runs done" in result.output and (out / "report" / "index.html").is_file()
    assert result.stdout.startswith(f"Demo campaign in {out}")
    assert result.stderr.splitlines()[0] == f"profile: {DEFAULT_PROFILE}"  # the demo's runs: the one default


def test_demo_command_bad_input_is_one_line(tmp_path):
    result = runner.invoke(app, ["demo", "--out", str(tmp_path / "d"), "--workers", "0"])
    assert (
        result.exit_code == 2
        and result.output.strip().startswith("error: ")
        and len(result.output.strip().splitlines()) == 1
    )
    (tmp_path / "taken").mkdir()
    (tmp_path / "taken" / "notes.txt").write_text("not a campaign")
    result = runner.invoke(app, ["demo", "--out", str(tmp_path / "taken"), "--workers", "1"])
    assert result.exit_code == 2 and "is not empty and holds no campaign" in result.output
    assert len(result.output.strip().splitlines()) == 1
