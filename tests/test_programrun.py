"""Running an external SLAM program over a recording (:func:`slamtrials.external.run_program`): what the
program is given (no ground truth, the run's time base), what comes back (its estimate per frame), and
its failures as one-line :class:`~slamtrials.errors.ProgramError`."""

from __future__ import annotations

import os
import shlex
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from slamtrials.errors import ConfigError, ProgramError
from slamtrials.external import STDERR_LINES, check_program, run_program, time_origin_ns
from slamtrials.geometry import compose, wrap_angle
from slamtrials.io.carmen import read_carmen
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.slam.program import program_spec
from slamtrials.worlds import World

REPO = Path(__file__).resolve().parents[1]
ODOMETRY_PROGRAM = REPO / "docs" / "examples" / "odometry_program.py"
PYTHON = shlex.quote(sys.executable)
#: The reference program: its estimate is the odometry.
ODOMETRY_COMMAND = f"{PYTHON} {shlex.quote(str(ODOMETRY_PROGRAM))} {{input}} {{output}}"

#: A program that reads a bag (ROS 1 or 2) and writes its /odom poses as TUM at their header stamps.
BAG_PROGRAM = """
import sys
from pathlib import Path

from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

with AnyReader([Path(sys.argv[1])], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader, open(
    sys.argv[2], "w"
) as out:
    odom = [c for c in reader.connections if c.topic == "/odom"]
    for connection, _, raw in reader.messages(connections=odom):
        msg = reader.deserialize(raw, connection.msgtype)
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        out.write(f"{stamp:.9f} {p.x!r} {p.y!r} 0 {q.x!r} {q.y!r} {q.z!r} {q.w!r}\\n")
"""

#: A program that writes the CARMEN input's ODOM lines as TUM with its times shifted by argv[3] s and
#: only every argv[4]-th line.
SHIFTED_PROGRAM = """
import math, sys

shift, every = float(sys.argv[3]), int(sys.argv[4])
odom = [line.split() for line in open(sys.argv[1]) if line.startswith("ODOM ")]
with open(sys.argv[2], "w") as out:
    for words in odom[::every]:
        x, y, th, t = float(words[1]), float(words[2]), float(words[3]), float(words[7])
        out.write(f"{t + shift!r} {x!r} {y!r} 0 0 0 {math.sin(th / 2)!r} {math.cos(th / 2)!r}\\n")
"""


@pytest.fixture(scope="module")
def record():
    """A 17 s simulated run in a 5 m x 2 m room (170 frames, odometry that drifts from the truth)."""
    occ = np.ones((60, 120), bool)
    occ[10:50, 10:110] = False
    occ[10:25, 60:62] = True
    world = World(occ, 0.05, name="room", start=np.array([1.0, 1.0, 0.0]))
    run = simulate_waypoints(world, [[4.5, 1.0], [4.5, 1.8], [1.0, 1.8]], SimConfig(), seed=2, max_time=60)
    assert float(run.t[0]) == 0.0 and len(run) > 100
    return run


@pytest.fixture
def script(tmp_path):
    """``script(name, text)``: write a Python program into tmp_path; return the shell words that run it."""

    def write(name: str, text: str) -> str:
        path = tmp_path / name
        path.write_text(text)
        return f"{PYTHON} {shlex.quote(str(path))}"

    return write


def assert_is_odometry(estimate, record, atol=1e-6):
    np.testing.assert_allclose(estimate[:, :2], record.odometry[:, :2], atol=atol)
    np.testing.assert_allclose(wrap_angle(estimate[:, 2] - record.odometry[:, 2]), 0.0, atol=atol)


