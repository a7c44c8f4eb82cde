"""Relations files: the MIT CSAIL benchmark file, exact round trip, 3-D relations projected onto the
plane, and a FormatError naming file and line for malformed files."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from slamtrials.errors import FormatError
from slamtrials.io.relations import read_relations, write_relations
from slamtrials.record import Relations

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared"))
MIT_RELATIONS = SHARED / "data" / "mit-csail" / "mit-csail.relations"


@pytest.mark.skipif(not MIT_RELATIONS.is_file(), reason="shared data not present")
def test_mit_csail_relations():
    relations = read_relations(MIT_RELATIONS)
    lines = [line for line in MIT_RELATIONS.read_text().splitlines() if line.strip()]
    assert len(relations) == len(lines) == 1172
    assert relations.t1[0] == 1134864645.90321 and relations.t2[0] == 1134864646.32420
    np.testing.assert_array_equal(relations.delta[0], [0.31293, 0.02935, 0.24198])
    np.testing.assert_array_equal(relations.delta[3], [0.31459, -0.07383, -0.13753])
    assert np.all(relations.t1 < relations.t2)
    assert np.abs(relations.delta[:, 2]).max() <= math.pi


def test_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(0)
    t1 = 1.1e9 + rng.uniform(0, 500, 40)
    relations = Relations(t1=t1, t2=t1 + rng.uniform(0.1, 5, 40), delta=rng.normal(0, 2, (40, 3)))
    write_relations(tmp_path / "r.relations", relations)
    back = read_relations(tmp_path / "r.relations")
    for name in ("t1", "t2", "delta"):
        np.testing.assert_array_equal(getattr(back, name), getattr(relations, name))
    assert all(line.split()[4:7] == ["0.0"] * 3 for line in (tmp_path / "r.relations").read_text().splitlines())


finite = st.floats(allow_nan=False, allow_infinity=False)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rows=st.lists(st.tuples(finite, finite, finite, finite, finite), min_size=1, max_size=15))
def test_round_trip_property(tmp_path, rows):
    values = np.array(rows, dtype=np.float64)
    relations = Relations(t1=values[:, 0], t2=values[:, 1], delta=values[:, 2:])
    write_relations(tmp_path / "p.relations", relations)
    back = read_relations(tmp_path / "p.relations")
    np.testing.assert_array_equal(np.column_stack([back.t1, back.t2, back.delta]), values)


def _matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    cr, sr, cp, sp, cy, sy = (
        math.cos(roll),
        math.sin(roll),
        math.cos(pitch),
        math.sin(pitch),
        math.cos(yaw),
        math.sin(yaw),
    )
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


@pytest.mark.parametrize(
    ("roll", "pitch", "yaw"), [(0.2, 0.1, 1.0), (-0.5, 0.4, -2.9), (1.0, 2.0, 0.3), (0.0, -2.5, 3.0), (3.0, 0.0, 4.0)]
)
def test_three_d_relations_are_projected_to_the_heading_of_the_x_axis(tmp_path, roll, pitch, yaw):
    (tmp_path / "r.relations").write_text(f"1 2 0.5 -0.25 3.0 {roll} {pitch} {yaw}\n")
    back = read_relations(tmp_path / "r.relations")
    rotation = _matrix(roll, pitch, yaw)
    np.testing.assert_array_equal(back.delta[0, :2], [0.5, -0.25])
    assert back.delta[0, 2] == pytest.approx(math.atan2(rotation[1, 0], rotation[0, 0]), abs=1e-12)


def test_planar_yaw_is_taken_as_written(tmp_path):
    (tmp_path / "r.relations").write_text(
        "# t1 t2 x y z roll pitch yaw\n\n1 2 0 0 0 0 0 4.0\n3 1 0 0 0.0 -0.0 0 -7.5\n"
    )
    back = read_relations(tmp_path / "r.relations")
    assert back.delta[:, 2].tolist() == [4.0, -7.5] and back.t1.tolist() == [1.0, 3.0]


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("", 1, "no relations"),
        ("# header only\n", 1, "no relations"),
        ("1 2 0 0 0 0 0 0\n1 2 0 0 0 0 0\n", 2, "expected 8 fields"),
        ("1 2 0 0 0 0 0 zero\n", 1, "field 8 (yaw) is not a number: 'zero'"),
        ("1 2 0 0 0 0 0 0\n1 2 inf 0 0 0 0 0\n", 2, "field 3 (x) is not finite"),
        ("1 nan 0 0 0 0 0 0\n", 1, "field 2 (t2) is not finite"),
        ("1 2 0 0 0 0 1.5707963267948966 0\n", 1, "no 2-D heading"),
    ],
)
def test_malformed_files_name_file_and_line(tmp_path, text, line, message):
    path = tmp_path / "bad.relations"
    path.write_text(text)
    with pytest.raises(FormatError) as info:
        read_relations(path)
    assert info.value.path == path and info.value.line == line, str(info.value)
    assert message in str(info.value)


def test_writer_refuses_non_finite_values(tmp_path):
    with pytest.raises(ValueError, match="non-finite"):
        write_relations(
            tmp_path / "r", Relations(t1=np.array([1.0]), t2=np.array([2.0]), delta=np.array([[0, np.inf, 0]]))
        )
