"""The report's section on map quality: the definitions, one row per world of the runs' means, runs without a
map quality counted apart, and a campaign whose runs recorded none."""

from __future__ import annotations

import html

import numpy as np
import pandas as pd
import pytest

from slamtrials.campaign import CampaignConfig, run_campaign
from slamtrials.campaign.mapsummary import MAP_QUALITY_CSV_COLUMNS
from slamtrials.campaign.testing import FakeTrial
from slamtrials.metric.mapquality import DEFINITIONS, MAP_QUALITY_FIGURES
from slamtrials.report.build import build_report
from slamtrials.report.load import load_campaign
from slamtrials.report.map_quality import map_quality_section
from slamtrials.worlds import World


def _runs() -> pd.DataFrame:
    figures = {
        "occupied_precision_1": [0.8, 0.6, 0.9, np.nan],
        "occupied_recall_1": [0.7, 0.9, 0.5, np.nan],
        "occupied_precision_2": [0.9, 0.7, 1.0, np.nan],
        "occupied_recall_2": [0.8, 1.0, 0.6, np.nan],
        "free_iou": [0.95, 0.85, 0.5, np.nan],
        "ghost_free_m2": [1.0, 3.0, 0.25, np.nan],
    }
    return pd.DataFrame({"world": ["a", "a", "b", "b"], **figures})  # the last run recorded none


def test_one_row_per_world_with_the_means_of_the_runs_that_recorded_them(table_rows):
    page = map_quality_section(_runs(), ["b", "a"])
    assert table_rows(page, "map-quality-table") == [
        ["b", "1", "0.900", "0.500", "1.000", "0.600", "0.500", "0.25"],
        ["a", "2", "0.700", "0.800", "0.800", "0.900", "0.900", "2.00"],
    ]
    assert "1 finished run(s) recorded none" in page and 'id="map-quality"' in page
    for name in MAP_QUALITY_FIGURES:
        assert DEFINITIONS[name] in html.unescape(page)


def test_runs_without_map_quality_give_a_note_instead_of_a_table():
    page = map_quality_section(_runs()[["world"]], ["a", "b"])
    assert "No finished run recorded its map quality." in page and "map-quality-table" not in page
    assert DEFINITIONS["free_iou"] in html.unescape(page)


@pytest.mark.slow
def test_the_report_shows_the_worlds_means_as_the_worlds_table_holds_them(tmp_path, client, table_rows):
    from slamtrials.worlds.formats.rosmap_save import save_rosmap

    occupied = np.zeros((66, 66), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    world = World(occupied, 0.05, name="room", start=np.array([1.0, 1.5, 0.0]))
    ref = str(save_rosmap(world, tmp_path / "room.yaml"))
    config = CampaignConfig.from_dict(
        {
            "worlds": [ref],
            "seed": 2,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 5, "max_runs": 5},
        }
    )
    run_campaign(config, tmp_path / "c", scheduler=client, trial_fn=FakeTrial())
    means = load_campaign(tmp_path / "c").worlds.iloc[0]
    page = build_report(tmp_path / "c", repeats=10, pdf=False).read_text(encoding="utf-8")
    ((name, runs, *cells),) = table_rows(page, "map-quality-table")
    assert name == "room" and runs == "5" and 'href="#map-quality"' in page
    assert page.count('<section id="map-quality">') == 1 and page.count('href="#map-quality"') == 1
    for cell, column in zip(cells, MAP_QUALITY_CSV_COLUMNS):
        expected = means[column]
        digits = 2 if column.startswith("ghost") else 3
        assert cell == ("-" if np.isnan(expected) else f"{expected:.{digits}f}"), column