def test_the_odometry_program_over_a_carmen_log_gives_the_odometry(record):
    ran = run_program(record, program_spec(command=ODOMETRY_COMMAND), seed=4)
    assert_is_odometry(ran.estimate, record)
    assert ran.alignment.poses_read == len(record) and ran.alignment.frames_at_pose == len(record)
    assert ran.alignment.frames_carried == 0
    assert ran.time_origin_s == 0.0 and ran.seed == 4 and ran.seconds > 0
    np.testing.assert_allclose(ran.trajectory.t, record.t, atol=1e-6)
    assert ran.spec.label == "program:odometry_program.py"
    assert "{" not in ran.command and str(ODOMETRY_PROGRAM) in ran.command
    assert (ran.occupancy.grid == 100).any() and (ran.occupancy.grid == 0).any()  # the scans traced at it


@pytest.mark.parametrize("input_format", ["bag", "bag2"])
def test_a_bag_program_gives_the_odometry_in_the_runs_time_base(record, script, input_format):
    """The run starts at 0 s; the bag is written from 1 s on and the program's times mapped back."""
    assert time_origin_ns(record, input_format) == 1_000_000_000
    command = script("bag_odometry.py", BAG_PROGRAM) + " {input} {output}"
    ran = run_program(record, program_spec(command=command, input=input_format))
    assert ran.time_origin_s == 1.0
    assert_is_odometry(ran.estimate, record, atol=1e-9)
    assert ran.alignment.frames_at_pose == len(record)
    np.testing.assert_allclose(ran.trajectory.t, record.t, atol=1e-9)  # back in the run's time base


def test_the_time_origin_rule(record):
    from dataclasses import replace

    assert time_origin_ns(record, "carmen") == 0
    late = replace(record, t=record.t + 5.0)  # a real log's stamps: kept as they are
    assert time_origin_ns(late, "bag") == time_origin_ns(late, "bag2") == 0


def test_a_program_reporting_every_few_frames_is_carried_by_odometry(record, script):
    command = script("shifted.py", SHIFTED_PROGRAM) + " {input} {output} 0 5"
    ran = run_program(record, program_spec(command=command))
    a = ran.alignment
    assert a.poses_read == len(range(0, len(record), 5)) and a.frames_at_pose == a.poses_read
    assert a.frames_carried == len(record) - a.poses_read
    assert_is_odometry(ran.estimate, record, atol=1e-5)  # its poses are the (6-digit) odometry: correction ~0


def test_the_recording_given_holds_no_ground_truth_carmen(record, tmp_path):
    copy = tmp_path / "given.clf"
    command = f"cp {{input}} {shlex.quote(str(copy))} && {ODOMETRY_COMMAND}"
    run_program(record, program_spec(command=command))
    text = copy.read_text()
    assert "TRUEPOS" not in text
    log = read_carmen(copy)
    assert log.truepos is None or len(log.truepos.t) == 0
    np.testing.assert_allclose(log.laser.odometry, record.odometry, atol=1e-5)
    np.testing.assert_allclose(log.laser.pose, compose(record.odometry, record.laser.mount), atol=1e-5)
    np.testing.assert_allclose(log.odom.pose, record.odometry, atol=1e-5)
    np.testing.assert_allclose(log.laser.t, record.t, atol=1e-6)  # the run's own time base


@pytest.mark.parametrize("input_format", ["bag", "bag2"])
def test_the_recording_given_holds_no_ground_truth_bag(record, tmp_path, script, input_format):
    from slamtrials.io.rosbag import TRUTH_TOPIC, bag_topics, run_from_bag

    copy = tmp_path / "given"
    bag = script("bag_odometry.py", BAG_PROGRAM)
    command = f"cp -r {{input}} {shlex.quote(str(copy))} && {bag} {{input}} {{output}}"
    run_program(record, program_spec(command=command, input=input_format))
    topics = bag_topics(copy)
    assert "/odom" in topics and "/base_scan" in topics
    assert TRUTH_TOPIC not in topics
    given = run_from_bag(copy, truth_topic=None)
    assert not np.isfinite(given.truth).any()
    np.testing.assert_allclose(given.odometry, record.odometry, atol=1e-9)
    np.testing.assert_allclose(given.t, record.t, atol=1e-9)
    assert not {"start", "bias", "world", "sim_config", "waypoints"} & set(given.metadata), sorted(given.metadata)


