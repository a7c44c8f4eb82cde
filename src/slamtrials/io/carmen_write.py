"""Writing CARMEN logs: :func:`write_carmen` (the format is described in :mod:`slamtrials.io.carmen`)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

import numpy as np
from numpy.typing import NDArray

from slamtrials.atomicfile import atomic_write
from slamtrials.io.carmen_log import ROBOTLASER_EXTRA, CarmenLaser, CarmenLog, CarmenOdometry, CarmenTruePos
from slamtrials.io.carmen_read import PARAM_FOV, PARAM_RANGE_MAX, PARAM_RESOLUTION
from slamtrials.io.textfile import float_text

__all__ = ["write_carmen", "RANGE_FORMAT", "NUMBER_FORMAT"]

#: printf formats of ranges and of every other number, as CARMEN's own log writer prints them: ranges
#: to the millimetre, poses, velocities and timestamps to 6 decimals. Laser geometry and PARAM values
#: are written exactly (shortest round-trip text).
RANGE_FORMAT = "%.3f"
NUMBER_FORMAT = "%.6f"

#: CARMEN's comment block describing the line formats (as its logger writes it, for the line types
#: slamtrials writes); the TRUEPOS line is listed only in a log that holds TRUEPOS lines.
_HEADER = (
    "# CARMEN Logfile",
    "# file format is one message per line",
    "# message_name [message contents] ipc_timestamp ipc_hostname logger_timestamp",
    "# message formats defined: PARAM ODOM{truepos} ROBOTLASER1 FLASER",
    "# PARAM param_name param_value",
    "# ODOM x y theta tv rv accel",
    "# TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta",
    "# ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy remission_mode "
    "num_readings [range_readings] num_remissions [remission values] laser_pose_x laser_pose_y laser_pose_theta "
    "robot_pose_x robot_pose_y robot_pose_theta laser_tv laser_rv forward_safety_dist side_safty_dist turn_axis",
    "# (old) FLASER num_readings [range_readings] x y theta odom_x odom_y odom_theta",
)

_CHUNK = 2000  # lines per write


def _finite(name: str, array: NDArray) -> None:
    if not np.isfinite(array).all():
        raise ValueError(f"write_carmen: {name} holds non-finite values")


def _token(name: str, value: str) -> None:
    if not value or value.split() != [value]:
        raise ValueError(f"write_carmen: {name} must be one non-empty token without whitespace, got {value!r}")


def _stamps(name: str, t: NDArray[np.float64], strict: bool) -> tuple[list[str], NDArray[np.float64]]:
    """Timestamps as printed and as they read back; checks the order survives the rounding."""
    text = [NUMBER_FORMAT % v for v in t.tolist()]
    back = np.array([float(s) for s in text], dtype=np.float64)
    steps = np.diff(back)
    if np.any(steps <= 0 if strict else steps < 0):
        order = "strictly increasing" if strict else "non-decreasing"
        raise ValueError(f"write_carmen: {name} ipc timestamps are not {order} at {NUMBER_FORMAT} (1 us) precision")
    return text, back


def _geometry_params(laser: CarmenLaser) -> dict[str, str]:
    """The PARAMs that give a FLASER laser its geometry; the scan must be centred on the heading."""
    beams, increment = laser.beams, float(laser.angle_increment)
    if beams == 0:  # a pose-only trajectory: no laser to describe
        return {}
    params = {PARAM_RANGE_MAX: float_text(laser.range_max)}
    if beams > 1:
        if not increment > 0 or not math.isclose(
            laser.angle_min, -increment * (beams - 1) / 2, rel_tol=1e-12, abs_tol=1e-12
        ):
            raise ValueError(
                "write_carmen: FLASER lines need a counter-clockwise scan centred on the heading "
                f"(angle_min = -angle_increment * (B - 1) / 2); got angle_min {laser.angle_min}, "
                f"angle_increment {increment}: write ROBOTLASER1 instead"
            )
        params[PARAM_RESOLUTION] = float_text(math.degrees(increment))
        params[PARAM_FOV] = float_text(math.degrees(increment * (beams - 1)))
    return params


def _header(log: CarmenLog) -> str:
    """The format block, then the log's comments, one ``#`` line each."""
    truepos = len(log.truepos) > 0
    lines = [
        line.format(truepos=" TRUEPOS" if truepos else "")
        for line in _HEADER
        if truepos or not line.startswith("# TRUEPOS")
    ]
    lines += [f"# {comment}" if comment else "#" for comment in log.comments]
    return "\n".join(lines) + "\n"


