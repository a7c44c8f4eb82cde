"""Stage world files: parsing, Stage's bitmap scaling and placement, robot start, real worlds, errors."""

from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from slamtrials.errors import FormatError, WorldError
from slamtrials.worlds import load_world, world_to_cell
from slamtrials.worlds.formats.stage import load_stage_world, parse_worldfile, type_chain

# The shared data folder beside the repository, or wherever SLAMTRIALS_SHARED points.
REAL = (
    Path(os.environ.get("SLAMTRIALS_SHARED", Path(__file__).resolve().parents[2].parent / "shared")) / "worlds" / "real"
)

# The bitmap: 20 x 10 px, a white margin of 2 px around a 16 x 6 px walled box (the part Stage
# scales), an interior wall with a door, and an L-shaped notch that makes the plan asymmetric.
BITMAP = np.full((10, 20), 255, dtype=np.uint8)
BITMAP[2:8, 2:18] = 0
BITMAP[3:7, 3:17] = 255
BITMAP[3:7, 9] = 0
BITMAP[5, 9] = 255  # door
BITMAP[3, 3:5] = 0  # notch in the top-left room
BITMAP[4, 3] = 0
CROP = BITMAP[2:8, 2:18] < 230  # what the world grid must show (16 x 6)

WORLD = """\
# a hand-written world
include "missing.inc"   # not there: skipped
resolution 0.02
interval_sim 100

define bot position
(
  size [0.3 0.3 0.2]
  drive "diff"
  ranger( sensor( range [0 30] fov 270 samples 541 ) )
)
define mybot bot ( color "red" )

window ( size [ 400 300 ] scale 10 )

floorplan
(
  name "lab"
  bitmap "maps/plan.png"   # relative to this file
  size [{sx} {sy} 1]
  pose [{px} {py} 0 {yaw}]
)

mybot( name "r0" pose [{rx} {ry} 0 {ryaw}] )
"""


def write_world(folder: Path, text: str | None = None, *, bitmap: np.ndarray = BITMAP, **values) -> Path:
    params = {"sx": 8, "sy": 3, "px": 2, "py": 1, "yaw": 0, "rx": 1.25, "ry": 0.75, "ryaw": 90}
    params.update(values)
    (folder / "maps").mkdir(exist_ok=True)
    Image.fromarray(bitmap).save(folder / "maps" / "plan.png")
    path = folder / "test.world"
    path.write_text((text or WORLD).format(**params))
    return path


def test_parser_reads_defines_models_and_properties(tmp_path):
    parsed = parse_worldfile(write_world(tmp_path))
    assert parsed.missing_includes == ["missing.inc"]
    assert parsed.props["resolution"].values == (0.02,)
    assert [m.type for m in parsed.models] == ["window", "floorplan", "mybot"]
    assert type_chain(parsed, "mybot") == ["mybot", "bot", "position"]
    bot = parsed.defines["bot"]
    assert bot.props["drive"].values == ("diff",)
    assert bot.children[0].type == "ranger" and bot.children[0].children[0].props["samples"].values == (541.0,)
    floor = parsed.models[1]
    assert floor.props["bitmap"].values == ("maps/plan.png",)
    assert floor.props["bitmap"].line == 19
    assert floor.props["size"].values == (8.0, 3.0, 1.0)


def test_includes_are_read_in_place_relative_to_the_including_file(tmp_path):
    (tmp_path / "inc" / "sub").mkdir(parents=True)
    (tmp_path / "inc" / "robots.inc").write_text(
        'include "sub/base.inc"\ndefine pioneer2dx pioneer_base ( color "red" )\nresolution 0.5\n'
    )
    (tmp_path / "inc" / "sub" / "base.inc").write_text("define pioneer_base position ( size [0.44 0.38 0.22] )\n")
    text = WORLD.replace('include "missing.inc"', 'include "inc/robots.inc"').replace(
        "mybot( name", 'pioneer2dx( name "p" pose [3 1 0 0] )\nmybot( name'
    )
    path = write_world(tmp_path, text)
    parsed = parse_worldfile(path)
    assert parsed.missing_includes == []
    assert type_chain(parsed, "pioneer2dx") == ["pioneer2dx", "pioneer_base", "position"]
    assert parsed.props["resolution"].values == (0.02,)  # set after the include: the file's own wins
    world = load_stage_world(path)
    np.testing.assert_allclose(world.start, [3.0, 1.0, 0.0])  # the first position model
    assert "missing_includes" not in world.metadata


