"""The calibration's settings (pydantic, frozen): range bins, cut-offs, window lengths, bootstrap."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, field_validator

__all__ = ["CalibrationSettings"]


class CalibrationSettings(BaseModel):
    """How :func:`~slamtrials.calibration.calibrate` fits the error models.

    Attributes
    ----------
    range_bins:
        Edges (m, increasing) of the range bins of the laser fit (by the cast range).
    min_bin_beams:
        Fewest beams a range bin needs to enter the noise and dropout fits.
    core_cut:
        The Gaussian core of a bin's residuals is taken within this many sigmas of its median.
    short_sigmas:
        A reading shorter than the cast range by more than this many sigmas (of its bin) is a short reading.
    edge_reach:
        How far (rad) to either side of a beam a nearer wall is looked for by the edge model
        (:mod:`slamtrials.sim.edges`); written into the profile as ``edge_reach``, not fitted. 1 degree: two
        beams of the shared logs' lasers, where the real readings of nearer walls are most frequent
        (docs/realism.md, "Assumptions").
    position_floor:
        Least gap before the wall (m) of the short readings whose position along the beam fits
        ``short_position_power``; nearer the wall lie the reference map's own errors and what stands
        against the walls, which the power would otherwise follow (docs/realism.md, "Calibration").
    position_min_short:
        Fewest such short readings to fit the power (uniform, 0, below).
    max_beams:
        Cap on the beams used (scans are thinned evenly to stay below it), for speed.
    laser_anchors_only:
        Cast only the frames the reference is more than odometry at (its SLAM updates,
        :func:`~slamtrials.calibration.odometry.anchor_frames`). Off by default: the updates of GMapping
        come when the robot has turned or moved enough, so they over-represent turns (docs/realism.md).
    windows:
        Odometry window lengths in segments between anchor frames (every frame, with a true path; the
        SLAM updates, with a SLAM estimate); windows of each length tile the log without overlap.
    outlier_sigmas:
        An odometry window whose error is beyond this many predicted sigmas is left out of the noise fit
        (and counted as a heavy-tail event).
    direction_min_step:
        Odometry segments where the odometry and the reference move at least this far (m) in opposite
        directions are a recording defect, not noise; every window holding one is left out
        (:func:`~slamtrials.calibration.odometry.direction_conflicts`).
    chunk_distance, chunk_turn:
        The odometry's true motion (the ``D`` and ``R`` the noise grows with) is measured over chunks of
        its path that end after this many metres or radians of travel, where the motion outgrows the
        noise (:func:`~slamtrials.calibration.odometry.step_magnitudes`); GMapping's update distances.
    relation_tolerance:
        Largest gap (s) between a relation's stamp and a frame (the Freiburg evaluator's 0.1 s).
    relation_max_distance, relation_max_turn:
        Relations whose span drives farther (m) or turns more (rad) by the odometry are not used by the
        odometry fit: a span that long (a loop closure) is not one arc.
    min_step_share:
        A log is too irregular to calibrate from when more than this share of its frame gaps are shorter
        than ``min_gap`` (duplicated stamps, or lines out of order).
    min_gap:
        See ``min_step_share`` (s). 0.01 s: no laser scanner of the logs scans at 100 Hz, so gaps that short
        are stamping artefacts (the Intel Research Lab log has 30 % of them after sorting its lines; it
        is accepted: the odometry noise follows the motion, not the stamps).
    lifetime_lags:
        Lags (s, rounded to whole frames) of the persistence curve the short readings' lifetime is fitted to
        (:mod:`~slamtrials.calibration.lifetime`).
    lifetime_grid:
        Lifetimes (s, increasing) the laser model is replayed with for that fit (besides 0).
    fleeting_grid:
        Fleeting shares (increasing, in [0, 1)) the laser model is replayed with, with every lifetime.
    persistence_radius:
        A short reading persists when a later frame reads short within this distance (m) of its end point.
    lifetime_base_frames:
        Most base frames of the persistence curve (spread evenly over the log).
    lifetime_min_short:
        Fewest short readings the base frames need for the lifetime to be fitted (else it stays 0).
    bootstrap:
        Bootstrap replicates of the uncertainty (blocks of consecutive frames are resampled).
    block_frames:
        Length (frames) of a bootstrap block.
    min_frames:
        Fewest frames a log needs.
    min_distance:
        Least distance (m) the odometry must travel.
    min_rotation:
        Least total rotation (rad) the odometry must turn.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    range_bins: tuple[float, ...] = Field(
        (0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 15.0, 20.0, 30.0, 50.0, 100.0),
        description="range bin edges (m)",
    )
    min_bin_beams: int = Field(200, ge=20, description="fewest beams per range bin")
    core_cut: float = Field(2.5, gt=1.0, le=5.0, description="Gaussian core cut (sigmas)")
    short_sigmas: float = Field(3.0, gt=1.0, le=10.0, description="short-reading threshold (sigmas)")
    edge_reach: float = Field(
        0.017453292519943295, ge=0.0, le=0.17453292519943295, description="edge model's reach (rad)"
    )
    position_floor: float = Field(0.5, ge=0.0, le=10.0, description="least gap of the position fit's readings (m)")
    position_min_short: int = Field(100, ge=10, description="fewest short readings to fit the position power")
    max_beams: int = Field(600_000, ge=1000, description="cap on the beams used")
    laser_anchors_only: bool = Field(False, description="cast only the reference's update frames")
    windows: tuple[int, ...] = Field((1, 2, 4, 8, 16, 32), description="odometry window lengths (segments)")
    outlier_sigmas: float = Field(5.0, gt=2.0, le=20.0, description="odometry outlier threshold (sigmas)")
    direction_min_step: float = Field(
        0.02, gt=0.0, le=1.0, description="least opposite travel of a direction conflict (m)"
    )
    chunk_distance: float = Field(1.0, gt=0.0, le=100.0, description="chunk length of the motion estimate (m)")
    chunk_turn: float = Field(0.5, gt=0.0, le=10.0, description="chunk turn of the motion estimate (rad)")
    relation_tolerance: float = Field(0.1, gt=0.0, le=10.0, description="relation stamp tolerance (s)")
    relation_max_distance: float = Field(3.0, gt=0.0, le=1000.0, description="longest relation span used (m)")
    relation_max_turn: float = Field(1.5, gt=0.0, le=100.0, description="largest relation turn used (rad)")
    min_step_share: float = Field(0.5, gt=0.0, le=1.0, description="largest share of tiny frame gaps")
    min_gap: float = Field(0.01, ge=0.0, le=1.0, description="a frame gap shorter than this is tiny (s)")
    lifetime_lags: tuple[float, ...] = Field((0.2, 0.6, 1.0, 2.0, 4.0), description="persistence lags (s)")
    lifetime_grid: tuple[float, ...] = Field(
        (0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0), description="lifetimes replayed (s)"
    )
    fleeting_grid: tuple[float, ...] = Field(
        (0.0, 0.2, 0.4, 0.6, 0.8, 0.9, 0.95), description="fleeting shares replayed"
    )
    persistence_radius: float = Field(0.15, gt=0.0, le=2.0, description="persistence radius (m)")
    lifetime_base_frames: int = Field(600, ge=10, description="most base frames of the persistence curve")
    lifetime_min_short: int = Field(100, ge=1, description="fewest short readings to fit the lifetime")
    bootstrap: int = Field(100, ge=10, le=10_000, description="bootstrap replicates")
    block_frames: int = Field(64, ge=1, description="bootstrap block length (frames)")
    min_frames: int = Field(200, ge=10, description="fewest frames")
    min_distance: float = Field(10.0, gt=0.0, description="least odometry distance (m)")
    min_rotation: float = Field(6.283185307179586, gt=0.0, description="least odometry rotation (rad)")

    @field_validator("range_bins")
    @classmethod
    def _increasing(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if len(value) < 3 or any(b <= a for a, b in zip(value, value[1:])) or value[0] < 0.0:
            raise ValueError(f"range_bins must be at least 3 increasing non-negative edges, got {value}")
        return value

    @field_validator("windows")
    @classmethod
    def _windows(cls, value: tuple[int, ...]) -> tuple[int, ...]:
        if len(value) < 2 or any(b <= a for a, b in zip(value, value[1:])) or value[0] < 1:
            raise ValueError(f"windows must be at least 2 increasing lengths >= 1 frame, got {value}")
        return value

    @field_validator("lifetime_lags", "lifetime_grid")
    @classmethod
    def _positive_increasing(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if len(value) < 2 or any(b <= a for a, b in zip(value, value[1:])) or value[0] <= 0.0:
            raise ValueError(f"must be at least 2 increasing positive values (s), got {value}")
        return value

    @field_validator("fleeting_grid")
    @classmethod
    def _shares(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if len(value) < 2 or any(b <= a for a, b in zip(value, value[1:])) or value[0] < 0.0 or value[-1] >= 1.0:
            raise ValueError(f"must be at least 2 increasing shares in [0, 1), got {value}")
        return value
