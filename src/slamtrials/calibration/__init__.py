"""Calibration: fitting the simulator's error models to a real log (``slamtrials calibrate``).

A SLAM run over the log gives the reference (its final path and map); the real ranges are compared with
ranges cast in that map from those poses, and the odometry's increments with the path's, and the laser
and odometry error models of :mod:`slamtrials.sim` are fitted to the differences, each value with a
block-bootstrap standard error. This package composes sim and slam like a trial does, so it sits at the
trial's level of the layers; it does no I/O (docs/realism.md, "Calibration", has the method).
"""

from slamtrials.calibration.fit import Calibration, FittedValue, calibrate
from slamtrials.calibration.reference import Reference, check_calibratable, slam_reference
from slamtrials.calibration.settings import CalibrationSettings

__all__ = [
    "Calibration",
    "CalibrationSettings",
    "FittedValue",
    "Reference",
    "calibrate",
    "check_calibratable",
    "slam_reference",
]
