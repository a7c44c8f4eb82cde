"""An online SLAM program: the algorithm ``program``, a process that gets every frame as it happens and
answers with its pose (and map), over the ``slamtrials-online/1`` protocol
(:mod:`slamtrials.external.protocol`).

It is a :class:`~slamtrials.slam.SlamAlgorithm` like any other, so a trial explores with it and a
campaign repeats it: ``slam: {algorithm: program, params: {command: "python my_slam.py"}}``. It is
published under the ``slamtrials.slam`` entry-point group (pyproject.toml), so the ``slam`` layer never
imports this module.

:meth:`OnlineProgram.reset` starts the command (``/bin/sh -c``, its own process group, stderr to a
scratch file) and sends ``start``; :meth:`process` sends a frame and waits at most ``reply_timeout``
seconds for the reply; :meth:`trajectory` sends ``end``, reads the final trajectory and map, and waits
for the program to exit, reading what its process used (:meth:`OnlineProgram.child_usage`, the SLAM
cost of a trial with a program). A program that exits early, answers late or breaks the protocol raises
:class:`~slamtrials.errors.ProgramError` with the last lines of its stderr; its process group is killed.
"""

from __future__ import annotations

import math
import os
import select
import signal
import subprocess
import tempfile
import time
import weakref
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from slamtrials.cost import ProcessUsage
from slamtrials.errors import ConfigError, ProgramError
from slamtrials.external import protocol
from slamtrials.external.childwait import wait_with_usage
from slamtrials.geometry import ominus
from slamtrials.record import LaserGeometry, OccupancyGrid, Reading, Trajectory
from slamtrials.slam.gridmap import GridMap

__all__ = ["OnlineProgram", "OnlineProgramConfig"]


