"""Scripted waypoint runs: completion, timeout, stall, determinism, recorded metadata."""

from __future__ import annotations

import json

import numpy as np
import pytest

from slamtrials.errors import SimulationError
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.worlds.world import World


def two_rooms() -> World:
    """A 12 m x 8 m floor with a wall across the middle and a 1.2 m door in it."""
    res = 0.05
    occ = np.zeros((160, 240), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[:, 120] = True
    occ[60:84, 120] = False  # the door: y from 3.8 to 5.0 m
    return World(occ, res, name="two_rooms", start=[2.0, 2.0, 0.0])


ROUTE = [[4.0, 2.0], [4.0, 4.4], [9.0, 4.4], [9.0, 6.5], [10.5, 6.5]]


def test_route_through_a_door_completes():
    world = two_rooms()
    rec = simulate_waypoints(world, ROUTE, seed=3)
    meta = rec.metadata
    assert meta["outcome"] == "completed"
    assert meta["waypoints_reached"] == len(ROUTE)
    assert meta["seed"] == 3 and meta["world"] == "two_rooms"
    assert np.hypot(*(rec.truth[-1, :2] - ROUTE[-1])) < 0.2
    assert not rec.stalled.any()
    assert rec.t[0] == 0.0 and np.allclose(np.diff(rec.t), 0.1)
    assert rec.scans.shape == (len(rec), 541) and rec.scans.dtype == np.float32
    np.testing.assert_array_equal(rec.odometry[0], [0.0, 0.0, 0.0])
    assert rec.laser.range_max == 80.0
    json.dumps(meta)


def test_same_seed_same_record_and_different_seed_different_odometry():
    world = two_rooms()
    a = simulate_waypoints(world, ROUTE[:2], seed=7)
    b = simulate_waypoints(world, ROUTE[:2], seed=7)
    c = simulate_waypoints(world, ROUTE[:2], seed=8)
    for name in ("t", "scans", "odometry", "truth", "stalled"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.metadata["bias"] != c.metadata["bias"]
    # The controller uses the true pose, so the true path does not depend on the bias.
    np.testing.assert_array_equal(a.truth, c.truth)
    assert not np.array_equal(a.odometry, c.odometry)


def test_timeout():
    rec = simulate_waypoints(two_rooms(), ROUTE, seed=1, max_time=5.0)
    assert rec.metadata["outcome"] == "timeout"
    assert rec.metadata["waypoints_reached"] < len(ROUTE)
    assert rec.t[-1] == pytest.approx(5.0)
    assert len(rec) == 51


def test_stalled_against_a_wall():
    # Straight through the middle wall, away from the door: the robot bumps and gives up after 5 s.
    rec = simulate_waypoints(two_rooms(), [[9.0, 1.5]], seed=1, max_time=120.0)
    assert rec.metadata["outcome"] == "stalled"
    assert rec.metadata["waypoints_reached"] == 0
    assert rec.stalled[-51:].all()
    assert rec.truth[-1, 0] < 6.0 - 0.15 + 1e-9


def test_no_waypoints_is_an_empty_completed_run():
    rec = simulate_waypoints(two_rooms(), np.zeros((0, 2)), seed=1)
    assert rec.metadata["outcome"] == "completed" and len(rec) == 1


def test_generator_seed_is_recorded_as_none():
    rec = simulate_waypoints(two_rooms(), ROUTE[:1], seed=np.random.default_rng(2))
    assert rec.metadata["seed"] is None and rec.metadata["outcome"] == "completed"


def test_custom_config_is_recorded():
    cfg = SimConfig(dt=0.05)
    rec = simulate_waypoints(two_rooms(), ROUTE[:1], cfg, seed=2)
    assert rec.metadata["sim_config"]["dt"] == 0.05
    assert np.allclose(np.diff(rec.t), 0.05)


@pytest.mark.parametrize("bad", [[[1.0, np.nan]], [1.0, 2.0, 3.0], [[1.0, 2.0, 3.0]]])
def test_bad_waypoints(bad):
    with pytest.raises(SimulationError, match="waypoints"):
        simulate_waypoints(two_rooms(), bad, seed=1)


def test_bad_limits():
    with pytest.raises(SimulationError, match="tolerance"):
        simulate_waypoints(two_rooms(), ROUTE, seed=1, tolerance=0.0)
    with pytest.raises(SimulationError, match="max_time"):
        simulate_waypoints(two_rooms(), ROUTE, seed=1, max_time=-1.0)
