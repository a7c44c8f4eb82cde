"""The odometry fit: scale biases and random-walk noise per metre and per radian, against a reference.

The model (:mod:`slamtrials.sim.odometry`): every step of arc length ``L`` and heading change ``phi``
is measured as ``(1 + e_lin) L + n_L`` and ``(1 + e_ang) phi + n_phi``, with independent zero-mean
errors of variance ``a^2 |L| + b^2 |phi|`` and ``c^2 |phi| + d^2 |L|`` (``a, b, c, d`` the profile's
``noise_linear_per_m``, ``noise_linear_per_rad``, ``noise_angular_per_rad``, ``noise_angular_per_m``).
Variances add, so over any stretch of path that drives ``D`` metres and turns ``R`` radians

    E_L   = L' - (1 + e_lin) L,       var = a^2 D + b^2 R (+ k_L)
    E_phi = phi' - (1 + e_ang) phi,   var = c^2 R + d^2 D (+ k_phi)

whatever the stretch's steps. The fit measures these errors over *segments* of the log, against one of
two references:

- **benchmark relations** (:func:`relation_segments`): each relation (human-checked relative pose between
  two stamps, Freiburg ``.relations``) is a segment, the odometry's motion between the relation's two
  frames against the relation's; chained relations (one starting where another ends) make the longer
  windows. Independent of any SLAM run.
- **a SLAM path** (:func:`slam_segments`): the reference's update frames (:func:`anchor_frames`) cut the
  log.

``k`` is an error at a window's two ends that does not grow with the window: the SLAM path's own pose
error, or, against relations, whatever does not add up along a chain (the odometry's timing against the
laser stamps the relations are given at; on the shared logs a constant per window fits the window errors
of every length far better than one per relation, which would be the relations' own independent errors).

Windows of ``w`` consecutive segments (1, 2, 4, ..., non-overlapping) give error samples of growing
``D`` and ``R``. The biases are the least-squares slopes of the window errors on the reference's
window motion (overlapping windows of the middle length); the noise is the non-negative least-squares
fit of the squared window errors (bias removed) on ``[k column, D, R]``, weighted by the inverse squared
predicted variance and refitted without windows beyond ``outlier_sigmas``.

``D`` and ``R`` are the *true* distance and turn, which only the odometry measures step by step: the
odometry's own steps, unbiased, hold its noise too (a straight drive's heading noise looks like turning).
So the motion is measured over *chunks* of the odometry path (cut every ``chunk_distance`` metres or
``chunk_turn`` radians of travel, like a SLAM algorithm's updates), where the true motion outgrows the
noise, as ``sqrt(max(m^2 - s^2, 0))`` with ``m`` the chunk's net measured motion and ``s^2`` the fitted
noise's variance over it (refitted three times), and shared among the chunk's steps by their measured
size (:func:`step_magnitudes`). The coefficients are per metre and per radian: they do not depend on the
log's step or the simulator's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials import stablemath
from slamtrials.calibration.settings import CalibrationSettings
from slamtrials.calibration.stats import least_squares, nonnegative_least_squares
from slamtrials.errors import CalibrationError
from slamtrials.geometry import inverse, ominus
from slamtrials.metric.kernels import nearest_indices
from slamtrials.record import Relations

__all__ = [
    "StepMotion",
    "step_motion",
    "anchor_frames",
    "direction_conflicts",
    "Segments",
    "RelationUse",
    "slam_segments",
    "relation_segments",
    "check_relations_belong",
    "segment_conflicts",
    "motion_chunks",
    "step_magnitudes",
    "OdometryFit",
    "OdometryWindows",
    "fit_odometry",
    "fit_segments",
    "ODOMETRY_VALUES",
]

#: The fitted odometry values: the biases (signed, per run) and the noise coefficients (profile units).
ODOMETRY_VALUES = (
    "bias_linear",
    "bias_angular",
    "noise_linear_per_m",
    "noise_linear_per_rad",
    "noise_angular_per_rad",
    "noise_angular_per_m",
)


@dataclass(frozen=True, eq=False)
class StepMotion:
    """Per-step arcs, float64 ``[T - 1]``: reference ``length``, ``turn``; odometry ``odo_length``, ``odo_turn``."""

    length: NDArray[np.float64]
    turn: NDArray[np.float64]
    odo_length: NDArray[np.float64]
    odo_turn: NDArray[np.float64]


def _arc_read(d: NDArray[np.float64]) -> NDArray[np.float64]:
    """Signed arc length ``[N]`` (m) of relative poses ``d`` ``[N, 3]`` read as arcs:
    ``(dx cos(phi/2) + dy sin(phi/2)) / sinc(phi/2)``."""
    half = 0.5 * d[:, 2]
    small = np.abs(half) < 1e-3
    safe = np.where(small, 1.0, half)
    sinc = np.where(small, 1.0 - half * half / 6.0, stablemath.sin(safe) / safe)
    return (d[:, 0] * stablemath.cos(half) + d[:, 1] * stablemath.sin(half)) / sinc


def _arcs(poses: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    d = ominus(poses[:-1], poses[1:])
    return _arc_read(d), d[:, 2]


def step_motion(reference: NDArray[np.float64], odometry: NDArray[np.float64]) -> StepMotion:
    """The steps of a reference path and of the odometry (both ``[T, 3]``)."""
    length, turn = _arcs(reference)
    odo_length, odo_turn = _arcs(odometry)
    return StepMotion(length, turn, odo_length, odo_turn)


def anchor_frames(reference: NDArray[np.float64], odometry: NDArray[np.float64]) -> NDArray[np.int64]:
    """Frames ``[A]`` whose reference pose is more than the odometry carried on from the previous frame.

    A SLAM estimate places the frames between its updates by odometry (GMapping, Karto): there the
    reference step equals the odometry step, and the frame tells nothing about the odometry's error.
    Frame 0 and every frame whose reference step differs from the odometry step (by more than 1e-6 m
    or rad) are anchors; windows run between anchors. With a true path every moving frame is one.
    """
    ref = ominus(reference[:-1], reference[1:])
    odo = ominus(odometry[:-1], odometry[1:])
    d = ref - odo
    d[:, 2] = (d[:, 2] + np.pi) % (2.0 * np.pi) - np.pi
    moved = np.max(np.abs(d), axis=1) > 1e-6
    return np.concatenate(([0], np.flatnonzero(moved) + 1)).astype(np.int64)


@dataclass(frozen=True, eq=False)
class Segments:
    """The stretches of the log the odometry's errors are measured over, ``[S]`` arrays.

    Attributes
    ----------
    first, last:
        int64 frame indices of each segment's start and end (``first < last``).
    odo_length, ref_length:
        float64 signed arc length (m) of the segment by the odometry and by the reference.
    odo_turn, ref_turn:
        float64 heading change (rad) of the segment by the odometry (summed over its steps, unwrapped)
        and by the reference (unwrapped next to the odometry's).
    chain:
        int64 chain id, non-decreasing: windows run over consecutive segments of one chain, each ending
        where the next starts (one chain for a SLAM path's anchors; chained relations).
    """

    first: NDArray[np.int64]
    last: NDArray[np.int64]
    odo_length: NDArray[np.float64]
    ref_length: NDArray[np.float64]
    odo_turn: NDArray[np.float64]
    ref_turn: NDArray[np.float64]
    chain: NDArray[np.int64]

    def __len__(self) -> int:
        return int(self.first.size)


@dataclass(frozen=True)
class RelationUse:
    """How the relations file was used (counts of relations).

    Attributes
    ----------
    total:
        Relations in the file.
    matched:
        Relations both of whose stamps lie within the tolerance of two different frames.
    long:
        Matched relations whose span drives more than ``relation_max_distance`` or turns more than
        ``relation_max_turn`` by the odometry (loop closures): not used, a span that long is not one arc.
    used:
        Relations used (segments).
    chains:
        Chains they form (a relation continues a chain when it starts at the frame where another ends).
    """

    total: int
    matched: int
    long: int
    used: int
    chains: int


def slam_segments(steps: StepMotion, anchors: NDArray[np.int64]) -> Segments:
    """The anchor-to-anchor segments of a SLAM reference path (:func:`anchor_frames`), one chain."""
    first, last = anchors[:-1].astype(np.int64), anchors[1:].astype(np.int64)

    def seg(values: NDArray[np.float64]) -> NDArray[np.float64]:
        cum = np.concatenate(([0.0], np.cumsum(values)))
        return cum[last] - cum[first]

    return Segments(
        first=first,
        last=last,
        odo_length=seg(steps.odo_length),
        ref_length=seg(steps.length),
        odo_turn=seg(steps.odo_turn),
        ref_turn=seg(steps.turn),
        chain=np.zeros(first.size, dtype=np.int64),
    )


def relation_segments(
    t: NDArray[np.float64],
    odometry: NDArray[np.float64],
    relations: Relations,
    settings: CalibrationSettings,
) -> tuple[Segments, RelationUse]:
    """The relations of a log as segments: the odometry's motion between each relation's two frames
    against the relation.

    Parameters
    ----------
    t:
        float64 ``[T]`` frame times (s), strictly increasing.
    odometry:
        float64 ``[T, 3]`` odometry poses (odometry frame).
    relations:
        The benchmark relations (``delta`` is the pose at ``t2`` seen from the pose at ``t1``).
    settings:
        ``relation_tolerance`` (s) for the stamps, ``relation_max_distance`` (m) and
        ``relation_max_turn`` (rad) for the spans used.

    A relation is matched to the frames nearest its stamps (within the tolerance, two different frames;
    one with ``t1 > t2`` is turned round). Both sides are read as arcs (signed arc length of the relative
    pose; the odometry's heading change summed over its steps, the relation's unwrapped next to it).
    Relations are chained (one starting at the frame where another ends continues its chain; a relation
    joins one chain only), chains in order of their first frame.
    """
    first, _, near1 = nearest_indices(t, relations.t1, settings.relation_tolerance)
    second, _, near2 = nearest_indices(t, relations.t2, settings.relation_tolerance)
    matched = near1 & near2 & (first != second)
    i = np.minimum(first, second)[matched].astype(np.int64)
    j = np.maximum(first, second)[matched].astype(np.int64)
    delta = relations.delta[matched].copy()
    turned = first[matched] > second[matched]
    if np.any(turned):
        delta[turned] = inverse(delta[turned])
    odo_length_steps, odo_turn_steps = _arcs(odometry)
    cum_turn = np.concatenate(([0.0], np.cumsum(odo_turn_steps)))
    cum_travel = np.concatenate(([0.0], np.cumsum(np.abs(odo_length_steps))))
    cum_turned = np.concatenate(([0.0], np.cumsum(np.abs(odo_turn_steps))))
    short = (cum_travel[j] - cum_travel[i] <= settings.relation_max_distance) & (
        cum_turned[j] - cum_turned[i] <= settings.relation_max_turn
    )
    i, j, delta = i[short], j[short], delta[short]
    # chains: sort by start frame (then end frame); each relation continues the first unchained one ending at its start
    order = np.lexsort((j, i))
    i, j, delta = i[order], j[order], delta[order]
    by_start: dict[int, list[int]] = {}
    for k, start in enumerate(i.tolist()):
        by_start.setdefault(start, []).append(k)
    taken = np.zeros(i.size, dtype=bool)
    chains: list[list[int]] = []
    for k in range(i.size):
        if taken[k]:
            continue
        chain = [k]
        taken[k] = True
        end = int(j[k])
        while True:
            nxt = next((c for c in by_start.get(end, []) if not taken[c]), None)
            if nxt is None:
                break
            chain.append(nxt)
            taken[nxt] = True
            end = int(j[nxt])
        chains.append(chain)
    flat = np.array([k for chain in chains for k in chain], dtype=np.int64)
    chain_id = np.repeat(np.arange(len(chains), dtype=np.int64), [len(c) for c in chains])
    i, j, delta = i[flat], j[flat], delta[flat]
    odo_turn = cum_turn[j] - cum_turn[i]
    ref_turn = delta[:, 2] + 2.0 * np.pi * np.round((odo_turn - delta[:, 2]) / (2.0 * np.pi))
    segments = Segments(
        first=i,
        last=j,
        odo_length=_arc_read(ominus(odometry[i], odometry[j])),
        ref_length=_arc_read(delta),
        odo_turn=odo_turn,
        ref_turn=ref_turn,
        chain=chain_id,
    )
    use = RelationUse(
        total=len(relations),
        matched=int(np.count_nonzero(matched)),
        long=int(np.count_nonzero(~short)),
        used=int(i.size),
        chains=len(chains),
    )
    return segments, use


def check_relations_belong(t: NDArray[np.float64], relations: Relations, tolerance: float) -> None:
    """Raise :class:`CalibrationError` (one line) when ``relations`` do not belong to the log of frame times ``t``.

    They belong when every stamp lies within the log's span (first frame - tolerance to last frame +
    tolerance) and some relation falls on two frames.
    """
    if len(relations) == 0:
        raise CalibrationError("the relations file holds no relation")
    stamps = np.concatenate([relations.t1, relations.t2])
    low, high = float(t[0]) - tolerance, float(t[-1]) + tolerance
    outside = (stamps < low) | (stamps > high) | ~np.isfinite(stamps)
    if np.any(outside):
        bad = float(stamps[np.flatnonzero(outside)[0]])
        raise CalibrationError(
            f"{int(np.count_nonzero(outside))} of {stamps.size} relation stamps lie outside the log's span "
            f"{t[0]:.3f}-{t[-1]:.3f} s (first: {bad:.3f} s): the relations are not this log's"
        )
    first, _, near1 = nearest_indices(t, relations.t1, tolerance)
    second, _, near2 = nearest_indices(t, relations.t2, tolerance)
    if not np.any(near1 & near2 & (first != second)):
        raise CalibrationError(
            f"no relation has both stamps within {tolerance:g} s of two frames of the log: the relations are not this log's"
        )


@njit(cache=True, nogil=True)
def _chunk_bounds(abs_length, abs_turn, max_length, max_turn):  # pragma: no cover - compiled
    """Frame indices where chunks start, from 0 to ``T - 1`` (``abs_*`` ``[T - 1]`` per step)."""
    n = abs_length.shape[0]
    out = np.empty(n + 2, dtype=np.int64)
    out[0] = 0
    count = 1
    travel = 0.0
    turn = 0.0
    for k in range(n):
        travel += abs_length[k]
        turn += abs_turn[k]
        if travel >= max_length or turn >= max_turn:
            out[count] = k + 1
            count += 1
            travel = 0.0
            turn = 0.0
    if out[count - 1] != n:
        out[count] = n
        count += 1
    return out[:count]


def motion_chunks(
    odo_length: NDArray[np.float64], odo_turn: NDArray[np.float64], settings: CalibrationSettings
) -> NDArray[np.int64]:
    """int64 ``[C + 1]`` frame bounds of the chunks the true motion is measured over: a chunk ends after
    ``chunk_distance`` metres or ``chunk_turn`` radians of odometry travel (``odo_*`` ``[T - 1]`` per step)."""
    return _chunk_bounds(
        np.ascontiguousarray(np.abs(odo_length)),
        np.ascontiguousarray(np.abs(odo_turn)),
        float(settings.chunk_distance),
        float(settings.chunk_turn),
    )


def step_magnitudes(
    odo_length: NDArray[np.float64],
    odo_turn: NDArray[np.float64],
    bounds: NDArray[np.int64],
    bias_lin: float,
    bias_ang: float,
    lin: list[float] | None = None,
    ang: list[float] | None = None,
    previous: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Estimated true ``|L|`` (m) and ``|phi|`` (rad) of every step, float64 ``[T - 1]`` each.

    Per chunk (``bounds``, :func:`motion_chunks`) the net measured motion ``m`` (unbiased: over ``1 + e``)
    is corrected for the noise it holds, ``sqrt(max(m^2 - s^2, 0))``, ``s^2`` the noise variance the
    fitted coefficients ``lin = [k_L, a^2, b^2]``, ``ang = [k_phi, c^2, d^2]`` give for the chunk's motion
    in ``previous`` (the last estimate; without coefficients there is no correction), and shared among the
    chunk's steps in proportion to their measured size.
    """
    length = odo_length / (1.0 + bias_lin)
    turn = odo_turn / (1.0 + bias_ang)

    def chunk(values: NDArray[np.float64]) -> NDArray[np.float64]:
        cum = np.concatenate(([0.0], np.cumsum(values)))
        return cum[bounds[1:]] - cum[bounds[:-1]]

    net_l, net_t = np.abs(chunk(length)), np.abs(chunk(turn))
    if lin is not None and ang is not None and previous is not None:
        d, r = chunk(previous[0]), chunk(previous[1])
        var_l = (lin[1] * d + lin[2] * r) / (1.0 + bias_lin) ** 2
        var_t = (ang[1] * r + ang[2] * d) / (1.0 + bias_ang) ** 2
        net_l = np.sqrt(np.maximum(net_l * net_l - var_l, 0.0))
        net_t = np.sqrt(np.maximum(net_t * net_t - var_t, 0.0))
    size_l, size_t = chunk(np.abs(length)), chunk(np.abs(turn))
    which = np.repeat(np.arange(bounds.size - 1), np.diff(bounds))
    share_l = np.abs(length) / np.where(size_l > 0.0, size_l, 1.0)[which]
    share_t = np.abs(turn) / np.where(size_t > 0.0, size_t, 1.0)[which]
    return net_l[which] * share_l, net_t[which] * share_t


def direction_conflicts(steps: StepMotion, anchors: NDArray[np.int64], min_step: float) -> NDArray[np.bool_]:
    """``[A - 1]``: anchor-to-anchor segments where the odometry and the reference move in opposite directions
    (:func:`segment_conflicts` of :func:`slam_segments`)."""
    return segment_conflicts(slam_segments(steps, anchors), min_step)


def segment_conflicts(segments: Segments, min_step: float) -> NDArray[np.bool_]:
    """``[S]``: segments where the odometry and the reference move in opposite directions.

    A segment is a conflict when its odometry arc length and its reference arc length have opposite signs
    and both are at least ``min_step`` (m) long. No odometry noise model turns driving backwards into
    driving forwards: this is a recording defect (fr079 logs reversing as driving forward,
    docs/real-datasets.md), and a fit that kept it would read it as huge noise per metre and per radian.
    """
    a, b = segments.ref_length, segments.odo_length
    return (a * b < 0.0) & (np.abs(a) >= min_step) & (np.abs(b) >= min_step)


def _window_starts(chain: NDArray[np.int64], w: int, stride: int) -> NDArray[np.int64]:
    """Start segments ``[N]`` of the windows of ``w`` consecutive segments of one chain, one every
    ``stride`` segments from each chain's first."""
    n = chain.size
    if n < w:
        return np.zeros(0, dtype=np.int64)
    index = np.arange(n)
    new = np.concatenate(([True], chain[1:] != chain[:-1]))
    chain_first = np.maximum.accumulate(np.where(new, index, 0))
    starts = index[((index - chain_first) % stride == 0) & (index + w <= n)]
    return starts[chain[starts + w - 1] == chain[starts]].astype(np.int64)


def _wsum(values: NDArray[np.float64], starts: NDArray[np.int64], w: int) -> NDArray[np.float64]:
    cum = np.concatenate(([0.0], np.cumsum(values)))
    return cum[starts + w] - cum[starts]


@dataclass(frozen=True, eq=False)
class OdometryWindows:
    """Per window length (float64 ``[W]`` arrays, the non-overlapping windows of the noise fit).

    Attributes
    ----------
    frames:
        Window length (segments).
    count:
        Windows used (after the outliers are taken out).
    distance:
        Mean absolute reference distance per window (m).
    rotation:
        Mean absolute reference rotation per window (rad).
    rms_linear, rms_angular:
        RMS arc-length (m) and heading (rad) errors after the bias, outliers out.
    fit_linear, fit_angular:
        The fitted model's RMS for the same windows, the constant ``k`` included.
    raw_angular:
        RMS heading error with the bias left in (rad), outliers out.
    outliers:
        Windows beyond ``outlier_sigmas`` in heading or arc length.
    """

    frames: NDArray[np.float64]
    count: NDArray[np.float64]
    distance: NDArray[np.float64]
    rotation: NDArray[np.float64]
    rms_linear: NDArray[np.float64]
    rms_angular: NDArray[np.float64]
    fit_linear: NDArray[np.float64]
    fit_angular: NDArray[np.float64]
    raw_angular: NDArray[np.float64]
    outliers: NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class OdometryFit:
    """The odometry's fitted values (:data:`ODOMETRY_VALUES`) and the figures behind them.

    Attributes
    ----------
    values:
        Name -> value; the noise coefficients in profile units (m/sqrt(m), m/sqrt(rad), rad/sqrt(rad),
        rad/sqrt(m)), which do not depend on any step length.
    source:
        ``"relations"`` (fitted against benchmark relations) or ``"slam"`` (against a SLAM path).
    reference_linear, reference_angular:
        The constants ``k_L`` (m^2) and ``k_phi`` (rad^2): error variance at a window's two ends that does
        not grow with the window (the SLAM path's own error; against relations, the odometry's timing).
    log_step:
        Median time between frames (s), for the record: the fit does not use it.
    distance, rotation:
        The segments' total absolute distance (m) and rotation (rad) by the reference.
    anchors:
        Segments plus one (SLAM path: the frames windows run between, :func:`anchor_frames`).
    heavy_tail:
        Single segments whose error is beyond ``outlier_sigmas`` predicted sigmas (slip candidates, or
        reference errors).
    conflicts:
        Segments where the odometry and the reference travel in opposite directions
        (:func:`segment_conflicts`); every window holding one is left out of the fit.
    conflict_distance:
        The reference's absolute arc length over those segments (m).
    conflict_neighbours:
        Segments next to a conflict (in its chain) left out with it: a reversal starts and ends inside them.
    excluded_windows:
        Non-overlapping windows (all lengths) left out for holding a conflict.
    relations:
        How the relations were used (None for a SLAM path).
    windows:
        The per-length table.
    """

    values: dict[str, float]
    source: str
    reference_linear: float
    reference_angular: float
    log_step: float
    distance: float
    rotation: float
    anchors: int
    heavy_tail: int
    conflicts: int
    conflict_distance: float
    conflict_neighbours: int
    excluded_windows: int
    relations: RelationUse | None
    windows: OdometryWindows


def _slope(error: NDArray[np.float64], motion: NDArray[np.float64], weight: NDArray[np.float64]) -> float:
    x = least_squares([motion], error, weight)
    return 0.0 if x is None else x[0]


def _noise_fit(
    error: NDArray[np.float64],
    constant: NDArray[np.float64],
    main: NDArray[np.float64],
    cross: NDArray[np.float64],
    weight: NDArray[np.float64],
    scale: NDArray[np.float64],
    cut: float,
) -> tuple[list[float], NDArray[np.bool_]]:
    """NNLS of ``error^2`` on ``[constant, main, cross]``, reweighted by the predicted variance; outliers out.

    Reweighting runs first with every window until the coefficients settle (a fit that trims while it is
    still wrong can trim the very windows that would correct it), then with the windows within ``cut``
    predicted sigmas. For the weights every coefficient is held at least at the value that alone would
    explain 1 % of the squared errors, so no window's predicted variance drops to zero when a
    coefficient does (which makes the reweighting jump between solutions).
    """
    target = error * error
    columns = [constant, main, cross]
    floors = [0.01 * float(np.sum(weight * target)) / max(float(np.sum(weight * c)), 1e-300) for c in columns]
    keep = np.ones(target.size, dtype=bool)
    coef = nonnegative_least_squares(columns, target, weight / (scale * scale))
    trimming = False
    for _ in range(60):
        predicted = np.zeros_like(target)
        for x, f, c in zip(coef, floors, columns):
            predicted = predicted + max(x, f) * c
        if trimming:
            keep = target < cut * cut * (coef[0] * constant + coef[1] * main + coef[2] * cross)
        previous = coef
        coef = nonnegative_least_squares(
            [c[keep] for c in columns], target[keep], weight[keep] / (predicted[keep] * predicted[keep])
        )
        change = max(abs(a - b) / max(abs(a), abs(b), 1e-300) for a, b in zip(coef, previous))
        if change < 1e-6:
            if trimming:
                break
            trimming = True
    return coef, keep


def fit_segments(
    segments: Segments,
    odo_length: NDArray[np.float64],
    odo_turn: NDArray[np.float64],
    settings: CalibrationSettings,
    *,
    source: str,
    log_step: float,
    frame_weight: NDArray[np.float64] | None = None,
    chunks: NDArray[np.int64] | None = None,
    relations: RelationUse | None = None,
) -> OdometryFit | None:
    """Fit biases and noise over windows of consecutive ``segments``.

    Parameters
    ----------
    segments:
        The segments (:func:`slam_segments` or :func:`relation_segments`).
    odo_length, odo_turn:
        float64 ``[T - 1]`` the odometry's per-step arcs (m, rad), for the motion of every window.
    settings:
        Window lengths, outlier cut, conflict threshold, chunk sizes.
    source:
        ``"relations"`` or ``"slam"``: what the segments were measured against (reported).
    log_step:
        Median time between frames (s), reported only.
    frame_weight:
        float64 ``[T]`` weight of each window by its first frame (bootstrap multiplicities); None: 1.
    chunks:
        :func:`motion_chunks` of the odometry (computed when None).
    relations:
        Reported with the fit.

    Windows holding a direction conflict (:func:`segment_conflicts`) are left out. Window lengths with
    fewer than four clean windows are left out; None when fewer than three lengths are left.
    """
    n = len(segments)
    conflicts = segment_conflicts(segments, settings.direction_min_step)
    # a reversal starts and ends inside the segments next to its first and last conflicting one, which
    # hold both directions (their net motion need not be reversed): they are left out too
    excluded = conflicts.copy()
    same_chain = segments.chain[1:] == segments.chain[:-1]
    excluded[1:] |= conflicts[:-1] & same_chain
    excluded[:-1] |= conflicts[1:] & same_chain
    conflict_count = np.concatenate(([0], np.cumsum(excluded.astype(np.int64))))

    def clean_starts(w: int, stride: int) -> tuple[NDArray[np.int64], int]:
        starts = _window_starts(segments.chain, w, stride)
        ok = conflict_count[starts + w] - conflict_count[starts] == 0
        return starts[ok], int(np.count_nonzero(~ok))

    clean = {w: clean_starts(w, w) for w in settings.windows if n >= w}
    lengths = [w for w in clean if clean[w][0].size >= 4]  # at least four windows of each length
    if len(lengths) < 3:
        return None
    weight_of = np.ones(int(segments.last.max()) + 1) if frame_weight is None else frame_weight
    mid = lengths[len(lengths) // 2]
    overlapping, _ = clean_starts(mid, 1)
    wb = weight_of[segments.first[overlapping]]
    ref_l, ref_t = _wsum(segments.ref_length, overlapping, mid), _wsum(segments.ref_turn, overlapping, mid)
    bias_lin = _slope(_wsum(segments.odo_length, overlapping, mid) - ref_l, ref_l, wb)
    bias_ang = _slope(_wsum(segments.odo_turn, overlapping, mid) - ref_t, ref_t, wb)
    bounds = motion_chunks(odo_length, odo_turn, settings) if chunks is None else chunks

    def motion(magnitudes: tuple[NDArray[np.float64], NDArray[np.float64]]):
        cum_l = np.concatenate(([0.0], np.cumsum(magnitudes[0])))
        cum_t = np.concatenate(([0.0], np.cumsum(magnitudes[1])))
        seg_d = cum_l[segments.last] - cum_l[segments.first]
        seg_r = cum_t[segments.last] - cum_t[segments.first]
        return (
            np.concatenate([_wsum(seg_d, clean[w][0], w) for w in lengths]),
            np.concatenate([_wsum(seg_r, clean[w][0], w) for w in lengths]),
        )

    parts: dict[str, list[NDArray[np.float64]]] = {k: [] for k in ("el", "ea", "w", "len", "l", "t", "raw")}
    for w in lengths:
        starts = clean[w][0]
        ref_l, ref_t = _wsum(segments.ref_length, starts, w), _wsum(segments.ref_turn, starts, w)
        parts["el"].append(_wsum(segments.odo_length, starts, w) - (1.0 + bias_lin) * ref_l)
        parts["ea"].append(_wsum(segments.odo_turn, starts, w) - (1.0 + bias_ang) * ref_t)
        parts["raw"].append(_wsum(segments.odo_turn, starts, w) - ref_t)
        parts["w"].append(weight_of[segments.first[starts]])
        parts["len"].append(np.full(starts.size, float(w)))
        parts["l"].append(np.abs(ref_l))
        parts["t"].append(np.abs(ref_t))
    cat = {k: np.concatenate(v) for k, v in parts.items()}
    constant = np.ones_like(cat["len"])
    # every window length weighs the same in all: the short windows, which are many, must not decide alone
    per_length = {float(w): float(np.sum(cat["w"][cat["len"] == w])) for w in lengths}
    cat["w"] = cat["w"] / np.array([max(per_length[v], 1e-300) for v in cat["len"].tolist()])
    cut = settings.outlier_sigmas
    magnitudes = step_magnitudes(odo_length, odo_turn, bounds, bias_lin, bias_ang)
    dist, rot = motion(magnitudes)
    lin, keep_l = _noise_fit(cat["el"], constant, dist, rot, cat["w"], cat["len"], cut)
    ang, keep_a = _noise_fit(cat["ea"], constant, rot, dist, cat["w"], cat["len"], cut)
    for _ in range(3):  # the true motion without the fitted noise's share, and the fits again
        magnitudes = step_magnitudes(odo_length, odo_turn, bounds, bias_lin, bias_ang, lin, ang, magnitudes)
        dist, rot = motion(magnitudes)
        lin, keep_l = _noise_fit(cat["el"], constant, dist, rot, cat["w"], cat["len"], cut)
        ang, keep_a = _noise_fit(cat["ea"], constant, rot, dist, cat["w"], cat["len"], cut)
    values = {
        "bias_linear": bias_lin,
        "bias_angular": bias_ang,
        "noise_linear_per_m": math.sqrt(lin[1]),
        "noise_linear_per_rad": math.sqrt(lin[2]),
        "noise_angular_per_rad": math.sqrt(ang[1]),
        "noise_angular_per_m": math.sqrt(ang[2]),
    }
    pred_l = lin[0] * constant + lin[1] * dist + lin[2] * rot
    pred_a = ang[0] * constant + ang[1] * rot + ang[2] * dist
    rows = []
    for w in lengths:
        sel = cat["len"] == w
        both = sel & keep_l & keep_a
        rows.append(
            (
                float(w),
                float(np.count_nonzero(both)),
                float(np.mean(cat["l"][sel])),
                float(np.mean(cat["t"][sel])),
                float(np.sqrt(np.mean(cat["el"][both] ** 2))),
                float(np.sqrt(np.mean(cat["ea"][both] ** 2))),
                float(np.sqrt(np.mean(pred_l[both]))),
                float(np.sqrt(np.mean(pred_a[both]))),
                float(np.sqrt(np.mean(cat["raw"][both] ** 2))),
                float(np.count_nonzero(sel & ~(keep_l & keep_a))),
            )
        )
    table = np.array(rows)
    single = cat["len"] == lengths[0]
    return OdometryFit(
        values=values,
        source=source,
        reference_linear=lin[0],
        reference_angular=ang[0],
        log_step=log_step,
        distance=float(np.sum(np.abs(segments.ref_length))),
        rotation=float(np.sum(np.abs(segments.ref_turn))),
        anchors=n + 1,
        heavy_tail=int(np.count_nonzero(single & ~(keep_l & keep_a))),
        conflicts=int(np.count_nonzero(conflicts)),
        conflict_distance=float(np.sum(np.abs(segments.ref_length)[conflicts])),
        conflict_neighbours=int(np.count_nonzero(excluded & ~conflicts)),
        excluded_windows=int(sum(clean[w][1] for w in lengths)),
        relations=relations,
        windows=OdometryWindows(*(table[:, i].copy() for i in range(table.shape[1]))),
    )


def fit_odometry(
    steps: StepMotion,
    anchors: NDArray[np.int64],
    settings: CalibrationSettings,
    log_step: float,
    frame_weight: NDArray[np.float64] | None = None,
) -> OdometryFit | None:
    """Fit biases and noise against a SLAM reference path: :func:`fit_segments` of :func:`slam_segments`
    (``anchors`` from :func:`anchor_frames`)."""
    return fit_segments(
        slam_segments(steps, anchors),
        steps.odo_length,
        steps.odo_turn,
        settings,
        source="slam",
        log_step=log_step,
        frame_weight=frame_weight,
    )
