"""A simulation config is its error profile plus overrides: which values override, the label, the written
form that follows the profile's name, and the one warning line."""

from __future__ import annotations

import logging

import pytest

from slamtrials.sim import LaserConfig, SimConfig
from slamtrials.sim.overrides import ProfileOverride, profile_label, profile_summary, warn_overrides, written_form
from slamtrials.sim.profiles import BUNDLED_PROFILES, DEFAULT_PROFILE

REALISTIC = BUNDLED_PROFILES["realistic"]


def test_a_config_that_is_its_profile_has_no_overrides():
    for config in (SimConfig(), SimConfig.paper(), SimConfig(profile="mit-csail")):
        assert config.profile_overrides == () and config.profile_label == config.profile_name
    assert SimConfig().profile_label == DEFAULT_PROFILE


def test_values_that_differ_from_the_profile_are_overrides_and_equal_ones_are_not():
    same = REALISTIC.laser_values()["dropout_rate"]
    config = SimConfig.model_validate(
        {
            "profile": "realistic",
            "laser": {"dropout_rate": same, "range_noise_std": 0.5, "fov": 3.0},  # fov: not an error field
            "odometry": {
                "bias_linear_range": [-0.01, 0.01],
                "bias_angular_range": list(REALISTIC.odometry["bias_angular_range"]),
            },
        }
    )
    assert config.profile_overrides == (
        ProfileOverride("laser.range_noise_std", 0.5, REALISTIC.laser_values()["range_noise_std"]),
        ProfileOverride("odometry.bias_linear_range", (-0.01, 0.01), REALISTIC.odometry["bias_linear_range"]),
    )
    assert profile_label(config) == config.profile_label == "realistic + 2 overrides"
    one = SimConfig(profile="paper", laser=LaserConfig(short_rate=0.1))
    assert one.profile_label == "paper + 1 override"
    summary = profile_summary(config)
    assert summary == {
        "name": "realistic",
        "label": "realistic + 2 overrides",
        "overrides": {"laser.range_noise_std": 0.5, "odometry.bias_linear_range": [-0.01, 0.01]},
    }
    # a stored config holds every value: reading it back gives the same overrides
    assert SimConfig.model_validate(config.model_dump(mode="json")).profile_overrides == config.profile_overrides


def test_the_written_form_holds_the_name_and_only_the_overrides_so_the_name_sets_every_value():
    default = written_form(SimConfig())
    assert default["profile"] == "realistic"
    assert not set(default["laser"]) & set(REALISTIC.laser_values()) and "noise_linear_per_m" not in default["odometry"]
    assert SimConfig.model_validate(default) == SimConfig()
    edited = SimConfig.model_validate({**default, "profile": "paper"})  # the name edited, nothing else
    assert edited == SimConfig.paper() and not edited.laser.has_errors
    changed = SimConfig.model_validate({"laser": {"short_rate": 0.1}})
    written = written_form(changed)
    assert written["laser"]["short_rate"] == 0.1 and "dropout_rate" not in written["laser"]
    assert SimConfig.model_validate(written) == changed
    assert SimConfig.model_validate({**written, "profile": "paper"}).laser.short_rate == 0.1  # the override stays


def test_one_warning_line_names_the_overriding_keys(caplog):
    config = SimConfig.model_validate({"profile": "realistic", "laser": {"dropout_rate": 0.0, "short_rate": 0.0}})
    with caplog.at_level(logging.WARNING, logger="slamtrials.sim.overrides"):
        found = warn_overrides(config, "c.yaml")
        assert warn_overrides(SimConfig(), "d.yaml") == ()
    assert [o.key for o in found] == ["laser.short_rate", "laser.dropout_rate"]
    assert [r.getMessage() for r in caplog.records] == [
        "c.yaml: keys that override profile realistic: sim.laser.short_rate, sim.laser.dropout_rate"
    ]


@pytest.mark.parametrize("profile", ["paper", "realistic", "mit-csail", "fr079"])
def test_every_bundled_profile_written_and_read_back_is_itself(profile):
    config = SimConfig(profile=profile)
    assert SimConfig.model_validate(written_form(config)) == config and config.profile_overrides == ()
