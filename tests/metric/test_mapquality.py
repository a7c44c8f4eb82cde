"""Map quality on maps with known defects: a perfect map, a shifted room, a missing wall, free space outside
the building, a map in another frame, a map at another resolution; each checked against the definitions
computed by brute force."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from slamtrials.metric.mapquality import (
    DEFINITIONS,
    MAP_QUALITY_FIGURES,
    MAP_QUALITY_KEY,
    FloorPlan,
    MapQuality,
    map_quality,
)
from slamtrials.record import FREE, OCCUPIED, UNKNOWN, OccupancyGrid

from .mapplans import DOOR, ORIGIN, RES, RIGHT_ROOM, H, W, as_map, brute_force, perfect_grid, plan

IDENTITY = np.zeros(3)
PERFECT = {
    "occupied_precision_1": 1.0,
    "occupied_recall_1": 1.0,
    "occupied_precision_2": 1.0,
    "occupied_recall_2": 1.0,
    "free_iou": 1.0,
    "ghost_free_m2": 0.0,
}


def _figures(quality: MapQuality) -> dict[str, float | None]:
    return quality.figures()


def _agrees(quality: MapQuality, expected: dict[str, float | None]) -> None:
    for name, value in expected.items():
        got = getattr(quality, name)
        assert (got is None) == (value is None), name
        if value is not None:
            assert got == pytest.approx(value, abs=1e-12), name


def test_the_perfect_map_scores_one_and_no_ghost():
    truth = plan()
    quality = map_quality(as_map(perfect_grid(truth)), truth, IDENTITY, alignment_rms_m=0.0)
    assert _figures(quality) == PERFECT
    assert quality.cell_m == RES and quality.alignment_rms_m == 0.0


def test_a_room_shifted_by_three_cells_loses_precision_and_recall_less_so_at_two_cells():
    truth = plan()
    grid = perfect_grid(truth)
    shifted = np.full_like(grid, UNKNOWN)
    shifted[...] = grid
    room = grid[RIGHT_ROOM].copy()
    shifted[RIGHT_ROOM] = UNKNOWN
    rows, cols = RIGHT_ROOM
    shifted[rows, cols.start + 3 : cols.stop + 3] = room
    quality = map_quality(as_map(shifted), truth, IDENTITY)
    _agrees(quality, brute_force(shifted, truth))
    assert quality.occupied_precision_1 < 0.9 and quality.occupied_recall_1 < 0.9
    assert quality.occupied_precision_1 <= quality.occupied_precision_2 < 1.0
    assert quality.occupied_recall_1 < quality.occupied_recall_2 < 1.0
    assert quality.free_iou < 1.0 and quality.ghost_free_m2 > 0.0  # free space pushed into the outer wall


def test_a_room_shifted_by_two_cells_is_within_the_two_cell_tolerance():
    truth = plan()
    grid = perfect_grid(truth)
    shifted = grid.copy()
    shifted[RIGHT_ROOM] = UNKNOWN
    rows, cols = RIGHT_ROOM
    shifted[rows, cols.start + 2 : cols.stop + 2] = grid[RIGHT_ROOM]
    quality = map_quality(as_map(shifted), truth, IDENTITY)
    _agrees(quality, brute_force(shifted, truth))
    assert quality.occupied_precision_1 < 1.0 and quality.occupied_precision_2 == 1.0


def test_a_missing_wall_lowers_recall_and_keeps_precision():
    truth = plan()
    grid = perfect_grid(truth)
    grid[6:24, 20] = np.where(np.isin(np.arange(6, 24), list(DOOR)), FREE, UNKNOWN)  # the middle wall not mapped
    quality = map_quality(as_map(grid), truth, IDENTITY)
    _agrees(quality, brute_force(grid, truth))
    assert quality.occupied_precision_1 == 1.0 and quality.occupied_precision_2 == 1.0
    assert quality.occupied_recall_1 < 1.0 and quality.occupied_recall_2 < 1.0
    assert quality.free_iou == 1.0 and quality.ghost_free_m2 == 0.0


def test_free_space_outside_the_building_is_ghost_area_exactly():
    truth = plan()
    grid = perfect_grid(truth)
    grid[0:4, 0:5] = FREE  # 20 cells outside, 2 cells or more from the building's reachable space
    grid[10:12, 36:39] = FREE  # 6 more beyond the right outer wall
    quality = map_quality(as_map(grid), truth, IDENTITY)
    assert quality.ghost_free_m2 == pytest.approx(26 * RES * RES, abs=1e-12)
    reachable = float(np.count_nonzero(truth.reachable))
    assert quality.free_iou == pytest.approx(reachable / (reachable + 26))
    assert quality.occupied_precision_1 == 1.0 and quality.occupied_recall_1 == 1.0
    _agrees(quality, brute_force(grid, truth))


def test_free_space_inside_a_wall_next_to_the_room_is_not_ghost_but_beyond_it_is():
    truth = plan()
    grid = perfect_grid(truth)
    grid[10, 34] = FREE  # in the outer wall: one cell from the room
    grid[10, 35] = FREE  # just outside it: two cells
    quality = map_quality(as_map(grid), truth, IDENTITY)
    assert quality.ghost_free_m2 == pytest.approx(RES * RES, abs=1e-12)


def test_a_rotated_and_translated_map_with_its_alignment_scores_as_the_perfect_one():
    truth = plan()
    rotated = np.rot90(perfect_grid(truth))  # map cell (i, j) holds plan cell (j, W - 1 - i)
    a, b = 3.7, -1.2  # the map's origin in its own frame
    # a map point (u, v) from the map's lower-left corner is the plan point (v, H res - u) from the plan's
    world_from_map = np.array([ORIGIN[0] - b, ORIGIN[1] + H * RES + a, -math.pi / 2])
    quality = map_quality(as_map(rotated, origin=[a, b, 0.0]), truth, world_from_map)
    assert _figures(quality) == PERFECT
    wrong = map_quality(as_map(rotated, origin=[a, b, 0.0]), truth, world_from_map + np.array([0.0, 0.0, 0.05]))
    assert wrong.occupied_precision_1 < 0.9


def test_a_map_in_a_plan_with_a_rotated_origin_scores_as_the_perfect_one():
    truth = plan()
    turned = FloorPlan(truth.walls, truth.reachable, RES, np.array([0.5, -0.3, 0.4]))
    quality = map_quality(as_map(perfect_grid(truth), origin=[0.0, 0.0, 0.0]), turned, np.array([0.5, -0.3, 0.4]))
    assert _figures(quality) == PERFECT


def test_a_finer_map_of_the_same_plan_scores_as_the_perfect_one_and_its_cells_set_the_tolerance():
    truth = plan()
    fine = np.kron(perfect_grid(truth), np.ones((2, 2), dtype=np.int8))
    quality = map_quality(OccupancyGrid(fine, RES / 2, ORIGIN.copy()), truth, IDENTITY)
    assert _figures(quality) == PERFECT and quality.cell_m == RES / 2


def test_unknown_cells_are_neither_free_nor_occupied():
    truth = plan()
    quality = map_quality(as_map(np.full((H, W), UNKNOWN, dtype=np.int8)), truth, IDENTITY)
    assert quality.occupied_precision_1 is None and quality.occupied_recall_1 == 0.0
    assert quality.free_iou == 0.0 and quality.ghost_free_m2 == 0.0


def test_a_probability_map_splits_occupied_and_free_at_50():
    truth = plan()
    grid = perfect_grid(truth)
    soft = np.where(grid == OCCUPIED, 65, np.where(grid == FREE, 10, -1)).astype(np.int8)
    assert _figures(map_quality(as_map(soft), truth, IDENTITY)) == PERFECT


def test_the_json_form_round_trips_and_reads_missing_figures_as_none():
    truth = plan()
    quality = map_quality(as_map(perfect_grid(truth)), truth, IDENTITY, alignment_rms_m=0.01)
    doc = json.loads(json.dumps({MAP_QUALITY_KEY: quality.to_dict()}))
    assert doc[MAP_QUALITY_KEY]["format"] == "slamtrials-mapquality/1"
    assert MapQuality.of(doc) == quality
    assert MapQuality.of({}) is None
    partial = MapQuality.from_dict({"occupied_precision_1": 0.5, "free_iou": None})
    assert partial.occupied_precision_1 == 0.5 and partial.free_iou is None and math.isnan(partial.ghost_free_m2)
    assert partial.figures()["ghost_free_m2"] is None


def test_every_figure_has_a_one_line_definition():
    assert set(DEFINITIONS) == set(MAP_QUALITY_FIGURES)
    assert all("\n" not in text and text for text in DEFINITIONS.values())


def test_a_floor_plan_refuses_reachable_walls_and_mismatched_shapes():
    walls = np.zeros((3, 3), dtype=bool)
    with pytest.raises(ValueError, match="same"):
        FloorPlan(walls, np.zeros((2, 3), dtype=bool), RES, ORIGIN)
    walls[1, 1] = True
    with pytest.raises(ValueError, match="wall"):
        FloorPlan(walls, np.ones((3, 3), dtype=bool), RES, ORIGIN)
