"""Reading CARMEN logs: :func:`read_carmen` (the format is described in :mod:`slamtrials.io.carmen`)."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import FormatError
from slamtrials.io.carmen_log import LASER_KINDS, CarmenLaser, CarmenLog, CarmenOdometry
from slamtrials.io.textfile import data_lines, first_bad_row, last_line, parse_floats, parse_int, read_lines

__all__ = ["read_carmen", "PARAM_RANGE_MAX", "PARAM_FOV", "PARAM_RESOLUTION", "PARAM_MOUNT", "PARAM_RANGE_MIN"]

#: PARAM names that give an old-format (FLASER) laser's geometry: metres, degrees, degrees.
PARAM_RANGE_MAX = "robot_front_laser_max"
PARAM_FOV = "laser_front_laser_fov"
PARAM_RESOLUTION = "laser_front_laser_resolution"
#: PARAM names of the laser's mounting on the robot base: forward and left offsets (m), angle (rad).
PARAM_MOUNT = ("robot_frontlaser_offset", "robot_frontlaser_side_offset", "robot_frontlaser_angular_offset")
#: Not a CARMEN parameter: the minimum range (m) of a laser simulated by slamtrials.
PARAM_RANGE_MIN = "slamtrials_laser_range_min"

_POSES = ("x", "y", "theta", "odom_x", "odom_y", "odom_theta")
_ROBOT_POSES = ("laser_pose_x", "laser_pose_y", "laser_pose_theta", "robot_pose_x", "robot_pose_y", "robot_pose_theta")
_EXTRA = ("laser_tv", "laser_rv", "forward_safety_dist", "side_safety_dist", "turn_axis")
_CONFIG = ("start_angle", "field_of_view", "angular_resolution", "maximum_range", "accuracy")
_ODOM = ("x", "y", "theta", "tv", "rv", "accel", "ipc_timestamp", "logger_timestamp")


def _flaser(path: Path, line: int, tokens: list[str]) -> tuple[NDArray[np.float64], int]:
    """``FLASER n r_1..r_n x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname logger_timestamp``
    -> ``[r_1..r_n, x..odom_theta, ipc_timestamp, logger_timestamp]``."""
    if len(tokens) < 2:
        raise FormatError(path, "FLASER line ends before num_readings", line=line)
    n = parse_int(path, line, tokens[1], 2, "num_readings", minimum=1)
    if len(tokens) != n + 11:
        raise FormatError(path, f"FLASER with num_readings {n} needs {n + 11} fields (FLASER n, {n} ranges, "
                          f"6 pose numbers, ipc_timestamp ipc_hostname logger_timestamp), got {len(tokens)}", line=line)
    values = parse_floats(path, line, tokens[2 : n + 9], 3, "range, pose or ipc_timestamp")
    values += parse_floats(path, line, tokens[-1:], n + 11, "logger_timestamp")
    return np.array(values), n


def _robotlaser(path: Path, line: int, tokens: list[str]) -> tuple[NDArray[np.float64], int, tuple[int, int]]:
    """``ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy
    remission_mode n r_1..r_n m e_1..e_m laser_pose(3) robot_pose(3) laser_tv laser_rv
    forward_safety_dist side_safety_dist turn_axis ipc_timestamp ipc_hostname logger_timestamp``
    -> ``[start_angle..accuracy, r_1..r_n, laser_pose, robot_pose, laser_tv..turn_axis, ipc_timestamp,
    logger_timestamp]`` (remissions are checked to be numbers, then dropped) and the two integers."""
    if len(tokens) < 10:
        raise FormatError(path, f"ROBOTLASER1 line ends after {len(tokens)} fields, before its readings", line=line)
    laser_type = parse_int(path, line, tokens[1], 2, "laser_type")
    remission_mode = parse_int(path, line, tokens[7], 8, "remission_mode")
    n = parse_int(path, line, tokens[8], 9, "num_readings", minimum=1)
    if len(tokens) < n + 10:
        raise FormatError(path, f"ROBOTLASER1 with num_readings {n} ends after {len(tokens)} fields, before num_remissions",
                          line=line)
    m = parse_int(path, line, tokens[n + 9], n + 10, "num_remissions")
    if len(tokens) != n + m + 24:
        raise FormatError(path, f"ROBOTLASER1 with num_readings {n} and num_remissions {m} needs {n + m + 24} fields, "
                          f"got {len(tokens)}", line=line)
    values = parse_floats(path, line, tokens[2:7], 3, "laser configuration")
    values += parse_floats(path, line, tokens[9 : n + 9], 10, "range")
    parse_floats(path, line, tokens[n + 10 : n + m + 10], n + 11, "remission")
    values += parse_floats(path, line, tokens[n + m + 10 : n + m + 22], n + m + 11, "pose, velocity, distance or ipc_timestamp")
    values += parse_floats(path, line, tokens[-1:], n + m + 24, "logger_timestamp")
    return np.array(values), n, (laser_type, remission_mode)


def _param(path: Path, line: int, tokens: list[str]) -> tuple[str, str]:
    """``PARAM name value [ipc_timestamp ipc_hostname logger_timestamp]``; a value may hold spaces."""
    if len(tokens) < 3:
        raise FormatError(path, "expected 'PARAM name value [ipc_timestamp ipc_hostname logger_timestamp]'", line=line)
    stamped = len(tokens) >= 6
    if stamped:
        try:
            float(tokens[-3]), float(tokens[-1])
        except ValueError:
            stamped = False
    return tokens[1], " ".join(tokens[2:-3] if stamped else tokens[2:])


def _check_rows(path: Path, rows: NDArray[np.float64], numbers: list[int], names: list[str], what: str) -> None:
    """Every value finite; report the first bad one by line and field name."""
    bad = first_bad_row(~np.isfinite(rows))
    if bad is not None:
        row, col = bad
        raise FormatError(path, f"{what} {names[col]} is not finite: {rows[row, col]}", line=numbers[row])


def _check_times(path: Path, t: NDArray[np.float64], numbers: list[int], what: str, strict: bool) -> None:
    steps = np.diff(t)
    back = np.flatnonzero(steps <= 0 if strict else steps < 0)
    if back.size:
        i = int(back[0])
        order = "strictly increasing" if strict else "non-decreasing"
        raise FormatError(path, f"{what} ipc_timestamps must be {order}: {t[i + 1]!r} after {t[i]!r} (line {numbers[i]})",
                          line=numbers[i + 1])


def _param_number(path: Path, params: dict[str, str], where: dict[str, int], name: str, positive: bool = True) -> float | None:
    """The numeric PARAM ``name`` (None if absent); FormatError at its line if it is not a (positive) number."""
    if name not in params:
        return None
    try:
        value = float(params[name])
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or (positive and value <= 0):
        kind = "a positive number" if positive else "a finite number"
        raise FormatError(path, f"PARAM {name} must be {kind}, got {params[name][:40]!r}", line=where[name])
    return value


def _flaser_geometry(path: Path, params: dict[str, str], where: dict[str, int], beams: int,
                     ranges: NDArray[np.float32]) -> tuple[float, float, float]:
    """angle_min, angle_increment, range_max of an old-format laser, from PARAMs or CARMEN's defaults."""
    resolution = _param_number(path, params, where, PARAM_RESOLUTION)
    fov = _param_number(path, params, where, PARAM_FOV)
    if resolution is not None:
        increment = math.radians(resolution)
    else:
        spread = math.radians(fov) if fov is not None else math.pi
        increment = spread / (beams - 1) if beams > 1 else 0.0
    range_max = _param_number(path, params, where, PARAM_RANGE_MAX)
    if range_max is None:
        range_max = float(str(ranges.max()))  # shortest decimal of the float32 maximum: 81.91, not 81.910004
    return -increment * (beams - 1) / 2.0, increment, range_max


