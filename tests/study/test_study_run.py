"""run_study with a cheap fake trial: cells share seeds, resume, refusals that keep what is stored, report."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from slamtrials.campaign.store import CampaignStore
from slamtrials.campaign.testing import FakeTrial
from slamtrials.cli.main import app
from slamtrials.cost import RunCost
from slamtrials.errors import ConfigError
from slamtrials.study import run_study, study_status
from slamtrials.study.report import build_study_report

pytestmark = pytest.mark.slow  # a Dask cluster and ~200 fake runs: about 30 s

runner = CliRunner()
FAKE = FakeTrial(cost=RunCost(slam_cpu_s=2.0, slam_peak_mib=50.0, run_cpu_s=3.0, run_peak_mib=80.0))


def snapshot(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def finished(tmp_path_factory, rooms, client):
    from slamtrials.study.run import run_study

    root = tmp_path_factory.mktemp("study")
    data = {
        "campaign": {
            "worlds": list(rooms),
            "seed": 11,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 5, "max_runs": 6},
        },
        "axes": {"sim.laser.max_range": [30, 15, 8]},
        "combinations": {"wide": {"sim.laser.fov": 6.0}},
    }
    events = []
    result = run_study(data, root / "s", scheduler=client, trial_fn=FAKE, on_event=lambda c, e: events.append((c, e)))
    return root / "s", data, result, events


def test_every_cell_is_a_campaign_and_cells_of_a_world_share_seeds(finished):
    folder, data, result, events = finished
    assert [c.name for c in result.cells] == ["max_range=30", "max_range=15", "max_range=8", "wide"]
    assert result.runs_failed == 0 and result.runs_done == sum(sum(r.runs for r in x.summary) for x in result.results)
    seeds = {}
    for cell in result.cells:
        with CampaignStore.open(folder / "cells" / cell.name) as store:
            assert store.config().sim.laser.max_range == (cell.value("sim.laser.max_range") or 80.0)
            seeds[cell.name] = {(r.world, r.idx): r.seed for r in store.runs()}
    common = set.intersection(*(set(s) for s in seeds.values()))
    assert len(common) >= 10  # 2 worlds x at least 5 runs
    for key in common:
        assert len({s[key] for s in seeds.values()}) == 1
    # events of every cell came through one driver loop
    assert {c for c, _ in events} == {c.name for c in result.cells}
    manifest = json.loads((folder / "study.json").read_text())
    assert [c["folder"] for c in manifest["cells"]] == [f"cells/{c.name}" for c in result.cells]
    assert manifest["cells"][3]["settings"] == {"sim.laser.fov": 6.0}


def test_resume_of_a_finished_study_runs_nothing(finished, client):
    folder, data, _, _ = finished
    before = snapshot(folder / "cells")
    again = run_study(None, folder, scheduler=client, trial_fn=FAKE)
    assert again.complete and again.runs_done == 0
    assert snapshot(folder / "cells") == before
    status = study_status(folder)
    assert status.finished and status.runs_done == sum(c.campaign.runs_done for c in status.cells)


def test_a_changed_config_is_refused_naming_the_changed_keys_and_nothing_is_lost(finished, client):
    folder, data, _, _ = finished
    before = snapshot(folder)
    changed = {**data, "axes": {"sim.laser.max_range": [30, 15]}}
    changed["campaign"] = {**data["campaign"], "seed": 12}
    with pytest.raises(ConfigError) as info:
        run_study(changed, folder, scheduler=client, trial_fn=FAKE)
    text = str(info.value)
    assert "holds a study with another config" in text and "\n" not in text
    assert "axes.sim.laser.max_range: stored [30, 15, 8], given [30, 15]" in text
    assert "campaign.seed: stored 11, given 12" in text
    assert snapshot(folder) == before


def test_cli_refuses_another_study_and_campaign_folders_in_one_line(finished, tmp_path, rooms, write_study):
    folder, data, _, _ = finished
    before = snapshot(folder)
    other = write_study(tmp_path / "other.yaml", rooms, axes={"sim.laser.max_range": [30, 20]})
    result = runner.invoke(app, ["study", "run", other, "--out", str(folder)])
    assert result.exit_code == 2 and "holds a study with another config" in result.output
    assert result.output.strip().count("\n") == 0 and snapshot(folder) == before
    cell = folder / "cells" / "wide"
    result = runner.invoke(app, ["study", "run", other, "--out", str(cell)])
    assert result.exit_code == 2 and "holds a campaign, not a study" in result.output
    result = runner.invoke(app, ["study", "run", "--out", str(tmp_path / "nothing")])
    assert result.exit_code == 2 and "not a study folder" in result.output


def test_report_compares_neighbouring_values_paired_and_draws_every_world(finished, tmp_path):
    folder, _, _, _ = finished
    page = build_study_report(folder, tmp_path / "report", pdf=False)
    html = page.page.read_text()
    for part in ("Error against each axis", "Every cell", "Paired comparisons", "Cost against error", "wide"):
        assert part in html
    import pandas as pd

    cells = pd.read_csv(page.cells_csv)
    assert len(cells) == 4 * 2 and set(cells["world"]) == {"room_a", "room_b"}
    assert (cells["slam_cpu_s_mean"] == 2.0).all()
    comparisons = pd.read_csv(page.comparisons_csv)
    # 2 steps (30 -> 15, 15 -> 8) x 2 worlds x 2 metrics, all paired (shared seeds); the fake's errors
    # depend on the seed only, so every difference is 0 and nothing is significant
    assert len(comparisons) == 8 and set(comparisons["test"]) == {"paired t"}
    assert set(comparisons["value_a"].astype(str) + ">" + comparisons["value_b"].astype(str)) == {"30>15", "15>8"}
    assert (comparisons["difference"] == 0).all()
    assert sorted(p.name for p in page.figures) == [
        "cost-room_a.png",
        "cost-room_b.png",
        "error-room_a.png",
        "error-room_b.png",
    ]
    result = runner.invoke(app, ["study", "report", str(folder), "--out", str(tmp_path / "r2"), "--no-pdf"])
    assert result.exit_code == 0, result.output
    assert "0 of 8 paired comparisons significant" in result.output
