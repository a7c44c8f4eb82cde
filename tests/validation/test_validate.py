"""Validation: a run recorded along a given path, the replica's laser geometry, and a simulated run's
replica reproducing the run's own errors."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.errors import ConfigError
from slamtrials.metric.sampling import relations_between
from slamtrials.record import OCCUPIED, UNKNOWN, LaserGeometry, OccupancyGrid, Relations, Trajectory
from slamtrials.seeding import run_streams
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.sim.config import ErrorProfile
from slamtrials.sim.pathreplay import simulate_path
from slamtrials.validation import (
    Replica,
    ValidationSettings,
    frame_pairs,
    laser_config_for,
    replica_config,
    validate,
    world_from_map,
)
from slamtrials.worlds import World

NOISY = ErrorProfile(
    name="noisy",
    laser={"range_noise_std": 0.02, "range_noise_per_m": 0.005, "short_rate": 0.02, "dropout_rate": 0.02},
    odometry={
        "bias_linear_range": (-0.02, 0.02),
        "bias_angular_range": (-0.05, 0.05),
        "noise_linear_per_m": 0.05,
        "noise_angular_per_rad": 0.05,
        "noise_angular_per_m": 0.02,
    },
)
GMAPPING_SMALL = {"particles": 5}


def _world() -> World:
    occ = np.ones((80, 140), bool)
    occ[10:70, 10:130] = False  # a 6 m x 3 m room
    occ[10:35, 60:63] = True  # a wall sticking in
    occ[50:70, 95:98] = True
    return World(occ, 0.05, name="room", start=np.array([1.0, 1.0, 0.0]))


@pytest.fixture(scope="module")
def drive():
    """A path driven by the simulator with the noisy profile (seed 3)."""
    world = _world()
    config = SimConfig.from_dict({"profile": NOISY})
    record = simulate_waypoints(world, [[5.5, 1.0], [5.5, 2.6], [1.0, 2.6], [1.0, 1.2]], config, seed=3, max_time=80)
    return world, config, record


def test_simulate_path_reproduces_the_simulators_frames(drive):
    world, config, driven = drive
    replayed = simulate_path(world, driven.t, driven.truth, config, 3)
    assert np.array_equal(replayed.scans, driven.scans)
    assert np.array_equal(replayed.odometry, driven.odometry)
    assert np.array_equal(replayed.truth, driven.truth)
    assert replayed.metadata["bias"] == driven.metadata["bias"]
    assert replayed.laser == driven.laser


@pytest.mark.slow  # by simulation: 600 replayed paths
def test_simulate_path_draws_the_same_odometry_noise_per_metre_whatever_the_frame_rate():
    """The profile's noise is a random walk per metre (issue 32); a path replayed at 0.4 s steps
    accumulates as much of it as at 0.1 s: the arc-length error over 5 m has the same spread at both
    rates (tests/sim/test_pathreplay.py has irregular stamps)."""
    world = _world()
    only_noise = ErrorProfile(
        name="n",
        odometry={"noise_linear_per_m": 0.05, "bias_linear_range": (0.0, 0.0), "bias_angular_range": (0.0, 0.0)},
    )
    config = SimConfig.from_dict({"profile": only_noise, "laser": {"fov": 0.2, "angular_resolution": 0.1}})
    spreads = {}
    for step in (0.1, 0.4):
        t = np.arange(0.0, 20.0 + 1e-9, step)
        path = np.column_stack([1.0 + 0.25 * t, np.full(t.size, 1.5), np.zeros(t.size)])  # 0.25 m/s for 5 m
        ends = [simulate_path(world, t, path, config, seed).odometry[-1, 0] for seed in range(300)]
        spreads[step] = float(np.std(ends, ddof=1))
    # 0.05 m/sqrt(m) over 5 m: std 0.05 * sqrt(5) = 0.112 m
    assert spreads[0.1] == pytest.approx(0.05 * 5.0**0.5, rel=0.15)
    assert spreads[0.4] == pytest.approx(spreads[0.1], rel=0.2)


def test_simulate_path_refuses_bad_paths(drive):
    world, config, driven = drive
    from slamtrials.errors import SimulationError

    with pytest.raises(SimulationError, match="strictly increasing"):
        simulate_path(world, driven.t[::-1].copy(), driven.truth, config, 0)
    with pytest.raises(SimulationError, match="shapes"):
        simulate_path(world, driven.t, driven.truth[:-1], config, 0)


@pytest.mark.parametrize(
    ("geometry", "beams"),
    [
        (LaserGeometry(-np.pi / 2, np.pi / 360, 0.0, 81.91), 361),  # MIT CSAIL's SICK
        (LaserGeometry(-2.0, 0.01, 0.1, 20.0, (0.1, 0.02, 0.05)), 300),  # asymmetric, mounted off-centre
    ],
)
def test_laser_config_casts_the_logs_beams(geometry, beams):
    config = laser_config_for(geometry, beams)
    assert config.num_beams == beams
    recorded = geometry.mount[2] + geometry.beam_angles(beams)
    np.testing.assert_allclose(config.mount[2] + config.angles, recorded, rtol=0, atol=1e-12)
    assert config.mount[:2] == pytest.approx(geometry.mount[:2], abs=1e-12)
    assert (config.max_range, config.min_range) == (geometry.range_max, geometry.range_min)


def test_laser_config_of_a_simulated_laser_is_that_laser():
    laser = SimConfig().laser
    config = laser_config_for(laser.geometry(), laser.num_beams)
    assert np.array_equal(config.angles, laser.angles) and config.mount == laser.mount


def test_replica_world_makes_unknown_cells_walls():
    grid = np.full((20, 30), UNKNOWN, dtype=np.int8)
    grid[5:15, 5:25] = 0
    grid[5:15, 15] = OCCUPIED
    world = world_from_map(OccupancyGrid(grid, 0.1, np.array([-1.0, -2.0, 0.0])), start=np.array([0.0, -1.0, 0.3]))
    assert np.array_equal(world.occupied, grid != 0)
    assert world.start.tolist() == [0.0, -1.0, 0.3]
    np.testing.assert_array_equal(world.origin, [-1.0, -2.0, 0.0])
    with pytest.raises(ConfigError, match="no free cell"):
        world_from_map(OccupancyGrid(np.full((4, 4), UNKNOWN, np.int8), 0.1, np.zeros(3)))


def test_frame_pairs_take_the_nearest_frames_within_the_tolerance():
    t = np.arange(10, dtype=float) * 0.2 + 100.0
    rel = Relations(
        t1=np.array([100.01, 100.0, 100.39, 105.0]),
        t2=np.array([100.62, 100.05, 101.0, 100.2]),
        delta=np.zeros((4, 3)),
    )
    first, second = frame_pairs(t, rel, 0.1)
    # relation 1 falls on one frame twice, relation 3's t1 is far from every frame
    assert first.tolist() == [0, 2] and second.tolist() == [3, 5]


def test_replica_of_a_simulated_run_reproduces_its_errors(drive):
    """A "real" run recorded along a path with a profile, replicated with its true world and path: the
    replica with the real run's seed is that run, so its errors are the real errors exactly."""
    world, _, driven = drive
    t, path = driven.t, driven.truth
    laser = laser_config_for(driven.laser, driven.scans.shape[1])
    replica = Replica(world=world, t=t, truth=path, laser=laser)
    real = simulate_path(
        world, t, path, replica_config(replica, NOISY), np.random.default_rng(run_streams(0).simulator)
    )
    rng = np.random.default_rng(5)
    i = np.sort(rng.choice(len(t) - 20, size=60, replace=False), kind="stable")
    relations = relations_between(Trajectory(t=t, poses=path), i, i + rng.integers(5, 20, size=60))
    settings = ValidationSettings(algorithm="gmapping", overrides=GMAPPING_SMALL, runs=2, reference_seed=0)
    result = validate(real, relations, NOISY, settings, replica=replica)
    same = result.replicas[0]
    assert same.seed == 0
    assert same.slam == result.real_slam and same.odometry == result.real_odometry
    assert result.relations_replica == len(relations) == result.real_slam.relations
    assert result.blocked == 0
    other = result.replicas[1]
    assert other.odometry.translational != result.real_odometry.translational  # another seed: other errors
    spread = result.simulated("odometry", "translational")
    assert spread.values == (same.odometry.translational, other.odometry.translational)
    assert spread.mean == pytest.approx(np.mean(spread.values)) and spread.std == pytest.approx(
        np.std(spread.values, ddof=1)
    )


