"""A simulation config as its error profile plus explicit overrides.

A :class:`~slamtrials.sim.config.SimConfig` names an error profile (:mod:`slamtrials.sim.profiles`),
whose values fill the laser's and the odometry's error-model fields
(:data:`~slamtrials.sim.config.LASER_ERROR_FIELDS`, :data:`~slamtrials.sim.config.ODOMETRY_ERROR_FIELDS`);
a value written in ``laser`` or ``odometry`` themselves overrides the profile's. An *override* is an
error-model field whose value differs from the profile's: a value written equal to the profile's is
not one, so a stored config (which holds every value) and the file it came from have the same overrides.

* :func:`profile_overrides`: the overrides, as typed :class:`ProfileOverride` values.
* :func:`profile_label`: ``"realistic"``, or ``"realistic + 2 overrides"``, the name the CLI prints and
  the report shows.
* :func:`written_form`: the config's JSON form with only the overriding error-model fields, what
  ``slamtrials config dump`` writes (editing the profile's name then changes every value it sets).
* :func:`warn_overrides`: the one warning line a config file that contradicts its profile gets.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

from slamtrials.sim.config import LASER_ERROR_FIELDS, ODOMETRY_ERROR_FIELDS, SimConfig

__all__ = [
    "ProfileOverride",
    "profile_overrides",
    "profile_label",
    "profile_summary",
    "written_form",
    "warn_overrides",
    "ERROR_SECTIONS",
]

logger = logging.getLogger(__name__)

#: The sections of a simulation config whose error-model fields a profile sets, and those fields.
ERROR_SECTIONS: dict[str, tuple[str, ...]] = {"laser": LASER_ERROR_FIELDS, "odometry": ODOMETRY_ERROR_FIELDS}


@dataclass(frozen=True)
class ProfileOverride:
    """One error-model field whose value is not the profile's.

    Attributes
    ----------
    key:
        ``section.field`` within the simulation config, e.g. ``laser.dropout_rate``.
    value:
        The config's value (a float, or a ``(low, high)`` tuple for the odometry's bias ranges).
    profile_value:
        The profile's value of the field.
    """

    key: str
    value: Any
    profile_value: Any


def _same(a: Any, b: Any) -> bool:
    """Whether two values of a field are equal (floats to 1e-12 relative, ranges bound by bound)."""
    if isinstance(a, (tuple, list)) and isinstance(b, (tuple, list)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        return math.isclose(float(a), float(b), rel_tol=1e-12, abs_tol=0.0)
    return a == b


def profile_overrides(config: SimConfig) -> tuple[ProfileOverride, ...]:
    """The error-model fields of ``config`` whose values differ from its profile's, laser first, each
    section in the order of its field list."""
    profile = config.error_profile
    expected = {"laser": profile.laser_values(), "odometry": profile.odometry_values()}
    out = []
    for section, fields in ERROR_SECTIONS.items():
        model = getattr(config, section)
        for name in fields:
            value, wanted = getattr(model, name), expected[section][name]
            if not _same(value, wanted):
                out.append(ProfileOverride(f"{section}.{name}", value, wanted))
    return tuple(out)


def profile_label(config: SimConfig) -> str:
    """The profile's name, with the number of overrides when there are any: ``realistic``,
    ``realistic + 1 override``, ``paper + 3 overrides``."""
    count = len(profile_overrides(config))
    if count == 0:
        return config.profile_name
    return f"{config.profile_name} + {count} override{'s' if count != 1 else ''}"


def profile_summary(config: SimConfig) -> dict[str, Any]:
    """JSON form for a run's metadata: ``{"name": ..., "label": ..., "overrides": {key: value}}``."""
    overrides = profile_overrides(config)
    return {
        "name": config.profile_name,
        "label": profile_label(config),
        "overrides": {o.key: list(o.value) if isinstance(o.value, tuple) else o.value for o in overrides},
    }


def written_form(config: SimConfig) -> dict[str, Any]:
    """``config``'s JSON form without the error-model fields that hold the profile's values.

    It loads back (:meth:`SimConfig.model_validate`) as a config equal to ``config``; with another
    profile's name in it, every field the profile sets takes the other profile's value except the
    overrides.
    """
    data = config.model_dump(mode="json")
    overridden = {o.key for o in profile_overrides(config)}
    for section, fields in ERROR_SECTIONS.items():
        for name in fields:
            if f"{section}.{name}" not in overridden:
                data[section].pop(name, None)
    return data


def warn_overrides(config: SimConfig, source: str, prefix: str = "sim.") -> tuple[ProfileOverride, ...]:
    """Log one warning naming the keys of ``config`` (read from ``source``) that override its profile.

    Parameters
    ----------
    config:
        The simulation config as read.
    source:
        What it was read from (a file name), for the message.
    prefix:
        The config's place in the file (``sim.`` in a campaign or trial config, empty for a file that
        is a simulation config itself), for the keys in the message.

    Returns
    -------
    tuple of ProfileOverride
        The overrides (empty: nothing logged).
    """
    overrides = profile_overrides(config)
    if overrides:
        keys = ", ".join(f"{prefix}{o.key}" for o in overrides)
        logger.warning("%s: keys that override profile %s: %s", source, config.profile_name, keys)
    return overrides
