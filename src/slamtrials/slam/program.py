"""A SLAM algorithm that is a program: what to run (:class:`ProgramSpec`) and how its trajectory becomes
one pose per frame (:func:`align_to_frames`).

A program is evaluated offline: slamtrials writes the recording (odometry and laser only) in the format
the program reads, runs its command, reads the trajectory it writes and scores it. Running it is the
job of :mod:`slamtrials.external` (files and processes); this module holds the pure parts.

A program rarely writes a pose for every frame: scan matchers report a pose when they process a scan,
and that may be every few frames or at times of their own. :func:`align_to_frames` gives every frame
the pose a robot running the program would have reported then: the correction (map from odometry) of
the program's latest pose at or before the frame, applied to the frame's odometry. This is how the
``map -> odom`` transform of a ROS SLAM node is used between its updates. At a frame the program wrote
a pose for, that pose is the estimate.
"""

from __future__ import annotations

import shlex
import string
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, field_validator

from slamtrials.errors import ConfigError
from slamtrials.geometry import compose, inverse, wrap_angle
from slamtrials.record import Trajectory

__all__ = [
    "ProgramSpec",
    "program_spec",
    "PLACEHOLDERS",
    "FrameAlignment",
    "align_to_frames",
    "SAME_FRAME",
    "MIN_COVERED_SHARE",
]

#: The placeholders a command may hold: ``{input}`` (the recording written for the program),
#: ``{output}`` (where it writes its trajectory), ``{seed}`` (the run's seed) and ``{workdir}`` (an
#: empty scratch folder for the program's own files; the command runs in the folder slamtrials was
#: started in, so relative paths in it mean what they mean there).
PLACEHOLDERS = ("input", "output", "seed", "workdir")

#: Words that start a program rather than name it (the label takes the next word).
_INTERPRETERS = {"python", "sh", "bash", "env", "exec", "perl", "ruby", "node", "java", "julia", "Rscript", "nice"}

#: A program pose within this many seconds of a frame is that frame's pose.
SAME_FRAME = 1e-3

#: A trajectory whose poses span less than this share of the run's duration is refused: the program
#: stopped early, and odometry would stand in for most of its estimate.
MIN_COVERED_SHARE = 0.5


