"""Configuration of the simulated robot, laser and odometry (pydantic models, SI units).

All lengths are in metres, angles in radians, times in seconds. The robot's, the laser's geometry and
the step are the settings of the paper (Amigoni, Castelli and Luperto, IROS 2018) and of its Stage
set-up; the error models take their values from an error profile, ``realistic`` unless the config names
another (:data:`slamtrials.sim.profiles.DEFAULT_PROFILE`), so ``SimConfig.paper()`` (the paper's
noise-free set-up) is not ``SimConfig()``. Every model is frozen and rejects unknown keys; a bad value
raises a ``pydantic.ValidationError`` that names the field, the value and the allowed range
(:meth:`SimConfig.from_dict` turns that into a one-line :class:`~slamtrials.errors.ConfigError`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from slamtrials.errors import ConfigError, validation_problems
from slamtrials.record import LaserGeometry

__all__ = [
    "RobotConfig",
    "LaserConfig",
    "OdometryConfig",
    "SimConfig",
    "ErrorProfile",
    "LASER_ERROR_FIELDS",
    "ODOMETRY_ERROR_FIELDS",
]

#: The laser's error-model fields: what an error profile sets (:mod:`slamtrials.sim.profiles`).
LASER_ERROR_FIELDS = (
    "range_noise_std",
    "range_noise_per_m",
    "short_rate",
    "short_run_beams",
    "short_lifetime",
    "short_fleeting_share",
    "short_position_power",
    "short_range_scale",
    "short_range_shape",
    "dropout_rate",
    "dropout_per_m",
    "dropout_grazing",
    "edge_chance",
    "edge_reach",
)


def short_start_chance(config: LaserConfig) -> float:
    """Probability that a beam reads short after one that did not, in runs of ``short_run_beams``, for the
    largest rate, ``short_rate`` (see :func:`start_chances`)."""
    p, length = config.short_rate, config.short_run_beams
    return p / (length * (1.0 - p)) if p < 1.0 else math.inf


def start_chances(rates: NDArray[np.float64], run_beams: float) -> NDArray[np.float64]:
    """float64 ``[B]``: each beam's probability of starting a run of ``run_beams`` short readings after one
    that did not read short, for its probability ``rates`` ``[B]`` of reading short.

    The chain along the scan stays short with ``q = 1 - 1 / L`` and starts a run with ``s``; its share of
    short beams is ``s / (s + 1 - q)``, which is ``p`` for ``s = p (1 - q) / (1 - p)``.
    """
    out = np.full(rates.shape, math.inf)
    below = rates < 1.0
    out[below] = rates[below] / (run_beams * (1.0 - rates[below]))
    return out


#: The odometry's error-model fields: what an error profile sets.
ODOMETRY_ERROR_FIELDS = (
    "bias_linear_range",
    "bias_angular_range",
    "noise_linear_per_m",
    "noise_angular_per_rad",
    "noise_linear_per_rad",
    "noise_angular_per_m",
    "slip_per_m",
    "slip_linear_std",
    "slip_angular_std",
)

_MODEL_CONFIG = ConfigDict(extra="forbid", frozen=True)


def _check_finite(name: str, values: tuple[float, ...]) -> None:
    if not all(math.isfinite(v) for v in values):
        raise ValueError(f"{name} must be finite numbers, got {values}")


class RobotConfig(BaseModel):
    """A differential-drive base with a disc footprint.

    Attributes
    ----------
    radius:
        Footprint radius (m). The paper's robot is a 0.2 x 0.2 m Pioneer-like square base; the disc that
        circumscribes it has radius ``0.1 * sqrt(2) = 0.141`` m, rounded up to 0.15 m. Using the
        circumscribed disc means the simulated robot never fits where the square one would not.
    max_linear_speed:
        Largest forward speed (m/s), 0.7 m/s as the paper's planner limit.
    max_angular_speed:
        Largest turn rate (rad/s), 70 deg/s as in the paper.
    max_linear_accel:
        Largest change of linear speed (m/s^2), used for acceleration and braking alike. 0.5 m/s^2:
        a Pioneer's controller ships with a few tenths of m/s^2 (about 0.3) and allows more; 0.5 reaches
        the top speed of 0.7 m/s in 1.4 s and stops from it within 0.49 m.
    max_angular_accel:
        Largest change of turn rate (rad/s^2), 100 deg/s^2 (the order of a Pioneer controller's
        rotational acceleration setting): full turn rate in 0.7 s.
    allow_reverse:
        Whether negative linear speeds are obeyed (otherwise they are clipped to 0).
    max_reverse_speed:
        Largest backward speed (m/s, positive number). ``None`` means the same as ``max_linear_speed``.
    """

    model_config = _MODEL_CONFIG

    radius: float = Field(0.15, gt=0.0, le=5.0, description="footprint disc radius (m)")
    max_linear_speed: float = Field(0.7, gt=0.0, le=10.0, description="largest forward speed (m/s)")
    max_angular_speed: float = Field(
        math.radians(70.0), gt=0.0, le=4.0 * math.pi, description="largest turn rate (rad/s)"
    )
    max_linear_accel: float = Field(0.5, gt=0.0, le=100.0, description="largest linear acceleration (m/s^2)")
    max_angular_accel: float = Field(
        math.radians(100.0), gt=0.0, le=100.0, description="largest angular acceleration (rad/s^2)"
    )
    allow_reverse: bool = Field(True, description="obey negative linear speeds")
    max_reverse_speed: float | None = Field(
        None, gt=0.0, le=10.0, description="largest backward speed (m/s); None = max_linear_speed"
    )

    @property
    def reverse_speed_limit(self) -> float:
        """Largest backward speed actually allowed (m/s, >= 0): 0 when reversing is off."""
        if not self.allow_reverse:
            return 0.0
        return self.max_linear_speed if self.max_reverse_speed is None else self.max_reverse_speed


class LaserConfig(BaseModel):
    """A planar laser range finder (Stage ``ranger``-like), noise-free by default.

    Beams are spread evenly over the field of view, counter-clockwise, from ``angle_min = -fov / 2`` to
    ``+fov / 2`` in the laser frame. The beam count is ``round(fov / angular_resolution) + 1`` and the
    actual increment is ``fov / (num_beams - 1)``, so the beams always span exactly the field of view
    (270 deg at 0.5 deg gives 541 beams, increment exactly 0.5 deg up to rounding).

    Attributes
    ----------
    fov:
        Field of view (rad), in (0, 2 pi]. Default 270 deg.
    angular_resolution:
        Requested angle between beams (rad). Default 0.5 deg.
    max_range:
        Largest range (m): the sensor's maximum, the ``range_max`` of the recorded laser geometry. A beam
        that hits nothing within it has no return and reads ``+inf`` (ROS REP 117), which every algorithm
        skips. Default 80 m: the seed paper's Stage laser (its ``hokuyo.inc``, ``range [0 80]``), whose
        GMapping used returns up to 30 m (``maxUrange``) and skipped readings beyond 60 m (``maxRange``),
        no-returns among them; the ``paper`` GMapping preset holds those two values, so the paper's
        "30 m laser" is this 80 m sensor read through GMapping's 30 m cut.
    min_range:
        Smallest reportable range (m); readings are clipped up to it. Default 0: the simulator never
        reports less than the true distance, and the robot's footprint keeps a centred laser at least
        the robot radius away from walls. Set it (e.g. 0.02 m) to mimic a real scanner's dead zone.
    mount:
        Pose (x, y, theta) of the laser in the robot base frame (m, m, rad). Default (0, 0, 0).
    range_noise_std:
        Constant part (m) of the standard deviation of the zero-mean Gaussian noise added to every reading
        that hit something. No-returns stay no-returns. Default 0, as
        Stage's laser.
    range_noise_per_m:
        Range-proportional part (m/m): the noise's standard deviation is
        ``range_noise_std + range_noise_per_m * range``. Default 0.
    short_rate:
        Probability per beam that something not in the map (a person, a chair leg, glass) returns the beam
        early, where it stands as ``short_position_power`` says (uniformly between ``min_range`` and the
        true range by default); with ``short_range_scale`` the top of a chance that rises with the range.
        Default 0.
    short_run_beams:
        Mean length (beams) of a run of neighbouring short readings: such things are wider than a beam,
        so real short readings come in runs (fitted: 5 to 7 beams of 0.5 degree in the shared logs). 0 (the
        default): every beam on its own. At least 1: along the scan, a beam reads short with probability
        ``1 - 1 / short_run_beams`` after a short one and such that ``short_rate`` of the beams do in
        all; a run is one object, at the distance drawn for its first beam (beams whose wall is nearer
        read the wall).
    short_lifetime:
        Mean time (s) a thing not in the map stays where a scan saw it, read again by the scans that follow
        (:mod:`slamtrials.sim.unmapped`; real short readings mostly persist for seconds). 0 (the default):
        each scan's short readings are drawn anew.
    short_fleeting_share:
        With ``short_lifetime > 0``: the share of the new runs of short readings that leave no thing (gone
        by the next scan, like the readings of things that move); the others stay for ``short_lifetime``
        on average. 0 (the default): every run leaves a thing. Real logs have both kinds
        (:mod:`slamtrials.calibration.lifetime` fits the two values together).
    short_range_scale, short_range_shape:
        How the chance of a short reading grows with the range ``r`` of the beam's wall
        (:mod:`slamtrials.sim.shortrate`): ``short_rate (1 - exp(-(r / scale)^shape))``. Scale 0 (the
        default): ``short_rate`` on every beam. The shared logs' fits: a scale of about 4 m, a shape of 1.2
        to 1.6.
    short_position_power:
        Where a short reading's thing stands (:mod:`slamtrials.sim.shortdistance`): its position as a
        fraction ``v`` of the beam from ``min_range`` to the wall has density ``(a + 1) v^a``. 0 (the
        default): anywhere, uniformly. Real short readings stand farther out (fits near 1).
    dropout_rate, dropout_per_m, dropout_grazing:
        Probability per beam of no return (the reading is ``+inf``, like any beam without a return):
        ``dropout_rate + dropout_per_m * range + dropout_grazing * (1 - |cos(incidence)|)``, capped at 1,
        where the incidence is the angle between the beam and the normal of the wall it hits. Default 0.
    edge_chance, edge_reach:
        Readings at depth edges (:mod:`slamtrials.sim.edges`): a beam with a neighbour within ``edge_reach``
        (rad) to either side whose wall is more than 0.3 m nearer reads that nearer wall with probability
        ``edge_chance``. Default 0 (off). A laser whose beams are farther apart than ``edge_reach`` has no
        such neighbours (its spot does not reach the next beam), so the model does nothing there. The shared
        logs' fits: 0.15 to 0.20 within 1 degree.

    See :mod:`slamtrials.sim.laser_errors` for the order of the draws.
    """

    model_config = _MODEL_CONFIG

    fov: float = Field(math.radians(270.0), gt=0.0, le=2.0 * math.pi, description="field of view (rad)")
    angular_resolution: float = Field(
        math.radians(0.5), gt=0.0, le=2.0 * math.pi, description="angle between beams (rad)"
    )
    max_range: float = Field(
        80.0, gt=0.0, le=1000.0, description="the sensor's largest range (m); beyond it a beam reads +inf (no return)"
    )
    min_range: float = Field(0.0, ge=0.0, le=1000.0, description="smallest range (m)")
    mount: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="laser pose (x, y, theta) in the base frame")
    range_noise_std: float = Field(0.0, ge=0.0, le=10.0, description="Gaussian range noise std, constant part (m)")
    range_noise_per_m: float = Field(
        0.0, ge=0.0, le=1.0, description="Gaussian range noise std, part proportional to the range (m/m)"
    )
    short_rate: float = Field(0.0, ge=0.0, le=1.0, description="probability per beam of a short reading")
    short_run_beams: float = Field(
        0.0, ge=0.0, le=1000.0, description="mean run of neighbouring short readings (beams); 0: independent beams"
    )
    short_lifetime: float = Field(
        0.0, ge=0.0, le=3600.0, description="mean time a thing not in the map stays (s); 0: drawn anew per scan"
    )
    short_fleeting_share: float = Field(
        0.0, ge=0.0, lt=1.0, description="share of new short-reading runs that leave no thing (with short_lifetime)"
    )
    short_position_power: float = Field(
        0.0, ge=0.0, le=50.0, description="power a of the short readings' position density (a + 1) v^a along the beam"
    )
    short_range_scale: float = Field(
        0.0, ge=0.0, le=1000.0, description="range (m) over which the short-reading chance rises; 0: constant"
    )
    short_range_shape: float = Field(
        1.0, gt=0.0, le=20.0, description="shape of that rise (1 - exp(-(r / scale)^shape))"
    )
    dropout_rate: float = Field(0.0, ge=0.0, le=1.0, description="probability per beam of no return")
    dropout_per_m: float = Field(
        0.0, ge=0.0, le=1.0, description="added probability of no return per metre of range (1/m)"
    )
    dropout_grazing: float = Field(
        0.0, ge=0.0, le=1.0, description="added probability of no return times (1 - |cos incidence|)"
    )
    edge_chance: float = Field(
        0.0, ge=0.0, le=1.0, description="probability that a beam next to a nearer wall (within edge_reach) reads it"
    )
    edge_reach: float = Field(
        0.0, ge=0.0, le=math.radians(10.0), description="angle (rad) to either side within which edge_chance applies"
    )

    @property
    def has_errors(self) -> bool:
        """Whether any reading error is on (the noise-free Stage laser otherwise)."""
        shape_only = (
            "short_run_beams",
            "short_lifetime",
            "short_fleeting_share",
            "short_position_power",
            "short_range_scale",
            "short_range_shape",
            "edge_reach",
        )  # they shape the errors, add none
        return any(getattr(self, name) > 0.0 for name in LASER_ERROR_FIELDS if name not in shape_only)

    @field_validator("mount")
    @classmethod
    def _mount_finite(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        _check_finite("mount", value)
        return value

    @model_validator(mode="after")
    def _consistent(self) -> LaserConfig:
        if self.angular_resolution > self.fov:
            raise ValueError(
                f"angular_resolution ({self.angular_resolution:g} rad) must not exceed fov ({self.fov:g} rad)"
            )
        if self.min_range >= self.max_range:
            raise ValueError(f"min_range ({self.min_range:g} m) must be smaller than max_range ({self.max_range:g} m)")
        if self.num_beams > 100_000:
            raise ValueError(f"fov / angular_resolution gives {self.num_beams} beams; at most 100000 are allowed")
        if 0.0 < self.short_run_beams < 1.0:
            raise ValueError(
                f"short_run_beams must be 0 (independent beams) or at least 1, got {self.short_run_beams:g}"
            )
        if self.short_run_beams >= 1.0 and self.short_rate > 0.0 and short_start_chance(self) > 1.0:
            raise ValueError(
                f"short_rate {self.short_rate:g} with runs of {self.short_run_beams:g} beams cannot be: at most "
                f"{self.short_run_beams / (self.short_run_beams + 1.0):.4g} of the beams can read short with runs that long"
            )
        return self

    @property
    def num_beams(self) -> int:
        """Number of beams B = ``round(fov / angular_resolution) + 1``."""
        return int(round(self.fov / self.angular_resolution)) + 1

    @property
    def angle_min(self) -> float:
        """Angle (rad) of beam 0 in the laser frame: ``-fov / 2``."""
        return -0.5 * self.fov

    @property
    def angle_increment(self) -> float:
        """Angle (rad) between consecutive beams: ``fov / (num_beams - 1)``."""
        return self.fov / (self.num_beams - 1)

    @property
    def angles(self) -> NDArray[np.float64]:
        """float64 ``[B]`` beam angles (rad) in the laser frame, counter-clockwise from ``angle_min``."""
        return self.angle_min + np.arange(self.num_beams, dtype=np.float64) * self.angle_increment

    def geometry(self) -> LaserGeometry:
        """The laser's geometry as it is recorded with every run."""
        return LaserGeometry(
            angle_min=self.angle_min,
            angle_increment=self.angle_increment,
            range_min=self.min_range,
            range_max=self.max_range,
            mount=(float(self.mount[0]), float(self.mount[1]), float(self.mount[2])),
        )


