"""Reading CARMEN logs: :func:`read_carmen` (the format is described in :mod:`slamtrials.io.carmen`).

What logs in the wild hold, and what the Freiburg evaluation program reads, is tolerated; each kind of
oddity is counted in :attr:`CarmenLog.tolerated` and logged once, as one warning line:

* a laser or ODOM line with a non-finite pose or timestamp (``nan``, ``inf``): skipped;
* laser or ODOM timestamps that go backwards: the lines are ordered by timestamp (stable sort);
* laser lines that repeat an earlier line's timestamp: the first in the file is kept;
* a last line cut short (no newline at the end of the file, and the line does not parse): skipped;
* laser lines with zero readings (``FLASER 0 x y th x y th ts host ts``, a pose-only trajectory as SLAM
  programs write them for the Freiburg tool): read, with ``ranges`` ``[N, 0]`` if every line has none;
* a beam count or geometry that changes between laser lines: the scans are stacked on their common
  angular grid, padded with no-return readings (:mod:`slamtrials.io.carmen_grid`), or refused at the
  first line on another grid. ``read_carmen(path, ranges=False)`` reads only the poses, whatever the
  readings (what evaluation needs);
* PARAM lines with any trailing fields (a numeric PARAM is its value's first token);
* TRUEPOS lines whose timestamps go backwards: ordered by timestamp (stable).

``TRUEPOS`` lines (the ground truth CARMEN's simulator logs, and slamtrials writes for a run exported
with its ground truth) are read into :attr:`CarmenLog.truepos`; a broken one, or one with a non-finite
number, is a FormatError naming its line. :func:`truth_at_laser` gives each laser line its TRUEPOS pose
(same timestamp, else the nearest within :data:`TRUEPOS_TOLERANCE`), or a FormatError naming the first
laser line without one.

A log holding both FLASER and ROBOTLASER1 lines (CARMEN's logger can write the front laser in the old
format and its ``robot_laser`` message of the same scans in the new one) is read as ONE stream, the
ROBOTLASER1 lines (:data:`PREFERRED_KIND`): they carry the laser's geometry on every line, where FLASER
lines leave it to PARAMs or to a guess from the beam count. The FLASER lines are still parsed (a broken
one is a FormatError naming its line, as in a FLASER-only log), then skipped and counted in
:attr:`CarmenLog.skipped`, and one warning line says how many of their timestamps match a ROBOTLASER1
line within :data:`SAME_SCAN_TOLERANCE` (all of them: the same scans; fewer: two lasers, or lines
missing from one stream; only the ROBOTLASER1 stream is read either way). CARMEN's own tools read both
kinds as the same front laser (``playback`` publishes both as the robot's front-laser message;
``vasco-tiny`` takes ``-f``/``-r`` to use only the FLASER or only the ROBOTLASER1 lines), and so do
GMapping's log reader and the Freiburg metricEvaluator; reading both would give every scan twice.

A line broken anywhere else is a FormatError naming the file and the line.
"""

from __future__ import annotations

import logging
import math
from collections import Counter
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from slamtrials import stablemath
from slamtrials.errors import FormatError
from slamtrials.io.carmen_grid import common_grid
from slamtrials.io.carmen_lines import (
    CONFIG,
    EXTRA,
    STAMP_COLUMNS,
    LaserLine,
    param_number,
    parse_flaser,
    parse_odom,
    parse_param,
    parse_robotlaser,
    parse_truepos,
)
from slamtrials.io.carmen_log import LASER_KINDS, CarmenLaser, CarmenLog, CarmenOdometry, CarmenTruePos
from slamtrials.io.textfile import data_lines, first_bad_row, last_line, read_lines

__all__ = [
    "read_carmen",
    "truth_at_laser",
    "PARAM_RANGE_MAX",
    "PARAM_FOV",
    "PARAM_RESOLUTION",
    "PARAM_MOUNT",
    "PARAM_RANGE_MIN",
    "PREFERRED_KIND",
    "SAME_SCAN_TOLERANCE",
    "TRUEPOS_TOLERANCE",
    "TOLERATED",
]

