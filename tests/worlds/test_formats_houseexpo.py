"""HouseExpo JSON layouts: rasterization of the free-space polygon, frame, metadata, errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from matplotlib.path import Path as PolygonPath
from scipy import ndimage

from slamtrials.errors import FormatError, WorldError
from slamtrials.worlds import cell_to_world, load_world
from slamtrials.worlds.formats.houseexpo import MARGIN_CELLS, load_houseexpo

# A 6 x 4 m house: two rooms split by a wall 2 cm thick (x = 2.99 .. 3.01) that leaves a 1 m door at
# the bottom, plus a 1 x 1 m cut-out in the top-right corner.
HOUSE = [[0, 0], [6, 0], [6, 3], [5, 3], [5, 4], [3.01, 4], [3.01, 1], [2.99, 1], [2.99, 4], [0, 4]]


def write(path: Path, doc) -> Path:
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc, indent=1))
    return path


def house_doc(verts=HOUSE) -> dict:
    xs, ys = [v[0] for v in verts], [v[1] for v in verts]
    return {
        "id": "0a1b2c",
        "room_num": 2,
        "bbox": {"min": [min(xs), min(ys)], "max": [max(xs), max(ys)]},
        "verts": verts,
        "room_category": {"bedroom": [[0, 0, 3, 4]], "kitchen": [[3, 0, 6, 4]]},
    }


def cell_centres(world) -> np.ndarray:
    rows, cols = np.indices(world.occupied.shape)
    return cell_to_world(world, rows, cols)


def test_free_cells_are_exactly_the_polygon_interior_minus_the_edge_cells(tmp_path):
    world = load_houseexpo(write(tmp_path / "house.json", house_doc()), resolution=0.1)
    centres = cell_centres(world).reshape(-1, 2)
    inside = PolygonPath(np.array(HOUSE, float)).contains_points(centres).reshape(world.occupied.shape)
    free = ~world.occupied
    assert not (free & ~inside).any(), "a free cell lies outside the polygon"
    # distance from each cell centre to the polygon boundary, via a fine raster of the boundary
    far_inside = inside & (ndimage.distance_transform_edt(inside) * world.resolution > 1.5 * world.resolution)
    assert free[far_inside].all(), "a cell well inside the polygon is not free"
    # the area lost to the one-cell wall along the edges is about half a cell per metre of edge
    perimeter = 2 * (6 + 4) + 2 * 3  # outer box plus both faces of the 3 m internal wall
    assert world.free_area == pytest.approx(6 * 4 - 1 - 0.02 * 3 - 0.5 * 0.1 * perimeter, abs=0.6)


def test_thin_interior_wall_blocks_and_door_connects(tmp_path):
    world = load_houseexpo(write(tmp_path / "house.json", house_doc()), resolution=0.05)
    labels, count = ndimage.label(~world.occupied)
    assert count == 1  # both rooms connected through the door
    # at y = 2.5 m the row crossing x = 3 has a wall cell between the rooms
    ys = cell_centres(world)[:, 0, 1]
    row = int(np.argmin(abs(ys - 2.5)))
    xs = cell_centres(world)[row, :, 0]
    between = (xs > 2.9) & (xs < 3.1)
    assert world.occupied[row, between].any()
    left, right = int(np.argmin(abs(xs - 2.8))), int(np.argmin(abs(xs - 3.2)))
    assert not world.occupied[row, left] and not world.occupied[row, right]


def test_grid_frame_margin_and_metadata(tmp_path):
    world = load_houseexpo(write(tmp_path / "house.json", house_doc()))
    res = 0.05
    assert world.resolution == res
    # 6 x 4 m plus one cell (edges through cell centres) plus the margin on both sides
    assert world.occupied.shape == (round(4 / res) + 1 + 2 * MARGIN_CELLS, round(6 / res) + 1 + 2 * MARGIN_CELLS)
    np.testing.assert_allclose(world.origin, [-(MARGIN_CELLS + 0.5) * res, -(MARGIN_CELLS + 0.5) * res, 0.0])
    border = np.concatenate(
        [
            world.occupied[: MARGIN_CELLS + 1].ravel(),
            world.occupied[-MARGIN_CELLS - 1 :].ravel(),
            world.occupied[:, : MARGIN_CELLS + 1].ravel(),
            world.occupied[:, -MARGIN_CELLS - 1 :].ravel(),
        ]
    )
    assert border.all()
    assert world.name == "0a1b2c"
    assert world.metadata["format"] == "houseexpo" and world.metadata["room_num"] == 2
    assert set(world.metadata["room_category"]) == {"bedroom", "kitchen"}
    json.dumps(world.metadata)


def test_translated_polygon_translates_the_grid(tmp_path):
    base = load_houseexpo(write(tmp_path / "a.json", house_doc()), resolution=0.1)
    moved = load_houseexpo(
        write(tmp_path / "b.json", house_doc([[x + 12.5, y - 7.25] for x, y in HOUSE])), resolution=0.1
    )
    np.testing.assert_array_equal(base.occupied, moved.occupied)
    np.testing.assert_allclose(moved.origin[:2], base.origin[:2] + [12.5, -7.25])


def test_closed_ring_and_load_world(tmp_path):
    ring = HOUSE + [HOUSE[0]]
    a = load_houseexpo(write(tmp_path / "ring.json", house_doc(ring)), resolution=0.1)
    b = load_world(write(tmp_path / "open.json", house_doc()), resolution=0.1, name="h")
    np.testing.assert_array_equal(a.occupied, b.occupied)
    assert b.name == "h"


@pytest.mark.parametrize(
    ("doc", "fragment"),
    [
        ({"id": "x", "room_num": 1}, "no 'verts'"),
        ({"verts": []}, "non-empty"),
        ({"verts": "0 0 1 1"}, "non-empty list"),
        ({"verts": [[0, 0], [1, "a"], [1, 1]]}, "finite numbers"),
        ({"verts": [[0, 0], [1, 0, 5], [1, 1]]}, "pair"),
        ({"verts": [[0, 0], [1, 0]]}, "at least 3"),
        ({"verts": [[0, 0], [1, 1], [2, 2], [3, 3]]}, "no area"),
        ([1, 2, 3], "JSON object"),
    ],
)
def test_bad_layouts_are_format_errors_naming_the_file(tmp_path, doc, fragment):
    with pytest.raises(FormatError, match=fragment) as info:
        load_houseexpo(write(tmp_path / "bad_layout.json", doc))
    assert "bad_layout.json" in str(info.value)


def test_verts_error_points_at_the_verts_line(tmp_path):
    path = write(tmp_path / "layout.json", '{\n "id": "x",\n "verts": [[0, 0], [1, 0]]\n}\n')
    with pytest.raises(FormatError) as info:
        load_houseexpo(path)
    assert info.value.line == 3


def test_garbled_json_gives_the_line(tmp_path):
    path = write(tmp_path / "garbled.json", '{\n "id": "x",\n "verts": [[0, 0], [1, 0]\n "room_num": 2\n}\n')
    with pytest.raises(FormatError, match="garbled.json") as info:
        load_houseexpo(path)
    assert info.value.line == 4
    with pytest.raises(FormatError, match="missing.json"):
        load_houseexpo(tmp_path / "missing.json")


@pytest.mark.parametrize("resolution", [0, -0.05, math.nan])
def test_bad_resolution(tmp_path, resolution):
    with pytest.raises(WorldError, match="house.json"):
        load_houseexpo(write(tmp_path / "house.json", house_doc()), resolution=resolution)


def test_polygon_smaller_than_a_cell_has_no_free_space(tmp_path):
    path = write(tmp_path / "tiny.json", {"verts": [[0, 0], [0.04, 0], [0.04, 0.04], [0, 0.04]]})
    with pytest.raises(FormatError, match="no free cell"):
        load_houseexpo(path, resolution=0.05)
