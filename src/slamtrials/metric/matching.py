"""Matching relation timestamps to an estimated trajectory, as the Freiburg evaluation program does.

For each timestamp the estimated pose with the nearest timestamp is taken, accepted if it is at most
``tolerance`` seconds away (inclusive; default 0.1 s). Optionally the pose is linearly interpolated
between the two poses around the timestamp instead (accepted under the same rule, so interpolation
never changes which relations are matched). When no pose is close enough and an odometry trajectory is
given, the nearest estimated pose is carried to the timestamp by the odometry motion between the two
times (``x(t) = x(t_e) (+) (o(t_e) (-) o(t))``). Timestamps that still have no pose are reported as
unmatched, never silently dropped; timestamps outside the time span of the data altogether are flagged
as ``outside`` so that callers can refuse them.

Inclusive comparison: timestamps are float64 seconds of about 1e9 in real logs, where one unit in the
last place is about 2.4e-7 s, so a gap is accepted when ``gap <= tolerance + ulp(t)``: a gap that
is exactly the tolerance in the decimal file is accepted whichever way its digits rounded (the slack
used is ``|t| * 2^-52``, at least one unit in the last place).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials.errors import MetricError
from slamtrials.geometry import compose, ominus
from slamtrials.geometry import interpolate as interpolate_poses
from slamtrials.metric.kernels import EPS, nearest_indices, relative_poses
from slamtrials.record import Relations, Trajectory

__all__ = [
    "DEFAULT_TOLERANCE",
    "RUN_TOLERANCE",
    "relations_meet",
    "check_trajectory",
    "check_relations",
    "PoseLookup",
    "lookup_poses",
    "RelationMatch",
    "match_relations",
]

#: Largest accepted gap (s) between a relation timestamp and the matched pose: the Freiburg program's 0.1 s.
DEFAULT_TOLERANCE = 0.1
#: Matching tolerance (s) of a simulated run's estimate to its ground truth: they share the simulator's
#: clock (frames every 0.1 s), so only the same frame's pose is taken directly and the odometry fills the rest.
RUN_TOLERANCE = 0.001


def relations_meet(times: NDArray[np.float64], relations: Relations, tolerance: float) -> bool:
    """Whether any finite timestamp of ``relations`` is within ``tolerance`` (s) of one of ``times``.

    ``times`` ``[N]`` must be strictly increasing. False means the relations and the trajectory do not
    belong together (another log's relations): every relation would go unmatched.
    """
    stamps = np.concatenate([relations.t1, relations.t2])
    stamps = stamps[np.isfinite(stamps)]
    if len(times) == 0 or len(stamps) == 0:
        return False
    return bool(nearest_indices(np.asarray(times, dtype=np.float64), stamps, tolerance)[2].any())


def check_trajectory(trajectory: Trajectory, what: str = "estimate") -> None:
    """Refuse an empty trajectory, non-finite values or timestamps that do not strictly increase.

    Parameters
    ----------
    trajectory:
        The trajectory to check.
    what:
        Its name in error messages (``"estimate"``, ``"odometry"``, ``"truth"``).

    Raises
    ------
    MetricError
        With ``what`` and ``index`` set to the first pose at fault (0-based).
    """
    t, poses = trajectory.t, trajectory.poses
    if len(t) == 0:
        raise MetricError(f"{what}: the trajectory is empty (no poses)", what=what)
    bad = ~(np.isfinite(t) & np.isfinite(poses).all(axis=1))
    if bad.any():
        i = int(np.argmax(bad))
        raise MetricError(f"{what}: pose {i} has a non-finite timestamp or coordinate", what=what, index=i)
    steps = np.diff(t)
    if (steps <= 0).any():
        i = int(np.argmax(steps <= 0)) + 1
        raise MetricError(
            f"{what}: timestamps must strictly increase, but pose {i} has t={float(t[i])!r} after t={float(t[i - 1])!r}",
            what=what,
            index=i,
        )


def check_relations(relations: Relations) -> None:
    """Refuse relations with non-finite timestamps or transforms, or with ``t1 == t2``.

    Raises
    ------
    MetricError
        With ``what="relations"`` and ``index`` set to the first relation at fault (0-based).
    """
    bad = ~(np.isfinite(relations.t1) & np.isfinite(relations.t2) & np.isfinite(relations.delta).all(axis=1))
    if bad.any():
        k = int(np.argmax(bad))
        raise MetricError(f"relation {k} has a non-finite timestamp or transform", what="relations", index=k)
    same = relations.t1 == relations.t2
    if same.any():
        k = int(np.argmax(same))
        raise MetricError(
            f"relation {k} relates a timestamp to itself (t1 == t2 == {float(relations.t1[k])!r})",
            what="relations",
            index=k,
        )


@dataclass(frozen=True, eq=False)
class PoseLookup:
    """Poses of a trajectory at requested timestamps.

    Attributes
    ----------
    poses:
        float64 ``[M, 3]`` pose (m, m, rad) at each timestamp, in the trajectory's frame; NaN where not found.
    found:
        bool ``[M]``: a pose was found (directly or through the odometry).
    corrected:
        bool ``[M]``: the pose was carried from the nearest pose by the odometry.
    outside:
        bool ``[M]``: the timestamp lies outside the data's time span by more than the tolerance
        (``[t_first - tol, t_last + tol]`` of the trajectory, or of it and the odometry together).
    nearest:
        int64 ``[M]`` index of the trajectory pose nearest in time.
    gap:
        float64 ``[M]`` absolute time (s) between each timestamp and that nearest pose.
    """

    poses: NDArray[np.float64]
    found: NDArray[np.bool_]
    corrected: NDArray[np.bool_]
    outside: NDArray[np.bool_]
    nearest: NDArray[np.int64]
    gap: NDArray[np.float64]


def _interpolated(
    times: NDArray[np.float64], poses: NDArray[np.float64], t: NDArray[np.float64], nearest: NDArray[np.int64]
) -> NDArray[np.float64]:
    """Poses linearly interpolated at ``t`` between the surrounding poses; the nearest pose at the ends."""
    before = nearest - (times[nearest] > t)  # last pose at or before t (-1 if none)
    inside = (before >= 0) & (before < len(times) - 1)
    out = poses[nearest].copy()
    if inside.any():
        b = before[inside]
        fraction = (t[inside] - times[b]) / (times[b + 1] - times[b])
        out[inside] = interpolate_poses(poses[b], poses[b + 1], fraction)
    return out


def _within(gap: NDArray[np.float64], t: NDArray[np.float64], tolerance: float) -> NDArray[np.bool_]:
    """``gap <= tolerance`` up to one unit in the last place of the timestamps (see the module docstring)."""
    return gap <= tolerance + np.abs(t) * EPS


def _span(trajectory: Trajectory, odometry: Trajectory | None) -> tuple[float, float]:
    """First and last time (s) covered by the trajectory, or by it and the odometry together."""
    first, last = float(trajectory.t[0]), float(trajectory.t[-1])
    if odometry is not None:
        first, last = min(first, float(odometry.t[0])), max(last, float(odometry.t[-1]))
    return first, last


def _outside(
    t: NDArray[np.float64], trajectory: Trajectory, odometry: Trajectory | None, tolerance: float
) -> NDArray[np.bool_]:
    """Timestamps more than ``tolerance`` before the first or after the last time of the data."""
    first, last = _span(trajectory, odometry)
    return ~(_within(np.maximum(first - t, 0.0), t, tolerance) & _within(np.maximum(t - last, 0.0), t, tolerance))


def _direct(trajectory: Trajectory, t: NDArray[np.float64], tolerance: float, interpolate: bool):
    nearest, gap, found = nearest_indices(trajectory.t, t, tolerance)
    poses = np.full((len(t), 3), np.nan)
    if found.any():
        if interpolate:
            poses[found] = _interpolated(trajectory.t, trajectory.poses, t[found], nearest[found])
        else:
            poses[found] = trajectory.poses[nearest[found]]
    return poses, found, nearest, gap


def lookup_poses(
    trajectory: Trajectory,
    t: ArrayLike,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
    interpolate: bool = False,
    odometry: Trajectory | None = None,
    check: bool = True,
) -> PoseLookup:
    """Find the pose of ``trajectory`` at each timestamp of ``t``, the Freiburg program's way.

    Parameters
    ----------
    trajectory:
        Estimated trajectory, timestamps strictly increasing.
    t:
        float64 ``[M]`` timestamps (s).
    tolerance:
        Largest accepted gap (s) between a timestamp and the pose used, inclusive.
    interpolate:
        Interpolate between the two poses around each accepted timestamp instead of taking the nearest.
    odometry:
        Optional odometry trajectory (any frame). A timestamp with no pose within ``tolerance`` then
        gets the nearest pose moved by the odometry motion from that pose's time to the timestamp, if
        the odometry has poses within ``tolerance`` of both times.
    check:
        Validate the trajectories first (:func:`check_trajectory`).

    Returns
    -------
    PoseLookup
        Poses, found/corrected/outside masks, nearest indices and gaps.

    Raises
    ------
    MetricError
        An empty, non-finite or unordered trajectory, or a negative tolerance.
    """
    if not (tolerance >= 0):
        raise MetricError(f"the matching tolerance must be a non-negative number of seconds, got {tolerance}")
    if check:
        check_trajectory(trajectory, "estimate")
        if odometry is not None:
            check_trajectory(odometry, "odometry")
    t = np.asarray(t, dtype=np.float64).reshape(-1)
    poses, found, nearest, gap = _direct(trajectory, t, tolerance, interpolate)
    outside = _outside(t, trajectory, odometry, tolerance)
    corrected = np.zeros(len(t), dtype=bool)
    if odometry is not None:
        missing = np.flatnonzero(~found & ~outside)
        if len(missing):
            t_missing = t[missing]
            t_near = trajectory.t[nearest[missing]]
            o_at, o_found, _, _ = _direct(odometry, t_missing, tolerance, interpolate)
            o_near, o_near_found, _, _ = _direct(odometry, t_near, tolerance, interpolate)
            ok = o_found & o_near_found
            rows = missing[ok]
            poses[rows] = compose(trajectory.poses[nearest[rows]], ominus(o_near[ok], o_at[ok]))
            found[rows] = True
            corrected[rows] = True
    return PoseLookup(poses=poses, found=found, corrected=corrected, outside=outside, nearest=nearest, gap=gap)


@dataclass(frozen=True, eq=False)
class RelationMatch:
    """The estimated counterpart of each relation.

    Attributes
    ----------
    delta:
        float64 ``[K, 3]`` estimated relative pose ``x(t1)^-1 * x(t2)`` (m, m, rad), NaN where unmatched.
    matched:
        bool ``[K]``: both timestamps of the relation have an estimated pose.
    corrected:
        bool ``[K]``: at least one of the two poses was carried there by the odometry.
    outside:
        bool ``[K]``: a timestamp lies outside the time span of the data (only when ``allow_outside``).
    """

    delta: NDArray[np.float64]
    matched: NDArray[np.bool_]
    corrected: NDArray[np.bool_]
    outside: NDArray[np.bool_]

    @property
    def unmatched(self) -> NDArray[np.int64]:
        """Indices ``[U]`` of the relations without an estimated counterpart."""
        return np.flatnonzero(~self.matched)


def match_relations(
    estimate: Trajectory,
    relations: Relations,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
    interpolate: bool = False,
    odometry: Trajectory | None = None,
    allow_outside: bool = False,
) -> RelationMatch:
    """Estimated relative poses for the timestamps of ``relations`` (see :func:`lookup_poses`).

    Parameters
    ----------
    estimate:
        Estimated trajectory, timestamps strictly increasing.
    relations:
        The relations to match, ``K`` of them.
    tolerance, interpolate, odometry:
        As for :func:`lookup_poses`.
    allow_outside:
        Report relations with a timestamp outside the data's time span as unmatched instead of refusing them.

    Returns
    -------
    RelationMatch

    Raises
    ------
    MetricError
        A bad trajectory (``what`` = "estimate" or "odometry", ``index`` = pose), or a relation that is
        non-finite, relates a time to itself or (unless ``allow_outside``) lies outside the trajectory
        (``what="relations"``, ``index`` = relation).
    """
    check_trajectory(estimate, "estimate")
    if odometry is not None:
        check_trajectory(odometry, "odometry")
    check_relations(relations)
    k = len(relations)
    stamps = np.concatenate([relations.t1, relations.t2])
    if not interpolate and odometry is None:  # the common case, without gathered copies of the poses
        nearest, _, within = nearest_indices(estimate.t, stamps, tolerance)
        outside_each = _outside(stamps, estimate, None, tolerance)
        found_each, corrected_each, poses = within, np.zeros(2 * k, dtype=bool), None
    else:
        found = lookup_poses(
            estimate, stamps, tolerance=tolerance, interpolate=interpolate, odometry=odometry, check=False
        )
        outside_each, found_each, corrected_each, poses = found.outside, found.found, found.corrected, found.poses
    outside = outside_each[:k] | outside_each[k:]
    if outside.any() and not allow_outside:
        i = int(np.argmax(outside))
        stamp = float(relations.t1[i] if outside_each[i] else relations.t2[i])
        first, last = _span(estimate, odometry)
        source = "estimate and odometry" if odometry is not None else "estimate"
        raise MetricError(
            f"relation {i}: timestamp {stamp!r} lies outside the time span of the {source} "
            f"[{first!r}, {last!r}] (+-{tolerance} s)",
            what="relations",
            index=i,
        )
    matched = found_each[:k] & found_each[k:] & ~outside
    if poses is None:
        delta = relative_poses(estimate.poses, nearest[:k], estimate.poses, nearest[k:])
    else:
        rows = np.arange(k)
        delta = relative_poses(poses, rows, poses, rows + k)
    delta[~matched] = np.nan
    corrected = (corrected_each[:k] | corrected_each[k:]) & matched
    return RelationMatch(delta=delta, matched=matched, corrected=corrected, outside=outside)
