"""SLAM maps as map_server files: map_saver's trinary classification, exact round trip, readable as a world."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from PIL import Image

from slamtrials.errors import FormatError
from slamtrials.io.mapfile import (
    FREE,
    FREE_GREY,
    OCCUPIED,
    OCCUPIED_GREY,
    UNKNOWN,
    UNKNOWN_GREY,
    read_map,
    trinary,
    write_map,
    write_map_png,
)
from slamtrials.worlds import load_world


def _slam_grid(seed: int = 0) -> np.ndarray:
    """A 40 x 60 int8 OccupancyGrid-like map: free room, walls, unknown outside, noisy in-between cells."""
    rng = np.random.default_rng(seed)
    grid = np.full((40, 60), -1, dtype=np.int8)
    grid[5:35, 5:55] = rng.integers(0, 101, (30, 50))
    grid[10:30, 10:50] = 0
    grid[5, 5:55] = 100
    return grid


def test_map_saver_thresholds():
    percent = np.array([[-1, 0, 25, 26, 64, 65, 100, -128]], dtype=np.int8)
    np.testing.assert_array_equal(
        trinary(percent), [[UNKNOWN, FREE, FREE, UNKNOWN, UNKNOWN, OCCUPIED, OCCUPIED, UNKNOWN]]
    )
    probability = np.array([[np.nan, 0.0, 0.25, 0.2500001, 0.6499, 0.65, 1.0, -0.5]])
    np.testing.assert_array_equal(
        trinary(probability), [[UNKNOWN, FREE, FREE, UNKNOWN, UNKNOWN, OCCUPIED, OCCUPIED, UNKNOWN]]
    )
    np.testing.assert_array_equal(trinary(np.array([[True, False]])), [[OCCUPIED, FREE]])
    with pytest.raises(ValueError, match="2-D"):
        trinary(np.zeros(3))


def test_yaml_and_pgm_are_those_of_map_saver(tmp_path):
    grid = _slam_grid()
    path = write_map(tmp_path / "map.yaml", grid, 0.05, [-1.5, 2.25, 0.0])
    doc = yaml.safe_load(path.read_text())
    assert doc == {
        "image": "map.pgm",
        "resolution": 0.05,
        "origin": [-1.5, 2.25, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
        "mode": "trinary",
    }
    data = (tmp_path / "map.pgm").read_bytes()
    assert data.startswith(b"P5\n# CREATOR: slamtrials 0.050 m/pix\n60 40\n255\n")
    pixels = np.asarray(Image.open(tmp_path / "map.pgm"))
    assert pixels.shape == (40, 60) and set(np.unique(pixels)) <= {FREE_GREY, OCCUPIED_GREY, UNKNOWN_GREY}
    expected = np.select([trinary(grid) == FREE, trinary(grid) == OCCUPIED], [FREE_GREY, OCCUPIED_GREY], UNKNOWN_GREY)
    np.testing.assert_array_equal(pixels, expected)  # row 0 of the grid is the top row of the picture
    assert pixels[5, 20] == OCCUPIED_GREY and pixels[0, 0] == UNKNOWN_GREY and pixels[20, 20] == FREE_GREY


@pytest.mark.parametrize("image", [None, "picture.png"])
def test_round_trip_gives_the_trinary_grid(tmp_path, image):
    grid = _slam_grid(1)
    write_map(tmp_path / "map.yaml", grid, 0.1, (3.0, -4.0, 0.5), image=image)
    back = read_map(tmp_path / "map.yaml")
    assert back.grid.dtype == np.int8
    np.testing.assert_array_equal(back.grid, trinary(grid))
    assert back.resolution == 0.1
    np.testing.assert_array_equal(back.origin, [3.0, -4.0, 0.5])


def test_probability_grids_round_trip(tmp_path):
    rng = np.random.default_rng(2)
    grid = rng.random((30, 30))
    grid[rng.random((30, 30)) < 0.2] = np.nan
    write_map(tmp_path / "map.yaml", grid, 0.05, (0.0, 0.0))
    np.testing.assert_array_equal(read_map(tmp_path / "map.yaml").grid, trinary(grid))


def test_load_world_reads_the_same_free_cells(tmp_path):
    grid = _slam_grid(3)
    write_map(tmp_path / "slam.yaml", grid, 0.05, (-1.0, -2.0, 0.0))
    world = load_world(tmp_path / "slam.yaml")
    cells = trinary(grid)
    np.testing.assert_array_equal(world.occupied, cells != FREE)  # unknown counts as occupied for a world
    assert world.resolution == 0.05
    np.testing.assert_array_equal(world.origin, [-1.0, -2.0, 0.0])
    assert world.metadata["occupied_pixels"] == np.count_nonzero(cells == OCCUPIED)
    assert world.metadata["unknown_pixels"] == np.count_nonzero(cells == UNKNOWN)


def test_png_picture(tmp_path):
    grid = _slam_grid(4)
    write_map_png(tmp_path / "map.png", grid)
    with Image.open(tmp_path / "map.png") as image:
        assert image.mode == "L"
        pixels = np.asarray(image)
    np.testing.assert_array_equal(pixels == FREE_GREY, trinary(grid) == FREE)
    np.testing.assert_array_equal(pixels == OCCUPIED_GREY, trinary(grid) == OCCUPIED)


def test_bad_arguments(tmp_path):
    with pytest.raises(ValueError, match="resolution"):
        write_map(tmp_path / "m.yaml", _slam_grid(), 0.0, (0, 0))
    with pytest.raises(ValueError, match="origin"):
        write_map(tmp_path / "m.yaml", _slam_grid(), 0.05, (0, 0, 0, 0))
    with pytest.raises(ValueError, match=".pgm or .png"):
        write_map(tmp_path / "m.yaml", _slam_grid(), 0.05, (0, 0), image="m.jpg")
    assert not list(tmp_path.iterdir())


def test_read_errors_name_the_file(tmp_path):
    with pytest.raises(FormatError, match="missing.yaml"):
        read_map(tmp_path / "missing.yaml")
    write_map(tmp_path / "map.yaml", _slam_grid(), 0.05, (0, 0))
    text = (tmp_path / "map.yaml").read_text()
    (tmp_path / "a.yaml").write_text(text.replace("resolution: 0.05", "resolution: -1"))
    with pytest.raises(FormatError, match="a.yaml.*resolution"):
        read_map(tmp_path / "a.yaml")
    (tmp_path / "b.yaml").write_text(text.replace("origin: [0.0, 0.0, 0.0]", "origin: [0, x]"))
    with pytest.raises(FormatError, match="b.yaml.*origin"):
        read_map(tmp_path / "b.yaml")
    (tmp_path / "c.yaml").write_text(text.replace("image: map.pgm", "image: gone.pgm"))
    with pytest.raises(FormatError, match="gone.pgm"):
        read_map(tmp_path / "c.yaml")
    (tmp_path / "d.yaml").write_text("image: map.pgm\n")
    with pytest.raises(FormatError, match="d.yaml.*resolution, origin"):
        read_map(tmp_path / "d.yaml")
    (tmp_path / "map.pgm").write_bytes(b"P5\n60 40\n255\n\x00")
    with pytest.raises(FormatError, match="map.pgm"):
        read_map(tmp_path / "map.yaml")
