"""GridFrame: the explore layer's cell <-> map-frame conversion (row 0 at the top)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from slamtrials.explore import GridFrame


def test_row_zero_is_the_top_row():
    frame = GridFrame(height=4, width=3, resolution=0.5, origin=(10.0, 20.0, 0.0))
    # lower-left cell (row 3, col 0) has its lower-left corner at the origin
    assert np.allclose(frame.to_xy(3, 0), [10.25, 20.25])
    assert np.allclose(frame.to_xy(0, 0), [10.25, 21.75])
    rows, cols = frame.to_cell(np.array([[10.1, 20.1], [10.1, 21.9], [11.4, 21.9]]))
    assert rows.tolist() == [3, 0, 0] and cols.tolist() == [0, 0, 2]


def test_of_reads_a_map_object():
    occupancy = SimpleNamespace(grid=np.zeros((5, 7), np.int8), resolution=0.05, origin=np.array([1.0, 2.0, 0.0]))
    frame = GridFrame.of(occupancy)
    assert (frame.height, frame.width, frame.resolution, frame.origin) == (5, 7, 0.05, (1.0, 2.0, 0.0))


@given(st.integers(-5, 20), st.integers(-5, 20), st.floats(-math.pi, math.pi))
def test_round_trip_and_sub_windows(row, col, theta):
    frame = GridFrame(height=12, width=9, resolution=0.1, origin=(-3.0, 4.0, theta))
    r, c = frame.to_cell(frame.to_xy(row, col))
    assert (int(r), int(c)) == (row, col)
    sub = frame.sub(2, 3, 5, 4)  # window whose top-left cell is (2, 3)
    assert np.allclose(sub.to_xy(row - 2, col - 3), frame.to_xy(row, col))
