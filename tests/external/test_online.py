"""The algorithm ``program`` (:class:`slamtrials.external.online.OnlineProgram`): a process that gets every
frame over ``slamtrials-online/1``. The reference clients answer as the built-in algorithms do (GMapping
bit for bit, in a trial too), and a program that exits, hangs or breaks the protocol is a one-line
ProgramError with its stderr, its process killed."""

from __future__ import annotations

import json
import os
import shlex
import signal
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from slamtrials.errors import ConfigError, ProgramError, SlamtrialsError
from slamtrials.external.online import OnlineProgram
from slamtrials.external.protocol import decode_ranges, encode_map
from slamtrials.record import OccupancyGrid, Reading
from slamtrials.seeding import slam_rng
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.slam import get_algorithm, make_algorithm
from slamtrials.slam.offline import run_over_recording
from slamtrials.trial import TrialConfig, run_trial
from slamtrials.worlds import World

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"
PYTHON = shlex.quote(sys.executable)
ODOMETRY_CLIENT = f"{PYTHON} {shlex.quote(str(EXAMPLES / 'online_odometry.py'))}"
GMAPPING_CLIENT = f"{PYTHON} {shlex.quote(str(EXAMPLES / 'online_gmapping.py'))} paper"
RES = 0.05


def box() -> World:
    """A 4 m x 2 m room."""
    occupied = np.ones((60, 100), bool)
    occupied[10:50, 10:90] = False
    return World(occupied, RES, name="box", start=np.array([1.0, 1.0, 0.0]))


