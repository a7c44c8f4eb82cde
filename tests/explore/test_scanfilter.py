"""The explorer's scan filters: isolated returns, returns inside the footprint, returns seen once only."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.explore.scanfilter import ScanMemory, confirmed_ranges, inside_footprint
from slamtrials.record import LaserGeometry

LASER = LaserGeometry(-0.75 * math.pi, math.radians(0.5), 0.02, 30.0)
BEAMS = 541


def wall_scan(distance: float = 2.0) -> np.ndarray:
    """Ranges of the paper's laser in front of an infinite wall ``distance`` m ahead (x = distance);
    beams that do not reach it return nothing (range_max)."""
    angles = LASER.beam_angles(BEAMS)
    cos = np.cos(angles)
    return np.where(cos > 1e-6, distance / np.maximum(cos, 1e-6), LASER.range_max).clip(max=LASER.range_max)


def test_an_isolated_short_reading_is_dropped_and_the_wall_kept():
    ranges = wall_scan()
    ranges[270] = 0.6  # straight ahead, something that is not there
    out = confirmed_ranges(ranges, LASER, 2, 0.15, 3.0)
    assert math.isnan(out[270])
    wall = (ranges < LASER.range_max) & (np.arange(BEAMS) != 270)
    assert np.array_equal(out[wall], ranges[wall])  # within 3 m confirmed, beyond left as they are
    far = confirmed_ranges(ranges, LASER, 2, 0.15)  # examined at every range: the wall seen at a grazing angle goes
    assert np.isnan(far[wall & (ranges > 10.0)]).all() and not np.isnan(far[wall & (ranges < 3.0)]).any()
    assert np.array_equal(out[ranges >= LASER.range_max], ranges[ranges >= LASER.range_max])  # no-returns untouched


def test_an_obstacle_two_beams_wide_is_kept_and_window_zero_changes_nothing():
    ranges = wall_scan()
    ranges[270:272] = 0.6  # a post 0.6 m ahead, two beams wide
    out = confirmed_ranges(ranges, LASER, 2, 0.15)
    assert out[270] == pytest.approx(0.6) and out[271] == pytest.approx(0.6)
    ranges[300] = 0.3
    assert np.array_equal(confirmed_ranges(ranges, LASER, 0, 0.15), ranges)


def test_returns_inside_the_robots_disc_are_dropped():
    ranges = wall_scan()
    ranges[100] = 0.1  # inside a 0.15 m disc around the laser (mounted at the base's origin)
    ranges[101] = 0.2  # just outside: kept
    out = inside_footprint(ranges, LASER, 0.15)
    assert math.isnan(out[100]) and out[101] == pytest.approx(0.2)
    assert np.array_equal(inside_footprint(ranges, LASER, 0.0), ranges)


def test_a_phantom_pair_seen_in_one_scan_only_is_dropped_a_real_post_is_kept():
    memory = ScanMemory(0.15)
    first = wall_scan()
    first[270:272] = 0.6  # a real post
    kept = memory.persistent(confirmed_ranges(first, LASER, 2, 0.15), [0.0, 0.0, 0.0], LASER)
    assert kept[270] == pytest.approx(0.6)  # the first scan is kept whole
    # the robot drives 5 cm forward and turns 2 degrees; the post stays, a phantom pair appears
    pose = np.array([0.05, 0.0, math.radians(2.0)])
    second = wall_scan()
    post = np.array([0.6, 0.0])
    for beam in range(BEAMS):  # the post as seen from the new pose, two beams wide
        bearing = math.atan2(post[1] - pose[1], post[0] - pose[0]) - pose[2]
        index = round((bearing - LASER.angle_min) / LASER.angle_increment)
        if beam == index:
            second[beam] = second[beam + 1] = math.hypot(*(post - pose[:2]))
    second[400:402] = 0.35  # two adjacent short readings: they confirm each other
    spatial = confirmed_ranges(second, LASER, 2, 0.15)
    assert not math.isnan(spatial[400])
    out = memory.persistent(spatial, pose, LASER)
    assert math.isnan(out[400]) and math.isnan(out[401])
    index = int(np.nanargmin(out))
    assert out[index] == pytest.approx(math.hypot(*(post - pose[:2])))
