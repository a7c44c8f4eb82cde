"""Waypoint files: values read exactly; every malformed file names its line."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.errors import FormatError
from slamtrials.io.waypoints import read_waypoints


def test_reads_pairs_in_order(tmp_path):
    path = tmp_path / "w.yaml"
    path.write_text("# a drive\nwaypoints:\n  - [1.0, 2]\n  - [-3.5, 1e1]\n")
    np.testing.assert_array_equal(read_waypoints(path), [[1.0, 2.0], [-3.5, 10.0]])


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("waypoints:\n  - [1, 2]\n  - [1, x]\n", 3, "numbers"),
        ("waypoints:\n  - [1, 2, 3]\n", 2, "pair"),
        ("waypoints:\n  - [1, .nan]\n", 2, "finite"),
        ("points:\n  - [1, 2]\n", 1, "waypoints"),
        ("waypoints: []\n", 1, "non-empty"),
        ("- [1, 2]\n", 1, "mapping"),
        ("waypoints: [1, 2\n", None, "YAML"),
    ],
)
def test_malformed_files_name_file_and_line(tmp_path, text, line, message):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(FormatError, match=message) as info:
        read_waypoints(path)
    assert str(path) in str(info.value)
    if line is not None:
        assert info.value.line == line


def test_binary_garbage_is_a_format_error(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(FormatError):
        read_waypoints(path)