# --- failures -------------------------------------------------------------------------------------------


def test_a_non_zero_exit_is_a_program_error_with_its_status_and_stderr(record):
    lines = "; ".join(f"echo line {k} >&2" for k in range(30))
    command = f"sh -c '{lines}; echo bad news >&2; exit 3' prog {{input}} {{output}}"
    with pytest.raises(ProgramError) as info:
        run_program(record, program_spec(command=command))
    error = info.value
    assert error.exit_code == 3
    assert len(error.stderr_tail) == STDERR_LINES and error.stderr_tail[-1] == "bad news"
    assert error.stderr_tail[0] == f"line {30 - STDERR_LINES + 1}"
    message = str(error)
    assert "exited with status 3" in message and "its stderr ends: line 28 | line 29 | bad news" in message
    assert "\n" not in message


def test_a_program_that_is_not_found_exits_127(record):
    with pytest.raises(ProgramError, match="was not found") as info:
        run_program(record, program_spec(command="no-such-slam-program-xyz {input} {output}"))
    assert info.value.exit_code == 127 and "not found" in " ".join(info.value.stderr_tail)


def test_a_timeout_kills_the_program_and_its_children_quickly(record, tmp_path):
    pid_file = tmp_path / "child.pid"
    command = f"sh -c 'sleep 30 & echo $! > {pid_file}; echo waiting >&2; wait' prog {{input}} {{output}}"
    started = time.monotonic()
    with pytest.raises(ProgramError) as info:
        run_program(record, program_spec(command=command, timeout=1.0))
    elapsed = time.monotonic() - started
    assert elapsed < 10.0, elapsed
    error = info.value
    assert error.exit_code is None and error.stderr_tail == ("waiting",)
    assert "ran past its timeout of 1 s and was killed" in str(error) and "waiting" in str(error)
    child = int(pid_file.read_text())
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline and _alive(child):
        time.sleep(0.05)
    assert not _alive(child), f"the program's child {child} survived its timeout"


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie waiting for its reaper does not run)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


@pytest.mark.parametrize(
    ("command", "expected"),
    [
        ("true {input} {output}", "wrote nothing to {output}"),
        ("touch {output} # {input}", "wrote nothing to {output}"),
        ("echo 'not a pose' > {output} # {input}", "output (tum) cannot be used"),
        ("echo '1.0 2.0 3.0' > {output} # {input}", "output (tum) cannot be used"),
    ],
)
def test_empty_or_unparsable_output_is_a_program_error(record, command, expected):
    with pytest.raises(ProgramError) as info:
        run_program(record, program_spec(command=command))
    assert expected in str(info.value) and info.value.exit_code == 0, str(info.value)
    assert "\n" not in str(info.value) and "slamtrials-program-" not in str(info.value)


def test_unparsable_carmen_output_is_a_program_error(record):
    spec = program_spec(command="echo 'ROBOTLASER1 nonsense' > {output} # {input}", output="carmen")
    with pytest.raises(ProgramError, match=r"output \(carmen\) cannot be used"):
        run_program(record, spec)


def test_carmen_output_is_read_from_the_laser_lines(record, tmp_path):
    from slamtrials.io.carmen import carmen_from_run, write_carmen

    offset = np.array([2.0, -1.0, 0.7])
    estimate = compose(offset, record.odometry)
    log = tmp_path / "estimate.clf"
    write_carmen(log, carmen_from_run(record, first_triple=estimate))
    ran = run_program(
        record, program_spec(command=f"cp {shlex.quote(str(log))} {{output}} # {{input}}", output="carmen")
    )
    np.testing.assert_allclose(ran.estimate[:, :2], estimate[:, :2], atol=1e-5)
    np.testing.assert_allclose(wrap_angle(ran.estimate[:, 2] - estimate[:, 2]), 0.0, atol=1e-5)


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        ("3600 1", "outside the run's frames"),  # another time base (a Unix time, say)
        ("-30 1", "outside the run's frames"),
        ("0 -1", "timestamps must be strictly increasing"),
    ],
)
def test_a_trajectory_that_does_not_fit_the_run_is_a_program_error(record, script, args, expected):
    command = script("shifted.py", SHIFTED_PROGRAM) + " {input} {output} " + args
    with pytest.raises(ProgramError) as info:
        run_program(record, program_spec(command=command))
    assert expected in str(info.value) and "cannot be used" in str(info.value), str(info.value)