log = logging.getLogger(__name__)

_FLOAT32_MAX = float(np.finfo(np.float32).max)

#: PARAM names that give an old-format (FLASER) laser's geometry: metres, degrees, degrees.
PARAM_RANGE_MAX = "robot_front_laser_max"
PARAM_FOV = "laser_front_laser_fov"
PARAM_RESOLUTION = "laser_front_laser_resolution"
#: PARAM names of the laser's mounting on the robot base: forward and left offsets (m), angle (rad).
PARAM_MOUNT = ("robot_frontlaser_offset", "robot_frontlaser_side_offset", "robot_frontlaser_angular_offset")
#: Not a CARMEN parameter: the minimum range (m) of a laser simulated by slamtrials.
PARAM_RANGE_MIN = "slamtrials_laser_range_min"

#: The front-laser line type read from a log holding both: its geometry is on every line.
PREFERRED_KIND = "ROBOTLASER1"
#: Two laser lines of the two kinds whose ipc timestamps differ by at most this (s) are the same scan.
SAME_SCAN_TOLERANCE = 1e-3
#: A laser line takes the pose of the TRUEPOS line at its ipc timestamp, else of the nearest within this (s).
TRUEPOS_TOLERANCE = 1e-3

#: Keys of :attr:`CarmenLog.tolerated` -> what the warning says about the lines counted ({kind}: the
#: line type).
TOLERATED = {
    "laser_nonfinite": "{kind} lines with a non-finite pose, velocity or timestamp skipped",
    "laser_reordered": "{kind} lines with a timestamp earlier than a line before them: laser lines ordered by timestamp (stable)",
    "laser_duplicate": "{kind} lines repeat an earlier line's timestamp: the first in the file kept",
    "laser_padded": "{kind} lines with fewer readings than the common grid padded with no-return readings",
    "laser_range_raised": "{kind} lines with a shorter maximum range: their no-return readings raised to the common one",
    "odom_nonfinite": "ODOM lines with a non-finite pose, velocity or timestamp skipped",
    "odom_reordered": "ODOM lines with a timestamp earlier than a line before them: ODOM lines ordered by timestamp (stable)",
    "odom_against_velocity": "ODOM lines move the pose forward while their velocity tv is below "
    f"-{0.05:g} m/s (a reversing robot logged as driving forward?): the odometry's translation has the "
    "wrong sign there; SLAM that trusts it can fail (docs/real-datasets.md, fr079)",
    "truepos_reordered": "TRUEPOS lines with a timestamp earlier than a line before them: TRUEPOS lines ordered by timestamp (stable)",
    "truncated_last_line": "the last line is cut short (no newline at the end of the file): skipped",
}
#: ``tv`` (m/s) below which an ODOM step counts as reversing, and the forward motion (m) that contradicts it.
_REVERSING_TV = -0.05
_FORWARD_STEP = 0.005


