"""The ``slamtrials-online/1`` messages (:mod:`slamtrials.external.protocol`): maps as ROS OccupancyGrid
cells (bottom row first), ranges as base64 float32, and a one-line ProgramError for every malformed reply."""

from __future__ import annotations

import base64
import json

import numpy as np
import pytest

from slamtrials.errors import ProgramError, SlamtrialsError
from slamtrials.external.protocol import (
    END_MESSAGE,
    PROTOCOL,
    decode_ranges,
    encode_map,
    frame_message,
    parse_map,
    parse_pose,
    parse_reply,
    parse_trajectory,
    start_message,
)
from slamtrials.record import LaserGeometry, OccupancyGrid, Reading


def _grid() -> OccupancyGrid:
    """A 3 x 4 map whose rows all differ, so a missing or doubled flip shows."""
    cells = np.array([[100, 100, -1, -1], [0, 0, 0, 100], [-1, 0, 100, 0]], dtype=np.int8)
    return OccupancyGrid(grid=cells, resolution=0.05, origin=np.array([-1.25, 2.5, 0.125]))


def _map_doc(cells_bottom_first: list[int], width: int, height: int, /, **changes) -> dict:
    doc = {
        "resolution": 0.1,
        "width": width,
        "height": height,
        "origin": [0.0, 0.0, 0.0],
        "data": base64.b64encode(np.array(cells_bottom_first, dtype=np.int8).tobytes()).decode("ascii"),
    }
    doc.update(changes)
    return {k: v for k, v in doc.items() if v is not None}


def _one_line_program_error(info: pytest.ExceptionInfo) -> str:
    message = str(info.value)
    assert isinstance(info.value, SlamtrialsError)
    assert "\n" not in message and message.startswith("protocol: "), message
    return message


# --- maps -------------------------------------------------------------------------------------------


def test_a_map_crosses_the_pipe_unchanged():
    grid = _grid()
    doc = json.loads(json.dumps(encode_map(grid)))  # through JSON text, as on the pipe
    assert (doc["width"], doc["height"], doc["resolution"]) == (4, 3, 0.05)
    assert doc["origin"] == [-1.25, 2.5, 0.125]
    back = parse_map(doc, "frame 0")
    assert back.grid.dtype == np.int8 and back.grid.flags.c_contiguous
    np.testing.assert_array_equal(back.grid, grid.grid)
    np.testing.assert_array_equal(back.origin, grid.origin)
    assert back.resolution == grid.resolution


def test_the_cells_go_bottom_row_first_as_in_ros():
    grid = _grid()
    data = np.frombuffer(base64.b64decode(encode_map(grid)["data"]), dtype=np.int8)
    # row 0 of OccupancyGrid.grid is the TOP row; the message starts with the bottom one
    np.testing.assert_array_equal(data[:4], grid.grid[-1])
    np.testing.assert_array_equal(data[-4:], grid.grid[0])
    # and a program's map whose first cells (bottom row) are walls has its walls in the last row here
    parsed = parse_map(_map_doc([100, 100, 0, 0, -1, -1], 2, 3), "frame 3")
    np.testing.assert_array_equal(parsed.grid, [[-1, -1], [0, 0], [100, 100]])


def test_a_map_of_known_values_only_is_kept_as_it_is():
    cells = [-1, 0, 100, 0, -1, 100]
    parsed = parse_map(_map_doc(cells, 3, 2), "end")
    np.testing.assert_array_equal(parsed.grid[::-1].ravel(), cells)


def test_probabilities_are_thresholded_as_map_saver_does():
    values = [0, 1, 25, 26, 50, 64, 65, 99, 100, -1]
    expected = [0, 0, 0, -1, -1, -1, 100, 100, 100, -1]
    parsed = parse_map(_map_doc(values, 10, 1), "frame 1")
    np.testing.assert_array_equal(parsed.grid[0], expected)
    assert parsed.grid.dtype == np.int8
    # the rows keep their places when the cells are thresholded
    two_rows = parse_map(_map_doc([70, 10, -1, 30], 2, 2), "frame 1")
    np.testing.assert_array_equal(two_rows.grid, [[-1, -1], [100, 0]])