def test_a_program_that_stops_early_is_a_program_error(record, script):
    head = f"{PYTHON} {shlex.quote(str(ODOMETRY_PROGRAM))} {{input}} {{workdir}}/full.tum && head -n 40 {{workdir}}/full.tum > {{output}}"
    with pytest.raises(ProgramError, match="it stopped early"):
        run_program(record, program_spec(command=head))


def test_the_command_runs_in_cwd_and_the_scratch_folder_is_removed(record, tmp_path):
    seen = tmp_path / "seen.txt"
    command = (
        f"pwd > {shlex.quote(str(seen))}; echo {{workdir}} {{seed}} >> {shlex.quote(str(seen))}; {ODOMETRY_COMMAND}"
    )
    run_program(record, program_spec(command=command), seed=11, cwd=tmp_path, scratch=tmp_path)
    cwd, line = seen.read_text().splitlines()
    workdir, seed = line.split()
    assert cwd == str(tmp_path) and seed == "11"
    assert workdir.startswith(str(tmp_path / "slamtrials-program-")) and workdir.endswith("workdir")
    assert not any(p.name.startswith("slamtrials-program-") for p in tmp_path.iterdir())
    with pytest.raises(ProgramError):
        run_program(record, program_spec(command="exit 1 # {input} {output}"), scratch=tmp_path)
    assert not any(p.name.startswith("slamtrials-program-") for p in tmp_path.iterdir())


def test_a_recording_without_frames_is_refused(record):
    from dataclasses import replace

    empty = replace(
        record,
        t=record.t[:0],
        scans=record.scans[:0],
        odometry=record.odometry[:0],
        truth=record.truth[:0],
        stalled=record.stalled[:0],
    )
    with pytest.raises(ConfigError, match="no frames"):
        run_program(empty, program_spec(command=ODOMETRY_COMMAND))


# --- check_program ------------------------------------------------------------------------------------


def test_check_program_refuses_a_program_that_is_not_there(tmp_path):
    with pytest.raises(ConfigError, match="'no-such-slam-program-xyz' of the command not found on PATH"):
        check_program(program_spec(command="no-such-slam-program-xyz {input} {output}"))
    with pytest.raises(ConfigError, match="'./missing_slam' of the command not found"):
        check_program(program_spec(command="./missing_slam {input} {output}"), cwd=tmp_path)
    with pytest.raises(ConfigError, match="not found"):
        check_program(program_spec(command="FOO=1 /nonexistent/bin/slam {input} {output}"))


def test_check_program_accepts_programs_that_are_there(tmp_path):
    check_program(program_spec(command=ODOMETRY_COMMAND))
    check_program(program_spec(command="sh -c 'anything' x {input} {output}"))
    (tmp_path / "my_slam").write_text("#!/bin/sh\n")
    check_program(program_spec(command="./my_slam {input} {output}"), cwd=tmp_path)
    check_program(program_spec(command="cd somewhere && ./slam {input} {output}"))  # a shell construct: not checked


@pytest.mark.parametrize(
    "command",
    [
        ". /etc/profile && true {input} {output}",  # how a ROS setup.sh is sourced under /bin/sh
        "case x in *) true;; esac; true {input} {output}",
        "ulimit -t 600; true {input} {output}",
        "trap '' INT; true {input} {output}",
    ],
)
def test_check_program_accepts_commands_that_start_with_a_shell_builtin(command):
    check_program(program_spec(command=command))
