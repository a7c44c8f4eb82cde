"""Karto's parameters: slam_toolbox's names and defaults, validated with their ranges."""

from __future__ import annotations

import pytest

from slamtrials.errors import ConfigError
from slamtrials.slam import get_algorithm, resolve_config
from slamtrials.slam.karto import KartoConfig

#: mapper_params_online_async.yaml (slam_toolbox), the parameters Karto uses.
SLAM_TOOLBOX_DEFAULTS = {
    "resolution": 0.05,
    "max_laser_range": 20.0,
    "map_update_interval": 5.0,
    "minimum_time_interval": 0.5,
    "scan_throttle": True,
    "use_scan_matching": True,
    "use_scan_barycenter": True,
    "minimum_travel_distance": 0.5,
    "minimum_travel_heading": 0.5,
    "scan_buffer_size": 10,
    "scan_buffer_maximum_scan_distance": 10.0,
    "link_match_minimum_response_fine": 0.1,
    "link_scan_maximum_distance": 1.5,
    "loop_search_maximum_distance": 3.0,
    "do_loop_closing": True,
    "loop_match_minimum_chain_size": 10,
    "loop_match_maximum_variance_coarse": 3.0,
    "loop_match_minimum_response_coarse": 0.35,
    "loop_match_minimum_response_fine": 0.45,
    "correlation_search_space_dimension": 0.5,
    "correlation_search_space_resolution": 0.01,
    "correlation_search_space_smear_deviation": 0.1,
    "loop_search_space_dimension": 8.0,
    "loop_search_space_resolution": 0.05,
    "loop_search_space_smear_deviation": 0.03,
    "distance_variance_penalty": 0.5,
    "angle_variance_penalty": 1.0,
    "fine_search_angle_offset": 0.00349,
    "coarse_search_angle_offset": 0.349,
    "coarse_angle_resolution": 0.0349,
    "minimum_angle_penalty": 0.9,
    "minimum_distance_penalty": 0.5,
    "use_response_expansion": True,
}


def test_defaults_are_slam_toolboxs():
    config = KartoConfig().model_dump()
    for name, value in SLAM_TOOLBOX_DEFAULTS.items():
        assert config[name] == value, name


def test_unknown_parameter_is_refused_by_name():
    with pytest.raises(ConfigError, match="no parameter scan_bufer_size"):
        resolve_config(get_algorithm("karto"), overrides={"scan_bufer_size": 5})


@pytest.mark.parametrize(
    ("name", "value", "expected"),
    [
        ("minimum_travel_distance", -0.1, ">= 0"),
        ("loop_match_minimum_response_fine", 1.5, "<= 1"),
        ("correlation_search_space_resolution", 0.0, ">= 0.001"),
        ("scan_buffer_size", 0, ">= 1"),
    ],
)
def test_out_of_range_value_names_parameter_value_and_range(name, value, expected):
    with pytest.raises(ConfigError) as info:
        resolve_config(get_algorithm("karto"), overrides={name: value})
    message = str(info.value)
    assert name in message and repr(value) in message and expected in message


def test_smear_deviation_must_fit_karto_kernel_bounds():
    with pytest.raises(ConfigError, match="between 0.5 and 10 times"):
        resolve_config(get_algorithm("karto"), overrides={"correlation_search_space_smear_deviation": 0.2})


def test_presets_are_the_defaults():
    cls = get_algorithm("karto")
    assert resolve_config(cls, preset="paper") == resolve_config(cls)


def test_slam_karto_preset_is_slam_karto_s_mapper_params():
    # slam_karto's config/mapper_params.yaml (open_karto's own defaults); slam_karto has no scan gate,
    # and Karto makes a node of any scan minimum_time_interval after the last, so 3600 s is kept as is
    config = resolve_config(get_algorithm("karto"), preset="slam_karto")
    expected = {
        "minimum_travel_distance": 0.2,
        "minimum_travel_heading": 0.174,
        "scan_buffer_size": 70,
        "scan_buffer_maximum_scan_distance": 20.0,
        "link_match_minimum_response_fine": 0.8,
        "link_scan_maximum_distance": 10.0,
        "loop_search_maximum_distance": 4.0,
        "loop_match_maximum_variance_coarse": 0.4,
        "loop_match_minimum_response_coarse": 0.8,
        "loop_match_minimum_response_fine": 0.8,
        "correlation_search_space_dimension": 0.3,
        "correlation_search_space_smear_deviation": 0.03,
        "distance_variance_penalty": 0.3,
        "angle_variance_penalty": 0.349,
        "use_response_expansion": False,
        "minimum_time_interval": 3600.0,
        "scan_throttle": False,
        "loop_search_space_dimension": 8.0,
        "coarse_angle_resolution": 0.0349,
    }
    dumped = config.model_dump()
    for name, value in expected.items():
        assert dumped[name] == value, name
