"""Bare floor-plan images: pixel classification, modes, resolution/origin, malformed input."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from slamtrials.errors import FormatError, SlamtrialsError, WorldError
from slamtrials.worlds import cell_to_world, load_world, world_to_cell
from slamtrials.worlds.formats.image import load_image

FREE, WALL, UNKNOWN = 255, 0, 205

# 10 wide x 8 high: outer walls, an interior wall with a door, an unknown patch and a dark-grey pillar.
LAYOUT = np.full((8, 10), FREE, dtype=np.uint8)
LAYOUT[0, :] = LAYOUT[-1, :] = LAYOUT[:, 0] = LAYOUT[:, -1] = WALL
LAYOUT[1:7, 5] = WALL
LAYOUT[4, 5] = FREE  # door
LAYOUT[1:3, 7:9] = UNKNOWN
LAYOUT[5, 2] = 100  # dark grey: wall
LAYOUT[6, 8] = 240  # light grey: free (>= 0.9 * 255)
EXPECTED = np.zeros((8, 10), dtype=bool)
EXPECTED[0, :] = EXPECTED[-1, :] = EXPECTED[:, 0] = EXPECTED[:, -1] = True
EXPECTED[1:7, 5] = True
EXPECTED[4, 5] = False
EXPECTED[1:3, 7:9] = True
EXPECTED[5, 2] = True


def save(path: Path, array: np.ndarray) -> Path:
    Image.fromarray(array).save(path)
    return path


def test_known_layout_gives_exactly_those_occupied_cells(tmp_path):
    world = load_image(save(tmp_path / "plan.png", LAYOUT), resolution=0.1)
    assert world.occupied.shape == (8, 10)
    np.testing.assert_array_equal(world.occupied, EXPECTED)
    assert world.name == "plan"
    assert world.metadata["format"] == "image"
    assert world.metadata["source"].endswith("plan.png")
    # walls: 0 and 100 are < 0.5; unknown: the four 205 pixels
    assert world.metadata["wall_pixels"] == int(np.count_nonzero(LAYOUT < 128))
    assert world.metadata["unknown_pixels"] == 4


def test_resolution_and_origin_place_every_cell(tmp_path):
    res, origin = 0.25, (1.0, -2.0, 0.0)
    world = load_image(save(tmp_path / "plan.png", LAYOUT), resolution=res, origin=origin)
    rows, cols = np.indices(LAYOUT.shape)
    xy = cell_to_world(world, rows, cols)
    # cell (row, col) centre: x = x0 + (col + 0.5) res, y = y0 + (H - row - 0.5) res
    np.testing.assert_allclose(xy[..., 0], 1.0 + (cols + 0.5) * res)
    np.testing.assert_allclose(xy[..., 1], -2.0 + (8 - rows - 0.5) * res)
    back_r, back_c = world_to_cell(world, xy)
    np.testing.assert_array_equal(back_r, rows)
    np.testing.assert_array_equal(back_c, cols)
    # just inside the lower-left corner is the bottom-left pixel
    r, c = world_to_cell(world, [1.0 + 1e-6, -2.0 + 1e-6])
    assert (int(r), int(c)) == (7, 0)


def test_two_origin_numbers_mean_zero_yaw(tmp_path):
    world = load_image(save(tmp_path / "plan.png", LAYOUT), resolution=0.1, origin=(3, 4))
    np.testing.assert_array_equal(world.origin, [3.0, 4.0, 0.0])


def grey_ramp() -> np.ndarray:
    return np.tile(np.arange(256, dtype=np.uint8), (2, 1))


def test_grey_ramp_free_only_at_or_above_free_level(tmp_path):
    world = load_image(save(tmp_path / "ramp.png", grey_ramp()), resolution=0.05)
    values = np.arange(256)
    # 0.9 * 255 = 229.5: 230 and brighter are free
    np.testing.assert_array_equal(world.occupied[0], values < 230)
    assert world.metadata["wall_pixels"] == 2 * 128  # 0..127 are darker than 0.5
    assert world.metadata["unknown_pixels"] == 2 * (230 - 128)


def test_free_level_equal_threshold_is_a_two_level_split(tmp_path):
    world = load_image(save(tmp_path / "ramp.png", grey_ramp()), resolution=0.05, threshold=0.5, free_level=0.5)
    np.testing.assert_array_equal(world.occupied[0], np.arange(256) < 128)
    assert world.metadata["unknown_pixels"] == 0


def test_threshold_above_free_level_is_rejected(tmp_path):
    path = save(tmp_path / "ramp.png", grey_ramp())
    with pytest.raises(WorldError, match="threshold"):
        load_image(path, resolution=0.05, threshold=0.95)
    with pytest.raises(WorldError, match="free_level"):
        load_image(path, resolution=0.05, free_level=1.5)


def test_negate_swaps_black_and_white(tmp_path):
    world = load_image(save(tmp_path / "plan.png", 255 - LAYOUT), resolution=0.1, negate=True)
    np.testing.assert_array_equal(world.occupied, EXPECTED)


def to_rgb(layout: np.ndarray) -> np.ndarray:
    return np.repeat(layout[:, :, None], 3, axis=2)


@pytest.mark.parametrize("kind", ["pgm", "png16", "pgm16", "palette", "rgb", "rgba", "la", "bilevel"])
def test_pixel_modes_load_the_same_plan(tmp_path, kind):
    layout = LAYOUT
    if kind == "pgm":
        path = save(tmp_path / "plan.pgm", layout)
    elif kind == "png16":
        path = save(tmp_path / "plan.png", layout.astype(np.uint16) * 257)
        assert Image.open(path).mode.startswith("I")
    elif kind == "pgm16":
        path = save(tmp_path / "plan.pgm", layout.astype(np.uint16) * 257)
    elif kind == "palette":
        path = tmp_path / "plan.png"
        Image.fromarray(layout).convert("P").save(path)
        assert Image.open(path).mode == "P"
    elif kind == "rgb":
        path = save(tmp_path / "plan.png", to_rgb(layout))
    elif kind == "rgba":
        path = save(tmp_path / "plan.png", np.dstack([to_rgb(layout), np.full(layout.shape, 255, np.uint8)]))
    elif kind == "la":
        path = tmp_path / "plan.png"
        Image.fromarray(np.dstack([layout, np.full(layout.shape, 255, np.uint8)]), mode="LA").save(path)
    else:  # 1-bit: unknown has no place, so compare with a black/white version
        layout = np.where(EXPECTED, 0, 255).astype(np.uint8)
        path = tmp_path / "plan.png"
        Image.fromarray(layout).convert("1").save(path)
        assert Image.open(path).mode == "1"
    world = load_image(path, resolution=0.1)
    np.testing.assert_array_equal(world.occupied, EXPECTED)


def test_transparent_pixels_are_unknown_whatever_their_colour(tmp_path):
    rgba = np.dstack([to_rgb(LAYOUT), np.full(LAYOUT.shape, 255, np.uint8)])
    rgba[2:4, 2:4, 3] = 0  # white but fully transparent
    rgba[6, 2, 3] = 128  # white, half transparent: still free
    world = load_image(save(tmp_path / "plan.png", rgba), resolution=0.1)
    expected = EXPECTED.copy()
    expected[2:4, 2:4] = True
    np.testing.assert_array_equal(world.occupied, expected)
    assert world.metadata["unknown_pixels"] == 4 + 4


def test_colour_pixels_use_the_mean_of_the_channels(tmp_path):
    rgb = to_rgb(LAYOUT)
    rgb[3, 2] = (255, 255, 180)  # mean 230 -> free
    rgb[3, 3] = (255, 255, 170)  # mean 226.7 -> not free
    world = load_image(save(tmp_path / "plan.png", rgb), resolution=0.1)
    assert not world.occupied[3, 2]
    assert world.occupied[3, 3]


@pytest.mark.parametrize("resolution", [None, 0, -0.05, math.nan, math.inf, "abc", True])
def test_bad_resolution_is_a_world_error_naming_the_file(tmp_path, resolution):
    path = save(tmp_path / "needs_scale.png", LAYOUT)
    with pytest.raises(WorldError, match="needs_scale.png"):
        load_image(path, resolution=resolution)


def test_load_world_without_resolution_says_what_is_missing(tmp_path):
    path = save(tmp_path / "needs_scale.png", LAYOUT)
    with pytest.raises(WorldError, match="resolution"):
        load_world(path)


def test_load_world_dispatches_png_and_pgm(tmp_path):
    for suffix in ("png", "pgm"):
        world = load_world(save(tmp_path / f"plan.{suffix}", LAYOUT), resolution=0.1, name="p")
        np.testing.assert_array_equal(world.occupied, EXPECTED)
        assert world.name == "p"


def test_truncated_png_is_a_format_error_naming_the_file(tmp_path):
    full = save(tmp_path / "full.png", np.random.default_rng(0).integers(0, 256, (64, 64), dtype=np.uint8))
    cut = tmp_path / "truncated.png"
    cut.write_bytes(full.read_bytes()[:100])
    with pytest.raises(FormatError, match="truncated.png") as info:
        load_image(cut, resolution=0.05)
    assert isinstance(info.value, SlamtrialsError)


def test_not_an_image_and_missing_file_are_format_errors(tmp_path):
    text = tmp_path / "notes.png"
    text.write_text("this is not a picture\n")
    with pytest.raises(FormatError, match="notes.png"):
        load_image(text, resolution=0.05)
    with pytest.raises(FormatError, match="absent.png"):
        load_image(tmp_path / "absent.png", resolution=0.05)


def test_all_black_image_has_no_free_space(tmp_path):
    path = save(tmp_path / "black.png", np.zeros((8, 10), np.uint8))
    with pytest.raises(WorldError, match="black.png"):
        load_image(path, resolution=0.05)
    grey = save(tmp_path / "unknown.png", np.full((8, 10), UNKNOWN, np.uint8))
    with pytest.raises(WorldError, match="unknown.png"):
        load_image(grey, resolution=0.05)


def test_start_pose_is_honoured_and_checked(tmp_path):
    path = save(tmp_path / "plan.png", LAYOUT)
    world = load_image(path, resolution=0.1, start=(0.25, 0.35, 1.0))
    np.testing.assert_allclose(world.start, [0.25, 0.35, 1.0])
    r, c = world_to_cell(world, world.start[:2])
    assert not world.occupied[r, c]
    with pytest.raises(WorldError):
        load_image(path, resolution=0.1, start=(0.05, 0.05, 0.0))  # bottom-left wall pixel
    with pytest.raises(WorldError, match="origin"):
        load_image(path, resolution=0.1, origin=("a", "b"))


def test_automatic_start_is_in_free_space(tmp_path):
    world = load_image(save(tmp_path / "plan.png", LAYOUT), resolution=0.1)
    r, c = world_to_cell(world, world.start[:2])
    assert not world.occupied[r, c]
