"""Parsing single CARMEN log lines (the format is described in :mod:`slamtrials.io.carmen`).

Each parser takes one line's tokens and returns its numbers, or raises a FormatError naming the file,
the line and the field; :func:`slamtrials.io.carmen_read.read_carmen` stacks them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import FormatError
from slamtrials.io.textfile import parse_floats, parse_int

__all__ = [
    "LaserLine",
    "parse_flaser",
    "parse_robotlaser",
    "parse_odom",
    "parse_truepos",
    "parse_param",
    "param_number",
    "POSES",
    "ROBOT_POSES",
    "EXTRA",
    "CONFIG",
    "ODOM_FIELDS",
    "TRUEPOS_FIELDS",
    "STAMP_COLUMNS",
]

POSES = ("x", "y", "theta", "odom_x", "odom_y", "odom_theta")
ROBOT_POSES = ("laser_pose_x", "laser_pose_y", "laser_pose_theta", "robot_pose_x", "robot_pose_y", "robot_pose_theta")
EXTRA = ("laser_tv", "laser_rv", "forward_safety_dist", "side_safety_dist", "turn_axis")
CONFIG = ("start_angle", "field_of_view", "angular_resolution", "maximum_range", "accuracy")
ODOM_FIELDS = ("x", "y", "theta", "tv", "rv", "accel", "ipc_timestamp", "logger_timestamp")
TRUEPOS_FIELDS = ("true_x", "true_y", "true_theta", *POSES[3:], "ipc_timestamp", "logger_timestamp")


@dataclass(frozen=True, eq=False)
class LaserLine:
    """The numbers of one front-laser line.

    Attributes
    ----------
    ranges:
        float64 ``[n]`` readings (m), ``n`` >= 0 (0: a pose-only line, as SLAM programs write trajectories).
    stamps:
        float64 ``[13]``: the two pose triples (``POSES`` / ``ROBOT_POSES``), the five ROBOTLASER1
        ``EXTRA`` numbers (zeros for FLASER), ``ipc_timestamp`` and ``logger_timestamp``
        (:data:`STAMP_COLUMNS`).
    config:
        float64 ``[5]`` ROBOTLASER1 ``CONFIG`` (rad, rad, rad, m, m), or None for FLASER.
    integers:
        ROBOTLASER1 ``(laser_type, remission_mode)``, or None.
    """

    ranges: NDArray[np.float64]
    stamps: NDArray[np.float64]
    config: NDArray[np.float64] | None = None
    integers: tuple[int, int] | None = None


#: Columns of :attr:`LaserLine.stamps`.
STAMP_COLUMNS = (*POSES, *EXTRA, "ipc_timestamp", "logger_timestamp")


def parse_flaser(path: Path, line: int, tokens: list[str]) -> LaserLine:
    """``FLASER n r_1..r_n x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname logger_timestamp``."""
    if len(tokens) < 2:
        raise FormatError(path, "FLASER line ends before num_readings", line=line)
    n = parse_int(path, line, tokens[1], 2, "num_readings")
    if len(tokens) != n + 11:
        raise FormatError(
            path,
            f"FLASER with num_readings {n} needs {n + 11} fields (FLASER n, {n} ranges, "
            f"6 pose numbers, ipc_timestamp ipc_hostname logger_timestamp), got {len(tokens)}",
            line=line,
        )
    ranges = parse_floats(path, line, tokens[2 : n + 2], 3, "range")
    tail = parse_floats(path, line, tokens[n + 2 : n + 9], n + 3, (*POSES, "ipc_timestamp"))
    logger = parse_floats(path, line, tokens[-1:], n + 11, "logger_timestamp")
    return LaserLine(np.array(ranges), np.array(tail[:6] + [0.0] * len(EXTRA) + tail[6:] + logger))


def parse_robotlaser(path: Path, line: int, tokens: list[str]) -> LaserLine:
    """``ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy
    remission_mode n r_1..r_n m e_1..e_m laser_pose(3) robot_pose(3) laser_tv laser_rv
    forward_safety_dist side_safety_dist turn_axis ipc_timestamp ipc_hostname logger_timestamp``
    (remissions are checked to be numbers, then dropped)."""
    if len(tokens) < 10:
        raise FormatError(path, f"ROBOTLASER1 line ends after {len(tokens)} fields, before its readings", line=line)
    laser_type = parse_int(path, line, tokens[1], 2, "laser_type")
    remission_mode = parse_int(path, line, tokens[7], 8, "remission_mode")
    n = parse_int(path, line, tokens[8], 9, "num_readings")
    if len(tokens) < n + 10:
        raise FormatError(
            path, f"ROBOTLASER1 with num_readings {n} ends after {len(tokens)} fields, before num_remissions", line=line
        )
    m = parse_int(path, line, tokens[n + 9], n + 10, "num_remissions")
    if len(tokens) != n + m + 24:
        raise FormatError(
            path,
            f"ROBOTLASER1 with num_readings {n} and num_remissions {m} needs {n + m + 24} fields, got {len(tokens)}",
            line=line,
        )
    config = parse_floats(path, line, tokens[2:7], 3, CONFIG)
    ranges = parse_floats(path, line, tokens[9 : n + 9], 10, "range")
    parse_floats(path, line, tokens[n + 10 : n + m + 10], n + 11, "remission")
    tail = parse_floats(
        path, line, tokens[n + m + 10 : n + m + 22], n + m + 11, (*ROBOT_POSES, *EXTRA, "ipc_timestamp")
    )
    logger = parse_floats(path, line, tokens[-1:], n + m + 24, "logger_timestamp")
    return LaserLine(np.array(ranges), np.array(tail + logger), np.array(config), (laser_type, remission_mode))


def parse_odom(path: Path, line: int, tokens: list[str]) -> list[float]:
    """``ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp`` -> the 8 numbers."""
    if len(tokens) != 10:
        raise FormatError(
            path,
            "expected 10 fields 'ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp', "
            f"got {len(tokens)}",
            line=line,
        )
    return parse_floats(path, line, tokens[1:8], 2, ODOM_FIELDS[:7]) + parse_floats(
        path, line, tokens[9:], 10, "logger_timestamp"
    )


def parse_truepos(path: Path, line: int, tokens: list[str]) -> list[float]:
    """``TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname
    logger_timestamp`` -> the 8 numbers, every one finite (a simulator's ground truth has no gaps)."""
    if len(tokens) != 10:
        raise FormatError(
            path,
            "expected 10 fields 'TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta ipc_timestamp "
            f"ipc_hostname logger_timestamp', got {len(tokens)}",
            line=line,
        )
    values = parse_floats(path, line, tokens[1:8], 2, TRUEPOS_FIELDS[:7]) + parse_floats(
        path, line, tokens[9:], 10, "logger_timestamp"
    )
    for i, (name, value) in enumerate(zip(TRUEPOS_FIELDS, values)):
        if not math.isfinite(value):
            field = i + 2 if i < 7 else 10
            raise FormatError(path, f"TRUEPOS field {field} ({name}) is not finite: {value}", line=line)
    return values


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def parse_param(path: Path, line: int, tokens: list[str]) -> tuple[str, str]:
    """``PARAM name value [ipc_timestamp] [ipc_hostname logger_timestamp]`` -> ``(name, value)``.

    A value may hold spaces. The trailer is recognised from the end: ``number word number`` (the full
    stamp), or ``word number`` (hostname and logger timestamp without the ipc timestamp, as in
    ``PARAM robot_frontlaser_offset 0.0 nohost 0``), provided a value is left before it.
    """
    if len(tokens) < 3:
        raise FormatError(path, "expected 'PARAM name value [ipc_timestamp ipc_hostname logger_timestamp]'", line=line)
    rest = tokens[2:]
    if len(rest) >= 4 and _is_number(rest[-3]) and not _is_number(rest[-2]) and _is_number(rest[-1]):
        rest = rest[:-3]
    elif len(rest) >= 3 and not _is_number(rest[-2]) and _is_number(rest[-1]):
        rest = rest[:-2]
    elif len(rest) >= 4 and _is_number(rest[-3]) and _is_number(rest[-1]):  # a numeric hostname
        rest = rest[:-3]
    return tokens[1], " ".join(rest)


def param_number(
    path: Path, params: dict[str, str], where: dict[str, int], name: str, positive: bool = True
) -> float | None:
    """The numeric PARAM ``name`` (None if absent): its value's first token, so that trailing fields a
    logger appended are tolerated. FormatError at its line if that is not a finite (positive) number."""
    if name not in params:
        return None
    words = params[name].split()
    try:
        value = float(words[0]) if words else math.nan
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or (positive and value <= 0):
        kind = "a positive number" if positive else "a finite number"
        raise FormatError(path, f"PARAM {name} must be {kind}, got {params[name][:40]!r}", line=where[name])
    return value
