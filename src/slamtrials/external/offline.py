"""Running an external SLAM program over a recording: what ``slamtrials slam --program``, ``campaign
replay --program`` and ``validate --program`` run.

:func:`run_program` writes the recording in the program's input format (odometry and laser only: no
ground truth, no start pose, no scores; :func:`slamtrials.io.transfer.export_record` with
``truth=False``) into a scratch folder, runs the command of its
:class:`~slamtrials.slam.program.ProgramSpec` with ``/bin/sh -c`` in the caller's folder (stdin closed,
in its own process group; ``{workdir}`` is an empty folder of its own), reads the trajectory it wrote, maps its times onto the run's and gives every frame an
estimate (:func:`slamtrials.slam.program.align_to_frames`). The map is the scans traced at that
estimate (:func:`slamtrials.slam.estimatemap.map_of_estimate`). The program's cost is its process's
``rusage`` (:func:`slamtrials.external.childwait.wait_with_usage`): :attr:`ProgramRun.cost`.

Time base: a CARMEN log carries the run's own times. A bag does too when the run's first time is at
least 1 s (a real log's stamps); a run that starts at 0 s (every simulated run) is written from 1 s
on, since ROS reads a zero stamp as "unset", and the program's times are shifted back by that second.

A program that exits with an error, runs past its timeout (its whole process group is killed), writes
nothing, or writes a trajectory that does not parse or does not fit the run raises
:class:`~slamtrials.errors.ProgramError` with its exit code and the last lines of its stderr. The
scratch folder is removed in every case, so nothing is left half-written.
"""

from __future__ import annotations

import os
import shlex
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from slamtrials.cost import ProcessUsage, RunCost
from slamtrials.costmeter import CostMeter
from slamtrials.errors import ConfigError, ProgramError, SlamtrialsError
from slamtrials.external.childwait import wait_with_usage
from slamtrials.record import OccupancyGrid, RunRecord, Trajectory
from slamtrials.slam.offline import SlamRun, run_over_recording
from slamtrials.slam.program import FrameAlignment, ProgramSpec, align_to_frames

__all__ = [
    "ProgramRun",
    "run_program",
    "run_offline",
    "check_program",
    "read_program_output",
    "time_origin_ns",
    "STDERR_LINES",
]

#: Lines of the program's stderr kept with a run (the last ones).
STDERR_LINES = 20

_INPUT_NAMES = {"carmen": "input.clf", "bag": "input.bag", "bag2": "input_bag2"}
_OUTPUT_NAMES = {"tum": "output.tum", "carmen": "output.clf"}


@dataclass(frozen=True, eq=False)
class ProgramRun:
    """What one run of an external program over a recording produced.

    Attributes
    ----------
    spec:
        The program.
    seed:
        The run's seed (given to the command as ``{seed}``).
    command:
        The command as run (placeholders replaced; the scratch paths no longer exist).
    trajectory:
        The poses the program wrote, in the run's time base (s; map frame).
    alignment:
        One estimate per frame (:class:`~slamtrials.slam.program.FrameAlignment`).
    occupancy:
        The map of the estimate.
    seconds:
        Wall time of the program (s), writing the input and reading the output excluded.
    time_origin_s:
        Seconds added to the run's times in the input (0, or 1 for a bag of a run starting at 0 s).
    stderr_tail:
        The last :data:`STDERR_LINES` lines of its stderr.
    cost:
        CPU time and peak memory of the program (its process's ``rusage``) and of the whole run (writing
        the input, the program, reading its output, drawing the map); no time per update (the program
        is timed as a whole). None only where a caller built the run without one.
    """

    spec: ProgramSpec
    seed: int
    command: str
    trajectory: Trajectory
    alignment: FrameAlignment
    occupancy: OccupancyGrid
    seconds: float
    time_origin_s: float
    stderr_tail: tuple[str, ...]
    cost: RunCost | None = None

    @property
    def estimate(self) -> np.ndarray:
        """float64 ``[T, 3]``: the estimate at each frame (map frame)."""
        return self.alignment.estimate


def time_origin_ns(record: RunRecord, input_format: str) -> int:
    """Nanoseconds added to the run's times in the program's input (see the module docstring)."""
    from slamtrials.io.ros_messages import DEFAULT_TIME_ORIGIN_NS

    if input_format == "carmen" or (len(record) and float(record.t[0]) >= 1.0):
        return 0
    return DEFAULT_TIME_ORIGIN_NS


