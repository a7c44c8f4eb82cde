"""Every real-building map in ../shared/worlds/real loads with the scale and free area SOURCES.md states."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from slamtrials.worlds import load_world, world_to_cell

# The shared data folder beside the repository, or wherever SLAMTRIALS_SHARED points.
REAL = (
    Path(os.environ.get("SLAMTRIALS_SHARED", Path(__file__).resolve().parents[2].parent / "shared")) / "worlds" / "real"
)

# From the table in shared/worlds/real/SOURCES.md (computed independently with map_server's rule):
# short_name: (resolution m/px, free area m^2, largest connected free area m^2)
TABLE = {
    "uh_robot_house": (0.05, 50, 47),
    "robotathome_sarmis": (0.05, 61, 61),
    "uoa_robotics_lab": (0.0127, 105, 84),
    "hbrs_c069": (0.05, 109, 107),
    "upenn_levine": (0.05, 144, 144),
    "ipa_office": (0.025, 195, 184),
    "freiburg_079": (0.05, 320, 313),
    "freiburg_052": (0.05, 356, 356),
    "radish_lab_c": (0.05, 357, 355),
    "ipa_factory": (0.05, 365, 349),
    "g4s_office": (0.05, 383, 380),
    "bremen_cartesium": (0.05, 425, 425),
    "uol_bl": (0.05, 564, 562),
    "intel_lab": (0.05, 772, 762),
    "radish_lab_a": (0.05, 901, 901),
    "mit_building31": (0.05, 1078, 1077),
    "bham_cs_lg": (0.05, 1129, 1126),
    "nlb": (0.05, 1247, 1247),
    "willow_garage": (0.05, 1373, 1364),
    "utexas_gdc3": (0.05, 1929, 1827),
    "ipa_production_plant": (0.05, 3053, 3008),
    "uol_mht": (0.05, 4717, 4703),
    "stage_hospital": (0.0455, 7475, 3811),
}

#: The start pose must leave room for the 0.2 x 0.2 m robot (half-diagonal 0.14 m) and a margin.
MIN_START_CLEARANCE = 0.4


@pytest.fixture(scope="module")
def real_dir() -> Path:
    if not REAL.is_dir():
        pytest.skip(f"shared real maps not available at {REAL}")
    return REAL


def test_table_lists_every_map_folder(real_dir):
    folders = {p.parent.name for p in real_dir.glob("*/map.yaml")}
    assert folders == set(TABLE)


@pytest.mark.parametrize(
    "short_name",
    # the maps of more than 1,500 m^2: half a second or more each
    [pytest.param(name, marks=[pytest.mark.slow] if TABLE[name][1] > 1500 else []) for name in sorted(TABLE)],
)
def test_real_map_loads_with_stated_scale_area_and_a_good_start(real_dir, short_name):
    resolution, free_area, largest = TABLE[short_name]
    world = load_world(real_dir / short_name / "map.yaml")
    assert world.name == short_name
    assert world.resolution == pytest.approx(resolution)
    assert world.metadata["format"] == "rosmap"
    assert world.free_area == pytest.approx(free_area, rel=0.10)

    row, col = (int(v) for v in world_to_cell(world, world.start[:2]))
    assert not world.occupied[row, col]
    labels, count = world.free_regions
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    sizes[0] = 0
    assert labels[row, col] == int(np.argmax(sizes)), "start is not in the largest free region"
    reachable = float(np.count_nonzero(world.reachable_free())) * world.resolution**2
    assert reachable == pytest.approx(largest, rel=0.10)
    assert world.clearance[row, col] >= MIN_START_CLEARANCE