def test_square_scale_keeps_the_cropped_bitmap_and_places_it(tmp_path):
    world = load_stage_world(write_world(tmp_path))
    assert world.name == "lab"
    assert world.resolution == pytest.approx(0.5)  # 8 m / 16 px = 3 m / 6 px
    np.testing.assert_array_equal(world.occupied, CROP)
    # the bounding box's centre is at the pose (2, 1): lower-left corner at (2 - 4, 1 - 1.5)
    np.testing.assert_allclose(world.origin, [-2.0, -0.5, 0.0])
    np.testing.assert_allclose(world.start, [1.25, 0.75, math.pi / 2])
    assert world.metadata["stage_scale"] == pytest.approx([0.5, 0.5])
    assert world.metadata["bitmap_bbox_px"] == [2, 2, 16, 6]
    assert "position" in world.metadata["start_from"]


def test_non_square_scale_resamples_to_the_finer_resolution(tmp_path):
    world = load_stage_world(write_world(tmp_path, sy=6))  # 0.5 m/px in x, 1.0 m/px in y
    assert world.resolution == pytest.approx(0.5)
    np.testing.assert_array_equal(world.occupied, np.repeat(CROP, 2, axis=0))
    np.testing.assert_allclose(world.origin, [-2.0, -2.0, 0.0])


def test_coarser_resolution_keeps_every_wall(tmp_path):
    world = load_stage_world(write_world(tmp_path), resolution=1.0)
    expected = CROP.reshape(3, 2, 8, 2).any(axis=(1, 3))
    assert world.resolution == 1.0
    np.testing.assert_array_equal(world.occupied, expected)
    assert world.occupied[1, 3]  # the 1-px interior wall (crop column 7) survives


def model_frame_centres(res: float, sx: float, sy: float) -> np.ndarray:
    """Centres [6, 16, 2] of the crop's pixels in the floorplan model's frame (bbox centred at 0)."""
    rows, cols = np.indices(CROP.shape)
    return np.stack([-sx / 2 + (cols + 0.5) * res, sy / 2 - (rows + 0.5) * res], axis=-1)


@pytest.mark.parametrize("yaw", [90, -90, 180, 30])
def test_yaw_rotates_the_plan_about_its_pose(tmp_path, yaw):
    world = load_stage_world(write_world(tmp_path, yaw=yaw, px=5, py=-3, rx=5, ry=-3))
    local = model_frame_centres(0.5, 8, 3)
    a = math.radians(yaw)
    xy = np.stack(
        [
            5 + math.cos(a) * local[..., 0] - math.sin(a) * local[..., 1],
            -3 + math.sin(a) * local[..., 0] + math.cos(a) * local[..., 1],
        ],
        axis=-1,
    )
    rows, cols = world_to_cell(world, xy)
    assert rows.min() >= 0 and cols.min() >= 0
    np.testing.assert_array_equal(world.occupied[rows, cols], CROP)
    if yaw % 90 == 0:
        assert world.origin[2] == 0.0  # applied by rotating the grid
        assert sorted(world.occupied.shape) == [6, 16]
    else:
        assert world.origin[2] == pytest.approx(a)


def test_stage2_pose_and_units(tmp_path):
    text = WORLD.replace("pose [{px} {py} 0 {yaw}]", "pose [{px} {py} {yaw}]").replace(
        "resolution 0.02", 'unit_length "cm"\nunit_angle "radians"'
    )
    world = load_stage_world(
        write_world(tmp_path, text, sx=800, sy=300, px=200, py=100, yaw=0, rx=125, ry=75, ryaw=1.5)
    )
    assert world.resolution == pytest.approx(0.5)
    np.testing.assert_allclose(world.origin, [-2.0, -0.5, 0.0])
    np.testing.assert_allclose(world.start, [1.25, 0.75, 1.5])