def read_carmen(path: str | Path) -> CarmenLog:
    """Read the front laser (FLASER or ROBOTLASER1), ODOM and PARAM lines of a CARMEN log.

    Other line types (``RLASER``, ``ROBOTLASER2``, ``RAWLASER1``, ``TRUEPOS``, ``SYNC``, ...) are
    skipped and counted in :attr:`CarmenLog.skipped`; ``#`` lines and blank lines are ignored.

    Parameters
    ----------
    path:
        The log file (plain text; compressed logs must be decompressed first).

    Returns
    -------
    CarmenLog
        Laser lines stacked in file order (``ranges`` float32 [N, B] in metres), the ODOM lines and the
        PARAMs. ROBOTLASER1 lines give their own geometry; FLASER lines take it from the PARAMs
        ``laser_front_laser_resolution`` (deg), ``laser_front_laser_fov`` (deg) and
        ``robot_front_laser_max`` (m), else 180 degrees spread over the beams, centred on the heading
        (``angle_min = -pi/2``), and the largest range in the log as ``range_max``.

    Raises
    ------
    FormatError
        Naming the file and line: a wrong field count (``num_readings`` disagreeing with the fields), a
        field that is not a (finite) number, a negative range, laser timestamps not strictly increasing
        or ODOM timestamps decreasing, FLASER and ROBOTLASER1 lines in one log, lines with different beam
        counts or (ROBOTLASER1) different laser geometry, or no laser line at all.
    """
    path = Path(path)
    lines = read_lines(path)
    rows: list[NDArray[np.float64]] = []
    numbers: list[int] = []
    hosts: list[str] = []
    integers: list[tuple[int, int]] = []
    odom_rows: list[list[float]] = []
    odom_numbers: list[int] = []
    odom_hosts: list[str] = []
    params: dict[str, str] = {}
    param_lines: dict[str, int] = {}
    skipped: Counter[str] = Counter()
    kind: str | None = None
    beams = 0
    for number, tokens in data_lines(lines):
        name = tokens[0]
        if name in LASER_KINDS:
            if kind is None:
                kind = name
            elif name != kind:
                raise FormatError(path, f"{name} line in a log of {kind} lines (line {numbers[0]}); slamtrials reads one front laser",
                                  line=number)
            if name == "FLASER":
                row, n = _flaser(path, number, tokens)
            else:
                row, n, ints = _robotlaser(path, number, tokens)
                integers.append(ints)
            if rows and n != beams:
                raise FormatError(path, f"{name} has {n} readings, earlier lines have {beams}", line=number)
            beams = n
            rows.append(row)
            numbers.append(number)
            hosts.append(tokens[-2])
        elif name == "ODOM":
            if len(tokens) != 10:
                raise FormatError(path, "expected 10 fields 'ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp', "
                                  f"got {len(tokens)}", line=number)
            odom_rows.append(parse_floats(path, number, tokens[1:8], 2, _ODOM[:7])
                             + parse_floats(path, number, tokens[9:], 10, "logger_timestamp"))
            odom_numbers.append(number)
            odom_hosts.append(tokens[8])
        elif name == "PARAM":
            key, value = _param(path, number, tokens)
            params[key] = value
            param_lines[key] = number
        else:
            skipped[name] += 1
    for key in (*PARAM_MOUNT, PARAM_RANGE_MIN):
        _param_number(path, params, param_lines, key, positive=False)
    if kind is None:
        raise FormatError(path, "no FLASER or ROBOTLASER1 line: not a CARMEN log with a front laser", line=last_line(lines))
    laser = _laser(path, kind, np.stack(rows), numbers, hosts, integers, beams, params, param_lines)
    return CarmenLog(laser=laser, odom=_odometry(path, odom_rows, odom_numbers, odom_hosts), params=params, skipped=dict(skipped))