class OdometryConfig(BaseModel):
    """The odometry error model of the paper: a constant per-run scale bias, plus optional noise.

    Once per run, ``e_lin`` is drawn uniformly from ``bias_linear_range`` (m/m) and ``e_ang`` from
    ``bias_angular_range`` (rad/rad). Every step, the odometry measures the true arc length times
    ``1 + e_lin`` and the true heading change times ``1 + e_ang`` (see :mod:`slamtrials.sim.odometry`).

    Optional random noise (off by default, as in the paper): a random walk per metre driven and per
    radian turned. A step of arc length ``L`` (m) and heading change ``phi`` (rad) adds zero-mean
    Gaussian errors to its measured arc length, variance ``noise_linear_per_m^2 |L| +
    noise_linear_per_rad^2 |phi|`` (m^2), and to its measured heading change, variance
    ``noise_angular_per_rad^2 |phi| + noise_angular_per_m^2 |L|`` (rad^2). Variances grow linearly with
    distance and angle, so the noise accumulated along a path does not depend on how it is cut into
    steps (``dt``, or a log's irregular stamps), and a robot that stands still gets none. The
    coefficients are therefore square roots of variance per unit of motion: m/sqrt(m), m/sqrt(rad),
    rad/sqrt(rad), rad/sqrt(m). (Before issue 32 they were stds per unit of a 0.1 s step's motion, m/m
    etc.; an old value ``k`` for steps of ``l`` metres is about ``k sqrt(l)`` here, 0.22 k for 0.05 m.)

    Attributes
    ----------
    bias_linear_range:
        (low, high) of the uniform draw of ``e_lin`` (m/m). Paper: (-0.005, 0.005).
    bias_angular_range:
        (low, high) of the uniform draw of ``e_ang`` (rad/rad). Paper: +-1 deg/rad = +-0.017453.
    bias_linear, bias_angular:
        Fixed values that replace the draws (the draws are still made, so the random stream of the
        rest of the run does not change). ``None`` (default) uses the draw.
    noise_linear_per_m:
        Arc-length random walk per metre driven (m/sqrt(m)): the arc-length error's std after 1 m is
        this, after ``D`` m this times ``sqrt(D)``. Default 0.
    noise_angular_per_rad:
        Heading random walk per radian turned (rad/sqrt(rad)). Default 0.
    noise_linear_per_rad:
        Arc-length random walk per radian turned (m/sqrt(rad)): the cross term, ``noise_linear_per_rad^2
        |phi|`` added to the arc-length variance. Default 0.
    noise_angular_per_m:
        Heading random walk per metre driven (rad/sqrt(m)): the other cross term. Default 0.
    slip_per_m:
        Expected wheel-slip events per metre travelled (1/m): a Poisson process in distance, so a step of
        arc length ``L`` slips with probability ``1 - exp(-slip_per_m |L|)`` (whatever the step's length,
        the slips along a path do not depend on how it is cut); each slip adds ``N(0, slip_linear_std)``
        to its measured arc length and ``N(0, slip_angular_std)`` to its measured heading change. Default 0.
    slip_linear_std, slip_angular_std:
        Size of a slip's errors (m, rad).
    """

    model_config = _MODEL_CONFIG

    bias_linear_range: tuple[float, float] = Field((-0.005, 0.005), description="uniform range of e_lin (m/m)")
    bias_angular_range: tuple[float, float] = Field(
        (-math.radians(1.0), math.radians(1.0)), description="uniform range of e_ang (rad/rad)"
    )
    bias_linear: float | None = Field(None, gt=-0.5, lt=0.5, description="fixed e_lin (m/m), overrides the draw")
    bias_angular: float | None = Field(None, gt=-0.5, lt=0.5, description="fixed e_ang (rad/rad), overrides the draw")
    noise_linear_per_m: float = Field(
        0.0, ge=0.0, le=1.0, description="arc-length random walk per metre driven (m/sqrt(m))"
    )
    noise_angular_per_rad: float = Field(
        0.0, ge=0.0, le=1.0, description="heading random walk per radian turned (rad/sqrt(rad))"
    )
    noise_linear_per_rad: float = Field(
        0.0, ge=0.0, le=1.0, description="arc-length random walk per radian turned (m/sqrt(rad))"
    )
    noise_angular_per_m: float = Field(
        0.0, ge=0.0, le=1.0, description="heading random walk per metre driven (rad/sqrt(m))"
    )
    slip_per_m: float = Field(0.0, ge=0.0, le=10.0, description="expected wheel-slip events per metre (1/m)")
    slip_linear_std: float = Field(0.0, ge=0.0, le=10.0, description="arc-length error std of a slip (m)")
    slip_angular_std: float = Field(0.0, ge=0.0, le=math.pi, description="heading error std of a slip (rad)")

    @field_validator("bias_linear_range", "bias_angular_range")
    @classmethod
    def _range_ok(cls, value: tuple[float, float], info: Any) -> tuple[float, float]:
        _check_finite(info.field_name, value)
        low, high = value
        if low > high:
            raise ValueError(f"{info.field_name} must be (low, high) with low <= high, got {value}")
        if low <= -0.5 or high >= 0.5:
            raise ValueError(f"{info.field_name} must lie inside (-0.5, 0.5), got {value}")
        return value


