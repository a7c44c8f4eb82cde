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
for the program to exit. A program that exits early, answers late or breaks the protocol raises
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

from slamtrials.errors import ConfigError, ProgramError
from slamtrials.external import protocol
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

    def __init__(self, command: str):
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
        self._closer = weakref.finalize(self, _kill_group, self.popen, self.scratch)

    def tail(self) -> tuple[str, ...]:
        try:
            text = self.err_path.read_text(encoding="utf-8", errors="replace")
        except OSError:
            return ()
        return tuple(line.rstrip() for line in text.splitlines() if line.strip())[-20:]

    def fail(self, problem: str) -> ProgramError:
        code = self.popen.poll()
        tail = self.tail()
        said = f"; its stderr ends: {' | '.join(tail[-3:])}" if tail else ""
        self.close()
        return ProgramError(f"{problem}{said}", exit_code=code, stderr_tail=tail)

    def send(self, line: bytes, what: str) -> None:
        try:
            assert self.popen.stdin is not None
            self.popen.stdin.write(line)
            self.popen.stdin.flush()
        except (BrokenPipeError, OSError):
            raise self.fail(f"the program exited before {what} (status {self.popen.wait()})") from None

    def receive(self, timeout: float, what: str) -> bytes:
        assert self.popen.stdout is not None
        fd = self.popen.stdout.fileno()
        deadline = time.monotonic() + timeout
        while True:
            end = self._buffer.find(b"\n")
            if end >= 0:
                line = bytes(self._buffer[:end])
                del self._buffer[: end + 1]
                return line
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise self.fail(f"the program did not answer {what} within {timeout:g} s")
            ready, _, _ = select.select([fd], [], [], remaining)
            if not ready:
                continue
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                raise self.fail(f"the program exited before answering {what} (status {self.popen.wait()})")
            self._buffer += chunk

    def finish(self, timeout: float) -> None:
        """Close its stdin and wait for a zero exit status."""
        try:
            assert self.popen.stdin is not None
            self.popen.stdin.close()
        except OSError:
            pass
        try:
            code = self.popen.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            raise self.fail(f"the program did not exit within {timeout:g} s of the end") from None
        if code != 0:
            raise self.fail(f"the program exited with status {code} at the end")
        self.close()

    def close(self) -> None:
        self._closer()


def _kill_group(popen: subprocess.Popen, scratch: tempfile.TemporaryDirectory) -> None:
    if popen.poll() is None:
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
        if not config.command.strip():
            raise ConfigError("slam.params.command: the program algorithm needs the command that starts it")
        self.config = config
        self.laser = laser
        self._process: _Process | None = None
        self.updates = 0

    def reset(self, rng: np.random.Generator) -> None:
        """Start the program afresh and send it ``start`` (its seed from ``rng``'s state, not a draw)."""
        if self._process is not None:
            self._process.close()
        self._rng_state = rng.bit_generator.state
        self._seed = int(self._rng_state.get("state", {}).get("state", 0)) & 0xFFFFFFFF
        self._process = None
        self._t: list[float] = []
        self._poses: list[NDArray[np.float64]] = []
        self._map: OccupancyGrid | None = None
        self._drawn = GridMap(self.config.resolution)
        self._last_drawn: NDArray[np.float64] | None = None
        self._final: Trajectory | None = None
        self.updates = 0

    def _started(self, beams: int) -> _Process:
        if self._process is None:
            self._process = _Process(self.config.command)
            self._process.send(protocol.start_message(self.laser, beams, self._seed, self._rng_state), "start")
        return self._process

    def process(self, frame: Reading) -> NDArray[np.float64]:
        """Send the frame; return the pose the program answers (map frame)."""
        if self._final is not None:
            raise ProgramError("the program's run has ended (trajectory() was read); reset() starts another")
        index = len(self._t)
        ranges = np.asarray(frame.ranges)
        process = self._started(int(ranges.shape[0]))
        what = f"frame {index}"
        process.send(protocol.frame_message(index, frame), what)
        try:
            reply = protocol.parse_reply(process.receive(self.config.reply_timeout, what), what)
            pose = protocol.parse_pose(reply, what)
            if reply.get("map") is not None:
                self._map = protocol.parse_map(reply["map"], what)
            if "updates" in reply:
                self.updates = _count(reply["updates"], what)
        except ProgramError as exc:
            if exc.stderr_tail or self._process is None:
                raise
            raise process.fail(str(exc)) from None
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

    def occupancy(self) -> OccupancyGrid:
        """The latest map the program sent, else the map drawn from its poses."""
        return self._map if self._map is not None else self._drawn.occupancy()

    def trajectory(self) -> Trajectory:
        """The final estimate of every frame: sends ``end`` once and reads the program's answer."""
        if self._final is not None:
            return self._final
        t = np.array(self._t, dtype=np.float64)
        poses = np.array(self._poses, dtype=np.float64).reshape(-1, 3)
        if self._process is None:
            self._final = Trajectory(t=t, poses=poses)
            return self._final
        process = self._process
        process.send(protocol.END_MESSAGE, "end")
        reply = protocol.parse_reply(process.receive(self.config.reply_timeout, "end"), "end")
        try:
            if reply.get("trajectory") is not None:
                poses = protocol.parse_trajectory(reply["trajectory"], t)
            if reply.get("map") is not None:
                self._map = protocol.parse_map(reply["map"], "end")
        except ProgramError as exc:
            raise process.fail(str(exc)) from None
        process.finish(self.config.reply_timeout)
        self._process = None
        self._final = Trajectory(t=t, poses=poses)
        return self._final


def _count(value: Any, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ProgramError(f'protocol: "updates" in the reply to {what} must be a count, got {value!r}')
    return value