def _first_word(spec: ProgramSpec) -> str | None:
    """The program the command starts (None when it starts with a shell construct)."""
    dummy = spec.command_for(input="in", output="out", seed=0, workdir="work")
    try:
        words = shlex.split(dummy)
    except ValueError:
        return None
    for word in words:
        if "=" in word.split("/", 1)[0]:
            continue  # VAR=value before the program
        return word
    return None


def check_program(spec: ProgramSpec, cwd: str | Path | None = None) -> None:
    """Refuse a command whose program cannot be found (not on PATH, nor a file relative to ``cwd``).

    Raises
    ------
    ConfigError
        The program is not found.
    """
    word = _first_word(spec)
    if word is None:
        return
    base = Path(cwd) if cwd is not None else Path.cwd()
    if "/" in word:
        path = Path(word) if Path(word).is_absolute() else base / word
        if not path.is_file():
            raise ConfigError(f"program {word!r} of the command not found (no such file from {base})")
        return
    found = subprocess.run(  # the shell's own lookup: builtins (".", "ulimit", ...), keywords and PATH
        ["/bin/sh", "-c", 'command -v -- "$1" >/dev/null', "sh", word], cwd=base, stdin=subprocess.DEVNULL
    )
    if found.returncode != 0:
        raise ConfigError(f"program {word!r} of the command not found on PATH")


def read_program_output(path: Path, output_format: str) -> Trajectory:
    """The trajectory a program wrote: a TUM file, or a CARMEN log's laser lines (their first pose triple;
    a pose-only log's second, as the Freiburg tools read one), at their timestamps.

    Raises
    ------
    FormatError
        The file does not parse in that format (naming the line).
    """
    if output_format == "tum":
        from slamtrials.io.tum import read_tum

        return read_tum(path)
    from slamtrials.io.carmen import read_carmen

    laser = read_carmen(path, ranges=False).laser
    return Trajectory(t=laser.t, poses=laser.odometry if laser.pose_only else laser.pose)


def _tail(path: Path) -> tuple[str, ...]:
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return ()
    lines = [line.rstrip() for line in text.splitlines() if line.strip()]
    return tuple(lines[-STDERR_LINES:])


def _said(tail: tuple[str, ...], count: int = 3) -> str:
    """The last ``count`` stderr lines, as one line."""
    return f"; its stderr ends: {' | '.join(tail[-count:])}" if tail else "; its stderr is empty"


def _kill(process: subprocess.Popen) -> None:
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    process.wait()


def _run_command(
    command: str, cwd: Path, work: Path, timeout: float
) -> tuple[float, tuple[str, ...], ProcessUsage | None]:
    """Run ``command``; return (seconds, stderr tail, what its process used). Raises ProgramError on a
    failure of the program."""
    out_log, err_log = work / "stdout.txt", work / "stderr.txt"
    started = time.perf_counter()
    with open(out_log, "wb") as stdout, open(err_log, "wb") as stderr:
        process = subprocess.Popen(
            ["/bin/sh", "-c", command],
            cwd=cwd,
            stdin=subprocess.DEVNULL,
            stdout=stdout,
            stderr=stderr,
            start_new_session=True,  # its own process group, so a timeout kills its children too
        )
        try:
            code, usage = wait_with_usage(process, timeout)
        except subprocess.TimeoutExpired:
            _kill(process)
            tail = _tail(err_log)
            raise ProgramError(
                f"the program ran past its timeout of {timeout:g} s and was killed{_said(tail)}", stderr_tail=tail
            ) from None
        except BaseException:
            _kill(process)
            raise
    seconds = time.perf_counter() - started
    tail = _tail(err_log)
    if code != 0:
        what = "was not found" if code == 127 else f"exited with status {code}"
        raise ProgramError(f"the program {what} after {seconds:.1f} s{_said(tail)}", exit_code=code, stderr_tail=tail)
    return seconds, tail, usage


