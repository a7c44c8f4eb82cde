"""An external SLAM program's spec (placeholders, label, quoting) and how its trajectory is carried onto
the frames of the run it processed (:func:`slamtrials.slam.program.align_to_frames`)."""

from __future__ import annotations

import shlex

import numpy as np
import pytest

from slamtrials.errors import ConfigError
from slamtrials.geometry import compose, compose1, ominus1, wrap_angle
from slamtrials.record import Trajectory
from slamtrials.slam.program import MIN_COVERED_SHARE, SAME_FRAME, ProgramSpec, align_to_frames, program_spec

# --- the spec ---------------------------------------------------------------------------------------


def test_a_spec_with_input_and_output_has_the_defaults():
    spec = program_spec(command="my_slam {input} {output}")
    assert (spec.input, spec.output, spec.timeout, spec.name) == ("carmen", "tum", 3600.0, None)
    assert program_spec(command="x --seed {seed} --tmp {workdir} {input} {output}").command.startswith("x --seed")


@pytest.mark.parametrize(
    ("command", "expected"),
    [
        ("my_slam {input}", "must hold {output}"),
        ("my_slam > {output}", "must hold {input}"),
        ("my_slam", "must hold {input}"),
        ("my_slam {input} {output} {map}", "unknown placeholder {map}"),
        ("my_slam {0} {input} {output}", "unknown placeholder {0}"),
        ("my_slam {input:>20} {output}", "takes no format"),
        ("my_slam {input!r} {output}", "takes no format"),
        ("my_slam {} {input} {output}", "takes no format"),
        ("my_slam {input} {output", "not a valid template"),
        ("awk '{print $1}' {input} > {output}", "unknown placeholder {print $1}"),
        ("", "command"),
    ],
)
def test_bad_commands_are_one_line_config_errors(command, expected):
    with pytest.raises(ConfigError) as info:
        program_spec(command=command)
    message = str(info.value)
    assert message.startswith("--program: command: ") and expected in message, message
    assert "\n" not in message


@pytest.mark.parametrize(
    ("values", "field"),
    [
        ({"input": "rosbag"}, "input"),
        ({"output": "g2o"}, "output"),
        ({"timeout": 0}, "timeout"),
        ({"timeout": -1.0}, "timeout"),
        ({"name": ""}, "name"),
        ({"commnad": "x"}, "commnad"),
    ],
)
def test_bad_values_are_named(values, field):
    with pytest.raises(ConfigError, match=f"--program: {field}:"):
        program_spec(command="my_slam {input} {output}", **values)


def test_the_spec_is_frozen_and_refuses_unknown_fields_directly():
    spec = ProgramSpec(command="a {input} {output}")
    with pytest.raises(Exception):  # noqa: B017 - pydantic's frozen-instance error
        spec.command = "b {input} {output}"  # type: ignore[misc]


@pytest.mark.parametrize(
    ("command", "label"),
    [
        ("python3 path/x.py {input} {output}", "program:x.py"),
        ("python /opt/tools/slam_run.py {input} {output}", "program:slam_run.py"),
        ("python3.11 -u ./wrap.py {input} {output}", "program:wrap.py"),
        ("env FOO=1 python3 x.py {input} {output}", "program:x.py"),
        ("FOO=1 ./bin/gmapping_offline --map {input} {output}", "program:gmapping_offline"),
        ("/usr/local/bin/cartographer_offline {input} {output}", "program:cartographer_offline"),
        ("nice bash run.sh {input} {output}", "program:run.sh"),
        ("my_slam {input} {output}", "program:my_slam"),
    ],
)
def test_the_label_names_the_program_not_its_interpreter(command, label):
    assert program_spec(command=command).label == label


def test_a_name_replaces_the_label():
    assert program_spec(command="python3 x.py {input} {output}", name="MySLAM").label == "MySLAM"


def test_command_for_quotes_every_value_and_keeps_literal_braces():
    spec = program_spec(command="run --seed {seed} -C {workdir} {input} {output} | awk '{{print $1}}'")
    values = {"input": "/tmp/my run/in.clf", "output": "/tmp/it's/out.tum", "workdir": "/tmp/w d"}
    command = spec.command_for(seed=7, **values)
    words = shlex.split(command)
    assert words[:7] == ["run", "--seed", "7", "-C", "/tmp/w d", "/tmp/my run/in.clf", "/tmp/it's/out.tum"]
    assert words[-1] == "{print $1}"
    assert spec.command_for(input="a", output="b", seed=3, workdir="w") == "run --seed 3 -C w a b | awk '{print $1}'"