def _check(log: CarmenLog) -> None:
    laser, odom, truepos = log.laser, log.odom, log.truepos
    if len(laser) == 0:
        raise ValueError("write_carmen: the log has no laser lines")
    for name in ("t", "logger_t", "ranges", "pose", "odometry"):
        _finite(f"laser.{name}", getattr(laser, name))
    if laser.extra is not None:
        _finite("laser.extra", laser.extra)
    for name in ("angle_min", "angle_increment", "range_max", "accuracy"):
        _finite(f"laser.{name}", np.asarray(getattr(laser, name), dtype=np.float64))
    if laser.beams and not laser.range_max > 0:
        raise ValueError(f"write_carmen: laser.range_max must be positive, got {laser.range_max}")
    if (laser.ranges < 0).any():
        raise ValueError("write_carmen: laser.ranges holds negative ranges")
    for name in ("t", "logger_t", "pose", "tv", "rv", "accel"):
        _finite(f"odom.{name}", getattr(odom, name))
    for name in ("t", "logger_t", "pose", "odometry"):
        _finite(f"truepos.{name}", getattr(truepos, name))
    hosts = set(laser.hostnames()) | set(odom.hostnames()) | set(truepos.hostnames())
    for host in sorted(hosts):  # sorted: the same host named first on every run
        _token("hostname", host)
    for comment in log.comments:
        if "\n" in comment or "\r" in comment:
            raise ValueError(f"write_carmen: a comment must be one line, got {comment!r}")
    for key, value in log.params.items():
        _token("PARAM name", key)
        if not value or " ".join(value.split()) != value:
            raise ValueError(
                f"write_carmen: PARAM {key} value must be non-empty words separated by single spaces, got {value!r}"
            )


def _laser_lines(laser: CarmenLaser, stamps: list[str]) -> Iterator[str]:
    beams = laser.beams
    ranges = RANGE_FORMAT + " "
    number = NUMBER_FORMAT + " "
    if laser.kind == "FLASER":
        fmt = f"FLASER {beams} " + ranges * beams + number * 6 + "%s %s " + NUMBER_FORMAT + "\n"
        tails: NDArray[np.float64] = np.hstack([laser.pose, laser.odometry])
    else:
        config = (
            laser.angle_min,
            laser.angle_increment * (beams - 1),
            laser.angle_increment,
            laser.range_max,
            laser.accuracy,
        )
        numbers = " ".join(float_text(v) for v in config)
        head = f"ROBOTLASER1 {int(laser.laser_type)} {numbers} {int(laser.remission_mode)} {beams} "
        fmt = head + ranges * beams + "0 " + number * (6 + len(ROBOTLASER_EXTRA)) + "%s %s " + NUMBER_FORMAT + "\n"
        extra = laser.extra if laser.extra is not None else np.zeros((len(laser), len(ROBOTLASER_EXTRA)))
        tails = np.hstack([laser.pose, laser.odometry, extra])
    hosts, logger_t = laser.hostnames(), laser.logger_t.tolist()
    for i, (row, tail) in enumerate(zip(laser.ranges.tolist(), tails.tolist())):
        yield fmt % (*row, *tail, stamps[i], hosts[i], logger_t[i])


def _odom_lines(odom: CarmenOdometry, stamps: list[str]) -> Iterator[str]:
    fmt = "ODOM " + (NUMBER_FORMAT + " ") * 6 + "%s %s " + NUMBER_FORMAT + "\n"
    values = np.column_stack([odom.pose, odom.tv, odom.rv, odom.accel]).tolist()
    for row, stamp, host, logger in zip(values, stamps, odom.hostnames(), odom.logger_t.tolist()):
        yield fmt % (*row, stamp, host, logger)