def test_replicas_without_errors_have_exact_odometry(drive):
    world, _, driven = drive
    exact = ErrorProfile(name="exact", odometry={"bias_linear_range": (0.0, 0.0), "bias_angular_range": (0.0, 0.0)})
    replica = Replica(world, driven.t, driven.truth, laser_config_for(driven.laser, driven.scans.shape[1]))
    relations = relations_between(Trajectory(t=driven.t, poses=driven.truth), np.array([0, 10]), np.array([40, 90]))
    result = validate(driven, relations, exact, ValidationSettings(algorithm="odometry", runs=1), replica=replica)
    assert result.replicas[0].odometry.translational < 1e-9
    assert np.isnan(result.simulated("slam", "translational").std)  # one replica: no std


def test_relations_of_another_log_are_refused(drive):
    _, _, driven = drive
    far = Relations(t1=driven.t[:3] + 1e4, t2=driven.t[3:6] + 1e4, delta=np.zeros((3, 3)))
    with pytest.raises(ConfigError, match="does not belong to"):
        validate(driven, far, NOISY, ValidationSettings(algorithm="odometry", runs=1))


def test_validate_without_a_profile_takes_the_one_default_and_a_name_resolves(drive):
    from slamtrials.sim.profiles import BUNDLED_PROFILES, DEFAULT_PROFILE

    world, _, driven = drive
    replica = Replica(world, driven.t, driven.truth, laser_config_for(driven.laser, driven.scans.shape[1]))
    relations = relations_between(Trajectory(t=driven.t, poses=driven.truth), np.array([0, 10]), np.array([40, 90]))
    settings = ValidationSettings(algorithm="odometry", runs=1)
    default = validate(driven, relations, settings=settings, replica=replica)
    assert default.profile == BUNDLED_PROFILES[DEFAULT_PROFILE] and default.profile.name == "realistic"
    assert default.to_dict()["profile"]["name"] == "realistic"
    paper = validate(driven, relations, "paper", settings, replica=replica)
    assert paper.profile == BUNDLED_PROFILES["paper"]
    with pytest.raises(ConfigError, match="unknown error profile 'realstic'"):
        validate(driven, relations, "realstic", settings, replica=replica)
