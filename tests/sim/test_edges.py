"""The edge model: a beam next to a nearer wall reads it with ``edge_chance`` (slamtrials.sim.edges)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.sim.config import LaserConfig
from slamtrials.sim.edges import EDGE_MIN_STEP, edge_ranges, nearest_neighbour_range, reach_in_beams
from slamtrials.sim.laser_errors import apply_laser_errors
from slamtrials.sim.raycast import LaserModel
from slamtrials.worlds.world import World


def test_reach_counts_whole_beams():
    assert reach_in_beams(math.radians(1.0), math.radians(0.5)) == 2
    assert reach_in_beams(math.radians(1.0), math.radians(1.0)) == 1
    assert reach_in_beams(math.radians(1.0), math.radians(0.25)) == 4
    assert reach_in_beams(math.radians(0.4), math.radians(0.5)) == 0
    assert reach_in_beams(0.0, math.radians(0.5)) == 0


def test_nearest_neighbour_range_leaves_the_beam_itself_out():
    r = np.array([5.0, 1.0, 5.0, 5.0, 5.0, 2.0])
    np.testing.assert_array_equal(nearest_neighbour_range(r, 1), [1.0, 5.0, 1.0, 5.0, 2.0, 5.0])
    np.testing.assert_array_equal(nearest_neighbour_range(r, 2), [1.0, 5.0, 1.0, 1.0, 2.0, 5.0])
    assert np.isinf(nearest_neighbour_range(r, 0)).all()


def test_only_far_sides_of_edges_read_the_nearer_wall():
    r = np.array([5.0, 5.0, 1.0, 5.0, 5.0 - 0.5 * EDGE_MIN_STEP, 5.0])
    nearer = nearest_neighbour_range(r, 1)
    out = edge_ranges(r, nearer, np.zeros(6), 0.5)  # every uniform below the chance
    np.testing.assert_array_equal(out, [5.0, 1.0, 1.0, 1.0, 5.0 - 0.5 * EDGE_MIN_STEP, 5.0])
    np.testing.assert_array_equal(edge_ranges(r, nearer, np.full(6, 0.5), 0.5), r)  # none below it


def _pillar_world() -> World:
    """A 20 m room with a 1 m pillar 3 m in front of a laser at (5, 10): its sides are depth edges (and so
    are the room's walls where a beam meets them at a grazing angle: neighbours' ranges differ by more
    than 0.3 m there)."""
    occ = np.zeros((400, 400), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[190:210, 160:180] = True  # rows are y, columns x: x 8.0-9.0 m, y 9.5-10.5 m
    return World(occ, 0.05, origin=np.zeros(3), name="pillar")


def test_beams_beside_a_pillar_read_it_with_the_chance_and_others_never():
    config = LaserConfig(edge_chance=0.3, edge_reach=math.radians(1.0))
    laser = LaserModel(_pillar_world(), config)
    pose = np.array([5.0, 10.0, 0.0])
    true = laser.true_ranges(pose).astype(np.float64)
    nearer = nearest_neighbour_range(true, 2)
    far_side = nearer < true - EDGE_MIN_STEP  # the pillar's sides, and the room's walls at grazing incidence
    ahead = np.abs(config.angles) < math.radians(20.0)
    assert (far_side & ahead).sum() == 4  # two beams each side of the pillar
    rng = np.random.default_rng(3)
    scans = np.array([laser.scan(pose, rng) for _ in range(2000)], dtype=np.float64)
    reads_near = np.isclose(scans, nearer.astype(np.float32), atol=1e-5)
    assert reads_near[:, far_side].mean() == pytest.approx(0.3, abs=0.02)
    np.testing.assert_array_equal(
        scans[:, ~far_side], np.broadcast_to(true.astype(np.float32), scans.shape)[:, ~far_side]
    )


def test_edge_readings_take_the_other_errors_as_their_own_range():
    r = np.array([10.0, 10.0, 2.0, 10.0, 10.0])
    config = LaserConfig(edge_chance=1.0, edge_reach=math.radians(0.5), range_noise_std=0.01)
    readings = [apply_laser_errors(r.astype(np.float32), config, np.random.default_rng(s)) for s in range(400)]
    beside = np.array([x[[1, 3]] for x in readings])
    assert np.abs(beside - 2.0).max() < 0.06 and beside.std() == pytest.approx(0.01, rel=0.15)


def test_off_by_default_draws_nothing_and_given_neighbours_win():
    rng = np.random.default_rng(1)
    r = np.array([4.0, 1.0, 4.0], dtype=np.float32)
    out = apply_laser_errors(r, LaserConfig(range_noise_std=0.0, dropout_rate=0.0, short_rate=0.0), rng)
    np.testing.assert_array_equal(out, r)
    assert rng.bit_generator.state == np.random.default_rng(1).bit_generator.state
    config = LaserConfig(edge_chance=1.0, edge_reach=math.radians(0.5))
    given = apply_laser_errors(r, config, np.random.default_rng(1), nearer=np.array([0.5, np.inf, 3.0]))
    np.testing.assert_array_equal(given, np.array([0.5, 1.0, 3.0], dtype=np.float32))


def test_a_coarse_laser_has_no_neighbours_within_reach():
    config = LaserConfig(angular_resolution=math.radians(2.0), edge_chance=1.0, edge_reach=math.radians(1.0))
    laser = LaserModel(_pillar_world(), config)
    pose = np.array([5.0, 10.0, 0.0])
    np.testing.assert_array_equal(laser.scan(pose, np.random.default_rng(0)), laser.true_ranges(pose))