class _Tally:
    """Counts of tolerated oddities, the first line of each, and one warning per kind."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.counts: dict[str, int] = {}
        self.first: dict[str, int] = {}

    def add(self, key: str, lines: list[int] | NDArray[np.int64]) -> None:
        lines = [int(v) for v in lines]
        if lines:
            self.counts[key] = self.counts.get(key, 0) + len(lines)
            self.first[key] = min(self.first.get(key, lines[0]), min(lines))

    def warn(self, kind: str, detail: dict[str, str]) -> None:
        for key, count in self.counts.items():
            what = TOLERATED[key].format(kind=kind) + detail.get(key, "")
            if key == "truncated_last_line":
                log.warning("%s:%d: %s", self.path, self.first[key], what)
            else:
                log.warning("%s: %d %s (first: line %d)", self.path, count, what, self.first[key])


def _flaser_geometry(path: Path, params: dict[str, str], where: dict[str, int], beams: int) -> tuple[float, float]:
    """angle_min and angle_increment (rad) of an old-format laser of ``beams`` beams.

    The increment is ``laser_front_laser_resolution``, else ``laser_front_laser_fov`` (default 180
    degrees) spread over the beams. The first beam is at -90 degrees, as CARMEN's own reader puts it
    (``start_angle = -M_PI / 2`` for every old-format laser; a 360-beam laser of 0.5 degrees covers
    -90 to +89.5, "last beam ignored"), and as GMapping's reader does; a ``laser_front_laser_fov`` PARAM
    instead centres that field of view on the heading (slamtrials writes it, for scans centred so)."""
    resolution = param_number(path, params, where, PARAM_RESOLUTION)
    fov = param_number(path, params, where, PARAM_FOV)
    if resolution is not None:
        increment = math.radians(resolution)
    else:
        spread = math.radians(fov) if fov is not None else math.pi
        increment = spread / (beams - 1) if beams > 1 else 0.0
    if beams == 0:
        return 0.0, increment
    if fov is not None:
        return -math.radians(fov) / 2.0, increment
    return -math.pi / 2.0, increment


def _check_ranges(path: Path, kind: str, ranges: list[NDArray[np.float64]], numbers: list[int]) -> None:
    """Every reading a finite, non-negative float32 number; FormatError at the first that is not."""
    for row, values in enumerate(ranges):
        bad = ~np.isfinite(values) | (values < 0) | (values > _FLOAT32_MAX)
        if bad.any():
            col = int(np.argmax(bad))
            value = values[col]
            problem = (
                "is not finite"
                if not np.isfinite(value)
                else "is negative"
                if value < 0
                else "is too large for float32"
            )
            raise FormatError(path, f"{kind} range {col + 1} {problem}: {value}", line=numbers[row])


def _order(
    t: NDArray[np.float64], numbers: NDArray[np.int64], tally: _Tally, what: str, unique: bool
) -> NDArray[np.int64]:
    """Indices that put ``t`` in order (stable); with ``unique``, the first of equal timestamps only."""
    late = np.flatnonzero(t[1:] < np.maximum.accumulate(t)[:-1]) + 1
    tally.add(f"{what}_reordered", numbers[late])
    order = np.argsort(t, kind="stable")
    if unique and len(order) > 1:
        repeat = np.concatenate([[False], np.diff(t[order]) == 0])
        tally.add(f"{what}_duplicate", np.sort(numbers[order[repeat]], kind="stable"))
        order = order[~repeat]
    return order


def read_carmen(path: str | Path, *, ranges: bool = True) -> CarmenLog:
    """Read the front laser (FLASER or ROBOTLASER1), ODOM and PARAM lines of a CARMEN log.

    A log holding both FLASER and ROBOTLASER1 lines is read as one stream, its ROBOTLASER1 lines (exact
    geometry on every line): the FLASER lines are parsed, then skipped, counted in
    :attr:`CarmenLog.skipped` and reported in one warning line with how many of their timestamps match a
    ROBOTLASER1 line (module docstring: why, and what CARMEN's own tools do). TRUEPOS lines (ground truth)
    are read into :attr:`CarmenLog.truepos`, in timestamp order; :func:`truth_at_laser` pairs them with the
    laser lines. Other line types (``RLASER``, ``ROBOTLASER2``, ``RAWLASER1``, ``SYNC``, ...) are skipped
    unparsed and counted in :attr:`CarmenLog.skipped`; ``#`` lines and blank lines are ignored. What is
    tolerated (and counted in :attr:`CarmenLog.tolerated`, and logged once per kind) is listed in the
    module docstring.

    Parameters
    ----------
    path:
        The log file: plain text, or gzip- or bzip2-compressed (recognised by its first bytes).
    ranges:
        Read the readings. False reads only the poses and timestamps (``ranges`` ``[N, 0]``): readings
        are neither checked nor stacked, so a log whose beam count or geometry changes is read whatever
        its grids; the geometry is then that of the first line.

    Returns
    -------
    CarmenLog
        Laser lines in timestamp order (``ranges`` float32 [N, B] in metres), the ODOM lines and the
        PARAMs. ROBOTLASER1 lines give their own geometry; FLASER lines take it from the PARAMs
        ``laser_front_laser_resolution`` (deg), ``laser_front_laser_fov`` (deg) and
        ``robot_front_laser_max`` (m), else 180 degrees spread over the beams; the first beam at -90
        degrees as CARMEN's reader puts it (centred on the heading when a ``laser_front_laser_fov`` PARAM
        gives the field of view), and the largest range in the log as ``range_max`` (0 without readings).
        The odometry of a frame is its laser line's own second pose triple; ODOM and TRUEPOS lines are
        returned separately, not merged into the frames. ``path`` and the laser lines' ``line_numbers``
        are set, for errors found later.

    Raises
    ------
    FormatError
        Naming the file and line: a wrong field count (``num_readings`` disagreeing with the fields), a
        field that is not a number (in the lines of both front-laser kinds, the skipped one too), a
        reading that is negative or not finite, a TRUEPOS number that is not finite, lines whose beams
        are not on one angular grid (with ``ranges``), a non-positive ROBOTLASER1 maximum range, or no
        usable laser line at all.
    """
    path = Path(path)
    lines = read_lines(path)
    cut_short = bool(lines) and lines[-1].strip() != ""  # no newline after the last line
    final = last_line(lines)
    tally = _Tally(path)
    laser_lines: dict[str, list[LaserLine]] = {name: [] for name in LASER_KINDS}
    laser_numbers: dict[str, list[int]] = {name: [] for name in LASER_KINDS}
    laser_hosts: dict[str, list[str]] = {name: [] for name in LASER_KINDS}
    odom_rows: list[list[float]] = []
    odom_numbers: list[int] = []
    odom_hosts: list[str] = []
    truepos_rows: list[list[float]] = []
    truepos_numbers: list[int] = []
    truepos_hosts: list[str] = []
    params: dict[str, str] = {}
    param_lines: dict[str, int] = {}
    skipped: Counter[str] = Counter()
    for number, tokens in data_lines(lines):
        name = tokens[0]
        try:
            if name in LASER_KINDS:
                parsed = (
                    parse_flaser(path, number, tokens) if name == "FLASER" else parse_robotlaser(path, number, tokens)
                )
                laser_lines[name].append(parsed)
                laser_numbers[name].append(number)
                laser_hosts[name].append(tokens[-2])
            elif name == "ODOM":
                odom_rows.append(parse_odom(path, number, tokens))
                odom_numbers.append(number)
                odom_hosts.append(tokens[8])
            elif name == "TRUEPOS":
                truepos_rows.append(parse_truepos(path, number, tokens))
                truepos_numbers.append(number)
                truepos_hosts.append(tokens[8])
            elif name == "PARAM":
                key, value = parse_param(path, number, tokens)
                params[key] = value
                param_lines[key] = number
            else:
                skipped[name] += 1
        except FormatError:
            if not (cut_short and number == final):
                raise
            tally.add("truncated_last_line", [number])
    for key in (*PARAM_MOUNT, PARAM_RANGE_MIN):
        param_number(path, params, param_lines, key, positive=False)
    present = [name for name in LASER_KINDS if laser_lines[name]]
    if not present:
        rear = (
            f" ({skipped['RLASER']} RLASER lines: slamtrials reads the front laser, as the Freiburg evaluator does)"
            if skipped["RLASER"]
            else ""
        )
        raise FormatError(path, f"no FLASER or ROBOTLASER1 line: not a CARMEN log with a front laser{rear}", line=final)
    kind = PREFERRED_KIND if PREFERRED_KIND in present else present[0]
    laser = _laser(
        path,
        kind,
        laser_lines[kind],
        laser_numbers[kind],
        laser_hosts[kind],
        params,
        param_lines,
        tally,
        ranges,
    )
    odom = _odometry(path, odom_rows, odom_numbers, odom_hosts, tally)
    truepos = _truepos(truepos_rows, truepos_numbers, truepos_hosts, tally)
    tally.warn(
        kind,
        {
            "laser_padded": f" to {laser.beams} beams ({laser.range_max:g} m)",
            "laser_range_raised": f" ({laser.range_max:g} m)",
        },
    )
    for other in present:
        if other != kind:
            skipped[other] = len(laser_numbers[other])
            _warn_other_stream(path, laser, laser_lines[kind], other, laser_lines[other], laser_numbers[other])
    return CarmenLog(
        laser=laser,
        odom=odom,
        params=params,
        skipped=dict(skipped),
        tolerated=dict(tally.counts),
        truepos=truepos,
        path=path,
    )


def _same_scans(t: NDArray[np.float64], other: NDArray[np.float64]) -> int:
    """How many of the timestamps ``other`` are within :data:`SAME_SCAN_TOLERANCE` of one of ``t``."""
    t = np.sort(t[np.isfinite(t)], kind="stable")
    other = other[np.isfinite(other)]
    if len(t) == 0 or len(other) == 0:
        return 0
    right = np.clip(np.searchsorted(t, other), 0, len(t) - 1)
    left = np.clip(right - 1, 0, len(t) - 1)
    gap = np.minimum(np.abs(t[right] - other), np.abs(t[left] - other))
    return int(np.count_nonzero(gap <= SAME_SCAN_TOLERANCE))


def _warn_other_stream(
    path: Path, laser: CarmenLaser, read: list[LaserLine], other: str, parsed: list[LaserLine], numbers: list[int]
) -> None:
    """One warning: the lines ``parsed`` of the front-laser kind ``other`` were skipped, and whether they are
    the same scans as the lines ``read`` (all of them, also those the reader then dropped: same timestamp)."""
    stamp = STAMP_COLUMNS.index("ipc_timestamp")
    matched = _same_scans(
        np.array([line.stamps[stamp] for line in read]), np.array([line.stamps[stamp] for line in parsed])
    )
    total = len(parsed)
    verdict = (
        "the same scans"
        if matched == total
        else f"the two streams differ (two lasers, or lines missing from one): only the {laser.kind} lines are read"
    )
    log.warning(
        "%s: %d %s lines skipped (first: line %d): the log also holds %s lines, the front laser in CARMEN's "
        "new format with its geometry on every line, read instead (%d frames); %d of %d %s timestamps match "
        "a %s line within %g ms: %s",
        path,
        total,
        other,
        numbers[0],
        laser.kind,
        len(laser),
        matched,
        total,
        other,
        laser.kind,
        SAME_SCAN_TOLERANCE * 1e3,
        verdict,
    )


def _one_or_all(hosts: list[str]) -> str | list[str]:
    return hosts[0] if hosts and hosts.count(hosts[0]) == len(hosts) else hosts


def _geometry(
    path: Path, kind: str, kept: list[LaserLine], numbers: list[int], params: dict[str, str], where: dict[str, int]
) -> NDArray[np.float64]:
    """float64 ``[N, 3]`` angle of the first beam, increment (rad) and maximum range (m) of each line."""
    n = len(kept)
    geometry = np.empty((n, 3))
    if kind == "ROBOTLASER1":
        config = np.stack([line.config if line.config is not None else np.full(len(CONFIG), np.nan) for line in kept])
        bad = first_bad_row(~np.isfinite(config))
        if bad is not None:
            raise FormatError(path, f"ROBOTLASER1 {CONFIG[bad[1]]} is not finite: {config[bad]}", line=numbers[bad[0]])
        small = np.flatnonzero(~((config[:, 3] > 0) & (config[:, 3] <= _FLOAT32_MAX)))
        if small.size:
            i = int(small[0])
            raise FormatError(
                path, f"ROBOTLASER1 maximum_range must be positive (and a float32), got {config[i, 3]}", line=numbers[i]
            )
        geometry[:, 0], geometry[:, 1], geometry[:, 2] = config[:, 0], config[:, 2], config[:, 3]
        return geometry
    counts = [len(line.ranges) for line in kept]
    range_max = param_number(path, params, where, PARAM_RANGE_MAX)
    if range_max is not None and range_max > _FLOAT32_MAX:
        raise FormatError(
            path, f"PARAM {PARAM_RANGE_MAX} is too large for float32: {range_max}", line=where[PARAM_RANGE_MAX]
        )
    if range_max is None:
        usable = [line.ranges[np.isfinite(line.ranges) & (line.ranges <= _FLOAT32_MAX)] for line in kept]
        top = max((float(r.max()) for r in usable if len(r)), default=0.0)
        range_max = float(str(np.float32(top)))  # shortest decimal of the float32 maximum: 81.91, not 81.910004
    by_count = {count: _flaser_geometry(path, params, where, count) for count in sorted(set(counts))}
    for i, count in enumerate(counts):
        geometry[i] = (*by_count[count], range_max)
    return geometry


def _laser(
    path: Path,
    kind: str,
    parsed: list[LaserLine],
    numbers_list: list[int],
    hosts: list[str],
    params: dict[str, str],
    where: dict[str, int],
    tally: _Tally,
    with_ranges: bool,
) -> CarmenLaser:
    numbers = np.asarray(numbers_list, dtype=np.int64)
    stamps = np.stack([line.stamps for line in parsed])
    finite = np.isfinite(stamps).all(axis=1)
    tally.add("laser_nonfinite", numbers[~finite])
    keep = np.flatnonzero(finite)
    if keep.size == 0:
        raise FormatError(path, f"every {kind} line has a non-finite pose or timestamp", line=int(numbers[0]))
    order = keep[_order(stamps[keep, -2], numbers[keep], tally, "laser", unique=True)]
    kept = [parsed[i] for i in order.tolist()]
    kept_numbers = numbers[order].tolist()
    readings = [line.ranges for line in kept]
    if with_ranges:
        _check_ranges(path, kind, readings, kept_numbers)
    geometry = _geometry(path, kind, kept, kept_numbers, params, where)
    if with_ranges:
        grid = common_grid(path, kind, kept_numbers, readings, geometry)
        tally.add("laser_padded", np.asarray(kept_numbers)[grid.padded])
        tally.add("laser_range_raised", np.asarray(kept_numbers)[grid.raised])
        scans, angle_min, increment, range_max = grid.ranges, grid.angle_min, grid.angle_increment, grid.range_max
    else:
        scans = np.zeros((len(kept), 0), dtype=np.float32)
        angle_min, increment, range_max = (float(v) for v in geometry[0])
    rows = stamps[order]
    first = kept[0]
    integers = first.integers if first.integers is not None else (0, 0)  # ROBOTLASER1's laser_type, remission_mode
    return CarmenLaser(
        kind=kind,
        t=rows[:, -2].copy(),
        logger_t=rows[:, -1].copy(),
        hostname=_one_or_all([hosts[i] for i in order.tolist()]),
        ranges=scans,
        pose=rows[:, :3].copy(),
        odometry=rows[:, 3:6].copy(),
        angle_min=angle_min,
        angle_increment=increment,
        range_max=range_max,
        laser_type=integers[0],
        accuracy=float(first.config[4]) if first.config is not None else 0.0,
        remission_mode=integers[1],
        extra=rows[:, 6 : 6 + len(EXTRA)].copy() if kind == "ROBOTLASER1" else None,
        line_readings=np.array([len(r) for r in readings], dtype=np.int64),
        line_numbers=np.asarray(kept_numbers, dtype=np.int64),
    )


def _forward_while_reversing(values: NDArray[np.float64]) -> NDArray[np.bool_]:
    """``[N - 1]``: ODOM step k -> k + 1 moves forward along the heading at k while line k + 1's tv says reversing."""
    poses = values[:, :3]
    step = poses[1:, :2] - poses[:-1, :2]
    forward = step[:, 0] * stablemath.cos(poses[:-1, 2]) + step[:, 1] * stablemath.sin(poses[:-1, 2])
    return (values[1:, 3] < _REVERSING_TV) & (forward > _FORWARD_STEP)


