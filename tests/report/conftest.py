"""Shared fixtures of the report tests that build small campaigns (on the session's Dask client of
tests/conftest.py): two tiny rooms, a fake campaign over them, and a reader of the report's HTML tables."""

from __future__ import annotations

import html
import re

import numpy as np
import pytest


@pytest.fixture(scope="session")
def rooms(tmp_path_factory):
    """Two 3 m x 3 m rooms as map_server files."""
    from slamtrials.worlds import World
    from slamtrials.worlds.formats.rosmap_save import save_rosmap

    folder = tmp_path_factory.mktemp("worlds")
    occupied = np.zeros((66, 66), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    return [
        str(save_rosmap(World(occupied, 0.05, name=name, start=np.array([1.0, 1.5, 0.0])), folder / f"{name}.yaml"))
        for name in ("room_a", "room_b")
    ]


@pytest.fixture(scope="session")
def fake_campaign(rooms, client):
    """``fake_campaign(folder, trial)``: a campaign of 5 runs per room with ``trial`` as the trial function
    (e.g. :class:`~slamtrials.campaign.testing.FakeTrial`); returns ``folder``."""
    from slamtrials.campaign import CampaignConfig, run_campaign

    def run(folder, trial):
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

    return run


def _table_rows(page: str, ident: str) -> list[list[str]]:
    body = re.search(rf'<table id="{ident}">.*?<tbody>(.*?)</tbody>', page, re.S).group(1)
    return [
        [html.unescape(re.sub(r"<[^>]+>", "", cell)) for cell in re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)]
        for row in re.findall(r"<tr[^>]*>(.*?)</tr>", body, re.S)
    ]


@pytest.fixture(scope="session")
def table_rows():
    """``table_rows(page, ident)``: the text of each cell of each body row of the HTML table ``ident``."""
    return _table_rows
