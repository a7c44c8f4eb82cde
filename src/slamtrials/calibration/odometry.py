"""The odometry fit: scale biases and per-step noise from odometry increments against the reference's.

Each frame-to-frame step ``j`` is read as an arc, for the reference and for the odometry alike: heading
change ``phi_j`` and signed arc length ``L_j = (dx cos(phi/2) + dy sin(phi/2)) / sinc(phi/2)`` (the
chord's projection on the arc's mean heading: negative when driving backwards), which is exactly what the
simulator's odometry model scales and perturbs (:mod:`slamtrials.sim.odometry`). Over a window of ``w``
steps the model's errors add up:

    E_phi = sum phi'_j - (1 + e_ang) sum phi_j,    var = c^2 sum phi_j^2 + d^2 sum L_j^2 (+ k_phi)
    E_L   = sum L'_j  - (1 + e_lin) sum L_j,       var = a^2 sum L_j^2 + b^2 sum phi_j^2 (+ k_L)

with ``a, b, c, d`` the profile's ``noise_linear_per_m``, ``noise_linear_per_rad``,
``noise_angular_per_rad``, ``noise_angular_per_m``. The biases ``e_lin``, ``e_ang`` are the least-squares
slopes of the window errors on the reference's window motion (overlapping windows of the middle length);
the noise coefficients are the non-negative least-squares fit of the squared window errors (bias removed)
on the window's sums of squared step motions (the odometry's, with the fitted noise's share taken out
and refitted, :func:`_without_noise`), over non-overlapping windows of every length, weighted by
the inverse squared predicted variance and refitted without windows beyond ``outlier_sigmas``. The
constant ``k`` takes the reference's own pose error, which does not grow with the window: that is what
several window lengths separate. The per-step coefficients hold for the log's step; the simulator's step
of ``sim_dt`` seconds needs them times ``sqrt(log step / sim_dt)`` (the same path in shorter steps has
smaller squared step motions, summing to ``sim_dt / log step`` times as much).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials import stablemath
from slamtrials.calibration.settings import CalibrationSettings
from slamtrials.calibration.stats import least_squares, nonnegative_least_squares
from slamtrials.geometry import ominus

__all__ = [
    "StepMotion",
    "step_motion",
    "anchor_frames",
    "direction_conflicts",
    "OdometryFit",
    "OdometryWindows",
    "fit_odometry",
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


def _arcs(poses: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    d = ominus(poses[:-1], poses[1:])
    half = 0.5 * d[:, 2]
    small = np.abs(half) < 1e-3
    safe = np.where(small, 1.0, half)
    sinc = np.where(small, 1.0 - half * half / 6.0, stablemath.sin(safe) / safe)
    length = (d[:, 0] * stablemath.cos(half) + d[:, 1] * stablemath.sin(half)) / sinc
    return length, d[:, 2]


def step_motion(reference: NDArray[np.float64], odometry: NDArray[np.float64]) -> StepMotion:
    """The steps of a reference path and of the odometry (both ``[T, 3]``)."""
    length, turn = _arcs(reference)
    odo_length, odo_turn = _arcs(odometry)
    return StepMotion(length, turn, odo_length, odo_turn)


@dataclass(frozen=True, eq=False)
class OdometryWindows:
    """Per window length (float64 ``[W]`` arrays, the non-overlapping windows of the noise fit).

    Attributes
    ----------
    frames:
        Window length (frames).
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
        Name -> value; the noise coefficients are for steps of ``sim_dt``.
    reference_linear, reference_angular:
        The constants ``k_L`` (m^2) and ``k_phi`` (rad^2): window error variance that does not grow
        with the window (the reference's own error at the window's two ends).
    step_scale:
        ``sqrt(log step / sim_dt)``, the factor applied to the log-step coefficients.
    log_step:
        Median time between frames (s).
    distance, rotation:
        The reference path's total distance (m) and absolute rotation (rad).
    anchors:
        Frames the windows run between (:func:`anchor_frames`).
    heavy_tail:
        Single segments whose heading error is beyond ``outlier_sigmas`` predicted sigmas (slip candidates).
    conflicts:
        Segments where the odometry and the reference travel in opposite directions
        (:func:`direction_conflicts`); every window holding one is left out of the fit.
    conflict_distance:
        The reference's absolute arc length over those segments (m).
    windows:
        The per-length table.
    """

    values: dict[str, float]
    reference_linear: float
    reference_angular: float
    step_scale: float
    log_step: float
    distance: float
    rotation: float
    anchors: int
    heavy_tail: int
    conflicts: int
    conflict_distance: float
    windows: OdometryWindows


def _sums(values: NDArray[np.float64], anchors: NDArray[np.int64], w: int, stride: int) -> NDArray[np.float64]:
    """Sums of the per-step ``values`` ``[T - 1]`` over windows of ``w`` anchor-to-anchor segments
    (windows start every ``stride`` segments); ``anchors`` ``[A]`` are frame indices."""
    cum = np.concatenate(([0.0], np.cumsum(values)))[anchors]
    starts = np.arange(0, anchors.size - w, stride)
    return cum[starts + w] - cum[starts]


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


def direction_conflicts(steps: StepMotion, anchors: NDArray[np.int64], min_step: float) -> NDArray[np.bool_]:
    """``[A - 1]``: anchor-to-anchor segments where the odometry and the reference move in opposite directions.

    A segment is a conflict when its odometry arc length and its reference arc length have opposite signs
    and both are at least ``min_step`` (m) long. No odometry noise model turns driving backwards into
    driving forwards: this is a recording defect (fr079 logs reversing as driving forward,
    docs/real-datasets.md), and a fit that kept it would read it as huge noise per metre and per radian.
    """
    length = _sums(steps.length, anchors, 1, 1)
    odo_length = _sums(steps.odo_length, anchors, 1, 1)
    return (length * odo_length < 0.0) & (np.abs(length) >= min_step) & (np.abs(odo_length) >= min_step)


def _clean_windows(conflicts: NDArray[np.bool_], w: int, stride: int) -> NDArray[np.bool_]:
    """Which windows of ``w`` segments (starting every ``stride``, as :func:`_sums`) hold no conflict."""
    cum = np.concatenate(([0], np.cumsum(conflicts.astype(np.int64))))
    starts = np.arange(0, conflicts.size + 1 - w, stride)
    return cum[starts + w] - cum[starts] == 0


def _slope(error: NDArray[np.float64], motion: NDArray[np.float64], weight: NDArray[np.float64]) -> float:
    x = least_squares([motion], error, weight)
    return 0.0 if x is None else x[0]


def _noise_fit(
    error: NDArray[np.float64],
    main: NDArray[np.float64],
    cross: NDArray[np.float64],
    weight: NDArray[np.float64],
    scale: NDArray[np.float64],
    cut: float,
) -> tuple[list[float], NDArray[np.bool_]]:
    """NNLS of ``error^2`` on ``[1, main, cross]``, reweighted by the predicted variance; outliers out.

    Reweighting runs first with every window until the coefficients settle (a fit that trims while it is
    still wrong can trim the very windows that would correct it), then with the windows within ``cut``
    predicted sigmas. For the weights every coefficient is held at least at the value that alone would
    explain 1 % of the squared errors, so no window's predicted variance drops to zero when a
    coefficient does (which makes the reweighting jump between solutions).
    """
    target = error * error
    columns = [np.ones_like(target), main, cross]
    floors = [0.01 * float(np.sum(weight * target)) / max(float(np.sum(weight * c)), 1e-300) for c in columns]
    keep = np.ones(target.size, dtype=bool)
    coef = nonnegative_least_squares(columns, target, weight / scale**2)
    trimming = False
    for _ in range(60):
        predicted = np.zeros_like(target)
        for x, f, c in zip(coef, floors, columns):
            predicted = predicted + max(x, f) * c
        if trimming:
            keep = target < cut * cut * (coef[0] + coef[1] * main + coef[2] * cross)
        previous = coef
        coef = nonnegative_least_squares([c[keep] for c in columns], target[keep], weight[keep] / predicted[keep] ** 2)
        change = max(abs(a - b) / max(abs(a), abs(b), 1e-300) for a, b in zip(coef, previous))
        if change < 1e-6:
            if trimming:
                break
            trimming = True
    return coef, keep


def _without_noise(
    odo_ll: NDArray[np.float64],
    odo_tt: NDArray[np.float64],
    lin: list[float],
    ang: list[float],
    bias_lin: float,
    bias_ang: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The squared step motions ``[T - 1]`` with the fitted noise's share taken out.

    ``odo_ll``, ``odo_tt`` are the odometry's squared steps over ``(1 + e)^2``; each holds its noise's
    variance besides the motion's square: ``L'^2 / (1 + e_lin)^2 = L^2 + (a^2 L^2 + b^2 phi^2) / (1 +
    e_lin)^2`` in expectation, and alike for ``phi``. With a large cross term (fr079's arc length errs by
    half a metre per radian of turning) a turn in place would otherwise look like driving. The two
    equations are solved per step for ``L^2`` and ``phi^2``: unbiased over a window, though a single step
    may come out slightly negative.
    """
    alpha = lin[1] / (1.0 + bias_lin) ** 2
    beta = lin[2] / (1.0 + bias_lin) ** 2
    gamma = ang[1] / (1.0 + bias_ang) ** 2
    delta = ang[2] / (1.0 + bias_ang) ** 2
    det = (1.0 + alpha) * (1.0 + gamma) - beta * delta
    return ((1.0 + gamma) * odo_ll - beta * odo_tt) / det, ((1.0 + alpha) * odo_tt - delta * odo_ll) / det