def test_stage_obstacle_rule_decides_the_bounding_box(tmp_path):
    light = BITMAP.copy()
    light[0, 0] = 128  # not an obstacle for Stage: the scale is unchanged
    world = load_stage_world(write_world(tmp_path, bitmap=light))
    assert world.metadata["bitmap_bbox_px"] == [2, 2, 16, 6]
    dark = BITMAP.copy()
    dark[0, 0] = 127  # an obstacle: the box grows to 18 x 8 px
    world = load_stage_world(write_world(tmp_path, bitmap=dark))
    assert world.metadata["bitmap_bbox_px"] == [0, 0, 18, 8]
    assert world.metadata["stage_scale"] == pytest.approx([8 / 18, 3 / 8])


def test_position_model_wins_over_a_name_hint(tmp_path):
    text = WORLD.replace("mybot( name", 'pioneer2dx( name "p" pose [3 1 0 0] )\nmybot( name')
    world = load_stage_world(write_world(tmp_path, text))
    np.testing.assert_allclose(world.start, [1.25, 0.75, math.pi / 2])


def test_unresolved_robot_type_is_found_by_name(tmp_path):
    text = WORLD.replace(
        "mybot( name", 'define autorob fancypioneer2dx ( color "red" )\ntable( pose [0 0 0 0] )\nautorob( name'
    )
    text = text.replace("define mybot bot", "define mybot model")
    world = load_stage_world(write_world(tmp_path, text))
    np.testing.assert_allclose(world.start, [1.25, 0.75, math.pi / 2])
    assert "autorob" in world.metadata["start_from"]


def test_no_robot_means_an_automatic_start(tmp_path):
    text = WORLD.split("mybot( name")[0]
    world = load_stage_world(write_world(tmp_path, text))
    assert world.metadata["start_from"] == "automatic"
    r, c = world_to_cell(world, world.start[:2])
    assert not world.occupied[r, c]


def test_robot_in_a_wall_falls_back_to_an_automatic_start(tmp_path):
    world = load_stage_world(write_world(tmp_path, rx=-1.75, ry=0.75))  # on the left outer wall
    r, c = world_to_cell(world, world.start[:2])
    assert not world.occupied[r, c]
    assert world.metadata["start_from"].startswith("automatic")


def test_load_world_dispatches_world_files(tmp_path):
    world = load_world(write_world(tmp_path), name="x")
    assert world.name == "x" and world.metadata["format"] == "stage"


def test_missing_bitmap_names_world_file_line_and_bitmap(tmp_path):
    path = write_world(tmp_path)
    (tmp_path / "maps" / "plan.png").unlink()
    with pytest.raises(FormatError, match="maps/plan.png") as info:
        load_stage_world(path)
    assert info.value.path == path and info.value.line == 19
    assert "test.world:19" in str(info.value)


@pytest.mark.parametrize(
    ("text", "line", "fragment"),
    [
        ('\nfloorplan\n(\n  bitmap "maps/plan.png"\n  size [8 3 1]\n', 2, "never closed"),
        ('floorplan ( bitmap "maps/plan.png" size [8 3 1 )\n', 1, "expected a number"),
        ("resolution 0.02\n)\n", 2, "without a matching"),
        ("resolution 0.02\nsize [1 2 @]\n", 2, "unexpected character"),
        ("include pioneer.inc\n", 1, "quoted include"),
        ('floorplan ( bitmap "maps/plan.png" )\n', 1, "no size"),
        ('floorplan ( bitmap "maps/plan.png" size [8] )\n', 1, "size"),
        ('floorplan ( bitmap "maps/plan.png" size [8 3 1] pose [1 2] )\n', 1, "pose"),
        ("floorplan ( size [8 3 1] )\n", None, "no floorplan"),
        ('unit_length "ft"\nfloorplan ( bitmap "maps/plan.png" size [8 3 1] )\n', 1, "unit_length"),
        ('unit_length []\nfloorplan ( bitmap "maps/plan.png" size [8 3 1] )\n', 1, "unit_length"),
        ("floorplan ( bitmap 5 size [8 3 1] )\n", 1, "bitmap"),
    ],
)
def test_malformed_worlds_are_format_errors_with_file_and_line(tmp_path, text, line, fragment):
    path = write_world(tmp_path, text)
    with pytest.raises(FormatError, match=fragment) as info:
        load_stage_world(path)
    assert "test.world" in str(info.value)
    assert info.value.line == line