@pytest.mark.parametrize(
    ("doc", "expected"),
    [
        ({"width": 2, "height": 1, "origin": [0, 0, 0], "data": "AAA="}, "needs resolution, width, height"),
        (_map_doc([0, 0], 2, 1, data=None), "needs resolution, width, height"),
        (_map_doc([0, 0], 2, 1, data="not base64!"), "base64"),
        (_map_doc([0, 0], 2, 1, data=12), "base64"),
        (_map_doc([0, 0], 2, 1, width="two"), "needs resolution, width, height"),
        (_map_doc([0, 0], 2, 1, origin="here"), "needs resolution, width, height"),
        ([1, 2, 3], "needs resolution, width, height"),
        ("map", "needs resolution, width, height"),
        (None, "needs resolution, width, height"),
        (_map_doc([0, 0], 2, 1, resolution=0.0), "resolution 0.0"),
        (_map_doc([0, 0], 2, 1, resolution=-0.05), "resolution -0.05"),
        (_map_doc([0, 0], 2, 1, resolution=float("nan")), "resolution nan"),
        (_map_doc([0, 0], 2, 1, resolution=float("inf")), "resolution inf"),
        (_map_doc([], 0, 1), "size 0 x 1"),
        (_map_doc([], 2, -1), "size 2 x -1"),
        (_map_doc([0, 0], 2, 1, origin=[0.0, 0.0]), "origin [x, y, theta]"),
        (_map_doc([0, 0], 2, 1, origin=[0.0, float("nan"), 0.0]), "origin [x, y, theta]"),
        (_map_doc([0, 0, 0], 2, 1), "holds 3 cells for 2 x 1 = 2"),
        (_map_doc([0], 2, 1), "holds 1 cells for 2 x 1 = 2"),
    ],
)
def test_a_malformed_map_is_a_one_line_program_error(doc, expected):
    with pytest.raises(ProgramError) as info:
        parse_map(doc, "frame 12")
    message = _one_line_program_error(info)
    assert "the map in the reply to frame 12" in message and expected in message, message


# --- ranges and the messages slamtrials sends ----------------------------------------------------------


def test_ranges_cross_the_pipe_bit_for_bit():
    ranges = np.array([0.1, 1 / 3, 29.999, np.inf, 1e-7, 5.5, np.inf], dtype=np.float32)
    reading = Reading(t=12.3456789, ranges=ranges, odometry=np.array([0.1, -2.0 / 3.0, np.pi]))
    doc = json.loads(frame_message(7, reading))
    assert doc["type"] == "frame" and doc["index"] == 7
    assert doc["t"] == 12.3456789 and doc["odometry"] == [0.1, -2.0 / 3.0, np.pi]  # shortest round-trip floats
    back = decode_ranges(doc["ranges"])
    assert back.dtype == np.float32 and back.shape == ranges.shape
    assert back.tobytes() == ranges.tobytes()
    assert np.isposinf(back[[3, 6]]).all()
    # little-endian float32, beam 0 first, whatever the array handed in
    assert base64.b64decode(doc["ranges"]) == ranges.astype("<f4").tobytes()
    wide = Reading(t=0.0, ranges=ranges.astype(">f8"), odometry=np.zeros(3))
    assert decode_ranges(json.loads(frame_message(0, wide))["ranges"]).tobytes() == ranges.tobytes()


def test_the_start_and_end_messages():
    laser = LaserGeometry(angle_min=-1.5, angle_increment=0.01, range_min=0.1, range_max=30.0, mount=(0.2, 0.0, 0.1))
    state = np.random.default_rng(5).bit_generator.state
    line = start_message(laser, 301, 1234, state)
    assert line.endswith(b"\n") and line.count(b"\n") == 1
    doc = json.loads(line)
    assert doc["type"] == "start" and doc["protocol"] == PROTOCOL == "slamtrials-online/1"
    assert doc["laser"] == {
        "beams": 301,
        "angle_min": -1.5,
        "angle_increment": 0.01,
        "range_min": 0.1,
        "range_max": 30.0,
        "mount": [0.2, 0.0, 0.1],
    }
    assert doc["seed"] == 1234 and doc["rng_state"] == json.loads(json.dumps(state))
    assert json.loads(END_MESSAGE) == {"type": "end"} and END_MESSAGE.endswith(b"\n")


# --- replies and poses ---------------------------------------------------------------------------------


def test_a_reply_is_a_json_object():
    assert parse_reply(b'{"pose": [1, 2, 3], "updates": 4}', "frame 0") == {"pose": [1, 2, 3], "updates": 4}
    assert parse_reply(b"{}", "end") == {}


@pytest.mark.parametrize(
    ("line", "expected"),
    [
        (b"hello world", "the reply to frame 5 is not a JSON line: 'hello world'"),
        (b"", "the reply to frame 5 is not a JSON line: ''"),
        (b'{"pose": [1, 2, 3]', "not a JSON line"),
        (b"\xff\xfe garbage", "not a JSON line"),
        (b"x" * 500, "not a JSON line: '" + "x" * 80 + "'"),
        (b"[1, 2, 3]", "must be a JSON object, got list"),
        (b"42", "must be a JSON object, got int"),
        (b"null", "must be a JSON object, got NoneType"),
    ],
)
def test_a_reply_that_is_no_json_object_is_a_program_error(line, expected):
    with pytest.raises(ProgramError) as info:
        parse_reply(line, "frame 5")
    message = _one_line_program_error(info)
    assert expected in message and len(message) < 200, message


