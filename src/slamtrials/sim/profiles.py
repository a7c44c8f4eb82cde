"""Error profiles: named sets of the simulator's error-model values (laser and odometry).

A profile sets the fields of :data:`~slamtrials.sim.config.LASER_ERROR_FIELDS` (range noise, short
readings, dropouts) and :data:`~slamtrials.sim.config.ODOMETRY_ERROR_FIELDS` (scale-bias ranges, noise
per metre and per radian with their cross terms, slips). A simulation config names one
(``sim.profile: paper``) or holds one inline (``sim.profile: {name: ..., laser: {...}, odometry:
{...}}``); values written in ``sim.laser`` or ``sim.odometry`` themselves override the profile's.

Bundled:

``paper``
    The IROS 2018 Stage set-up: a noise-free laser and a constant per-run odometry scale bias drawn
    from +-0.5 % and +-1 deg/rad, nothing else. These are the error-model fields' own defaults
    (``SimConfig.paper()``, bit for bit); a config that names no profile is ``realistic``
    (:data:`DEFAULT_PROFILE`).

``mit-csail``, ``fr079``
    Fitted by ``slamtrials calibrate`` to the shared real logs (MIT CSAIL with GMapping's defaults;
    fr079 with the GMapping setting that maps it, ``linearUpdate=0.1``, seed 0): the laser against
    GMapping's final path and map, the odometry against the log's benchmark relations (``--relations``,
    issue 32: a random walk per metre and per radian, independent of any SLAM run). The values are the
    printed fit rounded to four significant digits; docs/realism.md, "How the bundled profiles were
    fitted", has the command lines, and "Calibration" the method, the uncertainties and what the values
    include besides the sensors' own errors.

``realistic``
    The mean of the two fits, field by field, without the short readings' persistence: see
    :func:`_realistic`.

Profiles fitted to real logs (``slamtrials calibrate``) are YAML files of the same form; the config
loaders (campaign config, ``--config`` of the CLI) read a ``profile`` that is a path to such a file.
"""

from __future__ import annotations

import math
from typing import Any

from slamtrials.sim.config import ErrorProfile

__all__ = ["ErrorProfile", "BUNDLED_PROFILES", "resolve_profile", "mean_profile", "DEFAULT_PROFILE"]

#: The profile of every simulation that names none: ``SimConfig()``, ``TrialConfig()``, campaigns, the
#: demo, ``slamtrials trial``, ``simulate`` and ``validate``, :func:`slamtrials.validation.validate`. The one
#: source of that default; ``SimConfig.paper()`` (or ``profile: paper``) is the paper's set-up.
DEFAULT_PROFILE = "realistic"


BUNDLED_PROFILES: dict[str, ErrorProfile] = {
    "paper": ErrorProfile(
        name="paper",
        description="IROS 2018 Stage set-up: noise-free laser, per-run odometry scale bias within +-0.5 % and "
        "+-1 deg/rad",
        laser={},
        odometry={"bias_linear_range": (-0.005, 0.005), "bias_angular_range": (-math.radians(1.0), math.radians(1.0))},
    ),
    "mit-csail": ErrorProfile(
        name="mit-csail",
        description="fitted by slamtrials calibrate (2026-11-28) to the shared MIT CSAIL log: the laser against "
        "GMapping's final path and map (default settings, seed 0), the odometry against the log's 1,043 short "
        "benchmark relations (--relations); biases +- the measured per-run bias; odometry noise per metre and "
        "per radian; no slips (docs/realism.md, How the bundled profiles were fitted)",
        laser={
            "range_noise_std": 0.033,
            "range_noise_per_m": 0.0049,
            "short_rate": 0.2866,
            "short_range_scale": 3.981,
            "short_range_shape": 1.573,
            "short_run_beams": 7.315,
            "short_position_power": 0.8909,
            "short_lifetime": 9.012,
            "short_fleeting_share": 0.92,
            "dropout_rate": 0.03269,
            "dropout_per_m": 0.0,
            "dropout_grazing": 0.0,
            "edge_chance": 0.2044,
            "edge_reach": math.radians(1.0),
        },
        odometry={
            "bias_linear_range": (-0.02376, 0.02376),
            "bias_angular_range": (-0.06621, 0.06621),
            "noise_linear_per_m": 0.03424,
            "noise_linear_per_rad": 0.01494,
            "noise_angular_per_rad": 0.1315,
            "noise_angular_per_m": 0.02857,
        },
    ),
    "fr079": ErrorProfile(
        name="fr079",
        description="fitted by slamtrials calibrate (2026-11-28) to the shared fr079 log: the laser against "
        "GMapping's final path and map (linearUpdate=0.1, seed 0: GMapping's defaults do not map fr079, "
        "docs/real-datasets.md), the odometry against the log's 982 short benchmark relations (--relations) "
        "without the 34 where the log moves against them (reversing logged as driving forward) and their 41 "
        "neighbours; biases +- the measured per-run bias; odometry noise per metre and per radian; no slips "
        "(docs/realism.md, How the bundled profiles were fitted)",
        laser={
            "range_noise_std": 0.0323,
            "range_noise_per_m": 0.001789,
            "short_rate": 0.2326,
            "short_range_scale": 3.991,
            "short_range_shape": 1.241,
            "short_run_beams": 4.779,
            "short_position_power": 1.496,
            "short_lifetime": 8.354,
            "short_fleeting_share": 0.845,
            "dropout_rate": 0.01783,
            "dropout_per_m": 0.0,
            "dropout_grazing": 0.01623,
            "edge_chance": 0.1525,
            "edge_reach": math.radians(1.0),
        },
        odometry={
            "bias_linear_range": (-0.00156, 0.00156),
            "bias_angular_range": (-0.01155, 0.01155),
            "noise_linear_per_m": 0.0,
            "noise_linear_per_rad": 0.04803,
            "noise_angular_per_rad": 0.05656,
            "noise_angular_per_m": 0.0308,
        },
    ),
}


