"""The simulator's laser model built from fitted values, with a calibration error where it cannot be."""

from __future__ import annotations

from pydantic import ValidationError

from slamtrials.errors import CalibrationError, validation_problems
from slamtrials.record import LaserGeometry
from slamtrials.sim.config import LaserConfig

__all__ = ["fitted_laser_config"]


def fitted_laser_config(laser: LaserGeometry, values: dict[str, float], **extra: float) -> LaserConfig:
    """The :class:`LaserConfig` that reads like ``laser`` (its range limits, capped at 1000 m) with the
    fitted error ``values`` and any ``extra`` fields (profile units).

    Raises
    ------
    CalibrationError
        A fitted value lies outside what the laser model accepts (a log whose beams the fit cannot
        describe): one line naming each field, its value and the allowed range.
    """
    range_max = float(laser.range_max)
    try:
        return LaserConfig(
            max_range=min(range_max, 1000.0),
            min_range=min(float(laser.range_min), range_max * 0.5),
            **values,
            **extra,
        )
    except ValidationError as exc:
        raise CalibrationError(
            f"the laser fit gave values the simulator's laser model does not accept: {validation_problems(exc)}"
        ) from None