def _truepos_lines(truepos: CarmenTruePos, stamps: list[str]) -> Iterator[str]:
    """``TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname logger_timestamp``
    lines: the ground truth of the base (world frame), its odometry, the stamps."""
    # The field order of CARMEN's logger: carmen_logwrite_write_truepos() in CARMEN's
    # src/lib/carmen/writelog/writelog.c (e.g. the github.com/kralf/carmen copy) prints
    # "TRUEPOS %f %f %f %f %f %f %f %s %f\n" with the simulator's truepose.x/y/theta, odometrypose.x/y/theta,
    # the message's timestamp and host, then the logger's timestamp; its header documents the line as
    # "# TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta".
    fmt = "TRUEPOS " + (NUMBER_FORMAT + " ") * 6 + "%s %s " + NUMBER_FORMAT + "\n"
    values = np.hstack([truepos.pose, truepos.odometry]).tolist()
    for row, stamp, host, logger in zip(values, stamps, truepos.hostnames(), truepos.logger_t.tolist()):
        yield fmt % (*row, stamp, host, logger)


def write_carmen(path: str | Path, log: CarmenLog, *, header: bool = True) -> Path:
    """Write a CARMEN log (atomically) and return its path.

    The format header and the log's comments come first (with ``header``), then PARAM lines (stamped with
    the first laser line's times and host), then ODOM, TRUEPOS and laser lines merged by ``ipc_timestamp``
    (in that order at equal times). Ranges are printed to the millimetre,
    other numbers to 6 decimals, so what reads back equals the log rounded to that precision. A FLASER
    log also gets the PARAMs ``laser_front_laser_resolution``, ``laser_front_laser_fov`` (deg) and
    ``robot_front_laser_max`` (m) from its laser geometry, which override entries of ``log.params``.
    Remissions and skipped line types are not written.

    Parameters
    ----------
    path:
        The file to write.
    log:
        The log; laser ``t`` must stay strictly increasing and ODOM and TRUEPOS ``t`` non-decreasing
        when rounded to microseconds.
    header:
        Start with CARMEN's ``#`` comment block describing the line formats, and ``log.comments``.

    Raises
    ------
    ValueError
        Non-finite numbers, negative ranges, hostnames or PARAMs containing whitespace, a comment of more
        than one line, timestamps out of order, or a FLASER scan that is not centred on the heading: the
        file would not read back as written.
    """
    _check(log)
    laser, odom, truepos = log.laser, log.odom, log.truepos
    params = dict(log.params)
    if laser.kind == "FLASER":
        params.update(_geometry_params(laser))
    laser_stamps, laser_t = _stamps("laser", laser.t, strict=True)
    odom_stamps, odom_t = _stamps("odom", odom.t, strict=False)
    truepos_stamps, truepos_t = _stamps("truepos", truepos.t, strict=False)
    host0, logger0 = laser.hostnames()[0], NUMBER_FORMAT % laser.logger_t[0]
    param_lines = [f"PARAM {key} {value} {laser_stamps[0]} {host0} {logger0}\n" for key, value in params.items()]
    streams = [
        _odom_lines(odom, odom_stamps),
        _truepos_lines(truepos, truepos_stamps),
        _laser_lines(laser, laser_stamps),
    ]
    source = np.repeat(np.arange(3), [len(odom), len(truepos), len(laser)])
    order = np.argsort(np.concatenate([odom_t, truepos_t, laser_t]), kind="stable")  # ODOM, TRUEPOS, laser on ties
    sources = source[order].tolist()

    def write(handle: BinaryIO) -> None:
        chunk = ([_header(log)] if header else []) + param_lines
        for which in sources:
            chunk.append(next(streams[which]))
            if len(chunk) >= _CHUNK:
                handle.write("".join(chunk).encode("utf-8"))
                chunk.clear()
        handle.write("".join(chunk).encode("utf-8"))

    return atomic_write(path, write)