def _odometry(
    path: Path, rows: list[list[float]], numbers_list: list[int], hosts: list[str], tally: _Tally
) -> CarmenOdometry:
    if not rows:
        return CarmenOdometry.empty()
    values = np.array(rows, dtype=np.float64)
    numbers = np.asarray(numbers_list, dtype=np.int64)
    finite = np.isfinite(values).all(axis=1)
    tally.add("odom_nonfinite", numbers[~finite])
    keep = np.flatnonzero(finite)
    if keep.size == 0:
        return CarmenOdometry.empty()
    order = keep[_order(values[keep, 6], numbers[keep], tally, "odom", unique=False)]
    values = values[order]
    tally.add("odom_against_velocity", numbers[order][1:][_forward_while_reversing(values)])
    return CarmenOdometry(
        t=values[:, 6].copy(),
        logger_t=values[:, 7].copy(),
        hostname=_one_or_all([hosts[i] for i in order.tolist()]),
        pose=values[:, :3].copy(),
        tv=values[:, 3].copy(),
        rv=values[:, 4].copy(),
        accel=values[:, 5].copy(),
    )


def _truepos(rows: list[list[float]], numbers_list: list[int], hosts: list[str], tally: _Tally) -> CarmenTruePos:
    """The TRUEPOS lines (every number finite, checked when parsed) in timestamp order (stable)."""
    if not rows:
        return CarmenTruePos.empty()
    values = np.array(rows, dtype=np.float64)
    numbers = np.asarray(numbers_list, dtype=np.int64)
    order = _order(values[:, 6], numbers, tally, "truepos", unique=False)
    values = values[order]
    return CarmenTruePos(
        t=values[:, 6].copy(),
        logger_t=values[:, 7].copy(),
        hostname=_one_or_all([hosts[i] for i in order.tolist()]),
        pose=values[:, :3].copy(),
        odometry=values[:, 3:6].copy(),
        line_numbers=numbers[order].copy(),
    )


