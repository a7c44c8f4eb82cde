"""Campaign world names of map_server folders: the generic ``map.yaml`` is named by its folder."""

from __future__ import annotations

import numpy as np

from slamtrials.campaign.worldset import expand_worlds
from slamtrials.worlds import load_world


def write_map_folder(folder, name: str) -> str:
    """``folder/name/map.yaml`` + ``map.pgm``: a plain map_server map (a 2 x 2 m room), as ROS saves one."""
    target = folder / name
    target.mkdir(parents=True)
    image = np.full((46, 46), 254, dtype=np.uint8)
    image[:3, :] = image[-3:, :] = image[:, :3] = image[:, -3:] = 0
    (target / "map.pgm").write_bytes(b"P5\n46 46\n255\n" + image.tobytes())
    (target / "map.yaml").write_text(
        "image: map.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return str(target / "map.yaml")


def test_generic_map_yaml_files_are_named_by_their_folders(tmp_path):
    first, second = write_map_folder(tmp_path, "lab_one"), write_map_folder(tmp_path, "hall_two")
    named = expand_worlds([first, second])
    assert [name for name, _, _ in named] == ["lab_one", "hall_two"]  # was 'map' twice: refused as a clash
    assert [name for name, _, _ in named] == [load_world(first).name, load_world(second).name]
    # a folder entry holding one map_server folder's files directly: named by that folder too
    assert [name for name, _, _ in expand_worlds([str(tmp_path / "lab_one")])] == ["lab_one"]
    # a folder of map_server folders: one world per subfolder, as before
    assert [name for name, _, _ in expand_worlds([str(tmp_path)])] == ["hall_two", "lab_one"]


def test_other_plan_files_keep_their_stem(tmp_path):
    plan = write_map_folder(tmp_path, "lab_one")
    renamed = tmp_path / "lab_one" / "ground_floor.yaml"
    renamed.write_text(open(plan).read())
    assert [name for name, _, _ in expand_worlds([str(renamed)])] == ["ground_floor"]
