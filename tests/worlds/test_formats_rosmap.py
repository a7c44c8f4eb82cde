"""ROS map_server maps: map_server's classification, YAML keys, the slamtrials block, errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image

from slamtrials.errors import FormatError, WorldError
from slamtrials.worlds import World, cell_to_world, load_world, world_to_cell
from slamtrials.worlds.formats.rosmap import load_rosmap
from slamtrials.worlds.formats.rosmap_save import save_rosmap

RAMP = np.tile(np.arange(256, dtype=np.uint8), (2, 1))


def write_map(
    folder: Path, image: np.ndarray | None, yaml_text: str, *, image_name: str = "map.pgm", mode: str | None = None
) -> Path:
    if image is not None:
        picture = Image.fromarray(image, mode=mode) if mode else Image.fromarray(image)
        picture.save(folder / image_name)
    path = folder / "map.yaml"
    path.write_text(yaml_text)
    return path


def std_yaml(**override) -> str:
    doc = {
        "image": "map.pgm",
        "resolution": 0.05,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    doc.update(override)
    return "".join(
        f"{k}: {v if not isinstance(v, list) else '[' + ', '.join(map(str, v)) + ']'}\n"
        for k, v in doc.items()
        if v is not None
    )


def test_grey_ramp_is_classified_as_map_server_does(tmp_path):
    world = load_rosmap(write_map(tmp_path, RAMP, std_yaml()))
    # p = (255 - v) / 255 < 0.196  <=>  v >= 206 (205 gives p = 0.19608: unknown)
    np.testing.assert_array_equal(world.occupied[0], np.arange(256) < 206)
    # p > 0.65 <=> v <= 89
    assert world.metadata["occupied_pixels"] == 2 * 90
    assert world.metadata["unknown_pixels"] == 2 * (206 - 90)
    assert world.metadata["format"] == "rosmap"


def test_negate_flips_the_ramp(tmp_path):
    world = load_rosmap(write_map(tmp_path, RAMP, std_yaml(negate=1)))
    # p = v / 255 < 0.196 <=> v <= 49
    np.testing.assert_array_equal(world.occupied[0], np.arange(256) > 49)


def test_tight_thresholds_free_only_near_white(tmp_path):
    # the ipa320 maps' thresholds: pixels >= 250 free
    world = load_rosmap(write_map(tmp_path, RAMP, std_yaml(occupied_thresh=0.022, free_thresh=0.021)))
    np.testing.assert_array_equal(world.occupied[0], np.arange(256) < 250)


@pytest.mark.parametrize("mode", ["trinary", "scale"])
def test_scale_and_trinary_agree_on_free_cells(tmp_path, mode):
    world = load_rosmap(write_map(tmp_path, RAMP, std_yaml(mode=mode)))
    np.testing.assert_array_equal(world.occupied[0], np.arange(256) < 206)


def test_raw_mode_reads_pixel_values_as_occupancy_percent(tmp_path):
    world = load_rosmap(write_map(tmp_path, RAMP, std_yaml(mode="raw")))
    # value / 100 < 0.196 <=> value <= 19
    np.testing.assert_array_equal(world.occupied[0], np.arange(256) > 19)


def test_colour_channels_are_averaged(tmp_path):
    rgb = np.full((4, 4, 3), 255, np.uint8)
    rgb[0, 0] = (255, 255, 108)  # mean 206 -> free
    rgb[0, 1] = (255, 255, 105)  # mean 205 -> unknown
    rgb[0, 2] = (0, 0, 0)
    world = load_rosmap(write_map(tmp_path, rgb, std_yaml(image="map.png"), image_name="map.png"))
    assert world.occupied[0].tolist() == [False, True, True, False]


def test_alpha_is_averaged_in_trinary_mode_and_transparent_is_never_free(tmp_path):
    rgba = np.full((4, 4, 4), 255, np.uint8)
    rgba[0, 0] = (255, 255, 255, 0)  # (765 + 0) / 4 = 191.25 -> unknown
    rgba[0, 1] = (240, 240, 240, 200)  # (720 + 200) / 4 = 230 -> free
    rgba[0, 2] = (210, 210, 210, 180)  # (630 + 180) / 4 = 202.5 -> unknown (alone 210 would be free)
    path = write_map(tmp_path, rgba, std_yaml(image="map.png"), image_name="map.png")
    assert load_rosmap(path).occupied[0].tolist() == [True, False, True, False]
    # scale mode leaves alpha out of the mean, but a transparent pixel stays unknown
    path = write_map(tmp_path, rgba, std_yaml(image="map.png", mode="scale"), image_name="map.png")
    assert load_rosmap(path).occupied[0].tolist() == [True, False, False, False]


def test_grey_alpha_image_is_read_like_rgba(tmp_path):
    la = np.full((4, 4, 2), 255, np.uint8)
    la[0, 0] = (255, 0)  # (3 * 255 + 0) / 4 -> unknown
    la[0, 1] = (240, 255)  # (720 + 255) / 4 = 243.75 -> free
    path = write_map(tmp_path, la, std_yaml(image="map.png"), image_name="map.png", mode="LA")
    assert load_rosmap(path).occupied[0].tolist() == [True, False, False, False]


def test_resolution_and_origin_are_honoured(tmp_path):
    image = np.full((6, 8), 254, np.uint8)
    image[0, :] = 0
    world = load_rosmap(write_map(tmp_path, image, std_yaml(resolution=0.2, origin=[-3.5, 2.0, 0.0])))
    assert world.resolution == 0.2
    np.testing.assert_allclose(cell_to_world(world, 5, 0), [-3.5 + 0.1, 2.0 + 0.1])
    np.testing.assert_allclose(cell_to_world(world, 0, 7), [-3.5 + 1.5, 2.0 + 1.1])
    assert world.occupied[0].all() and not world.occupied[1:].any()
    rows, cols = np.indices(image.shape)
    back = world_to_cell(world, cell_to_world(world, rows, cols))
    np.testing.assert_array_equal(back[0], rows)
    np.testing.assert_array_equal(back[1], cols)


def test_origin_yaw_rotates_the_grid(tmp_path):
    image = np.full((6, 8), 254, np.uint8)
    world = load_rosmap(write_map(tmp_path, image, std_yaml(resolution=0.2, origin=[1.0, 2.0, math.pi / 2])))
    # the lower-left pixel's centre is (0.1, 0.1) in the map frame, rotated by +90 degrees
    np.testing.assert_allclose(cell_to_world(world, 5, 0), [1.0 - 0.1, 2.0 + 0.1])
    np.testing.assert_allclose(cell_to_world(world, 5, 7), [1.0 - 0.1, 2.0 + 1.5])


def test_name_defaults_to_folder_for_map_yaml_and_stem_otherwise(tmp_path):
    folder = tmp_path / "my_building"
    folder.mkdir()
    path = write_map(folder, RAMP, std_yaml())
    assert load_rosmap(path).name == "my_building"
    assert load_rosmap(path, name="other").name == "other"
    named = folder / "floor3.yaml"
    named.write_text(std_yaml())
    assert load_world(named).name == "floor3"


def test_image_path_is_relative_to_the_yaml_folder(tmp_path, monkeypatch):
    (tmp_path / "maps").mkdir()
    Image.fromarray(RAMP).save(tmp_path / "maps" / "ramp.pgm")
    path = tmp_path / "maps" / "map.yaml"
    path.write_text(std_yaml(image="ramp.pgm"))
    monkeypatch.chdir(tmp_path)
    world = load_rosmap(Path("maps/map.yaml"))
    np.testing.assert_array_equal(world.occupied[0], np.arange(256) < 206)


def make_world() -> World:
    occupied = np.ones((12, 16), dtype=bool)
    occupied[1:-1, 1:-1] = False
    occupied[1:8, 7] = True
    occupied[5, 3:5] = True
    return World(
        occupied,
        0.05,
        np.array([-1.2, 3.4, 0.0]),
        name="office",
        start=np.array([-1.2 + 2.5 * 0.05, 3.4 + 9.5 * 0.05, 0.75]),
        metadata={"source": "generator", "format": "generated", "seed": 7, "building": {"rooms": [2, 3]}},
    )


def test_save_then_load_round_trip_is_identical(tmp_path):
    original = make_world()
    path = save_rosmap(original, tmp_path / "office.yaml")
    loaded = load_rosmap(path)
    np.testing.assert_array_equal(loaded.occupied, original.occupied)
    assert loaded.resolution == original.resolution
    np.testing.assert_allclose(loaded.origin, original.origin)
    np.testing.assert_allclose(loaded.start, original.start, atol=1e-6)
    assert loaded.name == "office"
    assert loaded.metadata == original.metadata
    # through load_world too, and a world without metadata gets its source recorded
    bare = World(original.occupied, 0.1)
    path = save_rosmap(bare, tmp_path / "bare.yaml")
    again = load_world(path)
    np.testing.assert_array_equal(again.occupied, bare.occupied)
    np.testing.assert_allclose(again.start, bare.start, atol=1e-6)
    assert again.metadata == {"source": str(path), "format": "rosmap"}


def test_bad_slamtrials_block_names_the_line(tmp_path):
    text = std_yaml() + "slamtrials:\n  name: x\n  start: [1.0, 2.0]\n"
    with pytest.raises(FormatError, match=r"map.yaml:9: slamtrials.start") as info:
        load_rosmap(write_map(tmp_path, RAMP, text))
    assert info.value.line == 9
    text = std_yaml() + "slamtrials:\n  metadata: [1, 2]\n"
    with pytest.raises(FormatError, match="slamtrials.metadata"):
        load_rosmap(write_map(tmp_path, RAMP, text))


@pytest.mark.parametrize(
    ("override", "key", "line"),
    [
        ({"resolution": 0}, "resolution", 2),
        ({"resolution": -0.05}, "resolution", 2),
        ({"resolution": "abc"}, "resolution", 2),
        ({"resolution": "true"}, "resolution", 2),
        ({"origin": [1.0]}, "origin", 3),
        ({"origin": "here"}, "origin", 3),
        ({"negate": 2}, "negate", 4),
        ({"free_thresh": 0.7}, "free_thresh", 6),
        ({"occupied_thresh": 1.5}, "occupied_thresh", 5),
        ({"free_thresh": -0.1}, "free_thresh", 6),
        ({"free_thresh": "low"}, "free_thresh", 6),
        ({"image": "absent.pgm"}, "image", 1),
        ({"mode": "fancy"}, "mode", 7),
    ],
)
def test_bad_values_name_file_line_and_key(tmp_path, override, key, line):
    path = write_map(tmp_path, RAMP, std_yaml(**override))
    with pytest.raises(FormatError) as info:
        load_rosmap(path)
    message = str(info.value)
    assert "map.yaml" in message and key in message
    assert info.value.line == line
    assert f"map.yaml:{line}:" in message


@pytest.mark.parametrize("missing", ["image", "resolution", "origin"])
def test_missing_keys_are_named(tmp_path, missing):
    path = write_map(tmp_path, RAMP, std_yaml(**{missing: None}))
    with pytest.raises(FormatError, match=rf"map.yaml.*{missing}"):
        load_rosmap(path)


def test_missing_image_names_the_image(tmp_path):
    path = write_map(tmp_path, None, std_yaml(image="gone.pgm"))
    with pytest.raises(FormatError, match="gone.pgm") as info:
        load_rosmap(path)
    assert info.value.path.name == "map.yaml" and info.value.line == 1


def test_yaml_syntax_error_and_non_mapping(tmp_path):
    path = write_map(tmp_path, RAMP, "image: map.pgm\nresolution: [0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(FormatError, match="map.yaml") as info:
        load_rosmap(path)
    assert info.value.line is not None
    path.write_text("- image\n- resolution\n")
    with pytest.raises(FormatError, match="mapping"):
        load_rosmap(path)
    with pytest.raises(FormatError, match="nowhere.yaml"):
        load_rosmap(tmp_path / "nowhere.yaml")


def test_map_without_free_space(tmp_path):
    path = write_map(tmp_path, np.zeros((5, 5), np.uint8), std_yaml())
    with pytest.raises(WorldError, match="map.yaml"):
        load_rosmap(path)
    path = write_map(tmp_path, np.full((5, 5), 205, np.uint8), std_yaml())
    with pytest.raises(WorldError, match="no free space"):
        load_rosmap(path)


def test_truncated_image_names_the_image(tmp_path):
    Image.fromarray(np.random.default_rng(1).integers(0, 256, (64, 64), dtype=np.uint8)).save(tmp_path / "full.png")
    (tmp_path / "cut.png").write_bytes((tmp_path / "full.png").read_bytes()[:100])
    path = write_map(tmp_path, None, std_yaml(image="cut.png"))
    with pytest.raises(FormatError, match="cut.png"):
        load_rosmap(path)


def test_saved_yaml_is_plain_map_server_yaml(tmp_path):
    path = save_rosmap(make_world(), tmp_path / "office.yaml")
    doc = yaml.safe_load(path.read_text())
    assert {"image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh"} <= set(doc)
