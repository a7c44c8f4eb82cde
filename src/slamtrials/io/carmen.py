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
``TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname logger_timestamp``
    the ground truth of the robot base (world frame) and its odometry, as CARMEN's logger writes the
    simulator's ``truepos`` message (field order of ``carmen_logwrite_write_truepos`` in CARMEN's
    ``writelog.c``).
``PARAM name value [ipc_timestamp ipc_hostname logger_timestamp]``
    a configuration parameter.

A log holding both front-laser line types (CARMEN's logger can write the old FLASER line and the
ROBOTLASER1 line of the same scans) is read as its ROBOTLASER1 lines; the FLASER lines are skipped and
counted, with one warning (:mod:`slamtrials.io.carmen_read`). Other line types (``RLASER``,
``ROBOTLASER2``, ``RAWLASER1..4``, ``SYNC``, ...) are skipped and counted. Ranges are written to the
millimetre (CARMEN's ``%.3f``), other numbers to 6 decimals.
Logs may be gzip- or bzip2-compressed. What the reader tolerates in logs of the wild (pose-only
``FLASER 0`` lines, ``nan`` poses, timestamps going backwards, beam counts that change, a truncated last
line, PARAM trailers) is listed in :mod:`slamtrials.io.carmen_read` and docs/real-datasets.md.

Which pose is which. Each laser line has two pose triples, and neither is ground truth. The first is
the pose of the laser as the robot knows it: in logs of real robots its odometry pose, often corrected
afterwards by a SLAM program (in ``mit-csail.clf`` the two triples are equal); the second is the raw
odometry of the robot base. A run that slamtrials exports (:func:`carmen_from_run`) is written the same
way: the first triple is the odometry of the base composed with the laser mount (``odometry (+) mount``,
odometry frame), the second the odometry of the base, so the two ROBOTLASER1 triples give the mount as
CARMEN intends (also in the PARAMs ``robot_frontlaser_offset``, ``robot_frontlaser_side_offset`` (m) and
``robot_frontlaser_angular_offset`` (rad)). The ground truth of the base (world frame) goes only into
``TRUEPOS`` lines, one per frame at the laser line's timestamp, and only when asked for
(``carmen_from_run(..., truth=True)``; ``slamtrials export --to carmen`` does so unless ``--no-truth``):
a log written without them holds no ground truth at all, which is what a SLAM program may be given.
Reading (:func:`run_from_carmen`), a log's TRUEPOS lines give the run its truth; a log without them
gets its first triple as ``truth``, and ``metadata["truth_source"]`` says which.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials.geometry import compose, ominus
from slamtrials.io.carmen_log import (
    LASER_KINDS,
    ROBOTLASER_EXTRA,
    CarmenLaser,
    CarmenLog,
    CarmenOdometry,
    CarmenTruePos,
)
from slamtrials.io.carmen_read import PARAM_MOUNT, PARAM_RANGE_MIN, read_carmen, truth_at_laser
from slamtrials.io.carmen_write import write_carmen
from slamtrials.io.textfile import float_text
from slamtrials.record import LaserGeometry, RunRecord, Trajectory

__all__ = [
    "CarmenLaser",
    "CarmenLog",
    "CarmenOdometry",
    "CarmenTruePos",
    "read_carmen",
    "write_carmen",
    "carmen_from_run",
    "carmen_from_trajectory",
    "run_from_carmen",
    "TRUTH_SOURCE",
    "TRUTH_SOURCE_TRUEPOS",
    "TRUTH_SOURCE_NONE",
]

#: ``metadata["truth_source"]`` of a run imported from a CARMEN log without TRUEPOS lines.
TRUTH_SOURCE = "carmen first pose triple (may be a SLAM-corrected pose, not ground truth)"
#: ``metadata["truth_source"]`` of a run whose truth comes from the log's TRUEPOS lines.
TRUTH_SOURCE_TRUEPOS = "carmen TRUEPOS lines"
#: ``metadata["truth_source"]`` of a run read without ground truth (``truth`` NaN).
TRUTH_SOURCE_NONE = "none (read without ground truth)"


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


def _first_triple(record: RunRecord, pose: ArrayLike | None) -> NDArray[np.float64]:
    """``[N, 3]`` the first pose triple: ``pose`` if given, else the laser's pose by odometry,
    ``odometry (+) mount`` (odometry frame; the mount is the laser's pose in the base frame)."""
    if pose is not None:
        first = np.array(pose, dtype=np.float64)
        if first.shape != (len(record), 3):
            raise ValueError(f"first_triple has shape {first.shape}, expected ({len(record)}, 3)")
        return first
    return compose(np.asarray(record.odometry, dtype=np.float64), np.asarray(record.laser.mount, dtype=np.float64))


def _truepos(record: RunRecord, t: NDArray[np.float64], logger_t: NDArray[np.float64], hostname: str) -> CarmenTruePos:
    """One TRUEPOS line per frame: the ground truth of the base and its odometry."""
    truth = np.asarray(record.truth, dtype=np.float64)
    if not np.isfinite(truth).all():
        known = int(np.count_nonzero(np.isfinite(truth).all(axis=1)))
        raise ValueError(
            f"the run has ground truth for {known} of {len(record)} frames; TRUEPOS lines need it for every "
            "frame (write the log without them: truth=False)"
        )
    return CarmenTruePos(
        t=t.copy(),
        logger_t=logger_t.copy(),
        hostname=hostname,
        pose=truth.copy(),
        odometry=np.array(record.odometry, dtype=np.float64),
    )


def _comments(given: bool, truth: bool) -> tuple[str, ...]:
    """What the triples (and TRUEPOS lines) of a log written by :func:`carmen_from_run` hold."""
    first = (
        "a pose the writer gave (slamtrials slam: its estimate of the robot base)"
        if given
        else "the laser's pose by odometry (odometry of the robot base (+) laser mount)"
    )
    where = (
        "the ground truth of the base is in the TRUEPOS lines, one per laser line"
        if truth
        else "this log holds no ground truth"
    )
    return (f"written by slamtrials: first pose triple = {first}, second = odometry of the robot base; {where}",)


def carmen_from_run(
    record: RunRecord,
    *,
    kind: str = "ROBOTLASER1",
    hostname: str = "slamtrials",
    truth: bool = False,
    first_triple: ArrayLike | None = None,
) -> CarmenLog:
    """A run as a CARMEN log: one laser line and one ODOM line per frame, and TRUEPOS lines if asked.

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
    truth:
        Also write the ground truth, one TRUEPOS line per frame at its laser line's timestamp (the
        run's truth must be known at every frame). Default False: the log holds no ground truth
        anywhere, as a log handed to a SLAM program must not.
    first_triple:
        float64 ``[N, 3]`` poses for the first triple instead of the laser's pose by odometry
        (``slamtrials slam`` writes its estimate there, in ``trajectory.clf``).

    Returns
    -------
    CarmenLog
        Laser ``t`` = ``record.t``, ``logger_t`` = time since the first frame; first pose triple (FLASER
        ``x y theta``, ROBOTLASER1 ``laser_pose``) = the laser's pose by odometry, ``odometry (+)
        laser.mount`` (odometry frame), unless ``first_triple`` is given; second = the odometry of the
        base. ODOM lines repeat the odometry with the velocities of the step that ended at each frame.
        With ``truth``, TRUEPOS lines hold the ground truth of the base (world frame) and its odometry.
        PARAMs give the laser mounting and minimum range; a comment line says what the triples hold.
        A no-return (``+inf``, REP 117) is written as the laser's maximum range, as CARMEN logs and SICK
        scanners give it (CARMEN text has no infinity); readers take a reading at ``range_max`` for a
        no-return.

    Raises
    ------
    ValueError
        An unknown ``kind``, a ``first_triple`` of the wrong shape, or ``truth`` for a run whose ground
        truth is not known at every frame.
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
            pose=_first_triple(record, first_triple),
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
        truepos=_truepos(record, t, logger_t, hostname) if truth else CarmenTruePos.empty(),
        comments=_comments(first_triple is not None, truth),
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
    return CarmenLog(laser=laser, comments=("written by slamtrials: both pose triples = the trajectory's poses",))


def _param_float(params: dict[str, str], name: str) -> float:
    """A numeric PARAM as :func:`read_carmen` checked it (its value's first token), 0 when absent."""
    words = params.get(name, "0").split()
    return float(words[0]) if words else 0.0


def _truth(log: CarmenLog, truth: bool) -> tuple[NDArray[np.float64], dict[str, Any]]:
    """The run's truth ``[N, 3]`` and the metadata that says where it came from."""
    laser = log.laser
    if not truth:
        return np.full((len(laser), 3), np.nan), {"truth_source": TRUTH_SOURCE_NONE, "truth_available": False}
    if len(log.truepos):
        return truth_at_laser(log), {
            "truth_source": TRUTH_SOURCE_TRUEPOS,
            "truth_available": True,
            "carmen_truepos_lines": len(log.truepos),
        }
    return laser.pose.copy(), {"truth_source": TRUTH_SOURCE}


def run_from_carmen(log: CarmenLog, *, truth: bool = True) -> RunRecord:
    """A CARMEN log as a run record, one frame per laser line.

    ``t`` is the laser ``ipc_timestamp`` (as relation files refer to it), ``scans`` the ranges,
    ``odometry`` the second pose triple (as logged: it need not start at the origin) and ``stalled`` all
    False. ``truth``: the ground truth of the log's TRUEPOS lines, at each laser line's timestamp
    (:func:`~slamtrials.io.carmen_read.truth_at_laser`; ``metadata["truth_source"]`` is
    :data:`TRUTH_SOURCE_TRUEPOS`, ``metadata["truth_available"]`` True). A log without TRUEPOS lines (every
    log of a real robot) has no ground truth: ``truth`` is then the first pose triple, only as good as the
    pose it holds, and ``metadata["truth_source"]`` says so (:data:`TRUTH_SOURCE`). With ``truth=False``
    the log's poses are never taken for ground truth: ``truth`` is NaN, ``metadata["truth_available"]``
    False (:data:`TRUTH_SOURCE_NONE`), as for a ROS bag read without a ground-truth topic.
    The laser mounting and minimum range come from the PARAMs :data:`~slamtrials.io.carmen_read.PARAM_MOUNT`
    and ``slamtrials_laser_range_min`` when present, else zero. ``metadata["carmen_tolerated"]`` keeps
    what the reader tolerated (:attr:`CarmenLog.tolerated`).

    Raises
    ------
    FormatError
        With ``truth``: the TRUEPOS lines do not cover the laser lines (naming the file and the first
        laser line without one).
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
    poses, source = _truth(log, truth)
    hosts = sorted(set(laser.hostnames()))
    metadata: dict[str, Any] = {
        "source_format": "carmen",
        "carmen_kind": laser.kind,
        **source,
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
        truth=poses,
        stalled=np.zeros(n, dtype=bool),
        laser=geometry,
        metadata=metadata,
    )
