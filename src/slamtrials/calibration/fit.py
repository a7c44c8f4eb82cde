"""The calibration: laser and odometry fits against a reference, their bootstrap uncertainty, the profile.

The uncertainty of every value is the standard deviation over ``bootstrap`` replicates that resample
blocks of ``block_frames`` consecutive frames with replacement (neighbouring scans see the same clutter
and neighbouring odometry steps share their errors, so single beams or steps are not independent). Every
draw comes from the given seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.calibration.beams import BeamSample, beam_sample
from slamtrials.calibration.laser import LASER_VALUES, LaserFit, fit_laser
from slamtrials.calibration.lifetime import LifetimeFit, fit_lifetime, model_laser_values
from slamtrials.calibration.model_config import fitted_laser_config
from slamtrials.calibration.odometry import (
    ODOMETRY_VALUES,
    OdometryFit,
    anchor_frames,
    check_relations_belong,
    fit_segments,
    motion_chunks,
    relation_segments,
    slam_segments,
    step_motion,
)
from slamtrials.calibration.reference import Reference, check_calibratable
from slamtrials.calibration.settings import CalibrationSettings
from slamtrials.errors import CalibrationError
from slamtrials.record import LaserGeometry, Relations, RunRecord
from slamtrials.sim.config import ErrorProfile
from slamtrials.sim.laser_errors import apply_laser_errors

__all__ = ["Calibration", "calibrate", "FittedValue"]


@dataclass(frozen=True)
class FittedValue:
    """One fitted value and its bootstrap standard error (profile units)."""

    name: str
    value: float
    stderr: float
    unit: str


_UNITS = {
    "range_noise_std": "m",
    "range_noise_per_m": "m/m",
    "short_rate": "",
    "short_run_beams": "beams",
    "short_position_power": "",
    "short_range_scale": "m",
    "short_range_shape": "",
    "dropout_rate": "",
    "dropout_per_m": "1/m",
    "dropout_grazing": "",
    "edge_chance": "",
    "edge_reach": "rad",
    "short_lifetime": "s",
    "short_fleeting_share": "",
    "bias_linear": "m/m",
    "bias_angular": "rad/rad",
    "noise_linear_per_m": "m/sqrt(m)",
    "noise_linear_per_rad": "m/sqrt(rad)",
    "noise_angular_per_rad": "rad/sqrt(rad)",
    "noise_angular_per_m": "rad/sqrt(m)",
}


@dataclass(frozen=True, eq=False)
class Calibration:
    """What :func:`calibrate` found.

    Attributes
    ----------
    laser:
        The laser fit on all beams.
    odometry:
        The odometry fit on all steps.
    lifetime:
        The fit of the short readings' lifetime; None when it could not be fitted (too few short readings).
    fitted:
        Every value of :data:`LASER_VALUES`, ``short_lifetime`` and ``short_fleeting_share`` (0 when not
        fitted), then :data:`ODOMETRY_VALUES`, with its standard error.
    reference:
        What the reference is (the laser's: a SLAM path and map, or a known world).
    odometry_reference:
        What the odometry was fitted against: the benchmark relations (``"N benchmark relations of
        FILE"``), else the same as ``reference``.
    frames:
        Frames of the log.
    residuals:
        float64 ``[N]`` the kept beams' residuals (reading - cast, m).
    model_residuals:
        float64 ``[N]`` residuals of readings drawn by the simulator's laser model with the fitted values
        for the same cast ranges (the "fitted" side of real-versus-fitted).
    no_return_range:
        float64 ``[N]`` cast range of each kept beam (m), and ``no_return`` / ``model_no_return`` bool
        ``[N]``: whether the real and the modelled reading returned nothing.
    bootstrap:
        Replicates used.
    laser_frames:
        Frames whose beams were cast (every ``frame_step``-th, to stay within ``max_beams``).
    """

    laser: LaserFit
    odometry: OdometryFit
    lifetime: LifetimeFit | None
    fitted: tuple[FittedValue, ...]
    reference: str
    frames: int
    residuals: NDArray[np.float64]
    model_residuals: NDArray[np.float64]
    no_return_range: NDArray[np.float64]
    no_return: NDArray[np.bool_]
    model_no_return: NDArray[np.bool_]
    bootstrap: int
    laser_frames: int = 0
    odometry_reference: str = ""

    def value(self, name: str) -> FittedValue:
        """The fitted value called ``name``."""
        for item in self.fitted:
            if item.name == name:
                return item
        raise KeyError(name)

    def profile(self, name: str, description: str) -> ErrorProfile:
        """The error profile: the fitted laser values, the biases as symmetric ranges of their measured
        magnitude (one log is one draw of the per-run bias), the noise coefficients; no slips."""
        laser: dict[str, float] = model_laser_values(self.laser)
        lifetime = self.value("short_lifetime").value if laser["short_rate"] > 0.0 else 0.0
        laser["short_lifetime"] = lifetime
        laser["short_fleeting_share"] = min(self.value("short_fleeting_share").value, 0.99) if lifetime > 0.0 else 0.0
        lin = min(abs(self.value("bias_linear").value), 0.49)
        ang = min(abs(self.value("bias_angular").value), 0.49)
        odometry: dict[str, object] = {"bias_linear_range": (-lin, lin), "bias_angular_range": (-ang, ang)}
        for key in ("noise_linear_per_m", "noise_linear_per_rad", "noise_angular_per_rad", "noise_angular_per_m"):
            odometry[key] = float(min(self.value(key).value, 1.0))
        return ErrorProfile(name=name, description=description, laser=laser, odometry=odometry)


def _block_index(frames: NDArray[np.int64], block: int, rng: np.random.Generator, blocks: int) -> NDArray[np.int64]:
    """Indices of a block-bootstrap resample of items whose (sorted) frame numbers are ``frames``."""
    ids = frames // block
    starts = np.searchsorted(ids, np.arange(blocks), side="left")
    ends = np.searchsorted(ids, np.arange(blocks), side="right")
    chosen = rng.integers(0, blocks, size=blocks)
    return np.concatenate([np.arange(starts[b], ends[b]) for b in chosen])


def _laser_model(sample: BeamSample, fit: LaserFit, laser: LaserGeometry, rng: np.random.Generator):
    config = fitted_laser_config(laser, fit.values)
    readings = apply_laser_errors(
        sample.cast.astype(np.float32), config, rng, sample.incidence, nearer=sample.nearer
    ).astype(np.float64)
    return readings - sample.cast, readings >= np.float32(config.max_range)


def calibrate(
    record: RunRecord,
    reference: Reference,
    settings: CalibrationSettings | None = None,
    *,
    seed: int = 0,
    relations: Relations | None = None,
    relations_source: str = "relations",
) -> Calibration:
    """Fit the laser and odometry error models of ``record`` against ``reference``.

    With ``relations`` (the log's benchmark relations, human-checked relative poses) the odometry is
    fitted against them instead of the reference path (:func:`~slamtrials.calibration.odometry.relation_segments`),
    independent of any SLAM run; the laser is fitted against ``reference`` either way.
    ``relations_source`` names them in :attr:`Calibration.odometry_reference`.

    Raises
    ------
    CalibrationError
        The log is too short, too irregular or has no odometry, the reference does not hold one pose per
        frame, the relations are not the log's, or too few beams hit a mapped wall to fit the laser, or
        too few segments are left for the odometry fit.
    """
    cfg = settings or CalibrationSettings()
    check_calibratable(
        record,
        min_frames=cfg.min_frames,
        min_distance=cfg.min_distance,
        min_rotation=cfg.min_rotation,
        min_gap=cfg.min_gap,
        max_tiny_share=cfg.min_step_share,
    )
    if relations is not None:
        check_relations_belong(record.t, relations, cfg.relation_tolerance)
    if reference.poses.shape != (len(record), 3):
        raise CalibrationError(
            f"the reference holds {reference.poses.shape[0]} poses for {len(record)} frames; it needs one per frame"
        )
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    anchors = anchor_frames(reference.poses, record.odometry)
    sample = beam_sample(
        record, reference, cfg.max_beams, anchors if cfg.laser_anchors_only else None, edge_reach=cfg.edge_reach
    )
    laser = fit_laser(sample, cfg, record.laser.range_min)
    if laser is None:
        raise CalibrationError(
            f"only {sample.cast.size} beams hit a wall of the reference map through known free space; "
            f"the laser fit needs at least {cfg.min_bin_beams} returned beams in each of two range bins"
        )
    steps = step_motion(reference.poses, record.odometry)
    log_step = float(np.median(np.diff(record.t)))
    use = None
    if relations is None:
        segments = slam_segments(steps, anchors)
        source, odometry_reference = "slam", reference.source
    else:
        segments, use = relation_segments(record.t, record.odometry, relations, cfg)
        source = "relations"
        odometry_reference = f"{use.used} benchmark relations of {relations_source}"
    chunks = motion_chunks(steps.odo_length, steps.odo_turn, cfg)

    def fit_odo(weight: NDArray[np.float64] | None) -> OdometryFit | None:
        return fit_segments(
            segments,
            steps.odo_length,
            steps.odo_turn,
            cfg,
            source=source,
            log_step=log_step,
            frame_weight=weight,
            chunks=chunks,
            relations=use,
        )

    odometry = fit_odo(None)
    if odometry is None:
        what = (
            f"the reference has {anchors.size} frames that are more than odometry carried on"
            if use is None
            else f"{use.used} of the {use.total} relations are short ones on two frames of the log ({use.chains} chains)"
        )
        raise CalibrationError(
            f"{what}; the odometry fit needs windows of at least three lengths of {cfg.windows}, four of each"
        )
    frames = len(record)
    blocks = math.ceil(frames / cfg.block_frames)
    frame_blocks = np.arange(frames) // cfg.block_frames
    laser_draws, odo_draws = [], []
    for _ in range(cfg.bootstrap):
        index = _block_index(sample.frame, cfg.block_frames, rng, blocks)
        again = fit_laser(sample.take(index), cfg, record.laser.range_min)
        if again is not None:
            laser_draws.append([again.values[k] for k in LASER_VALUES])
        counts = np.bincount(rng.integers(0, blocks, size=blocks), minlength=blocks).astype(np.float64)
        refit = fit_odo(counts[frame_blocks])
        if refit is not None:
            odo_draws.append([refit.values[k] for k in ODOMETRY_VALUES])
    laser_se = (
        np.std(np.array(laser_draws), axis=0, ddof=1) if len(laser_draws) > 1 else np.full(len(LASER_VALUES), math.nan)
    )
    laser_se[LASER_VALUES.index("edge_reach")] = 0.0  # a setting, not fitted: the same in every replicate
    odo_se = np.std(np.array(odo_draws), axis=0, ddof=1) if len(odo_draws) > 1 else np.full(6, math.nan)
    lifetime = fit_lifetime(record, reference, laser, cfg, seed=seed)
    lifetime_values = (
        (
            FittedValue("short_lifetime", lifetime.lifetime, lifetime.stderr, "s"),
            FittedValue("short_fleeting_share", lifetime.fleeting, lifetime.fleeting_stderr, ""),
        )
        if lifetime is not None
        else (FittedValue("short_lifetime", 0.0, math.nan, "s"), FittedValue("short_fleeting_share", 0.0, math.nan, ""))
    )
    fitted = (
        tuple(FittedValue(k, float(laser.values[k]), float(se), _UNITS[k]) for k, se in zip(LASER_VALUES, laser_se))
        + lifetime_values
        + tuple(
            FittedValue(k, float(odometry.values[k]), float(se), _UNITS[k]) for k, se in zip(ODOMETRY_VALUES, odo_se)
        )
    )
    model_e, model_drop = _laser_model(sample, laser, record.laser, rng)
    return Calibration(
        laser=laser,
        odometry=odometry,
        lifetime=lifetime,
        fitted=fitted,
        reference=reference.source,
        frames=frames,
        residuals=sample.reading - sample.cast,
        model_residuals=model_e,
        no_return_range=sample.cast,
        no_return=sample.no_return,
        model_no_return=model_drop,
        bootstrap=cfg.bootstrap,
        laser_frames=sample.frames_used,
        odometry_reference=odometry_reference,
    )
