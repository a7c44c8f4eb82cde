"""Error profiles: named sets of the simulator's error-model values (laser and odometry).

A profile sets the fields of :data:`~slamtrials.sim.config.LASER_ERROR_FIELDS` (range noise, short
readings, dropouts) and :data:`~slamtrials.sim.config.ODOMETRY_ERROR_FIELDS` (scale-bias ranges, noise
per metre and per radian with their cross terms, slips). A simulation config names one
(``sim.profile: paper``) or holds one inline (``sim.profile: {name: ..., laser: {...}, odometry:
{...}}``); values written in ``sim.laser`` or ``sim.odometry`` themselves override the profile's.

Bundled:

``paper``
    The IROS 2018 Stage set-up: a noise-free laser and a constant per-run odometry scale bias drawn
    from +-0.5 % and +-1 deg/rad, nothing else. These are the config's own defaults, so a config that
    names no profile is this one, bit for bit.

Profiles fitted to real logs (``slamtrials calibrate``) are YAML files of the same form; the config
loaders (campaign config, ``--config`` of the CLI) read a ``profile`` that is a path to such a file.
"""

from __future__ import annotations

import math
from typing import Any

from slamtrials.sim.config import ErrorProfile

__all__ = ["ErrorProfile", "BUNDLED_PROFILES", "resolve_profile", "DEFAULT_PROFILE"]

DEFAULT_PROFILE = "paper"


BUNDLED_PROFILES: dict[str, ErrorProfile] = {
    "paper": ErrorProfile(
        name="paper",
        description="IROS 2018 Stage set-up: noise-free laser, per-run odometry scale bias within +-0.5 % and "
        "+-1 deg/rad",
        laser={},
        odometry={"bias_linear_range": (-0.005, 0.005), "bias_angular_range": (-math.radians(1.0), math.radians(1.0))},
    ),
}


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
