"""Things not in the map that stay where a scan saw them (``short_lifetime``, :mod:`slamtrials.sim.unmapped`)."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.sim.config import LaserConfig
from slamtrials.sim.raycast import LaserModel

from .test_raycast import room_world

POSE = np.array([5.0, 5.0, 0.3])


def _ends(pose: np.ndarray, config: LaserConfig, ranges: np.ndarray) -> np.ndarray:
    """World-frame end points ``[B, 2]`` of the readings ``ranges`` from the laser at base ``pose``."""
    heading = pose[2] + config.angles
    return np.c_[pose[0] + ranges * np.cos(heading), pose[1] + ranges * np.sin(heading)]


def test_a_thing_seen_short_is_read_again_from_the_next_pose():
    config = LaserConfig(short_rate=0.15, short_run_beams=4.0, short_lifetime=3600.0)
    laser = LaserModel(room_world(size_m=20.0), config)
    rng = np.random.default_rng(3)
    first = laser.scan(POSE, rng, t=0.0).astype(float)
    true0 = laser.true_ranges(POSE).astype(float)
    moved = POSE + np.array([0.05, 0.02, 0.01])
    second = laser.scan(moved, rng, t=0.1).astype(float)
    true1 = laser.true_ranges(moved).astype(float)
    short0 = first < true0 - 1e-4
    short1 = second < true1 - 1e-4
    assert short0.sum() > 30
    # what the first scan read short, the second reads short again, within 5 cm
    ends0, ends1 = _ends(POSE, config, first)[short0], _ends(moved, config, second)[short1]
    nearest = np.min(np.hypot(*(ends0[:, None, :] - ends1[None, :, :]).transpose(2, 0, 1)), axis=1)
    assert np.mean(nearest < 0.05) > 0.9
    # without a lifetime the second scan's short readings are new things
    fresh = LaserModel(room_world(size_m=20.0), config.model_copy(update={"short_lifetime": 0.0}))
    rng = np.random.default_rng(3)
    a = fresh.scan(POSE, rng).astype(float)
    b = fresh.scan(moved, rng).astype(float)
    ends_a = _ends(POSE, config, a)[a < true0 - 1e-4]
    ends_b = _ends(moved, config, b)[b < true1 - 1e-4]
    nearest = np.min(np.hypot(*(ends_a[:, None, :] - ends_b[None, :, :]).transpose(2, 0, 1)), axis=1)
    assert np.mean(nearest < 0.05) < 0.3


def test_things_keep_the_short_rate_and_die_after_their_lifetime():
    config = LaserConfig(short_rate=0.1, short_run_beams=4.0, short_lifetime=2.0)
    laser = LaserModel(room_world(size_m=20.0), config)
    rng = np.random.default_rng(8)
    shares, left = [], []
    for k in range(300):  # the robot turns slowly on the spot, 10 scans per second
        pose = POSE + np.array([0.0, 0.0, 0.02 * k])
        reading = laser.scan(pose, rng, t=0.1 * k).astype(float)
        shares.append(np.mean(reading < laser.true_ranges(pose) - 1e-4))
        if k >= 60 and k % 40 == 0:  # what the living things have left to live
            assert np.all(laser._things.deaths > 0.1 * k)  # the dead are gone
            left.extend((laser._things.deaths - 0.1 * k).tolist())
    # the covered share is made up by fewer new runs: the rate holds (a run's beams behind their wall
    # read the wall, a little below 0.1, as without a lifetime)
    assert np.mean(shares[50:]) == pytest.approx(0.1, abs=0.015)
    # lifetimes are exponential with the given mean, so (memoryless) is what the living have left
    assert len(left) > 50
    assert np.mean(left) == pytest.approx(2.0, rel=0.3)


def test_the_lifetime_adds_one_draw_per_beam_whatever_the_scene():
    config = LaserConfig(
        range_noise_std=0.01, short_rate=0.1, short_run_beams=3.0, short_lifetime=1.0, dropout_rate=0.05
    )
    world = room_world(size_m=20.0)
    a, b = np.random.default_rng(5), np.random.default_rng(5)
    LaserModel(world, config).scan(np.array([2.0, 2.0, 0.0]), a, t=0.0)
    LaserModel(world, config).scan(np.array([15.0, 9.0, 2.0]), b, t=0.0)
    assert a.bit_generator.state == b.bit_generator.state
    without = np.random.default_rng(5)
    LaserModel(world, config.model_copy(update={"short_lifetime": 0.0})).scan(np.array([2.0, 2.0, 0.0]), without)
    without.random(config.num_beams)
    assert without.bit_generator.state == a.bit_generator.state


def test_a_lifetime_needs_the_scan_time_and_changes_nothing_without_short_readings():
    config = LaserConfig(short_rate=0.1, short_lifetime=1.0)
    laser = LaserModel(room_world(size_m=20.0), config)
    with pytest.raises(ValueError, match="time"):
        laser.scan(POSE, np.random.default_rng(0))
    quiet = LaserConfig(range_noise_std=0.01, short_lifetime=5.0)
    plain = LaserConfig(range_noise_std=0.01)
    world = room_world(size_m=20.0)
    got = LaserModel(world, quiet).scan(POSE, np.random.default_rng(1), t=0.0)
    want = LaserModel(world, plain).scan(POSE, np.random.default_rng(1))
    assert np.array_equal(got, want)
    assert not LaserConfig(short_lifetime=3.0).has_errors


def test_fleeting_runs_leave_no_thing_and_the_share_keeps_the_rate():
    world = room_world(size_m=20.0)
    base = LaserConfig(short_rate=0.1, short_run_beams=4.0, short_lifetime=3600.0)
    fleeting = base.model_copy(update={"short_fleeting_share": 0.75})
    runs = things = 0
    for seed in range(20):  # first scans: the same draws make the same runs; about 1 in 4 leaves a thing
        every, some = LaserModel(world, base), LaserModel(world, fleeting)
        a = every.scan(POSE, np.random.default_rng(seed), t=0.0)
        b = some.scan(POSE, np.random.default_rng(seed), t=0.0)
        assert np.array_equal(a, b)
        runs, things = runs + len(every._things), things + len(some._things)
    assert runs > 200
    assert things / runs == pytest.approx(0.25, abs=0.07)
    # later scans draw more new runs where fewer things cover the beams: the share of short readings holds
    laser = LaserModel(world, fleeting)
    rng = np.random.default_rng(11)
    shares = []
    for k in range(60):
        pose = POSE + np.array([0.0, 0.0, 0.05 * k])
        reading = laser.scan(pose, rng, t=0.1 * k).astype(float)
        shares.append(np.mean(reading < laser.true_ranges(pose) - 1e-4))
    assert np.mean(shares[10:]) == pytest.approx(0.1, abs=0.015)
    assert not LaserConfig(short_fleeting_share=0.5).has_errors