class ErrorProfile(BaseModel):
    """A named set of error-model values.

    Attributes
    ----------
    name:
        The profile's name (letters, digits, ``_ . -``).
    description:
        Where its values come from.
    laser:
        Values of laser error fields (``range_noise_std`` m, ``range_noise_per_m`` m/m, ``short_rate``,
        ``dropout_rate``, ``dropout_per_m`` 1/m, ``dropout_grazing``); a field not given is 0.
    odometry:
        Values of odometry error fields (``bias_linear_range`` m/m, ``bias_angular_range`` rad/rad, the
        ``noise_*`` stds, ``slip_*``); a field not given keeps the odometry config's default.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = Field(..., pattern=r"^[A-Za-z0-9_.\-]+$", max_length=100, description="profile name")
    description: str = Field("", max_length=2000, description="where the values come from")
    laser: dict[str, float] = Field(default_factory=dict, description="laser error-model values")
    odometry: dict[str, Any] = Field(default_factory=dict, description="odometry error-model values")

    @field_validator("laser")
    @classmethod
    def _laser_fields(cls, values: dict[str, float]) -> dict[str, float]:
        _known("laser", values, LASER_ERROR_FIELDS)
        LaserConfig.model_validate(values)  # the fields' own ranges
        return dict(sorted(values.items()))

    @field_validator("odometry")
    @classmethod
    def _odometry_fields(cls, values: dict[str, Any]) -> dict[str, Any]:
        _known("odometry", values, ODOMETRY_ERROR_FIELDS)
        checked = OdometryConfig.model_validate(values)
        return {name: getattr(checked, name) for name in sorted(values)}

    def laser_values(self) -> dict[str, float]:
        """Every laser error field's value (the laser config's default where the profile gives none: 0 for
        every rate)."""
        defaults = LaserConfig()
        return {name: float(self.laser.get(name, getattr(defaults, name))) for name in LASER_ERROR_FIELDS}

    def odometry_values(self) -> dict[str, Any]:
        """Every odometry error field's value (the odometry config's default where the profile gives none)."""
        defaults = OdometryConfig()
        return {name: self.odometry.get(name, getattr(defaults, name)) for name in ODOMETRY_ERROR_FIELDS}


def _known(section: str, values: dict[str, Any], fields: tuple[str, ...]) -> None:
    unknown = sorted(set(values) - set(fields))
    if unknown:
        raise ValueError(f"unknown {section} error field {unknown[0]!r}; known: {', '.join(fields)}")


def _default_profile() -> str:
    """The name of the profile of a config that names none: :data:`slamtrials.sim.profiles.DEFAULT_PROFILE`."""
    from slamtrials.sim.profiles import DEFAULT_PROFILE

    return DEFAULT_PROFILE


def _under(profile_values: dict[str, Any], given: Any, model: type[BaseModel]) -> Any:
    """``given`` (a mapping, a model instance or None) with ``profile_values`` for the fields it does not set."""
    if given is None:
        return dict(profile_values)
    if isinstance(given, model):
        explicit = given.model_dump(include=given.model_fields_set)
        return {**given.model_dump(), **profile_values, **explicit}
    if isinstance(given, dict):
        return {**profile_values, **given}
    return given  # not a mapping: the field's own validation names it


class SimConfig(BaseModel):
    """Everything the :class:`~slamtrials.sim.Simulator` needs besides the world and the random stream.

    Attributes
    ----------
    dt:
        Simulation step (s): one laser scan, odometry reading and ground-truth pose per step.
        Default 0.1 s (10 Hz), as the paper.
    robot, laser, odometry:
        The sub-configurations.
    profile:
        The error profile (:mod:`slamtrials.sim.profiles`): a bundled name (by default
        :data:`~slamtrials.sim.profiles.DEFAULT_PROFILE`, ``realistic``) or an inline
        :class:`~slamtrials.sim.profiles.ErrorProfile`. It gives the laser's and the odometry's
        error-model fields their values; a value written in ``laser`` or ``odometry`` that differs from
        the profile's overrides it (:attr:`profile_overrides`, :mod:`slamtrials.sim.overrides`).
        :meth:`paper` is the paper's set-up.
    """

    model_config = _MODEL_CONFIG

    dt: float = Field(0.1, gt=0.0, le=1.0, description="simulation step (s)")
    robot: RobotConfig = Field(default_factory=RobotConfig)
    laser: LaserConfig = Field(default_factory=LaserConfig)
    odometry: OdometryConfig = Field(default_factory=OdometryConfig)
    profile: str | ErrorProfile = Field(
        default_factory=lambda: _default_profile(),
        description="error profile, which sets the error models: a bundled name (realistic, paper, mit-csail, "
        "fr079), a profile YAML file or inline {name, laser, odometry}",
    )

    @model_validator(mode="before")
    @classmethod
    def _profile_fills_the_error_models(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        from slamtrials.sim.profiles import BUNDLED_PROFILES, resolve_profile

        try:
            profile = resolve_profile(data.get("profile", _default_profile()))
        except ValidationError as exc:
            raise ValueError(f"profile: {validation_problems(exc)}") from None
        data = dict(data)
        data["laser"] = _under(profile.laser_values(), data.get("laser"), LaserConfig)
        data["odometry"] = _under(profile.odometry_values(), data.get("odometry"), OdometryConfig)
        bundled = BUNDLED_PROFILES.get(profile.name) == profile
        data["profile"] = profile.name if bundled else profile
        return data

    @property
    def profile_name(self) -> str:
        """The error profile's name."""
        return self.profile if isinstance(self.profile, str) else self.profile.name

    @property
    def error_profile(self) -> ErrorProfile:
        """The error profile itself (a bundled one looked up by name)."""
        from slamtrials.sim.profiles import resolve_profile

        return resolve_profile(self.profile)

    @property
    def profile_overrides(self) -> tuple[Any, ...]:
        """The error-model fields whose values differ from the profile's
        (:class:`~slamtrials.sim.overrides.ProfileOverride`, empty for a config that is its profile)."""
        from slamtrials.sim.overrides import profile_overrides

        return profile_overrides(self)

    @property
    def profile_label(self) -> str:
        """``realistic``, or ``realistic + 2 overrides``: the profile and how many of its values are overridden."""
        from slamtrials.sim.overrides import profile_label

        return profile_label(self)

    @classmethod
    def paper(cls) -> SimConfig:
        """The settings of the paper (270 deg / 0.5 deg / 80 m laser, 10 Hz, +-0.5 % and +-1 deg/rad bias).

        The default profile is ``realistic`` (:data:`~slamtrials.sim.profiles.DEFAULT_PROFILE`); this
        is the explicit way to get the paper's Stage set-up, bit for bit.
        """
        return cls(profile="paper")

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SimConfig:
        """Validate a plain dict (e.g. loaded from YAML); raise :class:`ConfigError` with a one-line message."""
        try:
            return cls.model_validate(data)
        except ValidationError as exc:
            raise ConfigError("simulation config: " + validation_problems(exc)) from None
