"""GMapping's parameters: slam_gmapping's defaults, the seed paper's preset, and one-line errors.

Checked through :func:`slamtrials.slam.resolve_config` and :func:`slamtrials.slam.make_algorithm`
(the paths the CLI uses): an unknown parameter, values out of range or of the wrong type, maxUrange
above maxRange and an unknown preset each raise ConfigError with a single-line message naming the
parameter (or preset). Defaults are those of the spec's table (spec/gmapping.md, section 6).
"""

from __future__ import annotations

import math

import pytest
from pydantic import ValidationError

from slamtrials.errors import ConfigError
from slamtrials.record import LaserGeometry
from slamtrials.slam import get_algorithm, make_algorithm, resolve_config
from slamtrials.slam.gmapping import GMapping, GMappingConfig

LASER = LaserGeometry.from_dict(
    {"angle_min": -2.35, "angle_increment": 0.0087, "range_min": 0.0, "range_max": 30.0, "mount": [0.0, 0.0, 0.0]}
)

#: slam_gmapping's defaults (spec table, column 1); maxUrange / maxRange: from the laser's range (None).
SLAM_GMAPPING_DEFAULTS = {
    "particles": 30,
    "linearUpdate": 1.0,
    "angularUpdate": 0.5,
    "temporalUpdate": -1.0,
    "srr": 0.1,
    "srt": 0.2,
    "str": 0.1,
    "stt": 0.2,
    "sigma": 0.05,
    "kernelSize": 1,
    "lstep": 0.05,
    "astep": 0.05,
    "iterations": 5,
    "lsigma": 0.075,
    "ogain": 3.0,
    "lskip": 0,
    "minimumScore": 0.0,
    "resampleThreshold": 0.5,
    "delta": 0.05,
    "maxUrange": None,
    "maxRange": None,
    "occ_thresh": 0.25,
    "map_update_interval": 5.0,
}
#: The seed paper's system (spec table, column 2): what differs from the defaults.
PAPER = {
    "particles": 40,
    "angularUpdate": 0.25,
    "srr": 0.01,
    "srt": 0.02,
    "str": 0.01,
    "stt": 0.02,
    "maxUrange": 30.0,
    "maxRange": 60.0,
}


def test_registered_under_gmapping():
    assert get_algorithm("gmapping") is GMapping


def test_defaults_are_slam_gmappings():
    config = resolve_config(GMapping)
    for name, value in SLAM_GMAPPING_DEFAULTS.items():
        assert getattr(config, name) == value, name
    assert config.free_cell_test is False  # behaves like the original code by default
    assert config.initial_pose is None
    # maxUrange defaults to the laser's range, maxRange to slam_gmapping's range_max - 0.01: a reading at
    # the sensor's maximum (no return) is skipped
    algorithm = make_algorithm("gmapping", LASER)
    assert algorithm.max_urange == LASER.range_max and algorithm.max_range == LASER.range_max - 0.01


def test_paper_preset_has_the_spec_values_and_defaults_elsewhere():
    config = resolve_config(GMapping, preset="paper")
    for name, value in SLAM_GMAPPING_DEFAULTS.items():
        assert getattr(config, name) == PAPER.get(name, value), name
    assert config.temporalUpdate < 0  # the launch file misspelt it: off
    assert config.linearUpdate == 1.0 and config.resampleThreshold == 0.5 and config.minimumScore == 0.0
    # overrides apply on top of the preset
    assert resolve_config(GMapping, preset="paper", overrides={"particles": 5}).particles == 5


def _error(**kwargs) -> str:
    with pytest.raises(ConfigError) as info:
        make_algorithm("gmapping", LASER, **kwargs)
    message = str(info.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize(
    "overrides, named",
    [
        ({"bogus": 1}, "bogus"),
        ({"particels": 30}, "particels"),
        ({"particles": 0}, "particles"),
        ({"srr": -0.1}, "srr"),
        ({"sigma": 0.0}, "sigma"),
        ({"resampleThreshold": 1.5}, "resampleThreshold"),
        ({"delta": 0.0}, "delta"),
        ({"kernelSize": 1.5}, "kernelSize"),
        ({"lstep": "far"}, "lstep"),
        ({"occ_thresh": 1.0}, "occ_thresh"),
        ({"maxUrange": -1.0}, "maxUrange"),
        ({"initial_pose": [0.0, 0.0, math.nan]}, "initial_pose"),
    ],
)
def test_bad_parameters_raise_one_line_errors_naming_them(overrides, named):
    message = _error(overrides=overrides)
    assert named in message
    assert "gmapping" in message


def test_bad_value_message_says_what_is_allowed():
    message = _error(overrides={"particles": 0})
    assert "particles = 0" in message and ">= 1" in message


@pytest.mark.parametrize(
    "kwargs",
    [
        {"overrides": {"maxUrange": 40.0, "maxRange": 30.0}},
        {"preset": "paper", "overrides": {"maxUrange": 70.0}},  # the preset's maxRange is 60 m
    ],
)
def test_max_urange_above_max_range_is_refused(kwargs):
    message = _error(**kwargs)
    assert "maxUrange" in message and "maxRange" in message


def test_max_urange_equal_to_max_range_is_fine():
    config = resolve_config(GMapping, overrides={"maxUrange": 30.0, "maxRange": 30.0})
    assert config.maxUrange == config.maxRange == 30.0


def test_unknown_preset_is_refused_listing_the_presets():
    message = _error(preset="fast")
    assert "'fast'" in message and "paper" in message


def test_config_is_frozen_and_forbids_extra_fields():
    config = GMappingConfig()
    with pytest.raises(ValidationError):
        config.particles = 3  # type: ignore[misc]
    with pytest.raises(ValidationError):
        GMappingConfig(bogus=1)  # type: ignore[call-arg]
