"""Moving a run between the run folder and other formats: the library behind ``export`` and ``import``.

Export writes a :class:`~slamtrials.record.RunRecord` as a ROS 1 bag, a ROS 2 bag (MCAP), a CARMEN log
(first pose triple = the laser's pose by odometry, second = the odometry of the base; the ground truth,
only when asked for, in TRUEPOS lines) or a TUM trajectory. Import reads a ROS bag or a CARMEN log (plain,
gzip or bzip2) back into a record. Functions return a one-line description of what they
did for the caller to show; they never print.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from slamtrials.errors import ConfigError, FormatError
from slamtrials.record import RunRecord, Trajectory

__all__ = [
    "EXPORT_FORMATS",
    "export_record",
    "sensor_only",
    "SENSOR_METADATA",
    "detect_recording_format",
    "read_carmen_run",
    "CARMEN_SUFFIXES",
    "BAG_SUFFIXES",
]

EXPORT_FORMATS = ("bag", "bag2", "carmen", "tum")
CARMEN_SUFFIXES = (".clf", ".log", ".carmen")
BAG_SUFFIXES = (".bag", ".mcap", ".db3")


def _remove(out: Path) -> None:
    """Remove an existing output that a writer cannot replace by itself (a file where a folder goes)."""
    if out.is_dir() and not out.is_symlink():
        shutil.rmtree(out)
    elif out.exists():
        out.unlink()


def export_record(
    record: RunRecord,
    out: str | Path,
    to: str,
    *,
    tum_source: str = "truth",
    time_origin_ns: int | None = None,
    compress: bool = False,
    carmen_kind: str = "ROBOTLASER1",
    truth: bool = False,
    overwrite: bool = False,
) -> str:
    """Write ``record`` to ``out`` in format ``to`` (one of :data:`EXPORT_FORMATS`); return a description.

    Parameters
    ----------
    tum_source:
        For ``tum``: ``"truth"`` (world frame) or ``"odometry"`` (odometry frame). Frames without that
        pose (NaN, e.g. an imported recording without ground truth) are skipped.
    time_origin_ns, compress:
        For bags: the ROS stamp of t = 0 (default 1 s) and LZ4 (ROS 1) or zstd (ROS 2) chunks.
    carmen_kind:
        For ``carmen``: ``"ROBOTLASER1"`` or ``"FLASER"``.
    truth:
        False (the default): a recording holding no ground truth at all, what a SLAM program may be
        given: a CARMEN log without TRUEPOS lines; a bag without ``/base_pose_ground_truth`` and with
        ``/slamtrials/run`` stripped to the recording's format, versions, frame and beam counts and laser
        (:func:`sensor_only`: a run's metadata holds its true start pose, its drawn odometry bias and
        its scores). True: the ground truth too (TRUEPOS lines; the topic and the whole metadata), so
        that import gives the run back; a run without ground truth at any frame is written without it.

    Raises
    ------
    ConfigError
        An unknown format or option, an existing ``out`` without ``overwrite``, or a record the format
        cannot hold (TRUEPOS lines for a run with ground truth at some frames only).
    """
    out = Path(out)
    if to not in EXPORT_FORMATS:
        raise ConfigError(f"unknown export format {to!r}; expected one of {', '.join(EXPORT_FORMATS)}")
    if out.exists() and not overwrite:
        raise ConfigError(f"{out}: already exists; choose another --out or pass --overwrite")
    if to in ("bag", "bag2"):
        from slamtrials.io.rosbag import DEFAULT_TIME_ORIGIN_NS, write_bag

        ros = 1 if to == "bag" else 2
        if out.exists() and (out.is_dir() != (ros == 2)):
            _remove(out)
        origin = DEFAULT_TIME_ORIGIN_NS if time_origin_ns is None else time_origin_ns
        if not truth:
            record = sensor_only(record)
        write_bag(out, record, ros=ros, time_origin_ns=origin, overwrite=overwrite, compress=compress)
        held = "with" if np.isfinite(record.truth).all(axis=1).any() else "without"
        return f"{out}: ROS {ros} bag, {len(record)} scans on /base_scan, /odom, /tf, {held} /base_pose_ground_truth"
    if to == "carmen":
        return _export_carmen(record, out, carmen_kind, truth)
    return _export_tum(record, out, tum_source)


#: The metadata a recording keeps when it is handed over without ground truth: nothing of the world,
#: the start pose, the drawn errors, the trial or its scores.
SENSOR_METADATA = ("format", "versions", "frames", "beams", "laser")


def sensor_only(record: RunRecord) -> RunRecord:
    """``record`` as a robot would have recorded it: the same times, scans, odometry, stalls and laser,
    the ground truth NaN, no estimate, map or online path, and only :data:`SENSOR_METADATA` kept (with
    ``truth_available`` False)."""
    metadata = {key: record.metadata[key] for key in SENSOR_METADATA if key in record.metadata}
    metadata["truth_available"] = False
    return RunRecord(
        t=record.t,
        scans=record.scans,
        odometry=record.odometry,
        truth=np.full_like(np.asarray(record.truth, dtype=np.float64), np.nan),
        stalled=record.stalled,
        laser=record.laser,
        metadata=metadata,
    )


def _export_carmen(record: RunRecord, out: Path, kind: str, truth: bool) -> str:
    from slamtrials.io.carmen import carmen_from_run, write_carmen

    if kind not in ("ROBOTLASER1", "FLASER"):
        raise ConfigError(f"CARMEN line kind must be ROBOTLASER1 or FLASER, got {kind!r}")
    known = np.isfinite(record.truth).all(axis=1)
    if truth and known.any() and not known.all():
        raise ConfigError(
            f"the run has ground truth for {np.count_nonzero(known)} of {len(record)} frames; TRUEPOS lines need it "
            "for every laser line: pass --no-truth to write the log without ground truth"
        )
    with_truth = truth and bool(known.all())
    try:
        write_carmen(out, carmen_from_run(record, kind=kind, truth=with_truth))
    except ValueError as exc:
        raise ConfigError(f"the run cannot be written as a CARMEN log: {exc}") from None
    held = "TRUEPOS lines with the ground truth" if with_truth else "no ground truth"
    return (
        f"{out}: CARMEN log, {len(record)} {kind} and ODOM lines (first pose = laser pose by odometry, "
        f"second = odometry), {held}"
    )


def _export_tum(record: RunRecord, out: Path, source: str) -> str:
    from slamtrials.io.tum import write_tum

    if source not in ("truth", "odometry"):
        raise ConfigError(f"TUM export takes the truth or the odometry, got {source!r}")
    poses = record.truth if source == "truth" else record.odometry
    known = np.isfinite(poses).all(axis=1)
    if not known.any():
        raise ConfigError(
            f"the run has no {source} (a recording without ground truth?); export the odometry instead (--what odometry)"
        )
    write_tum(out, Trajectory(t=np.asarray(record.t)[known], poses=np.asarray(poses)[known]))
    skipped = f" ({np.count_nonzero(~known)} frames without it skipped)" if not known.all() else ""
    frame = "world frame" if source == "truth" else "odometry frame"
    return f"{out}: TUM trajectory of the {source} ({frame}), {np.count_nonzero(known)} poses{skipped}"


def detect_recording_format(path: str | Path) -> str:
    """``"bag"`` or ``"carmen"``, from the name (suffix, folder) and, failing that, the first bytes."""
    path = Path(path)
    suffixes = [s.lower() for s in path.suffixes]
    if path.is_dir() or (suffixes and suffixes[-1] in BAG_SUFFIXES):
        return "bag"
    if suffixes and (suffixes[-1] in CARMEN_SUFFIXES or suffixes[-1] in (".gz", ".bz2")):
        return "carmen"
    if not path.exists():
        raise FormatError(path, "no such file or folder")
    with open(path, "rb") as handle:
        head = handle.read(16)
    return "bag" if head.startswith((b"#ROSBAG", b"\x89MCAP")) else "carmen"


def read_carmen_run(path: str | Path, *, truth: bool = True) -> RunRecord:
    """A CARMEN log (plain, gzip- or bzip2-compressed) as a run record.

    ``truth`` (:func:`~slamtrials.io.carmen.run_from_carmen`): the log's TRUEPOS lines, else its first pose
    triple, as ``metadata["truth_source"]`` says; with ``truth=False`` none (NaN).

    Raises
    ------
    FormatError
        The log does not parse, its laser lines hold no readings (a pose-only trajectory, which
        ``slamtrials evaluate`` reads but which has nothing to map or replay), or (with ``truth``) its
        TRUEPOS lines do not cover its laser lines.
    """
    from slamtrials.io.carmen import read_carmen, run_from_carmen

    log = read_carmen(path)
    if log.laser.beams == 0:
        raise FormatError(
            path,
            f"its {log.laser.kind} lines hold no readings (a pose-only trajectory): nothing to map or "
            "replay; evaluate it with slamtrials evaluate --estimate",
        )
    try:
        return run_from_carmen(log, truth=truth)
    except ValueError as exc:  # a geometry LaserGeometry refuses (one beam, a clockwise scan, no positive range)
        raise FormatError(path, f"its {log.laser.kind} laser geometry cannot be used: {exc}") from None