def _nearest(t: NDArray[np.float64], at: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Index into the sorted ``t`` of the time nearest each of ``at`` (the first of equal times, the earlier
    on a tie) and its distance (s)."""
    after = np.clip(np.searchsorted(t, at, side="left"), 0, len(t) - 1)
    before = np.searchsorted(t, t[np.clip(after - 1, 0, len(t) - 1)], side="left")
    gap_before, gap_after = np.abs(at - t[before]), np.abs(t[after] - at)
    pick = np.where((gap_before <= gap_after) & (t[before] != t[after]), before, after)
    return pick, np.minimum(gap_before, gap_after)


def truth_at_laser(log: CarmenLog) -> NDArray[np.float64]:
    """The ground truth at every laser line from the log's TRUEPOS lines: float64 ``[N, 3]`` (m, m, rad).

    Each laser line takes the true pose (``true_x true_y true_theta``, the robot base in the world frame)
    of the TRUEPOS line at its ``ipc_timestamp``, or of the nearest one within :data:`TRUEPOS_TOLERANCE`
    (the first in time of equal timestamps, the earlier of two equally near).

    Raises
    ------
    FormatError
        The log has no TRUEPOS lines, or a laser line has none within the tolerance: the error names the
        file (:attr:`CarmenLog.path`) and that laser line (the first such).
    """
    laser, truepos = log.laser, log.truepos
    path = log.path if log.path is not None else Path("<CARMEN log>")
    if len(truepos) == 0:
        raise FormatError(path, "no TRUEPOS line: the log holds no ground truth")
    pick, gap = _nearest(truepos.t, laser.t)
    missing = np.flatnonzero(~(gap <= TRUEPOS_TOLERANCE))
    if missing.size:
        i = int(missing[0])
        line = int(laser.line_numbers[i]) if laser.line_numbers is not None else None
        raise FormatError(
            path,
            f"the TRUEPOS lines do not cover the {laser.kind} lines: this one (ipc_timestamp {laser.t[i]:.6f}) "
            f"has no TRUEPOS line within {TRUEPOS_TOLERANCE * 1e3:g} ms (the nearest is {gap[i]:.6g} s away; "
            f"{len(truepos)} TRUEPOS lines from {truepos.t[0]:.6f} to {truepos.t[-1]:.6f} s, "
            f"{missing.size} of {len(laser)} laser lines without one); read it without ground truth "
            "(import --no-truth) to ignore them",
            line=line,
        )
    return truepos.pose[pick].copy()
