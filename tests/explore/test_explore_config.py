"""ExploreConfig and TerminationConfig: defaults, validation, dict loading."""

from __future__ import annotations

import math

import pytest
from pydantic import ValidationError

from slamtrials.errors import ConfigError
from slamtrials.explore import ExploreConfig, RobotLimits, TerminationConfig
from slamtrials.explore.config import ROBOT_FIELDS, lethal_distance


def test_explore_defaults_follow_the_paper():
    cfg, robot = ExploreConfig(), RobotLimits()
    assert robot.radius == 0.15
    assert robot.max_linear_speed == 0.7
    assert math.isclose(robot.max_angular_speed, math.radians(70.0))
    assert robot.max_linear_accel == 0.5
    assert math.isclose(robot.max_angular_accel, math.radians(100.0))
    assert robot.control_period == 0.1
    assert cfg.goal_timeout == 30.0
    assert math.isclose(lethal_distance(cfg, robot), robot.radius + cfg.inflation_margin)


@pytest.mark.parametrize("name", ROBOT_FIELDS)
def test_robot_fields_are_refused_naming_sim_robot(name):
    with pytest.raises(ConfigError, match=f"{name} is a property of the robot: set it in sim.robot"):
        ExploreConfig.from_dict({name: 0.5})


def test_robot_limits_must_be_positive():
    with pytest.raises(ValueError, match="RobotLimits.max_linear_speed"):
        RobotLimits(max_linear_speed=0.0)


def test_termination_defaults_follow_the_paper():
    cfg = TerminationConfig()
    assert (cfg.small_period, cfg.large_period) == (120.0, 600.0)
    assert cfg.mse_threshold == 10.0 and cfg.channels == 3 and cfg.downscale == 4
    assert cfg.max_snapshots == 19
    assert cfg.size_threshold == 1000.0


@pytest.mark.parametrize("cls", [ExploreConfig, TerminationConfig])
def test_every_field_is_described(cls):
    for name, field in cls.model_fields.items():
        assert field.description, name


def test_from_dict_round_trip():
    cfg = ExploreConfig.from_dict({"inflation_margin": 0.1, "replan_period": 5.0})
    assert cfg.inflation_margin == 0.1 and cfg.replan_period == 5.0
    assert ExploreConfig.from_dict(cfg.model_dump()) == cfg
    term = TerminationConfig.from_dict({"small_period": 60})
    assert term.small_period == 60.0
    assert TerminationConfig.from_dict(term.model_dump()) == term


@pytest.mark.parametrize(
    ("cls", "data", "word"),
    [
        (ExploreConfig, {"inflation_margin": -1.0}, "inflation_margin"),
        (ExploreConfig, {"no_such_field": 1}, "no_such_field"),
        (ExploreConfig, {"replan_period": 1.0, "min_replan_interval": 2.0}, "min_replan_interval"),
        (TerminationConfig, {"downscale": 0}, "downscale"),
        (TerminationConfig, {"mse_threshold": "much"}, "mse_threshold"),
    ],
)
def test_from_dict_rejects_bad_values_naming_the_field(cls, data, word):
    with pytest.raises(ConfigError, match=word):
        cls.from_dict(data)


def test_configs_are_frozen():
    cfg = ExploreConfig()
    with pytest.raises(ValidationError):
        cfg.inflation_margin = 1.0  # type: ignore[misc]
