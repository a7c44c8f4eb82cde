"""TUM trajectories: exact round trip, evo reads what we write (and we read what evo writes), 3-D poses
projected onto the plane, and a FormatError naming file and line for malformed files."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from slamtrials.errors import FormatError
from slamtrials.geometry import wrap_angle
from slamtrials.io.tum import read_tum, write_tum
from slamtrials.record import Trajectory


def _trajectory(n: int = 50, seed: int = 0) -> Trajectory:
    rng = np.random.default_rng(seed)
    t = 1.6e9 + np.cumsum(rng.uniform(0.01, 0.2, n))
    poses = np.column_stack([rng.normal(0, 30, n), rng.normal(0, 30, n), rng.uniform(-4, 4, n)])
    return Trajectory(t=t, poses=poses)


def _assert_same(back: Trajectory, trajectory: Trajectory) -> None:
    np.testing.assert_array_equal(back.t, trajectory.t)
    np.testing.assert_array_equal(back.poses[:, :2], trajectory.poses[:, :2])
    assert np.abs(wrap_angle(back.poses[:, 2] - trajectory.poses[:, 2])).max() <= 4e-16 * 4
    assert np.all(np.abs(back.poses[:, 2]) <= math.pi)


def test_round_trip(tmp_path):
    trajectory = _trajectory()
    write_tum(tmp_path / "a.tum", trajectory)
    _assert_same(read_tum(tmp_path / "a.tum"), trajectory)


finite = st.floats(min_value=-1e12, max_value=1e12, allow_nan=False)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    start=st.floats(min_value=-1e9, max_value=2e9),
    steps=st.lists(st.floats(min_value=1e-3, max_value=1e3), min_size=1, max_size=20),
    values=st.lists(st.tuples(finite, finite, st.floats(min_value=-50, max_value=50)), min_size=20, max_size=20),
)
def test_round_trip_property(tmp_path, start, steps, values):
    t = start + np.cumsum(steps)
    if np.any(np.diff(t) <= 0):
        return  # steps lost to rounding at this magnitude
    trajectory = Trajectory(t=t, poses=np.array(values[: len(t)], dtype=np.float64))
    write_tum(tmp_path / "p.tum", trajectory)
    back = read_tum(tmp_path / "p.tum")
    np.testing.assert_array_equal(back.t, trajectory.t)
    np.testing.assert_array_equal(back.poses[:, :2], trajectory.poses[:, :2])
    assert np.abs(wrap_angle(back.poses[:, 2] - trajectory.poses[:, 2])).max() < 1e-14


def test_evo_reads_what_we_write(tmp_path):
    from evo.tools import file_interface

    trajectory = _trajectory()
    write_tum(tmp_path / "a.tum", trajectory)
    evo = file_interface.read_tum_trajectory_file(str(tmp_path / "a.tum"))
    np.testing.assert_array_equal(evo.timestamps, trajectory.t)
    np.testing.assert_array_equal(evo.positions_xyz[:, :2], trajectory.poses[:, :2])
    assert not evo.positions_xyz[:, 2].any()
    w, x, y, z = evo.orientations_quat_wxyz.T
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    assert np.abs(wrap_angle(yaw - trajectory.poses[:, 2])).max() < 1e-15


def test_we_read_what_evo_writes(tmp_path):
    from evo.core.trajectory import PoseTrajectory3D
    from evo.tools import file_interface

    trajectory = _trajectory(seed=3)
    half = trajectory.poses[:, 2] / 2
    quat_wxyz = np.column_stack([np.cos(half), np.zeros_like(half), np.zeros_like(half), np.sin(half)])
    xyz = np.column_stack([trajectory.poses[:, :2], np.full(len(half), 1.5)])
    file_interface.write_tum_trajectory_file(str(tmp_path / "evo.tum"), PoseTrajectory3D(xyz, quat_wxyz, trajectory.t))
    back = read_tum(tmp_path / "evo.tum")
    np.testing.assert_allclose(back.t, trajectory.t, rtol=0, atol=1e-6)
    np.testing.assert_allclose(back.poses[:, :2], trajectory.poses[:, :2], rtol=0, atol=1e-6)
    assert np.abs(wrap_angle(back.poses[:, 2] - trajectory.poses[:, 2])).max() < 1e-6


def _quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(qx, qy, qz, qw) of Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


@pytest.mark.parametrize(
    ("roll", "pitch", "yaw", "heading"),
    [(0.1, -0.2, 0.7, 0.7), (0.3, 0.2, -3.0, -3.0), (0.0, 2.5, 0.5, 0.5 - math.pi), (math.pi, 0.0, 1.0, 1.0)],
)
def test_three_d_poses_are_projected_to_the_heading_of_the_x_axis(tmp_path, roll, pitch, yaw, heading):
    qx, qy, qz, qw = _quaternion(roll, pitch, yaw)
    scale = 3.0  # quaternions are normalised
    (tmp_path / "r.tum").write_text(f"1.0 4.0 -5.0 7.0 {qx * scale!r} {qy * scale!r} {qz * scale!r} {qw * scale!r}\n")
    back = read_tum(tmp_path / "r.tum")
    np.testing.assert_array_equal(back.poses[0, :2], [4.0, -5.0])
    assert wrap_angle(back.poses[0, 2] - heading) == pytest.approx(0.0, abs=1e-12)


def test_comments_blank_lines_and_tabs_are_allowed(tmp_path):
    (tmp_path / "c.tum").write_text(
        "# timestamp tx ty tz qx qy qz qw\n\n1 0 0 0 0 0 0 1\r\n  # indented comment\n2\t1 0 0 0 0 1 0\n"
    )
    back = read_tum(tmp_path / "c.tum")
    assert back.t.tolist() == [1.0, 2.0]
    np.testing.assert_allclose(back.poses, [[0, 0, 0], [1, 0, math.pi]])


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("", 1, "no poses"),
        ("# nothing\n\n", 2, "no poses"),
        ("1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n", 2, "expected 8 fields"),
        ("1 0 0 0 0 0 0 1 9\n", 1, "got 9"),
        ("1 0 x 0 0 0 0 1\n", 1, "field 3 (y) is not a number: 'x'"),
        ("1 0 0 0 0 0 0 1\n2 nan 0 0 0 0 0 1\n", 2, "field 2 (x) is not finite"),
        ("1 0 0 1e400 0 0 0 1\n", 1, "field 4 (z) is not finite"),
        ("1 0 0 0 0 0 0 0\n", 1, "quaternion is zero"),
        ("1 0 0 0 0 0.7071067811865476 0 0.7071067811865476\n", 1, "no heading"),
        ("2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n", 2, "strictly increasing"),
        ("1 0 0 0 0 0 0 1\n# c\n1 0 0 0 0 0 0 1\n", 3, "strictly increasing"),
    ],
)
def test_malformed_files_name_file_and_line(tmp_path, text, line, message):
    path = tmp_path / "bad.tum"
    path.write_text(text)
    with pytest.raises(FormatError) as info:
        read_tum(path)
    assert info.value.path == path and info.value.line == line, str(info.value)
    assert message in str(info.value)


def test_huge_quaternions_do_not_overflow(tmp_path):
    (tmp_path / "h.tum").write_text("1 1e308 -1e308 0 0 0 1e308 1e308\n")
    assert read_tum(tmp_path / "h.tum").poses[0, 2] == pytest.approx(math.pi / 2)


def test_writer_refuses_what_would_not_read_back(tmp_path):
    with pytest.raises(ValueError, match="non-finite"):
        write_tum(tmp_path / "a.tum", Trajectory(t=np.array([0.0, 1.0]), poses=np.array([[0, 0, 0], [np.nan, 0, 0]])))
    with pytest.raises(ValueError, match="strictly increasing"):
        write_tum(tmp_path / "a.tum", Trajectory(t=np.array([0.0, 0.0]), poses=np.zeros((2, 3))))
