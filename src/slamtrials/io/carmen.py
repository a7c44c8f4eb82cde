"""CARMEN log files: read and write the front laser, odometry and parameters, and convert runs.

A CARMEN log is text, one message per line, ``NAME [contents] ipc_timestamp ipc_hostname
logger_timestamp``; ``ipc_timestamp`` is when the message was sent (s, usually Unix time), the
logger's timestamp the seconds since logging started. slamtrials reads and writes:

``FLASER num_readings r_1..r_n x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname logger_timestamp``
    the old front-laser line (e.g. the Freiburg benchmark logs). Its geometry is not on the line: it
    comes from the PARAMs ``laser_front_laser_resolution`` and ``laser_front_laser_fov`` (degrees) and
    ``robot_front_laser_max`` (m), by default 180 degrees spread over the beams; the first beam at -90
    degrees, as CARMEN's reader puts it, unless ``laser_front_laser_fov`` centres the field of view.
``ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy remission_mode num_readings r_1..r_n num_remissions e_1..e_m laser_pose(x y theta) robot_pose(x y theta) laser_tv laser_rv forward_safety_dist side_safty_dist turn_axis ipc_timestamp ipc_hostname logger_timestamp``
    the current front-laser line, geometry included (radians, metres). slamtrials drops the
    remissions when reading and writes none.
``ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp``
    odometry, usually at a higher rate than the laser.
``PARAM name value [ipc_timestamp ipc_hostname logger_timestamp]``
    a configuration parameter.

A log holding both front-laser line types (CARMEN's logger can write the old FLASER line and the
ROBOTLASER1 line of the same scans) is read as its ROBOTLASER1 lines; the FLASER lines are skipped and
counted, with one warning (:mod:`slamtrials.io.carmen_read`). Other line types (``RLASER``,
``ROBOTLASER2``, ``RAWLASER1..4``, ``TRUEPOS``, ``SYNC``, ...) are skipped and counted. Ranges are written to the millimetre (CARMEN's ``%.3f``), other numbers to 6 decimals.
Logs may be gzip- or bzip2-compressed. What the reader tolerates in logs of the wild (pose-only
``FLASER 0`` lines, ``nan`` poses, timestamps going backwards, beam counts that change, a truncated last
line, PARAM trailers) is listed in :mod:`slamtrials.io.carmen_read` and docs/real-datasets.md.

Which pose is which. Each laser line has two pose triples. In logs of real robots the first is the pose
of the laser, often corrected afterwards by a SLAM program (in ``mit-csail.clf`` the two are equal),
and the second the robot's raw odometry; neither is ground truth. In logs that slamtrials writes, like
those of simulators such as Stage or the IROS 2018 seed system, the FIRST triple is the ground-truth pose
of the robot base in the world frame and the SECOND the odometry of the base. Programs that derive the
laser's mounting offset from the two ROBOTLASER1 triples would therefore get the odometry error instead;
slamtrials gives the mounting in the PARAMs ``robot_frontlaser_offset``, ``robot_frontlaser_side_offset``
(m) and ``robot_frontlaser_angular_offset`` (rad).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from slamtrials.geometry import ominus
from slamtrials.io.carmen_log import LASER_KINDS, ROBOTLASER_EXTRA, CarmenLaser, CarmenLog, CarmenOdometry
from slamtrials.io.carmen_read import PARAM_MOUNT, PARAM_RANGE_MIN, read_carmen
from slamtrials.io.carmen_write import write_carmen
from slamtrials.io.textfile import float_text
from slamtrials.record import LaserGeometry, RunRecord, Trajectory

__all__ = [
    "CarmenLaser",
    "CarmenLog",
    "CarmenOdometry",
    "read_carmen",
    "write_carmen",
    "carmen_from_run",
    "carmen_from_trajectory",
    "run_from_carmen",
    "TRUTH_SOURCE",
]

#: ``metadata["truth_source"]`` of a run imported from a CARMEN log.
TRUTH_SOURCE = "carmen first pose triple (may be a SLAM-corrected pose, not ground truth)"


def _velocities(
    t: NDArray[np.float64], odometry: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Forward and angular velocity (m/s, rad/s) over the step that ends at each frame (0 at the first)."""
    tv, rv = np.zeros(len(t)), np.zeros(len(t))
    if len(t) > 1:
        step = ominus(odometry[:-1], odometry[1:])
        dt = np.diff(t)
        tv[1:], rv[1:] = step[:, 0] / dt, step[:, 2] / dt
    return tv, rv