def _one_or_all(hosts: list[str]) -> str | list[str]:
    return hosts[0] if hosts and hosts.count(hosts[0]) == len(hosts) else hosts


def _laser(path: Path, kind: str, rows: NDArray[np.float64], numbers: list[int], hosts: list[str],
           integers: list[tuple[int, int]], beams: int, params: dict[str, str], param_lines: dict[str, int]) -> CarmenLaser:
    ranges_names = [f"range {i + 1}" for i in range(beams)]
    if kind == "FLASER":
        names = ranges_names + list(_POSES) + ["ipc_timestamp", "logger_timestamp"]
        first = 0
    else:
        names = list(_CONFIG) + ranges_names + list(_ROBOT_POSES) + list(_EXTRA) + ["ipc_timestamp", "logger_timestamp"]
        first = len(_CONFIG)
    _check_rows(path, rows, numbers, names, kind)
    ranges = rows[:, first : first + beams]
    negative = first_bad_row(ranges < 0)
    if negative is not None:
        row, col = negative
        raise FormatError(path, f"{kind} range {col + 1} is negative: {ranges[row, col]}", line=numbers[row])
    huge = first_bad_row(ranges > np.finfo(np.float32).max)
    if huge is not None:
        row, col = huge
        raise FormatError(path, f"{kind} range {col + 1} is too large for float32: {ranges[row, col]}", line=numbers[row])
    ranges = ranges.astype(np.float32)
    poses = rows[:, first + beams : first + beams + 6]
    t, logger_t = rows[:, -2].copy(), rows[:, -1].copy()
    _check_times(path, t, numbers, kind, strict=True)
    common = dict(kind=kind, t=t, logger_t=logger_t, hostname=_one_or_all(hosts), ranges=ranges,
                  pose=poses[:, :3].copy(), odometry=poses[:, 3:].copy())
    if kind == "FLASER":
        angle_min, increment, range_max = _flaser_geometry(path, params, param_lines, beams, ranges)
        return CarmenLaser(**common, angle_min=angle_min, angle_increment=increment, range_max=range_max)
    config = rows[:, :4]
    differ = np.flatnonzero((config != config[0]).any(axis=1))
    if differ.size:
        i = int(differ[0])
        raise FormatError(path, "ROBOTLASER1 start_angle, field_of_view, angular_resolution or maximum_range differ "
                          f"from line {numbers[0]}", line=numbers[i])
    if not config[0, 3] > 0:
        raise FormatError(path, f"ROBOTLASER1 maximum_range must be positive, got {config[0, 3]}", line=numbers[0])
    return CarmenLaser(**common, angle_min=float(config[0, 0]), angle_increment=float(config[0, 2]),
                       range_max=float(config[0, 3]),
                       laser_type=integers[0][0], accuracy=float(rows[0, 4]), remission_mode=integers[0][1],
                       extra=rows[:, first + beams + 6 : first + beams + 11].copy())


def _odometry(path: Path, rows: list[list[float]], numbers: list[int], hosts: list[str]) -> CarmenOdometry:
    if not rows:
        return CarmenOdometry.empty()
    values = np.array(rows, dtype=np.float64)
    _check_rows(path, values, numbers, list(_ODOM), "ODOM")
    _check_times(path, values[:, 6], numbers, "ODOM", strict=False)
    return CarmenOdometry(t=values[:, 6].copy(), logger_t=values[:, 7].copy(), hostname=_one_or_all(hosts),
                          pose=values[:, :3].copy(),
                          tv=values[:, 3].copy(), rv=values[:, 4].copy(), accel=values[:, 5].copy())
