"""Shared fixtures of the campaign tests: an in-process Dask client and tiny hand-made worlds."""

from __future__ import annotations

import numpy as np
import pytest

RES = 0.05


def room_world(name: str = "room", width_m: float = 4.0, height_m: float = 3.0):
    """A closed ``width_m`` x ``height_m`` room (walls 3 cells thick), start pose 1 m from the left wall."""
    from slamtrials.worlds import World

    h, w = int(round(height_m / RES)) + 6, int(round(width_m / RES)) + 6
    occupied = np.zeros((h, w), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    return World(occupied, RES, name=name, start=np.array([1.0, height_m / 2, 0.0]))


def write_room(folder, name: str = "room", **size) -> str:
    """Save :func:`room_world` as ``<folder>/<name>.yaml`` (+ PNG); return the YAML path."""
    from slamtrials.worlds.formats.rosmap_save import save_rosmap

    folder.mkdir(parents=True, exist_ok=True)
    return str(save_rosmap(room_world(name, **size), folder / f"{name}.yaml"))


@pytest.fixture(scope="session")
def rooms(tmp_path_factory):
    """Two tiny worlds as map_server files: ``room_a`` (4 x 3 m) and ``room_b`` (3 x 3 m)."""
    folder = tmp_path_factory.mktemp("worlds")
    return [write_room(folder, "room_a"), write_room(folder, "room_b", width_m=3.0, height_m=3.0)]


def _five_run_config(worlds: list[str]):
    from slamtrials.campaign import CampaignConfig

    return CampaignConfig.from_dict(
        {
            "worlds": list(worlds),
            "seed": 3,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 5, "max_runs": 5},
        }
    )


@pytest.fixture(scope="session")
def five_run_config():
    """``five_run_config(worlds)``: a campaign config of exactly 5 runs per world (seed 3, the odometry
    algorithm), for campaigns whose trials a FakeTrial makes."""
    return _five_run_config