class OnlineProgramConfig(BaseModel):
    """Parameters of the ``program`` algorithm.

    Attributes
    ----------
    command:
        Shell command that starts the program (run by ``/bin/sh -c`` in the current folder).
    reply_timeout:
        Seconds the program may take to answer one message before it is killed.
    resolution:
        Cell size (m) of the map drawn from its poses, when it sends no map of its own.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    command: str = Field("", description="shell command that starts the program")
    reply_timeout: float = Field(60.0, gt=0.0, le=86400.0, description="seconds for each reply")
    resolution: float = Field(0.05, gt=0.0, le=10.0, description="cell size (m) of a map drawn from the poses")


class _Process:
    """The running program: its stdin, a line reader on its stdout with a timeout, its stderr file."""

    #: Seconds between looks at whether the program has exited while its reply is awaited.
    POLL = 0.2

    def __init__(self, command: str, timeout: float):
        self.timeout = timeout
        self.scratch = tempfile.TemporaryDirectory(prefix="slamtrials-online-")
        self.err_path = Path(self.scratch.name) / "stderr.txt"
        with open(self.err_path, "wb") as stderr:
            self.popen = subprocess.Popen(
                ["/bin/sh", "-c", command],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=stderr,
                start_new_session=True,
            )
        self._buffer = bytearray()
        self.usage: ProcessUsage | None = None
        self._closer = weakref.finalize(self, _kill_group, self.popen, self.scratch)

    def tail(self) -> tuple[str, ...]:
        try:
            text = self.err_path.read_text(encoding="utf-8", errors="replace")
        except OSError:
            return ()
        return tuple(line.rstrip() for line in text.splitlines() if line.strip())[-20:]

    def fail(self, problem: str, code: int | None = None) -> ProgramError:
        """The ProgramError of ``problem`` with the end of its stderr; the process group is killed."""
        tail = self.tail()
        said = f"; its stderr ends: {' | '.join(tail[-3:])}" if tail else ""
        self.close()
        return ProgramError(f"{problem}{said}", exit_code=code, stderr_tail=tail)

    def _status(self) -> int | None:
        """The exit status once the program has exited (within the reply timeout), else None; what its
        process used is kept in :attr:`usage`."""
        try:
            code, usage = wait_with_usage(self.popen, self.timeout)
        except subprocess.TimeoutExpired:
            return None
        self.usage = usage if usage is not None else self.usage
        return code

    def send(self, line: bytes, what: str) -> None:
        try:
            assert self.popen.stdin is not None
            self.popen.stdin.write(line)
            self.popen.stdin.flush()
        except (OSError, ValueError):  # a broken pipe, or a stream already closed
            code = self._status()
            raise self.fail(f"the program exited before {what} (status {code})", code) from None

    def receive(self, what: str) -> bytes:
        """The next line of its stdout, within the reply timeout."""
        assert self.popen.stdout is not None
        fd = self.popen.stdout.fileno()
        deadline = time.monotonic() + self.timeout
        while True:
            end = self._buffer.find(b"\n")
            if end >= 0:
                line = bytes(self._buffer[:end])
                del self._buffer[: end + 1]
                return line
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise self.fail(f"the program did not answer {what} within {self.timeout:g} s")
            ready, _, _ = select.select([fd], [], [], min(remaining, self.POLL))
            if not ready:
                code = self.popen.poll()  # exited, though a child of its may hold its stdout open
                if code is not None:
                    raise self.fail(f"the program exited before answering {what} (status {code})", code)
                continue
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                code = self._status()
                raise self.fail(f"the program exited before answering {what} (status {code})", code)
            self._buffer += chunk

    def finish(self) -> None:
        """Close its stdin and wait for a zero exit status."""
        try:
            assert self.popen.stdin is not None
            self.popen.stdin.close()
        except OSError:
            pass
        code = self._status()
        if code is None:
            raise self.fail(f"the program did not exit within {self.timeout:g} s of the end")
        if code != 0:
            raise self.fail(f"the program exited with status {code} at the end", code)
        self.close()

    def close(self) -> None:
        self._closer()


def _kill_group(popen: subprocess.Popen, scratch: tempfile.TemporaryDirectory) -> None:
    """Kill the program's whole process group (children that outlived it too) and remove its scratch."""
    try:
        os.killpg(popen.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    popen.wait()
    for stream in (popen.stdin, popen.stdout):
        try:
            if stream is not None:
                stream.close()
        except OSError:
            pass
    scratch.cleanup()


class OnlineProgram:
    """The ``program`` algorithm (see the module docstring).

    Parameters
    ----------
    config:
        Validated :class:`OnlineProgramConfig`.
    laser:
        The laser's geometry, sent in the ``start`` message.
    """

    name = "program"
    Config = OnlineProgramConfig
    PRESETS: dict[str, dict[str, Any]] = {}

    def __init__(self, config: OnlineProgramConfig, laser: LaserGeometry):
        self.check_config(config)
        self.config = config
        self.laser = laser
        self._process: _Process | None = None
        self._failure: ProgramError | None = None
        self._usage: ProcessUsage | None = None
        self.updates = 0

    def reset(self, rng: np.random.Generator) -> None:
        """Start the program afresh and send it ``start`` (its seed from ``rng``'s state, not a draw)."""
        if self._process is not None:
            self._process.close()
        self._failure = None
        self._rng_state = rng.bit_generator.state
        self._seed = int(self._rng_state.get("state", {}).get("state", 0)) & 0xFFFFFFFF
        self._process = None
        self._t: list[float] = []
        self._poses: list[NDArray[np.float64]] = []
        self._map: OccupancyGrid | None = None
        self._drawn = GridMap(self.config.resolution)
        self._drawn_grid: OccupancyGrid | None = None
        self._last_drawn: NDArray[np.float64] | None = None
        self._final: Trajectory | None = None
        self._usage = None
        self.updates = 0

    @classmethod
    def check_config(cls, config: OnlineProgramConfig) -> None:
        """Refuse a config without a command (called when a trial or campaign config is read)."""
        if not config.command.strip():
            raise ConfigError("params.command: the algorithm 'program' needs the command that starts the program")

    def _started(self, beams: int) -> _Process:
        if self._failure is not None:
            raise ProgramError(f"the program failed earlier ({self._failure}); reset() starts it again")
        if self._process is None:
            self._process = _Process(self.config.command, self.config.reply_timeout)
            self._exchange(
                lambda p: p.send(protocol.start_message(self.laser, beams, self._seed, self._rng_state), "start")
            )
        return self._process

    def _exchange(self, talk):
        """Run ``talk(process)``; a ProgramError ends the program for good (until :meth:`reset`)."""
        process = self._process
        assert process is not None
        try:
            return talk(process)
        except ProgramError as exc:
            self._process, self._failure = None, exc
            process.close()
            raise

    def _ask(self, line: bytes, what: str) -> dict[str, Any]:
        """Send ``line``, read the reply and check it; a broken reply kills the program."""

        def talk(process: _Process) -> dict[str, Any]:
            process.send(line, what)
            answer = process.receive(what)
            try:
                return protocol.parse_reply(answer, what)
            except ProgramError as exc:
                raise process.fail(str(exc)) from None

        return self._exchange(talk)

    def _checked(self, check):
        """``check()``, a ProgramError from it killing the program."""
        return self._exchange(lambda process: _or_fail(process, check))

    def process(self, frame: Reading) -> NDArray[np.float64]:
        """Send the frame; return the pose the program answers (map frame)."""
        if self._final is not None:
            raise ProgramError("the program's run has ended (trajectory() was read); reset() starts another")
        index = len(self._t)
        ranges = np.asarray(frame.ranges)
        self._started(int(ranges.shape[0]))
        what = f"frame {index}"
        reply = self._ask(protocol.frame_message(index, frame), what)

        def read() -> NDArray[np.float64]:
            pose = protocol.parse_pose(reply, what)
            if reply.get("map") is not None:
                self._map = protocol.parse_map(reply["map"], what)
            if "updates" in reply:
                self.updates = _count(reply["updates"], what)
            return pose

        pose = self._checked(read)
        self._t.append(float(frame.t))
        self._poses.append(pose)
        if self._map is None:
            self._draw(pose, ranges)
        return pose

    def _draw(self, pose: NDArray[np.float64], ranges: NDArray[Any]) -> None:
        """Trace the scan at ``pose`` on slam_gmapping's update rule (1 m or 0.5 rad since the last)."""
        if self._last_drawn is not None:
            step = ominus(self._last_drawn, pose)
            if math.hypot(step[0], step[1]) < 1.0 and abs(step[2]) < 0.5:
                return
        self._drawn.integrate_frame(pose, ranges, self.laser)
        self._last_drawn = pose
        self._drawn_grid = None

    def occupancy(self) -> OccupancyGrid:
        """The latest map the program sent, else the map drawn from its poses (one object until the next
        scan is traced into it: the explorer keeps its plans per map object)."""
        if self._map is not None:
            return self._map
        if self._drawn_grid is None:
            self._drawn_grid = self._drawn.occupancy()
        return self._drawn_grid

    def trajectory(self) -> Trajectory:
        """The final estimate of every frame: sends ``end`` once and reads the program's answer."""
        if self._final is not None:
            return self._final
        if self._failure is not None:
            raise ProgramError(f"the program failed earlier ({self._failure}); reset() starts it again")
        t = np.array(self._t, dtype=np.float64)
        poses = np.array(self._poses, dtype=np.float64).reshape(-1, 3)
        if self._process is None:
            self._final = Trajectory(t=t, poses=poses)
            return self._final
        reply = self._ask(protocol.END_MESSAGE, "end")

        def read() -> NDArray[np.float64]:
            final = poses
            if reply.get("trajectory") is not None:
                final = protocol.parse_trajectory(reply["trajectory"], t)
            if reply.get("map") is not None:
                self._map = protocol.parse_map(reply["map"], "end")
            return final

        poses = self._checked(read)
        running = self._process
        assert running is not None
        self._exchange(lambda process: process.finish())
        self._usage = running.usage
        self._process = None
        self._final = Trajectory(t=t, poses=poses)
        return self._final

    def child_usage(self) -> ProcessUsage | None:
        """What the program's process used (CPU time and peak resident memory, with the descendants it
        waited for), once it has exited at the end of the run (:meth:`trajectory`); None before, or for a
        program that failed."""
        return self._usage


def _count(value: Any, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ProgramError(f'protocol: "updates" in the reply to {what} must be a count, got {value!r}')
    return value


def _or_fail(process: _Process, check):
    try:
        return check()
    except ProgramError as exc:
        raise process.fail(str(exc)) from None