def test_command_for_does_not_let_a_value_run_as_shell():
    spec = program_spec(command="cat {input} > {output}")
    command = spec.command_for(input="x; rm -rf /", output="$(reboot)", seed=0, workdir="w")
    assert shlex.split(command) == ["cat", "x; rm -rf /", ">", "$(reboot)"]


# --- align_to_frames ----------------------------------------------------------------------------------


@pytest.fixture
def run(drive, odometry_of):
    """Frame times (0.1 s apart, 20 s), true poses and a drifting odometry of a turning robot."""
    t, truth = drive(4, seconds=20.0)
    return t, truth, odometry_of(truth, 5)


def traj(t, poses) -> Trajectory:
    return Trajectory(t=np.asarray(t, dtype=np.float64), poses=np.asarray(poses, dtype=np.float64))


def assert_poses_close(actual, expected, atol=1e-9):
    actual, expected = np.asarray(actual), np.asarray(expected)
    np.testing.assert_allclose(actual[:, :2], expected[:, :2], atol=atol)
    np.testing.assert_allclose(wrap_angle(actual[:, 2] - expected[:, 2]), 0.0, atol=atol)


def test_a_pose_at_every_frame_is_the_estimate(run):
    t, truth, odometry = run
    aligned = align_to_frames(traj(t, truth), t, odometry)
    np.testing.assert_array_equal(aligned.estimate, truth)
    assert (aligned.poses_read, aligned.frames_at_pose, aligned.frames_carried) == (len(t), len(t), 0)
    assert aligned.estimate.dtype == np.float64 and aligned.estimate.flags.c_contiguous


def test_a_pose_within_same_frame_of_a_frame_is_that_frames_pose(run):
    t, truth, odometry = run
    jitter = np.where(np.arange(len(t)) % 2 == 0, 0.5, -0.5) * SAME_FRAME
    aligned = align_to_frames(traj(t + jitter, truth), t, odometry)
    np.testing.assert_array_equal(aligned.estimate, truth)
    assert aligned.frames_at_pose == len(t)


def test_frames_between_poses_take_the_latest_poses_correction_applied_to_their_odometry(run):
    t, truth, odometry = run
    every = np.arange(0, len(t), 5)
    aligned = align_to_frames(traj(t[every], truth[every]), t, odometry)
    expected = np.empty_like(truth)
    for k in range(len(t)):
        j = every[every <= k].max()
        correction = compose1(truth[j], ominus1(odometry[j], [0.0, 0.0, 0.0]))  # map <- odom at frame j
        expected[k] = compose1(correction, odometry[k])
    assert_poses_close(aligned.estimate, expected)
    np.testing.assert_array_equal(aligned.estimate[every], truth[every])
    assert aligned.frames_at_pose == len(every) and aligned.frames_carried == len(t) - len(every)
    assert aligned.poses_read == len(every)
    # carried frames are not the truth (the odometry drifts), yet close to it right after a pose
    carried = np.setdiff1d(np.arange(len(t)), every)
    assert np.abs(aligned.estimate[carried, :2] - truth[carried, :2]).max() > 1e-4
    assert np.abs(aligned.estimate[carried, :2] - truth[carried, :2]).max() < 0.05


def test_a_constant_map_from_odom_offset_is_that_offset_at_every_frame(run):
    t, _, odometry = run
    offset = np.array([3.0, -7.5, 2.5])
    rng = np.random.default_rng(0)
    some = np.sort(rng.choice(np.arange(1, len(t) - 1), size=25, replace=False))
    some = np.concatenate([[0], some, [len(t) - 1]])
    aligned = align_to_frames(traj(t[some], compose(offset, odometry[some])), t, odometry)
    assert_poses_close(aligned.estimate, compose(offset, odometry), atol=1e-9)


def test_a_pose_between_frames_uses_the_odometry_interpolated_at_its_time(run):
    t, _, odometry = run
    offset = np.array([1.0, 2.0, -0.3])
    # a program reporting half-way between frames, in the map frame offset from odometry's
    half = (t[:-1] + t[1:]) / 2
    theta = np.unwrap(odometry[:, 2])
    mid = np.stack(
        [
            (odometry[:-1, 0] + odometry[1:, 0]) / 2,
            (odometry[:-1, 1] + odometry[1:, 1]) / 2,
            wrap_angle((theta[:-1] + theta[1:]) / 2),
        ],
        axis=1,
    )
    aligned = align_to_frames(traj(half[::3], compose(offset, mid[::3])), t, odometry)
    assert aligned.frames_at_pose == 0 and aligned.frames_carried == len(t)
    assert_poses_close(aligned.estimate, compose(offset, odometry), atol=1e-9)


