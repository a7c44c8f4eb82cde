"""FirstKnown: when maps first knew each place, across growing maps; the coverage curve read from it."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.record import OCCUPIED, UNKNOWN, OccupancyGrid
from slamtrials.trial.firstknown import SAMPLE_PERIOD, SECONDS_PER_CELL, FirstKnown, coverage_curve, sample_period

RES = 0.5


def grid(rows: int, cols: int, origin=(0.0, 0.0), known=()) -> OccupancyGrid:
    """A ``rows`` x ``cols`` map, unknown but the ``(row, col)`` cells in ``known`` (row 0 at the top)."""
    cells = np.full((rows, cols), UNKNOWN, dtype=np.int8)
    for r, c in known:
        cells[r, c] = 0
    return OccupancyGrid(cells, RES, np.array([origin[0], origin[1], 0.0]))


def centre(x_cell: int, y_cell: int) -> list[float]:
    """Map-frame centre of the cell ``x_cell`` columns right and ``y_cell`` rows up of the map frame's origin."""
    return [(x_cell + 0.5) * RES, (y_cell + 0.5) * RES]


def test_the_first_sample_that_knew_a_cell_across_growing_maps():
    history = FirstKnown()
    history.update(0, grid(2, 2, known=[(1, 0)]))  # knows cell (x 0, y 0)
    # the map grows left and down by one cell: its origin moves; (row 1, col 2) is cell (x 1, y 0)
    grown = grid(3, 3, origin=(-RES, -RES), known=[(1, 2), (1, 1)])
    grown.grid[0, 0] = OCCUPIED  # occupied counts as known: cell (x -1, y 1)
    history.update(7, grown)
    history.update(9, grid(1, 1, origin=(5.0, 5.0), known=[(0, 0)]))  # far away: the raster grows again
    points = np.array([centre(0, 0), centre(1, 0), centre(-1, 1), centre(1, 1), centre(10, 10), centre(99, 99)])
    assert history.frames == [0, 7, 9]
    assert history.first_sample(points).tolist() == [0, 1, 1, 3, 2, 3]


def test_a_cell_known_once_keeps_its_first_sample():
    history = FirstKnown()
    history.update(0, grid(1, 2, known=[(0, 0)]))
    history.update(1, grid(1, 2, known=[(0, 1)]))  # cell (0, 0) unknown again: still known since sample 0
    history.update(2, grid(1, 2, known=[(0, 0), (0, 1)]))
    assert history.first_sample(np.array([centre(0, 0), centre(1, 0)])).tolist() == [0, 1]


def test_an_empty_history_or_map_knows_nothing():
    history = FirstKnown()
    assert history.first_sample(np.zeros((3, 2))).tolist() == [0, 0, 0]
    history.update(0, OccupancyGrid(np.zeros((0, 0), dtype=np.int8), RES, np.zeros(3)))
    assert history.first_sample(np.zeros((2, 2))).tolist() == [1, 1]


def test_maps_of_another_resolution_are_refused():
    history = FirstKnown()
    history.update(0, grid(1, 1, known=[(0, 0)]))
    with pytest.raises(ValueError, match="resolution"):
        history.update(1, OccupancyGrid(np.zeros((1, 1), dtype=np.int8), 0.25, np.zeros(3)))


def test_the_coverage_curve():
    first = np.array([0, 0, 1, 3, 3, 4, 2])  # 4: never known by any sample
    known = np.array([True, True, True, True, False, True, True])  # the final map's view
    curve = coverage_curve(first, known, 4)
    # sample 3 is the final map: a cell it knows counts there at the latest
    assert curve.tolist() == pytest.approx([2 / 7, 3 / 7, 4 / 7, 6 / 7])
    assert curve[-1] == np.mean(known)
    assert coverage_curve(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=bool), 3).tolist() == [0.0, 0.0, 0.0]
    assert coverage_curve(first, known, 0).size == 0


def test_the_sample_period_grows_with_the_map():
    assert sample_period(grid(100, 100)) == SAMPLE_PERIOD
    assert sample_period(grid(2000, 1000)) == pytest.approx(2e6 * SECONDS_PER_CELL)
    assert 2e6 * SECONDS_PER_CELL > SAMPLE_PERIOD