def _mean(values: list[Any]) -> Any:
    """The mean of one field's values: numbers, or ranges (tuples) bound by bound; rounded to 6 places."""
    if isinstance(values[0], tuple):
        return tuple(_mean(list(bounds)) for bounds in zip(*values))
    return round(math.fsum(float(v) for v in values) / len(values), 6)


def mean_profile(name: str, description: str, profiles: list[ErrorProfile]) -> ErrorProfile:
    """The profile whose every error-model value is the mean of ``profiles``' values (ranges bound by bound,
    rounded to 6 places): the pooled fit of several logs, each log's fit one sample of its kind of robot."""
    if not profiles:
        raise ValueError("mean_profile needs at least one profile")
    lasers = [p.laser_values() for p in profiles]
    odometries = [p.odometry_values() for p in profiles]
    odometry_fields = sorted({field for p in profiles for field in p.odometry})
    return ErrorProfile(
        name=name,
        description=description,
        laser={field: _mean([laser[field] for laser in lasers]) for field in lasers[0]},
        odometry={field: _mean([odometry[field] for odometry in odometries]) for field in odometry_fields},
    )


def _realistic(mit: ErrorProfile, fr079: ErrorProfile) -> ErrorProfile:
    """``realistic``: the mean of the two fitted logs' values, field by field (:func:`mean_profile`).

    Both logs were recorded with SICK laser scanners on wheeled robots in office buildings, so their fits
    are two samples of one kind of sensor, odometry and place; their mean stands for neither log alone.
    (fr079's odometry fit leaves out the spans where the log records reversing as driving forward,
    docs/realism.md, "Calibration"; it is a fit of the odometry's noise, not of that defect.) Fields
    neither fit sets (slips) stay off.

    One exception: the short readings' persistence (``short_lifetime``, ``short_fleeting_share``) stays
    off, each scan's short readings drawn anew. The explorer takes the things that stay for obstacles
    (which the simulator leaves at random places, not where real things stand): with them, trials explore
    1.4 to 1.7 times as long in simulated time (docs/realism.md, "Profiles"). Add them in a config to study it.
    """
    pooled = mean_profile(
        "realistic",
        "the mean of the mit-csail and fr079 fits, field by field, without the short readings' "
        "persistence (docs/realism.md, Profiles)",
        [mit, fr079],
    )
    laser = {**pooled.laser, "short_lifetime": 0.0, "short_fleeting_share": 0.0}
    return pooled.model_copy(update={"laser": dict(sorted(laser.items()))})


BUNDLED_PROFILES["realistic"] = _realistic(BUNDLED_PROFILES["mit-csail"], BUNDLED_PROFILES["fr079"])


def resolve_profile(value: str | dict[str, Any] | ErrorProfile) -> ErrorProfile:
    """The profile a config names (a bundled name) or holds inline (a mapping or an :class:`ErrorProfile`).

    Raises
    ------
    ValueError
        An unknown name (the message lists the bundled ones and says a file path is read by the loaders).
    """
    if isinstance(value, ErrorProfile):
        return value
    if isinstance(value, dict):
        return ErrorProfile.model_validate(value)
    if isinstance(value, str) and value in BUNDLED_PROFILES:
        return BUNDLED_PROFILES[value]
    raise ValueError(
        f"unknown error profile {value!r}; bundled: {', '.join(sorted(BUNDLED_PROFILES))}, or a profile YAML file "
        "(a path ending in .yaml, read by the config loaders), or an inline mapping {name, laser, odometry}"
    )