def test_frames_before_the_first_pose_take_its_correction(run):
    t, truth, odometry = run
    first = 7
    aligned = align_to_frames(traj(t[first:], truth[first:]), t, odometry)
    correction = compose1(truth[first], ominus1(odometry[first], [0.0, 0.0, 0.0]))
    expected = [compose1(correction, odometry[k]) for k in range(first)]
    assert_poses_close(aligned.estimate[:first], expected)
    np.testing.assert_array_equal(aligned.estimate[first:], truth[first:])


def test_time_shift_brings_the_programs_times_to_the_runs(run):
    t, truth, odometry = run
    every = np.arange(0, len(t), 4)
    plain = align_to_frames(traj(t[every], truth[every]), t, odometry)
    shifted = align_to_frames(traj(t[every] + 1000.0, truth[every]), t, odometry, time_shift=1000.0)
    np.testing.assert_allclose(shifted.estimate, plain.estimate, atol=1e-9)
    assert shifted.frames_at_pose == plain.frames_at_pose == len(every)
    with pytest.raises(ConfigError, match="after subtracting the input's time origin 995 s"):
        align_to_frames(traj(t[every] + 1000.0, truth[every]), t, odometry, time_shift=995.0)


def test_equal_times_keep_the_last_pose_written(run):
    t, truth, odometry = run
    times = np.concatenate([t[:10], [t[9]], t[10:]])
    other = truth[9] + [0.5, -0.25, 0.1]
    poses = np.concatenate([truth[:10], [other], truth[10:]])
    aligned = align_to_frames(traj(times, poses), t, odometry)
    np.testing.assert_allclose(aligned.estimate[9], other)
    assert aligned.poses_read == len(t)
    np.testing.assert_array_equal(np.delete(aligned.estimate, 9, axis=0), np.delete(truth, 9, axis=0))


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        (lambda t, p: (t[:0], p[:0]), "holds no poses"),
        (lambda t, p: (t, np.where(np.arange(len(t))[:, None] == 3, np.nan, p)), "non-finite time or pose at pose 4"),
        (lambda t, p: (np.where(np.arange(len(t)) == 5, np.inf, t), p), "non-finite time or pose at pose 6"),
        (lambda t, p: (np.concatenate([t[:10], t[8:9], t[11:]]), p), "goes back in time at pose 11"),
        (lambda t, p: (t + 100.0, p), "outside the run's frames"),
        (lambda t, p: (t - 5.0, p), "outside the run's frames"),
        (lambda t, p: (t[: len(t) // 3], p[: len(t) // 3]), "it stopped early"),
        (lambda t, p: (t[-len(t) // 3 :], p[-len(t) // 3 :]), "it stopped early"),
    ],
)
def test_trajectories_that_do_not_fit_are_refused_with_one_line(run, make, expected):
    t, truth, odometry = run
    times, poses = make(t, truth)
    with pytest.raises(ConfigError) as info:
        align_to_frames(traj(times, poses), t, odometry)
    assert expected in str(info.value) and "\n" not in str(info.value), str(info.value)


def test_the_span_rules_edges(run):
    t, truth, odometry = run
    # up to span_tolerance (1 s) outside the frames is accepted (clipped); a bit more is refused
    align_to_frames(traj(t + 0.9, truth), t, odometry)
    with pytest.raises(ConfigError, match="outside the run's frames"):
        align_to_frames(traj(t + 1.1, truth), t, odometry)
    align_to_frames(traj(t + 1.1, truth), t, odometry, span_tolerance=1.5)
    # exactly MIN_COVERED_SHARE of the run is enough; a single pose in a run of one frame too
    n = int(np.ceil(MIN_COVERED_SHARE * (len(t) - 1))) + 1
    align_to_frames(traj(t[:n], truth[:n]), t, odometry)
    single = align_to_frames(traj(t[:1], truth[:1]), t[:1], odometry[:1])
    np.testing.assert_array_equal(single.estimate, truth[:1])