def test_blank_bitmap_and_bad_options(tmp_path):
    path = write_world(tmp_path, bitmap=np.full((10, 20), 255, np.uint8))
    with pytest.raises(FormatError, match="no obstacle pixel"):
        load_stage_world(path)
    path = write_world(tmp_path)
    with pytest.raises(WorldError, match="resolution"):
        load_stage_world(path, resolution=0)
    with pytest.raises(FormatError, match="absent.world"):
        load_stage_world(tmp_path / "absent.world")


# ---------------------------------------------------------------- the real Stage worlds


def real_layout(tmp_path: Path, folder: str, world_rel: str, image: str, bitmap_rel: str) -> Path:
    """Copy a real source.world and its image so that the world's bitmap path resolves."""
    source = REAL / folder
    if not source.is_dir():
        pytest.skip(f"shared real maps not available at {REAL}")
    world_path = tmp_path / world_rel
    world_path.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(source / "source.world", world_path)
    bitmap_path = (world_path.parent / bitmap_rel).resolve()
    bitmap_path.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(source / image, bitmap_path)
    return world_path


def test_real_uoa_robotics_lab(tmp_path):
    path = real_layout(
        tmp_path,
        "uoa_robotics_lab",
        "worlds/uoa_robotics_lab.world",
        "uoa_robotics_lab.png",
        "bitmaps/uoa_robotics_lab.png",
    )
    world = load_stage_world(path)
    # Stage fits the wall bounding box, 505 x 1218 px, to 6.27 x 15.7 m (SOURCES.md)
    assert world.metadata["bitmap_bbox_px"][2:] == [505, 1218]
    assert world.metadata["stage_scale"] == pytest.approx([6.27 / 505, 15.7 / 1218])
    assert world.resolution == pytest.approx(6.27 / 505)
    assert world.size_m[0] == pytest.approx(6.27, abs=world.resolution)
    assert world.size_m[1] == pytest.approx(15.7, abs=world.resolution)
    np.testing.assert_allclose(world.start, [0.0, 0.0, 0.0])  # autorob "r0"
    assert "autorob" in world.metadata["start_from"]
    assert world.name == "uoa_robotics_lab"
    assert 75 < world.reachable_free().sum() * world.resolution**2 < 95  # ~84 m^2 in SOURCES.md


def test_real_willow_garage(tmp_path):
    path = real_layout(
        tmp_path, "willow_garage", "worlds/willow-pr2-5cm.world", "willow-full-0.05.pgm", "../maps/willow-full-0.05.pgm"
    )
    world = load_stage_world(path)
    assert world.resolution == pytest.approx(0.05)
    # yaw 90: the 1165 x 945 px image stands upright, centred at (-23.625, 29.125)
    assert world.occupied.shape == (1165, 945)
    np.testing.assert_allclose(world.origin, [-23.625 - 23.625, 29.125 - 29.125, 0.0], atol=1e-9)
    np.testing.assert_allclose(world.start, [-21.670, 47.120, math.radians(28.166)])
    assert world.metadata["start_from"].startswith("pr2")


def test_real_hospital(tmp_path):
    path = real_layout(
        tmp_path, "stage_hospital", "benchmark/hospital.world", "hospital.png", "../bitmaps/hospital.png"
    )
    world = load_stage_world(path)
    assert world.metadata["stage_scale"] == pytest.approx([140 / 3116, 60 / 1188])
    assert world.resolution == pytest.approx(140 / 3116)
    assert world.size_m[0] == pytest.approx(140, abs=world.resolution)
    assert world.size_m[1] == pytest.approx(60, abs=world.resolution)
    np.testing.assert_allclose(world.start, [-59.0, -15.0, 0.0])  # swarmbot "r0"


@pytest.mark.parametrize("folder", ["uoa_robotics_lab", "willow_garage", "stage_hospital"])
def test_real_source_world_in_place_reports_the_missing_bitmap(folder):
    path = REAL / folder / "source.world"
    if not path.is_file():
        pytest.skip(f"shared real maps not available at {REAL}")
    line = next(i for i, text in enumerate(path.read_text().splitlines(), 1) if text.strip().startswith("bitmap"))
    bitmap = path.read_text().splitlines()[line - 1].split('"')[1]
    with pytest.raises(FormatError) as info:
        load_stage_world(path)
    message = str(info.value)
    assert f"source.world:{line}:" in message and bitmap in message
