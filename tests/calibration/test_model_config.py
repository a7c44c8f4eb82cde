"""The fitted laser model: values the simulator cannot take are a calibration error of one line."""

import numpy as np
import pytest

from slamtrials.calibration.model_config import fitted_laser_config
from slamtrials.errors import CalibrationError
from slamtrials.record import LaserGeometry


def _laser(range_max: float = 30.0) -> LaserGeometry:
    return LaserGeometry(angle_min=-np.pi / 2, angle_increment=np.pi / 180, range_min=0.0, range_max=range_max)


def test_fitted_values_build_the_log_s_laser():
    config = fitted_laser_config(_laser(), {"range_noise_std": 0.012, "dropout_rate": 0.03})
    assert config.max_range == 30.0
    assert config.range_noise_std == 0.012
    assert config.dropout_rate == 0.03


def test_an_infeasible_fit_names_the_field_and_its_value():
    with pytest.raises(CalibrationError) as info:
        fitted_laser_config(_laser(), {"range_noise_std": 0.01, "dropout_rate": 1.7})
    message = str(info.value)
    assert "\n" not in message
    assert "dropout_rate" in message and "1.7" in message
    assert "range_noise_std" not in message