def test_a_pose_is_three_finite_numbers():
    pose = parse_pose({"pose": [1.5, -2, 0.25]}, "frame 0")
    assert pose.dtype == np.float64 and pose.tolist() == [1.5, -2.0, 0.25]


@pytest.mark.parametrize(
    "reply",
    [
        {},
        {"pose": None},
        {"pose": [1.0, 2.0]},
        {"pose": [1.0, 2.0, 3.0, 4.0]},
        {"pose": [[1.0, 2.0, 3.0]]},
        {"pose": [1.0, float("nan"), 3.0]},
        {"pose": [1.0, 2.0, float("inf")]},
        {"pose": ["a", "b", "c"]},
        {"pose": [1.0, [2.0], 3.0]},
        {"pose": "1 2 3"},
        {"pose": {"x": 1, "y": 2, "theta": 3}},
        {"pose": list(range(1000))},
    ],
)
def test_a_missing_or_bad_pose_is_a_program_error(reply):
    with pytest.raises(ProgramError) as info:
        parse_pose(reply, "frame 9")
    message = _one_line_program_error(info)
    assert 'the reply to frame 9 needs "pose": [x, y, theta] (finite)' in message, message
    assert len(message) <= 200


def test_a_nan_pose_read_from_json_text_is_refused():
    # Python's json reads NaN and Infinity: a program may well write them
    with pytest.raises(ProgramError, match="finite"):
        parse_pose(parse_reply(b'{"pose": [NaN, 0, 0]}', "frame 2"), "frame 2")
    with pytest.raises(ProgramError, match="finite"):
        parse_pose(parse_reply(b'{"pose": [0, -Infinity, 0]}', "frame 2"), "frame 2")


# --- trajectories --------------------------------------------------------------------------------------

TIMES = np.array([0.0, 0.1, 0.2, 0.30000000000000004])


def test_a_trajectory_gives_the_poses_of_its_rows():
    rows = [[t, k, -k, 0.5 * k] for k, t in enumerate(TIMES.tolist())]
    poses = parse_trajectory(json.loads(json.dumps(rows)), TIMES)
    assert poses.shape == (4, 3) and poses.flags.c_contiguous
    np.testing.assert_array_equal(poses, np.array(rows)[:, 1:])


@pytest.mark.parametrize(
    ("rows", "expected"),
    [
        ([[t, 0, 0, 0] for t in TIMES[:3]], "must hold 4 rows [t, x, y, theta] (one per frame), got shape (3, 4)"),
        ([[t, 0, 0, 0] for t in [*TIMES, 0.4]], "got shape (5, 4)"),
        ([[t, 0, 0] for t in TIMES], "got shape (4, 3)"),
        ([0.0, 0.1, 0.2, 0.3], "got shape (4,)"),
        ([[t, 0, 0, 0] for t in TIMES[:3]] + [[0.3, 0, 0]], "got shape (0, 0)"),
        ([[t, "x", 0, 0] for t in TIMES], "got shape (0, 0)"),
        ([[t, 0, float("nan"), 0] for t in TIMES], "got shape (4, 4)"),
        ("trajectory", "got shape (0, 0)"),
        ({"t": 0}, "must hold 4 rows"),
        ([], "got shape (0,)"),
    ],
)
def test_a_malformed_trajectory_is_a_program_error(rows, expected):
    with pytest.raises(ProgramError) as info:
        parse_trajectory(rows, TIMES)
    message = _one_line_program_error(info)
    assert "the end reply's trajectory must hold 4 rows" in message and expected in message, message


def test_a_trajectory_row_at_another_time_is_named():
    rows = [[t, 0, 0, 0] for t in TIMES.tolist()]
    rows[3][0] = 0.3  # not the frame's time 0.30000000000000004: times must match exactly
    with pytest.raises(ProgramError) as info:
        parse_trajectory(rows, TIMES)
    message = _one_line_program_error(info)
    assert "trajectory row 3 has t = " in message and "frame 3 is at " in message, message
    assert "0.30000000000000004" in message, message


def test_the_row_at_another_time_is_named_with_plain_numbers():
    rows = [[t, 0, 0, 0] for t in TIMES.tolist()]
    rows[3][0] = 0.3
    with pytest.raises(ProgramError) as info:
        parse_trajectory(rows, TIMES)
    assert "row 3 has t = 0.3, frame 3 is at 0.30000000000000004" in str(info.value), str(info.value)
