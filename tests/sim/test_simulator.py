"""The Simulator front: frames, time, determinism, metadata, configuration validation."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from pydantic import ValidationError

from slamtrials.errors import ConfigError, SimulationError
from slamtrials.record import RunRecord
from slamtrials.sim import LaserConfig, OdometryConfig, RobotConfig, SimConfig, Simulator
from slamtrials.sim.config import LASER_ERROR_FIELDS, ODOMETRY_ERROR_FIELDS
from slamtrials.sim.profiles import DEFAULT_PROFILE


def room_world(size_m: float = 10.0, resolution: float = 0.05):
    from slamtrials.worlds.world import World

    n = int(round(size_m / resolution))
    occ = np.zeros((n, n), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[n // 3, n // 4 : n // 2] = True  # something to see
    return World(occ, resolution, name="room", start=[3.0, 3.0, 0.5])


COMMANDS = [(0.5, 0.2)] * 30 + [(0.7, -0.4)] * 30 + [(0.0, 1.0)] * 10 + [(0.4, 0.0)] * 30


def run(seed, config: SimConfig | None = None, commands=COMMANDS) -> RunRecord:
    sim = Simulator(room_world(), config or SimConfig.paper(), np.random.default_rng(seed))
    frames = [sim.observe()] + [sim.step(c) for c in commands]
    return RunRecord.from_frames(frames, sim.laser, sim.metadata)


def test_first_frame():
    world = room_world()
    sim = Simulator(world, SimConfig.paper(), np.random.default_rng(0))
    f = sim.observe()
    assert f.t == 0.0 and sim.t == 0.0
    np.testing.assert_array_equal(f.truth, world.start)
    np.testing.assert_array_equal(f.odometry, [0.0, 0.0, 0.0])
    assert f.ranges.dtype == np.float32 and f.ranges.shape == (541,)
    assert not f.stalled
    assert sim.observe() is f  # observing again changes nothing


def test_time_advances_by_dt():
    sim = Simulator(room_world(), SimConfig(dt=0.05), np.random.default_rng(0))
    frames = [sim.step((0.1, 0.0)) for _ in range(7)]
    assert [f.t for f in frames] == [k * 0.05 for k in range(1, 8)]
    assert sim.steps == 7 and sim.t == pytest.approx(0.35)
    assert frames[-1] is sim.observe()


def test_same_seed_same_run_bitwise():
    cfg = SimConfig(
        laser=LaserConfig(range_noise_std=0.01),
        odometry=OdometryConfig(noise_linear_per_m=0.02, noise_angular_per_rad=0.05),
    )
    a = run(11, cfg)
    b = run(11, cfg)
    for name in ("t", "scans", "odometry", "truth", "stalled"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.metadata == b.metadata


def test_different_seed_different_bias():
    a = run(1)
    b = run(2)
    assert a.metadata["bias"] != b.metadata["bias"]
    np.testing.assert_array_equal(a.truth, b.truth)  # same commands, same true path (no collisions here)
    assert not np.array_equal(a.odometry, b.odometry)
    np.testing.assert_array_equal(a.scans, b.scans)  # noise-free laser


def test_generator_and_seed_give_the_same_run():
    world = room_world()
    a = Simulator(world, SimConfig.paper(), 5)
    b = Simulator(world, SimConfig.paper(), np.random.default_rng(5))
    assert a.bias == b.bias


def test_metadata_and_laser_info():
    sim = Simulator(room_world(), SimConfig.paper(), np.random.default_rng(3))
    meta = sim.metadata
    json.dumps(meta)
    assert meta["world"] == "room"
    assert set(meta["bias"]) == {"linear", "angular"}
    assert abs(meta["bias"]["linear"]) <= 0.005 and abs(meta["bias"]["angular"]) <= math.radians(1)
    assert SimConfig.model_validate(meta["sim_config"]) == sim.config
    info = sim.laser
    assert info.angle_min == pytest.approx(-math.radians(135))
    assert info.angle_increment == pytest.approx(math.radians(0.5))
    assert info.range_max == 80.0 and info.range_min == 0.0


def test_accessors_return_copies():
    sim = Simulator(room_world(), SimConfig.paper(), np.random.default_rng(3))
    truth = sim.truth
    truth[0] = 99.0
    assert sim.truth[0] != 99.0
    assert sim.bias is not sim.bias


def test_bad_commands_and_start():
    sim = Simulator(room_world(), SimConfig.paper(), np.random.default_rng(3))
    with pytest.raises(SimulationError, match="finite"):
        sim.step((math.nan, 0.0))
    with pytest.raises(SimulationError, match="two numbers"):
        sim.step((1.0,))
    with pytest.raises(SimulationError, match="overlaps a wall"):
        Simulator(room_world(), SimConfig.paper(), np.random.default_rng(3), start=[0.1, 0.1, 0.0])
    with pytest.raises(TypeError):
        Simulator(room_world(), SimConfig.paper(), "seed")  # type: ignore[arg-type]


def test_scan_matches_the_truth():
    # The frame's scan is the laser seen from the frame's true pose.
    from slamtrials.sim.raycast import LaserModel

    world = room_world()
    sim = Simulator(world, SimConfig.paper(), np.random.default_rng(3))
    for _ in range(20):
        f = sim.step((0.6, 0.3))
    np.testing.assert_array_equal(f.ranges, LaserModel(world, LaserConfig()).true_ranges(f.truth))


# --- configuration ---------------------------------------------------------------------------------------


def test_paper_config_is_explicit_and_realistic_the_default():
    cfg = SimConfig.paper()
    assert cfg == SimConfig(profile="paper") and cfg.profile_label == "paper" and not cfg.laser.has_errors
    default = SimConfig()
    assert default.profile_name == DEFAULT_PROFILE == "realistic" and default.profile_label == "realistic"
    assert default.laser.has_errors and default.model_copy(update={"profile": "paper"}) != cfg
    # everything but the error models is the paper's in both
    errors = {*LASER_ERROR_FIELDS, *ODOMETRY_ERROR_FIELDS, "profile"}
    assert {k: v for k, v in default.laser.model_dump().items() if k not in errors} == {
        k: v for k, v in cfg.laser.model_dump().items() if k not in errors
    }
    assert default.robot == cfg.robot and default.dt == cfg.dt
    assert cfg.dt == 0.1
    assert cfg.laser.num_beams == 541 and cfg.laser.max_range == 80.0
    assert cfg.laser.fov == pytest.approx(math.radians(270))
    assert cfg.robot.max_linear_speed == 0.7
    assert cfg.robot.max_angular_speed == pytest.approx(math.radians(70))
    assert cfg.robot.radius == 0.15
    assert cfg.odometry.bias_angular_range == pytest.approx((-math.radians(1), math.radians(1)))


@pytest.mark.parametrize(
    "model, kwargs, field",
    [
        (RobotConfig, {"radius": -0.1}, "radius"),
        (RobotConfig, {"max_linear_speed": 0.0}, "max_linear_speed"),
        (LaserConfig, {"fov": 7.0}, "fov"),
        (LaserConfig, {"max_range": -1.0}, "max_range"),
        (LaserConfig, {"mount": (0.0, math.inf, 0.0)}, "mount"),
        (LaserConfig, {"min_range": 90.0}, "min_range"),
        (OdometryConfig, {"bias_linear_range": (0.01, -0.01)}, "bias_linear_range"),
        (OdometryConfig, {"noise_linear_per_m": -1.0}, "noise_linear_per_m"),
        (SimConfig, {"dt": 0.0}, "dt"),
    ],
)
def test_invalid_values_name_the_field(model, kwargs, field):
    with pytest.raises(ValidationError) as info:
        model(**kwargs)
    assert field in str(info.value)


def test_configs_are_strict_and_frozen():
    with pytest.raises(ValidationError, match="extra"):
        RobotConfig(radus=0.2)
    cfg = SimConfig.paper()
    with pytest.raises(ValidationError):
        cfg.dt = 0.2  # type: ignore[misc]


def test_from_dict_gives_a_one_line_config_error():
    cfg = SimConfig.from_dict({"dt": 0.05, "laser": {"fov": 3.0}})
    assert cfg.dt == 0.05 and cfg.laser.fov == 3.0
    with pytest.raises(ConfigError) as info:
        SimConfig.from_dict({"robot": {"radius": -1}})
    message = str(info.value)
    assert "robot.radius" in message and "greater than 0" in message and "-1" in message
    assert "\n" not in message


def test_config_round_trips_through_json():
    cfg = SimConfig(laser=LaserConfig(mount=(0.1, 0.0, 0.2)), odometry=OdometryConfig(bias_linear=0.002))
    again = SimConfig.model_validate_json(cfg.model_dump_json())
    assert again == cfg
