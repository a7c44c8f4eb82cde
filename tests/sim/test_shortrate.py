"""The chance of a short reading by the range of the beam's wall (``short_range_scale``,
``short_range_shape``): ``short_rate (1 - exp(-(r / scale)^shape))``; scale 0 is the constant rate."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.sim.config import LaserConfig
from slamtrials.sim.raycast import LaserModel
from slamtrials.sim.shortrate import short_chances

from .test_raycast import room_world

RATE, SCALE, SHAPE = 0.4, 4.0, 1.5


def _short_by_range(config: LaserConfig, scans: int = 60) -> tuple[np.ndarray, np.ndarray]:
    """The walls' ranges (m) of every beam, and whether it read short, over ``scans`` scans from a corner of a
    20 m room (walls from under 2 m to over 20 m away)."""
    laser = LaserModel(room_world(size_m=20.0), config)
    rng = np.random.default_rng(8)
    walls, short = [], []
    for k in range(scans):
        pose = np.array([3.0, 2.5, 0.05 * k])
        true = laser.true_ranges(pose).astype(float)
        reading = laser.scan(pose, rng, t=0.1 * k).astype(float)
        walls.append(true)
        short.append(reading < true - 1e-4)
    return np.concatenate(walls), np.concatenate(short)


@pytest.mark.parametrize(
    "shape",
    [{}, {"short_run_beams": 4.0}, {"short_run_beams": 4.0, "short_lifetime": 5.0, "short_fleeting_share": 0.5}],
    ids=["independent", "runs", "runs that stay"],
)
def test_the_short_share_follows_the_chance_by_range(shape):
    config = LaserConfig(short_rate=RATE, short_range_scale=SCALE, short_range_shape=SHAPE, **shape)
    walls, short = _short_by_range(config)
    for low, high in ((1.5, 3.0), (3.0, 6.0), (6.0, 12.0), (12.0, 25.0)):
        inside = (walls >= low) & (walls < high)
        expected = float(np.mean(short_chances(walls[inside], RATE, SCALE, SHAPE)))
        # runs carry a share to the next beams, whose walls are about as far; things that stay are read by
        # later beams whatever their walls' range, and the fresh rate makes up for them only class by class
        # of chance (unmapped._fresh_rates), which holds the share to within a third here
        tolerance = 0.03 if not shape else 0.04 if "short_lifetime" not in shape else 0.1
        assert np.mean(short[inside]) == pytest.approx(expected, abs=tolerance), (low, high)
    expected_all = float(np.mean(short_chances(walls, RATE, SCALE, SHAPE)))
    assert np.mean(short) == pytest.approx(expected_all, rel=0.12)
    # the rise: few short readings on near walls, twice as many and more on far ones
    near, far = np.mean(short[walls < 3.0]), np.mean(short[walls > 12.0])
    assert far > 2.0 * near


def test_scale_zero_is_the_constant_rate_and_the_formula():
    r = np.array([0.0, 0.5, 2.0, 4.0, 30.0])
    assert np.array_equal(short_chances(r, 0.12, 0.0, 1.5), np.full(5, 0.12))
    chances = short_chances(r, RATE, SCALE, SHAPE)
    assert chances == pytest.approx([RATE * (1.0 - math.exp(-((x / SCALE) ** SHAPE))) for x in r], abs=1e-15)
    assert chances[0] == 0.0 and chances[-1] == pytest.approx(RATE, abs=1e-6)
    assert not LaserConfig(short_range_scale=4.0, short_range_shape=2.0).has_errors
