"""Shared fixtures of the study tests: tiny rooms as map_server files and an in-process Dask client."""

from __future__ import annotations

import numpy as np
import pytest
import yaml


def write_room(folder, name: str = "room", width_m: float = 4.0, height_m: float = 3.0) -> str:
    """A closed ``width_m`` x ``height_m`` room (walls 3 cells thick) as ``<folder>/<name>.yaml``."""
    from slamtrials.worlds import World
    from slamtrials.worlds.formats.rosmap_save import save_rosmap

    res = 0.05
    h, w = int(round(height_m / res)) + 6, int(round(width_m / res)) + 6
    occupied = np.zeros((h, w), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    folder.mkdir(parents=True, exist_ok=True)
    world = World(occupied, res, name=name, start=np.array([1.0, height_m / 2, 0.0]))
    return str(save_rosmap(world, folder / f"{name}.yaml"))


@pytest.fixture(scope="session")
def rooms(tmp_path_factory):
    """Two tiny worlds: ``room_a`` (4 x 3 m) and ``room_b`` (3 x 3 m)."""
    folder = tmp_path_factory.mktemp("worlds")
    return [write_room(folder, "room_a"), write_room(folder, "room_b", width_m=3.0, height_m=3.0)]


def _campaign_mapping(rooms, **changes) -> dict:
    """A base campaign of the odometry baseline, 5 runs per world."""
    return {
        "worlds": list(rooms),
        "seed": 4,
        "slam": {"algorithm": "odometry", "preset": None},
        "termination": {"small_period": 60.0, "max_time": 300.0},
        "runs": {"initial": 5, "max_runs": 5},
        **changes,
    }


def _write_study(path, rooms, text: str | None = None, **study) -> str:
    """Write a study config (``text`` as it is, or ``study`` with the base campaign inline) to ``path``."""
    if text is None:
        text = yaml.safe_dump({"campaign": _campaign_mapping(rooms), **study}, sort_keys=False)
    path.write_text(text)
    return str(path)


@pytest.fixture
def campaign_mapping():
    """``(rooms, **changes) -> dict``: a base campaign of the odometry baseline, 5 runs per world."""
    return _campaign_mapping


@pytest.fixture
def write_study():
    """``(path, rooms, text=None, **study) -> str``: write a study config file."""
    return _write_study