def two_rooms() -> World:
    """An 8 m x 5 m box split by a wall with a 1 m door (the world of tests/trial/test_trial.py)."""
    height, width = int(5.0 / RES) + 2, int(8.0 / RES) + 2
    occupied = np.zeros((height, width), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    wall = width // 2
    occupied[:, wall : wall + 3] = True
    door = slice(height // 2 - 10, height // 2 + 10)
    occupied[door, wall : wall + 3] = False
    return World(occupied, RES, name="two-rooms", start=np.array([1.5, 2.5, 0.0]))


@pytest.fixture(scope="module")
def record():
    """69 frames of a short drive in the box."""
    return simulate_waypoints(box(), [[3.5, 1.0], [3.5, 1.9]], SimConfig.paper(), seed=1, max_time=30)


# --- small clients written for one test ----------------------------------------------------------------

PRELUDE = """\
import json, os, sys, time
open({pidfile!r}, "w").write(str(os.getpid()))


def reply(doc):
    sys.stdout.write(json.dumps(doc) + "\\n")
    sys.stdout.flush()


def messages():
    for line in sys.stdin:
        yield json.loads(line)


"""


class Client:
    """A Python client script in ``folder``: PRELUDE (writes its pid, ``reply``, ``messages``) + ``body``."""

    def __init__(self, folder: Path, body: str, name: str = "client"):
        self.pidfile = folder / f"{name}.pid"
        self.script = folder / f"{name}.py"
        self.script.write_text(PRELUDE.format(pidfile=str(self.pidfile)) + textwrap.dedent(body))
        self.command = f"{PYTHON} {shlex.quote(str(self.script))}"

    @property
    def pid(self) -> int:
        return int(self.pidfile.read_text())

    def gone(self, within: float = 5.0) -> bool:
        return _gone(self.pid, within)

    def kill(self) -> None:
        """Clean up after a test that expects the process to survive (a known bug)."""
        if self.pidfile.exists() and not _gone(self.pid, 0.0):
            os.kill(self.pid, signal.SIGKILL)


def _gone(pid: int, within: float) -> bool:
    """True once process ``pid`` is no more (or a zombie), polling for up to ``within`` seconds."""
    deadline = time.monotonic() + within
    while True:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except (FileNotFoundError, ProcessLookupError):
            return True
        if state in ("Z", "X"):
            return True
        if time.monotonic() >= deadline:
            return False
        time.sleep(0.02)


ECHO_ODOMETRY = """\
for m in messages():
    if m["type"] == "frame":
        reply({"pose": m["odometry"]})
    elif m["type"] == "end":
        reply({})
        break
"""


def _run(record, command: str, **params):
    return run_over_recording(record, "program", overrides={"command": command, **params})


# --- the odometry client ------------------------------------------------------------------------------


def test_the_odometry_client_answers_the_odometry_and_gets_a_map_drawn_from_its_poses(record):
    result = _run(record, ODOMETRY_CLIENT)
    assert result.algorithm == "program" and result.preset is None
    assert np.array_equal(result.online, record.odometry)  # floats cross the pipe bit for bit
    assert np.array_equal(result.trajectory.t, record.t)
    assert np.array_equal(result.trajectory.poses, record.odometry)
    grid = result.occupancy
    assert grid.resolution == 0.05
    assert np.count_nonzero(grid.grid == 100) > 50 and np.count_nonzero(grid.grid == 0) > 500
    assert result.updates == 0  # it sends no "updates"
    coarse = _run(record, ODOMETRY_CLIENT, resolution=0.2)
    assert coarse.occupancy.resolution == 0.2 and (coarse.occupancy.grid == 100).any()
    assert coarse.occupancy.grid.size < grid.grid.size


def test_the_program_gets_the_start_message_and_every_frame(record, tmp_path):
    seen = tmp_path / "seen.jsonl"
    client = Client(
        tmp_path,
        f"""\
        with open({str(seen)!r}, "w") as out:
            for m in messages():
                out.write(json.dumps(m) + "\\n")
                out.flush()
                if m["type"] == "frame":
                    reply({{"pose": [0.0, 0.0, 0.0], "updates": m["index"] + 1}})
                elif m["type"] == "end":
                    reply({{}})
                    break
        """,
    )
    result = _run(record, client.command)
    lines = [json.loads(line) for line in seen.read_text().splitlines()]
    start, frames, end = lines[0], lines[1:-1], lines[-1]
    assert start["type"] == "start" and start["protocol"] == "slamtrials-online/1"
    laser = record.laser
    assert start["laser"] == {
        "beams": record.scans.shape[1],
        "angle_min": laser.angle_min,
        "angle_increment": laser.angle_increment,
        "range_min": laser.range_min,
        "range_max": laser.range_max,
        "mount": list(laser.mount),
    }
    state = slam_rng(0).bit_generator.state  # the run's seed is 0
    assert start["rng_state"] == json.loads(json.dumps(state))
    assert start["seed"] == state["state"]["state"] & 0xFFFFFFFF
    assert end == {"type": "end"}
    assert [f["index"] for f in frames] == list(range(len(record)))
    assert np.array_equal([f["t"] for f in frames], record.t)
    assert np.array_equal([f["odometry"] for f in frames], record.odometry)
    assert np.array_equal(np.stack([decode_ranges(f["ranges"]) for f in frames]), record.scans)
    assert result.updates == len(record)
    assert client.gone()


def test_another_seed_gives_the_program_another_stream(record, tmp_path):
    seen = tmp_path / "start.json"
    client = Client(tmp_path, f"open({str(seen)!r}, 'w').write(sys.stdin.readline())\n" + ECHO_ODOMETRY)
    starts = []
    for seed in (0, 1):
        run_over_recording(record, "program", overrides={"command": client.command}, seed=seed)
        starts.append(json.loads(seen.read_text()))
    assert starts[0]["seed"] != starts[1]["seed"]
    assert starts[1]["rng_state"] == json.loads(json.dumps(slam_rng(1).bit_generator.state))


def test_the_map_a_program_sends_is_the_map(record, tmp_path):
    first = OccupancyGrid(grid=np.array([[100, 0], [-1, 0]], np.int8), resolution=0.1, origin=np.array([1.0, 2.0, 0]))
    final = OccupancyGrid(grid=np.full((3, 5), 100, np.int8), resolution=0.2, origin=np.array([-1.0, 0.0, 0.0]))
    client = Client(
        tmp_path,
        f"""\
        for m in messages():
            if m["type"] == "frame":
                reply({{"pose": m["odometry"], "map": {encode_map(first)!r}}} if m["index"] == 1 else {{"pose": m["odometry"]}})
            elif m["type"] == "end":
                reply({{"map": {encode_map(final)!r}}})
                break
        """,
    )
    slam = make_algorithm("program", record.laser, overrides={"command": client.command})
    assert isinstance(slam, OnlineProgram)
    slam.reset(slam_rng(0))
    frames = [Reading(t=float(record.t[k]), ranges=record.scans[k], odometry=record.odometry[k]) for k in range(4)]
    slam.process(frames[0])
    drawn = slam.occupancy()  # no map sent yet: drawn from the poses
    assert drawn.resolution == 0.05 and (drawn.grid == 100).any()
    for frame in frames[1:]:
        slam.process(frame)
        got = slam.occupancy()  # the map of frame 1 stays the map
        assert np.array_equal(got.grid, first.grid) and np.array_equal(got.origin, first.origin)
        assert got.resolution == 0.1
    trajectory = slam.trajectory()
    assert np.array_equal(trajectory.poses, record.odometry[:4])
    assert np.array_equal(slam.occupancy().grid, final.grid) and slam.occupancy().resolution == 0.2
    assert slam.trajectory() is trajectory  # end is sent once
    with pytest.raises(ProgramError, match="has ended"):
        slam.process(frames[0])
    assert client.gone()


def test_reset_starts_the_program_afresh(record, tmp_path):
    client = Client(tmp_path, ECHO_ODOMETRY)
    slam = make_algorithm("program", record.laser, overrides={"command": client.command})
    frames = [Reading(t=float(record.t[k]), ranges=record.scans[k], odometry=record.odometry[k]) for k in range(5)]
    slam.reset(slam_rng(0))
    for frame in frames[:3]:
        slam.process(frame)
    first = client.pid
    slam.reset(slam_rng(0))  # mid-run: the first process is killed
    assert _gone(first, 5.0)
    online = [slam.process(frame) for frame in frames]
    assert client.pid != first
    assert np.array_equal(online, record.odometry[:5])
    assert np.array_equal(slam.trajectory().poses, record.odometry[:5])
    # without a frame no program is started
    idle = make_algorithm("program", record.laser, overrides={"command": "exit 1"})
    idle.reset(slam_rng(0))
    assert len(idle.trajectory()) == 0


# --- bit for bit with the built-in GMapping -------------------------------------------------------------


@pytest.mark.slow
def test_the_gmapping_client_is_the_built_in_gmapping_bit_for_bit(record):
    for seed in (0, 7):
        built_in = run_over_recording(record, "gmapping", preset="paper", seed=seed)
        program = run_over_recording(record, "program", overrides={"command": GMAPPING_CLIENT}, seed=seed)
        assert np.array_equal(program.online, built_in.online), seed
        assert np.array_equal(program.trajectory.t, built_in.trajectory.t)
        assert np.array_equal(program.trajectory.poses, built_in.trajectory.poses), seed
        assert np.array_equal(program.occupancy.grid, built_in.occupancy.grid), seed
        assert np.array_equal(program.occupancy.origin, built_in.occupancy.origin)
        assert program.occupancy.resolution == built_in.occupancy.resolution
        assert program.updates == built_in.updates > 0


@pytest.mark.slow
def test_a_trial_through_the_gmapping_client_is_the_built_in_trial_bit_for_bit():
    world = two_rooms()
    base = {"sim": {"profile": "paper"}, "termination": {"small_period": 60.0, "max_time": 20.0}}
    built_in = run_trial(world, TrialConfig.from_dict({**base, "slam": {"algorithm": "gmapping"}}), seed=4)
    config = TrialConfig.from_dict({**base, "slam": {"algorithm": "program", "params": {"command": GMAPPING_CLIENT}}})
    assert config.slam.preset is None  # 'program' has no paper preset: the client gets its own
    program = run_trial(world, config, seed=4)
    assert len(program) == len(built_in) > 100
    for name in ("t", "truth", "odometry", "stalled", "scans", "estimate", "online"):
        assert np.array_equal(getattr(program, name), getattr(built_in, name)), name
    assert np.array_equal(program.map.grid, built_in.map.grid)
    assert np.array_equal(program.map.origin, built_in.map.origin)
    ours, theirs = program.metadata["trial"], built_in.metadata["trial"]
    for key in ("termination_reason", "slam_updates", "mapped_fraction", "snapshots"):
        assert ours[key] == theirs[key], key
    assert {k: v for k, v in ours["explorer"].items() if k != "plan_seconds"} == {
        k: v for k, v in theirs["explorer"].items() if k != "plan_seconds"
    }


# --- failures -----------------------------------------------------------------------------------------

FAILURES = {
    "exits after start": (
        "sys.stdin.readline()\nsys.exit(0)\n",
        r"the program exited before (answering )?frame 0 \(status 0\)",
        0,
    ),
    "prints garbage": (
        """\
        for m in messages():
            if m["type"] == "frame":
                reply({"pose": m["odometry"]}) if m["index"] < 3 else print("ready to map!", flush=True)
        """,
        "protocol: the reply to frame 3 is not a JSON line: 'ready to map!'",
        None,
    ),
    "answers a NaN pose": (
        """\
        for m in messages():
            if m["type"] == "frame":
                reply({"pose": [float("nan"), 0.0, 0.0]})
        """,
        r'protocol: the reply to frame 0 needs "pose": \[x, y, theta\] \(finite\), got \[nan, 0.0, 0.0\]',
        None,
    ),
    "answers without a pose": (
        """\
        for m in messages():
            if m["type"] == "frame":
                reply({"position": m["odometry"]})
        """,
        'the reply to frame 0 needs "pose"',
        None,
    ),
    "answers a bad map": (
        """\
        for m in messages():
            if m["type"] == "frame":
                bad = {"resolution": 0.05, "width": 3, "height": 3, "origin": [0, 0, 0], "data": "AAAA"}
                reply({"pose": m["odometry"], "map": bad})
        """,
        "the map in the reply to frame 0 holds 3 cells for 3 x 3 = 9",
        None,
    ),
    "answers a bad update count": (
        """\
        for m in messages():
            if m["type"] == "frame":
                reply({"pose": m["odometry"], "updates": -1})
        """,
        '"updates" in the reply to frame 0 must be a count, got -1',
        None,
    ),
    "answers a short trajectory": (
        """\
        rows = []
        for m in messages():
            if m["type"] == "frame":
                rows.append([m["t"], *m["odometry"]])
                reply({"pose": m["odometry"]})
            elif m["type"] == "end":
                reply({"trajectory": rows[:-1]})
                time.sleep(30)  # still running when the reply is read: killed, no exit status
        """,
        r"protocol: the end reply's trajectory must hold 69 rows .*got shape \(68, 4\)",
        None,
    ),
    "exits 3 at the end": (
        ECHO_ODOMETRY + "sys.exit(3)\n",
        "the program exited with status 3 at the end",
        3,
    ),
    "writes to stderr, then exits": (
        """\
        for m in messages():
            if m["type"] == "frame" and m["index"] == 2:
                sys.stderr.write("loading vocabulary\\nscan matcher: beam 42 has range -1\\n")
                sys.stderr.flush()
                sys.exit(1)
            if m["type"] == "frame":
                reply({"pose": m["odometry"]})
        """,
        r"the program exited before answering frame 2 \(status 1\); its stderr ends: "
        r"loading vocabulary \| scan matcher: beam 42 has range -1",
        1,
    ),
}


@pytest.mark.parametrize("case", list(FAILURES))
def test_a_failing_program_is_a_one_line_program_error_and_is_gone(record, tmp_path, case):
    body, expected, exit_code = FAILURES[case]
    client = Client(tmp_path, body)
    started = time.monotonic()
    with pytest.raises(ProgramError, match=expected) as info:
        _run(record, client.command, reply_timeout=5.0)
    assert time.monotonic() - started < 10.0
    assert isinstance(info.value, SlamtrialsError) and "\n" not in str(info.value)
    assert info.value.exit_code == exit_code
    assert client.gone()


def test_the_stderr_tail_rides_on_the_error(record, tmp_path):
    client = Client(
        tmp_path,
        """\
        for k in range(30):
            sys.stderr.write(f"line {k}\\n")
        sys.stderr.flush()
        for m in messages():
            print("not json", flush=True)
        """,
    )
    with pytest.raises(ProgramError) as info:
        _run(record, client.command)
    error = info.value
    assert str(error).startswith("protocol: the reply to frame 0 is not a JSON line: 'not json'")
    assert str(error).endswith("; its stderr ends: line 27 | line 28 | line 29")
    assert error.stderr_tail == tuple(f"line {k}" for k in range(10, 30))  # the last 20 lines
    assert client.gone()


def test_a_program_that_never_answers_is_killed_at_its_reply_timeout(record, tmp_path):
    client = Client(tmp_path, "for line in sys.stdin:\n    pass\n")
    started = time.monotonic()
    with pytest.raises(ProgramError) as info:
        _run(record, client.command, reply_timeout=1.0)
    elapsed = time.monotonic() - started
    assert 1.0 <= elapsed < 10.0
    assert str(info.value) == "the program did not answer frame 0 within 1 s"
    assert client.gone()


def test_a_program_that_does_not_exit_after_the_end_is_killed(record, tmp_path):
    client = Client(tmp_path, ECHO_ODOMETRY + "time.sleep(60)\n")
    started = time.monotonic()
    with pytest.raises(ProgramError, match="the program did not exit within 1 s of the end"):
        _run(record, client.command, reply_timeout=1.0)
    assert time.monotonic() - started < 10.0
    assert client.gone()


def test_a_command_that_does_not_start_is_a_program_error(record, tmp_path):
    missing = shlex.quote(str(tmp_path / "no_such_slam"))
    with pytest.raises(ProgramError) as info:
        _run(record, missing)
    assert "exited before" in str(info.value) and "status 127" in str(info.value)
    assert "not found" in str(info.value)  # the shell's own message, from the stderr tail


def test_a_trial_with_a_failing_program_raises_program_error(tmp_path):
    client = Client(
        tmp_path,
        """\
        for m in messages():
            if m["type"] != "frame":
                continue
            if m["index"] == 5:
                sys.stderr.write("out of particles\\n")
                sys.stderr.flush()
                os._exit(2)
            reply({"pose": m["odometry"]})
        """,
    )
    config = TrialConfig.from_dict(
        {
            "sim": {"profile": "paper"},
            "slam": {"algorithm": "program", "params": {"command": client.command, "reply_timeout": 5.0}},
            "termination": {"max_time": 5.0},
        }
    )
    with pytest.raises(SlamtrialsError) as info:
        run_trial(box(), config, seed=1)
    assert isinstance(info.value, ProgramError)
    assert "frame 5 (status 2)" in str(info.value) and "out of particles" in str(info.value)
    assert client.gone()


def test_inside_a_campaign_a_failing_program_is_a_failed_run(tmp_path):
    from slamtrials.campaign.config import MetricSettings
    from slamtrials.campaign.results import RunFailed
    from slamtrials.campaign.task import RunTask, run_one

    client = Client(
        tmp_path,
        """\
        for m in messages():
            if m["type"] == "frame":
                print("no pose today", flush=True)
        """,
    )
    config = TrialConfig.from_dict(
        {"sim": {"profile": "paper"}, "slam": {"algorithm": "program", "params": {"command": client.command}}}
    )
    task = RunTask(
        str(tmp_path / "campaign"),
        "box",
        "office_small_01",  # loaded, then replaced by the box: the trial function ignores it
        3,
        11,
        config,
        MetricSettings(),
        lambda world, trial, seed: run_trial(box(), trial, seed),
    )
    result = run_one(task)
    assert isinstance(result, RunFailed) and (result.world, result.index) == ("box", 3)
    assert result.error == "ProgramError: protocol: the reply to frame 0 is not a JSON line: 'no pose today'"
    assert client.gone()


# --- configuration --------------------------------------------------------------------------------------


def test_program_is_found_through_its_entry_point():
    cls = get_algorithm("program")
    assert cls is OnlineProgram and cls.PRESETS == {}
    config = TrialConfig.from_dict({"slam": {"algorithm": "program", "params": {"command": "my_slam"}}})
    assert config.slam.preset is None and config.slam.resolved().command == "my_slam"


@pytest.mark.parametrize("params", [{}, {"command": ""}, {"command": "   "}])
def test_a_program_without_a_command_is_a_config_error(record, params):
    with pytest.raises(ConfigError, match=r"params\.command: the algorithm 'program' needs the command"):
        run_over_recording(record, "program", overrides=params)
    with pytest.raises(ConfigError, match=r"params\.command"):  # when the config is read, before any run
        TrialConfig.from_dict({"sim": {"profile": "paper"}, "slam": {"algorithm": "program", "params": params}})


@pytest.mark.parametrize(
    ("params", "field"),
    [
        ({"command": "x", "reply_timeout": 0}, "reply_timeout"),
        ({"command": "x", "resolution": -1}, "resolution"),
        ({"command": "x", "comand": "y"}, "comand"),
    ],
)
def test_bad_program_parameters_are_config_errors(params, field):
    with pytest.raises(ConfigError, match=field):
        TrialConfig.from_dict({"slam": {"algorithm": "program", "params": params}})


# --- edge cases: a config read early, a broken end, calls after a failure, leftover children --------------


def test_a_config_without_a_command_is_refused_when_read():
    with pytest.raises(ConfigError, match="command"):
        TrialConfig.from_dict({"slam": {"algorithm": "program"}})


def test_garbage_at_the_end_kills_the_program_and_carries_its_stderr(record, tmp_path):
    client = Client(
        tmp_path,
        """\
        for m in messages():
            if m["type"] == "frame":
                reply({"pose": m["odometry"]})
            elif m["type"] == "end":
                sys.stderr.write("saving the map failed\\n")
                sys.stderr.flush()
                print("bye", flush=True)
                time.sleep(30)
        """,
    )
    try:
        with pytest.raises(ProgramError, match="the reply to end is not a JSON line") as info:
            _run(record, client.command, reply_timeout=5.0)
        assert "saving the map failed" in str(info.value)
        assert client.gone(1.0)
    finally:
        client.kill()


def test_calls_after_a_failure_are_program_errors(record, tmp_path):
    client = Client(tmp_path, "sys.stdin.readline()\nprint('garbage', flush=True)\n")
    slam = make_algorithm("program", record.laser, overrides={"command": client.command})
    slam.reset(slam_rng(0))
    frame = Reading(t=float(record.t[0]), ranges=record.scans[0], odometry=record.odometry[0])
    with pytest.raises(ProgramError):
        slam.process(frame)
    with pytest.raises(ProgramError):
        slam.process(frame)


@pytest.mark.slow
def test_a_program_whose_leader_exits_leaves_no_child_behind(record, tmp_path):
    client = Client(
        tmp_path,
        """\
        import subprocess
        child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
        open(sys.argv[0] + ".child", "w").write(str(child.pid))
        sys.stdin.readline()
        os._exit(0)
        """,
    )
    child = Path(str(client.script) + ".child")
    try:
        with pytest.raises(ProgramError, match="exited before"):
            _run(record, client.command, reply_timeout=3.0)
        assert _gone(int(child.read_text()), 1.0)
    finally:
        if child.exists() and not _gone(int(child.read_text()), 0.0):
            os.kill(int(child.read_text()), signal.SIGKILL)


@pytest.mark.slow
def test_a_program_that_closes_its_stdout_and_hangs_is_killed_at_its_reply_timeout(record, tmp_path):
    client = Client(
        tmp_path,
        """\
        for m in messages():
            if m["type"] != "frame":
                continue
            if m["index"] == 1:
                os.close(1)
                time.sleep(6)
                sys.exit(0)
            reply({"pose": m["odometry"]})
        """,
    )
    started = time.monotonic()
    try:
        with pytest.raises(ProgramError):  # 'exec': the program itself leads the group (dash does not exec)
            _run(record, "exec " + client.command, reply_timeout=1.0)
        assert time.monotonic() - started < 4.0
    finally:
        client.kill()


def test_a_program_killed_at_its_reply_timeout_has_no_exit_code(record, tmp_path):
    client = Client(tmp_path, "for line in sys.stdin:\n    pass\n")
    with pytest.raises(ProgramError, match="did not answer frame 0 within 1 s") as info:
        _run(record, client.command, reply_timeout=1.0)
    assert info.value.exit_code is None