def run_program(
    record: RunRecord,
    spec: ProgramSpec,
    seed: int = 0,
    *,
    cwd: str | Path | None = None,
    scratch: str | Path | None = None,
    resolution: float = 0.05,
) -> ProgramRun:
    """Run program ``spec`` over ``record`` and carry its trajectory onto the frames (module docstring).

    Parameters
    ----------
    record:
        The recording (its ground truth, if any, is not written).
    spec:
        The program.
    seed:
        Given to the command as ``{seed}``.
    cwd:
        The command's working directory (default: the current one), so relative paths in the command
        mean what they mean where slamtrials was started.
    scratch:
        Folder in which the scratch folder is made (default: the system's temporary folder).
    resolution:
        Cell size (m) of the map of the estimate.

    Raises
    ------
    ConfigError
        A recording without frames, or one the input format cannot hold.
    ProgramError
        The program failed, timed out, wrote nothing, or wrote a trajectory that does not parse or fit.
    """
    from slamtrials.io.transfer import export_record
    from slamtrials.slam.estimatemap import map_of_estimate

    if len(record) == 0:
        raise ConfigError("the recording has no frames")
    meter = CostMeter()
    run_dir = Path(cwd) if cwd is not None else Path.cwd()
    origin_ns = time_origin_ns(record, spec.input)
    with tempfile.TemporaryDirectory(prefix="slamtrials-program-", dir=scratch) as tmp:
        work = Path(tmp)
        workdir = work / "workdir"
        workdir.mkdir()
        input_path = work / _INPUT_NAMES[spec.input]
        output_path = work / _OUTPUT_NAMES[spec.output]
        export_record(record, input_path, spec.input, truth=False, time_origin_ns=origin_ns)
        command = spec.command_for(input=str(input_path), output=str(output_path), seed=seed, workdir=str(workdir))
        seconds, tail, usage = _run_command(command, run_dir, work, spec.timeout)
        if not output_path.is_file() or output_path.stat().st_size == 0:
            raise ProgramError(
                f"the program exited with status 0 after {seconds:.1f} s but wrote nothing to {{output}}{_said(tail)}",
                exit_code=0,
                stderr_tail=tail,
            )
        try:
            written = read_program_output(output_path, spec.output)
            alignment = align_to_frames(written, record.t, record.odometry, time_shift=origin_ns * 1e-9)
        except SlamtrialsError as exc:
            problem = str(exc).replace(str(output_path), "{output}")
            raise ProgramError(
                f"the program's output ({spec.output}) cannot be used: {problem}", exit_code=0, stderr_tail=tail
            ) from None
    trajectory = Trajectory(t=np.asarray(written.t, dtype=np.float64) - origin_ns * 1e-9, poses=written.poses)
    occupancy = map_of_estimate(alignment.estimate, record.scans, record.laser, resolution=resolution)
    cost = meter.finish(usage, in_child=True)
    return ProgramRun(
        spec=spec,
        seed=int(seed),
        command=command,
        trajectory=trajectory,
        alignment=alignment,
        occupancy=occupancy,
        seconds=seconds,
        time_origin_s=origin_ns * 1e-9,
        stderr_tail=tail,
        cost=cost,
    )


def run_offline(
    record: RunRecord,
    algorithm: str,
    *,
    preset: str | None = None,
    overrides: dict | None = None,
    program: ProgramSpec | None = None,
    seed: int = 0,
) -> SlamRun:
    """A registered algorithm (:func:`slamtrials.slam.offline.run_over_recording`) or, when ``program`` is
    given, that program (:func:`run_program`) over ``record``, as a
    :class:`~slamtrials.slam.offline.SlamRun`.

    For a program, the SlamRun's ``trajectory`` and ``online`` are its estimate at every frame, its
    ``config`` the :class:`~slamtrials.slam.program.ProgramSpec`, ``updates`` the poses it wrote,
    ``timing`` NaN (a program is timed as a whole: the total is spread over no frame) and ``cost`` the
    program's (:attr:`ProgramRun.cost`).

    Raises
    ------
    ConfigError, ProgramError
        As the two functions raise them.
    """
    if program is None:
        return run_over_recording(record, algorithm, preset=preset, overrides=overrides, seed=seed)
    ran = run_program(record, program, seed)
    return SlamRun(
        algorithm=program.label,
        preset=None,
        config=program,
        seed=int(seed),
        trajectory=Trajectory(t=np.asarray(record.t, dtype=np.float64), poses=ran.estimate),
        online=ran.estimate,
        occupancy=ran.occupancy,
        timing=np.full(len(record), np.nan),
        updates=ran.alignment.poses_read,
        cost=ran.cost,
    )