def fit_odometry(
    steps: StepMotion,
    anchors: NDArray[np.int64],
    settings: CalibrationSettings,
    log_step: float,
    frame_weight: NDArray[np.float64] | None = None,
) -> OdometryFit | None:
    """Fit biases and noise to ``steps`` over windows between ``anchors`` (:func:`anchor_frames`).

    ``frame_weight`` ``[T]`` weighs each window by the weight of its first frame (bootstrap
    multiplicities). Windows that hold a direction conflict (:func:`direction_conflicts`, segments of at
    least ``settings.direction_min_step``) are left out. Window lengths with fewer than four clean windows
    are left out; None when fewer than three lengths are left.
    """
    segments = anchors.size - 1
    conflicts = direction_conflicts(steps, anchors, settings.direction_min_step)
    clean = {w: _clean_windows(conflicts, w, w) for w in settings.windows if segments >= w}
    lengths = [w for w in clean if np.count_nonzero(clean[w]) >= 4]  # at least four windows of each length
    if len(lengths) < 3:
        return None
    weight_of = np.ones(anchors[-1] + 1) if frame_weight is None else frame_weight
    mid = lengths[len(lengths) // 2]
    wb = weight_of[anchors[: segments - mid + 1]] * _clean_windows(conflicts, mid, 1)
    ref_l, ref_t = _sums(steps.length, anchors, mid, 1), _sums(steps.turn, anchors, mid, 1)
    bias_lin = _slope(_sums(steps.odo_length, anchors, mid, 1) - ref_l, ref_l, wb)
    bias_ang = _slope(_sums(steps.odo_turn, anchors, mid, 1) - ref_t, ref_t, wb)
    # squared step motions: the odometry's, unbiased (between anchors the reference is the odometry; at
    # an anchor the reference step holds the SLAM correction, which is no motion)
    step_ll = (steps.odo_length / (1.0 + bias_lin)) ** 2
    step_tt = (steps.odo_turn / (1.0 + bias_ang)) ** 2
    parts: dict[str, list[NDArray[np.float64]]] = {k: [] for k in ("el", "ea", "ll", "tt", "w", "len", "l", "t", "raw")}
    for w in lengths:
        keep = clean[w]
        ref_l, ref_t = _sums(steps.length, anchors, w, w)[keep], _sums(steps.turn, anchors, w, w)[keep]
        parts["el"].append(_sums(steps.odo_length, anchors, w, w)[keep] - (1.0 + bias_lin) * ref_l)
        parts["ea"].append(_sums(steps.odo_turn, anchors, w, w)[keep] - (1.0 + bias_ang) * ref_t)
        parts["raw"].append(_sums(steps.odo_turn, anchors, w, w)[keep] - ref_t)
        parts["ll"].append(_sums(step_ll, anchors, w, w)[keep])
        parts["tt"].append(_sums(step_tt, anchors, w, w)[keep])
        parts["w"].append(weight_of[anchors[np.arange(0, segments - w + 1, w)]][keep])
        parts["len"].append(np.full(ref_l.size, float(w)))
        parts["l"].append(np.abs(ref_l))
        parts["t"].append(np.abs(ref_t))
    cat = {k: np.concatenate(v) for k, v in parts.items()}
    # every window length weighs the same in all: the short windows, which are many, must not decide alone
    per_length = {float(w): float(np.sum(cat["w"][cat["len"] == w])) for w in lengths}
    cat["w"] = cat["w"] / np.array([max(per_length[v], 1e-300) for v in cat["len"].tolist()])
    cut = settings.outlier_sigmas
    lin, keep_l = _noise_fit(cat["el"], cat["ll"], cat["tt"], cat["w"], cat["len"], cut)
    ang, keep_a = _noise_fit(cat["ea"], cat["tt"], cat["ll"], cat["w"], cat["len"], cut)
    for _ in range(3):  # the squared step motions without the fitted noise's share, and the fits again
        clean_ll, clean_tt = _without_noise(step_ll, step_tt, lin, ang, bias_lin, bias_ang)
        cat["ll"] = np.concatenate([_sums(clean_ll, anchors, w, w)[clean[w]] for w in lengths])
        cat["tt"] = np.concatenate([_sums(clean_tt, anchors, w, w)[clean[w]] for w in lengths])
        lin, keep_l = _noise_fit(cat["el"], cat["ll"], cat["tt"], cat["w"], cat["len"], cut)
        ang, keep_a = _noise_fit(cat["ea"], cat["tt"], cat["ll"], cat["w"], cat["len"], cut)
    scale = math.sqrt(log_step / settings.sim_dt)
    values = {
        "bias_linear": bias_lin,
        "bias_angular": bias_ang,
        "noise_linear_per_m": math.sqrt(lin[1]) * scale,
        "noise_linear_per_rad": math.sqrt(lin[2]) * scale,
        "noise_angular_per_rad": math.sqrt(ang[1]) * scale,
        "noise_angular_per_m": math.sqrt(ang[2]) * scale,
    }
    pred_l = lin[0] + lin[1] * cat["ll"] + lin[2] * cat["tt"]
    pred_a = ang[0] + ang[1] * cat["tt"] + ang[2] * cat["ll"]
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
        reference_linear=lin[0],
        reference_angular=ang[0],
        step_scale=scale,
        log_step=log_step,
        distance=float(np.sum(np.abs(steps.length))),
        rotation=float(np.sum(np.abs(steps.turn))),
        anchors=int(anchors.size),
        heavy_tail=int(np.count_nonzero(single & ~keep_a)),
        conflicts=int(np.count_nonzero(conflicts)),
        conflict_distance=float(np.sum(np.abs(_sums(steps.length, anchors, 1, 1))[conflicts])),
        windows=OdometryWindows(*(table[:, i].copy() for i in range(table.shape[1]))),
    )