def carmen_from_run(record: RunRecord, *, kind: str = "ROBOTLASER1", hostname: str = "slamtrials") -> CarmenLog:
    """A run as a CARMEN log: one laser line and one ODOM line per frame.

    Parameters
    ----------
    record:
        The run; ``t`` strictly increasing (s).
    kind:
        ``"ROBOTLASER1"`` (default: the laser geometry is exact on every line) or ``"FLASER"`` (the old
        format most SLAM programs of the Freiburg benchmark read; the scan must be centred on the
        heading, and its geometry goes into PARAMs in degrees).
    hostname:
        ``ipc_hostname`` of every line.

    Returns
    -------
    CarmenLog
        Laser ``t`` = ``record.t``, ``logger_t`` = time since the first frame, first pose triple = ground
        truth of the base (world frame), second = odometry. ODOM lines repeat the odometry with the
        velocities of the step that ended at each frame. PARAMs give the laser mounting and minimum range.
        A no-return (``+inf``, REP 117) is written as the laser's maximum range, as CARMEN logs and SICK
        scanners give it (CARMEN text has no infinity); readers take a reading at ``range_max`` for a
        no-return.
    """
    if kind not in LASER_KINDS:
        raise ValueError(f"kind must be one of {LASER_KINDS}, got {kind!r}")
    t = np.asarray(record.t, dtype=np.float64)
    logger_t = t - t[0] if len(t) else t.copy()
    odometry = np.asarray(record.odometry, dtype=np.float64)
    tv, rv = _velocities(t, odometry)
    laser = record.laser
    extra = None
    if kind == "ROBOTLASER1":
        extra = np.zeros((len(t), len(ROBOTLASER_EXTRA)))
        extra[:, 0], extra[:, 1] = tv, rv
    params = {name: float_text(value) for name, value in zip(PARAM_MOUNT, laser.mount)}
    params[PARAM_RANGE_MIN] = float_text(laser.range_min)
    return CarmenLog(
        laser=CarmenLaser(
            kind=kind,
            t=t.copy(),
            logger_t=logger_t,
            hostname=hostname,
            ranges=np.minimum(np.asarray(record.scans, dtype=np.float32), np.float32(laser.range_max)),
            pose=np.asarray(record.truth, dtype=np.float64),
            odometry=odometry,
            angle_min=laser.angle_min,
            angle_increment=laser.angle_increment,
            range_max=laser.range_max,
            extra=extra,
        ),
        odom=CarmenOdometry(
            t=t.copy(),
            logger_t=logger_t.copy(),
            hostname=hostname,
            pose=odometry.copy(),
            tv=tv,
            rv=rv,
            accel=np.zeros(len(t)),
        ),
        params=params,
    )


def carmen_from_trajectory(trajectory: Trajectory, *, hostname: str = "slamtrials") -> CarmenLog:
    """A trajectory as the Freiburg evaluator's test logs hold one: ``FLASER 0 x y th x y th ts host ts``.

    Both pose triples are the trajectory's pose (the metricEvaluator reads the second, slamtrials'
    ``evaluate`` either), ``logger_t`` is the time since the first pose, and there are no ODOM lines.

    Parameters
    ----------
    trajectory:
        Poses ``[N, 3]`` (m, m, rad) at strictly increasing times (s).
    hostname:
        ``ipc_hostname`` of every line.
    """
    t = np.asarray(trajectory.t, dtype=np.float64)
    poses = np.asarray(trajectory.poses, dtype=np.float64)
    laser = CarmenLaser(
        kind="FLASER",
        t=t.copy(),
        logger_t=t - t[0] if len(t) else t.copy(),
        hostname=hostname,
        ranges=np.zeros((len(t), 0), dtype=np.float32),
        pose=poses.copy(),
        odometry=poses.copy(),
        angle_min=0.0,
        angle_increment=0.0,
        range_max=0.0,
    )
    return CarmenLog(laser=laser)


def _param_float(params: dict[str, str], name: str) -> float:
    """A numeric PARAM as :func:`read_carmen` checked it (its value's first token), 0 when absent."""
    words = params.get(name, "0").split()
    return float(words[0]) if words else 0.0


def run_from_carmen(log: CarmenLog) -> RunRecord:
    """A CARMEN log as a run record, one frame per laser line.

    ``t`` is the laser ``ipc_timestamp`` (as relation files refer to it), ``scans`` the ranges,
    ``odometry`` the second pose triple (as logged: it need not start at the origin), ``truth`` the first
    pose triple and ``stalled`` all False. A CARMEN log has no ground truth: ``truth`` is only as good as
    the pose its first triple holds, and ``metadata["truth_source"]`` says so (:data:`TRUTH_SOURCE`).
    The laser mounting and minimum range come from the PARAMs :data:`~slamtrials.io.carmen_read.PARAM_MOUNT`
    and ``slamtrials_laser_range_min`` when present, else zero. ``metadata["carmen_tolerated"]`` keeps
    what the reader tolerated (:attr:`CarmenLog.tolerated`).
    """
    laser, params = log.laser, log.params
    mount = [_param_float(params, name) for name in PARAM_MOUNT]
    geometry = LaserGeometry(
        angle_min=float(laser.angle_min),
        angle_increment=float(laser.angle_increment),
        range_min=_param_float(params, PARAM_RANGE_MIN),
        range_max=float(laser.range_max),
        mount=(mount[0], mount[1], mount[2]),
    )
    hosts = sorted(set(laser.hostnames()))
    metadata: dict[str, Any] = {
        "source_format": "carmen",
        "carmen_kind": laser.kind,
        "truth_source": TRUTH_SOURCE,
        "carmen_hostnames": hosts,
        "carmen_odom_lines": len(log.odom),
        "carmen_params": dict(params),
        "carmen_skipped": dict(log.skipped),
        "carmen_tolerated": dict(log.tolerated),
        "field_of_view_deg": math.degrees(laser.angle_increment * max(laser.beams - 1, 0)),
    }
    n = len(laser)
    return RunRecord(
        t=laser.t.copy(),
        scans=laser.ranges.astype(np.float32, copy=True),
        odometry=laser.odometry.copy(),
        truth=laser.pose.copy(),
        stalled=np.zeros(n, dtype=bool),
        laser=geometry,
        metadata=metadata,
    )