class ProgramSpec(BaseModel):
    """An external SLAM program, evaluated offline over a recording.

    Attributes
    ----------
    command:
        Shell command template (run by ``/bin/sh -c`` in the folder slamtrials was started in, stdin
        closed). It must hold ``{input}`` and ``{output}``, and may hold ``{seed}`` and ``{workdir}``;
        each is replaced by a shell-quoted value. Write ``{{`` and ``}}`` for literal braces.
    input:
        The format slamtrials writes the recording in: ``carmen`` (a CARMEN log, ROBOTLASER1 and ODOM
        lines, odometry in both pose triples), ``bag`` (ROS 1) or ``bag2`` (ROS 2, MCAP). No ground
        truth in any of them.
    output:
        The format of the trajectory the program writes to ``{output}``: ``tum`` (``t x y z qx qy qz
        qw``) or ``carmen`` (a CARMEN log whose laser lines' first pose triple is the estimate; a
        pose-only log's second, as the Freiburg tools read it).
    timeout:
        Seconds the program may run on one recording before it is killed and the run fails.
    name:
        Label of the algorithm in tables and reports; default ``program:<first word of the command>``.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    command: str = Field(..., min_length=1, description="shell command with {input} and {output}")
    input: Literal["carmen", "bag", "bag2"] = Field("carmen", description="format of the recording given")
    output: Literal["tum", "carmen"] = Field("tum", description="format of the trajectory written")
    timeout: float = Field(3600.0, gt=0.0, le=7.0 * 86400.0, description="seconds before the program is killed")
    name: str | None = Field(None, min_length=1, description="label in tables and reports")

    @field_validator("command")
    @classmethod
    def _placeholders(cls, command: str) -> str:
        fields = _template_fields(command)
        unknown = sorted(fields - set(PLACEHOLDERS))
        if unknown:
            raise ValueError(
                f"unknown placeholder {{{unknown[0]}}} in the command; known: "
                + ", ".join("{" + p + "}" for p in PLACEHOLDERS)
            )
        missing = [p for p in ("input", "output") if p not in fields]
        if missing:
            raise ValueError(
                f"the command must hold {{{missing[0]}}}: where the program reads the recording ({{input}}) "
                "and writes its trajectory ({output})"
            )
        return command

    @property
    def label(self) -> str:
        """The name shown in tables and reports."""
        if self.name:
            return self.name
        try:
            words = shlex.split(self.command.replace("{", "").replace("}", ""))
        except ValueError:
            words = self.command.split()
        named = [w for w in words if "=" not in w.split("/", 1)[0] and not w.startswith("-")]
        while len(named) > 1 and named[0].rsplit("/", 1)[-1].rstrip("0123456789.") in _INTERPRETERS:
            named = named[1:]
        if not named:
            return "program:program"
        if any(c.isspace() for c in named[0]):  # sh -c '<script>': the interpreter names it
            return "program:" + words[0].rsplit("/", 1)[-1]
        return "program:" + named[0].rsplit("/", 1)[-1]

    def command_for(self, *, input: str, output: str, seed: int, workdir: str) -> str:
        """The command with every placeholder replaced by its shell-quoted value."""
        values = {"input": input, "output": output, "seed": str(int(seed)), "workdir": workdir}
        return self.command.format(**{k: shlex.quote(v) for k, v in values.items()})


def _template_fields(command: str) -> set[str]:
    try:
        parsed = list(string.Formatter().parse(command))
    except ValueError as exc:
        raise ValueError(
            f"the command is not a valid template ({exc}); write {{{{ and }}}} for literal braces"
        ) from None
    fields = set()
    for _, name, spec, conversion in parsed:
        if name is None:
            continue
        if spec or conversion or not name:
            raise ValueError(
                f"placeholder {{{name}{'!' + conversion if conversion else ''}{':' + spec if spec else ''}}} "
                "takes no format; write {input}, {output}, {seed} or {workdir}"
            )
        fields.add(name)
    return fields


@dataclass(frozen=True, eq=False)
class FrameAlignment:
    """A program's trajectory carried onto the frames of the run it processed.

    Attributes
    ----------
    estimate:
        float64 ``[T, 3]``: the estimate at each frame (map frame, m and rad).
    poses_read:
        Poses the program wrote (after dropping repeated times).
    frames_at_pose:
        Frames the program wrote a pose for (within :data:`SAME_FRAME`).
    frames_carried:
        Frames whose estimate is a program pose's correction applied to the frame's odometry.
    """

    estimate: NDArray[np.float64]
    poses_read: int
    frames_at_pose: int
    frames_carried: int


def _odometry_at(t_frames: NDArray[np.float64], odometry: NDArray[np.float64], times: NDArray[np.float64]):
    """Odometry poses interpolated at ``times`` (inside the frames' span; heading unwrapped)."""
    theta = np.unwrap(odometry[:, 2])
    return np.stack(
        [
            np.interp(times, t_frames, odometry[:, 0]),
            np.interp(times, t_frames, odometry[:, 1]),
            wrap_angle(np.interp(times, t_frames, theta)),
        ],
        axis=1,
    )


def align_to_frames(
    trajectory: Trajectory,
    t_frames: NDArray[np.float64],
    odometry: NDArray[np.float64],
    *,
    time_shift: float = 0.0,
    span_tolerance: float = 1.0,
) -> FrameAlignment:
    """One estimate per frame from a program's trajectory (see the module docstring).

    Parameters
    ----------
    trajectory:
        What the program wrote: times (s, in the time base of the recording it was given) and poses.
    t_frames:
        float64 ``[T]``: the run's frame times (s), increasing.
    odometry:
        float64 ``[T, 3]``: the run's odometry at each frame (odometry frame).
    time_shift:
        Seconds subtracted from the program's times to bring them to the run's (a bag's time origin).
    span_tolerance:
        Seconds the program's poses may lie outside the run's span.

    Raises
    ------
    ConfigError
        No poses, non-finite values, times that go back, times that cannot be mapped onto the run's
        (outside its span: another time base or another recording), or poses spanning less than
        :data:`MIN_COVERED_SHARE` of the run.
    """
    t_frames = np.asarray(t_frames, dtype=np.float64)
    odometry = np.asarray(odometry, dtype=np.float64)
    t = np.asarray(trajectory.t, dtype=np.float64) - float(time_shift)
    poses = np.asarray(trajectory.poses, dtype=np.float64)
    if len(t) == 0:
        raise ConfigError("the program's trajectory holds no poses")
    bad = ~(np.isfinite(t) & np.isfinite(poses).all(axis=1))
    if bad.any():
        raise ConfigError(f"the program's trajectory has a non-finite time or pose at pose {int(np.argmax(bad)) + 1}")
    back = np.flatnonzero(np.diff(t) < 0)
    if len(back):
        k = int(back[0]) + 1
        raise ConfigError(
            f"the program's trajectory goes back in time at pose {k + 1} ({float(t[k] + time_shift)!r} s after {float(t[k - 1] + time_shift)!r} s)"
        )
    keep = np.concatenate([t[1:] > t[:-1], [True]])  # of equal times, the last pose written
    t, poses = t[keep], poses[keep]
    start, end = float(t_frames[0]), float(t_frames[-1])
    if t[0] < start - span_tolerance or t[-1] > end + span_tolerance:
        shifted = f" after subtracting the input's time origin {time_shift:g} s" if time_shift else ""
        raise ConfigError(
            f"the program's poses span {float(t[0])!r} to {float(t[-1])!r} s{shifted}, outside the run's frames "
            f"({start!r} to {end!r} s): its times cannot be mapped onto the run's (another time base, or "
            "another recording?)"
        )
    duration = end - start
    covered = min(float(t[-1]), end) - max(float(t[0]), start)
    if duration > 0 and covered < MIN_COVERED_SHARE * duration:
        raise ConfigError(
            f"the program's poses span only {max(covered, 0.0):.1f} s of the run's {duration:.1f} s "
            f"(from {float(t[0])!r} to {float(t[-1])!r} s): it stopped early"
        )
    inside = np.clip(t, start, end)
    correction = compose(poses, inverse(_odometry_at(t_frames, odometry, inside)))  # map <- odom at each pose
    latest = np.searchsorted(t, t_frames + SAME_FRAME, side="right") - 1
    latest = np.maximum(latest, 0)  # frames before the first pose take the first pose's correction
    estimate = compose(correction[latest], odometry)
    at_pose = np.abs(t[latest] - t_frames) <= SAME_FRAME
    estimate[at_pose] = poses[latest[at_pose]]
    n_at = int(np.count_nonzero(at_pose))
    return FrameAlignment(
        estimate=np.ascontiguousarray(estimate),
        poses_read=len(t),
        frames_at_pose=n_at,
        frames_carried=len(t_frames) - n_at,
    )


def program_spec(**values: object) -> ProgramSpec:
    """A :class:`ProgramSpec` from keyword values (as command-line options give them).

    Raises
    ------
    ConfigError
        A value the spec refuses, named (``--program``: a command without ``{input}``, ...).
    """
    from pydantic import ValidationError

    from slamtrials.errors import validation_problems

    try:
        return ProgramSpec.model_validate(values)
    except ValidationError as exc:
        raise ConfigError(f"--program: {validation_problems(exc)}") from None
