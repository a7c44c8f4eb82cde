"""The snapshot termination rule on synthetic map sequences."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from slamtrials.explore import SnapshotTermination, TerminationConfig
from slamtrials.explore.termination import (
    Snapshot,
    align_into,
    downscale,
    map_image,
    snapshot_mse,
)


def occupancy(grid, origin=(0.0, 0.0), resolution=0.05):
    return SimpleNamespace(
        grid=np.asarray(grid, dtype=np.int8), resolution=resolution, origin=np.array([origin[0], origin[1], 0.0])
    )


def room(n=80, known=80):
    grid = np.full((n, n), -1, dtype=np.int8)
    grid[:, :known] = 0
    grid[0, :known] = grid[-1, :known] = grid[:, 0] = 100
    return grid


def run(rule, maps, until, step=1.0):
    """Poll ``rule`` every ``step`` s with ``maps(t)``; return (time, reason) of the first stop."""
    t = 0.0
    while t <= until:
        reason = rule.check(t, maps(t))
        if reason:
            return t, reason
        t += step
    return None, None


def test_map_image_grey_levels():
    img = map_image(np.array([[100, 0, -1, 30, 70]], dtype=np.int8))
    assert img.tolist() == [[0, 255, 205, 255, 0]]


def test_identical_maps_converge_after_two_small_periods():
    rule = SnapshotTermination(TerminationConfig())
    still = occupancy(room())
    t, reason = run(rule, lambda t: still, 1000)
    assert (t, reason) == (240.0, "map_converged")
    assert rule.snapshots == 2 and rule.history == [(240.0, 0.0)]


def test_growing_maps_do_not_converge():
    rule = SnapshotTermination(TerminationConfig(max_snapshots=100))

    def grow(t):
        return occupancy(room(known=min(10 + int(t / 10), 200), n=200))

    t, reason = run(rule, grow, 1500)
    assert reason is None or t >= 1900
    assert all(mse >= 10 for _, mse in rule.history)


def test_large_environments_use_the_long_period():
    still = occupancy(room())
    rule = SnapshotTermination(TerminationConfig(), area=5000.0)
    assert run(rule, lambda t: still, 2000) == (1200.0, "map_converged")
    # without a given area, the known free area decides: 80 x 80 cells at 0.5 m = 1,600 m^2 -> large
    big = occupancy(room(), resolution=0.5)
    assert run(SnapshotTermination(TerminationConfig()), lambda t: big, 2000) == (1200.0, "map_converged")


def test_grown_map_is_aligned_by_its_origin():
    res = 0.05
    old = room(60, known=60)
    # the same map, grown by 8 unknown cells on the left and 12 at the bottom (origin moves accordingly)
    new = np.full((72, 68), -1, dtype=np.int8)
    new[:60, 8:] = old
    a = Snapshot(0.0, map_image(old), res, np.array([0.0, 0.0, 0.0]), 0.0)
    b = Snapshot(1.0, map_image(new), res, np.array([-8 * res, -12 * res, 0.0]), 0.0)
    assert np.array_equal(align_into(a, b), map_image(new))
    assert snapshot_mse(a, b) == 0.0
    # misaligned by one cell, the walls no longer match
    shifted = Snapshot(1.0, map_image(new), res, np.array([-7 * res, -12 * res, 0.0]), 0.0)
    assert snapshot_mse(a, shifted) > 10.0
    rule = SnapshotTermination(TerminationConfig())

    def maps(t):
        return occupancy(old) if t < 200 else occupancy(new, origin=(-8 * res, -12 * res))

    assert run(rule, maps, 1000) == (240.0, "map_converged")


def test_mse_is_summed_over_channels_and_downscaled():
    res = 0.05
    a = np.full((8, 8), 255, np.uint8)
    b = a.copy()
    b[:4, :4] = 0  # one 4x4 block: after block means that one pixel of four differs by 255
    sa = Snapshot(0.0, a, res, np.zeros(3), 0.0)
    sb = Snapshot(0.0, b, res, np.zeros(3), 0.0)
    assert snapshot_mse(sa, sb, factor=4, channels=1) == pytest.approx(255**2 / 4)
    assert snapshot_mse(sa, sb, factor=4, channels=3) == pytest.approx(3 * 255**2 / 4)
    assert downscale(np.zeros((5, 5), np.uint8), 4, fill=205).shape == (2, 2)


def test_time_cap_and_snapshot_cap():
    def grow(t):
        return occupancy(room(known=min(10 + int(t / 3), 200), n=200))

    assert run(SnapshotTermination(TerminationConfig(max_time=300.0)), grow, 1000) == (300.0, "time_cap")
    t, reason = run(SnapshotTermination(TerminationConfig(max_snapshots=3)), grow, 1000)
    assert (t, reason) == (360.0, "max_snapshots")


def test_reason_sticks_and_reset_forgets():
    rule = SnapshotTermination(TerminationConfig(max_time=10.0))
    still = occupancy(room())
    assert rule.check(0.0, still) is None
    assert rule.check(10.0, still) == "time_cap"
    assert rule.check(11.0, still) == "time_cap"
    rule.reset()
    assert rule.check(20.0, still) is None  # time counts from the first check after a reset


@pytest.mark.parametrize("factor", [1, 3, 4])
def test_compiled_mse_equals_the_mean_over_downscaled_aligned_images(factor):
    # random images of odd sizes, the older one placed anywhere, also partly outside the newer one
    rng = np.random.default_rng(7)
    res = 0.05
    for trial in range(12):
        oh, ow, nh, nw = (int(v) for v in rng.integers(5, 40, size=4))
        older = rng.choice(np.array([0, 205, 255], np.uint8), size=(oh, ow))
        newer = rng.choice(np.array([0, 205, 255], np.uint8), size=(nh, nw))
        shift = rng.integers(-12, 12, size=2) * res
        a = Snapshot(0.0, older, res, np.array([shift[0], shift[1], 0.0]), 0.0)
        b = Snapshot(1.0, newer, res, np.zeros(3), 0.0)
        aligned = downscale(align_into(a, b), factor)
        expected = float(np.mean((aligned - downscale(newer, factor)) ** 2)) * 3
        got = snapshot_mse(a, b, factor=factor)
        if factor in (1, 4):  # block means are exact in binary, so every sum is too, in any order
            assert got == expected, (trial, factor)
        else:  # thirds round, and numpy sums pairwise where the kernel sums in row order
            assert got == pytest.approx(expected, rel=1e-12, abs=1e-12), (trial, factor)
