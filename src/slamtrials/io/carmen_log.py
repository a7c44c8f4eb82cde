"""The contents of a CARMEN log as arrays: :class:`CarmenLaser`, :class:`CarmenOdometry`, :class:`CarmenTruePos`,
:class:`CarmenLog`.

Plain containers with shape checks, filled by :func:`slamtrials.io.carmen.read_carmen` and written by
:func:`slamtrials.io.carmen.write_carmen`. Times are float64 seconds, lengths metres, angles radians.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["CarmenLaser", "CarmenOdometry", "CarmenTruePos", "CarmenLog", "LASER_KINDS", "ROBOTLASER_EXTRA"]

#: The laser line types slamtrials reads and writes (the front laser, old and new format).
LASER_KINDS = ("FLASER", "ROBOTLASER1")

#: The per-line numbers of a ROBOTLASER1 line after its two poses, held in :attr:`CarmenLaser.extra`.
ROBOTLASER_EXTRA = ("laser_tv", "laser_rv", "forward_safety_dist", "side_safety_dist", "turn_axis")


def _hostnames(hostname: str | list[str], n: int) -> list[str]:
    return [hostname] * n if isinstance(hostname, str) else list(hostname)


def _check_host(name: str, hostname: str | list[str], n: int) -> None:
    if not isinstance(hostname, str) and len(hostname) != n:
        raise ValueError(f"{name}.hostname has {len(hostname)} entries for {n} lines")


def _pose_pair_shapes(lines: Any, n: int) -> dict[str, tuple[NDArray, tuple[int, ...]]]:
    """The shapes every line type with two pose triples must have: ``t``, ``logger_t`` ``[n]``, ``pose``
    and ``odometry`` ``[n, 3]`` (laser and TRUEPOS lines)."""
    return {
        "t": (lines.t, (n,)),
        "logger_t": (lines.logger_t, (n,)),
        "pose": (lines.pose, (n, 3)),
        "odometry": (lines.odometry, (n, 3)),
    }


def _check(name: str, arrays: dict[str, tuple[NDArray, tuple[int, ...]]]) -> None:
    for key, (array, shape) in arrays.items():
        if np.shape(array) != shape:
            raise ValueError(f"{name}.{key} has shape {np.shape(array)}, expected {shape}")


@dataclass(eq=False)
class CarmenLaser:
    """The front-laser lines of a log (``FLASER`` or ``ROBOTLASER1``), stacked in file order.

    Attributes
    ----------
    kind:
        ``"FLASER"`` (old format) or ``"ROBOTLASER1"``.
    t:
        float64 ``[N]`` ``ipc_timestamp`` of each line (s), strictly increasing.
    logger_t:
        float64 ``[N]`` ``logger_timestamp`` (s since the logger started).
    hostname:
        ``ipc_hostname``: one string for every line, or a list of ``N`` strings.
    ranges:
        float32 ``[N, B]`` ranges (m); beam ``i`` at angle ``angle_min + i * angle_increment`` in the laser
        frame, counter-clockwise.
    pose:
        float64 ``[N, 3]`` the first pose triple: FLASER ``x y theta``, ROBOTLASER1 ``laser_pose``: the pose
        of the laser as the robot knows it. In logs of real robots the laser's odometry pose, often
        corrected by a SLAM program; in runs slamtrials exports, the odometry of the base composed with
        the laser mount (odometry frame); in ``trajectory.clf`` of ``slamtrials slam``, the SLAM estimate
        of the base. Never the ground truth: that is in :class:`CarmenTruePos`.
    odometry:
        float64 ``[N, 3]`` the second pose triple: FLASER ``odom_x odom_y odom_theta``, ROBOTLASER1
        ``robot_pose``: the raw odometry of the robot base.
    angle_min, angle_increment:
        Angle of beam 0 and between beams (rad).
    range_max:
        Maximum range (m); a reading of ``range_max`` or more means no return.
    laser_type, accuracy, remission_mode:
        ROBOTLASER1's configuration fields, kept for writing (not used by slamtrials).
    extra:
        float64 ``[N, 5]`` ROBOTLASER1's ``laser_tv laser_rv forward_safety_dist side_safety_dist
        turn_axis`` (m/s, rad/s, m, m, m), or None (FLASER, or not known: written as zeros).
    line_readings:
        int64 ``[N]`` number of readings each line held in the file (set by the reader: the scans may
        have been padded to a common grid, or not read at all), or None (then ``B`` for every line).
    line_numbers:
        int64 ``[N]`` the 1-based file line of each laser line (set by the reader, for errors found after
        reading), or None.
    """

    kind: str
    t: NDArray[np.float64]
    logger_t: NDArray[np.float64]
    hostname: str | list[str]
    ranges: NDArray[np.float32]
    pose: NDArray[np.float64]
    odometry: NDArray[np.float64]
    angle_min: float
    angle_increment: float
    range_max: float
    laser_type: int = 0
    accuracy: float = 0.0
    remission_mode: int = 0
    extra: NDArray[np.float64] | None = None
    line_readings: NDArray[np.int64] | None = None
    line_numbers: NDArray[np.int64] | None = None

    def __post_init__(self) -> None:
        if self.kind not in LASER_KINDS:
            raise ValueError(f"CarmenLaser.kind must be one of {LASER_KINDS}, got {self.kind!r}")
        n = len(self.t)
        if np.ndim(self.ranges) != 2 or len(self.ranges) != n:
            raise ValueError(f"CarmenLaser.ranges has shape {np.shape(self.ranges)}, expected [{n}, B]")
        shapes = _pose_pair_shapes(self, n)
        if self.extra is not None:
            shapes["extra"] = (self.extra, (n, len(ROBOTLASER_EXTRA)))
        if self.line_readings is not None:
            shapes["line_readings"] = (self.line_readings, (n,))
        if self.line_numbers is not None:
            shapes["line_numbers"] = (self.line_numbers, (n,))
        _check("CarmenLaser", shapes)
        _check_host("CarmenLaser", self.hostname, n)

    def __len__(self) -> int:
        return len(self.t)

    @property
    def beams(self) -> int:
        """Number of beams per scan, ``B``."""
        return int(self.ranges.shape[1])

    def hostnames(self) -> list[str]:
        """The ``ipc_hostname`` of every line, a list of ``N`` strings."""
        return _hostnames(self.hostname, len(self))

    @property
    def pose_only(self) -> bool:
        """No line held a reading: a trajectory written as laser lines (``FLASER 0 x y th x y th ...``)."""
        if self.line_readings is not None:
            return not bool(np.any(self.line_readings))
        return self.beams == 0


@dataclass(eq=False)
class CarmenOdometry:
    """The ``ODOM`` lines of a log, stacked in file order (``M`` may be 0).

    Attributes
    ----------
    t:
        float64 ``[M]`` ``ipc_timestamp`` (s), non-decreasing.
    logger_t:
        float64 ``[M]`` ``logger_timestamp`` (s).
    hostname:
        ``ipc_hostname``: one string for every line, or a list of ``M`` strings.
    pose:
        float64 ``[M, 3]`` odometry pose ``x y theta`` (m, rad).
    tv, rv, accel:
        float64 ``[M]`` translational velocity (m/s), rotational velocity (rad/s), acceleration (m/s^2).
    """

    t: NDArray[np.float64]
    logger_t: NDArray[np.float64]
    hostname: str | list[str]
    pose: NDArray[np.float64]
    tv: NDArray[np.float64]
    rv: NDArray[np.float64]
    accel: NDArray[np.float64]

    def __post_init__(self) -> None:
        m = len(self.t)
        shapes = {"t": (self.t, (m,)), "logger_t": (self.logger_t, (m,)), "pose": (self.pose, (m, 3))}
        shapes.update({key: (getattr(self, key), (m,)) for key in ("tv", "rv", "accel")})
        _check("CarmenOdometry", shapes)
        _check_host("CarmenOdometry", self.hostname, m)

    def __len__(self) -> int:
        return len(self.t)

    @classmethod
    def empty(cls) -> CarmenOdometry:
        """A log without ODOM lines."""
        zeros = np.zeros(0)
        return cls(
            t=zeros,
            logger_t=zeros.copy(),
            hostname=[],
            pose=np.zeros((0, 3)),
            tv=zeros.copy(),
            rv=zeros.copy(),
            accel=zeros.copy(),
        )

    def hostnames(self) -> list[str]:
        """The ``ipc_hostname`` of every line, a list of ``M`` strings."""
        return _hostnames(self.hostname, len(self))


@dataclass(eq=False)
class CarmenTruePos:
    """The ``TRUEPOS`` lines of a log, stacked in timestamp order (``M`` may be 0): a simulator's ground truth.

    CARMEN's simulator publishes the robot's true pose with its odometry pose, and CARMEN's logger writes
    them as ``TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname
    logger_timestamp``; slamtrials writes one per frame of a run exported with its ground truth.

    Attributes
    ----------
    t:
        float64 ``[M]`` ``ipc_timestamp`` (s), non-decreasing.
    logger_t:
        float64 ``[M]`` ``logger_timestamp`` (s).
    hostname:
        ``ipc_hostname``: one string for every line, or a list of ``M`` strings.
    pose:
        float64 ``[M, 3]`` ``true_x true_y true_theta``: the ground-truth pose of the robot base in the
        world frame (m, m, rad).
    odometry:
        float64 ``[M, 3]`` ``odom_x odom_y odom_theta``: the odometry of the base (odometry frame).
    line_numbers:
        int64 ``[M]`` the 1-based file line of each TRUEPOS line (set by the reader), or None.
    """

    t: NDArray[np.float64]
    logger_t: NDArray[np.float64]
    hostname: str | list[str]
    pose: NDArray[np.float64]
    odometry: NDArray[np.float64]
    line_numbers: NDArray[np.int64] | None = None

    def __post_init__(self) -> None:
        m = len(self.t)
        shapes = _pose_pair_shapes(self, m)
        if self.line_numbers is not None:
            shapes["line_numbers"] = (self.line_numbers, (m,))
        _check("CarmenTruePos", shapes)
        _check_host("CarmenTruePos", self.hostname, m)

    def __len__(self) -> int:
        return len(self.t)

    @classmethod
    def empty(cls) -> CarmenTruePos:
        """A log without TRUEPOS lines."""
        return cls(t=np.zeros(0), logger_t=np.zeros(0), hostname=[], pose=np.zeros((0, 3)), odometry=np.zeros((0, 3)))

    def hostnames(self) -> list[str]:
        """The ``ipc_hostname`` of every line, a list of ``M`` strings."""
        return _hostnames(self.hostname, len(self))


@dataclass(eq=False)
class CarmenLog:
    """What slamtrials reads from and writes to a CARMEN log.

    Attributes
    ----------
    laser:
        The front-laser lines.
    odom:
        The ODOM lines (possibly none).
    params:
        ``PARAM`` lines, name -> value as written (a later line overrides an earlier one).
    skipped:
        Line types read past without being interpreted (e.g. ``RLASER``, ``RAWLASER1``, ``SYNC``, and
        ``FLASER`` in a log that also holds ``ROBOTLASER1`` lines, which are read instead) -> number of
        such lines. Never written back.
    tolerated:
        Oddities the reader tolerated -> number of lines (keys and meanings in
        :data:`slamtrials.io.carmen_read.TOLERATED`: lines with non-finite poses skipped, timestamps
        reordered, a truncated last line, scans padded, ...). Never written back.
    truepos:
        The TRUEPOS lines (possibly none): the ground truth of a simulated run.
    comments:
        Lines written as ``# ...`` comments after the format header (without the ``#``): what the pose
        triples of this log hold. Not read back (the reader ignores comments).
    path:
        The file the log was read from (set by the reader), named by errors found after reading; None
        for a log built in memory.
    """

    laser: CarmenLaser
    odom: CarmenOdometry = field(default_factory=CarmenOdometry.empty)
    params: dict[str, str] = field(default_factory=dict)
    skipped: dict[str, int] = field(default_factory=dict)
    tolerated: dict[str, int] = field(default_factory=dict)
    truepos: CarmenTruePos = field(default_factory=CarmenTruePos.empty)
    comments: tuple[str, ...] = ()
    path: Path | None = None
